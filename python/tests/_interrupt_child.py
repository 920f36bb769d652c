"""Child of test_interrupt.py: refines until SIGINT arrives, then reports
how many phases had started (each one is announced on stdout as it starts)."""

import signal
import sys

import tetrefine
from conftest import cube_grid

# Handle SIGINT as an interactive Python does, even when this process was
# started with SIGINT ignored (a background job of a non-interactive shell).
signal.signal(signal.SIGINT, signal.default_int_handler)

points, tets = cube_grid(16)
mesh = tetrefine.Mesh(points, tets)
started = []


def announce(step, phase, n_tets):
    started.append((step, phase))
    print(f"phase {step} {phase}", flush=True)


print("ready", flush=True)
try:
    mesh.refine(steps=2, progress=announce)
except KeyboardInterrupt:
    print(f"interrupted after {len(started)} phases", flush=True)
    sys.exit(0)
print("finished without interruption", flush=True)
sys.exit(1)
