//! Bulk 1-4 split: every selected tet split at its barycentre at once, in
//! parallel — the first phase of a √3 step.
//!
//! ```text
//!            3              split tet number i (ascending ids) gets the point
//!           /|\             c = n_points + i and the child slots
//!          / | \              child 0 = (c,1,2,3)  in the tet's own slot t
//!         /  c  \             child 1 = (0,c,2,3)  in claimed slot 3i
//!        0---|---2            child 2 = (0,1,c,3)  in claimed slot 3i+1
//!         \  |  /             child 3 = (0,1,2,c)  in claimed slot 3i+2
//!          \ | /            child j keeps face j of the parent and meets child
//!            1              k across its face k (which is child k's face j)
//! ```
//!
//! Face `j` of a split tet `t` faces a neighbour `w` across its face `m`: when
//! `w` is split too the new neighbour is `w`'s child `m` (its face `m`),
//! computed from `w`'s number alone; otherwise the task of `t` rewrites the
//! one entry `adj[w][m]` — the only writer of that entry.
//!
//! Slots and point ids come from a prefix sum over the selected tets; the
//! claimed slots are the free list first (from its end, as
//! [`TetMesh::alloc_tet`] pops it) then new slots reserved exactly at the end.
//! The result equals calling [`super::split14`](fn@super::split14) on the selected tets in
//! ascending order (same slots, points, generations, vertex → tet entries).
//!
//! Seed paper (Burkhart, Hamann, Umlauf 2010) §3.1; the parallel scheme
//! (allocate by prefix sum, fill in parallel) is the usual one of bulk mesh
//! refinement.

use crate::geom::all_positive;
use crate::mesh::{SharedSlots, TetMesh, DEAD, NO_ADJ};
use crate::topo::scatter::LastTouch;
use glam::DVec3;
use rayon::prelude::*;

const NONE: u32 = u32::MAX;

/// The barycentre of the tet with vertices `v`.
#[inline]
fn barycentre(points: &[DVec3], v: [u32; 4]) -> DVec3 {
    let p = v.map(|x| points[x as usize]);
    (p[0] + p[1] + p[2] + p[3]) * 0.25
}

/// Whether all four children of the split of `v` at `c` are positive (exact
/// predicate; the barycentre of a positive tet is inside it, so this fails
/// only should rounding put `c` on a face).
#[inline]
fn children_positive(points: &[DVec3], v: [u32; 4], c: DVec3) -> bool {
    let p = v.map(|x| points[x as usize]);
    all_positive((0..4).map(|j| {
        let mut q = p;
        q[j] = c;
        q
    }))
}

/// Whether a selection (per tet slot; `None`: every slot) selects slot `t`;
/// a slot past the selection's end is not selected. The one reading of
/// a refinement step's selection, for the split and the step's counts.
pub(crate) fn is_selected(selection: Option<&[bool]>, t: usize) -> bool {
    selection.is_none_or(|s| s.get(t).copied().unwrap_or(false))
}

/// 1-4 splits every live tet whose slot is selected (`None`: every tet) at
/// its barycentre, raising the children's `level` by one (saturating) and
/// keeping region and parent. A split that would create a non-positive child
/// is refused and the tet stays. Returns the number of tets split.
///
/// The tet arrays are reserved exactly for the children plus one tet per face
/// between two split tets, the 2-3 flips that follow in a √3 step, so that
/// neither phase reallocates them again.
pub fn split14_bulk(mesh: &mut TetMesh, selection: Option<&[bool]>) -> usize {
    let n = mesh.tets.len();
    let np0 = mesh.points.len();
    // Which tets split, and their numbers (prefix sum).
    let ok: Vec<bool> = {
        let (tets, points) = (&mesh.tets, &mesh.points);
        (0..n)
            .into_par_iter()
            .map(|t| {
                let v = tets[t];
                v[0] != DEAD
                    && is_selected(selection, t)
                    && children_positive(points, v, barycentre(points, v))
            })
            .collect()
    };
    let mut number = vec![NONE; n];
    let mut ids = Vec::with_capacity(ok.iter().filter(|&&b| b).count());
    for (t, &b) in ok.iter().enumerate() {
        if b {
            number[t] = ids.len() as u32;
            ids.push(t as u32);
        }
    }
    drop(ok);
    let k = ids.len();
    if k == 0 {
        return 0;
    }

    // Barycentres, appended in the order of the split tets.
    {
        let (tets, points) = (&mesh.tets, &mut mesh.points);
        points.reserve_exact(k);
        let new: Vec<DVec3> = ids
            .par_iter()
            .map(|&t| barycentre(points, tets[t as usize]))
            .collect();
        points.extend_from_slice(&new);
    }
    // Room for the children and for one tet per face between two split tets:
    // the 2-3 flips that follow in a √3 step then need no reallocation.
    let shared_faces: usize = {
        let (adj, number) = (&mesh.adj, &number);
        ids.par_iter()
            .map(|&t| {
                adj[t as usize]
                    .iter()
                    .filter(|&&h| h != NO_ADJ && (h >> 2) > t && number[(h >> 2) as usize] != NONE)
                    .count()
            })
            .sum()
    };
    let free = mesh.free.len();
    mesh.reserve_tets_exact((3 * k + shared_faces).saturating_sub(free));
    let slots = mesh.claim_slots(3 * k);
    let child_slot = |t: u32, i: usize, j: usize| {
        if j == 0 {
            t
        } else {
            slots.get(3 * i + j - 1)
        }
    };

    // Children and adjacency, one task per split tet.
    {
        let SharedSlots {
            tets,
            adj,
            generation,
            region,
            level,
            parent,
        } = mesh.shared_slots();
        let number = &number;
        ids.par_iter().enumerate().for_each(|(i, &t)| {
            let ti = t as usize;
            // This task alone reads and writes slot t and the claimed slots
            // 3i..3i+3; the one lane it writes in an unsplit neighbour faces
            // slot t, so no other task writes it, and no task reads unsplit
            // neighbours: one writer per element, a deterministic result.
            let v = tets.get(ti);
            let a = adj.get(ti);
            let (r, l, p) = (region.get(ti), level.get(ti), parent.get(ti));
            let c = (np0 + i) as u32;
            let cs = [0, 1, 2, 3].map(|j| child_slot(t, i, j));
            for j in 0..4 {
                let mut cv = v;
                cv[j] = c;
                let mut ca = [0; 4];
                for (m, x) in ca.iter_mut().enumerate() {
                    *x = 4 * cs[m] + j as u32;
                }
                ca[j] = match a[j] {
                    NO_ADJ => NO_ADJ,
                    h => {
                        let (w, m) = TetMesh::half_face(h);
                        match number[w as usize] {
                            NONE => {
                                adj.set_lane(w as usize, m, 4 * cs[j] + j as u32);
                                h
                            }
                            iw => 4 * child_slot(w, iw as usize, m) + m as u32,
                        }
                    }
                };
                let s = cs[j] as usize;
                tets.set(s, cv);
                adj.set(s, ca);
                region.set(s, r);
                level.set(s, l.saturating_add(1));
                parent.set(s, p);
            }
            // Slot t was freed and taken again.
            generation.set(ti, generation.get(ti).wrapping_add(2));
        });
    }

    // Vertex → tet: the last split over a vertex allocated child 3 last,
    // which holds every vertex of the parent but vertex 3.
    let last = LastTouch::new(np0);
    ids.par_iter().enumerate().for_each(|(i, &t)| {
        // Slot t now holds child 0, (c, v1, v2, v3); child 1 holds v0.
        let c0 = mesh.tets[t as usize];
        let v0 = mesh.tets[child_slot(t, i, 1) as usize][0];
        for x in [v0, c0[1], c0[2], c0[3]] {
            last.touch(x, i);
        }
    });
    let tets = &mesh.tets;
    mesh.v2t.par_iter_mut().enumerate().for_each(|(x, e)| {
        if let Some(i) = last.get(x) {
            let c3 = child_slot(ids[i], i, 3);
            *e = if tets[c3 as usize][..3].contains(&(x as u32)) {
                c3
            } else {
                child_slot(ids[i], i, 2)
            };
        }
    });
    mesh.v2t.reserve_exact(k);
    mesh.v2t
        .par_extend((0..k).into_par_iter().map(|i| child_slot(ids[i], i, 3)));
    k
}
