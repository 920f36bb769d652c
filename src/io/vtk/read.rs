//! The `.vtu` reader.

use super::decode::{Layout, Values};
use super::xml::{child_element, data_arrays, parse_xml, Element};
use super::VTK_TETRA;
use crate::io::{read_bytes, IoError};
use crate::mesh::MeshData;
use std::borrow::Cow;
use std::path::Path;

/// Reads a `.vtu` file: its tetrahedra, points and regions.
pub fn read(path: &Path) -> Result<MeshData, IoError> {
    with_pieces(path, |layout, elems, pieces| {
        let mut data = MeshData::default();
        let mut any_region = false;
        let mut regions: Vec<i32> = Vec::new();
        for piece in pieces {
            read_piece(
                path,
                layout,
                elems,
                piece,
                &mut data,
                &mut regions,
                &mut any_region,
            )?;
        }
        if data.tets.is_empty() {
            return Err(IoError::file(
                path,
                "no tetrahedra (VTK cell type 10): not a volume mesh",
            ));
        }
        if any_region {
            data.tet_regions = regions;
        }
        Ok(data)
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
            (&bytes[..at], Some(&bytes[under..]), base64)
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
    let layout = Layout {
        path,
        big_endian: root.attr("byte_order") == Some("BigEndian"),
        header64: root.attr("header_type") == Some("UInt64"),
        compressed,
        appended,
        appended_base64,
    };
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
    /// pieces: the order in which [`read`] lists the tets. Integer arrays are
    /// converted to `f64`.
    pub values: Vec<f64>,
    /// Per value, the 1-based file line of the `<DataArray>` element that
    /// holds it (for messages).
    pub lines: Vec<u32>,
}

/// Reads the one-component cell array `name` of a `.vtu` file, keeping the
/// values of the tetrahedra only (the cells [`read`] keeps, in the same
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

fn count_attr(path: &Path, e: &Element, key: &str) -> Result<usize, IoError> {
    let s = e
        .attr(key)
        .ok_or_else(|| IoError::at(path, e.line, format!("<{}> without {key}", e.name)))?;
    s.trim()
        .parse::<usize>()
        .map_err(|_| IoError::at(path, e.line, format!("{key}=\"{s}\" is not a valid count")))
}

fn read_piece(
    path: &Path,
    layout: &Layout,
    elems: &[Element],
    piece: &Element,
    data: &mut MeshData,
    regions: &mut Vec<i32>,
    any_region: &mut bool,
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
        if ty == VTK_TETRA as i64 {
            if end - start != 4 {
                return Err(at(
                    conn_e,
                    format!("tetrahedron (cell {}) has {} points", c + 1, end - start),
                ));
            }
            let mut v = [0u32; 4];
            for (k, slot) in v.iter_mut().enumerate() {
                let i = conn[start as usize + k];
                if i < 0 || i as u64 >= np as u64 {
                    return Err(at(
                        conn_e,
                        format!(
                            "cell {} refers to point {i} but the piece has {np} points (0-based)",
                            c + 1
                        ),
                    ));
                }
                *slot = (base + i) as u32;
            }
            data.tets.push(v);
            data.tet_lines.push(conn_e.line as u32);
            regions.push(region_values.as_ref().map_or(0, |r| r[c]));
        }
        start = end;
    }
    Ok(())
}

