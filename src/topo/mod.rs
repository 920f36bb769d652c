//! Local tables of a tetrahedron, their inverses, the one edge and face key,
//! and the parallel scatter helpers (`scatter`) that hold all of the core's
//! scatter `unsafe` (the rest: libc calls in `file::atomic` and `tetgen`,
//! the AVX2 dispatch of `report::stats`).
//!
//! Local numbering: vertices `0..4`; face `f` is the triangle without vertex
//! `f`; the six edges are listed in [`TET_EDGES`]; edge `e` joins
//! `TET_EDGES[e]` and is the intersection of the faces opposite the two other
//! vertices ([`TET_EDGE_OPPOSITE`]).
//!
//! ```text
//!            3
//!           /|\          edges: 0:(0,1) 1:(0,2) 2:(0,3)
//!          / | \                3:(1,2) 4:(1,3) 5:(2,3)
//!         /  |  \        face f = the triangle without vertex f,
//!        0---|---2       outward-oriented as TET_FACES[f]
//!         \  |  /
//!          \ | /
//!            1
//! ```
//!
//! Beside each forward table stands its inverse, as in MMG: [`EDGE_OF`]
//! (local vertices → local edge) inverts [`TET_EDGES`].

pub(crate) mod scatter;

/// The six edges of a tet as pairs of local vertex indices.
pub const TET_EDGES: [[usize; 2]; 6] = [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]];
/// For each edge of [`TET_EDGES`], the two local vertices not on it (the faces
/// opposite those two vertices meet along the edge).
pub const TET_EDGE_OPPOSITE: [[usize; 2]; 6] = [[2, 3], [1, 3], [1, 2], [0, 3], [0, 2], [0, 1]];
/// Face `f` (opposite local vertex `f`), ordered so that its right-hand normal
/// points out of a positively oriented tet.
pub const TET_FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];

/// No local edge: the diagonal of [`EDGE_OF`].
pub const NO_EDGE: u8 = 6;

/// Inverse of [`TET_EDGES`]: `EDGE_OF[i][j]` is the local edge joining local
/// vertices `i != j` (either order); [`NO_EDGE`] on the diagonal.
pub const EDGE_OF: [[u8; 4]; 4] = [[6, 0, 1, 2], [0, 6, 3, 4], [1, 3, 6, 5], [2, 4, 5, 6]];

/// The local edge joining local vertices `i != j`.
#[inline]
pub fn local_edge(i: usize, j: usize) -> usize {
    debug_assert!(
        i < 4 && j < 4 && i != j,
        "no edge joins local vertices {i} and {j}"
    );
    EDGE_OF[i][j] as usize
}

/// A face key: the three vertex ids sorted ascending.
pub type FaceKey = [u32; 3];
/// An edge key: the two vertex ids sorted ascending.
pub type EdgeKey = [u32; 2];

/// Sorted key of a triangle.
#[inline]
pub fn face_key(mut f: [u32; 3]) -> FaceKey {
    if f[0] > f[1] {
        f.swap(0, 1);
    }
    if f[1] > f[2] {
        f.swap(1, 2);
    }
    if f[0] > f[1] {
        f.swap(0, 1);
    }
    f
}

/// Sorted key of an edge.
#[inline]
pub fn edge_key(a: u32, b: u32) -> EdgeKey {
    if a < b {
        [a, b]
    } else {
        [b, a]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edge_of_inverts_tet_edges() {
        for (e, &[i, j]) in TET_EDGES.iter().enumerate() {
            assert_eq!(local_edge(i, j), e);
            assert_eq!(local_edge(j, i), e);
        }
        for (i, row) in EDGE_OF.iter().enumerate() {
            assert_eq!(row[i], NO_EDGE);
        }
    }

    #[test]
    fn opposite_edges_are_the_complement() {
        for (e, &[i, j]) in TET_EDGES.iter().enumerate() {
            let [k, l] = TET_EDGE_OPPOSITE[e];
            let mut all = [i, j, k, l];
            all.sort_unstable();
            assert_eq!(all, [0, 1, 2, 3]);
            // The faces opposite k and l both hold the edge.
            for f in [k, l] {
                assert!(TET_FACES[f].contains(&i) && TET_FACES[f].contains(&j));
            }
        }
    }

    #[test]
    fn faces_leave_out_their_vertex() {
        for (f, l) in TET_FACES.iter().enumerate() {
            assert!(!l.contains(&f));
        }
    }

    #[test]
    fn keys_sort() {
        assert_eq!(edge_key(5, 2), [2, 5]);
        assert_eq!(face_key([9, 1, 4]), [1, 4, 9]);
        assert_eq!(face_key([1, 9, 4]), [1, 4, 9]);
    }
}
