"""meshio and PyVista conversions. Both libraries are optional: they are
imported here, inside the functions, and only when called."""

import numpy as np

from ._core import Mesh

#: Cell data names that carry the region of a tet (or the marker of a face),
#: in the order they are looked for: tetrefine's .vtu, Gmsh, Medit.
REGION_KEYS = ("region", "gmsh:physical", "medit:ref")

_TETS = {"tetra": 4, "tetra10": 4}
_TRIANGLES = {"triangle": 3, "triangle6": 3}
_LINES = {"line": 2, "line3": 2}


def _need(module, what):
    try:
        return __import__(module)
    except ImportError as e:
        raise ImportError(f"{what} needs {module}: pip install {module}") from e


def _labels(m, blocks, keys):
    """The first of `keys` that the cell data has, for the given block
    indices, concatenated; None when no key is there."""
    for key in keys:
        data = m.cell_data.get(key)
        if data is not None:
            return np.concatenate([np.asarray(data[i]).reshape(-1) for i in blocks])
    return None


def from_meshio(m):
    """A tetrefine Mesh from a meshio.Mesh.

    Tets come from the "tetra" blocks ("tetra10": its corner nodes), their
    region from the cell data "region" (tetrefine's .vtu), "gmsh:physical"
    (Gmsh) or "medit:ref" (Medit), the first one present; marked faces from
    the "triangle" blocks with their marker from "gmsh:physical",
    "medit:ref" or "region"; feature edges from the "line" blocks. Other
    blocks (vertices, quads, ...) are ignored. The mesh is validated as
    Mesh(...) validates arrays (ValueError on bad input).
    """
    blocks = list(m.cells)
    tet_blocks = [i for i, b in enumerate(blocks) if b.type in _TETS]
    if not tet_blocks:
        kinds = sorted({b.type for b in blocks}) or ["no cells"]
        raise ValueError(f"the meshio mesh has no tetra cells (it has {', '.join(kinds)})")
    tets = np.concatenate([np.asarray(blocks[i].data)[:, :4] for i in tet_blocks])
    regions = _labels(m, tet_blocks, REGION_KEYS)
    kwargs = {"regions": regions}
    tri_blocks = [i for i, b in enumerate(blocks) if b.type in _TRIANGLES]
    if tri_blocks:
        kwargs["boundary_faces"] = np.concatenate(
            [np.asarray(blocks[i].data)[:, :3] for i in tri_blocks]
        )
        kwargs["boundary_markers"] = _labels(
            m, tri_blocks, ("gmsh:physical", "medit:ref", "region")
        )
    line_blocks = [i for i, b in enumerate(blocks) if b.type in _LINES]
    if line_blocks:
        kwargs["feature_edges"] = np.concatenate(
            [np.asarray(blocks[i].data)[:, :2] for i in line_blocks]
        )
    points = np.asarray(m.points)
    if points.ndim == 2 and points.shape[1] == 2:
        raise ValueError("points must have shape (n, 3), got a 2-D mesh " f"{points.shape}")
    return Mesh(points, tets, **{k: v for k, v in kwargs.items() if v is not None})


def _cell_arrays(mesh):
    """The per-tet arrays tetrefine's .vtu carries (int32 and float64)."""
    q = mesh.tet_quality()
    out = {
        "region": np.asarray(mesh.regions, dtype=np.int32),
        "level": np.asarray(mesh.level, dtype=np.int32),
        "parent": np.asarray(mesh.parent, dtype=np.int32),
        "marked": np.asarray(mesh.marked, dtype=np.int32),
    }
    for k in ("min_dihedral", "max_dihedral", "quality", "volume"):
        out[k] = np.asarray(q[k])
    return out


def to_meshio(mesh, faces=True):
    """See Mesh.to_meshio."""
    meshio = _need("meshio", "Mesh.to_meshio")
    arrays = _cell_arrays(mesh)
    cells = [("tetra", np.asarray(mesh.tets, dtype=np.int64))]
    data = {k: [v] for k, v in arrays.items()}
    for k in ("medit:ref", "gmsh:physical", "gmsh:geometrical"):
        data[k] = [arrays["region"]]
    if faces:
        blocks = [
            ("triangle", mesh.boundary_faces, mesh.boundary_markers),
            ("line", mesh.feature_edges, np.zeros(len(mesh.feature_edges), dtype=np.int32)),
        ]
        for kind, ids, markers in blocks:
            if not len(ids):
                continue
            cells.append((kind, np.asarray(ids, dtype=np.int64)))
            for k, v in data.items():
                if k in ("region", "medit:ref", "gmsh:physical", "gmsh:geometrical"):
                    v.append(np.asarray(markers, dtype=np.int32))
                elif v[0].dtype.kind == "f":
                    v.append(np.full(len(ids), np.nan))
                else:
                    v.append(np.full(len(ids), -1, dtype=v[0].dtype))
    return meshio.Mesh(np.array(mesh.points), cells, cell_data=data)


def to_pyvista(mesh):
    """See Mesh.to_pyvista."""
    pv = _need("pyvista", "Mesh.to_pyvista")
    tets = np.asarray(mesh.tets, dtype=np.int64)
    n = len(tets)
    cells = np.hstack([np.full((n, 1), 4, dtype=np.int64), tets]).ravel()
    types = np.full(n, pv.CellType.TETRA, dtype=np.uint8)
    grid = pv.UnstructuredGrid(cells, types, np.array(mesh.points))
    for k, v in _cell_arrays(mesh).items():
        grid.cell_data[k] = v
    return grid
