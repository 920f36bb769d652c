"""Reads a .pvtu written by `mpirun -n P tetrefine refine meshes/tripod.vtu
X.pvtu --boundary linear` with VTK's own parallel reader (the code ParaView
runs) and checks it against the input read by VTK itself: every piece is
found, the tets are VTK tetrahedra with positive volumes (VTK's
vtkCellSizeFilter) summing to the input's volume (the linear rule keeps the
domain), the arrays region, quality, rank and GlobalPointIds are there, the
rank count P is the number of pieces VTK finds in the .pvtu, the ranks are
0 .. P-1, each piece (read alone by VTK's serial reader, in the .pvtu's
order) is non-empty and holds rank r's tets only, and the global ids
number the points of the union densely (0 .. n-1, a point on the cut once,
one id per distinct coordinates). When the pieces carry the
vertex parent map (a run with --parent-map, --fields or --transfer), every
point is its parent_bary combination of the parent_vertices of the input as
VTK reads it.

Usage: python3 tests/vtk_pvtu_reader.py X.pvtu INPUT.vtu     (needs `pip install vtk`)
"""

import os
import sys
import xml.etree.ElementTree as ET

import vtk
from vtk.util.numpy_support import vtk_to_numpy


def volume(grid):
    f = vtk.vtkCellSizeFilter()
    f.SetInputData(grid)
    f.ComputeVolumeOn()
    f.Update()
    v = vtk_to_numpy(f.GetOutput().GetCellData().GetArray("Volume"))
    assert v.min() > 0, v.min()
    return v.sum()


def main(pvtu, original):
    reader = vtk.vtkXMLPUnstructuredGridReader()
    reader.SetFileName(pvtu)
    reader.Update()
    if reader.GetErrorCode() != 0:
        sys.exit(f"{pvtu}: VTK reader error {reader.GetErrorCode()}")
    grid = reader.GetOutput()
    n = grid.GetNumberOfCells()
    assert n > 0
    assert all(grid.GetCellType(i) == vtk.VTK_TETRA for i in range(n))
    cells = grid.GetCellData()
    for name in ["region", "quality", "min_dihedral", "rank", "level", "parent"]:
        a = cells.GetArray(name)
        assert a is not None and a.GetNumberOfTuples() == n, name
    n_pieces = reader.GetNumberOfPieces()
    assert n_pieces >= 1, n_pieces
    ranks = sorted(set(vtk_to_numpy(cells.GetArray("rank")).tolist()))
    assert ranks == list(range(n_pieces)), (ranks, n_pieces)
    # Each piece alone: the .pvtu lists piece r as rank r's file.
    sources = [e.get("Source") for e in ET.parse(pvtu).getroot().iter("Piece")]
    assert len(sources) == n_pieces, (sources, n_pieces)
    total = 0
    for r, src in enumerate(sources):
        piece = vtk.vtkXMLUnstructuredGridReader()
        piece.SetFileName(os.path.join(os.path.dirname(pvtu), src))
        piece.Update()
        if piece.GetErrorCode() != 0:
            sys.exit(f"{src}: VTK reader error {piece.GetErrorCode()}")
        pc = piece.GetOutput().GetNumberOfCells()
        assert pc > 0, f"{src}: an empty piece"
        own = set(vtk_to_numpy(piece.GetOutput().GetCellData().GetArray("rank")).tolist())
        assert own == {r}, (src, own)
        total += pc
    assert total == n, (total, n)
    gids = grid.GetPointData().GetArray("GlobalPointIds")
    assert gids is not None
    g = vtk_to_numpy(gids)
    unique = sorted(set(g.tolist()))
    assert unique == list(range(len(unique))), "global ids are not 0..n-1"
    # Points on the cut appear once per piece holding them.
    assert len(g) > len(unique), (len(g), len(unique))
    # One id per distinct point of the union, and one point per id.
    ids_at = {}
    for p, i in zip(map(tuple, vtk_to_numpy(grid.GetPoints().GetData()).tolist()), g.tolist()):
        ids_at.setdefault(p, set()).add(i)
    assert all(len(i) == 1 for i in ids_at.values()), "a point with two global ids"
    assert len(ids_at) == len(unique), (len(ids_at), len(unique))

    inp = vtk.vtkXMLUnstructuredGridReader()
    inp.SetFileName(original)
    inp.Update()
    bary = grid.GetPointData().GetArray("parent_bary")
    if bary is not None:
        verts = vtk_to_numpy(grid.GetPointData().GetArray("parent_vertices"))
        b = vtk_to_numpy(bary)
        x_in = vtk_to_numpy(inp.GetOutput().GetPoints().GetData())
        x = vtk_to_numpy(grid.GetPoints().GetData())
        rebuilt = (b[:, :, None] * x_in[verts]).sum(axis=1)
        err = abs(rebuilt - x).max()
        assert err <= 1e-9 * max(1.0, abs(x).max()), err
        print(f"{pvtu}: parent_bary rebuilds every point (max error {err:.2g})")
    v_in, v_out = volume(inp.GetOutput()), volume(grid)
    assert abs(v_in - v_out) <= 1e-9 * v_in, (v_in, v_out)
    print(f"{pvtu}: VTK {vtk.vtkVersion.GetVTKVersion()} reads {n} tets in {n_pieces} pieces, "
          f"{len(unique)} global points, volume {v_out:.6g} = input's: ok")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
