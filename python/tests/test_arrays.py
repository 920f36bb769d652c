"""numpy in and out: any integer dtype, float32/64, any strides; read-only
views back; the arrays of a mesh file equal meshio's reading of it."""

import numpy as np
import pytest

import tetrefine
from conftest import TRIPOD, cube_grid


def canonical(tets):
    """Tets as a sorted array of sorted rows (orientation-free)."""
    return np.array(sorted(map(tuple, np.sort(np.asarray(tets), axis=1))))


@pytest.mark.parametrize(
    "dtype", [np.int8, np.int16, np.int32, np.int64, np.uint8, np.uint16, np.uint32, np.uint64]
)
@pytest.mark.parametrize("fdtype", [np.float32, np.float64])
def test_round_trip_every_dtype(dtype, fdtype):
    points, tets = cube_grid(2)  # 27 points: ids fit in int8
    regions = np.arange(len(tets)) % 3
    m = tetrefine.Mesh(points.astype(fdtype), tets.astype(dtype), regions=regions.astype(dtype))
    assert m.n_tets == 48 and m.n_points == 27
    np.testing.assert_array_equal(m.points, points)
    assert m.points.dtype == np.float64 and m.tets.dtype == np.uint32
    # Same tets (orientation fixed by the library), same order, same regions.
    np.testing.assert_array_equal(np.sort(m.tets, axis=1), np.sort(tets, axis=1))
    np.testing.assert_array_equal(m.regions, regions)
    np.testing.assert_array_equal(m.level, 0)
    np.testing.assert_array_equal(m.parent, np.arange(48))
    assert not m.marked.any()
    q = m.quality()
    assert q["tets"] == 48 and q["inverted"] == 0
    assert q["volume"] == pytest.approx(8.0, rel=1e-12)  # closed form: (2h)³


def test_strided_and_list_input():
    points, tets = cube_grid(3)
    # Fortran order, a strided slice of a wider array, and plain lists.
    wide = np.zeros((len(tets), 8), dtype=np.int64)
    wide[:, ::2] = tets
    a = tetrefine.Mesh(np.asfortranarray(points), wide[:, ::2])
    b = tetrefine.Mesh(points.tolist(), tets.tolist())
    np.testing.assert_array_equal(a.tets, b.tets)
    np.testing.assert_array_equal(a.points, b.points)


def test_views_are_read_only_and_not_copies():
    m = tetrefine.read(TRIPOD)
    p, t = m.points, m.tets
    assert not p.flags.writeable and not t.flags.writeable
    with pytest.raises(ValueError):
        p[0, 0] = 1.0
    # The same memory each time: views of the mesh, no copies.
    assert np.shares_memory(m.points, p) and np.shares_memory(m.tets, t)
    for a in (m.regions, m.level, m.parent, m.marked, m.boundary_faces, m.feature_edges):
        assert not a.flags.writeable
    # A view keeps its mesh alive.
    del m
    assert p.shape == (967, 3) and float(np.abs(p).sum()) > 0


def test_arrays_equal_meshio_reading():
    meshio = pytest.importorskip("meshio")
    m = tetrefine.read(TRIPOD)
    ref = meshio.read(TRIPOD)  # an independent reader of the same file
    np.testing.assert_array_equal(m.points, ref.points)
    np.testing.assert_array_equal(canonical(m.tets), canonical(ref.cells_dict["tetra"]))


def test_rebuilt_from_own_arrays_is_the_same_mesh():
    m = tetrefine.read(TRIPOD)
    again = tetrefine.Mesh(
        m.points,
        m.tets,
        regions=m.regions,
        boundary_faces=m.boundary_faces,
        boundary_markers=m.boundary_markers,
        feature_edges=m.feature_edges,
    )
    assert again.quality() == m.quality()
    np.testing.assert_array_equal(again.boundary_faces, m.boundary_faces)
    np.testing.assert_array_equal(again.boundary_markers, m.boundary_markers)
    np.testing.assert_array_equal(again.feature_edges, m.feature_edges)


def test_negative_tet_is_turned_around_with_a_warning():
    points, tets = cube_grid(1)
    tets = tets.copy()
    tets[2, [0, 1]] = tets[2, [1, 0]]  # one tet given inside out
    with pytest.warns(UserWarning, match="1 tetrahedra were negatively oriented"):
        m = tetrefine.Mesh(points, tets)
    assert m.build_notes["reoriented"] == 1
    # Every tet positive: signed volumes from numpy, not from the library.
    p = m.points[m.tets.astype(np.int64)]
    vol = np.einsum("ij,ij->i", p[:, 1] - p[:, 0], np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]))
    np.testing.assert_allclose(vol, 1.0)  # 6 × the volume 1/6 of each tet
    assert m.quality()["inverted"] == 0


def test_boundary_markers_and_features_in():
    points, tets = cube_grid(1)
    m0 = tetrefine.Mesh(points, tets)
    # Mark every boundary face of the unit cube with the axis of its normal.
    faces = []
    for t in tets:
        for f in range(4):
            tri = np.delete(t, f)
            c = points[tri]
            for axis in range(3):
                if np.all(c[:, axis] == c[0, axis]):
                    faces.append((tri, axis + 1))
    tri = np.array([f for f, _ in faces])
    mk = np.array([k for _, k in faces])
    m = tetrefine.Mesh(points, tets, boundary_faces=tri, boundary_markers=mk,
                       feature_edges=[[0, 1]], corners=[0])
    assert len(m.boundary_faces) == 12 == m.quality()["boundary_faces"]
    assert sorted(np.bincount(m.boundary_markers)[1:]) == [4, 4, 4]
    np.testing.assert_array_equal(m.feature_edges, [[0, 1]])
    np.testing.assert_array_equal(m.corners, [0])
    assert len(m0.boundary_faces) == 0
