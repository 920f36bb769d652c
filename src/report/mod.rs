//! Reports: statistics, histograms and JSON.

pub mod stats;
pub mod steps;

pub use stats::{Histogram, MeshStats};
