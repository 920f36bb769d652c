//! 2-3 face flip: two tets sharing a face become three around the edge that
//! joins their apexes.
//!
//! ```text
//!            q                  before: (a,b,c) shared by the tets with
//!           /|\                         apexes p (below) and q (above)
//!          / | \                after:  (a,b,p,q) (b,c,p,q) (c,a,p,q)
//!         a--|--c                       around the new edge p-q
//!          \ | /                valid only where segment p-q crosses the
//!           \|/                 interior of (a,b,c): otherwise a new tet
//!            b   (p below)      is flat or inverted and the flip is refused
//! ```
//!
//! Seed paper §3.1 (its Figure 5); the precondition is the one of Lehner's
//! thesis that the paper cites.

use super::{replace_cavity, OpError};
use crate::mesh::{TetMesh, NO_ADJ};

/// The three tets a 2-3 flip of face `f` of tet `t` would create, or `None`
/// for a boundary face.
pub fn flip23_tets(mesh: &TetMesh, t: u32, f: usize) -> Option<[[u32; 4]; 3]> {
    let h = mesh.adj(t)[f];
    if h == NO_ADJ {
        return None;
    }
    let (u, g) = TetMesh::half_face(h);
    let [a, b, c] = mesh.face_vertices(t, f);
    let p = mesh.tet(t)[f];
    let q = mesh.tet(u)[g];
    Some([[a, b, p, q], [b, c, p, q], [c, a, p, q]])
}

/// Whether the 2-3 flip of face `f` of tet `t` would create three positive
/// tets (the segment between the apexes crosses the face's interior).
pub fn flip23_valid(mesh: &TetMesh, t: u32, f: usize) -> bool {
    flip23_tets(mesh, t, f).is_some_and(|n| super::all_positive(mesh, &n))
}

/// Flips face `f` of tet `t` (an interior face) and returns the three new tets.
/// Refused across faces between different regions.
pub fn flip23(mesh: &mut TetMesh, t: u32, f: usize) -> Result<[u32; 3], OpError> {
    let h = mesh.adj(t)[f];
    if h == NO_ADJ {
        return Err(OpError::NotApplicable("boundary face"));
    }
    let (u, g) = TetMesh::half_face(h);
    if mesh.region(t) != mesh.region(u) {
        return Err(OpError::NotApplicable("face between two regions"));
    }
    let _ = g;
    // The face seen from t is outward (normal towards q).
    let new = flip23_tets(mesh, t, f).ok_or(OpError::NotApplicable("boundary face"))?;
    let ids = replace_cavity(mesh, &[t, u], &new)?;
    Ok([ids[0], ids[1], ids[2]])
}
