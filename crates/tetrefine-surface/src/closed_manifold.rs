//! The closed-surface check of the Sierpinski and truncation schemes: a thin
//! layer over [`HalfEdges`], which does the adjacency and the manifold and
//! orientation validation for every scheme.

use super::error::SurfaceError;
use super::polymesh::{HalfEdges, PolyMesh, NO_TWIN};

/// The half-edges of `mesh` after checking that it is a non-empty, closed,
/// consistently oriented 2-manifold with finite points: the checks of
/// [`HalfEdges::build`] (reported as [`SurfaceError`]s), plus
/// [`SurfaceError::Empty`], [`SurfaceError::NonFinite`] and
/// [`SurfaceError::OpenEdge`] for the first half-edge without a twin.
pub(crate) fn closed_half_edges(mesh: &PolyMesh) -> Result<HalfEdges, SurfaceError> {
    if mesh.faces.is_empty() {
        return Err(SurfaceError::Empty);
    }
    if let Some(vertex) = mesh.points.iter().position(|p| !p.is_finite()) {
        return Err(SurfaceError::NonFinite { vertex });
    }
    let he = mesh.half_edges()?;
    if let Some(h) = he.twin.iter().position(|&t| t == NO_TWIN) {
        return Err(SurfaceError::OpenEdge {
            from: he.origin[h],
            to: he.dest(h as u32),
            face: he.face[h] as usize,
        });
    }
    Ok(he)
}
