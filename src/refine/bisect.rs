//! Uniform 1:8 red refinement by edge bisection: the speed-of-light reference
//! that the √3 step is measured against.
//!
//! Every edge gets its midpoint; every tet becomes the four corner tets at its
//! vertices and four tets that split the inner octahedron of the six edge
//! midpoints along one of its three diagonals. This is the regular ("red")
//! refinement of J. Bey, "Tetrahedral grid refinement", Computing 55 (1995),
//! and of Freudenthal's subdivision; as in H. Zhang's and in mmg's uniform
//! split, the octahedron is cut along its *shortest* diagonal, which keeps the
//! children's shapes within a bounded number of similarity classes.
//!
//! The step works on the [`TetMesh`] store directly, in parallel and without
//! any global hash table or sort:
//!
//! 1. per tet, the owner of each of its six edges is the smallest tet id in the
//!    edge's ring (a walk through face adjacency), and the octahedron diagonal
//!    is chosen;
//! 2. owned edges are numbered by a prefix sum over the tets, so midpoint ids
//!    follow tet order and do not depend on the number of threads;
//! 3. tet `t` writes children `8t..8t+8`, with their adjacency read from
//!    fixed templates: faces inside the parent link to siblings, faces on a
//!    parent face link to the matching child of the neighbour across it.
//!
//! Every child is checked with the exact [`orient3d_sign`]; in exact
//! arithmetic all eight children of a positive tet are positive, but the
//! rounded midpoints of a nearly flat tet might not be, and then the step
//! fails rather than produce an inverted mesh.
//!
//! Tags follow the geometry: region, level + 1 and parent (the input tet the
//! parent descends from) are inherited; a marked face gives its four child
//! faces the marker, a feature edge its two halves; corners and required
//! vertices keep their ids (old points keep theirs, midpoints come after).

use crate::geom::{orient3d_sign, Orientation};
use crate::mesh::{edge_key, face_key, EdgeKey, FaceKey, TetMesh, DEAD, NO_ADJ};
use crate::topo::TET_EDGES;
use glam::DVec3;
use rayon::prelude::*;
use std::sync::OnceLock;

/// Why a bisection step could not be done.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum BisectError {
    /// The output would not fit the store's `u32` ids.
    #[error("{tets} tetrahedra and {points} points are too many for one bisection step (at most {max_tets} tetrahedra and 4294967294 points after the step)")]
    TooLarge {
        /// Live tets of the input.
        tets: usize,
        /// Points after the step.
        points: usize,
        /// Largest input tet count a step can take.
        max_tets: usize,
    },
    /// A child would not be positively oriented (rounded midpoints of a
    /// nearly flat tet).
    #[error("tetrahedron {tet} is too flat to bisect: its child {child} would not be positively oriented")]
    Inverted {
        /// 1-based number of the tet among the live tets.
        tet: usize,
        /// Which child (0–3 corner tets, 4–7 octahedron tets).
        child: usize,
    },
    /// A marked face or feature edge names no face or edge of the mesh.
    #[error("the tagged {what} {vertices:?} (1-based) is not one of the mesh's")]
    DanglingTag {
        /// "face" or "edge".
        what: &'static str,
        /// Its 1-based vertex numbers.
        vertices: Vec<u64>,
    },
}

/// The largest number of input tets one step accepts: the output adjacency
/// `4 * (8 t + c) + f` must fit a `u32`.
pub const MAX_INPUT_TETS: usize = (u32::MAX as usize) / 32;

/// Where a child's face lies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Link {
    /// Shared with face `face` of sibling `child`.
    Inner { child: u8, face: u8 },
    /// On face `parent_face` of the parent, as the sub-triangle at parent
    /// vertex `sub` (0–3) or the central one (`sub == 4`).
    Outer { parent_face: u8, sub: u8 },
}

/// The red refinement of one tet for one choice of octahedron diagonal.
///
/// Nodes 0–3 are the parent's vertices, node `4 + e` the midpoint of
/// `TET_EDGES[e]`.
#[derive(Clone, Debug)]
struct Template {
    /// Child `c`'s four nodes, positively oriented.
    children: [[u8; 4]; 8],
    /// Where each face of each child lies.
    links: [[Link; 4]; 8],
    /// `on_face[f][s]`: (child, child face) covering sub-triangle `s` of
    /// parent face `f` (`s` = parent vertex 0–3, or 4 for the central one).
    on_face: [[(u8, u8); 5]; 4],
}

/// Local edge index of the edge between local vertices `i` and `j`.
const EDGE_INDEX: [[u8; 4]; 4] = {
    let mut t = [[u8::MAX; 4]; 4];
    let mut e = 0;
    while e < 6 {
        let (i, j) = (TET_EDGES[e][0], TET_EDGES[e][1]);
        t[i][j] = e as u8;
        t[j][i] = e as u8;
        e += 1;
    }
    t
};

/// The three octahedron diagonals as pairs of opposite parent edges.
const DIAGONALS: [[usize; 2]; 3] = [[0, 5], [1, 4], [2, 3]];

/// Node of the midpoint of the edge between parent vertices `i` and `j`.
fn mid_node(i: usize, j: usize) -> u8 {
    4 + EDGE_INDEX[i][j]
}

/// Whether node `n` lies on parent face `f` (the face opposite vertex `f`).
fn node_on_parent_face(n: u8, f: usize) -> bool {
    if n < 4 {
        n as usize != f
    } else {
        !TET_EDGES[(n - 4) as usize].contains(&f)
    }
}

fn build_template(diagonal: usize) -> Template {
    // A positively oriented reference tet: children are affine images of the
    // parent, so their orientation here is their orientation everywhere.
    let mut reference = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    if orient3d_sign(reference[0], reference[1], reference[2], reference[3])
        != Orientation::Positive
    {
        reference.swap(0, 1);
    }
    let node_pos = |n: u8| -> DVec3 {
        if n < 4 {
            reference[n as usize]
        } else {
            let [i, j] = TET_EDGES[(n - 4) as usize];
            (reference[i] + reference[j]) * 0.5
        }
    };
    let mut children = [[0u8; 4]; 8];
    // Corner child i: the parent scaled by 1/2 about vertex i, vertex order kept.
    for (i, child) in children.iter_mut().enumerate().take(4) {
        for (j, node) in child.iter_mut().enumerate() {
            *node = if i == j { i as u8 } else { mid_node(i, j) };
        }
    }
    // Octahedron: the diagonal p–q and the four other midpoints in cycle order
    // (consecutive ones share a parent vertex: opposite edges are the other
    // two diagonals, so take x0, y0, x1, y1).
    let [ea, eb] = DIAGONALS[diagonal];
    let (p, q) = (4 + ea as u8, 4 + eb as u8);
    let others: Vec<[usize; 2]> = DIAGONALS
        .iter()
        .enumerate()
        .filter(|&(d, _)| d != diagonal)
        .map(|(_, &pair)| pair)
        .collect();
    let cycle = [
        4 + others[0][0] as u8,
        4 + others[1][0] as u8,
        4 + others[0][1] as u8,
        4 + others[1][1] as u8,
    ];
    for k in 0..4 {
        let mut t = [p, q, cycle[k], cycle[(k + 1) % 4]];
        let s = t.map(node_pos);
        if orient3d_sign(s[0], s[1], s[2], s[3]) == Orientation::Negative {
            t.swap(0, 1);
        }
        children[4 + k] = t;
    }
    for c in &children {
        let s = c.map(node_pos);
        assert_eq!(
            orient3d_sign(s[0], s[1], s[2], s[3]),
            Orientation::Positive,
            "red refinement template child not positive"
        );
    }

    let face_nodes = |c: usize, f: usize| -> [u8; 3] {
        let mut k = [0u8; 3];
        let mut w = 0;
        for (i, &n) in children[c].iter().enumerate() {
            if i != f {
                k[w] = n;
                w += 1;
            }
        }
        k.sort_unstable();
        k
    };
    let mut links = [[Link::Outer {
        parent_face: 0,
        sub: 0,
    }; 4]; 8];
    let mut on_face = [[(u8::MAX, u8::MAX); 5]; 4];
    for (c, child_links) in links.iter_mut().enumerate() {
        for (f, link) in child_links.iter_mut().enumerate() {
            let k = face_nodes(c, f);
            let sibling = (0..8)
                .filter(|&c2| c2 != c)
                .flat_map(|c2| (0..4).map(move |f2| (c2, f2)))
                .find(|&(c2, f2)| face_nodes(c2, f2) == k);
            *link = match sibling {
                Some((c2, f2)) => Link::Inner {
                    child: c2 as u8,
                    face: f2 as u8,
                },
                None => {
                    let pf = (0..4)
                        .find(|&pf| k.iter().all(|&n| node_on_parent_face(n, pf)))
                        .expect("a child face inside no sibling lies on a parent face");
                    let sub = k.iter().copied().find(|&n| n < 4).unwrap_or(4);
                    on_face[pf][sub as usize] = (c as u8, f as u8);
                    Link::Outer {
                        parent_face: pf as u8,
                        sub,
                    }
                }
            };
        }
    }
    Template {
        children,
        links,
        on_face,
    }
}

fn templates() -> &'static [Template; 3] {
    static T: OnceLock<[Template; 3]> = OnceLock::new();
    T.get_or_init(|| [build_template(0), build_template(1), build_template(2)])
}

/// Index into [`DIAGONALS`] of the shortest octahedron diagonal of a tet
/// (ties go to the lower index).
#[inline]
fn shortest_diagonal(p: &[DVec3; 4]) -> usize {
    // Diagonal between midpoints of (i, j) and (k, l): (pi + pj - pk - pl) / 2.
    let l = [
        (p[0] + p[1] - p[2] - p[3]).length_squared(),
        (p[0] + p[2] - p[1] - p[3]).length_squared(),
        (p[0] + p[3] - p[1] - p[2]).length_squared(),
    ];
    let mut best = 0;
    for d in 1..3 {
        if l[d] < l[best] {
            best = d;
        }
    }
    best
}

/// One uniform red refinement step: every tet into eight, every edge into two.
///
/// Old points keep their ids; the midpoint of every edge is appended, in the
/// order of the tets that own the edges (see the module docs), so the result is
/// the same for any number of threads. The child `c` of the `i`-th live tet is
/// tet `8 i + c`. A mesh with dead slots is compacted (on a copy) first.
pub fn bisect(mesh: &TetMesh) -> Result<TetMesh, BisectError> {
    if mesh.free.is_empty() {
        bisect_dense(mesh)
    } else {
        let mut dense = mesh.clone();
        dense.compact();
        bisect_dense(&dense)
    }
}

/// `steps` successive [`bisect`] steps (`steps == 0` returns a copy).
pub fn bisect_steps(mesh: &TetMesh, steps: usize) -> Result<TetMesh, BisectError> {
    let mut m = mesh.clone();
    for _ in 0..steps {
        m = bisect(&m)?;
    }
    Ok(m)
}

fn bisect_dense(m: &TetMesh) -> Result<TetMesh, BisectError> {
    let n = m.tets.len();
    let np = m.points.len();
    if n > MAX_INPUT_TETS {
        return Err(BisectError::TooLarge {
            tets: n,
            points: np,
            max_tets: MAX_INPUT_TETS,
        });
    }
    let tpl = templates();
    let tets = &m.tets;
    let points = &m.points;

    // 1. Edge owners (8 t' + e' of the smallest tet around each edge), owned
    //    edge mask (bits 0-5) and octahedron diagonal (bits 6-7).
    let (flags, owners): (Vec<u8>, Vec<[u32; 6]>) = (0..n)
        .into_par_iter()
        .map(|t| {
            let v = tets[t];
            let p = v.map(|x| points[x as usize]);
            let mut flags = (shortest_diagonal(&p) as u8) << 6;
            let mut owner = [0u32; 6];
            for (e, o) in owner.iter_mut().enumerate() {
                let mut min = t as u32;
                m.for_each_tet_around_edge(t as u32, e, |u| {
                    min = min.min(u);
                    true
                });
                if min == t as u32 {
                    flags |= 1 << e;
                    *o = 8 * t as u32 + e as u32;
                } else {
                    let w = tets[min as usize];
                    let [i, j] = TET_EDGES[e];
                    let owns = "the edge's owner tet is in its ring, so it holds both ends";
                    let li = w.iter().position(|&x| x == v[i]).expect(owns);
                    let lj = w.iter().position(|&x| x == v[j]).expect(owns);
                    *o = 8 * min + EDGE_INDEX[li][lj] as u32;
                }
            }
            (flags, owner)
        })
        .unzip();

    // 2. Number the owned edges in tet order.
    let mut base = Vec::with_capacity(n);
    let mut n_edges = 0u64;
    for &f in &flags {
        base.push(n_edges as u32);
        n_edges += (f & 63).count_ones() as u64;
    }
    let n_points_out = np as u64 + n_edges;
    if n_points_out >= DEAD as u64 {
        return Err(BisectError::TooLarge {
            tets: n,
            points: n_points_out as usize,
            max_tets: MAX_INPUT_TETS,
        });
    }
    let mid_of = |owner: u32| -> u32 {
        let (t, e) = ((owner >> 3) as usize, owner & 7);
        np as u32 + base[t] + (flags[t] as u32 & ((1 << e) - 1)).count_ones()
    };

    // 3. Midpoints and a tet of each new point, in edge-number order.
    let (new_points, new_v2t): (Vec<DVec3>, Vec<u32>) = (0..n)
        .into_par_iter()
        .flat_map_iter(|t| {
            let v = tets[t];
            let own = flags[t];
            (0..6).filter(move |e| own >> e & 1 == 1).map(move |e| {
                let [i, j] = TET_EDGES[e];
                (
                    (points[v[i] as usize] + points[v[j] as usize]) * 0.5,
                    8 * t as u32 + i as u32,
                )
            })
        })
        .unzip();
    debug_assert_eq!(new_points.len() as u64, n_edges);

    // 4. Children and their adjacency.
    let mut tets_out = vec![[0u32; 4]; 8 * n];
    let mut adj_out = vec![[0u32; 4]; 8 * n];
    let inverted = tets_out
        .par_chunks_mut(8)
        .zip(adj_out.par_chunks_mut(8))
        .enumerate()
        .filter_map(|(t, (tc, ac))| {
            let v = tets[t];
            let tp = &tpl[(flags[t] >> 6) as usize];
            let mut node = [0u32; 10];
            let mut pos = [DVec3::ZERO; 10];
            for k in 0..4 {
                node[k] = v[k];
                pos[k] = points[v[k] as usize];
            }
            for e in 0..6 {
                let [i, j] = TET_EDGES[e];
                node[4 + e] = mid_of(owners[t][e]);
                pos[4 + e] = (pos[i] + pos[j]) * 0.5;
            }
            let adj = m.adj[t];
            let mut bad = None;
            for c in 0..8 {
                let ch = tp.children[c];
                tc[c] = ch.map(|k| node[k as usize]);
                let s = ch.map(|k| pos[k as usize]);
                if bad.is_none() && orient3d_sign(s[0], s[1], s[2], s[3]) != Orientation::Positive {
                    bad = Some((t, c));
                }
                for (a, &link) in ac[c].iter_mut().zip(&tp.links[c]) {
                    *a = match link {
                        Link::Inner { child, face } => {
                            4 * (8 * t as u32 + child as u32) + face as u32
                        }
                        Link::Outer { parent_face, sub } => {
                            let h = adj[parent_face as usize];
                            if h == NO_ADJ {
                                NO_ADJ
                            } else {
                                let (u, g) = ((h >> 2) as usize, (h & 3) as usize);
                                let w = tets[u];
                                let s2 = if sub == 4 {
                                    4
                                } else {
                                    let x = v[sub as usize];
                                    w.iter()
                                        .position(|&y| y == x)
                                        .expect("the tet across a face holds the face's vertices")
                                };
                                let (c2, f2) = tpl[(flags[u] >> 6) as usize].on_face[g][s2];
                                4 * (8 * u as u32 + c2 as u32) + f2 as u32
                            }
                        }
                    };
                }
            }
            bad
        })
        .min();
    if let Some((t, c)) = inverted {
        return Err(BisectError::Inverted {
            tet: t + 1,
            child: c,
        });
    }

    // Per-tet fields.
    let region: Vec<i32> = (0..8 * n)
        .into_par_iter()
        .map(|k| m.region[k / 8])
        .collect();
    let level: Vec<u8> = (0..8 * n)
        .into_par_iter()
        .map(|k| m.level[k / 8].saturating_add(1))
        .collect();
    let parent: Vec<u32> = (0..8 * n)
        .into_par_iter()
        .map(|k| m.parent[k / 8])
        .collect();

    // A child holding each point: the corner child at an old vertex.
    let mut v2t: Vec<u32> = m
        .v2t
        .par_iter()
        .enumerate()
        .map(|(x, &t)| {
            if t == DEAD {
                DEAD
            } else {
                let local = tets[t as usize]
                    .iter()
                    .position(|&y| y == x as u32)
                    .expect("v2t names a tet that holds the vertex");
                8 * t + local as u32
            }
        })
        .collect();
    v2t.extend_from_slice(&new_v2t);
    let mut all_points = Vec::with_capacity(n_points_out as usize);
    all_points.extend_from_slice(points);
    all_points.extend_from_slice(&new_points);
    drop(new_points);

    // Tags: find a tet holding each tagged face or edge by a walk around one
    // of its vertices, and read the midpoints from that tet's edge owners.
    let mid_in = |t: u32, a: u32, b: u32| -> u32 {
        let w = tets[t as usize];
        let holds = "the tet found around a tagged edge or face holds its vertices";
        let la = w.iter().position(|&y| y == a).expect(holds);
        let lb = w.iter().position(|&y| y == b).expect(holds);
        mid_of(owners[t as usize][EDGE_INDEX[la][lb] as usize])
    };
    let find_tet = |buf: &mut Vec<u32>, a: u32, others: &[u32]| -> Option<u32> {
        if a as usize >= np {
            return None;
        }
        m.ball(a, buf);
        buf.iter()
            .copied()
            .find(|&t| others.iter().all(|o| tets[t as usize].contains(o)))
    };
    let one_based = |k: &[u32]| k.iter().map(|&x| x as u64 + 1).collect::<Vec<u64>>();

    let faces: Vec<(FaceKey, i32)> = m.face_markers.iter().map(|(k, &v)| (*k, v)).collect();
    let face_children: Result<Vec<[(FaceKey, i32); 4]>, BisectError> = faces
        .par_iter()
        .map_init(Vec::new, |buf, &([a, b, c], marker)| {
            let t = find_tet(buf, a, &[b, c]).ok_or_else(|| BisectError::DanglingTag {
                what: "face",
                vertices: one_based(&[a, b, c]),
            })?;
            let (ab, bc, ca) = (mid_in(t, a, b), mid_in(t, b, c), mid_in(t, c, a));
            Ok([
                (face_key([a, ab, ca]), marker),
                (face_key([b, bc, ab]), marker),
                (face_key([c, ca, bc]), marker),
                (face_key([ab, bc, ca]), marker),
            ])
        })
        .collect();
    let face_markers: crate::mesh::fasthash::FastHashMap<FaceKey, i32> =
        face_children?.into_iter().flatten().collect();

    let edges: Vec<(EdgeKey, i32)> = m.feature_edges.iter().map(|(k, &v)| (*k, v)).collect();
    let edge_children: Result<Vec<[(EdgeKey, i32); 2]>, BisectError> = edges
        .par_iter()
        .map_init(Vec::new, |buf, &([a, b], marker)| {
            let t = find_tet(buf, a, &[b]).ok_or_else(|| BisectError::DanglingTag {
                what: "edge",
                vertices: one_based(&[a, b]),
            })?;
            let mid = mid_in(t, a, b);
            Ok([(edge_key(a, mid), marker), (edge_key(mid, b), marker)])
        })
        .collect();
    let feature_edges: crate::mesh::fasthash::FastHashMap<EdgeKey, i32> =
        edge_children?.into_iter().flatten().collect();

    Ok(TetMesh {
        points: all_points,
        tets: tets_out,
        adj: adj_out,
        generation: vec![0; 8 * n],
        free: Vec::new(),
        region,
        level,
        parent,
        face_markers,
        feature_edges,
        corners: m.corners.clone(),
        required: m.required.clone(),
        v2t,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn templates_cover_each_parent_face_with_four_children() {
        for tp in templates() {
            for (f, subs) in tp.on_face.iter().enumerate() {
                for (s, &(c, cf)) in subs.iter().enumerate() {
                    if s == f {
                        continue;
                    }
                    assert!(c < 8 && cf < 4, "face {f} sub {s} uncovered");
                    assert_eq!(
                        tp.links[c as usize][cf as usize],
                        Link::Outer {
                            parent_face: f as u8,
                            sub: s as u8
                        }
                    );
                }
            }
            // 8 children × 4 faces = 16 on parent faces + 16 inner half-faces.
            let inner = tp
                .links
                .iter()
                .flatten()
                .filter(|l| matches!(l, Link::Inner { .. }))
                .count();
            assert_eq!(inner, 16);
        }
    }

    #[test]
    fn shortest_diagonal_of_a_stretched_tet() {
        // Stretched along x: m01-m23 is short only if 0,1 and 2,3 straddle x.
        let p = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(10.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(10.0, 1.0, 1.0),
        ];
        // (p0+p1-p2-p3) = (0,-2,-1); (p0+p2-p1-p3) = (-20,0,-1); (p0+p3-p1-p2) = (0,0,1).
        assert_eq!(shortest_diagonal(&p), 2);
    }
}
