"""tetrefine.mesh_surface exists exactly in builds with the `tetgen`
feature; there it fills a closed surface as `tetrefine mesh` does."""

import os
import signal
import sys
import threading
import time

import numpy as np
import pytest

import tetrefine
from conftest import MESHES


def test_mesh_surface_only_with_tetgen(tmp_path):
    if not tetrefine.HAS_TETGEN:
        assert not hasattr(tetrefine, "mesh_surface")
        with pytest.raises(AttributeError, match="built without TetGen"):
            tetrefine.mesh_surface  # noqa: B018
        return
    # A unit cube as 12 triangles: the volume is 1 (closed form).
    p = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]
    m = tetrefine.mesh_surface((p, tris), max_volume=0.01)
    assert m.quality()["volume"] == pytest.approx(1.0, rel=1e-9)
    assert m.n_tets >= 100
    poly = MESHES / "tetgen_example.poly"
    a = tetrefine.mesh_surface(poly, min_dihedral=18)
    assert a.quality()["min_dihedral_deg"]["worst"] >= 17.9
    with pytest.raises(FileNotFoundError):
        tetrefine.mesh_surface(tmp_path / "missing.poly")


def _cube_surface():
    """The unit cube as 8 points and 12 triangles."""
    p = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return p, [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]


needs_tetgen = pytest.mark.skipif(not tetrefine.HAS_TETGEN, reason="built without TetGen")


@needs_tetgen
def test_mesh_surface_in_a_child_process_gives_the_in_process_mesh():
    # TetGen runs in a child process; the mesh is TetGen's own: the README's
    # table (measured in-process) gives pq2/18A on the example 1,198 tets,
    # and the volume is the closed form 17.9375 of the example's geometry.
    poly = MESHES / "tetgen_example.poly"
    a = tetrefine.mesh_surface(poly, min_dihedral=18)
    b = tetrefine.mesh_surface(poly, min_dihedral=18, time_limit=3600)
    assert a.n_tets == 1198
    assert a.quality()["volume"] == pytest.approx(17.9375, rel=1e-9)
    assert np.array_equal(a.points, b.points)
    assert np.array_equal(a.tets, b.tets)
    assert np.array_equal(a.regions, b.regions)


@needs_tetgen
def test_time_limit_stops_a_long_tetgen_run():
    # A maximum volume of 2e-6 on the unit cube: millions of tets, many
    # seconds of TetGen; the limit stops it with TimeoutError.
    with pytest.raises(TimeoutError, match=r"did not finish within 0\.3 s.*time_limit=0\.3"):
        tetrefine.mesh_surface(_cube_surface(), max_volume=2e-6, time_limit=0.3)
    # The interpreter is unharmed: a normal call still works.
    m = tetrefine.mesh_surface(_cube_surface(), max_volume=0.01, time_limit=60)
    assert m.quality()["volume"] == pytest.approx(1.0, rel=1e-9)
    for bad in (0, -1, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="time_limit"):
            tetrefine.mesh_surface(_cube_surface(), time_limit=bad)


def _children_running(exe):
    """Process ids of this process's children that run the program `exe`."""
    me = os.getpid()
    out = []
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            with open(f"/proc/{d}/stat") as f:
                rest = f.read().rsplit(")", 1)[1].split()
            if int(rest[1]) == me and os.path.realpath(f"/proc/{d}/exe") == exe:
                out.append(int(d))
        except (OSError, IndexError, ValueError):
            continue
    return out


@needs_tetgen
def test_a_tetgen_crash_is_an_error_not_the_end_of_the_interpreter():
    # A long run whose TetGen process is killed by SIGSEGV, as a crash of
    # TetGen would kill it: RuntimeError naming the file and the signal.
    poly = MESHES / "tetgen_example.poly"
    result = {}

    def run():
        try:
            tetrefine.mesh_surface(poly, max_volume=2e-5, time_limit=600)
            result["ok"] = True
        except Exception as e:  # noqa: BLE001 - the test inspects it
            result["error"] = e

    t = threading.Thread(target=run)
    t.start()
    exe = os.path.realpath(sys.executable)
    killed = False
    while t.is_alive() and not killed:
        for pid in _children_running(exe):
            os.kill(pid, signal.SIGSEGV)
            killed = True
        if not killed:
            time.sleep(0.02)
    t.join()
    assert killed, "no TetGen child process was found"
    e = result.get("error")
    assert isinstance(e, RuntimeError), result
    assert str(poly) in str(e) and "signal 11 (SIGSEGV)" in str(e), str(e)
    # The interpreter is unharmed: a normal call still works.
    assert tetrefine.mesh_surface(_cube_surface()).quality()["volume"] == pytest.approx(1.0)
