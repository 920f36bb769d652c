//! The √3 stencils the core owns: the geometric part of a √3 step of a
//! triangle surface, Kobbelt's approximating scheme
//! (L. Kobbelt, "√3-Subdivision", SIGGRAPH 2000) and Labsik and Greiner's
//! interpolating scheme (U. Labsik, G. Greiner, "Interpolatory √3-Subdivision",
//! Eurographics 2000), with open-boundary and tagged-crease rules, and adaptive
//! refinement of selected faces.
//!
//! One step is a 1-to-3 split of every triangle at a new *face point* and a
//! flip of every old edge, so the new edges join face points of neighbouring
//! triangles; the geometric part moves the old vertices and places the face
//! points. The geometric part ([`sqrt3_positions`],
//! [`sqrt3_positions_trisecting`], [`TriTopology::positions`]) is the code
//! the tetrahedral √3 step uses on its boundary surface and the surface
//! schemes (crate `tetrefine-surface`) use for whole surfaces, so that one
//! implementation serves both; the topological part of a surface step lives
//! with the surface schemes.
//!
//! **Curves.** Open-boundary edges (one triangle), edges with more than two
//! triangles, and tagged crease edges are *curve edges*; they are never
//! flipped. Following Kobbelt §4, curve edges are kept in odd steps (the 1st,
//! 3rd, …) and trisected in even steps, so that after two steps every curve
//! edge is divided in three, as every other edge is by two plain √3 steps. A
//! triangle next to a trisected edge gets no face point: it is split into
//! three triangles joining the two trisection points to its opposite vertex.
//! A vertex with two curve edges is a *crease vertex* and moves only along
//! its curve, by a univariate ternary rule applied in the trisecting steps;
//! a vertex with one or more than two curve edges, or a tagged corner, is a
//! *corner* and never moves.
//!
//! **Rules.**
//! * [`Sqrt3Rule::Approximating`] (Kobbelt): face point at the centroid; a
//!   smooth vertex of valence n moves to (1 − α(n)) p + α(n)/n Σ pᵢ with
//!   α(n) = (4 − 2 cos(2π/n))/9 ([`kobbelt_alpha`]); along a curve, the
//!   ternary cubic B-spline rules (10, 16, 1)/27 for the trisection points and
//!   (4, 19, 4)/27 for the old vertex.
//! * [`Sqrt3Rule::Interpolating`] (Labsik–Greiner): old vertices stay; a face
//!   point whose three vertices are regular (valence 6) takes the 12-point
//!   stencil 32/81 (triangle), −1/81 (the three opposite tips), −2/81 (the
//!   six next ones); near an irregular vertex of valence K it takes that
//!   vertex's K-stencil ([`labsik_greiner_weights`], averaged over the
//!   irregular vertices of the triangle); triangles along a curve use the
//!   special boundary stencils of the paper; along a curve, the trisection
//!   points follow the interpolating four-point ternary rule
//!   (−5/81, 20/27, 10/27, −4/81). Where a stencil would cross a curve edge
//!   the face point falls back to the average of the K = 6 stencils of its
//!   smooth vertices, or to the centroid.
//! * [`Sqrt3Rule::Linear`]: old vertices stay, face points at centroids,
//!   trisection points at the thirds: pure topological refinement.
//!
//! Every stencil is an affine combination, so a planar mesh stays planar.
//!
//! **Adaptive refinement** (in the manner of Kobbelt §5 and of the √3 tet
//! paper §6): only selected triangles are split; an old edge is flipped only
//! where both of its triangles were split, and a curve edge is trisected only
//! where all its triangles were selected. Unselected triangles stay as they
//! are, and the mesh stays conforming because a 1-to-3 split leaves the edges
//! of the triangle intact. An old vertex moves only when all of its triangles
//! were split, so unrefined regions keep their geometry.

use crate::topo::edge_key;
use glam::DVec3;
use rayon::prelude::*;
use std::collections::{HashMap, HashSet};
use std::f64::consts::PI;

/// Which geometric rule a √3 step uses: for a surface, and for the boundary
/// of the tetrahedral step (`--boundary`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Sqrt3Rule {
    /// Kobbelt's approximating rule.
    Approximating,
    /// Labsik and Greiner's interpolating rule: old points stay (the
    /// default of the tetrahedral step).
    #[default]
    Interpolating,
    /// No smoothing: old points fixed, face points at centroids (on the old
    /// surface).
    Linear,
}

impl std::str::FromStr for Sqrt3Rule {
    type Err = String;
    fn from_str(s: &str) -> Result<Sqrt3Rule, String> {
        match s {
            "interpolating" => Ok(Sqrt3Rule::Interpolating),
            "approximating" => Ok(Sqrt3Rule::Approximating),
            "linear" => Ok(Sqrt3Rule::Linear),
            _ => Err(format!(
                "unknown boundary rule '{s}'; one of interpolating, approximating, linear"
            )),
        }
    }
}

/// The geometric result of one √3 step (see [`sqrt3_positions`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Sqrt3Positions {
    /// New position of every old point (same length and order as `points`).
    pub vertices: Vec<DVec3>,
    /// Position of the point inserted in each old triangle (same order as
    /// `tris`); for a triangle along a trisected edge it is the centroid and
    /// is not used by the scheme.
    pub faces: Vec<DVec3>,
}

/// The geometric result of a trisecting √3 step.
#[derive(Clone, Debug, PartialEq)]
pub struct Sqrt3Trisection {
    /// Vertex moves and face points, as for [`sqrt3_positions`].
    pub positions: Sqrt3Positions,
    /// For each trisected edge `[a, b]` (a < b): the two new points, the one
    /// nearer `a` first.
    pub edge_points: HashMap<[u32; 2], [DVec3; 2]>,
}

/// Kobbelt's smoothing weight α(n) = (4 − 2 cos(2π/n))/9 for a vertex of
/// valence n (0 for n = 0).
pub fn kobbelt_alpha(n: usize) -> f64 {
    if n == 0 {
        return 0.0;
    }
    (4.0 - 2.0 * (2.0 * PI / n as f64).cos()) / 9.0
}

/// Labsik and Greiner's face-point stencil around a vertex of valence `k`:
/// the weight of the centre vertex and the weights of its neighbours r₀ … r₍ₖ₋₁₎
/// in counter-clockwise order, where the triangle whose point is placed is
/// (centre, r₀, r₁). For k ≥ 4, with a = 2 cos(π/k)/3 and θⱼ = (2j − 1)π/k:
/// centre 1 − a², wⱼ = (a² + 2a cos θⱼ + 2a² cos 2θⱼ)/k; for k = 3 the paper's
/// special weights 8/9 and (4/27, 4/27, −5/27).
pub fn labsik_greiner_weights(k: usize) -> (f64, Vec<f64>) {
    match k {
        0..=2 => (1.0, vec![0.0; k]),
        3 => (8.0 / 9.0, vec![4.0 / 27.0, 4.0 / 27.0, -5.0 / 27.0]),
        _ => {
            let kf = k as f64;
            let a = 2.0 * (PI / kf).cos() / 3.0;
            let w = (0..k)
                .map(|j| {
                    let t = (2.0 * j as f64 - 1.0) * PI / kf;
                    (a * a + 2.0 * a * t.cos() + 2.0 * a * a * (2.0 * t).cos()) / kf
                })
                .collect();
            (1.0 - a * a, w)
        }
    }
}

/// No twin (a curve half-edge) and no vertex.
const NONE: u32 = u32::MAX;

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum VertexKind {
    Unused,
    Smooth,
    Crease,
    Corner,
}

/// Half-edge adjacency of a triangle list: half-edge 3t+i runs from
/// `tris[t][i]` to `tris[t][(i+1)%3]`; curve half-edges have no twin here.
pub struct TriTopology {
    twin: Vec<u32>,
    curve: Vec<bool>,
    kind: Vec<VertexKind>,
    /// The two curve neighbours of a crease vertex.
    curve_nbrs: Vec<[u32; 2]>,
    valence: Vec<u32>,
}

#[inline]
fn next(h: u32) -> u32 {
    if h % 3 == 2 {
        h - 2
    } else {
        h + 1
    }
}
#[inline]
fn prev(h: u32) -> u32 {
    if h % 3 == 0 {
        h + 2
    } else {
        h - 1
    }
}

impl TriTopology {
    /// The adjacency of `tris` over `np` points, with the tagged `creases`
    /// (sorted pairs) and `corners`; open-boundary and non-manifold edges
    /// are curves too.
    pub fn build(
        np: usize,
        tris: &[[u32; 3]],
        creases: &HashSet<[u32; 2]>,
        corners: &HashSet<u32>,
    ) -> TriTopology {
        let nh = tris.len() * 3;
        let org = |h: usize| tris[h / 3][h % 3];
        let dst = |h: usize| tris[h / 3][(h % 3 + 1) % 3];
        let mut keys: Vec<(u64, u32)> = (0..nh)
            .into_par_iter()
            .map(|h| {
                let e = edge_key(org(h), dst(h));
                (((e[0] as u64) << 32) | e[1] as u64, h as u32)
            })
            .collect();
        keys.par_sort_unstable();
        let mut twin = vec![NONE; nh];
        let mut curve = vec![false; nh];
        let mut kind = vec![VertexKind::Unused; np];
        let mut cdeg = vec![0u32; np];
        let mut curve_nbrs = vec![[NONE; 2]; np];
        let mut valence = vec![0u32; np];
        let mut i = 0;
        while i < keys.len() {
            let mut j = i + 1;
            while j < keys.len() && keys[j].0 == keys[i].0 {
                j += 1;
            }
            let e = [(keys[i].0 >> 32) as u32, keys[i].0 as u32];
            let (h0, h1) = (keys[i].1 as usize, keys.get(i + 1).map(|k| k.1 as usize));
            let manifold_pair = j - i == 2 && h1.is_some_and(|h1| org(h0) != org(h1));
            let is_curve = !manifold_pair || creases.contains(&e);
            if manifold_pair && !is_curve {
                let h1 = h1.unwrap_or(h0);
                twin[h0] = h1 as u32;
                twin[h1] = h0 as u32;
            }
            valence[e[0] as usize] += 1;
            valence[e[1] as usize] += 1;
            if is_curve {
                for k in &keys[i..j] {
                    curve[k.1 as usize] = true;
                }
                for (a, b) in [(e[0], e[1]), (e[1], e[0])] {
                    let d = cdeg[a as usize] as usize;
                    if d < 2 {
                        curve_nbrs[a as usize][d] = b;
                    }
                    cdeg[a as usize] += 1;
                }
            }
            i = j;
        }
        for t in tris {
            for &v in t {
                let v = v as usize;
                kind[v] = if corners.contains(&(v as u32)) {
                    VertexKind::Corner
                } else {
                    match cdeg[v] {
                        0 => VertexKind::Smooth,
                        2 => VertexKind::Crease,
                        _ => VertexKind::Corner,
                    }
                };
            }
        }
        TriTopology {
            twin,
            curve,
            kind,
            curve_nbrs,
            valence,
        }
    }

    /// Whether half-edge `h` (= 3t+i) lies on a curve (open boundary,
    /// non-manifold edge or tagged crease).
    #[inline]
    pub fn is_curve(&self, h: usize) -> bool {
        self.curve[h]
    }

    /// The opposite half-edge of `h`, `None` on a curve.
    #[inline]
    pub fn twin(&self, h: u32) -> Option<u32> {
        let o = self.twin[h as usize];
        (o != NONE).then_some(o)
    }

    /// The geometric part of a step on this topology: as
    /// [`sqrt3_positions_trisecting`], for callers that also need the
    /// adjacency (the surface step's re-triangulation).
    pub fn positions(
        &self,
        points: &[DVec3],
        tris: &[[u32; 3]],
        rule: Sqrt3Rule,
        trisected: &HashSet<[u32; 2]>,
    ) -> Sqrt3Trisection {
        positions_with(self, points, tris, rule, trisected)
    }
}

/// Geometric part of one √3 step on a triangle surface given as old points +
/// old triangles (indices into `points`; `points` may contain points that are
/// in no triangle: they are left alone). Returns the new position of every
/// old point (`vertices`, same length as `points`) and the position of the
/// new point inserted in each old triangle (`faces`, same order as `tris`).
/// Crease edges (sorted vertex pairs) and open-boundary edges are treated as
/// curves: a vertex on a crease moves only along it (Linear/Interpolating:
/// fixed), corners never move; Linear: old points fixed, face points at the
/// centroid.
///
/// This is the step in which curve edges are kept (an odd step in Kobbelt's
/// counting), so crease vertices stay where they are under every rule; the
/// step that trisects curve edges, and moves crease vertices along them, is
/// [`sqrt3_positions_trisecting`].
pub fn sqrt3_positions(
    points: &[DVec3],
    tris: &[[u32; 3]],
    rule: Sqrt3Rule,
    creases: &HashSet<[u32; 2]>,
    corners: &HashSet<u32>,
) -> Sqrt3Positions {
    sqrt3_positions_trisecting(points, tris, rule, creases, corners, &HashSet::new()).positions
}

/// Geometric part of a √3 step that trisects the curve edges in `trisected`
/// (sorted pairs; each must be a crease or open-boundary edge of `tris`;
/// others are ignored). As [`sqrt3_positions`], and in addition: a crease
/// vertex whose two curve edges are both trisected moves along its curve
/// (Approximating: (4, 19, 4)/27 of the previous, itself and the next curve
/// vertex; Interpolating and Linear: fixed), and every trisected edge gets
/// its two trisection points. Where a curve ends (at a corner) the missing
/// neighbour is replaced by the reflection of the other endpoint, so the end
/// segments are trisected as straight lines.
pub fn sqrt3_positions_trisecting(
    points: &[DVec3],
    tris: &[[u32; 3]],
    rule: Sqrt3Rule,
    creases: &HashSet<[u32; 2]>,
    corners: &HashSet<u32>,
    trisected: &HashSet<[u32; 2]>,
) -> Sqrt3Trisection {
    let topo = TriTopology::build(points.len(), tris, creases, corners);
    positions_with(&topo, points, tris, rule, trisected)
}

fn positions_with(
    topo: &TriTopology,
    points: &[DVec3],
    tris: &[[u32; 3]],
    rule: Sqrt3Rule,
    trisected: &HashSet<[u32; 2]>,
) -> Sqrt3Trisection {
    let np = points.len();
    // The curve edges that are really trisected.
    let mut tri_set: HashSet<[u32; 2]> = HashSet::new();
    if !trisected.is_empty() {
        for (h, &c) in topo.curve.iter().enumerate() {
            if c {
                let t = &tris[h / 3];
                let e = edge_key(t[h % 3], t[(h % 3 + 1) % 3]);
                if trisected.contains(&e) {
                    tri_set.insert(e);
                }
            }
        }
    }
    // Old vertices.
    let mut vertices = points.to_vec();
    if rule == Sqrt3Rule::Approximating {
        let mut sum = vec![DVec3::ZERO; np];
        let mut cnt = vec![0u32; np];
        for (t, tri) in tris.iter().enumerate() {
            for i in 0..3 {
                let _ = t;
                let v = tri[i] as usize;
                sum[v] += points[tri[(i + 1) % 3] as usize];
                cnt[v] += 1;
            }
        }
        vertices
            .par_iter_mut()
            .enumerate()
            .for_each(|(v, out)| match topo.kind[v] {
                VertexKind::Smooth => {
                    let n = cnt[v] as usize;
                    let a = kobbelt_alpha(n);
                    *out = points[v] * (1.0 - a) + sum[v] * (a / n as f64);
                }
                VertexKind::Crease => {
                    let [a, b] = topo.curve_nbrs[v];
                    if tri_set.contains(&edge_key(v as u32, a))
                        && tri_set.contains(&edge_key(v as u32, b))
                    {
                        *out = (points[a as usize] * 4.0
                            + points[v] * 19.0
                            + points[b as usize] * 4.0)
                            / 27.0;
                    }
                }
                _ => {}
            });
    }
    // Face points.
    let faces: Vec<DVec3> = (0..tris.len())
        .into_par_iter()
        .map(|t| {
            let tri = tris[t];
            let centroid =
                (points[tri[0] as usize] + points[tri[1] as usize] + points[tri[2] as usize]) / 3.0;
            if rule != Sqrt3Rule::Interpolating {
                return centroid;
            }
            let ncurve = (0..3).filter(|&i| topo.curve[3 * t + i]).count();
            if ncurve == 0 {
                interior_face_point(topo, points, tris, t).unwrap_or(centroid)
            } else {
                let touches_trisected = (0..3).any(|i| {
                    topo.curve[3 * t + i] && tri_set.contains(&edge_key(tri[i], tri[(i + 1) % 3]))
                });
                if touches_trisected {
                    centroid
                } else {
                    curve_face_point(topo, points, tris, t, ncurve).unwrap_or(centroid)
                }
            }
        })
        .collect();
    // Trisection points.
    let mut edge_points = HashMap::with_capacity(tri_set.len());
    for &e in &tri_set {
        let [a, b] = e;
        let (pa, pb) = (points[a as usize], points[b as usize]);
        let beyond = |v: u32, other: u32| -> DVec3 {
            let p = points[v as usize];
            if topo.kind[v as usize] == VertexKind::Crease {
                let [x, y] = topo.curve_nbrs[v as usize];
                let w = if x == other { y } else { x };
                points[w as usize]
            } else {
                p * 2.0 - points[other as usize]
            }
        };
        let pts = match rule {
            Sqrt3Rule::Linear => [(pa * 2.0 + pb) / 3.0, (pa + pb * 2.0) / 3.0],
            Sqrt3Rule::Approximating => {
                let (qa, qb) = (beyond(a, b), beyond(b, a));
                [
                    (qa + pa * 16.0 + pb * 10.0) / 27.0,
                    (pa * 10.0 + pb * 16.0 + qb) / 27.0,
                ]
            }
            Sqrt3Rule::Interpolating => {
                let (qa, qb) = (beyond(a, b), beyond(b, a));
                [
                    qa * (-5.0 / 81.0)
                        + pa * (20.0 / 27.0)
                        + pb * (10.0 / 27.0)
                        + qb * (-4.0 / 81.0),
                    qb * (-5.0 / 81.0)
                        + pb * (20.0 / 27.0)
                        + pa * (10.0 / 27.0)
                        + qa * (-4.0 / 81.0),
                ]
            }
        };
        edge_points.insert(e, pts);
    }
    Sqrt3Trisection {
        positions: Sqrt3Positions { vertices, faces },
        edge_points,
    }
}

/// Apex (vertex opposite the edge) of the triangle of half-edge h.
#[inline]
fn apex(tris: &[[u32; 3]], h: u32) -> u32 {
    tris[(h / 3) as usize][((h % 3 + 2) % 3) as usize]
}

/// Counter-clockwise neighbours of a smooth vertex starting with the next
/// vertex of triangle `h / 3` (h = half-edge leaving the vertex in that
/// triangle); `None` if the fan does not close.
fn ccw_ring(topo: &TriTopology, tris: &[[u32; 3]], h0: u32) -> Option<Vec<u32>> {
    let mut ring = Vec::with_capacity(8);
    let mut h = h0;
    loop {
        ring.push(tris[(h / 3) as usize][((h % 3 + 1) % 3) as usize]);
        let t = topo.twin[prev(h) as usize];
        if t == NONE || ring.len() > 64 {
            return None;
        }
        if t == h0 {
            return Some(ring);
        }
        h = t;
    }
}

/// The Labsik–Greiner stencil of the (smooth) vertex at corner `i` of
/// triangle `t`.
fn vertex_stencil(
    topo: &TriTopology,
    points: &[DVec3],
    tris: &[[u32; 3]],
    t: usize,
    i: usize,
) -> Option<DVec3> {
    let v = tris[t][i];
    let ring = ccw_ring(topo, tris, (3 * t + i) as u32)?;
    let (wc, w) = labsik_greiner_weights(ring.len());
    let mut p = points[v as usize] * wc;
    for (j, &r) in ring.iter().enumerate() {
        p += points[r as usize] * w[j];
    }
    Some(p)
}

/// Face point of an interpolating step for a triangle without curve edges.
fn interior_face_point(
    topo: &TriTopology,
    points: &[DVec3],
    tris: &[[u32; 3]],
    t: usize,
) -> Option<DVec3> {
    let tri = tris[t];
    let irregular: Vec<usize> = (0..3)
        .filter(|&i| {
            let v = tri[i] as usize;
            topo.kind[v] == VertexKind::Smooth && topo.valence[v] != 6
        })
        .collect();
    if !irregular.is_empty() {
        let mut p = DVec3::ZERO;
        for &i in &irregular {
            p += vertex_stencil(topo, points, tris, t, i)?;
        }
        return Some(p / irregular.len() as f64);
    }
    if let Some(p) = twelve_point(topo, points, tris, t) {
        return Some(p);
    }
    // Near a curve: the K = 6 stencils of the smooth vertices (their fans
    // are closed, as no curve edge ends at a smooth vertex).
    let mut p = DVec3::ZERO;
    let mut n = 0;
    for (i, &v) in tri.iter().enumerate() {
        if topo.kind[v as usize] == VertexKind::Smooth {
            p += vertex_stencil(topo, points, tris, t, i)?;
            n += 1;
        }
    }
    if n == 0 {
        None
    } else {
        Some(p / n as f64)
    }
}

/// The regular 12-point stencil (32/81, −1/81, −2/81), if no curve edge is in
/// the way.
fn twelve_point(
    topo: &TriTopology,
    points: &[DVec3],
    tris: &[[u32; 3]],
    t: usize,
) -> Option<DVec3> {
    let mut p = DVec3::ZERO;
    for i in 0..3 {
        let h = (3 * t + i) as u32;
        p += points[tris[t][i] as usize] * (32.0 / 81.0);
        let o = topo.twin[h as usize];
        if o == NONE {
            return None;
        }
        p -= points[apex(tris, o) as usize] * (1.0 / 81.0);
        for g in [next(o), prev(o)] {
            let og = topo.twin[g as usize];
            if og == NONE {
                return None;
            }
            p -= points[apex(tris, og) as usize] * (2.0 / 81.0);
        }
    }
    Some(p)
}

/// Face point of an interpolating step for a triangle with `ncurve` kept
/// curve edges (Labsik–Greiner's boundary stencils).
fn curve_face_point(
    topo: &TriTopology,
    points: &[DVec3],
    tris: &[[u32; 3]],
    t: usize,
    ncurve: usize,
) -> Option<DVec3> {
    let tri = tris[t];
    let pt = |v: u32| points[v as usize];
    match ncurve {
        1 => {
            let i = (0..3).find(|&i| topo.curve[3 * t + i])?;
            let (u, w, o) = (tri[i], tri[(i + 1) % 3], tri[(i + 2) % 3]);
            let ok = o as usize;
            if topo.kind[ok] == VertexKind::Smooth && topo.valence[ok] != 6 {
                return vertex_stencil(topo, points, tris, t, (i + 2) % 3);
            }
            let h = (3 * t + i) as u32;
            let (t1, t2) = (topo.twin[next(h) as usize], topo.twin[prev(h) as usize]);
            if t1 == NONE || t2 == NONE {
                return None;
            }
            Some(
                pt(o) * 0.5 + (pt(u) + pt(w)) * (1.0 / 3.0)
                    - (pt(apex(tris, t1)) + pt(apex(tris, t2))) * (1.0 / 12.0),
            )
        }
        2 => {
            // The interior edge is the one that is not a curve.
            let i = (0..3).find(|&i| !topo.curve[3 * t + i])?;
            let h = (3 * t + i) as u32;
            let (x, y, s) = (tri[i], tri[(i + 1) % 3], tri[(i + 2) % 3]);
            let o = topo.twin[h as usize];
            if o == NONE {
                return None;
            }
            Some(
                pt(s) * (7.0 / 24.0) + (pt(x) + pt(y)) * (3.0 / 8.0)
                    - pt(apex(tris, o)) * (1.0 / 24.0),
            )
        }
        _ => None,
    }
}
