//! The core library's integration tests, one binary: the mesh store and its
//! local operations, mesh improvement, and the √3 step with its features and
//! marking.

#[path = "../support/mod.rs"]
mod support;

mod bulk_ops;
mod core_tripod;
mod features;
mod improve_parallel;
mod marking;
mod ops_proptest;
mod quality_guarantees;
mod refine_counts;
mod refine_meshes;
mod refine_quality;
mod transfer;
