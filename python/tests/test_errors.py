"""Bad input raises ValueError (bad arrays, options), TypeError (wrong
dtype) or OSError (files) with the library's message; a panic in the core
becomes a RuntimeError, never an abort."""

import numpy as np
import pytest

import tetrefine
from conftest import TRIPOD, cube_grid


@pytest.fixture
def grid():
    return cube_grid(2)


def test_wrong_shapes(grid):
    points, tets = grid
    with pytest.raises(ValueError, match=r"points must have shape \(n, 3\), got \(27, 2\)"):
        tetrefine.Mesh(points[:, :2], tets)
    with pytest.raises(ValueError, match=r"tets must have shape \(n, 4\), got \(48, 3\)"):
        tetrefine.Mesh(points, tets[:, :3])
    with pytest.raises(ValueError, match=r"tets must have shape \(n, 4\), got \(192,\)"):
        tetrefine.Mesh(points, tets.ravel())
    with pytest.raises(ValueError, match="regions has 3 values for 48 tets"):
        tetrefine.Mesh(points, tets, regions=[1, 2, 3])
    with pytest.raises(ValueError, match=r"boundary_faces must have shape \(n, 3\)"):
        tetrefine.Mesh(points, tets, boundary_faces=tets)
    with pytest.raises(ValueError, match="boundary_markers has 1 values for 2 boundary_faces"):
        tetrefine.Mesh(points, tets, boundary_faces=[[0, 1, 2], [0, 1, 3]], boundary_markers=[1])


def test_wrong_dtypes(grid):
    points, tets = grid
    with pytest.raises(TypeError, match="tets must hold integers, got dtype float64"):
        tetrefine.Mesh(points, tets.astype(float))
    with pytest.raises(TypeError, match="points must hold real numbers"):
        tetrefine.Mesh(points.astype(complex), tets)


def test_out_of_range_ids(grid):
    points, tets = grid
    bad = tets.copy()
    bad[5, 2] = 27
    with pytest.raises(ValueError) as e:
        tetrefine.Mesh(points, bad)
    # The library's message (1-based, as the file readers say it) and the row.
    assert str(e.value).startswith(
        "tets[5]: tetrahedron 6 refers to point 28 but the mesh has 27 points"
    )
    bad[5, 2] = -1
    with pytest.raises(ValueError, match=r"tets\[5, 2\] is -1: point ids are 0-based"):
        tetrefine.Mesh(points, bad)
    bad[5, 2] = 2**40
    with pytest.raises(ValueError, match=r"tets\[5, 2\] is 1099511627776"):
        tetrefine.Mesh(points, bad)
    with pytest.raises(ValueError, match="refers to point 100 but the mesh has 27 points"):
        tetrefine.Mesh(points, tets, boundary_faces=[[0, 1, 99]])


def test_nan_coordinate(grid):
    points, tets = grid
    p = points.copy()
    p[3, 1] = np.nan
    with pytest.raises(ValueError, match=r"point 4 has a non-finite coordinate \[0.0, NaN, 3.0\]|point 4 has a non-finite coordinate"):
        tetrefine.Mesh(p, tets)
    p[3, 1] = np.inf
    with pytest.raises(ValueError, match="point 4 has a non-finite coordinate"):
        tetrefine.Mesh(p, tets)


def test_inverted_flat_and_broken_tets(grid):
    points, tets = grid
    # An inverted tet that folds over its neighbour: move the one interior
    # point (1, 1, 1) out through the cube's corner region.
    p = points.copy()
    centre = 13  # (1, 1, 1)
    p[centre] = [2.6, 2.6, 2.6]
    with pytest.raises(ValueError, match="overlaps its neighbour across face"):
        tetrefine.Mesh(p, tets)
    # A flat tet.
    flat = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=float)
    with pytest.raises(ValueError, match=r"tets\[0\]: tetrahedron 1 has zero volume: its four points are coplanar"):
        tetrefine.Mesh(flat, [[0, 1, 2, 3]])
    with pytest.raises(ValueError, match=r"repeats a vertex \[1, 2, 2, 3\]"):
        tetrefine.Mesh(points, [[0, 1, 1, 2]])
    with pytest.raises(ValueError, match="tetrahedron 49 duplicates tetrahedron 1"):
        tetrefine.Mesh(points, np.vstack([tets, tets[:1, ::-1]]))
    with pytest.raises(ValueError, match="the mesh has no tetrahedra"):
        tetrefine.Mesh(points, np.zeros((0, 4), dtype=int))


def test_bad_options():
    m = tetrefine.read(TRIPOD)
    eta = np.ones(m.n_tets)
    cases = [
        (dict(indicator=eta[:-1]), "the indicator has 2798 values but the mesh has 2799 tets"),
        (dict(indicator=np.where(np.arange(m.n_tets) == 7, np.nan, 1.0)),
         "indicator value NaN of tet 7 is not a finite number >= 0"),
        (dict(indicator=-eta), "is not a finite number >= 0"),
        (dict(indicator=eta.reshape(-1, 1)), r"indicator must have shape \(n_tets,\)"),
        (dict(mark="fraction:0.1"), "needs an indicator array"),
        (dict(indicator=eta, mark="fraction:2"), "fraction:F needs F in \\(0,1\\], found 2"),
        (dict(indicator=eta, mark="bogus:1"), "mark=\"bogus:1\""),
        (dict(box=[0, 0, 0]), "box:x0,y0,z0,x1,y1,z1 needs 6 comma-separated numbers, found 3"),
        (dict(sphere=[0, 0, 0, -1]), "sphere"),
        (dict(boundary="cubic"), "unknown boundary rule 'cubic'"),
        (dict(interfaces="smooth"), "unknown interface rule 'smooth'; one of linear, sqrt3"),
        (dict(stop_after="later"), "unknown phase 'later'"),
        (dict(threshold=1.5), r"threshold=1.5 must lie in \(0, 1\)"),
        (dict(feature_angle=0), r"feature_angle=0 must lie in \(0, 180\)"),
        (dict(smooth="some"), "use 'refined' or 'all'"),
    ]
    for kwargs, msg in cases:
        with pytest.raises(ValueError, match=msg):
            m.refine(**kwargs)
    with pytest.raises(ValueError, match="bins must be between 1 and 10000"):
        m.quality(bins=0)


def test_nothing_to_refine_is_an_error_unless_allowed():
    m = tetrefine.read(TRIPOD)
    # A sphere far outside the tripod's bounding box holds no centroid.
    far = [1e6, 1e6, 1e6, 1.0]
    with pytest.raises(ValueError, match="selects none of the 2799 tets"):
        m.refine(sphere=far)
    with pytest.raises(ValueError, match="steps=0 refines nothing"):
        m.refine(0)
    for same in (m.refine(sphere=far, allow_empty=True), m.refine(0, allow_steps_zero=True)):
        assert same.n_tets == m.n_tets
        # The store renumbers (compact orders points along a curve), so
        # compare the point sets.
        assert np.array_equal(np.unique(same.points, axis=0), np.unique(m.points, axis=0))


def test_file_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="no such file"):
        tetrefine.read(tmp_path / "missing.mesh")
    bad = tmp_path / "bad.mesh"
    bad.write_text("MeshVersionFormatted 2\nDimension 3\nVertices\n2\n0 0 0 0\nbroken\n")
    with pytest.raises(OSError, match=r"bad\.mesh:\d+: "):
        tetrefine.read(bad)
    with pytest.raises(OSError, match="unknown mesh extension '.xyz'"):
        (tmp_path / "a.xyz").write_text("x")
        tetrefine.read(tmp_path / "a.xyz")
    m = tetrefine.read(TRIPOD)
    with pytest.raises(OSError, match="cannot write '.xyz'"):
        m.write(tmp_path / "out.xyz")
    with pytest.raises(OSError, match="cannot write"):
        m.write(tmp_path / "no" / "such" / "dir" / "out.mesh")
    assert not (tmp_path / "out.xyz").exists()
    with pytest.raises(OSError, match="missing.txt"):
        m.refine(features=str(tmp_path / "missing.txt"))


def test_panic_becomes_runtime_error():
    with pytest.raises(RuntimeError, match="internal error .*deliberate panic for the tests"):
        tetrefine._core._panic_for_tests()
    # The interpreter survives and the library still works.
    assert tetrefine.read(TRIPOD).n_tets == 2799
