"""Indicator arrays with every marking strategy. The expected selections are
computed here in numpy from the strategies' definitions (closed forms), and
checked against what the library split: with stop_after='split' every
child's centroid lies in its parent, so the parents of the level-1 tets are
exactly the selected tets, and the step splits exactly them (n + 3k tets)."""

import math

import numpy as np
import pytest

import tetrefine
from conftest import MESHES, TRIPOD


@pytest.fixture(scope="module")
def tripod():
    return tetrefine.read(TRIPOD)


@pytest.fixture(scope="module")
def eta(tripod):
    # A smooth indicator with ties: distance of the centroid from a point,
    # rounded to 1 decimal.
    c = tripod.points[tripod.tets.astype(np.int64)].mean(axis=1)
    return np.round(np.linalg.norm(c - c.mean(axis=0) - [5.0, 0, 0], axis=1), 1)


def order(eta):
    """Descending by value, ties by ascending tet id (the library's rule)."""
    return np.lexsort((np.arange(len(eta)), -eta))


def expected(spec, eta, mesh):
    name, _, arg = spec.partition(":")
    n = len(eta)
    c = mesh.points[mesh.tets.astype(np.int64)].mean(axis=1)
    if name == "fraction":
        return set(order(eta)[: math.ceil(float(arg) * n)])
    if name == "doerfler":
        s = eta[order(eta)] ** 2
        k = int(np.searchsorted(np.cumsum(s), float(arg) * s.sum() * (1 - 1e-15))) + 1
        return set(order(eta)[:k])
    if name == "max":
        return set(np.flatnonzero(eta >= float(arg) * eta.max()))
    if name == "threshold":
        return set(np.flatnonzero(eta >= float(arg)))
    if name == "region":
        ids = [int(x) for x in arg.split(",")]
        return set(np.flatnonzero(np.isin(mesh.regions, ids)))
    if name == "box":
        b = np.array(arg.split(","), dtype=float).reshape(2, 3)
        lo, hi = b.min(axis=0), b.max(axis=0)
        return set(np.flatnonzero(((c >= lo) & (c <= hi)).all(axis=1)))
    if name == "sphere":
        x = np.array(arg.split(","), dtype=float)
        return set(np.flatnonzero(np.linalg.norm(c - x[:3], axis=1) <= x[3]))
    raise AssertionError(spec)


def selected_by_library(fine):
    return set(fine.parent[fine.level == 1].tolist())


@pytest.mark.parametrize(
    "mark", ["fraction:0.1", "doerfler:0.5", "doerfler:0.9", "max:0.8", "threshold:20"]
)
def test_indicator_strategies(tripod, eta, mark):
    want = expected(mark, eta, tripod)
    assert 0 < len(want) < tripod.n_tets
    fine = tripod.refine(indicator=eta, mark=mark, stop_after="split")
    assert fine.reports[0]["split"] == len(want)
    assert fine.n_tets == tripod.n_tets + 3 * len(want)
    assert selected_by_library(fine) == want
    assert fine.marked.sum() == 4 * len(want)


def test_default_mark_is_doerfler_half(tripod, eta):
    fine = tripod.refine(indicator=eta, stop_after="split")
    assert selected_by_library(fine) == expected("doerfler:0.5", eta, tripod)


def test_indicator_dtypes(tripod, eta):
    a = tripod.refine(indicator=eta.astype(np.float32), mark="fraction:0.05", stop_after="split")
    b = tripod.refine(indicator=(eta * 10).astype(np.int32), mark="fraction:0.05",
                      stop_after="split")
    want32 = expected("fraction:0.05", eta.astype(np.float32).astype(np.float64), tripod)
    assert selected_by_library(a) == want32
    assert selected_by_library(b) == expected("fraction:0.05", (eta * 10).astype(np.int32), tripod)


def test_geometric_selections_and_union(tripod, eta):
    lo, hi = tripod.points.min(axis=0), tripod.points.max(axis=0)
    mid = (lo + hi) / 2
    box = [*lo, *mid]
    sphere = [*mid, float(np.linalg.norm(hi - lo)) / 5]
    box_spec = "box:" + ",".join(map(str, box))
    sph_spec = "sphere:" + ",".join(map(str, sphere))
    f = tripod.refine(box=box, stop_after="split")
    assert selected_by_library(f) == expected(box_spec, eta, tripod)
    f = tripod.refine(sphere=sphere, stop_after="split")
    assert selected_by_library(f) == expected(sph_spec, eta, tripod)
    f = tripod.refine(region=0, stop_after="split")
    assert selected_by_library(f) == expected("region:0", eta, tripod)
    # A union: an indicator strategy and a sphere.
    f = tripod.refine(indicator=eta, mark=["fraction:0.02", sph_spec], stop_after="split")
    assert selected_by_library(f) == expected("fraction:0.02", eta, tripod) | expected(
        sph_spec, eta, tripod
    )


def test_regions_on_a_two_region_mesh():
    m = tetrefine.read(MESHES / "mmg_tinyBoxt.mesh")
    r = sorted(set(m.regions.tolist()))
    assert len(r) == 2
    f = m.refine(region=r[1], stop_after="split")
    assert selected_by_library(f) == set(np.flatnonzero(m.regions == r[1]))


def test_full_adaptive_step_marks_and_levels(tripod, eta):
    fine = tripod.refine(indicator=eta, mark="fraction:0.1", steps=2)
    k = len(expected("fraction:0.1", eta, tripod))
    assert fine.reports[0]["split"] == k
    # Step 2 splits exactly the tets step 1 made from the selection.
    assert fine.reports[1]["split"] == fine.reports[0]["phases"][-1]["tets"] - (tripod.n_tets - k)
    assert set(np.unique(fine.level)) == {0, 2}
    # Unselected tets sharing no vertex with the zone are untouched:
    # level 0 tets are input tets.
    assert (fine.level == 0).sum() == tripod.n_tets - k
