//! [`TetMesh::reorder_spatially`]: renumbers points along a Morton (Z-order)
//! curve and tets by their first vertex, so that neighbours in space are
//! neighbours in memory. Refinement appends new tets and points at the end
//! of the arrays; without this, walks over balls and rings touch memory all
//! over a multi-gigabyte mesh (a 2.5M-tet step spent a fifth of its time in
//! cache misses of ball walks). The order is a pure function of the mesh, so
//! it is deterministic for any number of threads.

use super::fasthash::{FastHashMap, FastHashSet};
use super::{edge_key, face_key, Remap, TetMesh, DEAD, NO_ADJ};
use crate::topo::scatter::{permute_into, CountingSort, LastTouch};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering};

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

    /// The reordering, with the compaction fused in: the composite old → new
    /// maps are computed straight from the live slots, so every tet array is
    /// moved once. Memory matters here: it runs on the largest mesh of a
    /// refinement. The tet map lives in the generation array's allocation;
    /// on top of the mesh the reordering holds at most the 4-byte order and
    /// one 16-byte array per tet slot (20 bytes, where compacting and then
    /// permuting held 24) plus a few point arrays: tets are gathered into a
    /// fresh array, adjacency into the old tet array, region/level/parent
    /// into fresh arrays once the 16-byte one is gone. Fresh memory is
    /// touched by the parallel passes themselves (page faults cost as much
    /// as the moves). Each pass is parallel and its result does not depend
    /// on the number of threads.
    fn reorder(&mut self, want_maps: bool) -> Option<Remap> {
        // Points used by a live tet, numbered in order (the compaction's
        // point map, `DEAD` for unused points).
        let (mut pmap, np) = used_points(&self.tets, self.points.len());
        if np == 0 {
            let first = self.compact();
            return want_maps.then_some(first);
        }
        // The Morton order of the used points: sorted by (code, old id), which
        // is (code, compacted id) as the compaction keeps the order.
        let (lo, hi) = self
            .points
            .par_iter()
            .zip(pmap.par_iter())
            .filter(|(_, &c)| c != DEAD)
            .map(|(p, _)| (*p, *p))
            .reduce(
                || {
                    (
                        glam::DVec3::splat(f64::INFINITY),
                        glam::DVec3::splat(f64::NEG_INFINITY),
                    )
                },
                |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
            );
        let scale = (hi - lo).max_element().max(f64::MIN_POSITIVE);
        // Unused points get the largest key and end up last, cut off: an
        // indexed collect, without the copies of a parallel filter.
        let mut codes: Vec<(u64, u32)> = self
            .points
            .par_iter()
            .zip(pmap.par_iter())
            .enumerate()
            .map(|(i, (p, &c))| {
                if c == DEAD {
                    return (u64::MAX, i as u32);
                }
                let q = (*p - lo) / scale * ((1u64 << 21) - 1) as f64;
                let c = spread(q.x as u64) | (spread(q.y as u64) << 1) | (spread(q.z as u64) << 2);
                (c, i as u32)
            })
            .collect();
        codes.par_sort_unstable();
        codes.truncate(np);
        self.points = codes
            .par_iter()
            .map(|&(_, old)| self.points[old as usize])
            .collect();
        // Compacted id → new id, for the tag tables (keyed by compacted ids
        // after the compaction's pass).
        // Compacted ids of distinct used points are distinct: a permutation.
        let cmap = permute_into(
            np,
            codes
                .par_iter()
                .enumerate()
                .map(|(new, &(_, old))| (pmap[old as usize] as usize, new as u32)),
        );
        drop(codes);
        self.remap_tags(&pmap, &cmap);
        // Old id → new id.
        pmap.par_iter_mut().for_each(|c| {
            if *c != DEAD {
                *c = cmap[*c as usize];
            }
        });
        drop(cmap);

        // The tet map lives in the generation array's allocation (all zeros
        // afterwards): no fresh pages.
        let generation = std::mem::take(&mut self.generation);
        let TetOrder { map: tmap, order } = self.tet_order(&pmap, np, generation);
        let nt = order.len();
        // Gathered in the new order: the writes stream, and the reads of
        // spatial neighbours (their slots and tet map entries) stay close.
        // Tets into a fresh array, adjacency into the old tet array. Fresh
        // arrays are zeroed by the allocator: their pages are faulted by the
        // parallel writes rather than by a sequential fill.
        let mut tets = vec![[0u32; 4]; nt];
        tets.par_iter_mut()
            .zip(order.par_iter())
            .for_each(|(v, &t)| {
                *v = self.tets[t as usize].map(|x| pmap[x as usize]);
            });
        let mut adj = std::mem::replace(&mut self.tets, tets);
        adj.truncate(nt);
        adj.par_iter_mut()
            .zip(order.par_iter())
            .for_each(|(a, &t)| {
                *a = self.adj[t as usize].map(|h| {
                    if h == NO_ADJ {
                        NO_ADJ
                    } else {
                        4 * tmap[(h >> 2) as usize] + (h & 3)
                    }
                });
            });
        self.adj = adj;
        let mut region = vec![0i32; nt];
        let mut level = vec![0u8; nt];
        let mut parent = vec![0u32; nt];
        region
            .par_iter_mut()
            .zip(level.par_iter_mut())
            .zip(parent.par_iter_mut())
            .zip(order.par_iter())
            .for_each(|(((r, l), p), &t)| {
                let t = t as usize;
                (*r, *l, *p) = (self.region[t], self.level[t], self.parent[t]);
            });
        drop(order);
        self.region = region;
        self.level = level;
        self.parent = parent;
        self.free.clear();
        // The old table goes before the new one is built.
        self.v2t = Vec::new();
        self.v2t = last_tets(&self.tets, np);
        if want_maps {
            self.generation = vec![0; nt];
            return Some(Remap {
                points: pmap,
                tets: tmap,
            });
        }
        let mut generation = tmap;
        generation.truncate(nt);
        generation.par_iter_mut().for_each(|g| *g = 0);
        self.generation = generation;
        None
    }

    /// Remaps the tag tables as a compaction (`cmap`: old → compacted id,
    /// `DEAD` for unused) and then a renumbering (`rmap`: compacted → new)
    /// would, one table rebuild each: the tables' layout, and so their
    /// iteration order, stays that of the two-pass code.
    fn remap_tags(&mut self, cmap: &[u32], rmap: &[u32]) {
        let cm = |v: u32| cmap[v as usize];
        let rm = |v: u32| rmap[v as usize];
        let faces = self
            .face_markers
            .drain()
            .filter(|(k, _)| k.iter().all(|&v| cm(v) != DEAD))
            .map(|(k, m)| (face_key(k.map(cm)), m))
            .collect::<FastHashMap<_, _>>();
        self.face_markers = faces
            .into_iter()
            .map(|(k, m)| (face_key(k.map(rm)), m))
            .collect();
        let edges = self
            .feature_edges
            .drain()
            .filter(|(k, _)| k.iter().all(|&v| cm(v) != DEAD))
            .map(|(k, m)| (edge_key(cm(k[0]), cm(k[1])), m))
            .collect::<FastHashMap<_, _>>();
        self.feature_edges = edges
            .into_iter()
            .map(|(k, m)| (edge_key(rm(k[0]), rm(k[1])), m))
            .collect();
        let remap_set = |s: &FastHashSet<u32>| -> FastHashSet<u32> {
            let s = s
                .iter()
                .map(|&v| cm(v))
                .filter(|&v| v != DEAD)
                .collect::<FastHashSet<_>>();
            s.iter().map(|&v| rm(v)).collect()
        };
        self.corners = remap_set(&self.corners);
        self.required = remap_set(&self.required);
    }

    /// The new id of each tet slot (`DEAD` for dead slots) and its inverse:
    /// live tets sorted by their smallest new vertex id, ties in slot order
    /// (as the sort of compacted ids did) — a stable counting sort keyed by
    /// that vertex. `pmap` is old → new point id; `map` is a buffer to reuse.
    fn tet_order(&self, pmap: &[u32], np: usize, mut map: Vec<u32>) -> TetOrder {
        // Key of each slot first, written where its new id will go.
        map.clear();
        map.par_extend(self.tets.par_iter().map(|v| {
            if v[0] == DEAD {
                DEAD
            } else {
                v.iter().map(|&x| pmap[x as usize]).min().unwrap_or(DEAD)
            }
        }));
        // Contiguous parts counted and filled in parallel, each filling its
        // own stretch of every key: the result is that of one sequential
        // pass for any number of parts. Few parts: each holds a count per
        // point.
        let parts = rayon::current_num_threads().clamp(1, 8);
        let per = map.len().div_ceil(parts).max(1);
        let counts: Vec<Vec<u32>> = map
            .par_chunks(per)
            .map(|part| {
                let mut c = vec![0u32; np];
                for &k in part.iter().filter(|&&k| k != DEAD) {
                    c[k as usize] += 1;
                }
                c
            })
            .collect();
        // Each part fills its own stretch of every key.
        let order = CountingSort::new(counts, np).fill(
            0u32,
            map.par_chunks_mut(per).enumerate(),
            |(i, part), fill| {
                for (t, k) in part.iter_mut().enumerate() {
                    if *k != DEAD {
                        *k = fill.put(*k as usize, (i * per + t) as u32);
                    }
                }
            },
        );
        TetOrder { map, order }
    }
}

/// [`TetMesh::tet_order`]'s result.
struct TetOrder {
    /// New id of each old slot, `DEAD` for dead slots.
    map: Vec<u32>,
    /// Old slot of each new id.
    order: Vec<u32>,
}

/// The compaction's point map for these tet slots (old id → id among the
/// used points, `DEAD` for points no live tet uses) and the number of used
/// points.
fn used_points(tets: &[[u32; 4]], n: usize) -> (Vec<u32>, usize) {
    let used: Vec<AtomicU32> = (0..n).into_par_iter().map(|_| AtomicU32::new(0)).collect();
    tets.par_iter().filter(|v| v[0] != DEAD).for_each(|v| {
        for &x in v {
            let u = &used[x as usize];
            // A load first: most points were marked already.
            if u.load(Ordering::Relaxed) == 0 {
                u.store(1, Ordering::Relaxed);
            }
        }
    });
    let mut next = 0u32;
    // Reuses the allocation (same layout).
    let map = used
        .into_iter()
        .map(|u| {
            if u.into_inner() == 0 {
                DEAD
            } else {
                next += 1;
                next - 1
            }
        })
        .collect();
    (map, next as usize)
}

/// The vertex → tet table of a compacted mesh as
/// [`TetMesh::rebuild_v2t`] builds it: the last (highest) tet holding each
/// point.
fn last_tets(tets: &[[u32; 4]], n: usize) -> Vec<u32> {
    let last = LastTouch::new(n);
    tets.par_iter().enumerate().rev().for_each(|(t, v)| {
        for &x in v {
            last.touch(x, t);
        }
    });
    last.into_last(DEAD)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::MeshData;

    impl TetMesh {
        /// The reordering as it was before the compaction was fused in
        /// (compact, then sort and permute): what the fused one must equal.
        fn reorder_reference(&mut self, want_maps: bool) -> Option<Remap> {
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
                    let c =
                        spread(q.x as u64) | (spread(q.y as u64) << 1) | (spread(q.z as u64) << 2);
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

    /// Everything the reordering leaves in the mesh, the tag tables in their
    /// iteration order (later passes iterate them, so their layout is part
    /// of the result).
    #[derive(Debug, PartialEq)]
    struct State {
        points: Vec<[u64; 3]>,
        tets: Vec<[u32; 4]>,
        adj: Vec<[u32; 4]>,
        generation: Vec<u32>,
        free: Vec<u32>,
        region: Vec<i32>,
        level: Vec<u8>,
        parent: Vec<u32>,
        v2t: Vec<u32>,
        face_markers: Vec<([u32; 3], i32)>,
        feature_edges: Vec<([u32; 2], i32)>,
        corners: Vec<u32>,
        required: Vec<u32>,
    }

    fn state(m: &TetMesh) -> State {
        State {
            points: m
                .points
                .iter()
                .map(|p| p.to_array().map(f64::to_bits))
                .collect(),
            tets: m.tets.clone(),
            adj: m.adj.clone(),
            generation: m.generation.clone(),
            free: m.free.clone(),
            region: m.region.clone(),
            level: m.level.clone(),
            parent: m.parent.clone(),
            v2t: m.v2t.clone(),
            face_markers: m.face_markers.iter().map(|(k, v)| (*k, *v)).collect(),
            feature_edges: m.feature_edges.iter().map(|(k, v)| (*k, *v)).collect(),
            corners: m.corners.iter().copied().collect(),
            required: m.required.iter().copied().collect(),
        }
    }

    /// A refined grid with dead slots (edge removal frees tets), points no
    /// tet uses (with tags that the compaction drops), many tagged boundary
    /// faces and edges, and regions.
    fn untidy_mesh() -> TetMesh {
        let (mut m, _) = TetMesh::from_data(&crate::mesh::generate::cube_grid(4)).unwrap();
        for t in 0..m.n_tet_slots() as u32 {
            m.set_region(t, (t % 3) as i32);
        }
        // `fast` and the paper's bar, 0.3: the boundary fixed, as when the
        // fixture was written (its edge removals leave the dead slots the
        // tests need; at 0.35 the grid's step has none).
        let opts = crate::refine::RefineOptions {
            effort: crate::improve::Effort::Fast,
            threshold: 0.3,
            ..Default::default()
        };
        crate::refine::refine_step(&mut m, 1, &opts);
        let boundary: Vec<(u32, usize)> = m
            .tet_ids()
            .flat_map(|t| (0..4).map(move |f| (t, f)))
            .filter(|&(t, f)| m.is_boundary_face(t, f))
            .collect();
        for (i, &(t, f)) in boundary.iter().enumerate() {
            let v = m.face_vertices(t, f);
            m.set_face_marker(v, Some(i as i32));
            m.set_feature_edge(v[0], v[1], Some(i as i32 % 7));
            if i % 5 == 0 {
                m.set_corner(v[2], true);
                m.set_required(v[1], true);
            }
        }
        let lone = m.add_point(glam::DVec3::new(0.3, 0.2, 0.1));
        let far = m.add_point(glam::DVec3::new(-5.0, 9.0, 2.0));
        m.set_corner(lone, true);
        m.set_required(far, true);
        m.set_feature_edge(lone, 0, Some(1));
        m.set_face_marker([far, 1, 2], Some(2));
        // A used point after the unused ones, so that ids shift.
        let t = m.tet_ids().next().unwrap();
        let c = m.tet_points(t);
        crate::ops::split14(&mut m, t, (c[0] + c[1] + c[2] + c[3]) * 0.25).unwrap();
        assert!(m.n_tet_slots() > m.n_tets(), "no dead slots");
        m
    }

    #[test]
    fn fused_reordering_equals_compact_then_reorder() {
        let m = untidy_mesh();
        for want_maps in [false, true] {
            let (mut a, mut b) = (m.clone(), m.clone());
            let ra = a.reorder(want_maps);
            let rb = b.reorder_reference(want_maps);
            assert_eq!(ra, rb);
            assert_eq!(state(&a), state(&b));
            a.check().unwrap();
        }
    }

    #[test]
    fn reordering_does_not_depend_on_the_thread_count() {
        let m = untidy_mesh();
        let run = |threads: usize, want_maps: bool| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut a = m.clone();
                let r = a.reorder(want_maps);
                (r, state(&a))
            })
        };
        for want_maps in [false, true] {
            assert_eq!(run(1, want_maps), run(3, want_maps));
        }
    }

    #[test]
    fn reordering_a_mesh_without_tets() {
        let (mut a, _) = TetMesh::from_data(&crate::mesh::generate::cube_grid(1)).unwrap();
        for t in a.tet_ids().collect::<Vec<_>>() {
            a.kill_tet(t);
        }
        a.set_corner(0, true);
        let mut b = a.clone();
        assert_eq!(a.reorder(true), b.reorder_reference(true));
        assert_eq!(state(&a), state(&b));
        assert_eq!(a.n_points(), 0);
    }

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
