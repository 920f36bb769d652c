"""Refining a >= 1M-tet cube grid from Python against the CLI's in-core time.

    python python/bench/bench_refine.py N [RUNS]

Builds the Freudenthal–Kuhn grid of N³ cubes (6 N³ tets) in numpy, then per
run: Mesh(points, tets) (the one copy in, and the library's mesh building),
mesh.refine() (one √3 step, default options), and np.array of the refined
points and tets (the one copy out). The CLI runs `tetrefine refine` on the
same grid written as .mesh, with --stats; its in-core time is the step's
own clock (the "seconds" of the step in the stats file).
"""

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from conftest import REPO, cube_grid  # noqa: E402

import tetrefine  # noqa: E402

n = int(sys.argv[1]) if len(sys.argv) > 1 else 56
runs = int(sys.argv[2]) if len(sys.argv) > 2 else 3
cli = os.environ.get("TETREFINE_CLI", str(REPO / "target" / "release" / "tetrefine"))

points, tets = cube_grid(n)
print(f"cube grid N={n}: {len(tets):,} tets, {len(points):,} points")
tmp = Path(tempfile.mkdtemp())
src = tmp / "cube.mesh"
tetrefine.Mesh(points, tets).write(src)

for r in range(runs):
    stats = tmp / "s.json"
    subprocess.run([cli, "refine", src, "-o", tmp / "out.mesh", "--stats", stats],
                   check=True, capture_output=True)
    cli_step = json.loads(stats.read_text())["steps"][1]["seconds"]

    t0 = time.perf_counter()
    mesh = tetrefine.Mesh(points, tets)
    t1 = time.perf_counter()
    fine = mesh.refine()
    t2 = time.perf_counter()
    out_points, out_tets = np.array(fine.points), np.array(fine.tets)
    t3 = time.perf_counter()
    parent = fine.parent  # located on first use (the CLI does it after the step)
    t4 = time.perf_counter()
    step = fine.reports[0]["seconds"]
    refine_call = t2 - t1
    print(
        f"run {r + 1}: {fine.n_tets:,} tets out | CLI step {cli_step:.3f} s | "
        f"Python: Mesh() {t1 - t0:.3f} s, refine() {refine_call:.3f} s "
        f"(its step {step:.3f} s, rest {refine_call - step:.3f} s), arrays out {t3 - t2:.3f} s, "
        f"parents {t4 - t3:.3f} s | refine() / CLI step = {refine_call / cli_step:.3f}, "
        f"refine() / own step = {refine_call / step:.3f}",
        flush=True,
    )
    del mesh, fine, out_points, out_tets, parent
