//! Surface readers and writers: exact round trips, the XML and legacy VTK
//! files parsed back, and malformed files rejected with file and line.

use crate::shapes::*;
use glam::DVec3;
use std::path::Path;
use tetrefine_surface::{load_surface, read_surface, write_surface, PolyMesh};

/// A mesh with awkward coordinates and mixed face sizes.
fn sample() -> PolyMesh {
    let mut m = cube();
    for (i, p) in m.points.iter_mut().enumerate() {
        *p += DVec3::new(0.1 * i as f64, 1e-17 * i as f64, -(1.0 / 3.0) * i as f64);
    }
    // Split the top quad into two triangles to mix sizes.
    let top = m.faces.remove(1);
    m.faces.push(vec![top[0], top[1], top[2]]);
    m.faces.push(vec![top[0], top[2], top[3]]);
    m
}

#[test]
fn obj_off_ply_round_trips_are_exact() {
    let dir = tempfile::tempdir().unwrap();
    let m = sample();
    for ext in ["obj", "off", "ply"] {
        let path = dir.path().join(format!("m.{ext}"));
        write_surface(&path, &m).unwrap();
        let back = load_surface(&path).unwrap();
        assert_eq!(back, m, "{ext}");
    }
}

fn numbers_between(text: &str, open: &str, close: &str) -> Vec<f64> {
    let start = text.find(open).unwrap() + open.len();
    let rest = &text[start..];
    let rest = &rest[rest.find('>').unwrap() + 1..];
    let end = rest.find(close).unwrap();
    rest[..end]
        .split_whitespace()
        .map(|t| t.parse().unwrap())
        .collect()
}

#[test]
fn vtp_and_legacy_vtk_hold_the_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let m = sample();
    let vtp = dir.path().join("m.vtp");
    write_surface(&vtp, &m).unwrap();
    let text = std::fs::read_to_string(&vtp).unwrap();
    assert!(text.contains(&format!("NumberOfPoints=\"{}\"", m.points.len())));
    assert!(text.contains(&format!("NumberOfPolys=\"{}\"", m.faces.len())));
    let pts = numbers_between(&text, "Name=\"Points\"", "</DataArray>");
    let flat: Vec<f64> = m.points.iter().flat_map(|p| p.to_array()).collect();
    assert_eq!(pts, flat);
    let conn = numbers_between(&text, "Name=\"connectivity\"", "</DataArray>");
    let offs = numbers_between(&text, "Name=\"offsets\"", "</DataArray>");
    let mut start = 0usize;
    for (f, end) in m.faces.iter().zip(&offs) {
        let end = *end as usize;
        let face: Vec<u32> = conn[start..end].iter().map(|&x| x as u32).collect();
        assert_eq!(&face, f);
        start = end;
    }

    let vtk = dir.path().join("m.vtk");
    write_surface(&vtk, &m).unwrap();
    let text = std::fs::read_to_string(&vtk).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "# vtk DataFile Version 3.0");
    assert_eq!(lines[3], "DATASET POLYDATA");
    assert_eq!(lines[4], format!("POINTS {} double", m.points.len()));
    let size: usize = m.faces.iter().map(|f| f.len() + 1).sum();
    let poly = lines
        .iter()
        .position(|l| l.starts_with("POLYGONS"))
        .unwrap();
    assert_eq!(lines[poly], format!("POLYGONS {} {}", m.faces.len(), size));
    for (k, f) in m.faces.iter().enumerate() {
        let nums: Vec<u32> = lines[poly + 1 + k]
            .split_whitespace()
            .map(|t| t.parse().unwrap())
            .collect();
        assert_eq!(nums[0] as usize, f.len());
        assert_eq!(&nums[1..], &f[..]);
    }
}

#[test]
fn obj_reader_accepts_the_common_forms() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("forms.obj");
    std::fs::write(
        &path,
        "# comment\nmtllib x.mtl\no thing\nv 0 0 0\nv 2 0 0 2\nv 0 1 0\nvt 0 0\nvn 0 0 1\ng a\nusemtl m\ns off\nf 1/1/1 2/1/1 3//1\nv 1 1 0\nf -3 -1 -2\n",
    )
    .unwrap();
    let m = load_surface(&path).unwrap();
    assert_eq!(m.points[1], DVec3::X); // homogeneous w = 2
    assert_eq!(m.faces, vec![vec![0, 1, 2], vec![1, 3, 2]]);
}

fn err(path: &Path, text: &str) -> String {
    std::fs::write(path, text).unwrap();
    load_surface(path).unwrap_err().to_string()
}

#[test]
fn malformed_files_give_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("bad.obj");
    let name = obj.display().to_string();
    let e = err(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
    assert!(
        e.starts_with(&format!("{name}:4:")) && e.contains("vertex 4"),
        "{e}"
    );
    let e = err(&obj, "v 0 0 0\nv 1 zero 0\n");
    assert!(
        e.starts_with(&format!("{name}:2:")) && e.contains("'zero'"),
        "{e}"
    );
    let e = err(&obj, "v 0 0 0\nv 1 0 0\nf 1 2\n");
    assert!(
        e.starts_with(&format!("{name}:3:")) && e.contains("at least 3"),
        "{e}"
    );
    let e = err(&obj, "v 0 0 0\nbogus 1\n");
    assert!(
        e.starts_with(&format!("{name}:2:")) && e.contains("bogus"),
        "{e}"
    );
    // Topology: the line of the second face running along the same edge.
    let e = err(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nf 1 2 3\n\nf 1 2 4\n",
    );
    assert!(
        e.starts_with(&format!("{name}:7:")) && e.contains("orientations disagree"),
        "{e}"
    );

    let off = dir.path().join("bad.off");
    let name = off.display().to_string();
    let e = err(&off, "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n");
    assert!(
        e.starts_with(&format!("{name}:")) && e.contains("truncated"),
        "{e}"
    );
    let e = err(&off, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
    assert!(
        e.starts_with(&format!("{name}:6:")) && e.contains("out of range"),
        "{e}"
    );
    let e = err(&off, "PLY\n");
    assert!(
        e.starts_with(&format!("{name}:1:")) && e.contains("OFF"),
        "{e}"
    );

    let ply = dir.path().join("bad.ply");
    let name = ply.display().to_string();
    let e = err(&ply, "ply\nformat binary_middle_endian 1.0\nend_header\n");
    assert!(
        e.starts_with(&format!("{name}:2:")) && e.contains("unknown PLY format"),
        "{e}"
    );
    let e = err(
        &ply,
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0\n1 0\n0 1\n3 0 1 2\n",
    );
    assert!(
        e.starts_with(&format!("{name}:3:")) && e.contains("x, y, z"),
        "{e}"
    );
    let e = err(
        &ply,
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
    );
    assert!(
        e.starts_with(&format!("{name}:13:")) && e.contains("out of range"),
        "{e}"
    );

    let missing = dir.path().join("nope.obj");
    let e = read_surface(&missing).unwrap_err().to_string();
    assert!(e.contains("no such file"), "{e}");
    let e = read_surface(&dir.path().join("x.3ds"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("'.3ds'"), "{e}");
}

#[test]
fn ply_skips_extra_properties_and_elements() {
    let dir = tempfile::tempdir().unwrap();
    let ply = dir.path().join("extra.ply");
    std::fs::write(
        &ply,
        "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nelement face 1\nproperty list uchar int vertex_index\nproperty float quality\nelement edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n0 0 0 255\n1 0 0 0\n0 1 0 7\n3 0 1 2 0.5\n0 1\n",
    )
    .unwrap();
    let m = load_surface(&ply).unwrap();
    assert_eq!(m.points.len(), 3);
    assert_eq!(m.faces, vec![vec![0, 1, 2]]);
}

#[test]
fn failed_writes_leave_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("no_such_dir").join("m.obj");
    let e = write_surface(&path, &sample()).unwrap_err();
    assert!(e.to_string().contains("cannot write"), "{e}");
    assert!(!path.exists());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}
