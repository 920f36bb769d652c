//! Vertex valences (and so the edge count) from counts of tets and boundary
//! faces per vertex, by Euler's formula on the vertex links, without walking
//! around any edge.
//!
//! The link of vertex `v` is the triangulated surface made of the faces
//! opposite `v` in the tets around it: one triangle per tet at `v` (`n_t`),
//! one link vertex per edge at `v` (the valence), and one boundary edge per
//! boundary face at `v` (`n_bf`). Every link edge (a mesh face at `v`) lies in
//! two link triangles, or in one if it is a boundary face, so the link has
//! `(3 n_t + n_bf) / 2` edges, and Euler's formula `V − E + F = χ` gives
//!
//! `valence(v) = χ(link) + (n_t + n_bf) / 2`,
//!
//! with `χ = 2` for an interior vertex (the link is a sphere) and `χ = 1` for
//! a boundary vertex whose link is a disk.
//!
//! When the tets do not overlap (the premise of every count here: each edge of
//! the mesh then has one ring or fan of tets around it for each pair of its
//! boundary faces, and each vertex link is a surface in the sphere of
//! directions around `v`), the link of an interior vertex is one sphere, and
//! that of a boundary vertex is a disk exactly when its boundary is one cycle
//! and no edge at `v` has more than two boundary faces. That is checked per
//! boundary vertex on the boundary faces around it ([`link_is_a_disk`]);
//! where it fails — a pinched vertex, where the domain touches itself at a
//! point, or a pinched edge, where it touches itself along an edge — the
//! valence is counted exactly, by collecting the neighbours of those vertices
//! ([`count_neighbours`]).

use crate::mesh::{TetMesh, DEAD, NO_ADJ};
use crate::topo::TET_FACES;
use rayon::prelude::*;

/// Valence of each point slot (0 for points no tet uses), given the number
/// of tets at each point and the boundary faces (outward-oriented, as
/// [`TET_FACES`] orders them).
pub(super) fn valences(
    tets: &[[u32; 4]],
    tets_at: &[u32],
    boundary_faces: &[[u32; 3]],
) -> Vec<u32> {
    let n = tets_at.len();
    // The boundary faces around each vertex, as the link edge each one gives
    // (the two other corners, in the face's order): counting sort.
    let mut start = vec![0u32; n + 1];
    for f in boundary_faces {
        for &v in f {
            start[v as usize + 1] += 1;
        }
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    let mut link = vec![[0u32; 2]; start[n] as usize];
    let mut fill = start.clone();
    for &[a, b, c] in boundary_faces {
        for (v, edge) in [(a, [b, c]), (b, [c, a]), (c, [a, b])] {
            link[fill[v as usize] as usize] = edge;
            fill[v as usize] += 1;
        }
    }
    const NEEDS_COUNT: u32 = u32::MAX;
    let mut valence: Vec<u32> = (0..n)
        .into_par_iter()
        .with_min_len(4096)
        .map(|v| {
            let nt = tets_at[v];
            let links = &link[start[v] as usize..start[v + 1] as usize];
            let nbf = links.len() as u32;
            if nt == 0 {
                if nbf == 0 {
                    0
                } else {
                    NEEDS_COUNT // cannot happen: boundary faces belong to tets
                }
            } else if (nt + nbf) % 2 != 0 {
                NEEDS_COUNT // not a surface: Euler's formula does not apply
            } else if nbf == 0 {
                2 + nt / 2
            } else if link_is_a_disk(links) {
                1 + (nt + nbf) / 2
            } else {
                NEEDS_COUNT
            }
        })
        .collect();
    let pinched: Vec<u32> = (0..n as u32)
        .filter(|&v| valence[v as usize] == NEEDS_COUNT)
        .collect();
    if !pinched.is_empty() {
        for (v, count) in pinched.iter().zip(count_neighbours(tets, n, &pinched)) {
            valence[*v as usize] = count;
        }
    }
    valence
}

/// Whether the link edges `links` (one per boundary face at a vertex, from
/// the face's second corner to its third, all faces oriented alike) form a
/// single cycle through distinct link vertices: the boundary of a disk, with
/// no edge at the vertex in more than two boundary faces.
fn link_is_a_disk(links: &[[u32; 2]]) -> bool {
    let n = links.len();
    if n < 3 {
        return false;
    }
    // Sorted by tail, the tails must be distinct (a tail seen twice is an
    // edge with four or more boundary faces, or faces oriented both ways).
    let mut sorted = [[0u32; 2]; 16];
    let mut heap;
    let sorted: &mut [[u32; 2]] = if n <= sorted.len() {
        sorted[..n].copy_from_slice(links);
        &mut sorted[..n]
    } else {
        heap = links.to_vec();
        &mut heap
    };
    sorted.sort_unstable();
    if sorted.windows(2).any(|w| w[0][0] == w[1][0]) {
        return false;
    }
    // Follow heads to tails from the first edge: one cycle iff it comes back
    // after exactly n edges (every tail visited once, so the heads are the
    // tails in another order).
    let first = sorted[0][0];
    let mut at = sorted[0];
    for _ in 1..n {
        match sorted.binary_search_by_key(&at[1], |e| e[0]) {
            Ok(i) if sorted[i][0] != first => at = sorted[i],
            _ => return false,
        }
    }
    at[1] == first
}

/// Exact number of distinct neighbours of each vertex of `vertices` (sorted,
/// distinct), by collecting the corners of the tets around them.
fn count_neighbours(tets: &[[u32; 4]], n_points: usize, vertices: &[u32]) -> Vec<u32> {
    let mut slot = vec![u32::MAX; n_points];
    for (i, &v) in vertices.iter().enumerate() {
        slot[v as usize] = i as u32;
    }
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); vertices.len()];
    for t in tets {
        if t[0] == DEAD {
            continue;
        }
        for (i, &v) in t.iter().enumerate() {
            let s = slot[v as usize];
            if s != u32::MAX {
                let list = &mut neighbours[s as usize];
                list.extend((0..4).filter(|&j| j != i).map(|j| t[j]));
            }
        }
    }
    neighbours
        .into_iter()
        .map(|mut list| {
            list.sort_unstable();
            list.dedup();
            list.len() as u32
        })
        .collect()
}

/// Per-vertex valence of `mesh` on its own (one pass over the tets, for
/// callers that need only the valences).
pub(super) fn vertex_valence(mesh: &TetMesh) -> Vec<u32> {
    let mut tets_at = vec![0u32; mesh.n_points()];
    let mut boundary_faces = Vec::new();
    for (t, v) in mesh.tets.iter().enumerate() {
        if v[0] == DEAD {
            continue;
        }
        for &x in v {
            tets_at[x as usize] += 1;
        }
        for (f, &h) in mesh.adj[t].iter().enumerate() {
            if h == NO_ADJ {
                boundary_faces.push(TET_FACES[f].map(|i| v[i]));
            }
        }
    }
    valences(&mesh.tets, &tets_at, &boundary_faces)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn disk_links() {
        assert!(link_is_a_disk(&[[1, 2], [2, 3], [3, 1]]));
        assert!(link_is_a_disk(&[[5, 9], [2, 7], [9, 2], [7, 5]]));
        // Two cycles (a pinched vertex).
        assert!(!link_is_a_disk(&[
            [1, 2],
            [2, 3],
            [3, 1],
            [4, 5],
            [5, 6],
            [6, 4]
        ]));
        // Link vertex 1 twice as a tail (an edge with four boundary faces).
        assert!(!link_is_a_disk(&[[1, 2], [2, 1], [1, 3], [3, 1]]));
        // A face oriented the other way.
        assert!(!link_is_a_disk(&[[1, 2], [3, 2], [3, 1]]));
        // Open chains, and too short to be a cycle.
        assert!(!link_is_a_disk(&[[1, 2], [2, 3], [3, 4]]));
        assert!(!link_is_a_disk(&[[1, 2], [2, 1]]));
        // Long cycles take the sorting path.
        let long: Vec<[u32; 2]> = (0..40).map(|i| [i, (i + 1) % 40]).collect();
        assert!(link_is_a_disk(&long));
        let mut two = long.clone();
        two[39] = [39, 20];
        assert!(!link_is_a_disk(&two));
    }
}
