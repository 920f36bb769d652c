"""The solver's loop in Python (issue 17): Mesh.refine carries point and
cell fields over and gives the vertex parent map, as `tetrefine refine
--transfer` does, and refines to an MMG size map (size=, hsiz=, hmax=), as
`--size-array/--hsiz/--hmax` do. Expected values are closed forms: a field
linear in x, y, z; a cell field that is a function of the parent's index; a
target size linear in x."""

import numpy as np
import pytest

import tetrefine
from conftest import TRIPOD, cube_grid


def f(p):
    return 2.0 + 0.5 * p[:, 0] - 1.5 * p[:, 1] + 0.25 * p[:, 2]


def vec(p):
    return np.stack([p[:, 0] - p[:, 1], 3.0 * p[:, 2], -1.0 + p[:, 0]], axis=1)


def edges(mesh):
    """The unique edges of the tets, (e, 2)."""
    t = mesh.tets
    e = np.concatenate([t[:, [a, b]] for a, b in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]])
    return np.unique(np.sort(e, axis=1), axis=0)


def test_a_linear_point_field_through_two_refinements_is_exact():
    m = tetrefine.read(TRIPOD)
    m1 = m.refine(point_fields={"f": f(m.points), "v": vec(m.points)}, boundary="linear")
    # The second refinement carries the first one's fields over by default.
    m2 = m1.refine(boundary="linear")
    for mesh in (m1, m2):
        assert set(mesh.point_fields) == {"f", "v"}
        got = mesh.point_fields["f"]
        assert got.shape == (mesh.n_points,)
        assert np.abs(got - f(mesh.points)).max() <= 1e-9
        v = mesh.point_fields["v"]
        assert v.shape == (mesh.n_points, 3)
        assert np.abs(v - vec(mesh.points)).max() <= 1e-9
        assert not mesh.point_fields["f"].flags.writeable
    assert m2.n_points > m1.n_points > m.n_points
    # The vertex parent map rebuilds every point from its input tet's corners.
    vp = m2.vertex_parents
    assert vp["tet"].shape == (m2.n_points,)
    assert np.array_equal(vp["vertices"], m1.tets[vp["tet"]])
    assert np.allclose(vp["bary"].sum(axis=1), 1.0, atol=1e-12)
    rebuilt = np.einsum("pk,pkx->px", vp["bary"], m1.points[vp["vertices"]])
    # (Points flagged "outside" lie on the input boundary to round-off: their
    # nearest boundary point is themselves.)
    assert np.abs(rebuilt - m2.points).max() <= 1e-9


def test_cell_fields_follow_parent_and_fields_can_be_dropped():
    m = tetrefine.read(TRIPOD)
    c = 1.5 * np.arange(m.n_tets)
    two = np.stack([c, -c], axis=1)
    r = m.refine(cell_fields={"c": c, "two": two}, opt_passes=0)
    assert np.array_equal(r.cell_fields["c"], 1.5 * r.parent.astype(float))
    assert np.array_equal(r.cell_fields["two"], np.stack([1.5 * r.parent, -1.5 * r.parent], axis=1))
    assert r.point_fields == {}
    dropped = r.refine(transfer=False, opt_passes=0)
    assert dropped.cell_fields == {} and dropped.vertex_parents is None
    # Without fields there is no map unless asked for.
    assert m.refine(opt_passes=0).vertex_parents is None
    assert m.refine(opt_passes=0, vertex_parents=True).vertex_parents["tet"].shape[0] > m.n_points


def test_bad_fields_and_sizes_are_value_errors():
    m = tetrefine.read(TRIPOD)
    n = m.n_points
    bad = [
        (dict(point_fields={"f": np.zeros(n - 1)}), "rows but the mesh has"),
        (dict(point_fields={"f": np.r_[np.zeros(n - 1), np.nan]}), "not a finite number"),
        (dict(cell_fields={"c": np.zeros(m.n_tets + 1)}), "rows but the mesh has"),
        (dict(transfer=True), "carries no point or cell field"),
        (dict(size=np.r_[np.ones(n - 1), 0.0]), "not a positive size"),
        (dict(size=np.tile([1.0, 2.0, 1.0, 0.0, 0.0, 1.0], (n, 1))), "positive-definite metric"),
        (dict(size=np.ones((n, 2))), "2 components"),
        (dict(size=np.ones(n - 2)), "rows but the mesh has"),
        (dict(hsiz=-1.0), "must be a positive length"),
        (dict(hsiz=1.0, size=np.ones(n)), "give one size"),
        (dict(hsiz=1.0, indicator=np.ones(m.n_tets)), "chooses what to refine itself"),
        (dict(steps="auto"), "meets a size map"),
    ]
    for kwargs, words in bad:
        with pytest.raises(ValueError, match=words):
            m.refine(**kwargs)


def test_a_size_map_is_met():
    # A 3x3x3 grid of unit cubes; target h(x) = 0.35 + 0.1 x, linear, so the
    # target at any point is known in closed form.
    points, tets = cube_grid(3)
    m = tetrefine.Mesh(points, tets)
    h = lambda p: 0.35 + 0.1 * p[:, 0]  # noqa: E731
    r = m.refine(size=h(points))
    e = edges(r)
    a, b = r.points[e[:, 0]], r.points[e[:, 1]]
    length = np.linalg.norm(b - a, axis=1)
    target = 0.5 * (h(a) + h(b))
    assert (length <= 1.5 * target).all(), (length / target).max()
    assert r.reports[-1]["long_after"] == 0
    # hsiz: one target; hmax alone is the same map.
    for kwargs in (dict(hsiz=0.5), dict(hmax=0.5)):
        r = m.refine(**kwargs)
        e = edges(r)
        length = np.linalg.norm(r.points[e[:, 1]] - r.points[e[:, 0]], axis=1)
        assert length.max() <= 1.5 * 0.5, (kwargs, length.max())
    # hmax caps a coarser map.
    r = m.refine(size=np.full(len(points), 2.0), hmax=0.6)
    e = edges(r)
    assert np.linalg.norm(r.points[e[:, 1]] - r.points[e[:, 0]], axis=1).max() <= 1.5 * 0.6


def test_hsiz_equals_the_cli(tmp_path, cli, cli_json):
    out = tmp_path / "out.mesh"
    cli("refine", TRIPOD, "-o", out, "--hsiz", "4")
    r = tetrefine.read(TRIPOD).refine(hsiz=4.0)
    assert r.quality() == cli_json(out)
