//! [`TetMesh::reorder_spatially`]: renumbers points along a Morton (Z-order)
//! curve and tets by their first vertex, so that neighbours in space are
//! neighbours in memory. Refinement appends new tets and points at the end
//! of the arrays; without this, walks over balls and rings touch memory all
//! over a multi-gigabyte mesh (a 2.5M-tet step spent a fifth of its time in
//! cache misses of ball walks). The order is a pure function of the mesh, so
//! it is deterministic for any number of threads.

use super::fasthash::{FastHashMap, FastHashSet};
use super::{edge_key, face_key, Remap, TetMesh, DEAD, NO_ADJ};
use rayon::prelude::*;

/// Spreads the low 21 bits of `x` to every third bit.
fn spread(x: u64) -> u64 {
    let mut x = x & 0x1f_ffff;
    x = (x | (x << 32)) & 0x1f00000000ffff;
    x = (x | (x << 16)) & 0x1f0000ff0000ff;
    x = (x | (x << 8)) & 0x100f00f00f00f00f;
    x = (x | (x << 4)) & 0x10c30c30c30c30c3;
    x = (x | (x << 2)) & 0x1249249249249249;
    x
}

impl TetMesh {
    /// Compacts the mesh, then renumbers points by the Morton code of their
    /// position and tets by their smallest (new) vertex id. Returns the
    /// composite old → new maps. Tags, regions, levels and parents follow.
    pub fn reorder_spatially(&mut self) -> Remap {
        self.reorder(true)
            .expect("reorder(true) always returns the maps")
    }

    /// [`TetMesh::reorder_spatially`] without the old → new maps, for callers
    /// that do not need them (the refinement step): on a 14M-tet mesh the
    /// maps alone are 120 MB.
    pub fn reorder_spatially_in_place(&mut self) {
        self.reorder(false);
    }

    /// The reordering. Memory matters here: it runs on the largest mesh of a
    /// refinement, so each array is permuted on its own and its old copy
    /// dropped before the next one is built; at most 24 bytes per tet slot
    /// are held on top of the mesh (the 4-byte order and map plus one
    /// 16-byte array), where permuting everything at once took 53.
    fn reorder(&mut self, want_maps: bool) -> Option<Remap> {
        let first = self.compact();
        let first = want_maps.then_some(first);
        let np = self.points.len();
        if np == 0 {
            return first;
        }
        let (lo, hi) = self.points.iter().fold(
            (
                glam::DVec3::splat(f64::INFINITY),
                glam::DVec3::splat(f64::NEG_INFINITY),
            ),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        let scale = (hi - lo).max_element().max(f64::MIN_POSITIVE);
        let mut codes: Vec<(u64, u32)> = self
            .points
            .par_iter()
            .enumerate()
            .map(|(i, p)| {
                let q = (*p - lo) / scale * ((1u64 << 21) - 1) as f64;
                let c = spread(q.x as u64) | (spread(q.y as u64) << 1) | (spread(q.z as u64) << 2);
                (c, i as u32)
            })
            .collect();
        codes.par_sort_unstable();
        let mut pmap = vec![0u32; np];
        for (new, &(_, old)) in codes.iter().enumerate() {
            pmap[old as usize] = new as u32;
        }
        self.points = codes
            .par_iter()
            .map(|&(_, old)| self.points[old as usize])
            .collect();
        drop(codes);

        // Tets: renumber vertices, then sort by (smallest vertex, old id),
        // packed in one u64 so that the sort key is 8 bytes.
        let nt = self.tets.len();
        self.tets.par_iter_mut().for_each(|v| {
            for x in v.iter_mut() {
                *x = pmap[*x as usize];
            }
        });
        let mut keys: Vec<u64> = self
            .tets
            .par_iter()
            .enumerate()
            .map(|(t, v)| (u64::from(*v.iter().min().unwrap_or(&DEAD)) << 32) | t as u64)
            .collect();
        keys.par_sort_unstable();
        // `order[new] = old`, `tmap[old] = new`.
        let order: Vec<u32> = keys.par_iter().map(|&k| k as u32).collect();
        drop(keys);
        let mut tmap = vec![0u32; nt];
        for (new, &old) in order.iter().enumerate() {
            tmap[old as usize] = new as u32;
        }
        self.tets = permuted(&self.tets, &order);
        self.adj = order
            .par_iter()
            .map(|&o| {
                self.adj[o as usize].map(|h| {
                    if h == NO_ADJ {
                        NO_ADJ
                    } else {
                        4 * tmap[(h >> 2) as usize] + (h & 3)
                    }
                })
            })
            .collect();
        self.region = permuted(&self.region, &order);
        self.level = permuted(&self.level, &order);
        self.parent = permuted(&self.parent, &order);
        drop(order);
        self.generation.iter_mut().for_each(|g| *g = 0);

        let pm = |v: u32| pmap[v as usize];
        self.face_markers = self
            .face_markers
            .drain()
            .map(|(k, m)| (face_key(k.map(pm)), m))
            .collect::<FastHashMap<_, _>>();
        self.feature_edges = self
            .feature_edges
            .drain()
            .map(|(k, m)| (edge_key(pm(k[0]), pm(k[1])), m))
            .collect::<FastHashMap<_, _>>();
        self.corners = self
            .corners
            .iter()
            .map(|&v| pm(v))
            .collect::<FastHashSet<_>>();
        self.required = self
            .required
            .iter()
            .map(|&v| pm(v))
            .collect::<FastHashSet<_>>();
        self.rebuild_v2t();

        let compose = |a: &[u32], b: &[u32]| -> Vec<u32> {
            a.iter()
                .map(|&x| if x == DEAD { DEAD } else { b[x as usize] })
                .collect()
        };
        first.map(|first| Remap {
            points: compose(&first.points, &pmap),
            tets: compose(&first.tets, &tmap),
        })
    }
}

/// `values` gathered in `order` (`out[new] = values[order[new]]`).
fn permuted<T: Copy + Send + Sync>(values: &[T], order: &[u32]) -> Vec<T> {
    order.par_iter().map(|&o| values[o as usize]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::MeshData;

    #[test]
    fn spread_interleaves() {
        assert_eq!(spread(0b111), 0b1001001);
        assert_eq!(spread(1 << 20), 1 << 60);
    }

    #[test]
    fn reordering_keeps_the_mesh() {
        // Two tets sharing a face, with tags; listed in an order the Morton
        // curve will change.
        let data = MeshData {
            points: vec![
                [1.0, 1.0, 1.0],
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
            tets: vec![[1, 2, 3, 4], [2, 3, 4, 0]],
            tet_regions: vec![5, 7],
            triangles: vec![([1, 2, 3], 9)],
            edges: vec![([1, 2], 4)],
            corners: vec![1],
            ..Default::default()
        };
        let (mut m, _) = TetMesh::from_data(&data).unwrap();
        let before: f64 = m
            .tet_ids()
            .map(|t| crate::geom::tet_volume(&m.tet_points(t)))
            .sum();
        let remap = m.reorder_spatially();
        m.check().unwrap();
        let after: f64 = m
            .tet_ids()
            .map(|t| crate::geom::tet_volume(&m.tet_points(t)))
            .sum();
        assert!((before - after).abs() < 1e-15);
        // The origin (old point 1) has Morton code 0 and comes first.
        assert_eq!(remap.points[1], 0);
        assert!(m.is_corner(0));
        assert_eq!(m.feature_edge(remap.points[1], remap.points[2]), Some(4));
        assert_eq!(
            m.face_marker([0, remap.points[2], remap.points[3]]),
            Some(9)
        );
        let t0 = remap.tets[0];
        assert_eq!(m.region(t0), 5);
        assert_eq!(m.region(remap.tets[1]), 7);
    }

    #[test]
    fn in_place_reordering_matches_the_mapped_one() {
        // A grid with some tets killed and re-used, so compaction moves ids.
        let (mut a, _) = TetMesh::from_data(&crate::mesh::generate::cube_grid(3)).unwrap();
        let c = a.tet_points(5);
        let centre = (c[0] + c[1] + c[2] + c[3]) * 0.25;
        crate::ops::split14(&mut a, 5, centre).unwrap();
        let mut b = a.clone();
        let remap = a.reorder_spatially();
        b.reorder_spatially_in_place();
        assert_eq!(a.points, b.points);
        assert_eq!(a.tets, b.tets);
        assert_eq!(a.adj, b.adj);
        assert_eq!(a.parent, b.parent);
        b.check().unwrap();
        // The maps send every live old tet to a distinct new slot.
        let mut seen = vec![false; b.n_tet_slots()];
        for &t in remap.tets.iter().filter(|&&t| t != DEAD) {
            assert!(!std::mem::replace(&mut seen[t as usize], true));
        }
        assert!(seen.iter().all(|&s| s));
    }
}
