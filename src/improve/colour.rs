//! Independent sets of vertices for parallel smoothing: a greedy colouring in
//! which no two vertices of one colour share a tet.
//!
//! Moving a vertex reads the points of its ball and writes only its own
//! point and its ball's qualities, so the vertices of one colour can be
//! smoothed at the same time without touching each other's data, and
//! smoothing colour after colour is the vertex-by-vertex (Gauss–Seidel)
//! smoothing of a reordered vertex list. This is the independent-set scheme of
//! Freitag, Jones and Plassmann ("A parallel algorithm for mesh smoothing",
//! SIAM J. Sci. Comput. 20(6), 1999); the colouring here is greedy in vertex
//! order rather than their random one, so that it is the same whatever the
//! number of threads.
//!
//! Two vertices share a tet exactly when they are joined by an edge (every
//! pair of a tet's corners is one of its edges), so the colouring keeps one
//! colour byte per point rather than a colour mask per tet.

use crate::mesh::{TetMesh, DEAD};
use crate::topo::scatter::CountingSort;
use rayon::prelude::*;

/// The balls (incident tets) of a list of vertices, in one flat array.
#[derive(Clone, Debug, Default)]
pub struct Balls {
    /// Ball `i` is `tets[offsets[i]..offsets[i + 1]]`.
    offsets: Vec<usize>,
    tets: Vec<u32>,
}

impl Balls {
    /// The balls of `verts` (distinct vertices), in that order, each ball's
    /// tets ascending: a counting sort over the tet slots instead of a walk
    /// per vertex (a walk is a chain of cache misses; the sort streams the
    /// slots). The slots are cut into contiguous parts counted and filled in
    /// parallel, each part filling its own stretch of every ball, so the
    /// result does not depend on the number of parts.
    pub fn gather(mesh: &TetMesh, verts: &[u32]) -> Balls {
        const NONE: u32 = u32::MAX;
        let (Some(&lo), Some(&hi)) = (verts.iter().min(), verts.iter().max()) else {
            return Balls {
                offsets: vec![0],
                tets: Vec::new(),
            };
        };
        // Ids outside lo..=hi are rejected by one comparison: a block of a
        // spatially ordered vertex list skips most of the slots that way.
        let mut index = vec![NONE; (hi - lo) as usize + 1];
        for (i, &v) in verts.iter().enumerate() {
            index[(v - lo) as usize] = i as u32;
        }
        let position = |x: u32| -> Option<usize> {
            let k = x.wrapping_sub(lo);
            if k > hi - lo {
                return None;
            }
            let i = index[k as usize];
            (i != NONE).then_some(i as usize)
        };
        let slots = mesh.tet_slots();
        let parts = rayon::current_num_threads().max(1) * 2;
        let per = slots.len().div_ceil(parts).max(1);
        let counts: Vec<Vec<u32>> = slots
            .par_chunks(per)
            .map(|part| {
                let mut c = vec![0u32; verts.len()];
                for tv in part {
                    if tv[0] != DEAD {
                        for &x in tv {
                            if let Some(i) = position(x) {
                                c[i] += 1;
                            }
                        }
                    }
                }
                c
            })
            .collect();
        // Each part writes only the positions its counts reserved, ball by
        // ball: the order of one sequential pass.
        let sort = CountingSort::new(counts, verts.len());
        let offsets: Vec<usize> = (0..=verts.len()).map(|i| sort.key_start(i)).collect();
        let tets = sort.fill(
            0u32,
            slots.par_chunks(per).enumerate(),
            |(p, part), fill| {
                let base = (p * per) as u32;
                for (k, tv) in part.iter().enumerate() {
                    if tv[0] != DEAD {
                        for &x in tv {
                            if let Some(i) = position(x) {
                                fill.put(i, base + k as u32);
                            }
                        }
                    }
                }
            },
        );
        Balls { offsets, tets }
    }

    /// Number of balls.
    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// Ball `i`.
    pub fn ball(&self, i: usize) -> &[u32] {
        &self.tets[self.offsets[i]..self.offsets[i + 1]]
    }
}

/// Greedy colouring of the balls' vertices `verts` (ball `i` is the ball of
/// `verts[i]`), visited in order: each takes the smallest colour no earlier
/// vertex sharing a tet with it has. Returns the colour classes as lists of
/// ball indices (ascending), smallest colour first. A vertex that finds all
/// 64 colours taken around it gets a class of its own, after the others.
pub fn colour_balls(mesh: &TetMesh, balls: &Balls, verts: &[u32]) -> Vec<Vec<u32>> {
    colour_balls_except(mesh, balls, verts, |_| false)
}

/// [`colour_balls`], except that each ball for which `alone_if` holds gets a
/// class of its own, both before and after the coloured classes (in ball
/// order each time): those vertices are smoothed one at a time, twice. They
/// take no colour, so they constrain no other vertex.
pub fn colour_balls_except(
    mesh: &TetMesh,
    balls: &Balls,
    verts: &[u32],
    alone_if: impl Fn(usize) -> bool,
) -> Vec<Vec<u32>> {
    const NONE: u8 = u8::MAX;
    let mut colour = vec![NONE; mesh.n_points()];
    let mut classes: Vec<Vec<u32>> = Vec::new();
    let mut alone = Vec::new();
    let mut crowded = Vec::new();
    for (i, &v) in verts.iter().enumerate().take(balls.len()) {
        if alone_if(i) {
            alone.push(i as u32);
            continue;
        }
        let mut used = 0u64;
        for &t in balls.ball(i) {
            for u in mesh.tet(t) {
                let c = colour[u as usize];
                if c < 64 {
                    used |= 1 << c;
                }
            }
        }
        let c = (!used).trailing_zeros() as usize;
        if c == 64 {
            crowded.push(i as u32);
            continue;
        }
        colour[v as usize] = c as u8;
        if classes.len() <= c {
            classes.resize_with(c + 1, Vec::new);
        }
        classes[c].push(i as u32);
    }
    let mut all: Vec<Vec<u32>> = alone.iter().map(|&i| vec![i]).collect();
    all.extend(classes);
    all.extend(crowded.into_iter().map(|i| vec![i]));
    all.extend(alone.iter().map(|&i| vec![i]));
    all
}

/// Colour classes of `verts` (see [`colour_balls`]) as lists of vertex ids:
/// within a class no two vertices share a tet.
pub fn colour_classes(mesh: &TetMesh, verts: &[u32]) -> Vec<Vec<u32>> {
    let balls = Balls::gather(mesh, verts);
    colour_balls(mesh, &balls, verts)
        .into_iter()
        .map(|c| c.into_iter().map(|i| verts[i as usize]).collect())
        .collect()
}

/// The balls `seq` (indices into `balls`, possibly repeated; ball `i` is
/// the ball of `verts[i]`) grouped so that smoothing the groups one after
/// the other, each group's vertices in any order or at once, is exactly
/// smoothing `seq` one by one in order: an entry's group comes after the
/// groups of all earlier entries that are the same vertex or share a tet with
/// it (its level in the dependency order), so the balls of one group share
/// no tet. `level` is per-point scratch, all zero on entry and on return.
pub fn sequential_levels(
    mesh: &TetMesh,
    balls: &Balls,
    verts: &[u32],
    seq: &[u32],
    level: &mut Vec<u32>,
) -> Vec<Vec<u32>> {
    if level.len() < mesh.n_points() {
        level.resize(mesh.n_points(), 0);
    }
    let mut groups: Vec<Vec<u32>> = Vec::new();
    for &i in seq {
        // The ball's corners are the vertex and its neighbours.
        let v = verts[i as usize];
        let l = balls
            .ball(i as usize)
            .iter()
            .flat_map(|&t| mesh.tet(t))
            .map(|u| level[u as usize])
            .fold(level[v as usize], u32::max)
            + 1;
        level[v as usize] = l;
        if groups.len() < l as usize {
            groups.resize_with(l as usize, Vec::new);
        }
        groups[l as usize - 1].push(i);
    }
    for &i in seq {
        level[verts[i as usize] as usize] = 0;
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

    /// The shipped tripod: a real mesh with irregular balls.
    fn tripod() -> TetMesh {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("meshes/tripod.mesh");
        crate::io::load_mesh(&path).unwrap().0
    }

    fn in_pool<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(f)
    }

    #[test]
    fn colour_classes_of_the_tripod_are_independent_sets() {
        let mesh = tripod();
        let fixed = mesh.fixed_vertices();
        let verts: Vec<u32> = (0..mesh.n_points() as u32)
            .filter(|&v| !fixed[v as usize] && mesh.tet_of_vertex(v).is_some())
            .collect();
        assert!(verts.len() > 100, "the tripod has interior vertices");
        let classes = colour_classes(&mesh, &verts);
        assert!(classes.len() > 1);
        // Every vertex is in exactly one class.
        let mut seen = HashSet::new();
        for c in &classes {
            for &v in c {
                assert!(seen.insert(v), "vertex {v} in two classes");
            }
        }
        assert_eq!(seen.len(), verts.len());
        // No tet holds two vertices of one class.
        for c in &classes {
            let class: HashSet<u32> = c.iter().copied().collect();
            for t in mesh.tet_ids() {
                let k = mesh.tet(t).iter().filter(|v| class.contains(v)).count();
                assert!(k <= 1, "tet {t} holds {k} vertices of one class");
            }
        }
    }

    #[test]
    fn vertices_set_apart_get_classes_of_their_own_before_and_after() {
        let mesh = tripod();
        let fixed = mesh.fixed_vertices();
        let verts: Vec<u32> = (0..mesh.n_points() as u32)
            .filter(|&v| !fixed[v as usize] && mesh.tet_of_vertex(v).is_some())
            .collect();
        let balls = Balls::gather(&mesh, &verts);
        let apart: Vec<u32> = (0..verts.len() as u32).filter(|i| i % 7 == 0).collect();
        let classes = colour_balls_except(&mesh, &balls, &verts, |i| i % 7 == 0);
        let k = apart.len();
        let expected: Vec<Vec<u32>> = apart.iter().map(|&i| vec![i]).collect();
        assert_eq!(&classes[..k], &expected[..]);
        assert_eq!(&classes[classes.len() - k..], &expected[..]);
        // The classes in between hold every other vertex once, independently.
        let mut seen = HashSet::new();
        for c in &classes[k..classes.len() - k] {
            let mut tets = HashSet::new();
            for &i in c {
                assert!(i % 7 != 0 && seen.insert(i));
                for &t in balls.ball(i as usize) {
                    assert!(tets.insert(t), "tet {t} shared within a class");
                }
            }
        }
        assert_eq!(seen.len() + k, verts.len());
    }

    #[test]
    fn gathered_balls_are_the_walked_balls_in_ascending_order() {
        let mesh = tripod();
        // Every other vertex, so that the index has holes.
        let verts: Vec<u32> = (0..mesh.n_points() as u32).step_by(2).collect();
        let mut walked = Vec::new();
        for threads in [1, 3] {
            let balls = in_pool(threads, || Balls::gather(&mesh, &verts));
            assert_eq!(balls.len(), verts.len());
            for (i, &v) in verts.iter().enumerate() {
                mesh.ball(v, &mut walked);
                walked.sort_unstable();
                assert_eq!(balls.ball(i), &walked[..], "ball of {v}, {threads} threads");
            }
        }
        assert_eq!(Balls::gather(&mesh, &[]).len(), 0);
    }

    #[test]
    fn dependency_levels_keep_every_earlier_conflict_earlier() {
        let mesh = tripod();
        let verts: Vec<u32> = (0..mesh.n_points() as u32)
            .filter(|&v| mesh.tet_of_vertex(v).is_some())
            .collect();
        let balls = Balls::gather(&mesh, &verts);
        // A stretch of neighbours in memory, each visited twice, as the vertices
        // set apart are (before and after the colour classes).
        let mut seq: Vec<u32> = (0..200).collect();
        seq.extend(0..200u32);
        let mut level = Vec::new();
        let groups = sequential_levels(&mesh, &balls, &verts, &seq, &mut level);
        assert!(level.iter().all(|&l| l == 0), "scratch left clean");
        // Entry k of seq is the k-th occurrence, in group order, of its index.
        let mut group_of = vec![Vec::new(); seq.len()];
        for (g, group) in groups.iter().enumerate() {
            for &i in group {
                group_of[i as usize].push(g);
            }
        }
        let mut seen = vec![0usize; seq.len()];
        let entry_group: Vec<usize> = seq
            .iter()
            .map(|&i| {
                let g = group_of[i as usize][seen[i as usize]];
                seen[i as usize] += 1;
                g
            })
            .collect();
        let shares = |a: u32, b: u32| {
            let (ba, bb) = (balls.ball(a as usize), balls.ball(b as usize));
            a == b || ba.iter().any(|t| bb.contains(t))
        };
        let mut conflicts = 0;
        for k in 0..seq.len() {
            for j in 0..k {
                if shares(seq[j], seq[k]) {
                    conflicts += 1;
                    assert!(entry_group[j] < entry_group[k], "entries {j} and {k}");
                }
            }
        }
        assert!(
            conflicts > seq.len(),
            "the stretch is connected: {conflicts}"
        );
        for group in &groups {
            for (a, &x) in group.iter().enumerate() {
                for &y in &group[..a] {
                    assert!(!shares(x, y), "{x} and {y} share a tet in one group");
                }
            }
        }
    }
}
