//! Geometry: exact orientation predicates and tetrahedron quality measures.

pub mod predicates;
pub mod quality;

pub use predicates::{all_positive, is_positive, orient3d, orient3d_sign, Orientation};
pub use quality::{dihedral_angles, tet_min_sine, tet_quality, tet_volume, TetQuality};
