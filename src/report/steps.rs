//! The per-step table of `refine`: one row of statistics per step.

use super::MeshStats;

/// Header of the per-step table (the rows of Table 1 of the √3 paper (Burkhart, Hamann and Umlauf) as
/// columns, plus boundary faces, inverted tets, feature edges, corners and
/// wall time).
pub fn step_table_header() -> String {
    format!(
        "{:<8} {:>10} {:>11} {:>11} {:>9} {:>9} {:>9} {:>8} {:>7} {:>9} {:>8} {:>9} {:>7} {:>9}",
        "",
        "nodes",
        "edges",
        "tets",
        "worst°",
        "avg°",
        "best°",
        "val.avg",
        "val.max",
        "bnd.faces",
        "inverted",
        "features",
        "corners",
        "seconds"
    )
}

/// One row of the per-step table.
pub fn step_row(label: &str, s: &MeshStats, seconds: f64) -> String {
    format!(
        "{:<8} {:>10} {:>11} {:>11} {:>9.2} {:>9.2} {:>9.2} {:>8.2} {:>7} {:>9} {:>8} {:>9} {:>7} {:>9.3}",
        label,
        s.nodes,
        s.edges,
        s.tets,
        s.min_dihedral_deg.worst,
        s.min_dihedral_deg.avg,
        s.min_dihedral_deg.best,
        s.valence.avg,
        s.valence.max,
        s.boundary_faces,
        s.inverted,
        s.feature_edges,
        s.corners,
        seconds
    )
}
