"""Shared fixtures: the repository's meshes and the CLI binary (the
independent source the Python figures are checked against)."""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
MESHES = REPO / "meshes"
TRIPOD = MESHES / "tripod.mesh"


def _cli_path():
    if os.environ.get("TETREFINE_CLI"):
        return Path(os.environ["TETREFINE_CLI"])
    exe = REPO / "target" / "release" / "tetrefine"
    if not exe.exists():
        subprocess.run(
            ["cargo", "build", "--release", "--bin", "tetrefine"], cwd=REPO, check=True
        )
    return exe


@pytest.fixture(scope="session")
def cli():
    """Runs the CLI; returns its stdout (checks the exit code)."""
    exe = _cli_path()

    def run(*args):
        r = subprocess.run(
            [str(exe), *map(str, args)], capture_output=True, text=True, cwd=REPO
        )
        assert r.returncode == 0, f"tetrefine {args}: {r.stderr}"
        return r.stdout

    return run


@pytest.fixture(scope="session")
def cli_json(cli):
    """`tetrefine quality FILE --json` as a dict."""

    def q(path, *extra):
        return json.loads(cli("quality", path, "--json", *extra))

    return q


def cube_grid(n, h=1.0):
    """The Freudenthal–Kuhn grid of n³ cubes, 6 tets each, built here in
    numpy (independently of the library's generator): points (n+1)³ and
    tets (6n³, 4), every tet of volume h³/6."""
    g = np.arange(n + 1)
    x, y, z = np.meshgrid(g, g, g, indexing="ij")
    points = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1).astype(np.float64) * h

    def vid(i, j, k):
        return (i * (n + 1) + j) * (n + 1) + k

    i, j, k = np.meshgrid(np.arange(n), np.arange(n), np.arange(n), indexing="ij")
    i, j, k = i.ravel(), j.ravel(), k.ravel()
    corner = {
        (a, b, c): vid(i + a, j + b, k + c) for a in (0, 1) for b in (0, 1) for c in (0, 1)
    }
    tets = []
    # The six paths from (0,0,0) to (1,1,1) through the unit cube's edges.
    for perm in ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)):
        p = [0, 0, 0]
        verts = [corner[tuple(p)]]
        for axis in perm:
            p[axis] = 1
            verts.append(corner[tuple(p)])
        tets.append(np.stack(verts, axis=1))
    tets = np.concatenate(tets)
    # Odd paths give negatively oriented tets: swap two vertices so that every
    # det[p1-p0, p2-p0, p3-p0] is positive (the library's orientation).
    q = points[tets]
    det = np.einsum("ij,ij->i", q[:, 1] - q[:, 0], np.cross(q[:, 2] - q[:, 0], q[:, 3] - q[:, 0]))
    tets[det < 0] = tets[det < 0][:, [1, 0, 2, 3]]
    return points, tets
