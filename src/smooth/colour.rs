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

use crate::mesh::{TetMesh, DEAD};

/// The balls (incident tets) of a list of vertices, in one flat array.
#[derive(Clone, Debug, Default)]
pub struct Balls {
    /// Ball `i` is `tets[offsets[i]..offsets[i + 1]]`.
    offsets: Vec<usize>,
    tets: Vec<u32>,
}

impl Balls {
    /// The balls of `verts` (distinct vertices), in that order, each ball's
    /// tets ascending: one counting sort over the tets, instead of a walk
    /// per vertex.
    pub fn gather(mesh: &TetMesh, verts: &[u32]) -> Balls {
        const NONE: u32 = u32::MAX;
        let mut index = vec![NONE; mesh.n_points()];
        for (i, &v) in verts.iter().enumerate() {
            index[v as usize] = i as u32;
        }
        let mut offsets = vec![0usize; verts.len() + 1];
        for tv in mesh.tet_slots() {
            if tv[0] != DEAD {
                for &x in tv {
                    let i = index[x as usize];
                    if i != NONE {
                        offsets[i as usize + 1] += 1;
                    }
                }
            }
        }
        for i in 0..verts.len() {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets[..verts.len()].to_vec();
        let mut tets = vec![0u32; offsets[verts.len()]];
        for (t, tv) in mesh.tet_slots().iter().enumerate() {
            if tv[0] != DEAD {
                for &x in tv {
                    let i = index[x as usize];
                    if i != NONE {
                        tets[fill[i as usize]] = t as u32;
                        fill[i as usize] += 1;
                    }
                }
            }
        }
        Balls { offsets, tets }
    }

    /// Number of balls.
    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// Whether there are no balls.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Ball `i`.
    pub fn ball(&self, i: usize) -> &[u32] {
        &self.tets[self.offsets[i]..self.offsets[i + 1]]
    }
}

/// Greedy colouring of the balls' vertices, visited in order: each takes the
/// smallest colour no earlier vertex sharing a tet with it has. Returns the
/// colour classes as lists of ball indices (ascending), smallest colour
/// first. `masks` is per-tet-slot scratch (all zero on entry and on return;
/// grown as needed). A vertex that finds all 64 colours taken around it gets a
/// class of its own, after the others.
pub fn colour_balls(balls: &Balls, masks: &mut Vec<u64>) -> Vec<Vec<u32>> {
    colour_balls_except(balls, masks, |_| false)
}

/// [`colour_balls`], except that each ball for which `alone_if` holds gets a
/// class of its own, both before and after the coloured classes (in ball
/// order each time): those vertices are smoothed one at a time, twice.
pub fn colour_balls_except(
    balls: &Balls,
    masks: &mut Vec<u64>,
    alone_if: impl Fn(usize) -> bool,
) -> Vec<Vec<u32>> {
    let mut classes: Vec<Vec<u32>> = Vec::new();
    let mut alone = Vec::new();
    let mut crowded = Vec::new();
    let slots = balls.tets.iter().max().map_or(0, |&t| t as usize + 1);
    if masks.len() < slots {
        masks.resize(slots, 0);
    }
    for i in 0..balls.len() {
        if alone_if(i) {
            alone.push(i as u32);
            continue;
        }
        let ball = balls.ball(i);
        let mut used = 0u64;
        for &t in ball {
            used |= masks[t as usize];
        }
        let c = (!used).trailing_zeros() as usize;
        if c == 64 {
            crowded.push(i as u32);
            continue;
        }
        for &t in ball {
            masks[t as usize] |= 1 << c;
        }
        if classes.len() <= c {
            classes.resize_with(c + 1, Vec::new);
        }
        classes[c].push(i as u32);
    }
    for &t in &balls.tets {
        masks[t as usize] = 0;
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
    let mut masks = Vec::new();
    colour_balls(&balls, &mut masks)
        .into_iter()
        .map(|c| c.into_iter().map(|i| verts[i as usize]).collect())
        .collect()
}
