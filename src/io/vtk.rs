//! VTK XML unstructured grid `.vtu` (the "VTK File Formats" chapter of the VTK
//! User's Guide, Kitware), read and written.
//!
//! Read: ASCII, inline binary and appended (raw or base64) data arrays, zlib
//! compressed or not, `UInt32` or `UInt64` headers, either byte order; several
//! pieces are concatenated. Only tetrahedra (VTK cell type 10) are kept; every
//! other cell is skipped. The cell array `region` (any integer or float type,
//! integral values) gives the regions; without it, meshio's `gmsh:physical`,
//! `medit:ref` or `CellEntityIds` is used if present.
//!
//! Written: zlib-compressed (fastest level: float data hardly compresses
//! further) inline binary, `UInt64` headers, read by VTK's
//! `vtkXMLUnstructuredGridReader` (and so ParaView) and meshio. Cell arrays
//! `region` (Int32), `min_dihedral`, `max_dihedral` (Float64, degrees),
//! `quality` (Float64, minimum sine of the signed dihedral angles, as in the
//! √3 refinement paper), `volume` (Float64), any extra [`CellArray`]s; point
//! array `valence` (Int32, incident edges); field data `histogram_counts`
//! (Int64) and `histogram_edges_deg` (Float64): the minimum-dihedral histogram
//! of [`MeshStats::compute`].
//!
//! [`read_tet_cell_array`] reads one numeric cell array (an error indicator,
//! say) at the tetrahedra of a file, in the order [`read`] lists them.

use super::{read_bytes, write_atomic, IoError};
use crate::geom::{tet_quality, tet_volume};
use crate::mesh::{MeshData, TetMesh};
use crate::report::MeshStats;
use base64::Engine;
use rayon::prelude::*;
use std::borrow::Cow;
use std::io::{Read, Write};
use std::path::Path;

/// VTK's cell type of a linear tetrahedron.
const VTK_TETRA: u8 = 10;
/// Uncompressed size of one zlib block (VTK's default).
const BLOCK: usize = 1 << 15;

/// An extra per-tet array for [`write_vtu`]: one value per live tet, in id order.
pub enum CellArray<'a> {
    /// A 32-bit integer array with its name.
    Int32(String, Vec<i32>),
    /// A 64-bit float array with its name.
    Float64(String, Vec<f64>),
    /// A 32-bit integer array with its name and length, each value computed
    /// when it is written (the `i`-th live tet's): a 14M-tet mesh's arrays
    /// are 56 MB each, which a writer streaming blocks need not hold.
    Int32With(String, usize, &'a (dyn Fn(usize) -> i32 + Sync)),
}

impl std::fmt::Debug for CellArray<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let kind = match self {
            CellArray::Int32(..) | CellArray::Int32With(..) => "Int32",
            CellArray::Float64(..) => "Float64",
        };
        write!(
            f,
            "CellArray::{kind}({:?}, {} values)",
            self.name(),
            self.len()
        )
    }
}

impl CellArray<'_> {
    fn name(&self) -> &str {
        match self {
            CellArray::Int32(n, _) | CellArray::Float64(n, _) | CellArray::Int32With(n, ..) => n,
        }
    }

    fn len(&self) -> usize {
        match self {
            CellArray::Int32(_, v) => v.len(),
            CellArray::Float64(_, v) => v.len(),
            CellArray::Int32With(_, n, _) => *n,
        }
    }
}

/// Names of the arrays every written file carries.
const STANDARD_CELL_ARRAYS: [&str; 5] = [
    "region",
    "min_dihedral",
    "max_dihedral",
    "quality",
    "volume",
];

// ----------------------------------------------------------------------------
// Writing
// ----------------------------------------------------------------------------

/// Little-endian bytes of a slice of numbers.
trait LeBytes: Copy {
    const TYPE: &'static str;
    fn put(self, out: &mut Vec<u8>);
}

macro_rules! le_bytes {
    ($t:ty, $name:literal) => {
        impl LeBytes for $t {
            const TYPE: &'static str = $name;
            fn put(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
        }
    };
}
le_bytes!(i32, "Int32");
le_bytes!(i64, "Int64");
le_bytes!(f64, "Float64");
le_bytes!(u8, "UInt8");

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Writes one zlib-compressed array in VTK's block layout: the base64 of the
/// header `[blocks, block size, last block size, compressed sizes…]`
/// (UInt64), then the base64 of the concatenated compressed blocks.
///
/// The values are `value(i)` for `i` in `0..n`, produced block by block, so
/// the uncompressed array never exists as a whole: the blocks are filled and
/// compressed in parallel (rayon; the output does not depend on the number of
/// threads), and only the compressed array is held until its header, which
/// needs every compressed size, has been written.
fn compressed_array<T: LeBytes + Send>(
    w: &mut dyn Write,
    n: usize,
    value: impl Fn(usize) -> T + Sync,
) -> std::io::Result<()> {
    let per_block = BLOCK / std::mem::size_of::<T>();
    let blocks: Vec<Vec<u8>> = (0..n.div_ceil(per_block))
        .into_par_iter()
        .map(|b| {
            let range = b * per_block..((b + 1) * per_block).min(n);
            let mut raw = Vec::with_capacity(range.len() * std::mem::size_of::<T>());
            for i in range {
                value(i).put(&mut raw);
            }
            let mut z = flate2::write::ZlibEncoder::new(
                Vec::with_capacity(raw.len() / 2),
                flate2::Compression::fast(),
            );
            z.write_all(&raw)?;
            z.finish()
        })
        .collect::<std::io::Result<_>>()?;
    let raw_len = n * std::mem::size_of::<T>();
    let last = match raw_len % BLOCK {
        0 if raw_len == 0 => 0,
        0 => BLOCK,
        r => r,
    };
    let mut header = Vec::with_capacity(8 * (3 + blocks.len()));
    for v in [blocks.len() as u64, BLOCK as u64, last as u64]
        .into_iter()
        .chain(blocks.iter().map(|c| c.len() as u64))
    {
        header.extend_from_slice(&v.to_le_bytes());
    }
    let b64 = base64::engine::general_purpose::STANDARD;
    w.write_all(b64.encode(&header).as_bytes())?;
    let mut enc = base64::write::EncoderWriter::new(w, &b64);
    for c in &blocks {
        enc.write_all(c)?;
    }
    enc.finish()?;
    Ok(())
}

/// One `<DataArray>` element of `n` values `value(i)` (see [`compressed_array`]).
fn data_array<T: LeBytes + Send>(
    w: &mut dyn Write,
    name: &str,
    n: usize,
    extra_attrs: &str,
    value: impl Fn(usize) -> T + Sync,
) -> std::io::Result<()> {
    writeln!(
        w,
        "        <DataArray type=\"{}\" Name=\"{}\"{extra_attrs} format=\"binary\">",
        T::TYPE,
        xml_escape(name)
    )?;
    write!(w, "          ")?;
    compressed_array(w, n, value)?;
    writeln!(w, "\n        </DataArray>")
}

/// Writes `mesh` as a `.vtu` with the standard arrays and `extra_cells`
/// (through a temporary file). Extra arrays need one value per live tet and a
/// name different from the standard ones and from each other.
///
/// Memory: besides the mesh and the extra arrays, only the tet ids (when
/// the mesh has dead slots), the point valences and one compressed array at
/// a time are held; the per-tet quality arrays are computed block by block
/// as they are compressed.
pub fn write_vtu(path: &Path, mesh: &TetMesh, extra_cells: &[CellArray]) -> Result<(), IoError> {
    let n_tets = mesh.n_tets();
    for (i, a) in extra_cells.iter().enumerate() {
        if a.len() != n_tets {
            return Err(IoError::file(
                path,
                format!(
                    "cell array '{}' has {} values for {} tetrahedra",
                    a.name(),
                    a.len(),
                    n_tets
                ),
            ));
        }
        if STANDARD_CELL_ARRAYS.contains(&a.name())
            || extra_cells[..i].iter().any(|b| b.name() == a.name())
        {
            return Err(IoError::file(
                path,
                format!("cell array name '{}' is used twice", a.name()),
            ));
        }
    }
    // The i-th live tet: slot i when the mesh is compact.
    let ids: Option<Vec<u32>> = (mesh.n_tet_slots() != n_tets).then(|| mesh.tet_ids().collect());
    let tet_at = |i: usize| match &ids {
        Some(ids) => ids[i],
        None => i as u32,
    };
    let stats = MeshStats::compute(mesh);
    let valence = MeshStats::vertex_valence(mesh);
    let quality = |i: usize| tet_quality(&mesh.tet_points(tet_at(i)));
    let counts = &stats.histogram.counts;
    let edges = &stats.histogram.edges_deg;
    write_atomic(path, |w| {
        writeln!(w, "<?xml version=\"1.0\"?>")?;
        writeln!(
            w,
            "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">"
        )?;
        writeln!(
            w,
            "  <!-- written by tetrefine -->\n  <UnstructuredGrid>\n    <FieldData>"
        )?;
        data_array(
            w,
            "histogram_counts",
            counts.len(),
            &format!(" NumberOfTuples=\"{}\"", counts.len()),
            |i| counts[i] as i64,
        )?;
        data_array(
            w,
            "histogram_edges_deg",
            edges.len(),
            &format!(" NumberOfTuples=\"{}\"", edges.len()),
            |i| edges[i],
        )?;
        writeln!(w, "    </FieldData>")?;
        writeln!(
            w,
            "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{n_tets}\">",
            mesh.n_points(),
        )?;
        writeln!(w, "      <PointData Scalars=\"valence\">")?;
        data_array(w, "valence", valence.len(), "", |i| valence[i] as i32)?;
        writeln!(w, "      </PointData>\n      <CellData Scalars=\"region\">")?;
        data_array(w, "region", n_tets, "", |i| mesh.region(tet_at(i)))?;
        data_array(w, "min_dihedral", n_tets, "", |i| {
            quality(i).min_dihedral_deg
        })?;
        data_array(w, "max_dihedral", n_tets, "", |i| {
            quality(i).max_dihedral_deg
        })?;
        data_array(w, "quality", n_tets, "", |i| quality(i).min_sine)?;
        data_array(w, "volume", n_tets, "", |i| {
            tet_volume(&mesh.tet_points(tet_at(i)))
        })?;
        for a in extra_cells {
            match a {
                CellArray::Int32(n, v) => data_array(w, n, v.len(), "", |i| v[i])?,
                CellArray::Float64(n, v) => data_array(w, n, v.len(), "", |i| v[i])?,
                CellArray::Int32With(n, len, f) => data_array(w, n, *len, "", f)?,
            }
        }
        writeln!(w, "      </CellData>\n      <Points>")?;
        let points = mesh.points();
        data_array(
            w,
            "Points",
            3 * points.len(),
            " NumberOfComponents=\"3\"",
            |i| points[i / 3][i % 3],
        )?;
        writeln!(w, "      </Points>\n      <Cells>")?;
        data_array(w, "connectivity", 4 * n_tets, "", |i| {
            i64::from(mesh.tet(tet_at(i / 4))[i % 4])
        })?;
        data_array(w, "offsets", n_tets, "", |i| 4 * (i as i64 + 1))?;
        data_array(w, "types", n_tets, "", |_| VTK_TETRA)?;
        writeln!(
            w,
            "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>"
        )
    })
}

// ----------------------------------------------------------------------------
// Reading: a small XML scanner, enough for VTK files
// ----------------------------------------------------------------------------

/// An XML element: name, attributes, direct text, children, line.
///
/// The text borrows the file's bytes: a 14M-tet `.vtu` is an 880 MB file
/// whose data arrays are element text, and copying it (once into the parsed
/// string, once into the elements) tripled the reader's memory. Text split
/// by child elements (never the case for a data array) is joined in a copy.
struct Element<'a> {
    name: String,
    attrs: Vec<(String, String)>,
    text: Cow<'a, str>,
    children: Vec<usize>,
    line: usize,
}

/// Appends `t` to an element's text, borrowing while it is one piece.
fn push_text<'a>(text: &mut Cow<'a, str>, t: &'a str) {
    if text.is_empty() {
        *text = Cow::Borrowed(t);
    } else {
        text.to_mut().push_str(t);
    }
}

impl Element<'_> {
    fn attr(&self, key: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
}

fn unescape(s: &str) -> String {
    if !s.contains('&') {
        return s.to_string();
    }
    s.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&amp;", "&")
}

/// Parses the XML part of a file into a flat element list (index 0 is the root).
fn parse_xml<'a>(path: &Path, text: &'a str) -> Result<Vec<Element<'a>>, IoError> {
    let b = text.as_bytes();
    let mut pos = 0;
    let mut line = 1;
    let mut counted = 0; // newlines counted up to here
    let line_at = |p: usize, line: &mut usize, counted: &mut usize| {
        *line += b[*counted..p].iter().filter(|&&c| c == b'\n').count();
        *counted = p;
        *line
    };
    let mut elems: Vec<Element> = Vec::new();
    let mut stack: Vec<usize> = Vec::new();
    let mut root_closed = false;
    while pos < b.len() {
        let lt = match b[pos..].iter().position(|&c| c == b'<') {
            Some(i) => pos + i,
            None => {
                if let Some(&top) = stack.last() {
                    push_text(&mut elems[top].text, &text[pos..]);
                }
                break;
            }
        };
        if lt > pos {
            let t = &text[pos..lt];
            match stack.last() {
                Some(&top) => push_text(&mut elems[top].text, t),
                None if !t.trim().is_empty() => {
                    let l = line_at(pos, &mut line, &mut counted);
                    return Err(IoError::at(
                        path,
                        l,
                        "text outside the XML root element: not a VTK XML file",
                    ));
                }
                None => {}
            }
        }
        let l = line_at(lt, &mut line, &mut counted);
        let rest = &text[lt..];
        let skip_to = |end: &str| -> Result<usize, IoError> {
            rest.find(end).map(|i| lt + i + end.len()).ok_or_else(|| {
                IoError::at(
                    path,
                    l,
                    format!("unterminated XML markup (no '{end}'; truncated?)"),
                )
            })
        };
        if rest.starts_with("<?") {
            pos = skip_to("?>")?;
            continue;
        }
        if rest.starts_with("<!--") {
            pos = skip_to("-->")?;
            continue;
        }
        if rest.starts_with("<!") {
            pos = skip_to(">")?;
            continue;
        }
        let end = skip_to(">")?;
        let inner = &text[lt + 1..end - 1];
        if let Some(name) = inner.strip_prefix('/') {
            let name = name.trim();
            match stack.pop() {
                Some(top) if elems[top].name == name => {
                    if stack.is_empty() {
                        root_closed = true;
                    }
                }
                Some(top) => {
                    return Err(IoError::at(
                        path,
                        l,
                        format!("</{name}> closes <{}> (malformed XML)", elems[top].name),
                    ))
                }
                None => {
                    return Err(IoError::at(
                        path,
                        l,
                        format!("</{name}> closes nothing (malformed XML)"),
                    ))
                }
            }
            pos = end;
            continue;
        }
        let (inner, self_closing) = match inner.strip_suffix('/') {
            Some(i) => (i, true),
            None => (inner, false),
        };
        let name_end = inner
            .find(|c: char| c.is_ascii_whitespace())
            .unwrap_or(inner.len());
        let name = &inner[..name_end];
        if name.is_empty()
            || !name
                .chars()
                .all(|c| c.is_alphanumeric() || "_-.:".contains(c))
        {
            return Err(IoError::at(
                path,
                l,
                "malformed XML tag: not a VTK XML file",
            ));
        }
        let mut attrs = Vec::new();
        let mut a = inner[name_end..].trim_start();
        while !a.is_empty() {
            let eq = a
                .find('=')
                .ok_or_else(|| IoError::at(path, l, format!("malformed attribute in <{name}>")))?;
            let key = a[..eq].trim();
            let v = a[eq + 1..].trim_start();
            let q = v.chars().next().filter(|c| *c == '"' || *c == '\'');
            let Some(q) = q else {
                return Err(IoError::at(
                    path,
                    l,
                    format!("unquoted attribute '{key}' in <{name}>"),
                ));
            };
            let close = v[1..].find(q).ok_or_else(|| {
                IoError::at(
                    path,
                    l,
                    format!("unterminated attribute '{key}' in <{name}>"),
                )
            })?;
            attrs.push((key.to_string(), unescape(&v[1..1 + close])));
            a = v[close + 2..].trim_start();
        }
        if root_closed {
            return Err(IoError::at(
                path,
                l,
                "a second root element (malformed XML)",
            ));
        }
        let id = elems.len();
        elems.push(Element {
            name: name.to_string(),
            attrs,
            text: Cow::Borrowed(""),
            children: Vec::new(),
            line: l,
        });
        if let Some(&top) = stack.last() {
            elems[top].children.push(id);
        } else if id != 0 {
            return Err(IoError::at(
                path,
                l,
                "a second root element (malformed XML)",
            ));
        }
        if !self_closing {
            stack.push(id);
        }
        pos = end;
    }
    if let Some(&top) = stack.last() {
        let l = line_at(b.len(), &mut line, &mut counted);
        return Err(IoError::at(
            path,
            l,
            format!("file ends inside <{}> (truncated?)", elems[top].name),
        ));
    }
    if elems.is_empty() {
        return Err(IoError::file(path, "no XML element: not a VTK XML file"));
    }
    Ok(elems)
}

// ----------------------------------------------------------------------------
// Reading: data arrays
// ----------------------------------------------------------------------------

/// Decoded values of a data array.
enum Values {
    Ints(Vec<i64>),
    Floats(Vec<f64>),
}

impl Values {
    fn len(&self) -> usize {
        match self {
            Values::Ints(v) => v.len(),
            Values::Floats(v) => v.len(),
        }
    }
}

/// How the binary parts of the file are laid out.
struct Layout<'a> {
    path: &'a Path,
    big_endian: bool,
    header64: bool,
    compressed: bool,
    appended: Option<&'a [u8]>,
    appended_base64: bool,
}

#[derive(Clone, Copy, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "Int8" | "Char" => Scalar::I8,
            "UInt8" | "UnsignedChar" => Scalar::U8,
            "Int16" | "Short" => Scalar::I16,
            "UInt16" | "UnsignedShort" => Scalar::U16,
            "Int32" | "Int" => Scalar::I32,
            "UInt32" | "UnsignedInt" => Scalar::U32,
            "Int64" | "Long" | "LongLong" | "IdType" => Scalar::I64,
            "UInt64" | "UnsignedLong" | "UnsignedLongLong" => Scalar::U64,
            "Float32" | "Float" => Scalar::F32,
            "Float64" | "Double" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::I64 | Scalar::U64 | Scalar::F64 => 8,
        }
    }

    fn is_float(self) -> bool {
        matches!(self, Scalar::F32 | Scalar::F64)
    }
}

/// Decodes base64 that may be several independently padded pieces.
fn base64_pieces(text: &[u8]) -> Option<Vec<u8>> {
    let clean: Vec<u8> = text
        .iter()
        .copied()
        .filter(|c| !c.is_ascii_whitespace())
        .collect();
    let b64 = base64::engine::general_purpose::STANDARD;
    let mut out = Vec::with_capacity(clean.len() / 4 * 3);
    let mut start = 0;
    let mut i = 0;
    while i < clean.len() {
        if clean[i] == b'=' {
            while i < clean.len() && clean[i] == b'=' {
                i += 1;
            }
            out.extend(b64.decode(&clean[start..i]).ok()?);
            start = i;
        } else {
            i += 1;
        }
    }
    if start < clean.len() {
        out.extend(b64.decode(&clean[start..]).ok()?);
    }
    Some(out)
}

impl Layout<'_> {
    fn uint(&self, b: &[u8]) -> u64 {
        let mut a = [0u8; 8];
        let n = b.len();
        a[..n].copy_from_slice(b);
        if self.big_endian {
            a[..n].reverse();
        }
        u64::from_le_bytes(a)
    }

    /// The array bytes after the header (decompressed), from a stream that
    /// starts with the header.
    fn unpack(&self, s: &[u8], err: &dyn Fn(&str) -> IoError) -> Result<Vec<u8>, IoError> {
        let h = if self.header64 { 8 } else { 4 };
        let word = |i: usize| -> Result<u64, IoError> {
            s.get(i * h..(i + 1) * h)
                .map(|w| self.uint(w))
                .ok_or_else(|| err("data ends inside the array header (truncated?)"))
        };
        if !self.compressed {
            let n = word(0)? as usize;
            return s
                .get(h..h.saturating_add(n))
                .map(|d| d.to_vec())
                .ok_or_else(|| {
                    err(&format!(
                        "array announces {n} bytes but fewer follow (truncated?)"
                    ))
                });
        }
        let blocks = word(0)? as usize;
        let block = word(1)? as usize;
        let last = word(2)? as usize;
        if blocks > s.len() / h {
            return Err(err(&format!(
                "{blocks} compressed blocks cannot fit the data (corrupt header)"
            )));
        }
        let mut sizes = Vec::with_capacity(blocks);
        for i in 0..blocks {
            sizes.push(word(3 + i)? as usize);
        }
        let mut at = (3 + blocks) * h;
        let total = if blocks == 0 {
            0
        } else {
            block
                .saturating_mul(blocks - 1)
                .saturating_add(if last == 0 { block } else { last })
        };
        if total > s.len().saturating_mul(1100).saturating_add(1 << 20) {
            return Err(err(
                "compressed array header announces an impossible size (corrupt)",
            ));
        }
        let mut out = Vec::with_capacity(total.min(s.len().saturating_mul(8)));
        for (i, &cs) in sizes.iter().enumerate() {
            let want = if i + 1 == blocks && last != 0 {
                last
            } else {
                block
            };
            let src = s.get(at..at.saturating_add(cs)).ok_or_else(|| {
                err("compressed block runs past the end of the data (truncated?)")
            })?;
            let before = out.len();
            flate2::read::ZlibDecoder::new(src)
                .take(want as u64 + 1)
                .read_to_end(&mut out)
                .map_err(|e| err(&format!("cannot decompress block {}: {e}", i + 1)))?;
            if out.len() - before != want {
                return Err(err(&format!(
                    "compressed block {} holds {} bytes, not {want}",
                    i + 1,
                    out.len() - before
                )));
            }
            at += cs;
        }
        Ok(out)
    }

    /// Values of a DataArray element.
    fn values(&self, e: &Element) -> Result<(Values, usize), IoError> {
        let err = |m: &str| match e.attr("Name") {
            Some(n) => IoError::at(self.path, e.line, format!("DataArray '{n}': {m}")),
            None => IoError::at(self.path, e.line, format!("DataArray: {m}")),
        };
        let ty = e.attr("type").ok_or_else(|| err("no type attribute"))?;
        let scalar = Scalar::parse(ty).ok_or_else(|| err(&format!("unsupported type '{ty}'")))?;
        let comps = match e.attr("NumberOfComponents") {
            Some(s) => s
                .trim()
                .parse::<usize>()
                .ok()
                .filter(|&c| c >= 1)
                .ok_or_else(|| err(&format!("bad NumberOfComponents '{s}'")))?,
            None => 1,
        };
        let format = e.attr("format").unwrap_or("ascii");
        if format == "ascii" {
            let toks = e.text.split_ascii_whitespace();
            let v = if scalar.is_float() {
                Values::Floats(
                    toks.map(|t| {
                        t.parse::<f64>().map_err(|_| {
                            err(&format!(
                                "'{}' is not a number",
                                t.chars().take(24).collect::<String>()
                            ))
                        })
                    })
                    .collect::<Result<_, _>>()?,
                )
            } else {
                Values::Ints(
                    toks.map(|t| {
                        t.parse::<i64>().map_err(|_| {
                            err(&format!(
                                "'{}' is not an integer",
                                t.chars().take(24).collect::<String>()
                            ))
                        })
                    })
                    .collect::<Result<_, _>>()?,
                )
            };
            return Ok((v, comps));
        }
        let raw = match format {
            "binary" => {
                let bytes =
                    base64_pieces(e.text.as_bytes()).ok_or_else(|| err("invalid base64 data"))?;
                self.unpack(&bytes, &err)?
            }
            "appended" => {
                let app = self
                    .appended
                    .ok_or_else(|| err("format 'appended' but the file has no AppendedData"))?;
                let off: usize = e
                    .attr("offset")
                    .and_then(|s| s.trim().parse().ok())
                    .ok_or_else(|| err("appended array without a valid offset"))?;
                let s = app.get(off..).ok_or_else(|| {
                    err(&format!(
                        "offset {off} is past the end of the appended data (truncated?)"
                    ))
                })?;
                if self.appended_base64 {
                    let end = s.iter().position(|&c| c == b'<').unwrap_or(s.len());
                    let bytes =
                        base64_pieces(&s[..end]).ok_or_else(|| err("invalid base64 data"))?;
                    self.unpack(&bytes, &err)?
                } else {
                    self.unpack(s, &err)?
                }
            }
            other => return Err(err(&format!("unknown format '{other}'"))),
        };
        let size = scalar.size();
        if raw.len() % size != 0 {
            return Err(err(&format!(
                "{} bytes is not a whole number of {ty} values",
                raw.len()
            )));
        }
        let word = |c: &[u8]| {
            let mut a = [0u8; 8];
            a[..size].copy_from_slice(c);
            if self.big_endian {
                a[..size].reverse();
            }
            a
        };
        let chunks = raw.chunks_exact(size);
        let v = match scalar {
            Scalar::F32 => Values::Floats(
                chunks
                    .map(|c| f32::from_le_bytes(word(c)[..4].try_into().unwrap_or([0; 4])) as f64)
                    .collect(),
            ),
            Scalar::F64 => Values::Floats(chunks.map(|c| f64::from_le_bytes(word(c))).collect()),
            Scalar::I8 => Values::Ints(chunks.map(|c| c[0] as i8 as i64).collect()),
            Scalar::U8 => Values::Ints(chunks.map(|c| c[0] as i64).collect()),
            Scalar::I16 => Values::Ints(
                chunks
                    .map(|c| i16::from_le_bytes([word(c)[0], word(c)[1]]) as i64)
                    .collect(),
            ),
            Scalar::U16 => Values::Ints(
                chunks
                    .map(|c| u16::from_le_bytes([word(c)[0], word(c)[1]]) as i64)
                    .collect(),
            ),
            Scalar::I32 => Values::Ints(
                chunks
                    .map(|c| i32::from_le_bytes(word(c)[..4].try_into().unwrap_or([0; 4])) as i64)
                    .collect(),
            ),
            Scalar::U32 => Values::Ints(
                chunks
                    .map(|c| u32::from_le_bytes(word(c)[..4].try_into().unwrap_or([0; 4])) as i64)
                    .collect(),
            ),
            Scalar::I64 => Values::Ints(chunks.map(|c| i64::from_le_bytes(word(c))).collect()),
            Scalar::U64 => {
                let v: Vec<u64> = chunks.map(|c| u64::from_le_bytes(word(c))).collect();
                if v.iter().any(|&x| x > i64::MAX as u64) {
                    return Err(err("UInt64 value too large"));
                }
                Values::Ints(v.into_iter().map(|x| x as i64).collect())
            }
        };
        Ok((v, comps))
    }
}

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

/// The first child of `e` with tag `tag`.
fn child_element<'a, 'b>(
    elems: &'a [Element<'b>],
    e: &Element,
    tag: &str,
) -> Option<&'a Element<'b>> {
    e.children
        .iter()
        .map(|&i| &elems[i])
        .find(|c| c.name == tag)
}

/// The `<DataArray>` children of `e`.
fn data_arrays<'a, 'b>(elems: &'a [Element<'b>], e: &Element) -> Vec<&'a Element<'b>> {
    e.children
        .iter()
        .map(|&i| &elems[i])
        .filter(|c| c.name == "DataArray")
        .collect()
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn element_text_borrows_one_piece_and_joins_several() {
        let xml = "<a>\n 12 <b k=\"v\">in b</b> 34\n</a>";
        let elems = parse_xml(Path::new("t.xml"), xml).expect("well-formed");
        assert_eq!(elems[0].name, "a");
        assert_eq!(elems[0].text, "\n 12  34\n");
        assert!(matches!(elems[0].text, Cow::Owned(_)));
        assert_eq!(elems[1].text, "in b");
        assert!(matches!(elems[1].text, Cow::Borrowed(_)));
        assert_eq!(elems[1].attr("k"), Some("v"));
        assert_eq!(elems[1].line, 2);
    }
}
