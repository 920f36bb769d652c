//! Quality of the √3 step on the tripod against the seed paper's Table 1
//! (worst / average minimum dihedral angle: 6.1° / 36.1° after step 1 and
//! 4.9° / 28.4° after step 2), and `improve` on every mesh in meshes/.

use std::path::Path;
use tetrefine::io::load_mesh;
use tetrefine::MeshStats;
use tetrefine::{improve, ImproveOptions};
use tetrefine::{refine, refine_step, RefineOptions, Sqrt3Rule};

#[test]
fn tripod_beats_table_1_in_every_boundary_mode() {
    let paper = [(6.1, 36.1), (4.9, 28.4)];
    for rule in [
        Sqrt3Rule::Interpolating,
        Sqrt3Rule::Approximating,
        Sqrt3Rule::Linear,
    ] {
        let (mut mesh, _) = load_mesh(&crate::support::path("meshes/tripod.mesh")).unwrap();
        let opts = RefineOptions {
            boundary: rule,
            ..Default::default()
        };
        for (step, &(worst, avg)) in paper.iter().enumerate() {
            refine_step(&mut mesh, step + 1, &opts);
            let s = MeshStats::compute(&mesh);
            eprintln!(
                "{rule:?} step {}: worst {:.2} avg {:.2} ({} tets)",
                step + 1,
                s.min_dihedral_deg.worst,
                s.min_dihedral_deg.avg,
                s.tets
            );
            assert!(
                s.min_dihedral_deg.worst > worst,
                "{rule:?} step {}",
                step + 1
            );
            assert!(s.min_dihedral_deg.avg > avg, "{rule:?} step {}", step + 1);
            // Beyond the paper: the average stays above 38° (the input has 42.92°).
            assert!(s.min_dihedral_deg.avg > 38.0, "{rule:?} step {}", step + 1);
        }
    }
}

#[test]
fn tripod_keeps_the_inputs_worst_angle_in_every_boundary_mode() {
    // The input's worst minimum dihedral angle is 7.56° (DESIGN §4).
    for rule in [
        Sqrt3Rule::Interpolating,
        Sqrt3Rule::Approximating,
        Sqrt3Rule::Linear,
    ] {
        let (mut mesh, _) = load_mesh(&crate::support::path("meshes/tripod.mesh")).unwrap();
        let opts = RefineOptions {
            boundary: rule,
            ..Default::default()
        };
        for step in 1..=2 {
            refine_step(&mut mesh, step, &opts);
            let s = MeshStats::compute(&mesh);
            assert!(
                s.min_dihedral_deg.worst >= 7.56,
                "{rule:?} step {step}: {}",
                s.min_dihedral_deg.worst
            );
        }
    }
}

#[test]
fn improve_never_lowers_the_worst_and_raises_the_average() {
    let meshes = [
        "tripod.mesh",
        "mmg_cube.mesh",
        "getfem_holed_bar.mesh",
        "getfem_ladder.mesh",
        "gmsh_t16.mesh",
        "tetgen_example.mesh",
        "mmg_tinyBoxt.mesh",
    ];
    let mut below_15 = 0;
    let mut raised_below_15 = 0;
    for name in meshes {
        let (mut mesh, _) = load_mesh(&Path::new("meshes").join(name)).unwrap();
        let before = MeshStats::compute(&mesh);
        // Boundary fixed (`Effort::Fast`): the boundary-moving default is
        // held to the same rule in quality_guarantees.rs.
        improve(
            &mut mesh,
            &ImproveOptions {
                boundary: None,
                ..Default::default()
            },
        );
        mesh.check().unwrap();
        let after = MeshStats::compute(&mesh);
        eprintln!(
            "{name}: worst {:.2} -> {:.2}, avg {:.2} -> {:.2}",
            before.min_dihedral_deg.worst,
            after.min_dihedral_deg.worst,
            before.min_dihedral_deg.avg,
            after.min_dihedral_deg.avg
        );
        assert!(
            after.min_dihedral_deg.worst >= before.min_dihedral_deg.worst,
            "{name}"
        );
        assert!(
            after.min_dihedral_deg.avg > before.min_dihedral_deg.avg,
            "{name}"
        );
        // The boundary is fixed: same boundary faces, same volume.
        assert_eq!(after.boundary_faces, before.boundary_faces, "{name}");
        assert!(
            (after.volume - before.volume).abs() <= 1e-9 * before.volume.abs(),
            "{name}"
        );
        if before.min_dihedral_deg.worst < 15.0 {
            below_15 += 1;
            if after.min_dihedral_deg.worst > before.min_dihedral_deg.worst {
                raised_below_15 += 1;
            }
            if name == "tripod.mesh" {
                assert!(after.min_dihedral_deg.worst > before.min_dihedral_deg.worst);
            }
        }
    }
    assert!(below_15 > 0);
    assert!(
        2 * raised_below_15 > below_15,
        "{raised_below_15} of {below_15}"
    );
}

/// Issue 14, point 6: a default step evens out edge lengths. The √3
/// operations alone keep every old interior edge, so the input's edges
/// stand out after a step; the long-edge rounds split them. Measured
/// independently of the library's own criterion, from the edge list: on
/// the tripod and the holed bar the step's longest edge is below the
/// input's, and at most 1.5 % of the edges are longer than 1.4 times the
/// mean length of the edges at their two ends (one long-edge round left
/// 2.2 % and 1.8 %, two leave 1.2 % and 1.1 %).
#[test]
fn a_default_step_evens_out_edge_lengths() {
    for name in ["tripod", "getfem_holed_bar"] {
        let (mut mesh, _) =
            load_mesh(&crate::support::path(&format!("meshes/{name}.mesh"))).unwrap();
        let (input_longest, _) = edge_spread(&mesh);
        refine_step(&mut mesh, 1, &RefineOptions::default());
        let (longest, standing_out) = edge_spread(&mesh);
        eprintln!(
            "{name}: longest {input_longest:.4} -> {longest:.4}, {standing_out:.4} stand out"
        );
        assert!(longest < input_longest, "{name}");
        assert!(standing_out <= 0.015, "{name}: {standing_out}");
    }
}

/// Issue 14, point 6, the tail after two steps: a step keeps the tail of
/// edges the step before left, and its long-edge rounds' settling passes
/// and splits add to it; the outlier round of a second step splits the
/// edges over 1.5 times the means at their ends. The share of edges over
/// 1.5 times the mean length of the edges at their two ends after two
/// default steps (2026-12-07): here (no features detected) 0.12 %
/// (tripod), 0.14 % (holed bar) and 0.21 % (mmg_cube), and 0.27 % on the
/// tripod with the round switched off; measured with numpy on the CLI's
/// outputs (features detected), 0.30 %, 0.36 % and 0.36 % without the
/// round, 0.15 %, 0.18 % and 0.21 % with it. At most 0.25 % is allowed.
///
/// The longest edge, too: where no point of a very long free interior
/// edge cuts its shell above the bar, the edge is split at a lower bar
/// and the settling passes lift its halves. Here (no features detected)
/// the longest edge after two steps is 1.40 (tripod), 1.43 (holed bar)
/// and 1.42 (mmg_cube) times the 99th percentile of the edge lengths,
/// and mmg_cube's was 1.74 without the lower bar; on the CLI's outputs
/// (features detected) it was 1.94, 1.72 and 1.74 without it, 1.35, 1.31
/// and 1.42 with it, and MMG3D `-hsiz`'s outputs at the same counts have
/// 1.34, 1.27 and 1.25. At most 1.5 is allowed.
#[test]
fn two_default_steps_trim_the_tail_of_long_edges() {
    for name in ["tripod", "getfem_holed_bar", "mmg_cube"] {
        let (mut mesh, _) =
            load_mesh(&crate::support::path(&format!("meshes/{name}.mesh"))).unwrap();
        refine(&mut mesh, 2, &RefineOptions::default());
        let (_, standing_out) = edge_spread_over(&mesh, 1.5);
        let longest = longest_over_percentile_99(&mesh);
        eprintln!(
            "{name}: {standing_out:.5} of the edges stand out, the longest {longest:.3} x the 99th percentile"
        );
        assert!(standing_out <= 0.0025, "{name}: {standing_out}");
        assert!(longest <= 1.5, "{name}: {longest}");
    }
}

/// Issue 14, point 6, where the split at an edge's midpoint would leave a
/// thin half: mmg_cube's longest edges after a √3 step are chords between
/// two faces of the cube whose midpoint splits cut a poor tet, and split at
/// their midpoints only they stayed (the longest 0.72 against the input's
/// 1.02). Split off the middle where the midpoint is refused, a default
/// step leaves its longest edge below half the input's (0.34); split at a
/// lower bar where the edge is very long and free, within 1.4 times the
/// 99th percentile of the edge lengths (1.59 times without; MMG3D
/// `-hsiz`'s output at the same count has 1.26).
#[test]
fn a_default_step_halves_mmg_cubes_longest_edge() {
    let (mut mesh, _) = load_mesh(&crate::support::path("meshes/mmg_cube.mesh")).unwrap();
    let (input_longest, _) = edge_spread(&mesh);
    refine_step(&mut mesh, 1, &RefineOptions::default());
    let (longest, _) = edge_spread(&mesh);
    assert!(
        longest < 0.5 * input_longest,
        "longest {input_longest:.4} -> {longest:.4}"
    );
    let over = longest_over_percentile_99(&mesh);
    eprintln!("the longest edge is {over:.3} x the 99th percentile");
    assert!(
        over <= 1.4,
        "the longest edge is {over:.3} x the 99th percentile"
    );
}

/// Issue 14, point 6, on a graded input: gmsh_t16's shortest edge is 0.02
/// times its median, and the relative test alone keeps a step's grading,
/// so a step left 14.5 % of its edges longer than 1.9 times the median,
/// over the points, of the mean edge length at a point (measured on the
/// 2026-12-06 outputs, with numpy). The long-edge rounds after the first
/// also split every edge over 1.9 times that median as it stands before
/// them: a default step leaves at most 1 % over it (0.49 % on 2026-12-07),
/// measured here from the output's edge list.
#[test]
fn a_default_step_caps_a_graded_inputs_long_edges() {
    let (mut mesh, _) = load_mesh(&crate::support::path("meshes/gmsh_t16.mesh")).unwrap();
    refine_step(&mut mesh, 1, &RefineOptions::default());
    let (_, lengths, means) = edge_lengths(&mesh);
    let mut means: Vec<f64> = means.into_iter().filter(|m| !m.is_nan()).collect();
    means.sort_by(f64::total_cmp);
    let median = means[means.len() / 2];
    let over = lengths.iter().filter(|&&l| l > 1.9 * median).count();
    let share = over as f64 / lengths.len() as f64;
    assert!(
        share <= 0.01,
        "{over} of {} edges over 1.9 x {median:.5}",
        lengths.len()
    );
}

/// The edges of `mesh`, their lengths, and per point the mean length of
/// its edges (NaN at a point without one).
fn edge_lengths(mesh: &tetrefine::TetMesh) -> (Vec<[u32; 2]>, Vec<f64>, Vec<f64>) {
    let edges = mesh.edges();
    let lengths: Vec<f64> = edges
        .iter()
        .map(|&[a, b]| (mesh.point(a) - mesh.point(b)).length())
        .collect();
    let mut sum = vec![0.0; mesh.n_points()];
    let mut count = vec![0usize; mesh.n_points()];
    for (e, &l) in edges.iter().zip(&lengths) {
        for &v in e {
            sum[v as usize] += l;
            count[v as usize] += 1;
        }
    }
    let means = sum
        .iter()
        .zip(&count)
        .map(|(&s, &c)| s / c as f64)
        .collect();
    (edges, lengths, means)
}

/// The longest edge of `mesh` over the 99th percentile of its edge
/// lengths (the length below which 99 % of the edges are).
fn longest_over_percentile_99(mesh: &tetrefine::TetMesh) -> f64 {
    let (_, mut lengths, _) = edge_lengths(mesh);
    lengths.sort_by(f64::total_cmp);
    let p99 = lengths[(0.99 * (lengths.len() - 1) as f64).round() as usize];
    lengths[lengths.len() - 1] / p99
}

/// The longest edge of `mesh`, and the share of its edges longer than 1.4
/// times the mean length of the edges at their two ends.
fn edge_spread(mesh: &tetrefine::TetMesh) -> (f64, f64) {
    edge_spread_over(mesh, 1.4)
}

/// The longest edge of `mesh` and the share of its edges longer than
/// `factor` times the mean length of the edges at their two ends.
fn edge_spread_over(mesh: &tetrefine::TetMesh, factor: f64) -> (f64, f64) {
    let (edges, lengths, means) = edge_lengths(mesh);
    let longest = lengths.iter().copied().fold(0.0, f64::max);
    let out = edges
        .iter()
        .zip(&lengths)
        .filter(|&(&[a, b], &l)| l > factor * 0.5 * (means[a as usize] + means[b as usize]))
        .count();
    (longest, out as f64 / edges.len() as f64)
}
