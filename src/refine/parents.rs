//! The `parent` of an output tet: the input tet that holds its centroid.

use crate::geom::{orient3d, TET_FACES};
use crate::mesh::{TetMesh, NO_ADJ};
use glam::DVec3;

/// For every live tet of `mesh`, finds the tet of `input` that contains its
/// centroid, walking from the current `parent` value (a nearby input tet kept
/// by the operations) across faces whose plane separates the point
/// (a visibility walk). A centroid outside the input domain (a boundary rule
/// that moves the surface) gets the input tet where the walk leaves the
/// domain. Overwrites `parent`.
pub fn locate_parents(input: &TetMesh, mesh: &mut TetMesh) {
    let ids: Vec<u32> = mesh.tet_ids().collect();
    for t in ids {
        let p = mesh.tet_points(t);
        let c = (p[0] + p[1] + p[2] + p[3]) * 0.25;
        let hint = mesh.parent(t);
        let start = if (hint as usize) < input.n_tet_slots() && input.is_alive(hint) {
            hint
        } else {
            match input.tet_ids().next() {
                Some(s) => s,
                None => return,
            }
        };
        mesh.set_parent(t, walk_to(input, start, c));
    }
}

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
/// 100,000 tets) looks for the containing tet. If none is found (the point
/// is outside the domain), the tet where the walk left the domain.
pub fn walk_to(mesh: &TetMesh, start: u32, x: DVec3) -> u32 {
    let end = straight_walk(mesh, start, x);
    if contains(mesh, end, x) {
        return end;
    }
    let mut seen = std::collections::HashSet::new();
    let mut queue = std::collections::VecDeque::from([start]);
    seen.insert(start);
    while let Some(t) = queue.pop_front() {
        if contains(mesh, t, x) {
            return t;
        }
        if seen.len() > 100_000 {
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
