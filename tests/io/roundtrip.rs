//! Every writer's output, read back, is the same mesh: the same points in the
//! same order, the same tets (none turned around on reading, so vertex order is
//! kept up to an even permutation), regions, face markers, feature edges and
//! corners — as far as the format can carry them (TetGen files have no
//! corners; a .vtu carries tets and regions only).

use crate::support::{canon, load, mesh_path, Canon};
use std::path::Path;
use tetrefine::io::{load_mesh, write_mesh};
use tetrefine::TetMesh;

/// What a format carries besides points, tets and regions.
struct Carries {
    ext: &'static str,
    faces_and_edges: bool,
    corners: bool,
}

const FORMATS: [Carries; 4] = [
    Carries {
        ext: "mesh",
        faces_and_edges: true,
        corners: true,
    },
    Carries {
        ext: "msh",
        faces_and_edges: true,
        corners: true,
    },
    Carries {
        ext: "node",
        faces_and_edges: true,
        corners: false,
    },
    Carries {
        ext: "vtu",
        faces_and_edges: false,
        corners: false,
    },
];

fn round_trip(name: &str, mesh: &TetMesh, dir: &Path) {
    let before = canon(mesh);
    for f in &FORMATS {
        let out = dir.join(format!("{name}.{}", f.ext));
        write_mesh(&out, mesh).unwrap_or_else(|e| panic!("writing {}: {e}", out.display()));
        let (back, report) =
            load_mesh(&out).unwrap_or_else(|e| panic!("reading {}: {e}", out.display()));
        assert_eq!(
            report.reoriented,
            0,
            "{}: tets turned around",
            out.display()
        );
        assert_eq!(back.points(), mesh.points(), "{}: points", out.display());
        let after = canon(&back);
        // (assert! rather than assert_eq!: a diff of thousands of tets helps nobody)
        assert!(
            after.tets == before.tets,
            "{}: tets or regions differ",
            out.display()
        );
        if f.faces_and_edges {
            assert!(
                after.faces == before.faces,
                "{}: face markers differ",
                out.display()
            );
            assert!(
                after.edges == before.edges,
                "{}: feature edges differ",
                out.display()
            );
        } else {
            assert!(after.faces.is_empty() && after.edges.is_empty());
        }
        if f.corners {
            assert_eq!(after.corners, before.corners, "{}: corners", out.display());
        }
    }
}

#[test]
fn every_medit_mesh_survives_every_writer() {
    let dir = tempfile::tempdir().unwrap();
    let mut names: Vec<String> = std::fs::read_dir(mesh_path(""))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".mesh"))
        .collect();
    names.sort();
    assert_eq!(names.len(), 7, "meshes/*.mesh: {names:?}");
    for n in &names {
        let mesh = load(&mesh_path(n));
        round_trip(n.trim_end_matches(".mesh"), &mesh, dir.path());
    }
}

/// The MMG cube with made-up tags of every kind and sign: three regions
/// (-1, 0, 1), markers on boundary and interface faces, marked edges, corners.
fn tagged_cube() -> TetMesh {
    let mut mesh = load(&mesh_path("mmg_cube.mesh"));
    let ids: Vec<u32> = mesh.tet_ids().collect();
    for &t in &ids {
        mesh.set_region(t, (t % 3) as i32 - 1);
    }
    let mut faces: Vec<[u32; 3]> = mesh.face_markers().keys().copied().collect();
    faces.sort_unstable();
    for (i, f) in faces.iter().enumerate() {
        mesh.set_face_marker(*f, Some(i as i32 % 7 - 3));
    }
    // The interior faces of the first tet as interface markers.
    let t0 = ids[0];
    for f in 0..4 {
        if !mesh.is_boundary_face(t0, f) {
            mesh.set_face_marker(mesh.face_vertices(t0, f), Some(42));
        }
    }
    let mut edges: Vec<[u32; 2]> = mesh.feature_edges().keys().copied().collect();
    edges.sort_unstable();
    for (i, e) in edges.iter().enumerate() {
        mesh.set_feature_edge(e[0], e[1], Some(i as i32 % 5 + 100));
    }
    mesh.set_corner(mesh.tet(t0)[0], true);
    mesh
}

#[test]
fn tags_of_every_kind_and_sign_survive_every_writer() {
    let mesh = tagged_cube();
    let c = canon(&mesh);
    let t0 = mesh.tet_ids().next().unwrap();
    let interior = (0..4).filter(|&f| !mesh.is_boundary_face(t0, f)).count();
    assert!(interior > 0);
    assert_eq!(
        c.faces.len(),
        300 + interior,
        "the cube's 300 triangles and the interface faces"
    );
    assert!(c.faces.iter().any(|f| f.1 < 0) && c.tets.iter().any(|t| t.1 < 0));
    assert_eq!(c.edges.len(), 60);
    assert!(c.corners.len() >= 8);
    let dir = tempfile::tempdir().unwrap();
    round_trip("tagged_cube", &mesh, dir.path());
}

#[test]
fn binary_gmsh_files_written_by_gmsh_match_the_medit_original() {
    let original: Canon = canon(&load(&mesh_path("mmg_cube.mesh")));
    assert_eq!(original.faces.len(), 300);
    assert_eq!(original.edges.len(), 60);
    assert_eq!(original.corners.len(), 8);
    for name in ["mmg_cube_v41_binary.msh", "mmg_cube_v22_binary.msh"] {
        let path = crate::support::root().join("tests/data").join(name);
        let got = canon(&load(&path));
        if name.contains("v41") {
            assert!(got == original, "{name}: differs from meshes/mmg_cube.mesh");
        } else {
            // MSH 2.2 has no entities: Gmsh writes a physical tag 0 ("none" in
            // MSH 2.2) and the elementary tag (1) of each element, and the
            // elementary tag is what the reader then takes.
            let geometry = |c: &Canon| {
                (
                    c.tets.iter().map(|x| x.0).collect::<Vec<_>>(),
                    c.faces.iter().map(|x| x.0).collect::<Vec<_>>(),
                    c.edges.iter().map(|x| x.0).collect::<Vec<_>>(),
                    c.corners.clone(),
                )
            };
            assert!(
                geometry(&got) == geometry(&original),
                "{name}: differs from meshes/mmg_cube.mesh"
            );
            assert!(
                got.tets.iter().all(|t| t.1 == 1),
                "{name}: elementary tag 1"
            );
            assert!(got.faces.iter().all(|f| f.1 == 1));
            assert!(got.edges.iter().all(|e| e.1 == 1));
        }
    }
}

#[test]
fn vtu_files_in_every_layout_written_by_vtk_match_the_medit_original() {
    let original = load(&mesh_path("mmg_cube.mesh"));
    let data = crate::support::root().join("tests/data");
    for layout in [
        "ascii",
        "appended_raw",
        "appended_base64_zlib",
        "inline_raw",
    ] {
        let path = data.join(format!("mmg_cube_vtk_{layout}.vtu"));
        let (got, report) = load_mesh(&path).unwrap();
        assert_eq!(report.reoriented, 0, "{layout}");
        assert_eq!(got.points(), original.points(), "{layout}: points");
        assert!(
            canon(&got).tets == canon(&original).tets,
            "{layout}: tets differ"
        );
    }
}

/// Gmsh node tags need not be 1..n nor in order: a hand-written file in MSH
/// 2.2 and 4.1 with tags 50, 10, 40, 20, 30 (and a line, a triangle and a
/// point element with physical tags) reads as the mesh it describes.
#[test]
fn sparse_gmsh_node_tags_are_mapped() {
    let dir = tempfile::tempdir().unwrap();
    // tag -> point: 10 (0,0,0), 20 (1,0,0), 30 (0,1,0), 40 (0,0,1), 50 (1,1,1)
    let v22 = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n\
               50 1 1 1\n10 0 0 0\n40 0 0 1\n20 1 0 0\n30 0 1 0\n$EndNodes\n\
               $Elements\n5\n\
               7 15 2 5 1 10\n8 1 2 6 1 10 20\n9 2 2 7 1 10 20 30\n\
               100 4 2 3 1 10 20 30 40\n101 4 2 4 1 20 30 40 50\n$EndElements\n";
    let v41 = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n1 1 1 2\n\
               1 0 0 0 1 5\n1 0 0 0 1 0 0 1 6 0\n1 0 0 0 1 1 0 1 7 0\n1 0 0 0 1 1 1 1 3 0\n2 0 0 0 1 1 1 1 4 0\n$EndEntities\n\
               $Nodes\n2 5 10 50\n3 2 0 3\n50\n10\n40\n1 1 1\n0 0 0\n0 0 1\n3 2 0 2\n20\n30\n1 0 0\n0 1 0\n$EndNodes\n\
               $Elements\n5 5 7 101\n0 1 15 1\n7 10\n1 1 1 1\n8 10 20\n2 1 2 1\n9 10 20 30\n\
               3 1 4 1\n100 10 20 30 40\n3 2 4 1\n101 20 30 40 50\n$EndElements\n";
    let p = |x: f64, y: f64, z: f64| [x, y, z].map(f64::to_bits);
    let (a, b, c, d, e) = (
        p(0., 0., 0.),
        p(1., 0., 0.),
        p(0., 1., 0.),
        p(0., 0., 1.),
        p(1., 1., 1.),
    );
    let mut tets = vec![([a, b, c, d], 3), ([b, c, d, e], 4)];
    for (t, _) in tets.iter_mut() {
        t.sort_unstable();
    }
    tets.sort_unstable();
    for (name, text) in [("v22.msh", v22), ("v41.msh", v41)] {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        let got = canon(&load(&path));
        assert_eq!(got.tets, tets, "{name}");
        let mut abc = [a, b, c];
        abc.sort_unstable();
        assert_eq!(got.faces, vec![(abc, 7)], "{name}");
        let mut ab = [a, b];
        ab.sort_unstable();
        assert_eq!(got.edges, vec![(ab, 6)], "{name}");
        assert_eq!(got.corners, vec![a], "{name}");
    }
}
