//! Exact counts of the √3 step on the tripod (DESIGN §5 and the seed paper §7):
//! n tets, n_b boundary and n_i = (4n − n_b)/2 interior faces give 4n after
//! `split`, 4n + n_i after `flip`, + 2·n_b after `boundary-split`.

use tetrefine::io::load_mesh;
use tetrefine::MeshStats;
use tetrefine::{refine_step, Phase, RefineOptions, Sqrt3Rule};

fn tripod() -> tetrefine::TetMesh {
    load_mesh(&crate::support::path("meshes/tripod.mesh"))
        .unwrap()
        .0
}

fn run(stop: Phase) -> (tetrefine::TetMesh, tetrefine::StepReport) {
    let mut m = tripod();
    // The counted phases come before boundary smoothing; the linear rule
    // would refuse the flips of the tripod's bent (not exactly coplanar)
    // boundary edges, which the paper's counts assume flipped.
    let opts = RefineOptions {
        stop_after: Some(stop),
        boundary: Sqrt3Rule::Interpolating,
        ..Default::default()
    };
    let r = refine_step(&mut m, 1, &opts);
    m.check().unwrap();
    (m, r)
}

#[test]
fn tripod_counts_after_each_topological_phase() {
    let (m, r) = run(Phase::Split);
    assert_eq!(m.n_tets(), 11_196);
    assert_eq!(r.split, 2_799);
    let (m, r) = run(Phase::Flip);
    assert_eq!(r.refused_flips, 0, "{r:?}");
    assert_eq!(m.n_tets(), 15_939);
    let (m, r) = run(Phase::BoundarySplit);
    assert_eq!(m.n_tets(), 19_359);
    assert_eq!(r.boundary_split, 1_710);
    let (m, r) = run(Phase::BoundaryFlip);
    eprintln!("{r:?}");
    let s = MeshStats::compute(&m);
    // 967 + 2,799 barycentres + 1,710 face points.
    assert_eq!(s.nodes, 5_476);
    // √3 on the boundary: three triangles per old face.
    assert_eq!(s.boundary_faces, 5_130);
    assert_eq!(r.refused_boundary_flips, 0);
}

#[test]
fn tripod_full_step_quality() {
    for rule in [
        Sqrt3Rule::Linear,
        Sqrt3Rule::Approximating,
        Sqrt3Rule::Interpolating,
    ] {
        let mut m = tripod();
        let opts = RefineOptions {
            boundary: rule,
            ..Default::default()
        };
        let r = refine_step(&mut m, 1, &opts);
        m.check().unwrap();
        let s = MeshStats::compute(&m);
        eprintln!(
            "{rule:?} {r:?}\n{} tets worst {:.2} avg {:.2}",
            s.tets, s.min_dihedral_deg.worst, s.min_dihedral_deg.avg
        );
        // The √3 phases give 5,476 points and 5,130 boundary faces; each
        // long-edge split of the optimize phase adds its midpoint and one
        // boundary face per boundary face it cuts in two (two for an edge
        // of the tripod's manifold boundary); each vertex insertion (on an
        // interior edge) adds one interior point; each edge contraction
        // takes out one interior point and no boundary face.
        assert_eq!(
            s.nodes,
            5_476 + r.improve.long_edges_split + r.improve.vertices_inserted
                - r.improve.edges_contracted
        );
        assert_eq!(s.boundary_faces, 5_130 + r.improve.long_edge_boundary_faces);
        assert_eq!(r.improve.long_edge_boundary_faces % 2, 0);
        assert_eq!(s.inverted, 0);
    }
}

#[test]
fn tripod_second_step_adds_one_point_per_tet_and_boundary_face() {
    // After step 1 the mesh has 5,476 vertices (plus one per long edge
    // split or vertex insertion, minus one per edge contraction), T1 tets
    // and 5,130 boundary faces (plus one per boundary face a long-edge
    // split cut in two); step 2 adds one barycentre per tet and one point
    // per boundary face (plus its long-edge splits and insertions, minus
    // its contractions), and makes three boundary faces of each (plus its
    // long-edge splits' faces).
    let mut m = tripod();
    let opts = RefineOptions::default();
    let r1 = refine_step(&mut m, 1, &opts);
    assert!(r1.improve.long_edges_split > 0);
    let s1 = MeshStats::compute(&m);
    assert_eq!(
        (s1.nodes, s1.boundary_faces),
        (
            5_476 + r1.improve.long_edges_split + r1.improve.vertices_inserted
                - r1.improve.edges_contracted,
            5_130 + r1.improve.long_edge_boundary_faces
        )
    );
    let r2 = refine_step(&mut m, 2, &opts);
    m.check().unwrap();
    let s2 = MeshStats::compute(&m);
    assert_eq!(
        s2.nodes,
        s1.nodes
            + s1.tets
            + s1.boundary_faces
            + r2.improve.long_edges_split
            + r2.improve.vertices_inserted
            - r2.improve.edges_contracted
    );
    assert_eq!(
        s2.boundary_faces,
        3 * s1.boundary_faces + r2.improve.long_edge_boundary_faces
    );
}
