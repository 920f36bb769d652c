//! The tripod's reference figures (DESIGN §4, computed by an independent script).

use tetrefine::io::load_mesh;
use tetrefine::MeshStats;

#[test]
fn tripod_medit_matches_reference_figures() {
    let (mesh, report) = load_mesh(&crate::support::path("meshes/tripod.mesh")).unwrap();
    mesh.check().unwrap();
    let s = MeshStats::compute(&mesh);
    eprintln!("{report:?}\n{}", serde_json::to_string(&s).unwrap());
    assert_eq!(s.nodes, 967);
    assert_eq!(s.edges, 4621);
    assert_eq!(s.tets, 2799);
    assert_eq!(s.boundary_faces, 1710);
    assert_eq!(s.interior_faces, 4743);
    assert!((s.min_dihedral_deg.worst - 7.56).abs() < 0.01);
    assert!((s.min_dihedral_deg.avg - 42.92).abs() < 0.01);
    assert!((s.min_dihedral_deg.best - 65.15).abs() < 0.01);
    assert!((s.valence.avg - 9.56).abs() < 0.01);
    assert_eq!(s.valence.max, 27);
    assert_eq!(s.inverted, 0);
}
