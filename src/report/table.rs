//! The statistics as a plain-text table: the rows of Table 1 of the √3 paper (Burkhart, Hamann and Umlauf)
//! (Burkhart, Hamann and Umlauf, "Adaptive and feature-preserving subdivision
//! for high-quality tetrahedral meshes": nodes, edges, tets, worst / average /
//! best minimum dihedral angle, average / maximal valence) plus boundary and
//! interior faces, the maximum dihedral angle, inverted tets, volume and the
//! tets per region.
//!
//! One column per mesh (or per refinement step), so that a sequence of steps
//! reads left to right as in the paper.

use super::MeshStats;
use std::collections::BTreeSet;
use std::fmt::Write;

/// One row: its label and how to print it from the statistics of a column.
struct Row {
    label: &'static str,
    value: fn(&MeshStats) -> String,
}

fn degrees(x: f64) -> String {
    format!("{x:.2}")
}

/// The fixed rows, in the order of the paper's Table 1 and then the extras.
const ROWS: &[Row] = &[
    Row {
        label: "nodes",
        value: |s| s.nodes.to_string(),
    },
    Row {
        label: "edges",
        value: |s| s.edges.to_string(),
    },
    Row {
        label: "tets",
        value: |s| s.tets.to_string(),
    },
    Row {
        label: "worst min dihedral (deg)",
        value: |s| degrees(s.min_dihedral_deg.worst),
    },
    Row {
        label: "average min dihedral (deg)",
        value: |s| degrees(s.min_dihedral_deg.avg),
    },
    Row {
        label: "best min dihedral (deg)",
        value: |s| degrees(s.min_dihedral_deg.best),
    },
    Row {
        label: "average valence (edges)",
        value: |s| format!("{:.2}", s.valence.avg),
    },
    Row {
        label: "max valence (edges)",
        value: |s| s.valence.max.to_string(),
    },
    Row {
        label: "boundary faces",
        value: |s| s.boundary_faces.to_string(),
    },
    Row {
        label: "interior faces",
        value: |s| s.interior_faces.to_string(),
    },
    Row {
        label: "worst max dihedral (deg)",
        value: |s| degrees(s.max_dihedral_deg.worst),
    },
    Row {
        label: "average max dihedral (deg)",
        value: |s| degrees(s.max_dihedral_deg.avg),
    },
    Row {
        label: "inverted tets",
        value: |s| s.inverted.to_string(),
    },
    Row {
        label: "feature edges",
        value: |s| s.feature_edges.to_string(),
    },
    Row {
        label: "corners",
        value: |s| s.corners.to_string(),
    },
    Row {
        label: "volume",
        value: |s| significant(s.volume),
    },
    Row {
        label: "regions",
        value: |s| s.regions.len().to_string(),
    },
];

/// A number with 6 significant digits, in exponent form when it is very large
/// or very small (volumes come in any unit).
fn significant(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    // Round to 6 significant digits first, so that 0.9999999 counts as 1.
    let sci = format!("{x:.5e}");
    let exp: i32 = sci
        .rsplit('e')
        .next()
        .and_then(|e| e.parse().ok())
        .unwrap_or(0);
    if (-3..7).contains(&exp) {
        let decimals = (5 - exp).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        sci
    }
}

/// Formats the statistics as a table with one column per `(heading, stats)`.
///
/// Rows: nodes, edges, tets, worst / average / best minimum dihedral angle,
/// average / maximal valence (the paper's Table 1), then boundary and interior
/// faces, worst / average maximum dihedral angle, inverted tets, volume, the
/// number of regions and one `tets in region <id>` row per region id found in
/// any column (`-` where a column has none). Angles are in degrees with two
/// decimals. Labels are left-aligned, values right-aligned; every line ends
/// with `\n`.
pub fn format_table(columns: &[(&str, &MeshStats)]) -> String {
    let region_ids: BTreeSet<i64> = columns
        .iter()
        .flat_map(|(_, s)| s.regions.keys())
        .filter_map(|k| k.parse::<i64>().ok())
        .collect();

    // Build the cells first, then measure the widths.
    let mut lines: Vec<(String, Vec<String>)> = Vec::new();
    lines.push((
        String::new(),
        columns.iter().map(|(h, _)| h.to_string()).collect(),
    ));
    for row in ROWS {
        lines.push((
            row.label.to_string(),
            columns.iter().map(|(_, s)| (row.value)(s)).collect(),
        ));
    }
    for id in &region_ids {
        let key = id.to_string();
        lines.push((
            format!("  tets in region {id}"),
            columns
                .iter()
                .map(|(_, s)| s.regions.get(&key).map_or("-".into(), |n| n.to_string()))
                .collect(),
        ));
    }

    let label_width = lines
        .iter()
        .map(|(l, _)| l.chars().count())
        .max()
        .unwrap_or(0);
    let widths: Vec<usize> = (0..columns.len())
        .map(|c| {
            lines
                .iter()
                .map(|(_, cells)| cells[c].chars().count())
                .max()
                .unwrap_or(0)
        })
        .collect();

    let mut out = String::new();
    for (label, cells) in &lines {
        let mut line = format!("{label:<label_width$}");
        for (cell, &w) in cells.iter().zip(&widths) {
            let _ = write!(line, "  {cell:>w$}");
        }
        out.push_str(line.trim_end());
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::cube_grid;
    use crate::TetMesh;

    fn grid_stats(n: usize) -> MeshStats {
        let (mesh, _) = TetMesh::from_data(&cube_grid(n)).unwrap();
        MeshStats::compute(&mesh)
    }

    /// The value cells of the row with this label.
    fn row<'a>(table: &'a str, label: &str) -> Vec<&'a str> {
        let line = table
            .lines()
            .find(|l| l.starts_with(label) && l[label.len()..].starts_with("  "))
            .unwrap_or_else(|| panic!("no row {label:?} in\n{table}"));
        line[label.len()..].split_whitespace().collect()
    }

    #[test]
    fn one_column_per_mesh_with_the_paper_rows() {
        let (a, b) = (grid_stats(1), grid_stats(2));
        let t = format_table(&[("n=1", &a), ("n=2", &b)]);
        // Header row: empty label, then the headings.
        assert_eq!(
            t.lines()
                .next()
                .unwrap()
                .split_whitespace()
                .collect::<Vec<_>>(),
            ["n=1", "n=2"]
        );
        // Counts from the closed forms of the Kuhn grid: (n+1)³ nodes, 6n³ tets,
        // 3n(n+1)² + 3n²(n+1) + n³ edges, 12n² boundary faces.
        assert_eq!(row(&t, "nodes"), ["8", "27"]);
        assert_eq!(row(&t, "tets"), ["6", "48"]);
        assert_eq!(row(&t, "edges"), ["19", "98"]);
        assert_eq!(row(&t, "boundary faces"), ["12", "48"]);
        // Every Kuhn tet has angles 45°..90°, two decimals.
        assert_eq!(row(&t, "worst min dihedral (deg)"), ["45.00", "45.00"]);
        assert_eq!(row(&t, "average min dihedral (deg)"), ["45.00", "45.00"]);
        assert_eq!(row(&t, "best min dihedral (deg)"), ["45.00", "45.00"]);
        assert_eq!(row(&t, "worst max dihedral (deg)"), ["90.00", "90.00"]);
        // Average valence is 2E/V: 38/8 and 196/27.
        assert_eq!(row(&t, "average valence (edges)"), ["4.75", "7.26"]);
        // The main diagonal's ends of the single cube touch all 7 other corners.
        assert_eq!(row(&t, "max valence (edges)")[0], "7");
        assert_eq!(row(&t, "inverted tets"), ["0", "0"]);
        assert_eq!(row(&t, "volume"), ["1.00000", "1.00000"]);
        assert_eq!(row(&t, "regions"), ["1", "1"]);
        assert_eq!(row(&t, "  tets in region 0"), ["6", "48"]);
        // All data lines have the same rows in the same order as the paper's
        // Table 1 first.
        let labels: Vec<&str> = t
            .lines()
            .skip(1)
            .take(8)
            .map(|l| l.split("  ").next().unwrap())
            .collect();
        assert_eq!(
            labels,
            [
                "nodes",
                "edges",
                "tets",
                "worst min dihedral (deg)",
                "average min dihedral (deg)",
                "best min dihedral (deg)",
                "average valence (edges)",
                "max valence (edges)"
            ]
        );
    }

    #[test]
    fn regions_missing_from_a_column_show_a_dash() {
        let a = grid_stats(1);
        let mut b = a.clone();
        b.regions.clear();
        b.regions.insert("7".into(), 6);
        let t = format_table(&[("a", &a), ("b", &b)]);
        assert_eq!(row(&t, "  tets in region 0"), ["6", "-"]);
        assert_eq!(row(&t, "  tets in region 7"), ["-", "6"]);
    }

    #[test]
    fn values_are_right_aligned_in_equal_width_columns() {
        let a = grid_stats(1);
        let t = format_table(&[("a long heading", &a)]);
        let ends: BTreeSet<usize> = t.lines().map(|l| l.chars().count()).collect();
        assert_eq!(ends.len(), 1, "{t}");
    }

    #[test]
    fn significant_digits() {
        assert_eq!(significant(1.0), "1.00000");
        assert_eq!(significant(123.456789), "123.457");
        assert_eq!(significant(0.0123456), "0.0123456");
        assert_eq!(significant(2.5e-9), "2.50000e-9");
        assert_eq!(significant(0.0), "0");
        assert_eq!(significant(0.99999999999), "1.00000");
        assert_eq!(significant(-42.0), "-42.0000");
    }
}
