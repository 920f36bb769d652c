//! Regions survive every format. The figures are those of meshes/README.md:
//! gmsh_t16 has six physical volumes sharing 590 faces, mmg_tinyBoxt two
//! regions (refs 2 and 3) sharing 302 faces, tetgen_example two regions
//! (attributes 10 and 20) sharing 534 faces; the .mesh, .msh and .vtu files of
//! one name hold the same mesh, and gmsh_t16_v41.msh (Gmsh's own MSH 4.1) the
//! same mesh as gmsh_t16.msh (meshio's MSH 2.2).

use crate::support::{canon, load, mesh_path, region_sizes};
use tetrefine::io::write_mesh;
use tetrefine::TetMesh;

/// Faces whose two tets lie in different regions.
fn interface_faces(mesh: &TetMesh) -> usize {
    let mut n = 0;
    for t in mesh.tet_ids() {
        for h in mesh.adj(t) {
            if h != tetrefine::NO_ADJ {
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

/// TetGen's own output for meshes/tetgen_example.poly (tests/data/README.md),
/// checked against the geometry of the .poly: region 10 is the prism under
/// the slanted facet (2 x 2, heights 4 and 3: volume 14) less the cavity
/// (1.5 x 1.25 x 0.5) and the notch (1.5 x 1.5 x 0.5), region 20 the rest of
/// the 2 x 2 x 5 box (volume 6); the facet markers cover the bottom (1, area
/// 4), top (2, area 4), outer walls (3, area 39.25: the front wall less the
/// notch's opening), the cavity and notch walls (4: 6.5 + 6.75) and the
/// slanted interface (9, area 2·√5).
#[test]
fn tetgen_native_output_has_the_regions_and_markers_of_its_poly() {
    let dir = crate::support::root().join("tests/data");
    let mesh = load(&dir.join("tetgen_example.1.ele"));
    // Any of the files names the same mesh.
    for ext in ["node", "face", "edge"] {
        let other = load(&dir.join(format!("tetgen_example.1.{ext}")));
        assert!(canon(&other) == canon(&mesh), "read through .{ext}");
    }
    let mut volume = std::collections::BTreeMap::new();
    for t in mesh.tet_ids() {
        let p = mesh.tet_points(t);
        let v = (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / 6.0;
        assert!(v > 0.0);
        *volume.entry(mesh.region(t)).or_insert(0.0) += v;
    }
    let expect = [(10, 14.0 - 1.5 * 1.25 * 0.5 - 1.5 * 1.5 * 0.5), (20, 6.0)];
    assert_eq!(volume.len(), 2);
    for (r, v) in expect {
        assert!(
            (volume[&r] - v).abs() < 1e-12,
            "region {r}: {} != {v}",
            volume[&r]
        );
    }
    let mut area = std::collections::BTreeMap::new();
    for (f, &m) in mesh.face_markers() {
        let [a, b, c] = f.map(|v| mesh.point(v));
        *area.entry(m).or_insert(0.0) += 0.5 * (b - a).cross(c - a).length();
    }
    let expect = [
        (1, 4.0),
        (2, 4.0),
        (3, 39.25),
        (4, 6.5 + 6.75),
        (9, 2.0 * 5f64.sqrt()),
    ];
    assert_eq!(area.len(), expect.len(), "{area:?}");
    for (m, a) in expect {
        assert!(
            (area[&m] - a).abs() < 1e-12,
            "marker {m}: {} != {a}",
            area[&m]
        );
    }
    // Every sharp boundary edge (its two boundary faces not coplanar) is one
    // of TetGen's segments in the .edge file.
    let mut normals: std::collections::HashMap<[u32; 2], Vec<glam::DVec3>> = Default::default();
    for t in mesh.tet_ids() {
        for f in 0..4 {
            if mesh.is_boundary_face(t, f) {
                let v = mesh.face_vertices(t, f);
                let [a, b, c] = v.map(|x| mesh.point(x));
                let n = (b - a).cross(c - a).normalize();
                for i in 0..3 {
                    let (x, y) = (v[i], v[(i + 1) % 3]);
                    normals.entry([x.min(y), x.max(y)]).or_default().push(n);
                }
            }
        }
    }
    let mut sharp = 0;
    for (e, n) in &normals {
        assert_eq!(n.len(), 2);
        if n[0].dot(n[1]) < 1.0 - 1e-12 {
            sharp += 1;
            assert!(
                mesh.is_feature_edge(e[0], e[1]),
                "sharp edge {e:?} not a feature"
            );
        }
    }
    assert!(sharp > 0);
}
