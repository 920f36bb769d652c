"""The GIL is released while the core works; Ctrl-C (SIGINT) stops a long
refinement at the next phase and raises KeyboardInterrupt; a progress
callback sees every phase and can stop the run by raising."""

import _thread
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

import tetrefine
from conftest import TRIPOD, cube_grid

HERE = Path(__file__).resolve().parent


@pytest.fixture(scope="module")
def cube():
    points, tets = cube_grid(16)  # 24,576 tets; steps=2 gives about 0.9M
    return tetrefine.Mesh(points, tets)


@pytest.fixture(scope="module")
def one_step_seconds(cube):
    t0 = time.perf_counter()
    cube.refine(steps=1)
    return time.perf_counter() - t0


def test_gil_is_released_during_refinement(cube):
    ticks = 0
    done = threading.Event()

    def work():
        cube.refine(steps=1)
        done.set()

    t = threading.Thread(target=work)
    t0 = time.perf_counter()
    t.start()
    while not done.is_set():
        ticks += 1
        time.sleep(0.002)
    t.join()
    elapsed = time.perf_counter() - t0
    # With the GIL held for the whole run this loop could only tick around
    # the six phase boundaries (a few ticks each); released, it ticks all
    # along (one per 2 ms, fewer on a loaded machine).
    assert elapsed > 0.1
    assert ticks > max(30, 0.1 * elapsed / 0.002)


def test_interrupt_main_stops_a_long_run(cube, one_step_seconds):
    timer = threading.Timer(0.2, _thread.interrupt_main)
    t0 = time.perf_counter()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        cube.refine(steps=2)  # about 7x one step when not interrupted
    elapsed = time.perf_counter() - t0
    timer.cancel()
    assert elapsed < 2.5 * one_step_seconds + 0.5
    # The mesh is untouched and the library still works.
    assert cube.n_tets == 24576
    assert cube.refine(stop_after="split").n_tets == 4 * 24576


def test_sigint_to_a_subprocess(one_step_seconds):
    script = HERE / "_interrupt_child.py"
    p = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True,
                         cwd=HERE)
    assert p.stdout.readline().strip() == "ready"
    time.sleep(0.3)
    t0 = time.perf_counter()
    os.kill(p.pid, signal.SIGINT)
    out, _ = p.communicate(timeout=120)
    waited = time.perf_counter() - t0
    assert p.returncode == 0, out
    assert out.strip().startswith("interrupted"), out
    # It stopped at the next phase, not at the end of the run (which takes
    # about 7 times one step).
    assert waited < 2.5 * one_step_seconds + 1.0


def test_progress_callback_sees_every_phase_and_can_stop():
    m = tetrefine.read(TRIPOD)
    seen = []
    m.refine(steps=2, progress=lambda s, phase, tets: seen.append((s, phase, tets)))
    phases = ["split", "flip", "boundary-split", "boundary-flip", "boundary-smooth", "optimize"]
    assert [(s, p) for s, p, _ in seen] == [(s, p) for s in (1, 2) for p in phases]
    assert seen[0][2] == 2799

    class Stop(Exception):
        pass

    def stop(step, phase, tets):
        if phase == "flip":
            raise Stop(f"stopped at {step}:{phase}")

    with pytest.raises(Stop, match="stopped at 1:flip"):
        m.refine(progress=stop)


def test_progress_true_prints_phases(capsys):
    tetrefine.read(TRIPOD).refine(progress=True, stop_after="flip")
    err = capsys.readouterr().err
    assert "step 1/1: split (2799 tets)" in err and "step 1/1: flip" in err
