//! The tripod (the model of Table 1 of the √3 refinement paper) read from each
//! of its four files gives DESIGN §4's reference figures (computed by an
//! independent script) and identical statistics: GiD (10-node tets, corner
//! nodes kept), Medit, Gmsh 2.2 and VTU.

use crate::support::{canon, load, mesh_path};
use tetrefine::MeshStats;

const FILES: [&str; 4] = ["tripod.GiD.msh", "tripod.mesh", "tripod.msh", "tripod.vtu"];

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0)
}

#[test]
fn every_tripod_file_gives_the_reference_figures() {
    let mut all = Vec::new();
    for name in FILES {
        let mesh = load(&mesh_path(name));
        // The GiD file has 5,621 points; the mid-edge ones must be gone.
        assert_eq!(mesh.n_points(), 967, "{name}: points kept");
        let s = MeshStats::compute(&mesh);
        assert_eq!(s.nodes, 967, "{name}");
        assert_eq!(s.edges, 4621, "{name}");
        assert_eq!(s.tets, 2799, "{name}");
        assert_eq!(s.boundary_faces, 1710, "{name}");
        assert_eq!(s.interior_faces, 4743, "{name}");
        assert!(
            (s.min_dihedral_deg.worst - 7.56).abs() < 0.01,
            "{name}: {s:?}"
        );
        assert!(
            (s.min_dihedral_deg.avg - 42.92).abs() < 0.01,
            "{name}: {s:?}"
        );
        assert!(
            (s.min_dihedral_deg.best - 65.15).abs() < 0.01,
            "{name}: {s:?}"
        );
        assert!((s.valence.avg - 9.56).abs() < 0.01, "{name}: {s:?}");
        assert_eq!(s.valence.max, 27, "{name}");
        assert_eq!(s.inverted, 0, "{name}");
        all.push((name, s, canon(&mesh)));
    }
    let (first, s0, c0) = &all[0];
    for (name, s, c) in &all[1..] {
        assert_eq!(s.histogram, s0.histogram, "{name} vs {first}: histogram");
        assert_eq!(s.regions, s0.regions, "{name} vs {first}: regions");
        for (a, b) in [
            (s.min_dihedral_deg.worst, s0.min_dihedral_deg.worst),
            (s.min_dihedral_deg.avg, s0.min_dihedral_deg.avg),
            (s.min_dihedral_deg.best, s0.min_dihedral_deg.best),
            (s.max_dihedral_deg.worst, s0.max_dihedral_deg.worst),
            (s.max_dihedral_deg.avg, s0.max_dihedral_deg.avg),
            (s.valence.avg, s0.valence.avg),
            (s.volume, s0.volume),
        ] {
            assert!(close(a, b), "{name} vs {first}: {a} != {b}");
        }
        // Not only the same figures: the same tets on the same coordinates.
        assert_eq!(c.tets, c0.tets, "{name} vs {first}: tets");
    }
}
