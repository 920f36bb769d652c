//! TetGen `.node` / `.ele` / `.face` / `.edge` files (H. Si, "TetGen, a
//! Delaunay-based quality tetrahedral mesh generator", ACM TOMS 41(2), 2015;
//! file formats as in the TetGen 1.5 user manual).
//!
//! Read: any of the files may be named; its siblings are found by stem. `.node`
//! and `.ele` are required, `.face` and `.edge` are read when present. Indices
//! start at 0 or 1, whichever the first point of `.node` uses, and the other
//! files follow it; `#` starts a comment. The first element attribute of `.ele`
//! is the region; every triangle of `.face` becomes a marked face (its boundary
//! marker, or 0 when the file has none), every edge of `.edge` a feature edge
//! (note that `tetgen -e` lists *every* mesh edge). 10-node tets keep their
//! corners and the mid-edge points are dropped.
//!
//! Written: 1-based `.node`, `.ele` with the region as one attribute, `.face`
//! with the face markers and `.edge` with the feature edges (these two always,
//! possibly empty, so that stale siblings of the same stem cannot remain).
//! TetGen files have no place for corners or required vertices.

use super::text::{as_text, Records};
use super::{drop_unused_points, open_message, write_atomic, IoError};
use crate::mesh::{MeshData, TetMesh};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The sibling of `path` with extension `ext`.
fn sibling(path: &Path, ext: &str) -> PathBuf {
    path.with_extension(ext)
}

/// Reads a TetGen mesh given the path of its `.node`, `.ele`, `.face` or `.edge` file.
pub fn read(path: &Path) -> Result<MeshData, IoError> {
    let node_path = sibling(path, "node");
    let ele_path = sibling(path, "ele");
    let mut data = MeshData::default();
    let base = read_node(&node_path, &mut data)?;
    let quadratic = read_ele(&ele_path, base, &mut data)?;
    let face_path = sibling(path, "face");
    if face_path.exists() {
        read_face(&face_path, base, &mut data)?;
    }
    let edge_path = sibling(path, "edge");
    if edge_path.exists() {
        read_edge(&edge_path, base, &mut data)?;
    }
    if quadratic {
        drop_unused_points(&mut data);
    }
    Ok(data)
}

fn load(path: &Path) -> Result<Vec<u8>, IoError> {
    let bytes = std::fs::read(path).map_err(|e| {
        let mut m = open_message(&e);
        if e.kind() == std::io::ErrorKind::NotFound {
            m.push_str(" (a TetGen mesh needs both its .node and its .ele file)");
        }
        IoError::file(path, m)
    })?;
    if bytes.iter().all(|c| c.is_ascii_whitespace()) {
        return Err(IoError::file(path, "empty file"));
    }
    Ok(bytes)
}

/// An index of a point, with the file's first number `base`.
fn index(r: &Records, s: &str, base: u32, n: usize) -> Result<u32, IoError> {
    let i: i64 = r.parse(s, "a point index")?;
    let lo = base as i64;
    let hi = lo + n as i64 - 1;
    if i < lo || i > hi {
        return Err(r.error(format!("point index {i} is out of range {lo}..={hi}")));
    }
    Ok((i - lo) as u32)
}

/// Reads `.node`; returns the first index (0 or 1).
fn read_node(path: &Path, data: &mut MeshData) -> Result<u32, IoError> {
    let bytes = load(path)?;
    let text = as_text(path, &bytes)?;
    let max = text.len() / 8 + 1;
    let mut r = Records::new(path, text);
    let h = r.record("the .node header", 1)?;
    let n = r.count(h[0], "point count", max)?;
    let dim = match h.get(1) {
        Some(s) => r.parse::<i64>(s, "the dimension")?,
        None => 3,
    };
    if dim != 3 {
        return Err(r.error(format!("dimension {dim}: only 3-D meshes are supported")));
    }
    let n_attr = match h.get(2) {
        Some(s) => r.count(s, "attribute count", 1 << 16)?,
        None => 0,
    };
    let has_marker = match h.get(3) {
        Some(s) => r.count(s, "boundary marker flag", 1)?,
        None => 0,
    };
    let need = 4 + n_attr + has_marker;
    data.points.reserve(n);
    let mut base = 0;
    for i in 0..n {
        let f = r.record("a point", need)?;
        let id: i64 = r.parse(f[0], "a point index")?;
        if i == 0 {
            if id != 0 && id != 1 {
                return Err(r.error(format!(
                    "the first point is numbered {id}; TetGen numbers from 0 or 1"
                )));
            }
            base = id as u32;
        } else if id != base as i64 + i as i64 {
            return Err(r.error(format!(
                "point numbered {id} where {} was expected (points must be numbered consecutively)",
                base as i64 + i as i64
            )));
        }
        let x = r.coord(f[1], "an x coordinate")?;
        let y = r.coord(f[2], "a y coordinate")?;
        let z = r.coord(f[3], "a z coordinate")?;
        data.points.push([x, y, z]);
    }
    if n == 0 {
        return Err(r.error("the mesh has no points"));
    }
    if r.next_record().is_some() {
        return Err(r.error(format!("more points than the {n} announced in the header")));
    }
    Ok(base)
}

/// Reads `.ele`; returns whether the tets were quadratic (10 nodes).
fn read_ele(path: &Path, base: u32, data: &mut MeshData) -> Result<bool, IoError> {
    let bytes = load(path)?;
    let text = as_text(path, &bytes)?;
    let max = text.len() / 10 + 1;
    let mut r = Records::new(path, text);
    let h = r.record("the .ele header", 1)?;
    let n = r.count(h[0], "tetrahedron count", max)?;
    let per = match h.get(1) {
        Some(s) => r.parse::<i64>(s, "nodes per tetrahedron")?,
        None => 4,
    };
    if per != 4 && per != 10 {
        return Err(r.error(format!(
            "{per} nodes per tetrahedron: TetGen writes 4 or 10"
        )));
    }
    let n_attr = match h.get(2) {
        Some(s) => r.count(s, "attribute count", 1 << 16)?,
        None => 0,
    };
    let np = data.points.len();
    data.tets.reserve(n);
    for i in 0..n {
        let f = r.record("a tetrahedron", 1 + per as usize + n_attr)?;
        let id: i64 = r.parse(f[0], "a tetrahedron number")?;
        if id != base as i64 + i as i64 {
            return Err(r.error(format!(
                "tetrahedron numbered {id} where {} was expected",
                base as i64 + i as i64
            )));
        }
        let mut v = [0u32; 4];
        for (k, slot) in v.iter_mut().enumerate() {
            *slot = index(&r, f[1 + k], base, np)?;
        }
        for s in &f[5..1 + per as usize] {
            index(&r, s, base, np)?;
        }
        data.tets.push(v);
        data.tet_lines.push(r.line as u32);
        if n_attr > 0 {
            let a: f64 = r.parse(f[1 + per as usize], "a region attribute")?;
            if a.fract() != 0.0 || !(i32::MIN as f64..=i32::MAX as f64).contains(&a) {
                return Err(r.error(format!("region attribute {a} is not a 32-bit integer")));
            }
            data.tet_regions.push(a as i32);
        }
    }
    if n == 0 {
        return Err(r.error("no tetrahedra: not a volume mesh"));
    }
    if r.next_record().is_some() {
        return Err(r.error(format!(
            "more tetrahedra than the {n} announced in the header"
        )));
    }
    Ok(per == 10)
}

fn read_face(path: &Path, base: u32, data: &mut MeshData) -> Result<(), IoError> {
    let bytes = load(path)?;
    let text = as_text(path, &bytes)?;
    let mut r = Records::new(path, text);
    let h = r.record("the .face header", 1)?;
    let n = r.count(h[0], "face count", text.len() / 8 + 1)?;
    let has_marker = match h.get(1) {
        Some(s) => r.count(s, "boundary marker flag", 1)?,
        None => 0,
    };
    let np = data.points.len();
    for _ in 0..n {
        let f = r.record("a face", 4 + has_marker)?;
        let a = index(&r, f[1], base, np)?;
        let b = index(&r, f[2], base, np)?;
        let c = index(&r, f[3], base, np)?;
        let m = if has_marker == 1 {
            r.parse::<i32>(f[4], "a boundary marker")?
        } else {
            0
        };
        data.triangles.push(([a, b, c], m));
    }
    if r.next_record().is_some() {
        return Err(r.error(format!("more faces than the {n} announced in the header")));
    }
    Ok(())
}

fn read_edge(path: &Path, base: u32, data: &mut MeshData) -> Result<(), IoError> {
    let bytes = load(path)?;
    let text = as_text(path, &bytes)?;
    let mut r = Records::new(path, text);
    let h = r.record("the .edge header", 1)?;
    let n = r.count(h[0], "edge count", text.len() / 6 + 1)?;
    let has_marker = match h.get(1) {
        Some(s) => r.count(s, "boundary marker flag", 1)?,
        None => 0,
    };
    let np = data.points.len();
    for _ in 0..n {
        let f = r.record("an edge", 3 + has_marker)?;
        let a = index(&r, f[1], base, np)?;
        let b = index(&r, f[2], base, np)?;
        let m = if has_marker == 1 {
            r.parse::<i32>(f[3], "a boundary marker")?
        } else {
            0
        };
        data.edges.push(([a, b], m));
    }
    if r.next_record().is_some() {
        return Err(r.error(format!("more edges than the {n} announced in the header")));
    }
    Ok(())
}

/// Writes `mesh` as TetGen `.node`, `.ele`, `.face` and `.edge` files beside
/// `path` (whose extension is replaced).
pub fn write(path: &Path, mesh: &TetMesh) -> Result<(), IoError> {
    write_data(path, &mesh.to_data())
}

/// Writes plain mesh data as TetGen files; if one of them cannot be written,
/// those already written are removed again.
pub fn write_data(path: &Path, d: &MeshData) -> Result<(), IoError> {
    let files = ["node", "ele", "face", "edge"].map(|e| sibling(path, e));
    let mut written = 0;
    let result = (|| {
        write_atomic(&files[0], |w| {
            writeln!(w, "# written by tetrefine\n{} 3 0 0", d.points.len())?;
            for (i, p) in d.points.iter().enumerate() {
                writeln!(w, "{} {:?} {:?} {:?}", i + 1, p[0], p[1], p[2])?;
            }
            Ok(())
        })?;
        written = 1;
        write_atomic(&files[1], |w| {
            writeln!(
                w,
                "# written by tetrefine; the attribute is the region\n{} 4 1",
                d.tets.len()
            )?;
            for (t, v) in d.tets.iter().enumerate() {
                writeln!(
                    w,
                    "{} {} {} {} {} {}",
                    t + 1,
                    v[0] + 1,
                    v[1] + 1,
                    v[2] + 1,
                    v[3] + 1,
                    d.region(t)
                )?;
            }
            Ok(())
        })?;
        written = 2;
        write_atomic(&files[2], |w| {
            writeln!(
                w,
                "# written by tetrefine: marked faces\n{} 1",
                d.triangles.len()
            )?;
            for (i, (f, m)) in d.triangles.iter().enumerate() {
                writeln!(w, "{} {} {} {} {}", i + 1, f[0] + 1, f[1] + 1, f[2] + 1, m)?;
            }
            Ok(())
        })?;
        written = 3;
        write_atomic(&files[3], |w| {
            writeln!(
                w,
                "# written by tetrefine: feature edges\n{} 1",
                d.edges.len()
            )?;
            for (i, (e, m)) in d.edges.iter().enumerate() {
                writeln!(w, "{} {} {} {}", i + 1, e[0] + 1, e[1] + 1, m)?;
            }
            Ok(())
        })
    })();
    if result.is_err() {
        for f in &files[..written] {
            let _ = std::fs::remove_file(f);
        }
    }
    result
}
