//! Surface readers (`.poly`, `.smesh`, `.off`, `.stl` ASCII and binary,
//! triangles-only Medit `.mesh`) and the volume a surface encloses. No TetGen
//! needed: these run in the default build.

use std::io::Write;
use std::path::{Path, PathBuf};
use tetrefine::io::{Facet, Plc, PlcError};

/// The unit cube's corners: point `i` has coordinates given by its bits.
fn cube_points() -> Vec<[f64; 3]> {
    (0..8)
        .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
        .collect()
}

/// The six faces of the unit cube, outward, 0-based.
const CUBE_QUADS: [[u32; 4]; 6] = [
    [0, 2, 3, 1],
    [4, 5, 7, 6],
    [0, 1, 5, 4],
    [2, 6, 7, 3],
    [0, 4, 6, 2],
    [1, 3, 7, 5],
];

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The cube as a 1-based `.poly` with facet markers 1..=6.
fn cube_poly() -> String {
    let mut s = String::from("# unit cube\n8 3 0 0\n");
    for (i, p) in cube_points().iter().enumerate() {
        s += &format!("{} {} {} {}\n", i + 1, p[0], p[1], p[2]);
    }
    s += "6 1\n";
    for (m, q) in CUBE_QUADS.iter().enumerate() {
        s += &format!(
            "1 0 {}\n4 {} {} {} {}\n",
            m + 1,
            q[0] + 1,
            q[1] + 1,
            q[2] + 1,
            q[3] + 1
        );
    }
    s + "0\n0\n"
}

fn cube_triangles() -> Vec<[u32; 3]> {
    CUBE_QUADS
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect()
}

fn assert_unit_volume(plc: &Plc) {
    let v = plc.enclosed_volume().unwrap();
    assert!((v - 1.0).abs() < 1e-12, "volume {v}");
}

#[test]
fn example_poly_encloses_its_closed_form_volume() {
    // TetGen's example: the box [0,2]² × [0,5], split by the slanted facet
    // through z = 4 - y/2 into two regions, minus the closed cavity
    // [0.25,1.75]×[0.25,1.5]×[0.5,1] and minus the notch
    // [0.25,1.75]×[0,1.5]×[2,2.5] that opens on the face y = 0; both are
    // emptied by hole seeds.
    let plc = Plc::read(&crate::support::path("meshes/tetgen_example.poly")).unwrap();
    assert_eq!(plc.points.len(), 28);
    assert_eq!(plc.facets.len(), 23);
    assert_eq!(plc.holes.len(), 2);
    assert_eq!(plc.regions.len(), 2);
    assert_eq!(plc.regions[0].attribute, 10);
    assert_eq!(plc.regions[1].attribute, 20);
    assert_eq!(plc.regions[0].max_volume, Some(0.001));
    assert_eq!(plc.facets[2].polygons.len(), 2);
    assert_eq!(plc.facets[2].holes, vec![[1.0, 0.0, 2.25]]);
    let expected = 2.0 * 2.0 * 5.0 - 1.5 * 1.25 * 0.5 - 1.5 * 1.5 * 0.5;
    let v = plc.analyze().unwrap();
    assert!(
        (v.enclosed - expected).abs() < 1e-12 * expected,
        "{v:?} vs {expected}"
    );
    // Two regions, the cavity and the notch.
    assert_eq!(v.cells, 4);
    assert_eq!(v.hole_cells, 2);
}

#[test]
fn cube_poly_with_markers() {
    let dir = tempfile::tempdir().unwrap();
    let plc = Plc::read(&write(dir.path(), "cube.poly", &cube_poly())).unwrap();
    let markers: Vec<i32> = plc.facets.iter().map(|f| f.marker).collect();
    assert_eq!(markers, vec![1, 2, 3, 4, 5, 6]);
    assert_eq!(plc.facets[0].polygons, vec![vec![0, 2, 3, 1]]);
    assert_unit_volume(&plc);
}

#[test]
fn cube_poly_zero_based_with_points_in_a_node_file() {
    let dir = tempfile::tempdir().unwrap();
    let mut node = String::from("8 3 0 0\n");
    for (i, p) in cube_points().iter().enumerate() {
        node += &format!("{i} {} {} {}\n", p[0], p[1], p[2]);
    }
    write(dir.path(), "cube.node", &node);
    let mut poly = String::from("0 3 0 0\n6 0\n");
    for q in CUBE_QUADS {
        poly += &format!("1\n4 {} {} {} {}\n", q[0], q[1], q[2], q[3]);
    }
    let plc = Plc::read(&write(dir.path(), "cube.poly", &poly)).unwrap();
    assert_eq!(plc.points.len(), 8);
    assert!(plc.facets.iter().all(|f| f.marker == 0));
    assert_unit_volume(&plc);
}

#[test]
fn cube_smesh() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = String::from("8 3 0 0\n");
    for (i, p) in cube_points().iter().enumerate() {
        s += &format!("{} {} {} {}\n", i + 1, p[0], p[1], p[2]);
    }
    s += "6 1\n";
    for (m, q) in CUBE_QUADS.iter().enumerate() {
        s += &format!(
            "4 {} {} {} {} {}\n",
            q[0] + 1,
            q[1] + 1,
            q[2] + 1,
            q[3] + 1,
            10 + m
        );
    }
    s += "0\n0\n";
    let plc = Plc::read(&write(dir.path(), "cube.smesh", &s)).unwrap();
    let markers: Vec<i32> = plc.facets.iter().map(|f| f.marker).collect();
    assert_eq!(markers, vec![10, 11, 12, 13, 14, 15]);
    assert_unit_volume(&plc);
}

#[test]
fn cube_off() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = String::from("OFF\n# a comment\n8 6 12\n");
    for p in cube_points() {
        s += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    for q in CUBE_QUADS {
        s += &format!("4 {} {} {} {} 255 0 0\n", q[0], q[1], q[2], q[3]);
    }
    let plc = Plc::read(&write(dir.path(), "cube.off", &s)).unwrap();
    assert_eq!((plc.points.len(), plc.facets.len()), (8, 6));
    assert_unit_volume(&plc);
}

#[test]
fn cube_stl_ascii_and_binary_merge_vertices() {
    let dir = tempfile::tempdir().unwrap();
    let pts = cube_points();
    let mut ascii = String::from("solid cube\n");
    let mut binary = vec![0u8; 80];
    binary.extend_from_slice(&12u32.to_le_bytes());
    for t in cube_triangles() {
        ascii += "  facet normal 0 0 0\n    outer loop\n";
        binary.extend_from_slice(&[0u8; 12]);
        for v in t {
            let p = pts[v as usize];
            ascii += &format!("      vertex {} {} {}\n", p[0], p[1], p[2]);
            for c in p {
                binary.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
        ascii += "    endloop\n  endfacet\n";
        binary.extend_from_slice(&[0u8; 2]);
    }
    ascii += "endsolid cube\n";
    let a = Plc::read(&write(dir.path(), "a.stl", &ascii)).unwrap();
    // A binary header that starts with "solid" must not fool the reader.
    binary[..5].copy_from_slice(b"solid");
    let bpath = dir.path().join("b.stl");
    std::fs::File::create(&bpath)
        .unwrap()
        .write_all(&binary)
        .unwrap();
    let b = Plc::read(&bpath).unwrap();
    for plc in [&a, &b] {
        assert_eq!(plc.points.len(), 8, "coincident vertices merged");
        assert_eq!(plc.facets.len(), 12);
        assert_unit_volume(plc);
    }
}

#[test]
fn cube_medit_triangles() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = String::from("MeshVersionFormatted 2\nDimension 3\nVertices\n8\n");
    for p in cube_points() {
        s += &format!("{} {} {} 0\n", p[0], p[1], p[2]);
    }
    s += "Triangles\n12\n";
    for (i, t) in cube_triangles().iter().enumerate() {
        s += &format!("{} {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1, i / 2 + 1);
    }
    s += "End\n";
    let plc = Plc::read(&write(dir.path(), "cube.mesh", &s)).unwrap();
    assert_eq!(plc.facets.len(), 12);
    assert_eq!(plc.facets[11].marker, 6);
    assert_unit_volume(&plc);
    // A volume mesh is not a surface to mesh.
    let e = Plc::read(&crate::support::path("meshes/mmg_cube.mesh")).unwrap_err();
    assert!(e.to_string().contains("Tetrahedra"), "{e}");
}

#[test]
fn reader_errors_name_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let nan = cube_poly().replacen("2 1 0 0", "2 nan 0 0", 1);
    let e = Plc::read(&write(dir.path(), "nan.poly", &nan)).unwrap_err();
    assert_eq!(e.line, Some(4), "{e}");
    assert!(e.to_string().contains("not a finite number"), "{e}");
    let bad = cube_poly().replacen("4 1 3 4 2", "4 1 3 4 9", 1);
    let e = Plc::read(&write(dir.path(), "index.poly", &bad)).unwrap_err();
    assert!(
        e.to_string()
            .contains("index.poly:13: point index 9 is out of range 1..=8"),
        "{e}"
    );
    let e = Plc::read(&write(dir.path(), "short.off", "OFF\n8 6 0\n0 0 0\n")).unwrap_err();
    assert!(e.to_string().contains("truncated"), "{e}");
    let e = Plc::read(&write(dir.path(), "junk.stl", "hello")).unwrap_err();
    assert!(e.to_string().contains("neither ASCII STL"), "{e}");
    let e = Plc::read(&write(dir.path(), "x.obj", "")).unwrap_err();
    assert!(e.to_string().contains("unknown surface extension"), "{e}");
}

#[test]
fn open_and_duplicated_surfaces_are_reported() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = String::from("OFF\n8 5 0\n");
    for p in cube_points() {
        s += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    for q in &CUBE_QUADS[..5] {
        s += &format!("4 {} {} {} {}\n", q[0], q[1], q[2], q[3]);
    }
    let plc = Plc::read(&write(dir.path(), "open.off", &s)).unwrap();
    assert!(matches!(plc.validate(), Err(PlcError::Open { .. })));
    let sixth = Facet {
        polygons: vec![CUBE_QUADS[5].to_vec()],
        holes: vec![],
        marker: 0,
    };
    let mut closed = plc.clone();
    closed.facets.push(sixth.clone());
    assert_unit_volume(&closed);
    closed.facets.push(sixth);
    assert_eq!(
        closed.validate(),
        Err(PlcError::DuplicateFacet { facet: 7, other: 6 })
    );
}

#[test]
fn the_one_off_reader_keeps_face_lines_and_skips_extras() {
    let dir = tempfile::tempdir().unwrap();
    // COFF: a colour after each vertex and face; a comment and a blank line.
    let text = "COFF\n# a tet\n4 2 6\n0 0 0 1 0 0 1\n1 0 0 1 0 0 1\n\n0 1 0 1 0 0 1\n0 0 1 1 0 0 1\n3 0 2 1 255 0 0\n4 0 1 3 2\n";
    let off = tetrefine::io::read_off(&write(dir.path(), "t.off", text)).unwrap();
    assert_eq!(
        off.points,
        [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0]
        ]
    );
    assert_eq!(off.faces, [vec![0, 2, 1], vec![0, 1, 3, 2]]);
    assert_eq!(off.face_lines, [9, 10]);
}
