"""Child of test_interrupt.py: refines until SIGINT arrives, then reports."""

import sys
import time

import tetrefine
from conftest import cube_grid

points, tets = cube_grid(16)
mesh = tetrefine.Mesh(points, tets)
print("ready", flush=True)
t0 = time.perf_counter()
try:
    mesh.refine(steps=2)
except KeyboardInterrupt:
    print(f"interrupted after {time.perf_counter() - t0:.2f} s", flush=True)
    sys.exit(0)
print("finished without interruption", flush=True)
sys.exit(1)
