//! Mesh statistics: the rows of Table 1 of the seed paper plus boundary and
//! interior faces, maximum dihedral angle, inverted count, volume, regions and
//! the minimum-dihedral histogram. Computed in parallel in one sweep over the
//! tets; edges are counted without a global edge table (see [`edge_owner_mask`]).

use crate::geom::{orient3d, tet_quality, TET_EDGES};
use crate::mesh::{TetMesh, NO_ADJ};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

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
        let b = ((x - lo) / (hi - lo) * n as f64).floor();
        if b.is_nan() || b < 0.0 {
            0
        } else {
            (b as usize).min(n - 1)
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
}

/// Bit `e` is set when `t` is the smallest tet id around its local edge `e`, so
/// that each edge of the mesh is counted by exactly one tet. The ring walk stops
/// at the first smaller id, which keeps the average cost near half a ring.
#[inline]
pub fn edge_owner_mask(mesh: &TetMesh, t: u32) -> u8 {
    let mut mask = 0u8;
    for e in 0..6 {
        let mut owner = true;
        mesh.for_each_tet_around_edge(t, e, |u| {
            if u < t {
                owner = false;
            }
            owner
        });
        if owner {
            mask |= 1 << e;
        }
    }
    mask
}

#[derive(Clone)]
struct Acc {
    min_worst: f64,
    min_best: f64,
    min_sum: f64,
    max_worst: f64,
    max_sum: f64,
    inverted: usize,
    volume: f64,
    boundary: usize,
    edges: usize,
    tets: usize,
    hist: Vec<u64>,
}

impl Acc {
    fn new(bins: usize) -> Acc {
        Acc {
            min_worst: f64::INFINITY,
            min_best: f64::NEG_INFINITY,
            min_sum: 0.0,
            max_worst: f64::NEG_INFINITY,
            max_sum: 0.0,
            inverted: 0,
            volume: 0.0,
            boundary: 0,
            edges: 0,
            tets: 0,
            hist: vec![0; bins],
        }
    }

    fn merge(mut self, o: Acc) -> Acc {
        self.min_worst = self.min_worst.min(o.min_worst);
        self.min_best = self.min_best.max(o.min_best);
        self.min_sum += o.min_sum;
        self.max_worst = self.max_worst.max(o.max_worst);
        self.max_sum += o.max_sum;
        self.inverted += o.inverted;
        self.volume += o.volume;
        self.boundary += o.boundary;
        self.edges += o.edges;
        self.tets += o.tets;
        for (a, b) in self.hist.iter_mut().zip(o.hist) {
            *a += b;
        }
        self
    }
}

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
    /// Sums are accumulated in fixed-size chunks merged in order, so the result
    /// does not depend on the number of threads.
    pub fn compute_with(mesh: &TetMesh, mut histogram: Histogram) -> MeshStats {
        let bins = histogram.counts.len();
        let slots = mesh.n_tet_slots();
        const CHUNK: usize = 8192;
        let tets = mesh.tet_slots();
        let hist_ref = &histogram;
        let (acc, masks): (Vec<Acc>, Vec<Vec<u8>>) = (0..slots.div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let mut a = Acc::new(bins);
                let lo = c * CHUNK;
                let hi = (lo + CHUNK).min(slots);
                let mut masks = vec![0u8; hi - lo];
                for t in lo..hi {
                    if tets[t][0] == crate::mesh::DEAD {
                        continue;
                    }
                    let t32 = t as u32;
                    let p = mesh.tet_points(t32);
                    let q = tet_quality(&p);
                    a.tets += 1;
                    a.min_worst = a.min_worst.min(q.min_dihedral_deg);
                    a.min_best = a.min_best.max(q.min_dihedral_deg);
                    a.min_sum += q.min_dihedral_deg;
                    a.max_worst = a.max_worst.max(q.max_dihedral_deg);
                    a.max_sum += q.max_dihedral_deg;
                    a.volume += q.volume;
                    // The float volume decides nearly always; the exact predicate
                    // settles the near-flat cases.
                    if q.volume <= 1e-12 * (p[1] - p[0]).length_squared().powf(1.5)
                        && orient3d(p[0], p[1], p[2], p[3]) <= 0.0
                    {
                        a.inverted += 1;
                    }
                    a.hist[hist_ref.bin(q.min_dihedral_deg)] += 1;
                    a.boundary += mesh.adj(t32).iter().filter(|&&h| h == NO_ADJ).count();
                    let m = edge_owner_mask(mesh, t32);
                    a.edges += m.count_ones() as usize;
                    masks[t - lo] = m;
                }
                (a, masks)
            })
            .unzip();
        let acc = acc
            .into_iter()
            .reduce(Acc::merge)
            .unwrap_or_else(|| Acc::new(bins));

        // Valence: each owned edge adds one to both ends.
        let mut valence = vec![0u32; mesh.n_points()];
        for (c, m) in masks.iter().enumerate() {
            for (i, &mask) in m.iter().enumerate() {
                if mask == 0 {
                    continue;
                }
                let v = tets[c * CHUNK + i];
                for (e, ends) in TET_EDGES.iter().enumerate() {
                    if mask & (1 << e) != 0 {
                        valence[v[ends[0]] as usize] += 1;
                        valence[v[ends[1]] as usize] += 1;
                    }
                }
            }
        }
        let nodes = valence.iter().filter(|&&x| x > 0).count();
        let vmax = valence.iter().copied().max().unwrap_or(0);

        let mut regions: BTreeMap<i32, usize> = BTreeMap::new();
        for t in mesh.tet_ids() {
            *regions.entry(mesh.region(t)).or_default() += 1;
        }
        histogram.counts = acc.hist.clone();
        let n = acc.tets.max(1) as f64;
        MeshStats {
            nodes,
            edges: acc.edges,
            tets: acc.tets,
            boundary_faces: acc.boundary,
            interior_faces: (4 * acc.tets - acc.boundary) / 2,
            min_dihedral_deg: MinDihedral {
                worst: finite_or_zero(acc.min_worst),
                avg: acc.min_sum / n,
                best: finite_or_zero(acc.min_best),
            },
            max_dihedral_deg: MaxDihedral {
                worst: finite_or_zero(acc.max_worst),
                avg: acc.max_sum / n,
            },
            valence: Valence {
                avg: if nodes > 0 {
                    2.0 * acc.edges as f64 / nodes as f64
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
        }
    }

    /// Per-vertex valence (incident edges), for the `valence` point array.
    pub fn vertex_valence(mesh: &TetMesh) -> Vec<u32> {
        let mut valence = vec![0u32; mesh.n_points()];
        for t in mesh.tet_ids() {
            let m = edge_owner_mask(mesh, t);
            let v = mesh.tet(t);
            for (e, ends) in TET_EDGES.iter().enumerate() {
                if m & (1 << e) != 0 {
                    valence[v[ends[0]] as usize] += 1;
                    valence[v[ends[1]] as usize] += 1;
                }
            }
        }
        valence
    }
}

fn finite_or_zero(x: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        0.0
    }
}
