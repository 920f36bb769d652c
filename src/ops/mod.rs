//! Local operations on the tet mesh, one family per file.
//!
//! Every operation has the same shape: gather the cavity (the tets
//! it removes), build the new tets, check each with the exact `orient3d`,
//! and only then replace the cavity — re-using the freed slots and re-linking
//! the outer faces with `bond`. An operation that would create an inverted or
//! flat tet returns [`OpError::WouldInvert`] and leaves the mesh untouched.
//! The shared re-linking lives here in [`replace_cavity`].

pub(crate) mod boundary_flip;
pub(crate) mod bulk_flip;
pub(crate) mod bulk_split;
pub(crate) mod cap_removal;
pub(crate) mod edge_contraction;
pub(crate) mod edge_removal;
pub(crate) mod edge_split;
pub(crate) mod face_removal;
pub(crate) mod flip23;
pub(crate) mod flip32;
pub(crate) mod flip_repair;
pub(crate) mod interface;
pub(crate) mod split13;
pub(crate) mod split14;
pub(crate) mod trisect;

use crate::mesh::{face_key, FaceKey, TetMesh, NO_ADJ};
use crate::topo::TET_FACES;

pub use boundary_flip::{boundary_flip_ring, flip_boundary_edge, BoundaryFlipLimits, TetsAtVertex};
pub use bulk_flip::{flip23_bulk, FlipBatch};
pub(crate) use bulk_split::is_selected;
pub use bulk_split::split14_bulk;
pub use cap_removal::{is_cap_below, remove_boundary_cap, CapLimits};
pub use edge_contraction::{contract_boundary_edge, contract_edge};
pub use edge_removal::{remove_edge, EdgeRing};
pub use edge_split::split_edge;
pub(crate) use edge_split::split_halves;
pub use face_removal::{remove_faces, FaceRemoval};
pub use flip23::{flip23, flip23_tets, flip23_valid};
pub use flip32::flip32;
pub use flip_repair::make_flips_valid;
pub use interface::{remove_interface_edge, split_interface_face};
pub use split13::split_boundary_face;
pub use split14::split14;
pub use trisect::trisect_edge;

/// Why an operation was not applied. The mesh is unchanged in every case.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum OpError {
    /// A new tet would be inverted or flat (exact predicate).
    #[error("a new tetrahedron would be inverted or flat")]
    WouldInvert,
    /// The configuration does not fit the operation (e.g. a boundary face given
    /// to a flip, an edge with the wrong number of tets).
    #[error("operation does not apply here: {0}")]
    NotApplicable(&'static str),
    /// The operation would not improve the quality it was asked to beat.
    #[error("no improvement")]
    NoImprovement,
}

/// Whether every tet in `tets` is positively oriented (exact predicate).
pub fn all_positive(mesh: &TetMesh, tets: &[[u32; 4]]) -> bool {
    crate::geom::all_positive(tets.iter().map(|v| v.map(|x| mesh.point(x))))
}

/// Replaces the tets `old` by the tets `new`, re-using slots and re-linking
/// adjacency. The new tets must fill the cavity: each of their faces is either
/// shared by two new tets, equal to an outer face of the cavity, or a new
/// boundary face; each outer face of the cavity with a neighbour must be
/// matched (outer *boundary* faces may disappear — a boundary flip).
///
/// New boundary faces inherit the marker of the removed boundary faces when
/// those all had the same one. A cavity whose interior holds a marked face is
/// refused, as is one whose tets lie in different regions. New tets take the
/// region, the highest `level` and that tet's `parent`.
///
/// Everything is checked before the mesh is touched: on error it is unchanged.
pub fn replace_cavity(
    mesh: &mut TetMesh,
    old: &[u32],
    new: &[[u32; 4]],
) -> Result<Vec<u32>, OpError> {
    let region = mesh.region(old[0]);
    if old.iter().any(|&t| mesh.region(t) != region) {
        return Err(OpError::NotApplicable("cavity spans two regions"));
    }
    if !mesh.face_markers().is_empty() {
        for &t in old {
            for (f, &h) in mesh.adj(t).iter().enumerate() {
                if h != NO_ADJ
                    && (h >> 2) > t
                    && old.contains(&(h >> 2))
                    && mesh.face_marker(mesh.face_vertices(t, f)).is_some()
                {
                    return Err(OpError::NotApplicable("would remove a marked face"));
                }
            }
        }
    }
    let oldest = (0..old.len())
        .max_by_key(|&i| (mesh.level(old[i]), std::cmp::Reverse(i)))
        .expect("a cavity holds at least one tet (old[0] was read above)");
    let origin = vec![oldest; new.len()];
    replace_cavity_raw(mesh, old, new, &origin)
}

/// The core of [`replace_cavity`] for operations that manage regions and
/// interior markers themselves (trisection, interface splits and flips):
/// new tet `i` takes region, level and parent of `old[origin[i]]`; marked
/// faces inside the cavity are not checked (the caller moves their markers).
pub(crate) fn replace_cavity_raw(
    mesh: &mut TetMesh,
    old: &[u32],
    new: &[[u32; 4]],
    origin: &[usize],
) -> Result<Vec<u32>, OpError> {
    debug_assert_eq!(origin.len(), new.len());
    if !all_positive(mesh, new) {
        return Err(OpError::WouldInvert);
    }
    let check_markers = !mesh.face_markers().is_empty();
    // Outer faces of the cavity: (key, outside half-face or NO_ADJ).
    let mut outer: Vec<(FaceKey, u32)> = Vec::with_capacity(2 * old.len() + 2);
    for &t in old {
        let adj = mesh.adj(t);
        for (f, &h) in adj.iter().enumerate() {
            if h != NO_ADJ && old.contains(&(h >> 2)) {
                continue;
            }
            outer.push((face_key(mesh.face_vertices(t, f)), h));
        }
    }
    // Open faces of the new set, before touching the mesh.
    let mut open: Vec<FaceKey> = Vec::with_capacity(4 * new.len());
    for v in new {
        for l in TET_FACES {
            let k = face_key([v[l[0]], v[l[1]], v[l[2]]]);
            if let Some(i) = open.iter().position(|o| *o == k) {
                open.swap_remove(i);
            } else {
                open.push(k);
            }
        }
    }
    let mut removed_marker: Option<Option<i32>> = None;
    let mut uniform = true;
    for (k, h) in &outer {
        if open.contains(k) {
            continue;
        }
        if *h != NO_ADJ {
            return Err(OpError::NotApplicable("new tets do not fill the cavity"));
        }
        let m = mesh.face_marker(*k);
        match removed_marker {
            None => removed_marker = Some(m),
            Some(prev) if prev != m => uniform = false,
            _ => {}
        }
    }
    let new_marker = if uniform {
        removed_marker.flatten()
    } else {
        None
    };

    let info: Vec<(i32, u8, u32)> = origin
        .iter()
        .map(|&i| (mesh.region(old[i]), mesh.level(old[i]), mesh.parent(old[i])))
        .collect();
    if check_markers {
        for (k, h) in &outer {
            if *h == NO_ADJ && !open.contains(k) {
                mesh.set_face_marker(*k, None);
            }
        }
    }
    for &t in old {
        mesh.kill_tet(t);
    }
    let ids: Vec<u32> = new
        .iter()
        .zip(&info)
        .map(|(&v, &(region, level, parent))| {
            let t = mesh.alloc_tet(v, region);
            mesh.set_level(t, level);
            mesh.set_parent(t, parent);
            t
        })
        .collect();
    link_faces(mesh, &ids, &outer, new_marker);
    Ok(ids)
}

/// Bonds the faces of the new tets `ids` with each other and with the outer
/// half-faces (matched by sorted vertex key); unmatched faces become boundary
/// faces and take `boundary_marker`. Small cavities only: O(k²).
pub(crate) fn link_faces(
    mesh: &mut TetMesh,
    ids: &[u32],
    outer: &[(FaceKey, u32)],
    boundary_marker: Option<i32>,
) {
    let mut open: Vec<(FaceKey, u32)> = Vec::with_capacity(4 * ids.len());
    for &t in ids {
        let v = mesh.tet(t);
        for (f, l) in TET_FACES.iter().enumerate() {
            let k = face_key([v[l[0]], v[l[1]], v[l[2]]]);
            let h = 4 * t + f as u32;
            if let Some(i) = open.iter().position(|(ok, _)| *ok == k) {
                let (_, other) = open.swap_remove(i);
                mesh.bond(h, other);
            } else {
                open.push((k, h));
            }
        }
    }
    for (k, h) in open {
        match outer.iter().find(|(ok, _)| *ok == k) {
            Some(&(_, out)) => mesh.bond(h, out),
            None => {
                mesh.bond(h, NO_ADJ);
                if boundary_marker.is_some() {
                    mesh.set_face_marker(k, boundary_marker);
                }
            }
        }
    }
}
