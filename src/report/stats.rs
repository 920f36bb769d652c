//! Mesh statistics: the rows of Table 1 of the √3 paper (Burkhart, Hamann and Umlauf) plus boundary and
//! interior faces, maximum dihedral angle, inverted count, volume, regions and
//! the minimum-dihedral histogram, in one parallel sweep over the tets.
//!
//! The sweep takes four tets at a time through the vector units (an AVX2
//! copy where the CPU has it, same operations and so same bits) and counts,
//! besides the angle figures (`angles.rs`), the tets at each vertex and the
//! boundary faces; the edges and valences follow from those counts by Euler's
//! formula on the vertex links (`topology.rs`), with no global edge table and
//! no walk around any edge.
//!
//! Cost on the 1.05M-tet cube grid of `benches/quality.rs`, one core, CPU time
//! per tet (this machine: AMD EPYC, AVX2): about 48 ns, of which roughly 30 ns
//! are the cosine arithmetic and the gathering of the corners, 5 ns the two
//! arc cosines, 3 ns the histogram, 4 ns the per-vertex counts and 2–3 ns the
//! valences; the earlier version (libm `acos` per tet, walks around edges for
//! edge ownership) took about 111 ns.

mod angles;
mod topology;

use crate::geom::orient3d;
use crate::mesh::{TetMesh, DEAD, NO_ADJ};
use crate::topo::TET_FACES;
use angles::{cosine_extremes, lanes, BinThresholds, LaneVec, LANES};
use glam::DVec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::sync::Mutex;

/// Worst / average / best of the per-tet minimum dihedral angle, in degrees.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MinDihedral {
    /// Smallest per-tet minimum.
    pub worst: f64,
    /// Mean of the per-tet minima.
    pub avg: f64,
    /// Largest per-tet minimum.
    pub best: f64,
}

/// Worst / average of the per-tet maximum dihedral angle, in degrees.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MaxDihedral {
    /// Largest per-tet maximum.
    pub worst: f64,
    /// Mean of the per-tet maxima.
    pub avg: f64,
}

/// Vertex valence, counted as incident edges.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Valence {
    /// Mean number of incident edges over the nodes.
    pub avg: f64,
    /// Largest number of incident edges.
    pub max: u32,
}

/// A histogram of the per-tet minimum dihedral angle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Histogram {
    /// Bin edges in degrees (`counts.len() + 1` values).
    pub edges_deg: Vec<f64>,
    /// Tets per bin; values outside the range go to the first or last bin.
    pub counts: Vec<u64>,
}

impl Histogram {
    /// `bins` equal bins over `[lo, hi]` degrees, all empty.
    pub fn new(lo: f64, hi: f64, bins: usize) -> Histogram {
        let bins = bins.max(1);
        Histogram {
            edges_deg: (0..=bins)
                .map(|i| lo + (hi - lo) * i as f64 / bins as f64)
                .collect(),
            counts: vec![0; bins],
        }
    }

    /// Bin of value `x` (clamped into range).
    #[inline]
    pub fn bin(&self, x: f64) -> usize {
        let n = self.counts.len();
        let lo = self.edges_deg[0];
        let hi = self.edges_deg[n];
        let y = (x - lo) / (hi - lo) * n as f64;
        // Truncation is the floor for y >= 0; below 0 and NaN go to bin 0.
        if y >= 0.0 {
            // (Through u32: the same saturation, a cheaper conversion.)
            (y as u32 as usize).min(n - 1)
        } else {
            0
        }
    }
}

/// Default histogram: 1° bins over 0–71° (the regular tet's 70.53° is the top).
pub const DEFAULT_BINS: usize = 71;
/// Upper end of the default histogram range, degrees.
pub const DEFAULT_HIST_MAX_DEG: f64 = 71.0;

/// Statistics of a mesh; serialises to exactly the JSON of `quality --json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MeshStats {
    /// Vertices used by at least one tet.
    pub nodes: usize,
    /// Distinct edges.
    pub edges: usize,
    /// Live tets.
    pub tets: usize,
    /// Faces with one tet.
    pub boundary_faces: usize,
    /// Faces with two tets.
    pub interior_faces: usize,
    /// Per-tet minimum dihedral angle: worst / avg / best.
    pub min_dihedral_deg: MinDihedral,
    /// Per-tet maximum dihedral angle: worst / avg.
    pub max_dihedral_deg: MaxDihedral,
    /// Incident edges per node.
    pub valence: Valence,
    /// Tets with non-positive orientation (exact predicate).
    pub inverted: usize,
    /// Total signed volume.
    pub volume: f64,
    /// Tets per region id (keys are the ids as strings, sorted numerically).
    pub regions: BTreeMap<String, usize>,
    /// Histogram of the per-tet minimum dihedral angle.
    pub histogram: Histogram,
    /// Tagged feature (crease) edges.
    #[serde(default)]
    pub feature_edges: usize,
    /// Corner vertices.
    #[serde(default)]
    pub corners: usize,
}

/// Whether a tet with float determinant `d` and squared edge-vector lengths
/// product `edge_product` (from [`cosine_extremes`]) is inverted or flat by the
/// exact predicate; `corners` gives its points when that must be evaluated.
///
/// The float determinant `a·(b×c)` of the edge vectors from corner 0 is off by
/// at most about 10ε times its permanent Σ|a_i b_j c_k| ≤ 3√3 |a||b||c| (the
/// bound of Shewchuk's orient3d filter), i.e. below 6e-15·|a||b||c|. When
/// `d² > 1e-26·|a|²|b|²|c|²` (a margin of 15) its sign is therefore exact;
/// otherwise, and when the product under- or overflows, the exact predicate
/// decides.
#[inline(always)]
fn is_inverted(d: f64, edge_product: f64, corners: impl FnOnce() -> [DVec3; 4]) -> bool {
    if edge_product > 1e-250 && edge_product.is_finite() && d * d > 1e-26 * edge_product {
        d < 0.0
    } else {
        let p = corners();
        orient3d(p[0], p[1], p[2], p[3]) <= 0.0
    }
}

/// Tets per region, for one chunk: few distinct ids, so a short list with the
/// last hit first beats a map.
#[derive(Clone, Default)]
struct RegionCounts(Vec<(i32, usize)>);

impl RegionCounts {
    #[inline]
    fn add(&mut self, r: i32) {
        if let Some(first) = self.0.first_mut() {
            if first.0 == r {
                first.1 += 1;
                return;
            }
        }
        match self.0.iter().position(|x| x.0 == r) {
            Some(i) => {
                self.0[i].1 += 1;
                self.0.swap(0, i);
            }
            None => {
                self.0.push((r, 1));
                let last = self.0.len() - 1;
                self.0.swap(0, last);
            }
        }
    }
}

/// Partial sums of one chunk of tet slots.
///
/// The extreme angles of the ordinary tets (proper and not inverted) are kept
/// as their extreme cosines and turned into angles once, after the merge (see
/// [`angles`]); the few other tets contribute their angles directly.
#[derive(Clone)]
struct Acc {
    /// Ordinary tets seen (those whose cosine extremes below count).
    ordinary: usize,
    /// Largest / smallest of the per-tet largest cosines, and smallest of the
    /// per-tet smallest cosines, over the ordinary tets.
    max_max_cos: f64,
    min_max_cos: f64,
    min_min_cos: f64,
    /// Angle extremes of the other (degenerate or inverted) tets.
    min_worst: f64,
    min_best: f64,
    max_worst: f64,
    min_sum: f64,
    max_sum: f64,
    inverted: usize,
    volume: f64,
    boundary_faces: Vec<[u32; 3]>,
    tets: usize,
    hist: Vec<u64>,
    regions: RegionCounts,
}

impl Acc {
    fn new(bins: usize) -> Acc {
        Acc {
            ordinary: 0,
            max_max_cos: f64::NEG_INFINITY,
            min_max_cos: f64::INFINITY,
            min_min_cos: f64::INFINITY,
            min_worst: f64::INFINITY,
            min_best: f64::NEG_INFINITY,
            max_worst: f64::NEG_INFINITY,
            min_sum: 0.0,
            max_sum: 0.0,
            inverted: 0,
            volume: 0.0,
            boundary_faces: Vec::new(),
            tets: 0,
            hist: vec![0; bins],
            regions: RegionCounts::default(),
        }
    }

    fn merge(mut self, o: Acc) -> Acc {
        self.ordinary += o.ordinary;
        self.max_max_cos = self.max_max_cos.max(o.max_max_cos);
        self.min_max_cos = self.min_max_cos.min(o.min_max_cos);
        self.min_min_cos = self.min_min_cos.min(o.min_min_cos);
        self.min_worst = self.min_worst.min(o.min_worst);
        self.min_best = self.min_best.max(o.min_best);
        self.max_worst = self.max_worst.max(o.max_worst);
        self.min_sum += o.min_sum;
        self.max_sum += o.max_sum;
        self.inverted += o.inverted;
        self.volume += o.volume;
        self.boundary_faces.extend(o.boundary_faces);
        self.tets += o.tets;
        for (a, b) in self.hist.iter_mut().zip(o.hist) {
            *a += b;
        }
        self.regions.0.extend(o.regions.0);
        self
    }

    /// Worst and best minimum angle and worst maximum angle over all tets:
    /// those of the other tets, and the angles of the ordinary tets' extreme
    /// cosines (libm, as [`crate::geom::tet_quality`] does it per tet).
    fn extreme_angles(&self) -> (f64, f64, f64) {
        let (mut worst, mut best, mut max_worst) = (self.min_worst, self.min_best, self.max_worst);
        if self.ordinary > 0 {
            worst = worst.min(angles::exact_deg(self.max_max_cos));
            best = best.max(angles::exact_deg(self.min_max_cos));
            max_worst = max_worst.max(angles::exact_deg(self.min_min_cos));
        }
        (worst, best, max_worst)
    }
}

/// The inputs of one sweep over the tets.
struct Sweep<'a> {
    tets: &'a [[u32; 4]],
    adj: &'a [[u32; 4]],
    points: &'a [DVec3],
    region: &'a [i32],
    histogram: &'a Histogram,
    thresholds: &'a BinThresholds,
}

impl Sweep<'_> {
    /// The partial sums of tet slots `lo..hi`, adding the tets at each vertex
    /// to `tets_at`. Dispatches to a copy compiled for AVX2 where the CPU has
    /// it: the same operations (no fused multiply-add), so the same bits.
    fn chunk(&self, lo: usize, hi: usize, tets_at: &mut [u32]) -> Acc {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU supports AVX2 (checked just above).
                return unsafe { self.chunk_avx2(lo, hi, tets_at) };
            }
        }
        self.chunk_body(lo, hi, tets_at)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn chunk_avx2(&self, lo: usize, hi: usize, tets_at: &mut [u32]) -> Acc {
        self.chunk_body(lo, hi, tets_at)
    }

    #[inline(always)]
    fn chunk_body(&self, lo: usize, hi: usize, tets_at: &mut [u32]) -> Acc {
        let mut a = Acc::new(self.histogram.counts.len());
        let mut batch = [[0u32; 4]; LANES];
        let mut in_batch = 0;
        for t in lo..hi {
            let v = self.tets[t];
            if v[0] == DEAD {
                continue;
            }
            for &x in &v {
                tets_at[x as usize] += 1;
            }
            let row = self.adj[t];
            if row.contains(&NO_ADJ) {
                for (f, &h) in row.iter().enumerate() {
                    if h == NO_ADJ {
                        a.boundary_faces.push(TET_FACES[f].map(|i| v[i]));
                    }
                }
            }
            a.regions.add(self.region[t]);
            batch[in_batch] = v;
            in_batch += 1;
            if in_batch == LANES {
                self.add_tets(&mut a, &batch);
                in_batch = 0;
            }
        }
        if in_batch > 0 {
            self.add_tets(&mut a, &batch[..in_batch]);
        }
        a
    }

    /// Adds the angles, volume and inversion of up to [`LANES`] live tets, in
    /// the order given (so that the sums do not depend on the batching).
    #[inline(always)]
    fn add_tets(&self, a: &mut Acc, batch: &[[u32; 4]]) {
        let points = self.points;
        // The last tet repeated to fill the batch.
        let ids: [[u32; 4]; LANES] = std::array::from_fn(|i| batch[i.min(batch.len() - 1)]);
        let corner = |j: usize| {
            let q: [DVec3; LANES] = std::array::from_fn(|i| points[ids[i][j] as usize]);
            LaneVec {
                x: lanes(|i| q[i].x),
                y: lanes(|i| q[i].y),
                z: lanes(|i| q[i].z),
            }
        };
        let c = cosine_extremes(&[corner(0), corner(1), corner(2), corner(3)]);
        let lo = angles::acos_deg(c.max_cos);
        let hi = angles::acos_deg(c.min_cos);
        let estimate = self.thresholds.estimates(lo);
        for (i, v) in batch.iter().enumerate() {
            a.tets += 1;
            a.volume += c.d[i] / 6.0;
            a.inverted +=
                is_inverted(c.d[i], c.edge_product[i], || v.map(|k| points[k as usize])) as usize;
            if c.proper[i] && c.d[i] >= 0.0 {
                a.ordinary += 1;
                a.max_max_cos = a.max_max_cos.max(c.max_cos[i]);
                a.min_max_cos = a.min_max_cos.min(c.max_cos[i]);
                a.min_min_cos = a.min_min_cos.min(c.min_cos[i]);
                a.min_sum += lo[i];
                a.max_sum += hi[i];
                a.hist[self.thresholds.bin(c.max_cos[i], estimate[i])] += 1;
            } else {
                // The conventions of tet_quality: 0/180 for a face of zero
                // area, the angles negated and swapped for an inverted tet.
                let (lo, hi) = if !c.proper[i] {
                    (0.0, 180.0)
                } else {
                    (
                        -angles::exact_deg(c.min_cos[i]),
                        -angles::exact_deg(c.max_cos[i]),
                    )
                };
                a.min_worst = a.min_worst.min(lo);
                a.min_best = a.min_best.max(lo);
                a.max_worst = a.max_worst.max(hi);
                a.min_sum += lo;
                a.max_sum += hi;
                a.hist[self.histogram.bin(lo)] += 1;
            }
        }
    }
}

/// Tet slots per parallel task. Fixed, so that the floating-point sums are
/// grouped the same way whatever the number of threads.
const CHUNK: usize = 8192;

impl MeshStats {
    /// Statistics with the default histogram (1° bins over 0–71°).
    pub fn compute(mesh: &TetMesh) -> MeshStats {
        Self::compute_with(
            mesh,
            Histogram::new(0.0, DEFAULT_HIST_MAX_DEG, DEFAULT_BINS),
        )
    }

    /// Statistics, filling the given (empty) histogram bins.
    ///
    /// One parallel sweep over fixed-size chunks of tet slots computes the
    /// angles, volume, inversion, histogram, regions, boundary faces and the
    /// number of tets at each vertex; the chunk sums are merged in chunk
    /// order, so the result does not depend on the number of threads. The
    /// valences (and so the edge count) then follow from the per-vertex counts
    /// by Euler's formula on the vertex links (`topology.rs`).
    pub fn compute_with(mesh: &TetMesh, mut histogram: Histogram) -> MeshStats {
        let slots = mesh.n_tet_slots();
        let n_points = mesh.n_points();
        let thresholds = BinThresholds::new(&histogram);
        let sweep = Sweep {
            tets: &mesh.tets,
            adj: &mesh.adj,
            points: &mesh.points,
            region: &mesh.region,
            histogram: &histogram,
            thresholds: &thresholds,
        };
        // Tets per vertex, one array per worker thread (a thread works on one
        // chunk at a time, so its lock is never contended); integer sums, so
        // which thread counted what does not matter.
        let per_thread: Vec<Mutex<Vec<u32>>> = (0..rayon::current_num_threads().max(1))
            .map(|_| Mutex::new(vec![0u32; n_points]))
            .collect();
        let accs: Vec<Acc> = (0..slots.div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let lo = c * CHUNK;
                let hi = (lo + CHUNK).min(slots);
                let k = rayon::current_thread_index().unwrap_or(0) % per_thread.len();
                let mut tets_at = per_thread[k].lock().unwrap_or_else(|e| e.into_inner());
                sweep.chunk(lo, hi, &mut tets_at)
            })
            .collect();
        let acc = accs
            .into_iter()
            .reduce(Acc::merge)
            .unwrap_or_else(|| Acc::new(histogram.counts.len()));
        let mut per_thread = per_thread
            .into_iter()
            .map(|m| m.into_inner().unwrap_or_else(|e| e.into_inner()));
        let mut tets_at = per_thread.next().unwrap_or_default();
        for other in per_thread {
            tets_at
                .par_iter_mut()
                .zip(other.par_iter())
                .with_min_len(4096)
                .for_each(|(a, b)| *a += b);
        }

        let valence = topology::valences(&mesh.tets, &tets_at, &acc.boundary_faces);
        let nodes = tets_at.par_iter().filter(|&&n| n > 0).count();
        let edges = valence.par_iter().map(|&v| v as usize).sum::<usize>() / 2;
        let vmax = valence.par_iter().copied().max().unwrap_or(0);

        let (min_worst, min_best, max_worst) = acc.extreme_angles();
        let mut regions: BTreeMap<i32, usize> = BTreeMap::new();
        for (r, n) in acc.regions.0 {
            *regions.entry(r).or_default() += n;
        }
        histogram.counts = acc.hist;
        let n = acc.tets.max(1) as f64;
        let boundary = acc.boundary_faces.len();
        MeshStats {
            nodes,
            edges,
            tets: acc.tets,
            boundary_faces: boundary,
            interior_faces: (4 * acc.tets - boundary) / 2,
            min_dihedral_deg: MinDihedral {
                worst: finite_or_zero(min_worst),
                avg: acc.min_sum / n,
                best: finite_or_zero(min_best),
            },
            max_dihedral_deg: MaxDihedral {
                worst: finite_or_zero(max_worst),
                avg: acc.max_sum / n,
            },
            valence: Valence {
                avg: if nodes > 0 {
                    2.0 * edges as f64 / nodes as f64
                } else {
                    0.0
                },
                max: vmax,
            },
            inverted: acc.inverted,
            volume: acc.volume,
            regions: regions
                .into_iter()
                .map(|(k, v)| (k.to_string(), v))
                .collect(),
            histogram,
            feature_edges: mesh.feature_edges().len(),
            corners: mesh.corners().len(),
        }
    }

    /// Per-vertex valence (incident edges), for the `valence` point array.
    pub fn vertex_valence(mesh: &TetMesh) -> Vec<u32> {
        topology::vertex_valence(mesh)
    }
}

fn finite_or_zero(x: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{orient3d_sign, tet_quality, Orientation};
    use crate::mesh::generate::cube_grid;
    use crate::mesh::{edge_key, MeshData};
    use crate::topo::TET_EDGES;
    use std::collections::HashSet;

    fn xorshift(mut s: u64) -> impl FnMut() -> f64 {
        move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn batch_of(tets: &[[DVec3; 4]]) -> [LaneVec; 4] {
        let corner = |j: usize| LaneVec {
            x: lanes(|i| tets[i][j].x),
            y: lanes(|i| tets[i][j].y),
            z: lanes(|i| tets[i][j].z),
        };
        [corner(0), corner(1), corner(2), corner(3)]
    }

    #[test]
    fn batched_angles_are_the_bits_of_tet_quality() {
        let mut rnd = xorshift(7);
        let mut cases: Vec<[DVec3; 4]> = (0..4000)
            .map(|_| std::array::from_fn(|_| DVec3::new(rnd(), rnd(), rnd())))
            .collect();
        // Slivers, a degenerate tet (two equal points) and inverted tets.
        cases.push([DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.5, 0.5, 1e-9)]);
        cases.push([DVec3::ZERO, DVec3::ZERO, DVec3::Y, DVec3::Z]);
        cases.push([DVec3::ZERO, DVec3::Y, DVec3::X, DVec3::Z]);
        cases.push([DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z]);
        for group in cases.chunks_exact(LANES) {
            let c = cosine_extremes(&batch_of(group));
            for (i, p) in group.iter().enumerate() {
                let q = tet_quality(p);
                assert_eq!((c.d[i] / 6.0).to_bits(), q.volume.to_bits(), "{p:?}");
                if !c.proper[i] {
                    assert_eq!((q.min_dihedral_deg, q.max_dihedral_deg), (0.0, 180.0));
                    continue;
                }
                let (mut lo, mut hi) = (
                    angles::exact_deg(c.max_cos[i]),
                    angles::exact_deg(c.min_cos[i]),
                );
                if c.d[i] < 0.0 {
                    (lo, hi) = (-hi, -lo);
                }
                assert_eq!(lo.to_bits(), q.min_dihedral_deg.to_bits(), "{p:?}");
                assert_eq!(hi.to_bits(), q.max_dihedral_deg.to_bits(), "{p:?}");
            }
        }
    }

    #[test]
    fn inversion_filter_agrees_with_the_exact_predicate() {
        let mut rnd = xorshift(99);
        let mut cases: Vec<[DVec3; 4]> = Vec::new();
        for k in 0..2000 {
            let mut p: [DVec3; 4] = std::array::from_fn(|_| DVec3::new(rnd(), rnd(), rnd()));
            if k % 2 == 0 {
                // Nearly coplanar: the fourth point on the plane of the first
                // three, nudged by a tiny amount either way (or not at all).
                let (a, b, c) = (p[0], p[1], p[2]);
                let (u, v) = (rnd(), rnd());
                let nudge = [0.0, 1e-17, -1e-17, 1e-12, -1e-12][k / 2 % 5];
                p[3] = a + (b - a) * u + (c - a) * v + DVec3::Z * nudge;
            }
            cases.push(p);
        }
        // Exactly flat, with large coordinates.
        cases.push([
            DVec3::new(1e6, 0.0, 0.0),
            DVec3::new(0.0, 1e6, 0.0),
            DVec3::new(0.0, 0.0, 1e6),
            DVec3::new(1e6 / 3.0, 1e6 / 3.0, 1e6 - 2e6 / 3.0),
        ]);
        let mut flat_or_inverted = 0;
        for group in cases.chunks(LANES) {
            let mut padded = [group[0]; LANES];
            padded[..group.len()].copy_from_slice(group);
            let c = cosine_extremes(&batch_of(&padded));
            for (i, p) in group.iter().enumerate() {
                let exact = orient3d_sign(p[0], p[1], p[2], p[3]) != Orientation::Positive;
                flat_or_inverted += exact as usize;
                assert_eq!(
                    is_inverted(c.d[i], c.edge_product[i], || *p),
                    exact,
                    "{p:?}"
                );
            }
        }
        assert!(flat_or_inverted > 100, "the cases exercise both answers");
    }

    /// Distinct edges and per-vertex valence by brute force (a hash set).
    fn edges_by_hashing(mesh: &TetMesh) -> (usize, Vec<u32>) {
        let mut set = HashSet::new();
        for t in mesh.tet_ids() {
            let v = mesh.tet(t);
            for [i, j] in TET_EDGES {
                set.insert(edge_key(v[i], v[j]));
            }
        }
        let mut valence = vec![0u32; mesh.n_points()];
        for [a, b] in &set {
            valence[*a as usize] += 1;
            valence[*b as usize] += 1;
        }
        (set.len(), valence)
    }

    /// Edges and valences of `data` by [`MeshStats`] and by brute force.
    fn assert_counts_match(data: &MeshData) -> MeshStats {
        let (mesh, _) = TetMesh::from_data(data).unwrap();
        mesh.check().unwrap();
        let s = MeshStats::compute(&mesh);
        let (edges, valence) = edges_by_hashing(&mesh);
        assert_eq!(s.edges, edges);
        assert_eq!(MeshStats::vertex_valence(&mesh), valence);
        assert_eq!(s.valence.max, valence.iter().copied().max().unwrap_or(0));
        assert_eq!(s.nodes, valence.iter().filter(|&&v| v > 0).count());
        s
    }

    /// The cubes of `cube_grid(n)` (6 tets each, in cube order) for which
    /// `keep(i, j, k)` holds.
    fn grid_cubes(n: usize, keep: impl Fn(usize, usize, usize) -> bool) -> MeshData {
        let full = cube_grid(n);
        let mut tets = Vec::new();
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    if keep(i, j, k) {
                        let c = 6 * (i + n * (j + n * k));
                        tets.extend_from_slice(&full.tets[c..c + 6]);
                    }
                }
            }
        }
        MeshData {
            points: full.points,
            tets,
            ..Default::default()
        }
    }

    #[test]
    fn edges_and_valence_match_a_hash_set_count() {
        // A grid, and the same grid with its tets numbered in a scrambled order.
        let grid = cube_grid(5);
        let mut scrambled = grid.clone();
        let n = scrambled.tets.len();
        scrambled.tets = (0..n).map(|i| grid.tets[(i * 37) % n]).collect();
        assert_ne!(n % 37, 0, "i -> 37 i mod n is a permutation");
        for data in [grid, scrambled] {
            assert_counts_match(&data);
        }
    }

    #[test]
    fn edges_where_the_domain_touches_itself_count_once() {
        // Two cubes of the grid sharing only an edge: the edge has two fans.
        // Each Kuhn cube has 19 edges (12 sides, 6 face diagonals, 1 body
        // diagonal); here the shared edge is counted once: 37.
        let data = grid_cubes(2, |i, j, k| k == 0 && (i == 0) == (j == 0));
        let s = assert_counts_match(&data);
        assert_eq!((s.tets, s.nodes, s.edges), (12, 14, 37));
    }

    #[test]
    fn two_tets_sharing_only_a_vertex() {
        // Counts by hand: 7 nodes, 12 edges; the shared vertex has valence 6.
        let data = MeshData {
            points: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
                [-1.0, 0.0, 0.0],
                [0.0, -1.0, 0.0],
                [0.0, 0.0, -1.0],
            ],
            tets: vec![[0, 1, 2, 3], [0, 4, 5, 6]],
            ..Default::default()
        };
        let (mesh, _) = TetMesh::from_data(&data).unwrap();
        let s = MeshStats::compute(&mesh);
        assert_eq!((s.nodes, s.edges, s.valence.max), (7, 12, 6));
        assert_eq!(MeshStats::vertex_valence(&mesh), [6, 3, 3, 3, 3, 3, 3]);
        assert_counts_match(&data);
    }

    #[test]
    fn two_cubes_sharing_only_a_vertex() {
        // Cubes (0,0,0) and (1,1,1) meet at the grid's centre, a corner on the
        // body diagonal of both: valence 7 in each cube, 14 in all; 2·19 edges.
        let data = grid_cubes(2, |i, j, k| i == j && j == k);
        let s = assert_counts_match(&data);
        assert_eq!((s.tets, s.nodes, s.edges, s.valence.max), (12, 15, 38, 14));
    }

    #[test]
    fn a_vertex_whose_link_is_an_annulus() {
        // The 2×2×2 block without two opposite octants: around the centre the
        // domain is a ball minus two cones, its link a sphere minus two disks
        // (Euler characteristic 0, not 1), and no edge is pinched.
        let data = grid_cubes(2, |i, j, k| !(i == j && j == k));
        assert_counts_match(&data);
    }

    #[test]
    fn random_sets_of_cubes_count_like_a_hash_set() {
        // Random subsets of a grid's cubes: pinched vertices and edges of every
        // kind, cavities and separate pieces.
        let mut rnd = xorshift(5);
        for density in [0.3, 0.5, 0.7, 0.9] {
            for _ in 0..6 {
                let n = 4;
                let keep: Vec<bool> = (0..n * n * n).map(|_| rnd() < density).collect();
                let data = grid_cubes(n, |i, j, k| keep[i + n * (j + n * k)]);
                if !data.tets.is_empty() {
                    assert_counts_match(&data);
                }
            }
        }
    }

    #[test]
    fn dead_slots_are_skipped() {
        let (mut mesh, _) = TetMesh::from_data(&cube_grid(3)).unwrap();
        // Remove the corner cube (tets 0..6) and the centre cube (13: tets
        // 78..84, leaving a cavity); the boundary stays manifold.
        for t in (0u32..6).chain(78..84) {
            for f in 0..4 {
                let h = mesh.adj(t)[f];
                if h != NO_ADJ {
                    mesh.bond(h, NO_ADJ);
                }
            }
            mesh.kill_tet(t);
        }
        // The surgery above leaves the vertex → tet table naming dead slots.
        mesh.rebuild_v2t();
        mesh.check().unwrap();
        let s = MeshStats::compute(&mesh);
        let (rebuilt, _) = TetMesh::from_data(&mesh.to_data()).unwrap();
        let r = MeshStats::compute(&rebuilt);
        assert_eq!(s.tets, 6 * 27 - 12);
        // 64 grid points minus the corner (0,0,0), which no tet uses any more.
        assert_eq!(s.nodes, 63);
        // Boundary: 12n² outer triangles, the corner cube's 3 outer squares
        // replaced by its 3 inner ones, plus the 6 squares of the cavity.
        assert_eq!(s.boundary_faces, 12 * 9 + 12);
        assert_eq!(
            (s.nodes, s.edges, s.tets, s.boundary_faces, s.interior_faces),
            (r.nodes, r.edges, r.tets, r.boundary_faces, r.interior_faces)
        );
        assert_eq!(s.edges, edges_by_hashing(&mesh).0);
        assert_eq!(s.histogram.counts, r.histogram.counts);
        assert_eq!(s.regions, r.regions);
    }

    #[test]
    fn result_does_not_depend_on_the_thread_count() {
        // Several chunks, so that the parallel merge matters.
        let mut data: MeshData = cube_grid(14);
        data.tet_regions = (0..data.tets.len() as i32).map(|t| t % 3).collect();
        let (mesh, _) = TetMesh::from_data(&data).unwrap();
        assert!(mesh.n_tets() > 2 * CHUNK);
        let with = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| MeshStats::compute(&mesh))
        };
        let one = with(1);
        for threads in [2, 3] {
            let s = with(threads);
            assert_eq!(s, one);
            assert_eq!(s.volume.to_bits(), one.volume.to_bits());
            assert_eq!(
                s.min_dihedral_deg.avg.to_bits(),
                one.min_dihedral_deg.avg.to_bits()
            );
        }
        assert_eq!(one.regions.len(), 3);
        assert_eq!(one.regions.values().sum::<usize>(), mesh.n_tets());
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn the_avx2_copy_gives_the_bits_of_the_plain_code() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return; // nothing to compare on this CPU
        }
        // Points moved off the grid at random, so that the angles vary.
        let mut data = cube_grid(8);
        let mut rnd = xorshift(17);
        for p in &mut data.points {
            for c in p.iter_mut() {
                *c += 0.02 * (rnd() - 0.5);
            }
        }
        let (mesh, _) = TetMesh::from_data(&data).unwrap();
        let histogram = Histogram::new(0.0, DEFAULT_HIST_MAX_DEG, DEFAULT_BINS);
        let thresholds = BinThresholds::new(&histogram);
        let sweep = Sweep {
            tets: &mesh.tets,
            adj: &mesh.adj,
            points: &mesh.points,
            region: &mesh.region,
            histogram: &histogram,
            thresholds: &thresholds,
        };
        let n = mesh.n_tet_slots();
        let mut counts = [vec![0u32; mesh.n_points()], vec![0u32; mesh.n_points()]];
        let plain = sweep.chunk_body(0, n, &mut counts[0]);
        // SAFETY: AVX2 is present (checked above).
        let avx2 = unsafe { sweep.chunk_avx2(0, n, &mut counts[1]) };
        assert_eq!(counts[0], counts[1]);
        let bits = |a: &Acc| {
            [
                a.max_max_cos,
                a.min_max_cos,
                a.min_min_cos,
                a.min_sum,
                a.max_sum,
                a.volume,
            ]
            .map(f64::to_bits)
        };
        assert_eq!(bits(&plain), bits(&avx2));
        assert_eq!(plain.hist, avx2.hist);
        assert_eq!(plain.boundary_faces, avx2.boundary_faces);
        assert_eq!((plain.tets, plain.ordinary), (n, n));
    }

    #[test]
    fn histogram_bins_clamp_and_truncate() {
        let h = Histogram::new(0.0, 71.0, 71);
        assert_eq!(h.bin(0.0), 0);
        assert_eq!(h.bin(0.999), 0);
        assert_eq!(h.bin(1.0), 1);
        assert_eq!(h.bin(45.0), 45);
        assert_eq!(h.bin(70.99), 70);
        assert_eq!(h.bin(71.0), 70);
        assert_eq!(h.bin(180.0), 70);
        assert_eq!(h.bin(-0.5), 0);
        assert_eq!(h.bin(-5.0), 0);
        assert_eq!(h.bin(f64::NAN), 0);
        assert_eq!(h.bin(f64::INFINITY), 70);
    }
}
