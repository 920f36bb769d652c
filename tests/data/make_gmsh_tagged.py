"""Regenerates gmsh_tagged_*.msh (needs `pip install gmsh`): two boxes meshed
by Gmsh itself (the PyPI `gmsh` 4.15 module), with physical groups that put
entities in several groups at once and names with blanks:

- volumes: box 1 in 10 "steel" and 30 "all solids"; box 2 in 11 "copper" and 30;
- surfaces: the outer faces of box 1 in 5 "outer walls" (one of them, the
  bottom, also in 6 "ground"), the interface in 7 "interface";
- curves: the 12 edges of box 2 in 3 "box 2 edges"; points: its corners in 2.

a point field "temperature" = 1 + 2x - 3y + 0.5z ($NodeData), and two cell
fields on the tets ($ElementData): "density" = 7.85 in box 1 and 8.96 in box 2,
and "centroid" = the tet's centroid (3 components). Written as
MSH 2.2 ASCII (Gmsh writes an element once per physical group), MSH 4.1
ASCII and MSH 4.1 binary. Usage: python3 make_gmsh_tagged.py [OUTDIR]
"""
import os
import sys

import gmsh

out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("tagged")
occ = gmsh.model.occ
b1 = occ.addBox(0, 0, 0, 1, 1, 1)
b2 = occ.addBox(1, 0, 0, 1, 1, 1)
occ.fragment([(3, b1)], [(3, b2)])
occ.synchronize()
vols = [t for _, t in gmsh.model.getEntities(3)]
# Tell the boxes apart by their centre of mass.
v1 = min(vols, key=lambda t: occ.getCenterOfMass(3, t)[0])
v2 = max(vols, key=lambda t: occ.getCenterOfMass(3, t)[0])
s1 = {t for _, t in gmsh.model.getBoundary([(3, v1)], oriented=False)}
s2 = {t for _, t in gmsh.model.getBoundary([(3, v2)], oriented=False)}
interface = s1 & s2
outer1 = sorted(s1 - interface)
bottom = min(outer1, key=lambda t: occ.getCenterOfMass(2, t)[2])
curves2 = sorted({abs(t) for _, t in gmsh.model.getBoundary([(2, s) for s in s2], combined=False, oriented=False)})
points2 = sorted({abs(t) for _, t in gmsh.model.getBoundary([(1, c) for c in curves2], combined=False, oriented=False)})
gmsh.model.addPhysicalGroup(3, [v1], 10, "steel")
gmsh.model.addPhysicalGroup(3, [v2], 11, "copper")
gmsh.model.addPhysicalGroup(3, [v1, v2], 30, "all solids")
gmsh.model.addPhysicalGroup(2, outer1, 5, "outer walls")
gmsh.model.addPhysicalGroup(2, [bottom], 6, "ground")
gmsh.model.addPhysicalGroup(2, sorted(interface), 7, "interface")
gmsh.model.addPhysicalGroup(1, curves2, 3, "box 2 edges")
gmsh.model.addPhysicalGroup(0, points2, 2, "box 2 corners")
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.4)
gmsh.option.setNumber("PostProcessing.SaveMesh", 0)
gmsh.model.mesh.generate(3)
tags, coords, _ = gmsh.model.mesh.getNodes()
view = gmsh.view.add("temperature")
data = [[1 + 2 * coords[3 * i] - 3 * coords[3 * i + 1] + 0.5 * coords[3 * i + 2]] for i in range(len(tags))]
gmsh.view.addModelData(view, 0, "tagged", "NodeData", list(tags), data)
xyz = {int(t): coords[3 * i : 3 * i + 3] for i, t in enumerate(tags)}
tet_tags, density, centroid = [], [], []
for vol, rho in [(v1, 7.85), (v2, 8.96)]:
    types, etags, enodes = gmsh.model.mesh.getElements(3, vol)
    for etype, et, en in zip(types, etags, enodes):
        assert etype == 4, etype
        for k, t in enumerate(et):
            corners = [xyz[int(n)] for n in en[4 * k : 4 * k + 4]]
            tet_tags.append(int(t))
            density.append([rho])
            centroid.append([sum(c[a] for c in corners) / 4 for a in range(3)])
cells = []
for name, values in [("density", density), ("centroid", centroid)]:
    v = gmsh.view.add(name)
    gmsh.view.addModelData(v, 0, "tagged", "ElementData", tet_tags, values)
    cells.append(v)
for version, binary, name in [(2.2, 0, "gmsh_tagged_v22.msh"), (4.1, 0, "gmsh_tagged_v41.msh"), (4.1, 1, "gmsh_tagged_v41_binary.msh")]:
    gmsh.option.setNumber("Mesh.MshFileVersion", version)
    gmsh.option.setNumber("Mesh.Binary", binary)
    path = os.path.join(out, name)
    gmsh.write(path)
    for v in [view] + cells:
        gmsh.view.write(v, path, append=True)
gmsh.finalize()
