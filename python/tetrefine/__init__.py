"""tetrefine: adaptive, feature-preserving √3 refinement of tetrahedral meshes.

Python bindings of the Rust core (the library behind the ``tetrefine``
command line): numpy arrays in and out, meshio and PyVista objects.

>>> import tetrefine
>>> mesh = tetrefine.read("meshes/tripod.mesh")          # doctest: +SKIP
>>> fine = mesh.refine(steps=1)                           # doctest: +SKIP
>>> fine.quality()["min_dihedral_deg"]                    # doctest: +SKIP

Contents: :class:`Mesh` (from arrays), :func:`read`, :func:`from_meshio`,
``Mesh.refine / improve / bisect / quality / tet_quality / write /
to_meshio / to_pyvista``, and :func:`mesh_surface` in builds with TetGen.
meshio and PyVista are optional: they are imported only by the functions
that need them.
"""

from ._core import HAS_TETGEN, Mesh, __version__, read
from ._convert import from_meshio

__all__ = ["Mesh", "read", "from_meshio", "HAS_TETGEN", "__version__"]

if HAS_TETGEN:
    from ._core import mesh_surface  # noqa: F401

    __all__.append("mesh_surface")


def __getattr__(name):
    if name == "mesh_surface":
        raise AttributeError(
            "tetrefine was built without TetGen (AGPL-3), so it has no mesh_surface; "
            'rebuild with: MATURIN_PEP517_ARGS="--features tetgen" pip install ./python'
        )
    raise AttributeError(f"module 'tetrefine' has no attribute {name!r}")
