//! STL (ASCII, binary) and binary PLY, and the per-face attributes in
//! `.ply`, `.vtp` and `.vtk`: every file is parsed back here by a reader
//! written for the test (byte offsets from the format specifications), or
//! by vtkio, not by the crate's own readers; the crate's readers are then
//! checked against the written mesh.

use crate::shapes::*;
use glam::DVec3;
use std::path::Path;
use tetrefine_surface::{
    load_surface, read_surface, write_surface_with, Encoding, FaceAttributes, PolyMesh,
    WriteOptions,
};

/// A cube with awkward coordinates, its top split into two triangles: five
/// quads and two triangles.
fn mixed() -> PolyMesh {
    let mut m = cube();
    for (i, p) in m.points.iter_mut().enumerate() {
        *p += DVec3::new(0.1 * i as f64, 1e-17 * i as f64, -(1.0 / 3.0) * i as f64);
    }
    let top = m.faces.remove(1);
    m.faces.push(vec![top[0], top[1], top[2]]);
    m.faces.push(vec![top[0], top[2], top[3]]);
    m
}

fn ascii() -> WriteOptions<'static> {
    WriteOptions {
        encoding: Encoding::Ascii,
        attributes: None,
    }
}

fn f32s(rec: &[u8]) -> Vec<f32> {
    rec.chunks(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

/// The fan triangles of the mesh, computed here: (v0, vk, vk+1).
fn fans(m: &PolyMesh) -> Vec<[DVec3; 3]> {
    let mut out = Vec::new();
    for f in &m.faces {
        for k in 1..f.len() - 1 {
            out.push([f[0], f[k], f[k + 1]].map(|v| m.points[v as usize]));
        }
    }
    out
}

#[test]
fn binary_stl_has_84_plus_50_bytes_per_fan_triangle() {
    let dir = tempfile::tempdir().unwrap();
    let m = mixed();
    // 5 quads (2 triangles each) + 2 triangles.
    let tris = fans(&m);
    assert_eq!(tris.len(), 5 * 2 + 2);
    let path = dir.path().join("m.stl");
    write_surface_with(&path, &m, &WriteOptions::default()).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(bytes.len(), 84 + 50 * tris.len());
    assert!(!bytes.starts_with(b"solid"));
    let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]);
    assert_eq!(n as usize, tris.len());
    for (t, tri) in tris.iter().enumerate() {
        let rec = &bytes[84 + 50 * t..84 + 50 * (t + 1)];
        let v = f32s(&rec[..48]);
        for (c, p) in tri.iter().enumerate() {
            let want = [p.x as f32, p.y as f32, p.z as f32];
            assert_eq!(&v[3 + 3 * c..6 + 3 * c], &want, "triangle {t} vertex {c}");
        }
        // The normal: unit, perpendicular to the triangle, on the side of
        // the outward cross product.
        let nrm = DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
        let cross = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
        assert!((nrm.length() - 1.0).abs() < 1e-6, "triangle {t}");
        assert!(nrm.dot(cross.normalize()) > 1.0 - 1e-6, "triangle {t}");
        assert_eq!(&rec[48..50], &[0, 0]);
    }
    // Read back: the bitwise-equal f32 corners merge into the 8 cube
    // corners, 12 triangles, a closed surface (χ = 2).
    let back = load_surface(&path).unwrap();
    assert_eq!(back.points.len(), 8);
    assert_eq!(back.faces.len(), 12);
    assert_eq!(back.euler_characteristic(), 2);
    for p in &back.points {
        assert!(m
            .points
            .iter()
            .any(|q| (q.as_vec3().as_dvec3() - *p).length() == 0.0));
    }
}

#[test]
fn ascii_stl_is_parsed_back_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let m = mixed();
    let path = dir.path().join("m.stl");
    write_surface_with(&path, &m, &ascii()).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    // An independent parse: the words of the STL grammar, in order.
    let mut tok = text.split_whitespace();
    assert_eq!(tok.next(), Some("solid"));
    assert_eq!(tok.next(), Some("tetrefine"));
    let mut got: Vec<[DVec3; 3]> = Vec::new();
    loop {
        match tok.next() {
            Some("facet") => {}
            Some("endsolid") => break,
            other => panic!("unexpected {other:?}"),
        }
        assert_eq!(tok.next(), Some("normal"));
        let mut num = || tok.next().unwrap().parse::<f64>().unwrap();
        let nrm = DVec3::new(num(), num(), num());
        assert_eq!(tok.next(), Some("outer"));
        assert_eq!(tok.next(), Some("loop"));
        let mut tri = [DVec3::ZERO; 3];
        for p in &mut tri {
            assert_eq!(tok.next(), Some("vertex"));
            let mut num = || tok.next().unwrap().parse::<f64>().unwrap();
            *p = DVec3::new(num(), num(), num());
        }
        assert_eq!(tok.next(), Some("endloop"));
        assert_eq!(tok.next(), Some("endfacet"));
        let cross = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
        assert!((nrm - cross.normalize()).length() < 1e-12);
        got.push(tri);
    }
    assert_eq!(got, fans(&m), "ASCII STL coordinates are exact");
    let back = load_surface(&path).unwrap();
    assert_eq!(back.points.len(), 8);
    assert_eq!(back.faces.len(), 12);
    for p in &back.points {
        assert!(m.points.contains(p));
    }
}

#[test]
fn truncated_stl_files_are_refused_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let m = icosahedron();
    let bin = dir.path().join("ico.stl");
    write_surface_with(&bin, &m, &WriteOptions::default()).unwrap();
    let bytes = std::fs::read(&bin).unwrap();
    std::fs::write(&bin, &bytes[..bytes.len() - 30]).unwrap();
    let e = read_surface(&bin).unwrap_err().to_string();
    assert!(e.starts_with(&bin.display().to_string()), "{e}");
    assert!(e.contains("20 triangles need 1084 bytes"), "{e}");

    let asc = dir.path().join("ico-ascii.stl");
    write_surface_with(&asc, &m, &ascii()).unwrap();
    let text = std::fs::read_to_string(&asc).unwrap();
    // Cut after the sixth "outer loop": the file ends before a vertex.
    let (at, word) = text.match_indices("outer loop\n").nth(5).unwrap();
    std::fs::write(&asc, &text[..at + word.len()]).unwrap();
    let e = read_surface(&asc).unwrap_err().to_string();
    assert!(e.starts_with(&asc.display().to_string()), "{e}");
    assert!(e.contains("'vertex' was expected (truncated?)"), "{e}");
}

/// An independent binary little-endian PLY parse: the header lines, then
/// doubles x y z per vertex and per face a uchar count, int ids and (when
/// the header has them) three uint properties.
fn parse_binary_ply(bytes: &[u8]) -> (Vec<String>, PolyMesh, Vec<[u32; 3]>) {
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let header: Vec<String> = std::str::from_utf8(&bytes[..end])
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect();
    let count = |el: &str| -> usize {
        header
            .iter()
            .find_map(|l| l.strip_prefix(&format!("element {el} ")))
            .unwrap()
            .parse()
            .unwrap()
    };
    let (nv, nf) = (count("vertex"), count("face"));
    let with_attrs = header.iter().any(|l| l == "property uint generation");
    let mut pos = end;
    let mut take = |n: usize| {
        let s = &bytes[pos..pos + n];
        pos += n;
        s
    };
    let mut m = PolyMesh::default();
    for _ in 0..nv {
        let c: Vec<f64> = take(24)
            .chunks(8)
            .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
            .collect();
        m.points.push(DVec3::new(c[0], c[1], c[2]));
    }
    let mut attrs = Vec::new();
    for _ in 0..nf {
        let n = take(1)[0] as usize;
        let f: Vec<u32> = take(4 * n)
            .chunks(4)
            .map(|b| i32::from_le_bytes(b.try_into().unwrap()) as u32)
            .collect();
        m.faces.push(f);
        if with_attrs {
            let a: Vec<u32> = take(12)
                .chunks(4)
                .map(|b| u32::from_le_bytes(b.try_into().unwrap()))
                .collect();
            attrs.push([a[0], a[1], a[2]]);
        }
    }
    assert_eq!(pos, bytes.len(), "no bytes after the faces");
    (header, m, attrs)
}

/// Attributes with distinct values per face.
fn sample_attributes(m: &PolyMesh) -> FaceAttributes {
    let n = m.faces.len() as u32;
    FaceAttributes {
        generation: (0..n).map(|i| i % 3).collect(),
        origin: (0..n).map(|i| n - 1 - i).collect(),
        group: (0..n).map(|i| 100 + i).collect(),
    }
}

#[test]
fn binary_ply_holds_the_mesh_and_the_attributes() {
    let dir = tempfile::tempdir().unwrap();
    let m = mixed();
    let a = sample_attributes(&m);
    let path = dir.path().join("m.ply");
    let opts = WriteOptions {
        encoding: Encoding::Binary,
        attributes: Some(&a),
    };
    write_surface_with(&path, &m, &opts).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let (header, parsed, attrs) = parse_binary_ply(&bytes);
    assert_eq!(header[1], "format binary_little_endian 1.0");
    assert_eq!(parsed, m);
    for (i, got) in attrs.iter().enumerate() {
        assert_eq!(*got, [a.generation[i], a.origin[i], a.group[i]]);
    }
    // The crate's reader: the same mesh, exactly.
    assert_eq!(load_surface(&path).unwrap(), m);
    // Without attributes: 24 bytes per vertex, 1 + 4n per face.
    write_surface_with(&path, &m, &WriteOptions::default()).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let (header, parsed, attrs) = parse_binary_ply(&bytes);
    let head: usize = header.iter().map(|l| l.len() + 1).sum();
    let faces: usize = m.faces.iter().map(|f| 1 + 4 * f.len()).sum();
    assert_eq!(bytes.len(), head + 24 * m.points.len() + faces);
    assert_eq!(parsed, m);
    assert!(attrs.is_empty());
}

#[test]
fn ascii_ply_carries_the_attributes_after_each_face() {
    let dir = tempfile::tempdir().unwrap();
    let m = mixed();
    let a = sample_attributes(&m);
    let path = dir.path().join("m.ply");
    let opts = WriteOptions {
        encoding: Encoding::Ascii,
        attributes: Some(&a),
    };
    write_surface_with(&path, &m, &opts).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let end = lines.iter().position(|l| *l == "end_header").unwrap();
    let faces = &lines[end + 1 + m.points.len()..];
    assert_eq!(faces.len(), m.faces.len());
    for (i, (l, f)) in faces.iter().zip(&m.faces).enumerate() {
        let nums: Vec<u32> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
        assert_eq!(nums[0] as usize, f.len());
        assert_eq!(&nums[1..=f.len()], &f[..]);
        assert_eq!(
            &nums[f.len() + 1..],
            &[a.generation[i], a.origin[i], a.group[i]]
        );
    }
    assert_eq!(load_surface(&path).unwrap(), m);
}

fn write_bytes(path: &Path, header: &str, body: &[u8]) {
    let mut b = header.as_bytes().to_vec();
    b.extend_from_slice(body);
    std::fs::write(path, b).unwrap();
}

#[test]
fn big_endian_and_truncated_binary_ply() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("be.ply");
    let header = "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n";
    let mut body = Vec::new();
    for p in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.5, 0.0]] {
        for x in p {
            body.extend_from_slice(&x.to_be_bytes());
        }
        body.push(7);
    }
    body.push(3);
    for v in [0u32, 1, 2] {
        body.extend_from_slice(&v.to_be_bytes());
    }
    write_bytes(&path, header, &body);
    let m = read_surface(&path).unwrap().mesh;
    assert_eq!(m.points[2], DVec3::new(0.0, 2.5, 0.0));
    assert_eq!(m.faces, vec![vec![0, 1, 2]]);
    // An element without properties holds no bytes, whatever its count.
    let empty = header.replace(
        "element vertex 3",
        "element nothing 1000000000000\nelement vertex 3",
    );
    write_bytes(&path, &empty, &body);
    assert_eq!(read_surface(&path).unwrap().mesh, m);
    // Cut inside the face: the file and how far it got are named.
    write_bytes(&path, header, &body[..body.len() - 2]);
    let e = read_surface(&path).unwrap_err().to_string();
    assert!(e.starts_with(&path.display().to_string()), "{e}");
    assert!(e.contains("0 of 1 'face' entries (truncated?)"), "{e}");
    // Cut inside the vertices.
    write_bytes(&path, header, &body[..20]);
    let e = read_surface(&path).unwrap_err().to_string();
    assert!(e.contains("1 of 3 'vertex' entries"), "{e}");
    // A vertex id out of range, in binary: the entry is named.
    let mut bad = body.clone();
    let n = bad.len();
    bad[n - 4..].copy_from_slice(&9u32.to_be_bytes());
    write_bytes(&path, header, &bad);
    let e = read_surface(&path).unwrap_err().to_string();
    assert!(
        e.contains("'face' entry 0") && e.contains("out of range"),
        "{e}"
    );
}

#[test]
fn vtp_and_vtk_carry_the_attributes_as_cell_data() {
    let dir = tempfile::tempdir().unwrap();
    let m = mixed();
    let a = sample_attributes(&m);
    let opts = WriteOptions {
        encoding: Encoding::Binary,
        attributes: Some(&a),
    };
    for ext in ["vtp", "vtk"] {
        let path = dir.path().join(format!("m.{ext}"));
        write_surface_with(&path, &m, &opts).unwrap();
        let vtk = vtkio::Vtk::import(&path).unwrap_or_else(|e| panic!("{ext}: {e}"));
        let piece = match vtk.data {
            vtkio::model::DataSet::PolyData { pieces, .. } => match pieces.into_iter().next() {
                Some(vtkio::model::Piece::Inline(p)) => *p,
                _ => panic!("inline piece expected"),
            },
            _ => panic!("PolyData expected"),
        };
        assert_eq!(piece.num_points(), m.points.len(), "{ext}");
        let mut found = 0;
        for attr in &piece.data.cell {
            let vtkio::model::Attribute::DataArray(arr) = attr else {
                panic!("{ext}: a data array expected")
            };
            let values: Vec<u32> = arr.data.clone().cast_into().expect("u32 values");
            let want = match arr.name.as_str() {
                "generation" => &a.generation,
                "origin" => &a.origin,
                "group" => &a.group,
                other => panic!("{ext}: unexpected array {other}"),
            };
            assert_eq!(&values, want, "{ext}: {}", arr.name);
            found += 1;
        }
        assert_eq!(found, 3, "{ext}");
    }
    // Attributes of the wrong length are refused before anything is written.
    let short = FaceAttributes::input(3);
    let path = dir.path().join("short.vtp");
    let e = write_surface_with(
        &path,
        &m,
        &WriteOptions {
            encoding: Encoding::Binary,
            attributes: Some(&short),
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("the mesh has 7"), "{e}");
    assert!(!path.exists());
}
