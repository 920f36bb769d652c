"""Type stubs of tetrefine (the extension tetrefine._core and the Python helpers)."""

import os
from typing import Any, Callable, Literal, Sequence, TypedDict, Union

import numpy as np
import numpy.typing as npt

__version__: str
HAS_TETGEN: bool

_Path = Union[str, "os.PathLike[str]"]
_Ints = npt.ArrayLike
_Reals = npt.ArrayLike

class MinDihedral(TypedDict):
    worst: float
    avg: float
    best: float

class MaxDihedral(TypedDict):
    worst: float
    avg: float

class Valence(TypedDict):
    avg: float
    max: int

class Histogram(TypedDict):
    edges_deg: list[float]
    counts: list[int]

class Quality(TypedDict):
    """The fields of ``tetrefine quality --json``."""

    nodes: int
    edges: int
    tets: int
    boundary_faces: int
    interior_faces: int
    min_dihedral_deg: MinDihedral
    max_dihedral_deg: MaxDihedral
    valence: Valence
    inverted: int
    volume: float
    regions: dict[str, int]
    histogram: Histogram
    feature_edges: int
    corners: int

class TetQuality(TypedDict):
    min_dihedral: npt.NDArray[np.float64]
    max_dihedral: npt.NDArray[np.float64]
    quality: npt.NDArray[np.float64]
    volume: npt.NDArray[np.float64]

class BuildNotes(TypedDict):
    reoriented: int
    unreferenced_points: int
    dropped_triangles: int
    dropped_edges: int

class VertexParents(TypedDict):
    """Per output point: the input tet holding it, that tet's vertices, the
    point's barycentric coordinates for them, and whether it lies outside."""

    tet: npt.NDArray[np.uint32]
    vertices: npt.NDArray[np.uint32]
    bary: npt.NDArray[np.float64]
    outside: npt.NDArray[np.bool_]

Phase = Literal["split", "flip", "boundary-split", "boundary-flip", "boundary-smooth", "optimize"]

class Mesh:
    """A tetrahedral mesh (immutable): points, positively oriented tets,
    regions, marked faces and feature edges. See ``help(tetrefine.Mesh)``."""

    def __init__(
        self,
        points: _Reals,
        tets: _Ints,
        regions: _Ints | None = None,
        boundary_faces: _Ints | None = None,
        boundary_markers: _Ints | None = None,
        feature_edges: _Ints | None = None,
        corners: _Ints | None = None,
    ) -> None: ...
    @property
    def n_points(self) -> int: ...
    @property
    def n_tets(self) -> int: ...
    @property
    def points(self) -> npt.NDArray[np.float64]:
        """(n_points, 3), read-only view (no copy)."""
    @property
    def tets(self) -> npt.NDArray[np.uint32]:
        """(n_tets, 4), read-only view (no copy), positively oriented."""
    @property
    def regions(self) -> npt.NDArray[np.int32]: ...
    @property
    def level(self) -> npt.NDArray[np.uint8]: ...
    @property
    def parent(self) -> npt.NDArray[np.uint32]: ...
    @property
    def marked(self) -> npt.NDArray[np.bool_]: ...
    @property
    def boundary_faces(self) -> npt.NDArray[np.uint32]: ...
    @property
    def boundary_markers(self) -> npt.NDArray[np.int32]: ...
    @property
    def feature_edges(self) -> npt.NDArray[np.uint32]: ...
    @property
    def corners(self) -> npt.NDArray[np.uint32]: ...
    @property
    def point_fields(self) -> dict[str, npt.NDArray[np.float64]]:
        """Point fields refine() carried over: (n_points,) or (n_points, k)."""
    @property
    def cell_fields(self) -> dict[str, npt.NDArray[np.float64]]:
        """Cell fields refine() carried over (by parent): (n_tets,) or (n_tets, k)."""
    @property
    def vertex_parents(self) -> VertexParents | None:
        """The vertex parent map of a refine() with fields or vertex_parents=True."""
    @property
    def reports(self) -> list[dict[str, Any]]: ...
    @property
    def build_notes(self) -> BuildNotes: ...
    @property
    def timings(self) -> dict[str, float] | None: ...
    def quality(self, bins: int = 71) -> Quality: ...
    def tet_quality(self) -> TetQuality: ...
    def write(self, path: _Path) -> None: ...
    def refine(
        self,
        steps: int | Literal["auto"] | None = None,
        *,
        boundary: Literal["interpolating", "approximating", "linear"] = "interpolating",
        opt_passes: int = 3,
        threshold: float = 0.35,
        stop_after: Phase | None = None,
        features: Union[Literal["auto", "none"], _Path] = "auto",
        feature_angle: float = 45.0,
        indicator: _Reals | None = None,
        mark: str | Sequence[str] | None = "doerfler:0.5",
        region: int | Sequence[int] | None = None,
        box: Sequence[float] | None = None,
        sphere: Sequence[float] | None = None,
        smooth: Literal["refined", "all"] = "refined",
        step_offset: int = 0,
        progress: bool | Callable[[int, str, int], object] = False,
        stats: bool = False,
        allow_empty: bool = False,
        allow_steps_zero: bool = False,
        point_fields: dict[str, _Reals] | None = None,
        cell_fields: dict[str, _Reals] | None = None,
        transfer: bool | None = None,
        vertex_parents: bool = False,
        size: _Reals | None = None,
        hsiz: float | None = None,
        hmax: float | None = None,
        effort: str = "default",
        hausd: float | None = None,
        interfaces: Literal["linear", "sqrt3"] = "linear",
    ) -> Mesh: ...
    def improve(
        self,
        opt_passes: int = 5,
        *,
        threshold: float = 0.35,
        effort: str = "default",
        hausd: float | None = None,
        features: str = "auto",
        feature_angle: float = 45.0,
    ) -> Mesh: ...
    def bisect(self, steps: int = 1) -> Mesh: ...
    def to_meshio(self, faces: bool = True) -> Any:
        """A meshio.Mesh (needs meshio)."""
    def to_pyvista(self) -> Any:
        """A pyvista.UnstructuredGrid (needs pyvista)."""

def read(path: _Path) -> Mesh: ...
def from_meshio(m: Any) -> Mesh: ...

# Only in builds with the `tetgen` feature (HAS_TETGEN is True).
def mesh_surface(
    surface: Union[_Path, tuple[_Reals, _Ints], tuple[_Reals, _Ints, _Ints]],
    *,
    min_ratio: float | None = None,
    min_dihedral: float | None = None,
    max_volume: float | None = None,
    switches: str | None = None,
    time_limit: float | None = None,
) -> Mesh: ...
