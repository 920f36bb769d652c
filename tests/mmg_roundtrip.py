"""Round trip of binary Medit files through MMG's own reader and writer
(`mmg3d_O3` 5.8 from the PyPI wheel `mmgpy`), run with every remeshing
operation off (-noinsert -noswap -nomove -nosurf, -hgrad -1) so that MMG hands
back the mesh it read:

1. tetrefine writes meshes/mmg_tinyBoxt.mesh (two regions) as .meshb; MMG
   reads it and writes ASCII .mesh: same nodes, tets, boundary faces,
   regions and volume as the original (tetrefine quality --json).
2. MMG writes the original as .meshb and as .mesh: tetrefine reads both the
   same.
3. A size map h = 0.05 + 0.1 x (ASCII .sol made here) goes through
   `tetrefine convert --fields h.sol --fields-out h.solb`; MMG reads that
   .solb with the .meshb and gives back (ASCII .sol) exactly the metric it
   gives for the ASCII .sol with the ASCII mesh.

Usage: python3 tests/mmg_roundtrip.py TETREFINE_BINARY   (needs `pip install mmgpy`)
"""

import json
import os
import subprocess
import sys
import tempfile

import mmgpy

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
MMG = os.path.join(os.path.dirname(mmgpy.__file__), "bin", "mmg3d_O3")
KEEP = ["-noinsert", "-noswap", "-nomove", "-nosurf", "-hgrad", "-1", "-v", "-1"]
KEYS = ["nodes", "tets", "boundary_faces", "regions"]


def quality(tetrefine, path):
    out = subprocess.run([tetrefine, "quality", path, "--json"], check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def same(a, b, what):
    for k in KEYS:
        assert a[k] == b[k], (what, k, a[k], b[k])
    assert abs(a["volume"] - b["volume"]) <= 1e-9 * abs(a["volume"]), (what, a["volume"], b["volume"])


def medit_vertices(path):
    """The vertex coordinates of an ASCII Medit mesh."""
    tok = open(path).read().split()
    i = tok.index("Vertices")
    n = int(tok[i + 1])
    return [tuple(float(x) for x in tok[i + 2 + 4 * k : i + 5 + 4 * k]) for k in range(n)]


def sol_values(path):
    tok = open(path).read().split()
    i = tok.index("SolAtVertices")
    n = int(tok[i + 1])
    assert tok[i + 2 : i + 4] == ["1", "1"], tok[i + 2 : i + 4]
    return [float(x) for x in tok[i + 4 : i + 4 + n]]


def main(tetrefine):
    work = tempfile.mkdtemp()
    src = os.path.join(ROOT, "meshes", "mmg_tinyBoxt.mesh")
    ref = quality(tetrefine, src)
    w = lambda name: os.path.join(work, name)

    subprocess.run([tetrefine, "convert", src, w("a.meshb")], check=True)
    subprocess.run([MMG, "-in", w("a.meshb"), "-out", w("b.mesh")] + KEEP, check=True)
    same(quality(tetrefine, w("b.mesh")), ref, "MMG reads tetrefine's .meshb")
    print("mmg3d_O3 reads tetrefine's .meshb: same mesh")

    subprocess.run([MMG, "-in", src, "-out", w("c.meshb")] + KEEP, check=True)
    subprocess.run([MMG, "-in", src, "-out", w("c.mesh")] + KEEP, check=True)
    same(quality(tetrefine, w("c.meshb")), quality(tetrefine, w("c.mesh")), "tetrefine reads MMG's .meshb")
    print("tetrefine reads mmg3d_O3's .meshb: same mesh as its .mesh")

    pts = medit_vertices(src)
    with open(w("h.sol"), "w") as f:
        f.write(f"MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n{len(pts)}\n1 1\n")
        for p in pts:
            f.write(f"{0.05 + 0.1 * p[0]!r}\n")
        f.write("End\n")
    subprocess.run([tetrefine, "convert", src, w("h.meshb"), "--fields", w("h.sol"), "--fields-out", w("h.solb")], check=True)
    with open(w("h.solb"), "rb") as f:
        assert f.read(8) == b"\x01\x00\x00\x00\x02\x00\x00\x00", "a binary libMeshb version 2 file"
    # MMG adapts a size map it reads (to its own hmin/hmax and ridges), so
    # compare with what it makes of the same map given as ASCII .sol with
    # the original ASCII mesh.
    subprocess.run([MMG, "-in", w("h.meshb"), "-sol", w("h.solb"), "-out", w("d.mesh")] + KEEP, check=True)
    subprocess.run([MMG, "-in", src, "-sol", w("h.sol"), "-out", w("e.mesh")] + KEEP, check=True)
    assert medit_vertices(w("d.mesh")) == medit_vertices(w("e.mesh"))
    got, want = sol_values(w("d.sol")), sol_values(w("e.sol"))
    assert len(got) == len(pts) and got == want, (len(got), len(pts))
    print(f"mmg3d_O3 reads tetrefine's .solb as the ASCII .sol: {len(got)} sizes, all equal")

if __name__ == "__main__":
    main(sys.argv[1])
