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
    check_set(&data, &node_path, &face_path, &edge_path)?;
    Ok(data)
}

/// Refuses a set whose files do not belong together (a partly replaced
/// output, say): points of `.node` that no tet of `.ele` uses (TetGen
/// jettisons unused points, and tetrefine writes none), triangles of `.face`
/// that are not faces of a tet, edges of `.edge` that are not tet edges.
fn check_set(data: &MeshData, node: &Path, face: &Path, edge: &Path) -> Result<(), IoError> {
    use std::collections::HashSet;
    let mut used = vec![false; data.points.len()];
    for t in &data.tets {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let unused = used.iter().filter(|&&u| !u).count();
    if unused > 0 {
        let first = used.iter().position(|&u| !u).unwrap_or(0);
        return Err(IoError::file(
            node,
            format!(
                "{unused} of its {} points (the first is point {} in file order) belong to no tetrahedron of {}: the files of this TetGen set do not belong together",
                data.points.len(),
                first + 1,
                node.with_extension("ele").display()
            ),
        ));
    }
    let sorted3 = |mut f: [u32; 3]| {
        f.sort_unstable();
        f
    };
    if !data.triangles.is_empty() {
        let faces: HashSet<[u32; 3]> = data
            .tets
            .iter()
            .flat_map(|t| {
                [
                    [t[1], t[2], t[3]],
                    [t[0], t[2], t[3]],
                    [t[0], t[1], t[3]],
                    [t[0], t[1], t[2]],
                ]
            })
            .map(sorted3)
            .collect();
        if let Some(i) = data
            .triangles
            .iter()
            .position(|(f, _)| !faces.contains(&sorted3(*f)))
        {
            return Err(IoError::file(
                face,
                format!(
                    "face {} (in file order) is not a face of any tetrahedron of {}: the files of this TetGen set do not belong together",
                    i + 1,
                    node.with_extension("ele").display()
                ),
            ));
        }
    }
    if !data.edges.is_empty() {
        let key = |a: u32, b: u32| [a.min(b), a.max(b)];
        let edges: HashSet<[u32; 2]> = data
            .tets
            .iter()
            .flat_map(|t| {
                [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)].map(|(i, j)| key(t[i], t[j]))
            })
            .collect();
        if let Some(i) = data
            .edges
            .iter()
            .position(|(e, _)| !edges.contains(&key(e[0], e[1])))
        {
            return Err(IoError::file(
                edge,
                format!(
                    "edge {} (in file order) is not an edge of any tetrahedron of {}: the files of this TetGen set do not belong together",
                    i + 1,
                    node.with_extension("ele").display()
                ),
            ));
        }
    }
    Ok(())
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

/// Writes plain mesh data as TetGen files, as one set: the four files are
/// renamed into place only when all four were written (inside an open
/// [`super::OutputSet`], with the rest of its outputs), so a failure leaves
/// the old set whole. Points no tet uses are left out (a reader refuses a
/// set with unused points).
pub fn write_data(path: &Path, d: &MeshData) -> Result<(), IoError> {
    let mut owned;
    let d = if d
        .tets
        .iter()
        .flatten()
        .collect::<std::collections::HashSet<_>>()
        .len()
        < d.points.len()
    {
        owned = d.clone();
        drop_unused_points(&mut owned);
        &owned
    } else {
        d
    };
    let files = ["node", "ele", "face", "edge"].map(|e| sibling(path, e));
    let set = super::OutputSet::begin();
    let result = (|| {
        write_atomic(&files[0], |w| {
            writeln!(w, "# written by tetrefine\n{} 3 0 0", d.points.len())?;
            for (i, p) in d.points.iter().enumerate() {
                writeln!(w, "{} {:?} {:?} {:?}", i + 1, p[0], p[1], p[2])?;
            }
            Ok(())
        })?;
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
    match result {
        Ok(()) => set.commit(),
        Err(e) => Err(e), // dropping the set removes what was staged
    }
}
