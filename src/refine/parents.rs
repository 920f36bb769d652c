//! The `parent` of an output tet: the input tet that holds its centroid.

use crate::geom::orient3d;
use crate::mesh::fasthash::FastHashSet;
use crate::mesh::{TetMesh, NO_ADJ};
use crate::topo::TET_FACES;
use glam::DVec3;
use rayon::prelude::*;

/// For every live tet of `mesh`, finds the tet of `input` that contains its
/// centroid, walking from the current `parent` value (a nearby input tet kept
/// by the operations) across faces whose plane separates the point
/// (a visibility walk). A centroid outside the input domain (a boundary rule
/// that moves the surface) gets the input tet where the walk leaves the
/// domain. Overwrites `parent`.
///
/// The walks are independent: they run in parallel over runs of
/// `PARENT_BATCH` tet slots, each run's answers gathered before they are
/// written, so the extra memory stays at 4 bytes per slot of one run.
pub fn locate_parents(input: &TetMesh, mesh: &mut TetMesh) {
    let Some(first) = input.tet_ids().next() else {
        return;
    };
    let slots = mesh.n_tet_slots() as u32;
    let mut found = Vec::new();
    for lo in (0..slots).step_by(PARENT_BATCH) {
        let hi = lo.saturating_add(PARENT_BATCH as u32).min(slots);
        let m = &*mesh;
        (lo..hi)
            .into_par_iter()
            .with_min_len(1024)
            .map(|t| {
                if !m.is_alive(t) {
                    return NO_PARENT;
                }
                let p = m.tet_points(t);
                let c = (p[0] + p[1] + p[2] + p[3]) * 0.25;
                let hint = m.parent(t);
                let start = if (hint as usize) < input.n_tet_slots() && input.is_alive(hint) {
                    hint
                } else {
                    first
                };
                walk_to(input, start, c)
            })
            .collect_into_vec(&mut found);
        for (t, &p) in (lo..hi).zip(&found) {
            if p != NO_PARENT {
                mesh.set_parent(t, p);
            }
        }
    }
}

/// Tet slots whose parents [`locate_parents`] finds in one parallel run.
const PARENT_BATCH: usize = 1 << 20;

/// A dead slot's answer in [`locate_parents`] (never a tet id: ids stay
/// below `u32::MAX`).
const NO_PARENT: u32 = u32::MAX;

/// Tets [`walk_to`]'s breadth-first search visits at most. The search is for
/// a centroid the straight walk could not reach inside a non-convex domain,
/// which lies a few tets away; a centroid outside the domain (the common
/// case: the boundary rules move the surface) is found nowhere, and each
/// such search visits the whole limit. With the old limit of 100,000 a
/// two-step refinement of the tripod (167,657 tets) spent as long locating
/// parents as refining.
pub const WALK_SEARCH_LIMIT: usize = 2048;

/// Whether tet `t` contains `x` (boundary included), by exact predicates.
pub fn contains(mesh: &TetMesh, t: u32, x: DVec3) -> bool {
    let v = mesh.tet(t);
    TET_FACES.iter().all(|l| {
        orient3d(
            mesh.point(v[l[0]]),
            mesh.point(v[l[1]]),
            mesh.point(v[l[2]]),
            x,
        ) <= 0.0
    })
}

/// Visibility walk from `start` towards `x`; returns the tet containing `x`.
/// In a non-convex domain the straight walk can reach the boundary first;
/// then a breadth-first search over face neighbours from `start` (at most
/// `WALK_SEARCH_LIMIT` tets) looks for the containing tet. If none is found (the point
/// is outside the domain), the tet where the walk left the domain.
pub fn walk_to(mesh: &TetMesh, start: u32, x: DVec3) -> u32 {
    let end = straight_walk(mesh, start, x);
    if contains(mesh, end, x) {
        return end;
    }
    let mut seen = FastHashSet::default();
    let mut queue = std::collections::VecDeque::from([start]);
    seen.insert(start);
    while let Some(t) = queue.pop_front() {
        if contains(mesh, t, x) {
            return t;
        }
        if seen.len() > WALK_SEARCH_LIMIT {
            break;
        }
        for h in mesh.adj(t) {
            if h != NO_ADJ && seen.insert(h >> 2) {
                queue.push_back(h >> 2);
            }
        }
    }
    end
}

fn straight_walk(mesh: &TetMesh, start: u32, x: DVec3) -> u32 {
    let mut cur = start;
    let mut prev = u32::MAX;
    for _ in 0..mesh.n_tet_slots() + 1 {
        let v = mesh.tet(cur);
        let adj = mesh.adj(cur);
        let mut next = None;
        for (f, l) in TET_FACES.iter().enumerate() {
            let a = mesh.point(v[l[0]]);
            let b = mesh.point(v[l[1]]);
            let c = mesh.point(v[l[2]]);
            // Outward face: x strictly beyond it means leave through it.
            if orient3d(a, b, c, x) > 0.0 {
                let h = adj[f];
                if h != NO_ADJ && (h >> 2) != prev {
                    next = Some(h >> 2);
                    break;
                }
            }
        }
        match next {
            Some(n) => {
                prev = cur;
                cur = n;
            }
            None => return cur,
        }
    }
    cur
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::cube_grid;

    /// The unit cube grid without the slab `x > ⅓, ⅓ < y < ⅔`: a C-shaped
    /// prism whose slot blocks straight walks from one arm to the other.
    fn c_shape(n: usize) -> TetMesh {
        let mut data = cube_grid(n);
        let pts = data.points.clone();
        data.tets.retain(|t| {
            let c = t.iter().fold([0.0; 3], |c, &v| {
                let p = pts[v as usize];
                [c[0] + p[0] / 4.0, c[1] + p[1] / 4.0, c[2] + p[2] / 4.0]
            });
            !(c[0] > 1.0 / 3.0 && c[1] > 1.0 / 3.0 && c[1] < 2.0 / 3.0)
        });
        TetMesh::from_data(&data)
            .expect("an L-shaped grid builds")
            .0
    }

    fn tet_near(mesh: &TetMesh, x: DVec3) -> u32 {
        mesh.tet_ids()
            .min_by(|&a, &b| {
                let c = |t: u32| {
                    let p = mesh.tet_points(t);
                    ((p[0] + p[1] + p[2] + p[3]) * 0.25).distance_squared(x)
                };
                c(a).total_cmp(&c(b))
            })
            .expect("the mesh has tets")
    }

    #[test]
    fn the_search_finds_a_point_the_straight_walk_cannot_reach() {
        let mesh = c_shape(6);
        // From one arm's tip straight across the slot to the other's.
        let start = tet_near(&mesh, DVec3::new(0.9, 0.9, 0.5));
        let x = DVec3::new(0.9, 0.1, 0.5);
        assert!(
            !contains(&mesh, straight_walk(&mesh, start, x), x),
            "the fixture must block the straight walk"
        );
        let t = walk_to(&mesh, start, x);
        assert!(contains(&mesh, t, x), "tet {t} does not hold {x}");
    }

    #[test]
    fn a_point_outside_the_domain_gets_a_tet_after_a_bounded_search() {
        let mesh = c_shape(6);
        let start = tet_near(&mesh, DVec3::new(0.9, 0.9, 0.5));
        let x = DVec3::new(0.9, 0.5, 0.5); // in the slot
        let t = walk_to(&mesh, start, x);
        assert!(mesh.is_alive(t));
        assert!(mesh.tet_ids().all(|u| !contains(&mesh, u, x)));
    }

    #[test]
    fn parents_hold_the_centroids_and_do_not_depend_on_threads() {
        let input = c_shape(5);
        let mut fine = input.clone();
        crate::refine::refine_step(&mut fine, 1, &crate::refine::RefineOptions::default());
        let run = |threads: usize| {
            let mut m = fine.clone();
            // Hints from nowhere: every walk starts far away.
            for t in m.tet_ids().collect::<Vec<_>>() {
                m.set_parent(t, 0);
            }
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a thread pool")
                .install(|| locate_parents(&input, &mut m));
            m.tet_ids().map(|t| m.parent(t)).collect::<Vec<_>>()
        };
        let one = run(1);
        assert_eq!(one, run(3));
        for (t, &p) in fine.tet_ids().zip(&one) {
            let q = fine.tet_points(t);
            let c = (q[0] + q[1] + q[2] + q[3]) * 0.25;
            if input.tet_ids().any(|u| contains(&input, u, c)) {
                assert!(contains(&input, p, c), "tet {t}: parent {p}");
            }
        }
    }
}
