//! Reports: statistics, histograms and JSON.

pub(crate) mod histogram;
pub(crate) mod stats;
pub(crate) mod steps;
pub(crate) mod table;

pub use histogram::{to_csv, to_png, to_svg, write_histogram, HistogramFormat};
pub use stats::{
    Histogram, MaxDihedral, MeshStats, MinDihedral, Valence, DEFAULT_BINS, DEFAULT_HIST_MAX_DEG,
};
pub use steps::{step_row, step_table_header};
pub use table::format_table;
