"""Regenerates the binary Gmsh files in this folder (needs `pip install gmsh`).

The source is meshes/mmg_cube.mesh converted to MSH 4.1 ASCII by
`tetrefine convert meshes/mmg_cube.mesh cube.msh`; Gmsh itself (the Python
module of Gmsh 4.15) then reads that file and writes it in binary MSH 4.1 and
binary MSH 2.2. Usage: python3 make_gmsh_binary.py cube.msh
"""
import sys

import gmsh

gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.open(sys.argv[1])
gmsh.option.setNumber("Mesh.Binary", 1)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.write("mmg_cube_v41_binary.msh")
gmsh.option.setNumber("Mesh.MshFileVersion", 2.2)
gmsh.write("mmg_cube_v22_binary.msh")
gmsh.finalize()
