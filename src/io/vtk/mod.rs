//! VTK XML unstructured grid `.vtu` (the "VTK File Formats" chapter of the VTK
//! User's Guide, Kitware), read and written.
//!
//! Read: ASCII, inline binary and appended (raw or base64) data arrays, zlib
//! compressed or not, `UInt32` or `UInt64` headers, either byte order; several
//! pieces are concatenated. Tetrahedra (VTK cell type 10) are kept, and
//! triangles (type 5) become marked boundary faces (their region value is the
//! marker); other cells are dropped, which [`read_noted`] reports. Everything
//! the file declares is held against what it holds: `NumberOfPoints` and
//! `NumberOfCells` against the decoded array lengths, offsets monotone and
//! ending at the connectivity length, cell types in VTK's set with their
//! point counts, point ids in range, the block headers against the bytes
//! present, and raw appended arrays tiling the appended data exactly. The
//! cell array `region` (any integer or float type,
//! integral values) gives the regions; without it, meshio's `gmsh:physical`,
//! `medit:ref` or `CellEntityIds` is used if present.
//!
//! Written: zlib-compressed (fastest level: float data hardly compresses
//! further) inline binary, `UInt64` headers, read by VTK's
//! `vtkXMLUnstructuredGridReader` (and so ParaView) and meshio. Cell arrays
//! `region` (Int32), `min_dihedral`, `max_dihedral` (Float64, degrees),
//! `quality` (Float64, minimum sine of the signed dihedral angles, as in the
//! √3 refinement paper), `volume` (Float64), any extra [`CellArray`]s; point
//! array `valence` (Int32, incident edges) and field data `histogram_counts`
//! (Int64) and `histogram_edges_deg` (Float64) when the caller passes a
//! [`VtuSummary`] (the statistics are computed outside `io`).
//!
//! [`read_tet_cell_array`] reads one numeric cell array (an error indicator,
//! say) at the tetrahedra of a file, in the order [`read`] lists them.

mod decode;
mod pvtu;
mod read;
mod write;
mod xml;

pub use pvtu::read_pvtu_pieces;
pub use read::{
    read_noted, read_tet_cell_array, read_with_meta_noted, TetCellArray, DERIVED_CELL_ARRAYS,
    DERIVED_POINT_ARRAYS,
};
pub use write::{write_pvtu, write_vtu, write_vtu_with, CellArray, PointArray, VtuSummary};

/// VTK's cell type of a linear tetrahedron.
const VTK_TETRA: u8 = 10;
