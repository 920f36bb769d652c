//! Repair of the invalid 2-3 flips of a √3 step by moving barycentres, in
//! parallel rounds that give the result of the one-by-one repair.
//!
//! Where the segment between the two barycentres `p`, `q` of a flip misses
//! their shared face (the input violates the precondition the seed paper
//! borrows from Lehner), both are pulled towards the face's centroid by a
//! factor 0.7, 0.5, 0.3, 0.15 or 0.05 — the first that keeps every child of
//! `p` and `q` positive, makes the flip valid and leaves every other flip of
//! `p` and `q` that was valid valid. The faces are taken in batch order, each
//! seeing the moves of the ones before it.
//!
//! The repair of one face reads the points `p`, `q` and the other apexes `r`
//! of the flips around `p` and `q` (its *reach*; the old points never move
//! here), the validity of those flips, and writes `p`, `q` and the validity of
//! those flips. Two repairs with disjoint reaches therefore commute. Each
//! round, every pending repair marks its reach with its number (atomic
//! minimum); the repairs that hold all their marks have no earlier pending
//! repair reaching the same points, so they are decided at once in parallel
//! on the points as they are and then applied — a deterministic-reservations
//! scheme (Blelloch, Fineman, Gibbons, Shun, "Internally deterministic
//! parallel algorithms can be fast", PPoPP 2012). The result equals the
//! one-by-one repair for any number of threads.

use super::FlipBatch;
use crate::mesh::ball_stays_positive;
use crate::mesh::{TetMesh, NO_ADJ};
use glam::DVec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering};

/// The factors tried, in order, for pulling both barycentres towards the
/// face's centroid.
const PULL: [f64; 5] = [0.7, 0.5, 0.3, 0.15, 0.05];

/// The repair of one invalid flip.
struct Repair {
    /// Batch index of the flip.
    k: u32,
    /// Its apexes (barycentres).
    p: u32,
    q: u32,
    /// Centroid of its face (old points: fixed during the phase).
    centroid: DVec3,
    /// Batch indices of the other flips around `p` and `q`.
    around: Vec<u32>,
    /// `p`, `q` and the other apexes of `around`, as indices into the sorted
    /// list of all reached points.
    reach: Vec<u32>,
}

/// Batch indices of the flips that have `p` as an apex: across the face
/// opposite `p` of each tet of its ball (`ball` holds that ball).
fn flips_around(mesh: &TetMesh, batch: &FlipBatch, p: u32, ball: &[u32], out: &mut Vec<u32>) {
    for &c in ball {
        let Some(i) = mesh.local_index(c, p) else {
            continue;
        };
        let h = mesh.adj(c)[i];
        if h == NO_ADJ {
            continue;
        }
        let u = h >> 2;
        let (lo, hi) = (c.min(u), c.max(u));
        if let Some(j) = batch.index_of_slot(lo) {
            if batch.slots(j) == (lo, hi) {
                out.push(j as u32);
            }
        }
    }
}

/// The moves of `p` and `q` that repair `r`, judged on the current points,
/// or `None` when no factor works.
fn decide(
    mesh: &TetMesh,
    batch: &FlipBatch,
    r: &Repair,
    balls: &mut (Vec<u32>, Vec<u32>),
) -> Option<(DVec3, DVec3)> {
    let (p, q, c) = (r.p, r.q, r.centroid);
    let (p0, q0) = (mesh.point(p), mesh.point(q));
    mesh.ball(p, &mut balls.0);
    mesh.ball(q, &mut balls.1);
    let (tets, points) = (&mesh.tets[..], &mesh.points[..]);
    PULL.iter().find_map(|&s| {
        let (p1, q1) = (c + (p0 - c) * s, c + (q0 - c) * s);
        if !(ball_stays_positive(mesh, p, &balls.0, p1)
            && ball_stays_positive(mesh, q, &balls.1, q1))
        {
            return None;
        }
        let moved = [(p, p1), (q, q1)];
        let ok = batch.positive_with(tets, points, r.k as usize, &moved)
            && r.around.iter().all(|&j| {
                !batch.is_valid(j as usize) || batch.positive_with(tets, points, j as usize, &moved)
            });
        ok.then_some((p1, q1))
    })
}

/// Moves barycentres so that invalid flips of `batch` (as judged by
/// [`FlipBatch::barycentre_faces`] on this mesh, points unchanged since)
/// become valid, without making a valid flip invalid or a child of a split
/// non-positive (exact predicate), and re-judges the flips whose apexes moved.
/// Returns the number of points moved (two per repaired flip). See the module
/// docs for the rule and the parallel scheme.
pub fn make_flips_valid(mesh: &mut TetMesh, batch: &mut FlipBatch) -> usize {
    let invalid: Vec<u32> = (0..batch.len() as u32)
        .into_par_iter()
        .filter(|&i| !batch.is_valid(i as usize))
        .collect();
    if invalid.is_empty() {
        return 0;
    }
    let mut repairs: Vec<Repair> = {
        let (m, b) = (&*mesh, &*batch);
        invalid
            .par_iter()
            .map_init(Vec::new, |ball, &k| {
                let (f, p, q) = b.face_and_apexes(&m.tets, k as usize);
                let centroid = (m.point(f[0]) + m.point(f[1]) + m.point(f[2])) / 3.0;
                let mut around = Vec::new();
                for x in [p, q] {
                    m.ball(x, ball);
                    flips_around(m, b, x, ball, &mut around);
                }
                around.retain(|&j| j != k);
                let mut reach = vec![p, q];
                for &j in &around {
                    let (_, a, c) = b.face_and_apexes(&m.tets, j as usize);
                    reach.extend([a, c].into_iter().filter(|&x| x != p && x != q));
                }
                Repair {
                    k,
                    p,
                    q,
                    centroid,
                    around,
                    reach,
                }
            })
            .collect()
    };
    drop(invalid);
    // Reached points renumbered densely.
    let mut keys: Vec<u32> = repairs
        .iter()
        .flat_map(|r| r.reach.iter().copied())
        .collect();
    keys.par_sort_unstable();
    keys.dedup();
    repairs.par_iter_mut().for_each(|r| {
        for x in r.reach.iter_mut() {
            *x = keys.binary_search(x).unwrap_or(0) as u32;
        }
    });
    let owner: Vec<AtomicU32> = (0..keys.len()).map(|_| AtomicU32::new(u32::MAX)).collect();
    drop(keys);

    let mut moved = 0;
    let mut pending: Vec<u32> = (0..repairs.len() as u32).collect();
    while !pending.is_empty() {
        let (reps, own) = (&repairs, &owner);
        pending.par_iter().for_each(|&i| {
            for &x in &reps[i as usize].reach {
                own[x as usize].fetch_min(i, Ordering::Relaxed);
            }
        });
        let holds = |i: u32| {
            reps[i as usize]
                .reach
                .iter()
                .all(|&x| own[x as usize].load(Ordering::Relaxed) == i)
        };
        let ready: Vec<u32> = pending.par_iter().copied().filter(|&i| holds(i)).collect();
        let decisions: Vec<Option<(DVec3, DVec3)>> = {
            let (m, b) = (&*mesh, &*batch);
            ready
                .par_iter()
                .map_init(
                    || (Vec::new(), Vec::new()),
                    |balls, &i| decide(m, b, &reps[i as usize], balls),
                )
                .collect()
        };
        pending.par_iter().for_each(|&i| {
            for &x in &reps[i as usize].reach {
                own[x as usize].store(u32::MAX, Ordering::Relaxed);
            }
        });
        // The ready repairs reach disjoint points: apply them in any order.
        for (&i, d) in ready.iter().zip(decisions) {
            let Some((p1, q1)) = d else { continue };
            let r = &repairs[i as usize];
            mesh.set_point(r.p, p1);
            mesh.set_point(r.q, q1);
            moved += 2;
            batch.rejudge(mesh, r.k as usize);
            for &j in &r.around {
                batch.rejudge(mesh, j as usize);
            }
        }
        // `ready` is a subsequence of `pending`.
        let mut next = ready.iter().peekable();
        pending.retain(|i| {
            if next.peek() == Some(&i) {
                next.next();
                false
            } else {
                true
            }
        });
    }
    moved
}
