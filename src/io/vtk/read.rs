//! The `.vtu` reader.

use super::decode::{Layout, Values};
use super::xml::{child_element, data_arrays, parse_xml, Element};
use super::VTK_TETRA;
use crate::io::{read_bytes, IoError};
use crate::mesh::MeshData;
use std::borrow::Cow;
use std::collections::BTreeMap;
use std::path::Path;

/// VTK's cell type of a linear triangle.
const VTK_TRIANGLE: i64 = 5;

/// The number of points of VTK cell type `ty`: `None` if the type is not
/// VTK's, `Some(None)` if its cells have any number of points.
fn cell_size(ty: i64) -> Option<Option<i64>> {
    Some(match ty {
        1 => Some(1),
        3 | 21 => Some(if ty == 3 { 2 } else { 3 }),
        5 => Some(3),
        8 | 9 | 10 | 35 => Some(4),
        14 => Some(5),
        13 | 22 | 30 => Some(6),
        34 => Some(7),
        11 | 12 | 23 => Some(8),
        28 => Some(9),
        15 | 24 => Some(10),
        16 | 31 => Some(12),
        27 => Some(13),
        26 => Some(15),
        32 | 33 => Some(18),
        37 => Some(19),
        25 => Some(20),
        29 => Some(27),
        2 | 4 | 6 | 7 | 36 | 41 | 42 | 51..=56 | 60..=81 => None,
        _ => return None,
    })
}

/// the reader, and a note on what was dropped (cells other than tetrahedra
/// and triangles, by VTK type), if anything was.
pub fn read_noted(path: &Path) -> Result<(MeshData, Option<String>), IoError> {
    with_pieces(path, |layout, elems, pieces| {
        let mut data = MeshData::default();
        let mut any_region = false;
        let mut regions: Vec<i32> = Vec::new();
        let mut dropped = BTreeMap::new();
        for piece in pieces {
            read_piece(
                path,
                layout,
                elems,
                piece,
                &mut data,
                &mut regions,
                &mut any_region,
                &mut dropped,
            )?;
        }
        let note = (!dropped.is_empty()).then(|| {
            let kinds: Vec<String> = dropped
                .iter()
                .map(|(ty, n)| format!("{n} of VTK type {ty}"))
                .collect();
            format!(
                "kept {} tetrahedra and {} triangles; dropped the other cells ({})",
                data.tets.len(),
                data.triangles.len(),
                kinds.join(", ")
            )
        });
        if data.tets.is_empty() {
            return Err(IoError::file(
                path,
                "no tetrahedra (VTK cell type 10): not a volume mesh",
            ));
        }
        if any_region {
            data.tet_regions = regions;
        }
        Ok((data, note))
    })
}

/// Parses a `.vtu` file (XML, binary layout, root checks) and hands its
/// `<Piece>` elements, in file order, to `body`.
fn with_pieces<R>(
    path: &Path,
    body: impl FnOnce(&Layout, &[Element], &[&Element]) -> Result<R, IoError>,
) -> Result<R, IoError> {
    let bytes = read_bytes(path)?;
    if bytes.iter().all(|c| c.is_ascii_whitespace()) {
        return Err(IoError::file(path, "empty file"));
    }
    // Raw appended data may hold any byte: split it off before parsing the XML.
    let (xml_bytes, appended, appended_base64) = match find(&bytes, b"<AppendedData") {
        Some(at) => {
            let tag_end = bytes[at..]
                .iter()
                .position(|&c| c == b'>')
                .map(|i| at + i + 1)
                .ok_or_else(|| {
                    IoError::file(path, "unterminated <AppendedData> tag (truncated?)")
                })?;
            let tag = String::from_utf8_lossy(&bytes[at..tag_end]);
            let base64 = tag.contains("encoding=\"base64\"") || tag.contains("encoding='base64'");
            let under = bytes[tag_end..]
                .iter()
                .position(|&c| c == b'_')
                .map(|i| tag_end + i + 1)
                .ok_or_else(|| {
                    IoError::file(path, "AppendedData without its '_' marker (truncated?)")
                })?;
            // The data ends where the element closes (the last closing tag:
            // raw bytes may happen to spell it earlier).
            let data = &bytes[under..];
            let end = rfind(data, b"</AppendedData>").ok_or_else(|| {
                IoError::file(
                    path,
                    "<AppendedData> is never closed by </AppendedData> (truncated?)",
                )
            })?;
            (&bytes[..at], Some(&data[..end]), base64)
        }
        None => (&bytes[..], None, false),
    };
    let text = std::str::from_utf8(xml_bytes).map_err(|e| {
        let line = xml_bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&c| c == b'\n')
            .count()
            + 1;
        IoError::at(
            path,
            line,
            "not a text file (invalid UTF-8): expected VTK XML",
        )
    })?;
    // Close what the split cut off, so that the XML is complete (the part
    // before appended data is small; without any, the text is used as is).
    let xml: Cow<'_, str> = match appended {
        Some(_) => Cow::Owned(format!("{text}</VTKFile>")),
        None => Cow::Borrowed(text),
    };
    let elems = parse_xml(path, &xml)?;
    let root = &elems[0];
    if root.name != "VTKFile" {
        return Err(IoError::at(
            path,
            root.line,
            format!(
                "root element <{}> is not <VTKFile>: not a VTK XML file",
                root.name
            ),
        ));
    }
    let kind = root.attr("type").unwrap_or("");
    if kind != "UnstructuredGrid" {
        return Err(IoError::at(
            path,
            root.line,
            format!("VTKFile type '{kind}' is not an UnstructuredGrid"),
        ));
    }
    let compressed = match root.attr("compressor") {
        None | Some("") => false,
        Some("vtkZLibDataCompressor") => true,
        Some(other) => {
            return Err(IoError::at(
                path,
                root.line,
                format!("compressor '{other}' is not supported (use zlib or none)"),
            ))
        }
    };
    let big_endian = match root.attr("byte_order") {
        None | Some("LittleEndian") => false,
        Some("BigEndian") => true,
        Some(other) => {
            return Err(IoError::at(
                path,
                root.line,
                format!("byte_order '{other}' is neither LittleEndian nor BigEndian"),
            ))
        }
    };
    let header64 = match root.attr("header_type") {
        None | Some("UInt32") => false,
        Some("UInt64") => true,
        Some(other) => {
            return Err(IoError::at(
                path,
                root.line,
                format!("header_type '{other}' is neither UInt32 nor UInt64"),
            ))
        }
    };
    let layout = Layout {
        path,
        big_endian,
        header64,
        compressed,
        appended,
        appended_base64,
    };
    if !appended_base64 {
        if let Some(data) = appended {
            check_appended_blocks(&layout, &elems, data)?;
        }
    }
    let child = |e: &Element, name: &str| {
        e.children
            .iter()
            .map(|&i| &elems[i])
            .find(|c| c.name == name)
    };
    let grid = child(root, "UnstructuredGrid")
        .ok_or_else(|| IoError::at(path, root.line, "no <UnstructuredGrid> element"))?;
    let pieces: Vec<&Element> = grid
        .children
        .iter()
        .map(|&i| &elems[i])
        .filter(|c| c.name == "Piece")
        .collect();
    if pieces.is_empty() {
        return Err(IoError::at(path, grid.line, "no <Piece> element"));
    }
    body(&layout, &elems, &pieces)
}

/// A numeric cell array of a `.vtu`, restricted to its tetrahedra: what
/// [`read_tet_cell_array`] returns.
#[derive(Clone, Debug, PartialEq)]
pub struct TetCellArray {
    /// One value per tetrahedron (VTK cell type 10), in file order over all
    /// pieces: the order in which the reader lists the tets. Integer arrays are
    /// converted to `f64`.
    pub values: Vec<f64>,
    /// Per value, the 1-based file line of the `<DataArray>` element that
    /// holds it (for messages).
    pub lines: Vec<u32>,
}

/// Reads the one-component cell array `name` of a `.vtu` file, keeping the
/// values of the tetrahedra only (the cells the reader keeps, in the same
/// order), so that value `i` belongs to tet `i` of the mesh read from the
/// same file. Every piece must carry the array. The values are not checked
/// (NaN and infinities pass through).
pub fn read_tet_cell_array(path: &Path, name: &str) -> Result<TetCellArray, IoError> {
    with_pieces(path, |layout, elems, pieces| {
        let mut out = TetCellArray {
            values: Vec::new(),
            lines: Vec::new(),
        };
        for piece in pieces {
            read_piece_cell_array(path, layout, elems, piece, name, &mut out)?;
        }
        Ok(out)
    })
}

fn read_piece_cell_array(
    path: &Path,
    layout: &Layout,
    elems: &[Element],
    piece: &Element,
    name: &str,
    out: &mut TetCellArray,
) -> Result<(), IoError> {
    let nc = count_attr(path, piece, "NumberOfCells")?;
    let child = |e: &Element, tag: &str| child_element(elems, e, tag);
    let arrays = |e: &Element| data_arrays(elems, e);
    let at = |e: &Element, m: String| IoError::at(path, e.line, m);
    let cells = child(piece, "Cells").ok_or_else(|| at(piece, "<Piece> without <Cells>".into()))?;
    let typ_e = arrays(cells)
        .into_iter()
        .find(|a| a.attr("Name") == Some("types"))
        .ok_or_else(|| at(cells, "<Cells> without a 'types' array".into()))?;
    let types = match layout.values(typ_e)?.0 {
        Values::Ints(v) => v,
        Values::Floats(_) => {
            return Err(at(typ_e, "DataArray 'types' must hold integers".into()));
        }
    };
    if types.len() != nc {
        return Err(at(
            typ_e,
            format!("{} cell types for {nc} cells", types.len()),
        ));
    }
    let cell_data = child(piece, "CellData");
    let found = cell_data.and_then(|cd| {
        arrays(cd)
            .into_iter()
            .find(|a| a.attr("Name") == Some(name))
    });
    let Some(array) = found else {
        let names: Vec<String> = cell_data
            .map(|cd| {
                arrays(cd)
                    .iter()
                    .filter_map(|a| a.attr("Name"))
                    .map(|n| format!("'{n}'"))
                    .collect()
            })
            .unwrap_or_default();
        let have = if names.is_empty() {
            "it has no named cell arrays".to_string()
        } else {
            format!("its cell arrays are {}", names.join(", "))
        };
        let e = cell_data.unwrap_or(piece);
        return Err(at(
            e,
            format!("no cell array '{name}' in this <Piece>; {have}"),
        ));
    };
    let (values, comps) = layout.values(array)?;
    if comps != 1 {
        return Err(at(
            array,
            format!("cell array '{name}' has {comps} components; expected 1 (a scalar per cell)"),
        ));
    }
    if values.len() != nc {
        return Err(at(
            array,
            format!(
                "cell array '{name}' holds {} values for {nc} cells",
                values.len()
            ),
        ));
    }
    let values: Vec<f64> = match values {
        Values::Floats(v) => v,
        Values::Ints(v) => v.into_iter().map(|x| x as f64).collect(),
    };
    for (&ty, &x) in types.iter().zip(&values) {
        if ty == VTK_TETRA as i64 {
            out.values.push(x);
            out.lines.push(array.line as u32);
        }
    }
    Ok(())
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

fn rfind(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).rposition(|w| w == needle)
}

/// Checks that the raw appended arrays tile the appended data: each array's
/// block (header and data, by its header) ends exactly where the next array
/// (by offset) starts, and the last one where the data ends (whitespace
/// aside). A line duplicated or cut inside the data breaks this, and the
/// error names the first array whose block does not fit.
fn check_appended_blocks(layout: &Layout, elems: &[Element], data: &[u8]) -> Result<(), IoError> {
    let path = layout.path;
    let mut arrays: Vec<(usize, &Element)> = Vec::new();
    for e in elems
        .iter()
        .filter(|e| e.name == "DataArray" && e.attr("format") == Some("appended"))
    {
        let name = e.attr("Name").unwrap_or("");
        let off = e
            .attr("offset")
            .and_then(|s| s.trim().parse::<usize>().ok())
            .ok_or_else(|| {
                IoError::at(
                    path,
                    e.line,
                    format!("DataArray '{name}': appended array without a valid offset"),
                )
            })?;
        arrays.push((off, e));
    }
    arrays.sort_by_key(|&(off, e)| (off, e.line));
    let end_of_data = data
        .iter()
        .rposition(|c| !c.is_ascii_whitespace())
        .map_or(0, |i| i + 1);
    for (i, &(off, e)) in arrays.iter().enumerate() {
        let name = e.attr("Name").unwrap_or("");
        let err = |m: String| IoError::at(path, e.line, format!("DataArray '{name}': {m}"));
        let rest = data.get(off..).ok_or_else(|| {
            err(format!(
                "offset {off} is past the end of the {} bytes of appended data (truncated?)",
                data.len()
            ))
        })?;
        let extent = layout.raw_extent(rest).map_err(&err)?;
        let end = off + extent;
        match arrays.get(i + 1) {
            Some(&(next, ne)) if end != next => {
                let next_name = ne.attr("Name").unwrap_or("");
                return Err(err(format!(
                    "its appended block (offset {off}, {extent} bytes by its header) ends at byte {end}, but the next array '{next_name}' starts at {next}: the appended data is corrupt"
                )));
            }
            None if end < end_of_data => {
                return Err(err(format!(
                    "its appended block, the last one, ends at byte {end} but the appended data holds {end_of_data} bytes: the appended data is corrupt (a duplicated or inserted line?)"
                )));
            }
            _ => {}
        }
    }
    Ok(())
}

fn count_attr(path: &Path, e: &Element, key: &str) -> Result<usize, IoError> {
    let s = e
        .attr(key)
        .ok_or_else(|| IoError::at(path, e.line, format!("<{}> without {key}", e.name)))?;
    s.trim()
        .parse::<usize>()
        .map_err(|_| IoError::at(path, e.line, format!("{key}=\"{s}\" is not a valid count")))
}

#[allow(clippy::too_many_arguments)] // one piece's inputs and the accumulators
fn read_piece(
    path: &Path,
    layout: &Layout,
    elems: &[Element],
    piece: &Element,
    data: &mut MeshData,
    regions: &mut Vec<i32>,
    any_region: &mut bool,
    dropped: &mut BTreeMap<i64, usize>,
) -> Result<(), IoError> {
    let np = count_attr(path, piece, "NumberOfPoints")?;
    let nc = count_attr(path, piece, "NumberOfCells")?;
    let child = |e: &Element, tag: &str| child_element(elems, e, tag);
    let arrays = |e: &Element| data_arrays(elems, e);
    let at = |e: &Element, m: String| IoError::at(path, e.line, m);
    let base = data.points.len() as i64;

    // Points.
    let pts = child(piece, "Points").ok_or_else(|| at(piece, "<Piece> without <Points>".into()))?;
    let pa = arrays(pts);
    let pa = pa
        .first()
        .ok_or_else(|| at(pts, "<Points> without a DataArray".into()))?;
    let (pv, comps) = layout.values(pa)?;
    if comps != 3 || pv.len() != 3 * np {
        return Err(at(
            pa,
            format!(
                "points hold {} values in {comps} components; expected 3 x {np}",
                pv.len()
            ),
        ));
    }
    let coords: Vec<f64> = match pv {
        Values::Floats(v) => v,
        Values::Ints(v) => v.into_iter().map(|x| x as f64).collect(),
    };
    if let Some(i) = coords.iter().position(|x| !x.is_finite()) {
        return Err(at(
            pa,
            format!(
                "point {} has a non-finite coordinate {}",
                i / 3 + 1,
                coords[i]
            ),
        ));
    }
    data.points
        .extend(coords.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));

    // Cells.
    let cells = child(piece, "Cells").ok_or_else(|| at(piece, "<Piece> without <Cells>".into()))?;
    let named = |name: &str| {
        arrays(cells)
            .into_iter()
            .find(|a| a.attr("Name") == Some(name))
    };
    let ints = |a: &Element| -> Result<Vec<i64>, IoError> {
        match layout.values(a)?.0 {
            Values::Ints(v) => Ok(v),
            Values::Floats(_) => Err(at(
                a,
                format!(
                    "DataArray '{}' must hold integers",
                    a.attr("Name").unwrap_or("")
                ),
            )),
        }
    };
    let conn_e = named("connectivity")
        .ok_or_else(|| at(cells, "<Cells> without a 'connectivity' array".into()))?;
    let off_e =
        named("offsets").ok_or_else(|| at(cells, "<Cells> without an 'offsets' array".into()))?;
    let typ_e =
        named("types").ok_or_else(|| at(cells, "<Cells> without a 'types' array".into()))?;
    let conn = ints(conn_e)?;
    let offsets = ints(off_e)?;
    let types = ints(typ_e)?;
    if offsets.len() != nc {
        return Err(at(
            off_e,
            format!("{} offsets for {nc} cells", offsets.len()),
        ));
    }
    if types.len() != nc {
        return Err(at(
            typ_e,
            format!("{} cell types for {nc} cells", types.len()),
        ));
    }

    // Regions.
    let cell_data = child(piece, "CellData");
    let region_array = cell_data.and_then(|cd| {
        let a = arrays(cd);
        ["region", "gmsh:physical", "medit:ref", "CellEntityIds"]
            .iter()
            .find_map(|n| a.iter().find(|e| e.attr("Name") == Some(n)).copied())
    });
    let region_values: Option<Vec<i32>> = match region_array {
        None => None,
        Some(a) => {
            let (v, _) = layout.values(a)?;
            if v.len() != nc {
                return Err(at(a, format!("{} region values for {nc} cells", v.len())));
            }
            let as_i32 = |x: f64| -> Result<i32, IoError> {
                if x.fract() == 0.0 && (i32::MIN as f64..=i32::MAX as f64).contains(&x) {
                    Ok(x as i32)
                } else {
                    Err(at(a, format!("region value {x} is not a 32-bit integer")))
                }
            };
            Some(match v {
                Values::Ints(v) => v
                    .into_iter()
                    .map(|x| as_i32(x as f64))
                    .collect::<Result<_, _>>()?,
                Values::Floats(v) => v.into_iter().map(as_i32).collect::<Result<_, _>>()?,
            })
        }
    };
    if region_values.is_some() {
        *any_region = true;
    }

    if let Some(&last) = offsets.last() {
        if last as u64 != conn.len() as u64 {
            return Err(at(
                off_e,
                format!(
                    "the last offset is {last} but the connectivity holds {} entries",
                    conn.len()
                ),
            ));
        }
    } else if !conn.is_empty() {
        return Err(at(
            conn_e,
            format!("{} connectivity entries for no cells", conn.len()),
        ));
    }
    let mut start = 0i64;
    for (c, (&end, &ty)) in offsets.iter().zip(&types).enumerate() {
        if end < start || end as u64 > conn.len() as u64 {
            return Err(at(
                off_e,
                format!(
                    "offset {end} of cell {} is out of order or past the {} connectivity entries",
                    c + 1,
                    conn.len()
                ),
            ));
        }
        let n = end - start;
        let size = cell_size(ty).ok_or_else(|| {
            at(
                typ_e,
                format!("cell {} has type {ty}, which is not a VTK cell type", c + 1),
            )
        })?;
        if size.is_some_and(|k| k != n) {
            return Err(at(
                conn_e,
                format!(
                    "cell {} (VTK type {ty}) has {n} points; that type has {}",
                    c + 1,
                    size.unwrap_or(0)
                ),
            ));
        }
        let ids = &conn[start as usize..end as usize];
        if let Some(&i) = ids.iter().find(|&&i| i < 0 || i as u64 >= np as u64) {
            return Err(at(
                conn_e,
                format!(
                    "cell {} refers to point {i} but the piece has {np} points (0-based)",
                    c + 1
                ),
            ));
        }
        let id = |k: usize| (base + ids[k]) as u32;
        if ty == VTK_TETRA as i64 {
            data.tets.push([id(0), id(1), id(2), id(3)]);
            data.tet_lines.push(conn_e.line as u32);
            regions.push(region_values.as_ref().map_or(0, |r| r[c]));
        } else if ty == VTK_TRIANGLE {
            data.triangles.push((
                [id(0), id(1), id(2)],
                region_values.as_ref().map_or(0, |r| r[c]),
            ));
        } else {
            *dropped.entry(ty).or_default() += 1;
        }
        start = end;
    }
    Ok(())
}

/// Arrays a `.vtu` written by tetrefine carries that the writer computes
/// afresh (mesh quality, refinement bookkeeping, the vertex parent map) or
/// that give the regions: not fields of the solver, so not read as fields.
pub const DERIVED_POINT_ARRAYS: [&str; 5] = [
    "valence",
    "parent_tet",
    "parent_vertices",
    "parent_bary",
    "parent_outside",
];
/// See [`DERIVED_POINT_ARRAYS`]; the last four are the region arrays.
pub const DERIVED_CELL_ARRAYS: [&str; 12] = [
    "min_dihedral",
    "max_dihedral",
    "quality",
    "volume",
    "level",
    "parent",
    "marked",
    "region",
    "gmsh:physical",
    "medit:ref",
    "CellEntityIds",
    "gmsh:geometrical",
];

/// [`read_noted`] with the point and cell arrays of the file as fields
/// ([`MeshMeta::point_fields`](crate::io::meta::MeshMeta),
/// `cell_fields`; cell arrays at the tetrahedra only, in the order the reader
/// lists them), except the arrays tetrefine derives ([`DERIVED_POINT_ARRAYS`],
/// [`DERIVED_CELL_ARRAYS`]). With several pieces, an array must be in every
/// piece with the same number of components. Every value must be finite: a
/// NaN or an infinity is an error naming the array's line.
pub fn read_with_meta_noted(
    path: &Path,
) -> Result<(MeshData, crate::io::meta::MeshMeta, Option<String>), IoError> {
    use crate::io::meta::{Field, MeshMeta};
    let (data, note) = read_noted(path)?;
    let meta = with_pieces(path, |layout, elems, pieces| {
        // name → (components, values, pieces seen)
        let mut point: Vec<(String, usize, Vec<f64>, usize)> = Vec::new();
        let mut cell: Vec<(String, usize, Vec<f64>, usize)> = Vec::new();
        for (k, piece) in pieces.iter().enumerate() {
            let np = count_attr(path, piece, "NumberOfPoints")?;
            let nc = count_attr(path, piece, "NumberOfCells")?;
            let types: Vec<i64> = match child_element(elems, piece, "Cells").and_then(|c| {
                data_arrays(elems, c)
                    .into_iter()
                    .find(|a| a.attr("Name") == Some("types"))
            }) {
                Some(a) => match layout.values(a)?.0 {
                    Values::Ints(v) => v,
                    Values::Floats(_) => Vec::new(),
                },
                None => Vec::new(),
            };
            for (section, n, skip, out) in [
                ("PointData", np, &DERIVED_POINT_ARRAYS[..], &mut point),
                ("CellData", nc, &DERIVED_CELL_ARRAYS[..], &mut cell),
            ] {
                let Some(sec) = child_element(elems, piece, section) else {
                    continue;
                };
                for a in data_arrays(elems, sec) {
                    let Some(name) = a.attr("Name") else { continue };
                    if skip.contains(&name) {
                        continue;
                    }
                    let (values, comps) = layout.values(a)?;
                    if values.len() != n * comps {
                        return Err(IoError::at(
                            path,
                            a.line,
                            format!(
                                "{section} array '{name}' holds {} values for {n} entries of {comps} components",
                                values.len()
                            ),
                        ));
                    }
                    let mut v: Vec<f64> = match values {
                        Values::Floats(v) => v,
                        Values::Ints(v) => v.into_iter().map(|x| x as f64).collect(),
                    };
                    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                        return Err(IoError::at(
                            path,
                            a.line,
                            format!(
                                "{section} array '{name}': value {} of entry {} is not a finite number",
                                v[i],
                                i / comps + 1
                            ),
                        ));
                    }
                    if section == "CellData" {
                        // Keep the tetrahedra's values, as `read` keeps the tets.
                        v = types
                            .iter()
                            .enumerate()
                            .filter(|&(_, &ty)| ty == VTK_TETRA as i64)
                            .flat_map(|(c, _)| v[c * comps..(c + 1) * comps].to_vec())
                            .collect();
                    }
                    match out.iter_mut().find(|e| e.0 == name) {
                        Some(e) if e.1 == comps && e.3 == k => {
                            e.2.extend(v);
                            e.3 += 1;
                        }
                        Some(_) => {}
                        None if k == 0 => out.push((name.to_string(), comps, v, 1)),
                        None => {}
                    }
                }
            }
        }
        let n = pieces.len();
        let keep = |v: Vec<(String, usize, Vec<f64>, usize)>| -> Vec<Field> {
            v.into_iter()
                .filter(|e| e.3 == n)
                .map(|(name, components, values, _)| Field {
                    name,
                    components,
                    values,
                })
                .collect()
        };
        Ok(MeshMeta {
            point_fields: keep(point),
            cell_fields: keep(cell),
            ..MeshMeta::default()
        })
    })?;
    Ok((data, meta, note))
}
