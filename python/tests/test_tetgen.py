"""tetrefine.mesh_surface exists exactly in builds with the `tetgen`
feature; there it fills a closed surface as `tetrefine mesh` does."""

import numpy as np
import pytest

import tetrefine
from conftest import MESHES


def test_mesh_surface_only_with_tetgen(tmp_path):
    if not tetrefine.HAS_TETGEN:
        assert not hasattr(tetrefine, "mesh_surface")
        with pytest.raises(AttributeError, match="built without TetGen"):
            tetrefine.mesh_surface  # noqa: B018
        return
    # A unit cube as 12 triangles: the volume is 1 (closed form).
    p = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]
    m = tetrefine.mesh_surface((p, tris), max_volume=0.01)
    assert m.quality()["volume"] == pytest.approx(1.0, rel=1e-9)
    assert m.n_tets >= 100
    poly = MESHES / "tetgen_example.poly"
    a = tetrefine.mesh_surface(poly, min_dihedral=18)
    assert a.quality()["min_dihedral_deg"]["worst"] >= 17.9
    with pytest.raises(FileNotFoundError):
        tetrefine.mesh_surface(tmp_path / "missing.poly")
