"""The package calls the same library as the CLI: its figures equal the
CLI's JSON (run as a separate process), file for file and step for step."""

import json

import numpy as np
import pytest

import tetrefine
from conftest import MESHES, TRIPOD


def test_tripod_quality_equals_cli_json(cli_json):
    q = tetrefine.read(TRIPOD).quality()
    assert q == cli_json(TRIPOD)
    # And the figures computed by an independent script (shared/DESIGN.md §4).
    assert (q["nodes"], q["edges"], q["tets"]) == (967, 4621, 2799)
    assert (q["boundary_faces"], q["interior_faces"]) == (1710, 4743)
    assert q["valence"]["max"] == 27
    assert round(q["min_dihedral_deg"]["worst"], 2) == 7.56
    assert round(q["min_dihedral_deg"]["avg"], 2) == 42.92
    assert round(q["min_dihedral_deg"]["best"], 2) == 65.15
    assert sum(q["histogram"]["counts"]) == 2799


def test_histogram_bins_equal_cli(cli_json):
    q = tetrefine.read(TRIPOD).quality(bins=7)
    assert q["histogram"] == cli_json(TRIPOD, "--bins", "7")["histogram"]
    assert len(q["histogram"]["counts"]) == 7


@pytest.mark.parametrize("ext", [".mesh", ".msh", ".vtu", ".node"])
def test_every_format_reads_and_writes_as_the_cli(ext, tmp_path, cli, cli_json):
    # The CLI converts, Python reads; Python writes, the CLI reads.
    src = MESHES / "mmg_tinyBoxt.mesh"  # two regions, markers, ridges
    by_cli = tmp_path / f"cli{ext}"
    cli("convert", src, by_cli)
    m = tetrefine.read(by_cli)
    assert m.quality() == cli_json(by_cli)
    by_py = tmp_path / f"py{ext}"
    m.write(by_py)
    assert cli_json(by_py) == m.quality()
    assert sorted(np.unique(m.regions)) == [int(k) for k in cli_json(src)["regions"]]


def test_gid_reads_as_the_cli(cli_json):
    gid = MESHES / "tripod.GiD.msh"
    assert tetrefine.read(gid).quality() == cli_json(gid)


def test_refine_equals_cli_refine(tmp_path, cli, cli_json):
    stats = tmp_path / "s.json"
    out = tmp_path / "cli.vtu"
    cli("refine", TRIPOD, "-o", out, "--steps", "2", "--stats", stats)
    steps = json.loads(stats.read_text())["steps"]
    fine = tetrefine.read(TRIPOD).refine(steps=2, stats=True)
    # A .vtu holds no feature tags: the CLI reading it back counts none.
    q_out = {k: v for k, v in fine.quality().items() if k not in ("feature_edges", "corners")}
    assert q_out == {k: v for k, v in cli_json(out).items() if k in q_out}
    assert cli_json(out)["feature_edges"] == 0 < fine.quality()["feature_edges"]
    for mine, theirs in zip(fine.reports, steps[1:]):
        q = mine["quality"]
        assert {k: theirs[k] for k in q} == q
        # Same phases, same counts, in the same order.
        assert [(p["name"], p["tets"]) for p in mine["phases"]] == [
            (p["name"], p["tets"]) for p in theirs["phases"]
        ]
        for k in ("split", "flipped", "boundary_split", "boundary_flipped", "improve"):
            assert mine[k] == theirs["report"][k]
    # The cell arrays of the CLI's .vtu (read back by meshio, an independent
    # reader) equal the Python arrays.
    meshio = pytest.importorskip("meshio")
    ref = meshio.read(out)
    for name, arr in (("level", fine.level), ("parent", fine.parent), ("marked", fine.marked),
                      ("region", fine.regions)):
        np.testing.assert_array_equal(ref.cell_data[name][0], arr.astype(np.int64))
    np.testing.assert_array_equal(ref.points, fine.points)


def test_refine_options_equal_cli(tmp_path, cli, cli_json):
    out = tmp_path / "o.mesh"
    cli("refine", TRIPOD, "-o", out, "--boundary", "linear", "--opt-passes", "1",
        "--features", "none", "--stop-after", "boundary-smooth")
    fine = tetrefine.read(TRIPOD).refine(
        boundary="linear", opt_passes=1, features="none", stop_after="boundary-smooth"
    )
    assert fine.quality() == cli_json(out)
    assert [p["name"] for p in fine.reports[0]["phases"]][-1] == "boundary-smooth"


def test_sqrt3_interfaces_equal_cli(tmp_path, cli, cli_json):
    src = MESHES / "gmsh_t16.mesh"
    out = tmp_path / "o.mesh"
    cli("refine", src, "-o", out, "--interfaces", "sqrt3", "--effort", "fast")
    fine = tetrefine.read(src).refine(interfaces="sqrt3", effort="fast")
    assert fine.quality() == cli_json(out)
    # The curved inclusions are no creases under sqrt3 (only the box's
    # 219 edges sharper than 45 degrees are), unlike under linear.
    linear = tetrefine.read(src).refine(effort="fast", stop_after="split")
    assert fine.quality()["feature_edges"] < linear.quality()["feature_edges"]


def test_improve_and_bisect_equal_cli(tmp_path, cli, cli_json):
    src = MESHES / "tetgen_example.mesh"
    imp, bis = tmp_path / "i.mesh", tmp_path / "b.mesh"
    cli("improve", src, "-o", imp, "--opt-passes", "2")
    cli("bisect", src, "-o", bis)
    m = tetrefine.read(src)
    assert m.improve(opt_passes=2).quality() == cli_json(imp)
    b = m.bisect()
    assert b.quality() == cli_json(bis)
    assert b.n_tets == 8 * m.n_tets  # closed form of 1:8 refinement
    assert b.reports[0]["tets"] == b.n_tets


def test_parents_are_located_on_first_use_even_without_the_input():
    kept = tetrefine.read(TRIPOD)
    a = kept.refine(stop_after="split")
    b = tetrefine.read(TRIPOD).refine(stop_after="split")  # its input is gone
    import gc

    gc.collect()
    np.testing.assert_array_equal(a.parent, b.parent)
    # After the 1-4 split alone every child lies in the tet it came from:
    # each input tet is the parent of exactly 4 tets.
    np.testing.assert_array_equal(np.bincount(b.parent), np.full(2799, 4))
    assert set(b.timings) == {"copy", "features", "steps", "compact"}
    assert b.timings["steps"] >= b.reports[0]["seconds"]  # the step clock is inside
