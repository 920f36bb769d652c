"""meshio and PyVista objects in and out; refinement through meshio objects.
The figures are checked against meshio's own readers and the CLI."""

import numpy as np
import pytest

import tetrefine
from conftest import MESHES, TRIPOD

meshio = pytest.importorskip("meshio")


def test_from_meshio_medit_ref(cli_json):
    src = MESHES / "mmg_tinyBoxt.mesh"
    m = tetrefine.from_meshio(meshio.read(src))  # regions from medit:ref
    ref = cli_json(src)
    q = m.quality()
    for k in ("nodes", "tets", "boundary_faces", "min_dihedral_deg", "regions", "volume"):
        assert q[k] == ref[k], k
    assert len(ref["regions"]) == 2


def test_from_meshio_gmsh_physical(tmp_path, cli, cli_json):
    src = MESHES / "mmg_cube.mesh"  # marked triangles and ridges
    msh = tmp_path / "box.msh"
    cli("convert", src, msh)  # Gmsh 4.1 with physical groups
    mm = meshio.read(msh)
    assert "gmsh:physical" in mm.cell_data
    m = tetrefine.from_meshio(mm)
    assert m.quality()["regions"] == cli_json(src)["regions"]
    assert len(m.boundary_faces) == cli_json(src)["boundary_faces"] == 300
    np.testing.assert_array_equal(m.boundary_markers, tetrefine.read(src).boundary_markers)


def test_to_meshio_round_trip_through_meshio_files(tmp_path):
    m = tetrefine.read(MESHES / "mmg_cube.mesh")  # marked triangles
    out = m.to_meshio()
    assert [b.type for b in out.cells] == ["tetra", "triangle", "line"]
    np.testing.assert_array_equal(out.cell_data["region"][0], m.regions)
    q = m.tet_quality()
    np.testing.assert_array_equal(out.cell_data["quality"][0], q["quality"])
    # meshio writes it (Medit and VTU), tetrefine reads meshio's files back.
    for ext in (".mesh", ".vtu"):
        path = tmp_path / f"m{ext}"
        out.write(path)
        back = tetrefine.read(path)
        np.testing.assert_array_equal(back.regions, m.regions)
        assert back.quality()["min_dihedral_deg"] == m.quality()["min_dihedral_deg"]
    # And from_meshio inverts to_meshio.
    # (Corners have no meshio cell type: they are the one tag lost.)
    again = tetrefine.from_meshio(out)
    q, q0 = again.quality(), m.quality()
    assert q.pop("corners") == 0 and q0.pop("corners") == 8
    assert q == q0
    np.testing.assert_array_equal(again.feature_edges, m.feature_edges)
    np.testing.assert_array_equal(again.boundary_markers, m.boundary_markers)


def test_refinement_through_meshio_objects(tmp_path, cli, cli_json):
    mm = meshio.read(TRIPOD)
    fine = tetrefine.from_meshio(mm).refine()
    out = fine.to_meshio(faces=False)
    # The CLI refines the same file to the same mesh.
    cli_out = tmp_path / "cli.mesh"
    cli("refine", TRIPOD, "-o", cli_out)
    ref = meshio.read(cli_out)
    assert len(out.cells_dict["tetra"]) == len(ref.cells_dict["tetra"]) == fine.n_tets
    np.testing.assert_allclose(out.points, ref.points, rtol=0, atol=1e-12)
    assert fine.quality() == cli_json(cli_out)
    np.testing.assert_array_equal(out.cell_data["level"][0], 1)
    # meshio writes the refined mesh for ParaView.
    out.write(tmp_path / "fine.vtu")
    assert tetrefine.read(tmp_path / "fine.vtu").n_tets == fine.n_tets


def test_to_pyvista():
    pv = pytest.importorskip("pyvista")
    m = tetrefine.read(TRIPOD).refine()
    g = m.to_pyvista()
    assert isinstance(g, pv.UnstructuredGrid)
    assert g.n_cells == m.n_tets and g.n_points == m.n_points
    # VTK's own volume of the cells equals the library's total volume.
    assert g.volume == pytest.approx(m.quality()["volume"], rel=1e-9)
    for k in ("region", "level", "parent", "marked", "min_dihedral", "quality"):
        assert k in g.cell_data
    np.testing.assert_array_equal(g.cell_data["parent"], m.parent)


def test_no_tetra_cells():
    tri = meshio.Mesh(np.eye(3), [("triangle", np.array([[0, 1, 2]]))])
    with pytest.raises(ValueError, match="no tetra cells .*triangle"):
        tetrefine.from_meshio(tri)
