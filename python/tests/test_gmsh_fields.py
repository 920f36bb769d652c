"""Cell fields in Gmsh files, read by meshio (issue 17): `tetrefine refine`
carries a Gmsh `$ElementData` view over by parent and writes `$ElementData`
with a value for every element of the file, as meshio needs (it reads the
values in file order over all element blocks): the tets their values, the
boundary triangles, feature lines and corner points NaN. The expected
values are worked out from the geometry, not by tetrefine: Gmsh's "density"
view is 7.85 in the box x < 1 and 8.96 in the box x > 1
(tests/data/make_gmsh_tagged.py), and every child tet lies in its parent's
box. Runs the CLI only (no import of the package)."""

import numpy as np
import pytest

meshio = pytest.importorskip("meshio")

from conftest import REPO

GMSH_INPUT = REPO / "tests" / "data" / "gmsh_tagged_v41.msh"


def density_of(points, tets):
    """7.85 for tets whose centroid has x < 1, else 8.96."""
    x = points[tets].mean(axis=1)[:, 0]
    return np.where(x < 1.0, 7.85, 8.96)


def check_density(m, what):
    """Every tetra block has the density of its tets' box; every other block
    (triangle, line, vertex) NaN. Returns the number of tets."""
    assert "density" in m.cell_data, (what, list(m.cell_data))
    assert len(m.cell_data["density"]) == len(m.cells), what
    n_tets = 0
    kinds = set()
    for block, values in zip(m.cells, m.cell_data["density"]):
        assert len(values) == len(block.data), (what, block.type)
        kinds.add(block.type)
        if block.type == "tetra":
            want = density_of(m.points, block.data)
            assert np.array_equal(values, want), (what, block.type)
            n_tets += len(values)
        else:
            assert np.isnan(values).all(), (what, block.type, values[:5])
    assert {"tetra", "triangle"} <= kinds, (what, kinds)
    return n_tets


def input_centroids(cli, tmp_path):
    """The centroids of the input's tets (meshio cannot read the input
    itself: Gmsh wrote its views for the tets alone)."""
    vtu = tmp_path / "input.vtu"
    cli("convert", GMSH_INPUT, vtu)
    src = meshio.read(vtu)
    return np.concatenate(
        [src.points[b.data].mean(axis=1) for b in src.cells if b.type == "tetra"]
    )


# MSH 2.2 is left out: meshio 5.3's MSH 2.2 reader splits $ElementData at
# the wrong places whenever a file has more than one element type (it takes
# the length of each (type, array) pair, 2, for the block's size: meshio
# issue #1257, open), so no MSH 2.2 file with boundary triangles can give
# meshio its cell data. Gmsh reads tetrefine's MSH 2.2 cell data
# (tests/gmsh_roundtrip.py), as does tetrefine (tests/cli/gmsh_tags.rs).
@pytest.mark.parametrize("fmt", ["4.1", "4.1-binary"])
def test_meshio_reads_the_element_data_of_a_refined_gmsh_file(tmp_path, cli, fmt):
    out = tmp_path / "out.msh"
    cli("refine", GMSH_INPUT, "-o", out, "--msh-format", fmt)
    m = meshio.read(out)
    n_tets = check_density(m, fmt)
    # The √3 step splits every tet in three at least (1,455 in the input).
    assert n_tets > 3 * 1455, (fmt, n_tets)
    # The 3-component view: a centroid of an input tet for every tet, NaN
    # elsewhere.
    centroids = input_centroids(cli, tmp_path)
    assert len(centroids) == 1455
    for block, values in zip(m.cells, m.cell_data["centroid"]):
        assert values.shape == (len(block.data), 3), (fmt, block.type)
        if block.type != "tetra":
            assert np.isnan(values).all(), (fmt, block.type)
            continue
        d = np.abs(values[:, None, :] - centroids[None, :, :]).max(axis=2).min(axis=1)
        assert d.max() <= 1e-12, (fmt, d.max())
    # The point view, linear, to round-off at every output point.
    x, y, z = m.points.T
    t = m.point_data["temperature"]
    assert np.abs(t - (1 + 2 * x - 3 * y + 0.5 * z)).max() <= 1e-9, fmt


def test_element_data_meshio_writes_is_read_and_carried_over(tmp_path, cli):
    # meshio writes a value for every element; here -1 at the triangles,
    # which tetrefine skips (they are no cells of the mesh), taking the tets'
    # values and carrying them over by parent. (Only meshio's binary MSH 2.2
    # is used: its ASCII MSH 2.2 writer prints numpy 2 scalars as
    # "np.float64(...)", and its MSH 4.1 writer puts the triangles on a
    # surface entity its $Entities does not define.)
    src = tmp_path / "src.msh"
    cli("convert", GMSH_INPUT, src)
    m = meshio.read(src)
    keep = [i for i, b in enumerate(m.cells) if b.type in ("tetra", "triangle")]
    cells = [m.cells[i] for i in keep]
    cell_data = {
        k: [m.cell_data[k][i] for i in keep]
        for k in ("density", "gmsh:physical", "gmsh:geometrical")
    }
    cell_data["density"] = [
        v if b.type == "tetra" else np.full(len(v), -1.0)
        for b, v in zip(cells, cell_data["density"])
    ]
    written = tmp_path / "meshio_v22_binary.msh"
    meshio.write(
        written,
        meshio.Mesh(m.points, cells, cell_data=cell_data),
        file_format="gmsh22",
        binary=True,
    )
    out = tmp_path / "out.vtu"
    cli("refine", written, "-o", out)
    r = meshio.read(out)
    tets = np.concatenate([b.data for b in r.cells if b.type == "tetra"])
    got = np.concatenate(
        [v for b, v in zip(r.cells, r.cell_data["density"]) if b.type == "tetra"]
    )
    assert len(got) > 3 * 1455
    assert np.array_equal(got, density_of(r.points, tets))
