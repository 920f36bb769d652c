"""Regenerates the VTK-written .vtu variants in this folder (needs `pip install vtk`).

The source is `tetrefine convert meshes/mmg_cube.mesh cube.vtu`; VTK's own XML
writer (the PyPI `vtk` 9.7 wheel) reads it and writes it again in the layouts
the reader must understand: ASCII, appended raw without compression (UInt32
headers), appended base64 with zlib (UInt64 headers) and inline binary
without compression.
Usage: python3 make_vtk_variants.py cube.vtu
"""
import sys

import vtk

reader = vtk.vtkXMLUnstructuredGridReader()
reader.SetFileName(sys.argv[1])
reader.Update()
grid = reader.GetOutput()


def write(name, mode, compress, header64, encode):
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetInputData(grid)
    w.SetFileName(name)
    w.SetDataMode(mode)
    if compress:
        w.SetCompressorTypeToZLib()
    else:
        w.SetCompressorTypeToNone()
    w.SetHeaderTypeToUInt64() if header64 else w.SetHeaderTypeToUInt32()
    w.SetEncodeAppendedData(encode)
    assert w.Write() == 1


write("mmg_cube_vtk_ascii.vtu", vtk.vtkXMLWriter.Ascii, False, False, 0)
write("mmg_cube_vtk_appended_raw.vtu", vtk.vtkXMLWriter.Appended, False, False, 0)
write("mmg_cube_vtk_appended_base64_zlib.vtu", vtk.vtkXMLWriter.Appended, True, True, 1)
write("mmg_cube_vtk_inline_raw.vtu", vtk.vtkXMLWriter.Binary, False, False, 0)
