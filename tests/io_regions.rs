//! Regions survive every format. The figures are those of meshes/README.md:
//! gmsh_t16 has six physical volumes sharing 590 faces, mmg_tinyBoxt two
//! regions (refs 2 and 3) sharing 302 faces, tetgen_example two regions
//! (attributes 10 and 20) sharing 534 faces; the .mesh, .msh and .vtu files of
//! one name hold the same mesh, and gmsh_t16_v41.msh (Gmsh's own MSH 4.1) the
//! same mesh as gmsh_t16.msh (meshio's MSH 2.2).

mod common;

use common::{canon, load, mesh_path, region_sizes};
use tetrefine::io::write_mesh;
use tetrefine::TetMesh;

/// Faces whose two tets lie in different regions.
fn interface_faces(mesh: &TetMesh) -> usize {
    let mut n = 0;
    for t in mesh.tet_ids() {
        for h in mesh.adj(t) {
            if h != tetrefine::mesh::NO_ADJ {
                let u = h >> 2;
                if u > t && mesh.region(u) != mesh.region(t) {
                    n += 1;
                }
            }
        }
    }
    n
}

fn regions_of(name: &str, n_regions: usize, ids: Option<&[i32]>, interfaces: usize) {
    let dir = tempfile::tempdir().unwrap();
    let reference = load(&mesh_path(&format!("{name}.mesh")));
    let sizes = region_sizes(&reference);
    assert_eq!(sizes.len(), n_regions, "{name}: regions {sizes:?}");
    if let Some(ids) = ids {
        assert_eq!(sizes.iter().map(|s| s.0).collect::<Vec<_>>(), ids, "{name}");
    }
    assert_eq!(
        interface_faces(&reference),
        interfaces,
        "{name}: interface faces"
    );
    let reference_tets = canon(&reference).tets;
    let mut files: Vec<std::path::PathBuf> = ["msh", "vtu"]
        .iter()
        .map(|e| mesh_path(&format!("{name}.{e}")))
        .collect();
    for ext in ["mesh", "msh", "vtu", "node"] {
        let out = dir.path().join(format!("{name}.{ext}"));
        write_mesh(&out, &reference).unwrap();
        files.push(out);
    }
    for f in &files {
        let mesh = load(f);
        assert_eq!(region_sizes(&mesh), sizes, "{}", f.display());
        assert_eq!(interface_faces(&mesh), interfaces, "{}", f.display());
        assert!(
            canon(&mesh).tets == reference_tets,
            "{}: tets or regions differ",
            f.display()
        );
    }
}

#[test]
fn gmsh_t16_six_regions_survive_every_format() {
    regions_of("gmsh_t16", 6, None, 590);
}

#[test]
fn mmg_tiny_box_two_regions_survive_every_format() {
    regions_of("mmg_tinyBoxt", 2, Some(&[2, 3]), 302);
}

#[test]
fn tetgen_example_two_regions_survive_every_format() {
    regions_of("tetgen_example", 2, Some(&[10, 20]), 534);
}

#[test]
fn gmsh_native_41_agrees_with_meshio_22() {
    let native = load(&mesh_path("gmsh_t16_v41.msh"));
    let meshio = load(&mesh_path("gmsh_t16.msh"));
    assert_eq!(native.n_tets(), 15_078);
    assert_eq!(native.points().len(), 3_099);
    assert_eq!(region_sizes(&native).len(), 6);
    assert_eq!(region_sizes(&native), region_sizes(&meshio));
    assert!(
        canon(&native) == canon(&meshio),
        "tets, regions or tags differ"
    );
}
