#!/usr/bin/env python3
"""Edge-length figures of the README's issue-14 table: for each ASCII Medit
`.mesh` file given, the number of tets and of distinct tet edges, the 99th
percentile and the longest edge length. Reads the file itself (numpy only),
so an output with sections another reader skips (MMG's `RequiredEdges`) is
read too. A `.vtu` is converted first with `tetrefine convert IN.vtu OUT.mesh`.

Usage: benches/edge_lengths.py A.mesh [B.mesh ...]
"""
import sys

import numpy as np


def read_medit(path):
    """The points (n x 3) and tets (m x 4, 0-based) of an ASCII Medit file."""
    with open(path) as f:
        words = f.read().split()
    points = tets = None
    i = 0
    while i < len(words):
        w = words[i]
        if w == "Vertices":
            n = int(words[i + 1])
            a = np.array(words[i + 2 : i + 2 + 4 * n], dtype=float).reshape(n, 4)
            points = a[:, :3]
            i += 2 + 4 * n
        elif w == "Tetrahedra":
            n = int(words[i + 1])
            a = np.array(words[i + 2 : i + 2 + 5 * n], dtype=np.int64).reshape(n, 5)
            tets = a[:, :4] - 1
            i += 2 + 5 * n
        else:
            i += 1
    if points is None or tets is None:
        sys.exit(f"{path}: no Vertices or no Tetrahedra section")
    return points, tets


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    print("| file | tets | edges | 99th percentile | longest |")
    print("|---|---:|---:|---:|---:|")
    for path in sys.argv[1:]:
        points, tets = read_medit(path)
        pairs = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
        edges = np.sort(np.concatenate([tets[:, list(p)] for p in pairs]), axis=1)
        edges = np.unique(edges, axis=0)
        lengths = np.linalg.norm(points[edges[:, 0]] - points[edges[:, 1]], axis=1)
        print(
            f"| {path} | {len(tets):,} | {len(edges):,} "
            f"| {np.percentile(lengths, 99):.4g} | {lengths.max():.4g} |"
        )


if __name__ == "__main__":
    main()
