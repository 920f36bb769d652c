//! Reports: statistics, histograms and JSON.

pub mod stats;

pub use stats::{Histogram, MeshStats};
