//! GiD ASCII `.msh` (the mesh format of CIMNE's GiD pre/post-processor, also
//! written by getfem): blocks headed `MESH dimension 3 ElemType Tetrahedra
//! Nnode 4|10`, each with optional `Coordinates … end coordinates` and
//! `Elements … end elements` sections; `#` starts a comment.
//!
//! Read only. Node numbers are global and may be sparse. Tetrahedra with 4 or
//! 10 nodes keep their 4 corner nodes; an element line with one field more
//! than its nodes carries a material number, which becomes the region. Blocks
//! of other element types are skipped. Points that no tet uses (the mid-edge
//! nodes of quadratic tets) are dropped and the rest renumbered densely in file
//! order.

use super::text::{as_text, Records};
use super::{drop_unused_points, read_bytes, IoError};
use crate::mesh::MeshData;
use std::collections::HashMap;
use std::path::Path;

#[derive(Clone, Copy, PartialEq)]
enum Section {
    None,
    Coordinates,
    Elements,
}

/// Reads a GiD `.msh` file.
pub fn read(path: &Path) -> Result<MeshData, IoError> {
    let bytes = read_bytes(path)?;
    let text = as_text(path, &bytes)?;
    let mut r = Records::new(path, text);
    let mut data = MeshData::default();
    let mut ids: HashMap<i64, u32> = HashMap::new();
    // Element lines name nodes by id; they are resolved at the end, since GiD
    // allows coordinates in a later block than the elements that use them.
    let mut raw_tets: Vec<([i64; 4], u32)> = Vec::new();
    let mut regions: Vec<i32> = Vec::new();
    let mut has_material = false;
    let mut section = Section::None;
    let mut saw_mesh = false;
    let mut tets_here = false;
    let mut nnode = 0usize;
    while let Some(f) = r.next_record() {
        let kw = f[0].to_ascii_lowercase();
        match (section, kw.as_str()) {
            (Section::None, "mesh") => {
                saw_mesh = true;
                let (dim, elem, n) = header(&r, &f)?;
                if dim != 3 {
                    return Err(r.error(format!("dimension {dim}: only 3-D meshes are supported")));
                }
                tets_here = elem.eq_ignore_ascii_case("tetrahedra");
                if tets_here && n != 4 && n != 10 {
                    return Err(r.error(format!("Nnode {n}: tetrahedra have 4 or 10 nodes")));
                }
                nnode = n;
            }
            (Section::None, _) if !saw_mesh => {
                return Err(r.error(format!(
                    "expected a MESH header, found '{}': not a GiD mesh file",
                    f[0].chars().take(24).collect::<String>()
                )))
            }
            (Section::None, "coordinates") => section = Section::Coordinates,
            (Section::None, "elements") => section = Section::Elements,
            (Section::Coordinates, "end") => section = Section::None,
            (Section::Elements, "end") => section = Section::None,
            (Section::Coordinates, _) => {
                if f.len() != 4 {
                    return Err(r.error(format!(
                        "a coordinate line has 4 fields (number x y z), found {}",
                        f.len()
                    )));
                }
                let id: i64 = r.parse(f[0], "a node number")?;
                let x = r.coord(f[1], "an x coordinate")?;
                let y = r.coord(f[2], "a y coordinate")?;
                let z = r.coord(f[3], "a z coordinate")?;
                if ids.insert(id, data.points.len() as u32).is_some() {
                    return Err(r.error(format!("node {id} is defined twice")));
                }
                data.points.push([x, y, z]);
            }
            (Section::Elements, _) => {
                if !tets_here {
                    continue;
                }
                if f.len() != 1 + nnode && f.len() != 2 + nnode {
                    return Err(r.error(format!(
                        "an element line has {} or {} fields (number, {nnode} nodes, optional material), found {}",
                        1 + nnode,
                        2 + nnode,
                        f.len()
                    )));
                }
                let _num: i64 = r.parse(f[0], "an element number")?;
                let mut v = [0i64; 4];
                for (k, slot) in v.iter_mut().enumerate() {
                    *slot = r.parse(f[1 + k], "a node number")?;
                }
                for s in &f[5..1 + nnode] {
                    r.parse::<i64>(s, "a node number")?;
                }
                let material = if f.len() == 2 + nnode {
                    has_material = true;
                    r.parse::<i32>(f[1 + nnode], "a material number")?
                } else {
                    0
                };
                raw_tets.push((v, r.line as u32));
                regions.push(material);
            }
            (Section::None, other) => {
                return Err(r.error(format!(
                    "unknown keyword '{}' (expected Coordinates, Elements or MESH)",
                    other.chars().take(24).collect::<String>()
                )))
            }
        }
    }
    if !saw_mesh {
        return Err(IoError::file(path, "empty file"));
    }
    match section {
        Section::Coordinates => {
            return Err(r.error("file ends inside Coordinates (no 'end coordinates'; truncated?)"))
        }
        Section::Elements => {
            return Err(r.error("file ends inside Elements (no 'end elements'; truncated?)"))
        }
        Section::None => {}
    }
    if raw_tets.is_empty() {
        return Err(IoError::file(path, "no tetrahedra: not a volume mesh"));
    }
    for (v, line) in &raw_tets {
        let mut t = [0u32; 4];
        for (slot, id) in t.iter_mut().zip(v) {
            *slot = *ids.get(id).ok_or_else(|| {
                IoError::at(
                    path,
                    *line as usize,
                    format!("element refers to node {id}, which is not in Coordinates"),
                )
            })?;
        }
        data.tets.push(t);
        data.tet_lines.push(*line);
    }
    if has_material {
        data.tet_regions = regions;
    }
    drop_unused_points(&mut data);
    Ok(data)
}

/// Parses `MESH ["name"] dimension 3 ElemType Tetrahedra Nnode 10` (keywords in
/// any case and order, `=` allowed).
fn header(r: &Records, f: &[&str]) -> Result<(i64, String, usize), IoError> {
    let words: Vec<&str> = f.iter().copied().filter(|w| *w != "=").collect();
    let value = |key: &str| {
        words
            .iter()
            .position(|w| w.eq_ignore_ascii_case(key))
            .and_then(|i| words.get(i + 1).copied())
    };
    let dim = match value("dimension") {
        Some(s) => r.parse::<i64>(s, "the dimension")?,
        None => return Err(r.error("MESH header without 'dimension'")),
    };
    let elem = value("elemtype")
        .ok_or_else(|| r.error("MESH header without 'ElemType'"))?
        .to_string();
    let n = match value("nnode") {
        Some(s) => r.parse::<usize>(s, "the number of nodes per element")?,
        None => return Err(r.error("MESH header without 'Nnode'")),
    };
    if n == 0 || n > 64 {
        return Err(r.error(format!("Nnode {n} is not valid")));
    }
    Ok((dim, elem, n))
}
