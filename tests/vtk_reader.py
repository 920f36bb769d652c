"""Reads a .vtu written by `tetrefine convert meshes/tripod.mesh X.vtu` with
VTK's own XML reader (the code ParaView runs) and checks what tetrefine
promises to write: 2,799 tetrahedra (VTK cell type 10), the cell arrays
region (Int32), min_dihedral, max_dihedral, quality and volume (Float64), the
point array valence (Int32) and the field data histogram_counts and
histogram_edges_deg, each with the right length.

Usage: python3 tests/vtk_reader.py X.vtu     (needs `pip install vtk`)
"""

import sys

import vtk

TETS = 2799  # the tripod (DESIGN.md section 4)
NODES = 967


def main(path):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    if reader.GetErrorCode() != 0:
        sys.exit(f"{path}: VTK reader error {reader.GetErrorCode()}")
    grid = reader.GetOutput()
    assert grid.GetNumberOfCells() == TETS, grid.GetNumberOfCells()
    assert grid.GetNumberOfPoints() == NODES, grid.GetNumberOfPoints()
    for i in range(grid.GetNumberOfCells()):
        assert grid.GetCellType(i) == vtk.VTK_TETRA, (i, grid.GetCellType(i))

    def check(data, name, vtk_type, tuples):
        array = data.GetArray(name)
        assert array is not None, f"array {name} missing"
        assert array.GetDataType() == vtk_type, (name, array.GetDataTypeAsString())
        assert array.GetNumberOfTuples() == tuples, (name, array.GetNumberOfTuples())
        assert array.GetNumberOfComponents() == 1, name
        return array

    cells = grid.GetCellData()
    check(cells, "region", vtk.VTK_INT, TETS)
    for name in ["min_dihedral", "max_dihedral", "quality", "volume"]:
        check(cells, name, vtk.VTK_DOUBLE, TETS)
    valence = check(grid.GetPointData(), "valence", vtk.VTK_INT, NODES)
    # Valence counts incident edges: max 27 for the tripod (DESIGN.md section 4).
    assert valence.GetRange()[1] == 27, valence.GetRange()

    fields = grid.GetFieldData()
    counts = fields.GetArray("histogram_counts")
    edges = fields.GetArray("histogram_edges_deg")
    assert counts is not None and edges is not None, "field data missing"
    assert counts.GetDataType() in (vtk.VTK_LONG_LONG, vtk.VTK_LONG, vtk.VTK_ID_TYPE), counts.GetDataTypeAsString()
    assert edges.GetDataType() == vtk.VTK_DOUBLE, edges.GetDataTypeAsString()
    assert edges.GetNumberOfTuples() == counts.GetNumberOfTuples() + 1
    total = sum(counts.GetValue(i) for i in range(counts.GetNumberOfTuples()))
    assert total == TETS, total
    # Volume: all tets positive.
    volume = cells.GetArray("volume")
    assert volume.GetRange()[0] > 0, volume.GetRange()
    print(f"{path}: VTK {vtk.vtkVersion.GetVTKVersion()} reads {TETS} tets and every array: ok")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
