//! Every writer's output, read back, is the same mesh: the same points in the
//! same order, the same tets (none turned around on reading, so vertex order is
//! kept up to an even permutation), regions, face markers, feature edges and
//! corners — as far as the format can carry them (TetGen files have no
//! corners; a .vtu carries tets and regions only).

mod common;

use common::{canon, load, mesh_path, Canon};
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
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name);
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
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
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
