"""Round trip through Gmsh's own reader (the PyPI `gmsh` module): a mesh
Gmsh makes, with entities in several physical groups and named groups, goes
through `tetrefine convert` and `tetrefine refine` in each MSH variant
(2.2, 4.1, 4.1-binary), and Gmsh reads every output back with every name and
every (dim, physical tag) of the input, each group on the same number of
entities' worth of elements:

- convert: the same elements in every group (MSH 2.2 lists an element once
  per group and Gmsh keeps the copies on the entity: counted once);
- refine: every group of the input is there with its name and more
  elements than before (the √3 step splits every tet and boundary face);
  groups tetrefine adds for the features it detects are unnamed extras.

Cell fields: the input's `$ElementData` view "density" (7.85 in the box
x < 1, 8.96 in the box x > 1) comes back from `refine` in each variant as a
Gmsh view with a value at every element: at every tet the density of the
box its centroid is in (worked out here from Gmsh's own nodes), NaN at the
triangles, lines and points.

Usage: python3 tests/gmsh_roundtrip.py TETREFINE_BINARY   (needs `pip install gmsh`)
"""

import math
import os
import subprocess
import sys
import tempfile

import gmsh

HERE = os.path.dirname(os.path.abspath(__file__))


def groups(path, v22=False):
    """{(dim, tag): (name, elements in the group)} as Gmsh reads `path`.
    Gmsh keeps the copies of an MSH 2.2 element (one per physical group) on
    its entity: there an entity's elements are divided by its group count."""
    gmsh.open(path)
    out = {}
    for dim, tag in gmsh.model.getPhysicalGroups():
        n = 0
        for e in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
            _, tags, _ = gmsh.model.mesh.getElements(dim, int(e))
            k = sum(len(t) for t in tags)
            if v22:
                copies = len(gmsh.model.getPhysicalGroupsForEntity(dim, int(e)))
                assert k % copies == 0, (path, dim, e, k, copies)
                k //= copies
            n += k
        out[(dim, tag)] = (gmsh.model.getPhysicalName(dim, tag), n)
    return out


def check_density(path):
    """The "density" view of `path` as Gmsh reads it (see the docstring);
    returns the number of tets checked."""
    for v in gmsh.view.getTags():
        gmsh.view.remove(v)
    gmsh.open(path)
    views = {gmsh.view.option.getString(v, "Name"): v for v in gmsh.view.getTags()}
    assert "density" in views, (path, views)
    _, tags, data, _, comps = gmsh.view.getModelData(views["density"], 0)
    assert comps == 1, (path, comps)
    value = {int(t): d[0] for t, d in zip(tags, data)}
    nodes, coords, _ = gmsh.model.mesh.getNodes()
    xyz = {int(n): coords[3 * i : 3 * i + 3] for i, n in enumerate(nodes)}
    types, etags, enodes = gmsh.model.mesh.getElements()
    n_elements = sum(len(t) for t in etags)
    assert len(value) == n_elements, (path, len(value), n_elements)
    tets = 0
    for etype, et, en in zip(types, etags, enodes):
        k = len(en) // len(et)
        for i, t in enumerate(et):
            v = value[int(t)]
            if etype != 4:
                assert math.isnan(v), (path, etype, t, v)
                continue
            x = sum(xyz[int(n)][0] for n in en[k * i : k * i + k]) / k
            assert v == (7.85 if x < 1 else 8.96), (path, t, x, v)
            tets += 1
    return tets


def main(tetrefine):
    work = tempfile.mkdtemp()
    subprocess.run([sys.executable, os.path.join(HERE, "data", "make_gmsh_tagged.py"), work], check=True)
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    source = os.path.join(work, "gmsh_tagged_v41.msh")
    want = groups(source)
    assert len(want) == 8 and all(name for name, _ in want.values()), want
    for fmt in ["2.2", "4.1", "4.1-binary"]:
        out = os.path.join(work, f"convert_{fmt}.msh")
        subprocess.run([tetrefine, "convert", source, out, "--msh-format", fmt], check=True)
        got = groups(out, fmt == "2.2")
        assert got == want, (fmt, "convert", got, want)
        out = os.path.join(work, f"refine_{fmt}.msh")
        subprocess.run(
            [tetrefine, "refine", source, "-o", out, "--msh-format", fmt],
            check=True,
            stdout=subprocess.DEVNULL,
        )
        got = groups(out, fmt == "2.2")
        for key, (name, n) in want.items():
            assert key in got, (fmt, "refine", key, got)
            assert got[key][0] == name, (fmt, "refine", key, got[key], name)
            if key[0] >= 2:
                assert got[key][1] > n, (fmt, "refine", key, got[key], n)
            else:
                assert got[key][1] >= n, (fmt, "refine", key, got[key], n)
        extra = {k: v for k, v in got.items() if k not in want}
        assert all(name == "" for name, _ in extra.values()), extra
        tets = check_density(out)
        assert tets > 3 * 1455, (fmt, tets)
        print(f"gmsh reads MSH {fmt}: {len(want)} named groups kept through convert and refine, the cell field at {tets} tets")
    gmsh.finalize()


if __name__ == "__main__":
    main(sys.argv[1])
