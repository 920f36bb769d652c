//! Reports: statistics, histograms and JSON.

pub mod histogram;
pub mod stats;
pub mod steps;
pub mod table;

pub use histogram::write_histogram;
pub use stats::{Histogram, MeshStats};
pub use table::format_table;
