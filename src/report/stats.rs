//! Mesh statistics: the rows of Table 1 of the seed paper plus boundary and
//! interior faces, maximum dihedral angle, inverted count, volume, regions and
//! the minimum-dihedral histogram. Computed in parallel in one sweep over the
//! tets; edges are counted without a global edge table (see [`edge_owner_mask`]).
//!
//! Where the time goes (`benches/quality.rs`, a 1.05M-tet cube grid): the
//! angles of four tets at a time through the vector units, two `acos` per tet
//! (libm, kept so that the figures are the bits of
//! [`crate::geom::tet_quality`]), and the walks around the edges each tet may
//! own. Walks are avoided where a cheaper argument settles ownership (the
//! neighbour ids in `adj[t]`, the smallest tet at each vertex), and the
//! remaining ones are interleaved so that their memory accesses overlap.

use crate::geom::{orient3d, TET_EDGES, TET_EDGE_OPPOSITE};
use crate::mesh::{TetMesh, DEAD, NO_ADJ};
use glam::DVec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU32, Ordering};

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

/// Bit `e` is set when `t` is the smallest tet id around its local edge `e`, so
/// that each edge of the mesh is counted by exactly one tet. The ring walk stops
/// at the first smaller id, which keeps the average cost near half a ring.
///
/// Exact when every boundary edge lies in exactly two boundary faces (what
/// [`TetMesh::check`] requires): the ring of an edge is then one fan, which the
/// walk covers from `t` in both directions.
#[inline]
pub fn edge_owner_mask(mesh: &TetMesh, t: u32) -> u8 {
    owner_mask(&mesh.tets, &mesh.adj, t)
}

/// [`edge_owner_mask`] on the raw arrays, one edge after the other.
#[inline]
fn owner_mask(tets: &[[u32; 4]], adj: &[[u32; 4]], t: u32) -> u8 {
    let mut mask = 0u8;
    let candidates = owner_candidates(adj, t);
    for e in 0..6 {
        if candidates & (1 << e) != 0 {
            let mut w = EdgeWalk::new(tets, adj, t, e);
            let owned = loop {
                if let Some(owned) = w.step(tets, adj) {
                    break owned;
                }
            };
            mask |= (owned as u8) << e;
        }
    }
    mask
}

/// The local edges of `t` that it may own: those whose two faces in `t` both
/// lead to a larger id (or to the boundary). The neighbours across those faces
/// are the first tets of the ring in either direction and come with `adj[t]`,
/// so most edges that `t` does not own are settled here without a walk.
#[inline(always)]
fn owner_candidates(adj: &[[u32; 4]], t: u32) -> u8 {
    // Neighbour ids, the boundary counting as larger than everything.
    let a = adj[t as usize];
    let id = |h: u32| if h == NO_ADJ { u32::MAX } else { h >> 2 };
    let nb = [id(a[0]), id(a[1]), id(a[2]), id(a[3])];
    let mut mask = 0u8;
    for (e, &[k, l]) in TET_EDGE_OPPOSITE.iter().enumerate() {
        mask |= ((nb[k] > t && nb[l] > t) as u8) << e;
    }
    mask
}

/// The smallest live tet id incident to each vertex (`u32::MAX` for unused
/// points), in parallel; the minimum does not depend on the order.
///
/// Every tet around edge `ab` holds both `a` and `b`, so none is smaller than
/// `max(first[a], first[b])`: a tet with exactly that id owns the edge without
/// a walk. That settles about half of the owned edges.
fn first_tets(tets: &[[u32; 4]], n_points: usize) -> Vec<u32> {
    let first: Vec<AtomicU32> = (0..n_points).map(|_| AtomicU32::new(u32::MAX)).collect();
    (0..tets.len().div_ceil(CHUNK))
        .into_par_iter()
        .for_each(|c| {
            let lo = c * CHUNK;
            let hi = (lo + CHUNK).min(tets.len());
            for (t, v) in tets[lo..hi].iter().enumerate() {
                if v[0] == DEAD {
                    continue;
                }
                let t = (lo + t) as u32;
                for &x in v {
                    let f = &first[x as usize];
                    let mut cur = f.load(Ordering::Relaxed);
                    // Ascending t within a chunk: after the first visit this is
                    // one load and a comparison.
                    while t < cur {
                        match f.compare_exchange_weak(cur, t, Ordering::Relaxed, Ordering::Relaxed)
                        {
                            Ok(_) => break,
                            Err(now) => cur = now,
                        }
                    }
                }
            }
        });
    first.into_iter().map(AtomicU32::into_inner).collect()
}

/// One walk around local edge `e` of tet `t`, looking for a smaller id: the
/// walk of [`TetMesh::for_each_tet_around_edge`] (first one way from `t`, and
/// the other way if it reaches the boundary), as a resumable state so that
/// many walks can be interleaved and their memory accesses overlap.
#[derive(Clone, Copy)]
struct EdgeWalk {
    t: u32,
    va: u32,
    vb: u32,
    /// Adjacency row of the current tet, loaded together with its vertices so
    /// that the two loads of a step overlap.
    row: [u32; 4],
    exit: u8,
    e: u8,
    second_pass: bool,
}

impl EdgeWalk {
    #[inline(always)]
    fn new(tets: &[[u32; 4]], adj: &[[u32; 4]], t: u32, e: usize) -> EdgeWalk {
        let v = tets[t as usize];
        EdgeWalk {
            t,
            va: v[TET_EDGES[e][0]],
            vb: v[TET_EDGES[e][1]],
            row: adj[t as usize],
            exit: TET_EDGE_OPPOSITE[e][0] as u8,
            e: e as u8,
            second_pass: false,
        }
    }

    /// Crosses one face. `Some(true)`: no smaller id around the edge (`t` owns
    /// it); `Some(false)`: a smaller id was found; `None`: not finished.
    #[inline(always)]
    fn step(&mut self, tets: &[[u32; 4]], adj: &[[u32; 4]]) -> Option<bool> {
        let h = self.row[self.exit as usize];
        if h == NO_ADJ {
            if self.second_pass {
                return Some(true);
            }
            // Boundary: walk the other way from t.
            self.second_pass = true;
            self.row = adj[self.t as usize];
            self.exit = TET_EDGE_OPPOSITE[self.e as usize][1] as u8;
            return None;
        }
        let nt = h >> 2;
        if nt == self.t {
            return Some(true); // closed ring, every tet seen
        }
        if nt < self.t {
            return Some(false);
        }
        let nv = tets[nt as usize];
        self.row = adj[nt as usize];
        // Leave nt through the face opposite its vertex that is neither an end
        // of the edge nor opposite the face we came in by.
        let mut used = 1u32 << (h & 3);
        for (i, &x) in nv.iter().enumerate() {
            used |= ((x == self.va) as u32 | (x == self.vb) as u32) << i;
        }
        debug_assert_eq!(used.count_ones(), 3, "edge ring broken");
        self.exit = (!used & 0xF).trailing_zeros() as u8;
        None
    }
}

/// Walks in flight at once in [`resolve_owners`].
const WALKS_IN_FLIGHT: usize = 8;

/// Settles the candidate edges `(t, e)` (ascending `t` from `first`) and sets
/// bit `e` of `masks[t - first]` for each owned one. Up to
/// [`WALKS_IN_FLIGHT`] walks advance in turn, one face each, so that their
/// cache misses overlap instead of following one another.
fn resolve_owners(
    tets: &[[u32; 4]],
    adj: &[[u32; 4]],
    candidates: &[(u32, u8)],
    first: usize,
    masks: &mut [u8],
) {
    let mut pool = [EdgeWalk {
        t: 0,
        va: 0,
        vb: 0,
        row: [NO_ADJ; 4],
        exit: 0,
        e: 0,
        second_pass: false,
    }; WALKS_IN_FLIGHT];
    let mut next = 0;
    let mut live = 0;
    while live < WALKS_IN_FLIGHT && next < candidates.len() {
        let (t, e) = candidates[next];
        pool[live] = EdgeWalk::new(tets, adj, t, e as usize);
        live += 1;
        next += 1;
    }
    while live > 0 {
        let mut i = 0;
        while i < live {
            match pool[i].step(tets, adj) {
                None => i += 1,
                Some(owned) => {
                    let w = pool[i];
                    masks[w.t as usize - first] |= (owned as u8) << w.e;
                    if next < candidates.len() {
                        let (t, e) = candidates[next];
                        pool[i] = EdgeWalk::new(tets, adj, t, e as usize);
                        next += 1;
                        i += 1;
                    } else {
                        live -= 1;
                        pool[i] = pool[live];
                    }
                }
            }
        }
    }
}

/// Tets whose angles are computed side by side (see [`angle_extremes`]).
const LANES: usize = 4;

/// One `f64` per tet of a batch.
type Lanes = [f64; LANES];

/// A point or vector per tet of a batch, coordinate-major so that the
/// compiler can use vector instructions across the batch.
#[derive(Clone, Copy)]
struct LaneVec {
    x: Lanes,
    y: Lanes,
    z: Lanes,
}

#[inline(always)]
fn lanes(f: impl Fn(usize) -> f64) -> Lanes {
    [f(0), f(1), f(2), f(3)]
}

impl LaneVec {
    #[inline(always)]
    fn sub(self, o: LaneVec) -> LaneVec {
        LaneVec {
            x: lanes(|i| self.x[i] - o.x[i]),
            y: lanes(|i| self.y[i] - o.y[i]),
            z: lanes(|i| self.z[i] - o.z[i]),
        }
    }

    /// glam's `DVec3::cross`, operation for operation.
    #[inline(always)]
    fn cross(self, o: LaneVec) -> LaneVec {
        LaneVec {
            x: lanes(|i| self.y[i] * o.z[i] - o.y[i] * self.z[i]),
            y: lanes(|i| self.z[i] * o.x[i] - o.z[i] * self.x[i]),
            z: lanes(|i| self.x[i] * o.y[i] - o.x[i] * self.y[i]),
        }
    }

    /// glam's `DVec3::dot`, operation for operation.
    #[inline(always)]
    fn dot(self, o: LaneVec) -> Lanes {
        lanes(|i| (self.x[i] * o.x[i]) + (self.y[i] * o.y[i]) + (self.z[i] * o.z[i]))
    }
}

/// Smallest and largest dihedral angle (degrees), `D` = six times the signed
/// volume, and `|a|²|b|²|c|²` for the edge vectors `a, b, c` from corner 0 (see
/// [`is_inverted`]) of each tet of a batch (corner `j` of tet `i` in lane `i`
/// of `p[j]`).
///
/// The arithmetic is that of [`crate::geom::tet_quality`], operation for
/// operation and in the same order, so the results are the same bits; only the
/// sines, which the statistics do not need, are left out, and the tets of the
/// batch go side by side through the vector units.
#[inline(always)]
fn angle_extremes(p: &[LaneVec; 4]) -> (Lanes, Lanes, Lanes, Lanes) {
    let e1 = p[1].sub(p[0]);
    let e2 = p[2].sub(p[0]);
    let e3 = p[3].sub(p[0]);
    let n = [
        p[2].sub(p[1]).cross(p[3].sub(p[1])),
        e3.cross(e2),
        e1.cross(e3),
        e2.cross(e1),
    ];
    // DVec3::length_recip = 1 / sqrt(dot(v, v)).
    let recip_len = |v: LaneVec| {
        let l2 = v.dot(v);
        lanes(|i| 1.0 / l2[i].sqrt())
    };
    let inv = [
        recip_len(n[0]),
        recip_len(n[1]),
        recip_len(n[2]),
        recip_len(n[3]),
    ];
    let d = e1.dot(e2.cross(e3));
    let (l1, l2, l3) = (e1.dot(e1), e2.dot(e2), e3.dot(e3));
    let edge_product = lanes(|i| l1[i] * l2[i] * l3[i]);
    let mut max_cos = [f64::NEG_INFINITY; LANES];
    let mut min_cos = [f64::INFINITY; LANES];
    for &[k, l] in &TET_EDGE_OPPOSITE {
        let dot = n[k].dot(n[l]);
        for i in 0..LANES {
            let s = inv[k][i] * inv[l][i];
            let cos = -dot[i] * s;
            max_cos[i] = max_cos[i].max(cos);
            min_cos[i] = min_cos[i].min(cos);
        }
    }
    let mut lo = [0.0; LANES];
    let mut hi = [0.0; LANES];
    for i in 0..LANES {
        if !(0..4).all(|f| inv[f][i].is_finite()) {
            // A face of zero area: the convention of tet_quality.
            (lo[i], hi[i]) = (0.0, 180.0);
            continue;
        }
        lo[i] = max_cos[i].clamp(-1.0, 1.0).acos().to_degrees();
        hi[i] = min_cos[i].clamp(-1.0, 1.0).acos().to_degrees();
        if d[i] < 0.0 {
            (lo[i], hi[i]) = (-hi[i], -lo[i]);
        }
    }
    (lo, hi, d, edge_product)
}

/// Whether a tet with float determinant `d` and squared edge-vector lengths
/// product `edge_product` (from [`angle_extremes`]) is inverted or flat by the
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
    regions: RegionCounts,
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
            regions: RegionCounts::default(),
        }
    }

    /// Adds the angles, volume and inversion of up to [`LANES`] live tets, in
    /// the order given (so that the sums do not depend on the batching).
    #[inline(always)]
    fn add_tets(
        &mut self,
        tets: &[[u32; 4]],
        points: &[DVec3],
        batch: &[usize],
        histogram: &Histogram,
    ) {
        let corner = |j: usize| {
            let q = |i: usize| points[tets[batch[i.min(batch.len() - 1)]][j] as usize];
            LaneVec {
                x: lanes(|i| q(i).x),
                y: lanes(|i| q(i).y),
                z: lanes(|i| q(i).z),
            }
        };
        let p = [corner(0), corner(1), corner(2), corner(3)];
        let (lo, hi, d, edge_product) = angle_extremes(&p);
        for (i, &t) in batch.iter().enumerate() {
            self.tets += 1;
            self.min_worst = self.min_worst.min(lo[i]);
            self.min_best = self.min_best.max(lo[i]);
            self.min_sum += lo[i];
            self.max_worst = self.max_worst.max(hi[i]);
            self.max_sum += hi[i];
            self.volume += d[i] / 6.0;
            self.inverted += is_inverted(d[i], edge_product[i], || {
                tets[t].map(|k| points[k as usize])
            }) as usize;
            self.hist[histogram.bin(lo[i])] += 1;
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
        self.regions.0.extend(o.regions.0);
        self
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
    /// angles, volume, inversion, boundary faces, histogram, regions and which
    /// edges each tet owns ([`edge_owner_mask`]); the chunk sums are merged in
    /// chunk order, so the result does not depend on the number of threads.
    /// A second, sequential pass adds the owned edges to the vertex valences.
    pub fn compute_with(mesh: &TetMesh, mut histogram: Histogram) -> MeshStats {
        let bins = histogram.counts.len();
        let slots = mesh.n_tet_slots();
        let (tets, adj, points) = (&mesh.tets[..], &mesh.adj[..], &mesh.points[..]);
        let hist_ref = &histogram;
        let first = first_tets(tets, points.len());
        let first = &first[..];
        let (acc, masks): (Vec<Acc>, Vec<Vec<u8>>) = (0..slots.div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let mut a = Acc::new(bins);
                let lo = c * CHUNK;
                let hi = (lo + CHUNK).min(slots);
                let mut masks = vec![0u8; hi - lo];
                let mut candidates: Vec<(u32, u8)> = Vec::with_capacity(3 * (hi - lo));
                let mut batch = [0usize; LANES];
                let mut in_batch = 0;
                for t in lo..hi {
                    if tets[t][0] == DEAD {
                        continue;
                    }
                    a.boundary += adj[t].iter().filter(|&&h| h == NO_ADJ).count();
                    a.regions.add(mesh.region[t]);
                    let c = owner_candidates(adj, t as u32);
                    let v = tets[t];
                    for (e, &[i, j]) in TET_EDGES.iter().enumerate() {
                        if c & (1 << e) != 0 {
                            let f = first[v[i] as usize].max(first[v[j] as usize]);
                            if f == t as u32 {
                                masks[t - lo] |= 1 << e;
                            } else {
                                candidates.push((t as u32, e as u8));
                            }
                        }
                    }
                    batch[in_batch] = t;
                    in_batch += 1;
                    if in_batch == LANES {
                        a.add_tets(tets, points, &batch, hist_ref);
                        in_batch = 0;
                    }
                }
                if in_batch > 0 {
                    a.add_tets(tets, points, &batch[..in_batch], hist_ref);
                }
                resolve_owners(tets, adj, &candidates, lo, &mut masks);
                a.edges = masks.iter().map(|m| m.count_ones() as usize).sum();
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
        let mut edges = acc.edges;
        for ([a, b], extra) in pinched_boundary_edges(mesh) {
            edges -= extra as usize;
            valence[a as usize] -= extra;
            valence[b as usize] -= extra;
        }
        let nodes = valence.iter().filter(|&&x| x > 0).count();
        let vmax = valence.iter().copied().max().unwrap_or(0);

        let mut regions: BTreeMap<i32, usize> = BTreeMap::new();
        for (r, n) in acc.regions.0 {
            *regions.entry(r).or_default() += n;
        }
        histogram.counts = acc.hist;
        let n = acc.tets.max(1) as f64;
        MeshStats {
            nodes,
            edges,
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
        for ([a, b], extra) in pinched_boundary_edges(mesh) {
            valence[a as usize] -= extra;
            valence[b as usize] -= extra;
        }
        valence
    }
}

/// Boundary edges where the domain touches itself (more than two boundary
/// faces, i.e. several fans of tets around the edge), each with the number
/// of fans beyond the first. The ring walks of [`edge_owner_mask`] see one
/// fan at a time, so each fan elects an owner; the statistics subtract the
/// extra owners. Sorted, for determinism.
fn pinched_boundary_edges(mesh: &TetMesh) -> Vec<([u32; 2], u32)> {
    let mut count: std::collections::HashMap<[u32; 2], u32> = std::collections::HashMap::new();
    for t in mesh.tet_ids() {
        for f in 0..4 {
            if mesh.is_boundary_face(t, f) {
                let v = mesh.face_vertices(t, f);
                for i in 0..3 {
                    *count
                        .entry(crate::mesh::edge_key(v[i], v[(i + 1) % 3]))
                        .or_default() += 1;
                }
            }
        }
    }
    let mut out: Vec<([u32; 2], u32)> = count
        .into_iter()
        .filter(|&(_, c)| c > 2)
        .map(|(e, c)| (e, c / 2 - 1))
        .collect();
    out.sort_unstable();
    out
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
            let (lo, hi, d, _) = angle_extremes(&batch_of(group));
            for (i, p) in group.iter().enumerate() {
                let q = tet_quality(p);
                assert_eq!(lo[i].to_bits(), q.min_dihedral_deg.to_bits(), "{p:?}");
                assert_eq!(hi[i].to_bits(), q.max_dihedral_deg.to_bits(), "{p:?}");
                assert_eq!((d[i] / 6.0).to_bits(), q.volume.to_bits(), "{p:?}");
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
            let (_, _, d, edge_product) = angle_extremes(&batch_of(&padded));
            for (i, p) in group.iter().enumerate() {
                let exact = orient3d_sign(p[0], p[1], p[2], p[3]) != Orientation::Positive;
                flat_or_inverted += exact as usize;
                assert_eq!(is_inverted(d[i], edge_product[i], || *p), exact, "{p:?}");
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

    #[test]
    fn edges_and_valence_match_a_hash_set_count() {
        // A grid, and the same grid with its tets numbered in a scrambled order
        // (the owner rules depend on the numbering).
        let grid = cube_grid(5);
        let mut scrambled = grid.clone();
        let n = scrambled.tets.len();
        scrambled.tets = (0..n).map(|i| grid.tets[(i * 37) % n]).collect();
        assert_ne!(n % 37, 0, "i -> 37 i mod n is a permutation");
        for data in [grid, scrambled] {
            let (mesh, _) = TetMesh::from_data(&data).unwrap();
            let s = MeshStats::compute(&mesh);
            let (edges, valence) = edges_by_hashing(&mesh);
            assert_eq!(s.edges, edges);
            assert_eq!(MeshStats::vertex_valence(&mesh), valence);
            assert_eq!(s.valence.max, *valence.iter().max().unwrap());
            for t in mesh.tet_ids() {
                let by_walk = (0..6).fold(0u8, |m, e| {
                    let mut smallest = true;
                    mesh.for_each_tet_around_edge(t, e, |u| {
                        smallest &= u >= t;
                        smallest
                    });
                    m | (smallest as u8) << e
                });
                assert_eq!(edge_owner_mask(&mesh, t), by_walk);
            }
        }
    }

    #[test]
    fn edges_where_the_domain_touches_itself_count_once() {
        // Two cubes of the grid sharing only an edge: the edge has two fans.
        let full = cube_grid(2);
        let keep = |t: &[u32; 4]| {
            let c = t.iter().fold([0.0; 3], |acc, &v| {
                let p = full.points[v as usize];
                [acc[0] + p[0], acc[1] + p[1], acc[2] + p[2]]
            });
            // Cube (0,0,*) and cube (1,1,*): x and y both below or above 1/2.
            let (x, y) = (c[0] / 4.0, c[1] / 4.0);
            (x < 0.5) == (y < 0.5)
        };
        let data = MeshData {
            points: full.points.clone(),
            tets: full.tets.iter().copied().filter(keep).collect(),
            ..Default::default()
        };
        let (m, _) = TetMesh::from_data(&data).unwrap();
        m.check().unwrap();
        assert!(!pinched_boundary_edges(&m).is_empty());
        let (edges, valence) = edges_by_hashing(&m);
        let s = MeshStats::compute(&m);
        assert_eq!(s.edges, edges);
        assert_eq!(MeshStats::vertex_valence(&m), valence);
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
