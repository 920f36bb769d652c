//! The `.vtu` writer: zlib-compressed inline binary arrays in VTK's block
//! layout, `UInt64` headers.

use super::VTK_TETRA;
use crate::geom::{tet_quality, tet_volume};
use crate::io::{write_atomic, IoError};
use crate::mesh::TetMesh;
use base64::Engine;
use rayon::prelude::*;
use std::io::Write;
use std::path::Path;

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
    /// A 64-bit float array of several components per tet: name,
    /// components, values (tet after tet).
    Float64Components(String, usize, Vec<f64>),
}

/// An extra per-point array for [`write_vtu_with`]: a name, components per
/// point, and the values point after point (`components` × points).
#[derive(Clone, Debug, PartialEq)]
pub enum PointArray {
    /// 64-bit floats.
    Float64(String, usize, Vec<f64>),
    /// 32-bit integers: name, components, values.
    Int32(String, usize, Vec<i32>),
}

impl PointArray {
    fn name(&self) -> &str {
        match self {
            PointArray::Float64(n, ..) | PointArray::Int32(n, ..) => n,
        }
    }

    fn entries(&self) -> usize {
        match self {
            PointArray::Float64(_, c, v) => v.len() / (*c).max(1),
            PointArray::Int32(_, c, v) => v.len() / (*c).max(1),
        }
    }
}

impl std::fmt::Debug for CellArray<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let kind = match self {
            CellArray::Int32(..) | CellArray::Int32With(..) => "Int32",
            CellArray::Float64(..) | CellArray::Float64Components(..) => "Float64",
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
            CellArray::Int32(n, _)
            | CellArray::Float64(n, _)
            | CellArray::Int32With(n, ..)
            | CellArray::Float64Components(n, ..) => n,
        }
    }

    fn len(&self) -> usize {
        match self {
            CellArray::Int32(_, v) => v.len(),
            CellArray::Float64(_, v) => v.len(),
            CellArray::Int32With(_, n, _) => *n,
            CellArray::Float64Components(_, c, v) => v.len() / (*c).max(1),
        }
    }
}

/// What a `.vtu` carries besides the mesh and its per-tet quality arrays:
/// figures the caller computes (the statistics live outside `io`), written
/// as the point array `valence` and the field data `histogram_counts` and
/// `histogram_edges_deg`.
#[derive(Clone, Copy, Debug)]
pub struct VtuSummary<'a> {
    /// Per point, the number of incident edges (one value per point).
    pub valence: &'a [u32],
    /// Tets per histogram bin of the minimum dihedral angle.
    pub histogram_counts: &'a [u64],
    /// The bin edges in degrees (one more than the counts).
    pub histogram_edges_deg: &'a [f64],
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

/// The `NumberOfComponents` attribute of an array of `c` components: none
/// for a scalar, which readers (meshio) then give as a plain array rather
/// than one of `n × 1`.
fn components_attr(c: usize) -> String {
    if c == 1 {
        String::new()
    } else {
        format!(" NumberOfComponents=\"{c}\"")
    }
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

/// Writes `mesh` as a `.vtu` with the standard arrays, the `summary`
/// arrays (when given) and `extra_cells` (through a temporary file). Extra
/// arrays need one value per live tet and a name different from the
/// standard ones and from each other; the summary's valence needs one value
/// per point.
///
/// Memory: besides the mesh and the extra arrays, only the tet ids (when
/// the mesh has dead slots) and one compressed array at a time are held;
/// the per-tet quality arrays are computed block by block as they are
/// compressed.
pub fn write_vtu(
    path: &Path,
    mesh: &TetMesh,
    summary: Option<&VtuSummary>,
    extra_cells: &[CellArray],
) -> Result<(), IoError> {
    write_vtu_with(path, mesh, summary, extra_cells, &[])
}

/// [`write_vtu`] with extra point arrays (transferred fields, the vertex
/// parent map): one entry per point, names different from `valence` and
/// from each other.
pub fn write_vtu_with(
    path: &Path,
    mesh: &TetMesh,
    summary: Option<&VtuSummary>,
    extra_cells: &[CellArray],
    extra_points: &[PointArray],
) -> Result<(), IoError> {
    for (i, a) in extra_points.iter().enumerate() {
        if a.entries() != mesh.n_points()
            || matches!(a, PointArray::Float64(_, c, v) if *c == 0 || v.len() % c != 0)
            || matches!(a, PointArray::Int32(_, c, v) if *c == 0 || v.len() % c != 0)
        {
            return Err(IoError::file(
                path,
                format!(
                    "point array '{}' has {} entries for {} points",
                    a.name(),
                    a.entries(),
                    mesh.n_points()
                ),
            ));
        }
        if a.name() == "valence" || extra_points[..i].iter().any(|b| b.name() == a.name()) {
            return Err(IoError::file(
                path,
                format!("point array name '{}' is used twice", a.name()),
            ));
        }
    }
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
    if let Some(s) = summary {
        if s.valence.len() != mesh.n_points() {
            return Err(IoError::file(
                path,
                format!(
                    "valence has {} values for {} points",
                    s.valence.len(),
                    mesh.n_points()
                ),
            ));
        }
    }
    // The i-th live tet: slot i when the mesh is compact.
    let ids: Option<Vec<u32>> = (mesh.n_tet_slots() != n_tets).then(|| mesh.tet_ids().collect());
    let tet_at = |i: usize| match &ids {
        Some(ids) => ids[i],
        None => i as u32,
    };
    let quality = |i: usize| tet_quality(&mesh.tet_points(tet_at(i)));
    write_atomic(path, |w| {
        writeln!(w, "<?xml version=\"1.0\"?>")?;
        writeln!(
            w,
            "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">"
        )?;
        writeln!(w, "  <!-- written by tetrefine -->\n  <UnstructuredGrid>")?;
        if let Some(s) = summary {
            let counts = s.histogram_counts;
            let edges = s.histogram_edges_deg;
            writeln!(w, "    <FieldData>")?;
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
        }
        writeln!(
            w,
            "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{n_tets}\">",
            mesh.n_points(),
        )?;
        if summary.is_some() || !extra_points.is_empty() {
            match summary {
                Some(_) => writeln!(w, "      <PointData Scalars=\"valence\">")?,
                None => writeln!(w, "      <PointData>")?,
            }
            if let Some(s) = summary {
                let valence = s.valence;
                data_array(w, "valence", valence.len(), "", |i| valence[i] as i32)?;
            }
            for a in extra_points {
                match a {
                    PointArray::Float64(n, c, v) => {
                        data_array(w, n, v.len(), &components_attr(*c), |i| v[i])?
                    }
                    PointArray::Int32(n, c, v) => {
                        data_array(w, n, v.len(), &components_attr(*c), |i| v[i])?
                    }
                }
            }
            writeln!(w, "      </PointData>")?;
        }
        writeln!(w, "      <CellData Scalars=\"region\">")?;
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
                CellArray::Float64Components(n, c, v) => {
                    data_array(w, n, v.len(), &components_attr(*c), |i| v[i])?
                }
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

/// Writes the `.pvtu` (VTK's parallel unstructured grid) that lists the
/// `.vtu` pieces `pieces` (paths relative to the `.pvtu`'s folder, as
/// ParaView resolves them), each written by [`write_vtu_with`] with the same
/// `summary` presence and extra arrays: the declared arrays follow the same
/// constants as the pieces', so ParaView's `vtkXMLPUnstructuredGridReader`
/// finds every array it is told of.
pub fn write_pvtu(
    path: &Path,
    pieces: &[String],
    summary: bool,
    extra_cells: &[CellArray],
    extra_points: &[PointArray],
) -> Result<(), IoError> {
    if pieces.is_empty() {
        return Err(IoError::file(path, "a .pvtu needs at least one piece"));
    }
    let decl = |ty: &str, name: &str, c: usize| {
        let comps = if c > 1 {
            format!(" NumberOfComponents=\"{c}\"")
        } else {
            String::new()
        };
        format!(
            "      <PDataArray type=\"{ty}\" Name=\"{}\"{comps}/>",
            xml_escape(name)
        )
    };
    write_atomic(path, |w| {
        writeln!(w, "<?xml version=\"1.0\"?>")?;
        writeln!(
            w,
            "<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">"
        )?;
        writeln!(w, "  <!-- written by tetrefine -->")?;
        writeln!(w, "  <PUnstructuredGrid GhostLevel=\"0\">")?;
        if summary || !extra_points.is_empty() {
            writeln!(w, "    <PPointData>")?;
            if summary {
                writeln!(w, "{}", decl(<i32 as LeBytes>::TYPE, "valence", 1))?;
            }
            for a in extra_points {
                let line = match a {
                    PointArray::Float64(n, c, _) => decl(<f64 as LeBytes>::TYPE, n, *c),
                    PointArray::Int32(n, c, _) => decl(<i32 as LeBytes>::TYPE, n, *c),
                };
                writeln!(w, "{line}")?;
            }
            writeln!(w, "    </PPointData>")?;
        }
        writeln!(w, "    <PCellData Scalars=\"region\">")?;
        writeln!(w, "{}", decl(<i32 as LeBytes>::TYPE, "region", 1))?;
        for name in &STANDARD_CELL_ARRAYS[1..] {
            writeln!(w, "{}", decl(<f64 as LeBytes>::TYPE, name, 1))?;
        }
        for a in extra_cells {
            let line = match a {
                CellArray::Int32(n, _) | CellArray::Int32With(n, ..) => {
                    decl(<i32 as LeBytes>::TYPE, n, 1)
                }
                CellArray::Float64(n, _) => decl(<f64 as LeBytes>::TYPE, n, 1),
                CellArray::Float64Components(n, c, _) => decl(<f64 as LeBytes>::TYPE, n, *c),
            };
            writeln!(w, "{line}")?;
        }
        writeln!(w, "    </PCellData>")?;
        writeln!(w, "    <PPoints>")?;
        writeln!(w, "{}", decl(<f64 as LeBytes>::TYPE, "Points", 3))?;
        writeln!(w, "    </PPoints>")?;
        for p in pieces {
            writeln!(w, "    <Piece Source=\"{}\"/>", xml_escape(p))?;
        }
        writeln!(w, "  </PUnstructuredGrid>\n</VTKFile>")
    })
}
