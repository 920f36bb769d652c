//! Validation: points, facets, their planes and pieces, the edges they
//! share, and the intersection checks.

use super::geometry::*;
use super::{Facet, Plc, PlcError, PlcVolume};
use glam::DVec3;
use std::collections::HashMap;

pub(super) struct Analysis {
    /// Points, moved so that the bounding box of the surface is centred at
    /// the origin (better conditioned volume sums).
    pub(super) pts: Vec<DVec3>,
    /// The centre that was subtracted.
    pub(super) center: DVec3,
    pub(super) facets: Vec<FacetGeom>,
    pub(super) pieces: Vec<Piece>,
    /// Distance tolerance for degenerate ray hits.
    pub(super) tol: f64,
}

/// The power of two that brings the largest finite coordinate of `plc`
/// near 1, when it is far from 1 (beyond 2^±400): lengths, areas and
/// volumes of a surface at 1e±300 overflow or underflow in doubles, and the
/// exact predicates assume neither. Scaling by a power of two is exact.
fn scale_of(plc: &Plc) -> Option<f64> {
    let m = plc
        .points
        .iter()
        .flatten()
        .map(|c| c.abs())
        .filter(|c| c.is_finite() && *c > 0.0)
        .fold(0.0f64, f64::max);
    if m == 0.0 {
        return None;
    }
    let e = m.log2().floor() as i32;
    (e.abs() > 400).then(|| 2f64.powi(-e))
}

/// `plc` with every coordinate (points, holes, seeds) times `s` and the
/// regions' volume bounds times `s³`.
fn scaled(plc: &Plc, s: f64) -> Plc {
    let sc = |p: &[f64; 3]| p.map(|c| c * s);
    Plc {
        points: plc.points.iter().map(sc).collect(),
        facets: plc
            .facets
            .iter()
            .map(|f| Facet {
                polygons: f.polygons.clone(),
                holes: f.holes.iter().map(sc).collect(),
                marker: f.marker,
            })
            .collect(),
        holes: plc.holes.iter().map(sc).collect(),
        regions: plc
            .regions
            .iter()
            .map(|r| super::Region {
                point: sc(&r.point),
                attribute: r.attribute,
                max_volume: r.max_volume.map(|v| v * s * s * s),
            })
            .collect(),
        seed_lines: plc.seed_lines.clone(),
    }
}

impl Analysis {
    pub(super) fn run(plc: &Plc) -> Result<PlcVolume, PlcError> {
        Analysis::run_scaled(plc).map_err(|e| e.with_seed_lines(&plc.seed_lines))
    }

    fn run_scaled(plc: &Plc) -> Result<PlcVolume, PlcError> {
        if let Some(s) = scale_of(plc) {
            // Checked in exactly scaled coordinates; volumes scaled back (a
            // volume beyond the doubles' range becomes infinite).
            let mut v = Analysis::run_unscaled(&scaled(plc, s), plc)?;
            v.enclosed = v.enclosed / s / s / s;
            v.planarity_slack = v.planarity_slack / s / s / s;
            return Ok(v);
        }
        Analysis::run_unscaled(plc, plc)
    }

    /// The analysis of `plc`, which is `raw` or `raw` scaled by a power of
    /// two; seeds are located exactly in `raw`'s own coordinates.
    fn run_unscaled(plc: &Plc, raw: &Plc) -> Result<PlcVolume, PlcError> {
        let (pts, center, canon, diag) = check_points(plc)?;
        let tol = 1e-9 * diag;
        let mut a = Analysis {
            pts,
            center,
            facets: Vec::with_capacity(plc.facets.len()),
            pieces: Vec::new(),
            tol,
        };
        let mut segments: Vec<(usize, [u32; 2])> = Vec::new();
        for (fi, f) in plc.facets.iter().enumerate() {
            let (geom, segs) = a.facet_geometry(fi, f, &canon, diag)?;
            a.facets.push(geom);
            segments.extend(segs.into_iter().map(|s| (fi, s)));
        }
        let hole_loops = a.facet_holes(plc)?;
        a.build_pieces(&hole_loops)?;
        let incidences = a.edge_incidences(&segments, &hole_loops)?;
        a.check_intersections(&incidences)?;
        let mut sides = UnionFind::new(2 * a.pieces.len());
        a.glue_sides(&incidences, &mut sides)?;
        a.cells(raw, &mut sides, diag)
    }

    // ----- points --------------------------------------------------------------

    pub(super) fn point(&self, v: u32) -> DVec3 {
        self.pts[v as usize]
    }

    // ----- facets --------------------------------------------------------------

    /// Checks one facet and computes its plane, loops and segments.
    pub(super) fn facet_geometry(
        &self,
        fi: usize,
        f: &Facet,
        canon: &[u32],
        diag: f64,
    ) -> Result<(FacetGeom, Vec<[u32; 2]>), PlcError> {
        let bad = |reason: String| PlcError::BadFacet {
            facet: fi + 1,
            reason,
        };
        if f.polygons.is_empty() {
            return Err(bad("it has no polygon".into()));
        }
        let mut all: Vec<u32> = f
            .polygons
            .iter()
            .flatten()
            .map(|&v| canon[v as usize])
            .collect();
        all.sort_unstable();
        all.dedup();
        if all.len() < 3 {
            return Err(bad(format!(
                "it has {} distinct points; a facet needs at least 3",
                all.len()
            )));
        }
        // Loops and segments, in canonical ids.
        let mut raw_loops: Vec<(usize, Vec<u32>)> = Vec::new();
        let mut segs = Vec::new();
        for (pi, poly) in f.polygons.iter().enumerate() {
            let verts: Vec<u32> = poly.iter().map(|&v| canon[v as usize]).collect();
            let mut sorted = verts.clone();
            sorted.sort_unstable();
            if sorted.windows(2).any(|w| w[0] == w[1]) {
                return Err(bad(format!(
                    "polygon {} repeats a point (or two of its points coincide)",
                    pi + 1
                )));
            }
            match verts.len() {
                0 => return Err(bad(format!("polygon {} is empty", pi + 1))),
                1 => {}
                2 => segs.push([verts[0], verts[1]]),
                _ => raw_loops.push((pi, verts)),
            }
        }
        if raw_loops.is_empty() {
            return Err(bad(
                "it has no polygon of three or more points, so it bounds nothing".into(),
            ));
        }
        // The plane: normal of the largest loop, through the mean vertex.
        let normals: Vec<DVec3> = raw_loops
            .iter()
            .map(|(_, v)| newell(v.iter().map(|&i| self.point(i))))
            .collect();
        let big = (0..normals.len())
            .max_by(|&i, &j| normals[i].length().total_cmp(&normals[j].length()))
            .unwrap_or(0);
        let min_area2 = 1e-24 * diag * diag;
        for (k, nrm) in normals.iter().enumerate() {
            if nrm.length() <= min_area2 {
                return Err(bad(format!(
                    "polygon {} has zero area (its points are collinear)",
                    raw_loops[k].0 + 1
                )));
            }
        }
        let n = normals[big].normalize();
        let o = all.iter().map(|&v| self.point(v)).sum::<DVec3>() / all.len() as f64;
        let deviation = all
            .iter()
            .map(|&v| n.dot(self.point(v) - o).abs())
            .fold(0.0, f64::max);
        if deviation > 1e-6 * diag {
            return Err(bad(format!(
                "it is not planar: a point lies {deviation:.3e} from its plane"
            )));
        }
        let drop = (0..3)
            .max_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs()))
            .unwrap_or(2);
        let loops = raw_loops
            .into_iter()
            .zip(&normals)
            .map(|((_, verts), nrm)| Loop {
                uv: verts
                    .iter()
                    .map(|&v| project(self.point(v), drop))
                    .collect(),
                verts,
                area: 0.5 * nrm.length(),
                ccw: nrm.dot(n) > 0.0,
            })
            .collect();
        Ok((
            FacetGeom {
                n,
                o,
                drop,
                deviation,
                loops,
            },
            segs,
        ))
    }

    /// For each facet, which of its loops hole points empty.
    pub(super) fn facet_holes(&self, plc: &Plc) -> Result<Vec<Vec<bool>>, PlcError> {
        let center = self.center;
        let mut out = Vec::with_capacity(self.facets.len());
        for (fi, (f, g)) in plc.facets.iter().zip(&self.facets).enumerate() {
            let mut hole = vec![false; g.loops.len()];
            for (hi, h) in f.holes.iter().enumerate() {
                if !h.iter().all(|c| c.is_finite()) {
                    return Err(PlcError::NonFiniteSeed {
                        what: "facet hole",
                        index: hi + 1,
                        coords: *h,
                    });
                }
                let p = project(DVec3::from_array(*h) - center, g.drop);
                match innermost_loop(g, p) {
                    Some(l) => hole[l] = true,
                    None => {
                        return Err(PlcError::BadFacet {
                            facet: fi + 1,
                            reason: format!("hole {} lies outside all its polygons", hi + 1),
                        })
                    }
                }
            }
            out.push(hole);
        }
        Ok(out)
    }
}

/// Checks coordinates, seeds, extent and coplanarity. Returns the points
/// centred on the bounding box of the surface, the centre, the map to
/// canonical (first coincident) points and the bounding box diagonal.
#[allow(clippy::type_complexity)] // a private helper's several results
fn check_points(plc: &Plc) -> Result<(Vec<DVec3>, DVec3, Vec<u32>, f64), PlcError> {
    if let Some((i, p)) = plc
        .points
        .iter()
        .enumerate()
        .find(|(_, p)| !p.iter().all(|c| c.is_finite()))
    {
        return Err(PlcError::NonFinite {
            point: i + 1,
            coords: *p,
        });
    }
    for (what, list) in [("hole", &plc.holes)] {
        if let Some((i, h)) = list
            .iter()
            .enumerate()
            .find(|(_, h)| !h.iter().all(|c| c.is_finite()))
        {
            return Err(PlcError::NonFiniteSeed {
                what,
                index: i + 1,
                coords: *h,
            });
        }
    }
    for (i, r) in plc.regions.iter().enumerate() {
        if !r.point.iter().all(|c| c.is_finite()) {
            return Err(PlcError::NonFiniteSeed {
                what: "region",
                index: i + 1,
                coords: r.point,
            });
        }
        if let Some(v) = r.max_volume {
            if !(v.is_finite() && v > 0.0) {
                return Err(PlcError::BadMaxVolume {
                    region: i + 1,
                    value: v,
                });
            }
        }
    }
    if plc.facets.is_empty() {
        return Err(PlcError::NoFacets);
    }
    let np = plc.points.len();
    for (fi, f) in plc.facets.iter().enumerate() {
        for poly in &f.polygons {
            if let Some(&v) = poly.iter().find(|&&v| v as usize >= np) {
                return Err(PlcError::IndexOutOfRange {
                    facet: fi + 1,
                    index: v as u64 + 1,
                    n_points: np,
                });
            }
        }
    }
    let canon = plc.coincident_point_map();
    let mut used = vec![false; np];
    for f in &plc.facets {
        for &v in f.polygons.iter().flatten() {
            used[canon[v as usize] as usize] = true;
        }
    }
    let surface: Vec<DVec3> = (0..np)
        .filter(|&i| used[i])
        .map(|i| DVec3::from_array(plc.points[i]))
        .collect();
    let lo = surface.iter().fold(DVec3::INFINITY, |a, &p| a.min(p));
    let hi = surface.iter().fold(DVec3::NEG_INFINITY, |a, &p| a.max(p));
    for (axis, name) in ['x', 'y', 'z'].into_iter().enumerate() {
        if hi[axis] <= lo[axis] {
            return Err(PlcError::Flat { axis: name });
        }
    }
    if !spans_volume(&surface) {
        return Err(PlcError::Coplanar);
    }
    let center = 0.5 * (lo + hi);
    let diag = (hi - lo).length();
    let pts = plc
        .points
        .iter()
        .map(|p| DVec3::from_array(*p) - center)
        .collect();
    Ok((pts, center, canon, diag))
}

/// Whether some four of the points span a volume, with exact predicates.
fn spans_volume(p: &[DVec3]) -> bool {
    use crate::geom::{orient3d_sign, Orientation};
    let Some(&a) = p.first() else { return false };
    let Some(&b) = p.iter().find(|&&q| q != a) else {
        return false;
    };
    let collinear = |c: DVec3| {
        let o2 = |x: [f64; 2], y: [f64; 2], z: [f64; 2]| {
            robust::orient2d(
                robust::Coord { x: x[0], y: x[1] },
                robust::Coord { x: y[0], y: y[1] },
                robust::Coord { x: z[0], y: z[1] },
            ) == 0.0
        };
        (0..3).all(|d| o2(project(a, d), project(b, d), project(c, d)))
    };
    let Some(&c) = p.iter().find(|&&q| !collinear(q)) else {
        return false;
    };
    p.iter()
        .any(|&d| orient3d_sign(a, b, c, d) != Orientation::Zero)
}

impl Analysis {
    /// Splits every facet into pieces: each loop that no hole empties, minus
    /// the loops directly inside it.
    #[allow(clippy::needless_range_loop)] // loops index several parallel arrays
    pub(super) fn build_pieces(&mut self, hole_loops: &[Vec<bool>]) -> Result<(), PlcError> {
        let mut seen: HashMap<(Vec<u32>, Vec<Vec<u32>>), usize> = HashMap::new();
        for (fi, g) in self.facets.iter().enumerate() {
            let bad = |reason: String| PlcError::BadFacet {
                facet: fi + 1,
                reason,
            };
            let nl = g.loops.len();
            // The parent of a loop is the smallest larger loop around it.
            let mut parent: Vec<Option<usize>> = vec![None; nl];
            if nl > 1 {
                for b in 0..nl {
                    let lb = &g.loops[b];
                    let ip = interior_point(&[&lb.uv]).ok_or_else(|| {
                        bad("a polygon has no interior (self-overlapping?)".into())
                    })?;
                    for a in 0..nl {
                        if a == b {
                            continue;
                        }
                        let la = &g.loops[a];
                        if la.area == lb.area && sorted(&la.verts) == sorted(&lb.verts) {
                            return Err(bad("two of its polygons coincide".into()));
                        }
                        if la.area > lb.area
                            && inside_loop(&la.uv, ip)
                            && parent[b].is_none_or(|p| g.loops[p].area > la.area)
                        {
                            parent[b] = Some(a);
                        }
                    }
                }
            }
            for l in 0..nl {
                if hole_loops[fi][l] {
                    continue;
                }
                let inner: Vec<usize> = (0..nl).filter(|&c| parent[c] == Some(l)).collect();
                let outer = &g.loops[l];
                let area = outer.area - inner.iter().map(|&c| g.loops[c].area).sum::<f64>();
                if area <= 1e-12 * outer.area {
                    return Err(bad(
                        "the polygons inside one of its polygons cover it completely".into(),
                    ));
                }
                let mut inner_keys: Vec<Vec<u32>> =
                    inner.iter().map(|&c| sorted(&g.loops[c].verts)).collect();
                inner_keys.sort();
                let key = (sorted(&outer.verts), inner_keys);
                if let Some(&other) = seen.get(&key) {
                    return Err(if other == fi {
                        bad("two of its polygons coincide".into())
                    } else {
                        PlcError::DuplicateFacet {
                            facet: fi + 1,
                            other: other + 1,
                        }
                    });
                }
                seen.insert(key, fi);
                let lo = outer
                    .verts
                    .iter()
                    .fold(DVec3::INFINITY, |a, &v| a.min(self.pts[v as usize]));
                let hi = outer
                    .verts
                    .iter()
                    .fold(DVec3::NEG_INFINITY, |a, &v| a.max(self.pts[v as usize]));
                self.pieces.push(Piece {
                    facet: fi,
                    outer: l,
                    inner,
                    area,
                    lo,
                    hi,
                });
            }
        }
        Ok(())
    }

    /// The loops of piece `k` (outer first) in 2-D.
    pub(super) fn piece_loops(&self, k: usize) -> Vec<&[[f64; 2]]> {
        let p = &self.pieces[k];
        let g = &self.facets[p.facet];
        std::iter::once(p.outer)
            .chain(p.inner.iter().copied())
            .map(|l| g.loops[l].uv.as_slice())
            .collect()
    }

    /// For every edge, the pieces that leave it and in which direction.
    /// Checks that the surface is closed.
    pub(super) fn edge_incidences(
        &self,
        segments: &[(usize, [u32; 2])],
        hole_loops: &[Vec<bool>],
    ) -> Result<EdgeIncidences, PlcError> {
        let mut edges: HashMap<[u32; 2], Vec<Incidence>> = HashMap::new();
        let mut piece_of: HashMap<(usize, usize), usize> = HashMap::new();
        for (k, p) in self.pieces.iter().enumerate() {
            piece_of.insert((p.facet, p.outer), k);
            let g = &self.facets[p.facet];
            for (is_outer, l) in
                std::iter::once((true, p.outer)).chain(p.inner.iter().map(|&l| (false, l)))
            {
                let lp = &g.loops[l];
                // The piece lies left of a counter-clockwise outer loop and
                // right of a counter-clockwise inner loop.
                let sign = if lp.ccw == is_outer { 1.0 } else { -1.0 };
                let m = lp.verts.len();
                for i in 0..m {
                    let (a, b) = (lp.verts[i], lp.verts[(i + 1) % m]);
                    let d = sign * g.n.cross(self.point(b) - self.point(a));
                    edges.entry(edge(a, b)).or_default().push(Incidence {
                        piece: k as u32,
                        d,
                        from_segment: false,
                    });
                }
            }
        }
        // Segments embedded in a piece: the piece leaves them on both sides.
        for &(fi, [a, b]) in segments {
            let g = &self.facets[fi];
            let mid = project(0.5 * (self.point(a) + self.point(b)), g.drop);
            if g.loops
                .iter()
                .any(|l| loop_distance(&l.uv, mid) <= self.tol)
            {
                continue; // an edge of a loop already
            }
            let Some(l) = innermost_loop(g, mid) else {
                continue; // dangling outside the facet: bounds nothing
            };
            if hole_loops[fi][l] {
                continue;
            }
            let k = piece_of[&(fi, l)];
            let d = g.n.cross(self.point(b) - self.point(a));
            for s in [1.0, -1.0] {
                edges.entry(edge(a, b)).or_default().push(Incidence {
                    piece: k as u32,
                    d: s * d,
                    from_segment: true,
                });
            }
        }
        let mut list: Vec<([u32; 2], Vec<Incidence>)> = edges.into_iter().collect();
        list.sort_unstable_by_key(|(e, _)| *e);
        for (e, incs) in list.iter_mut() {
            // A piece whose outer and inner loops (or two inner loops) share
            // an edge does not touch it: the two loop sides cancel.
            let mut count: HashMap<u32, usize> = HashMap::new();
            for i in incs.iter().filter(|i| !i.from_segment) {
                *count.entry(i.piece).or_default() += 1;
            }
            if let Some((&k, _)) = count.iter().find(|(_, &c)| c > 2) {
                return Err(PlcError::BadFacet {
                    facet: self.pieces[k as usize].facet + 1,
                    reason: format!(
                        "edge ({}, {}) appears more than twice among its polygons",
                        e[0] + 1,
                        e[1] + 1
                    ),
                });
            }
            incs.retain(|i| i.from_segment || count[&i.piece] == 1);
            if incs.len() == 1 {
                return Err(PlcError::Open {
                    facet: self.pieces[incs[0].piece as usize].facet + 1,
                    a: e[0] as u64 + 1,
                    b: e[1] as u64 + 1,
                });
            }
        }
        list.retain(|(_, incs)| !incs.is_empty());
        Ok(list)
    }

    /// Whether the 3-D point `q` (in the plane of piece `k`) lies strictly
    /// inside the piece, farther than the tolerance from its boundary.
    pub(super) fn strictly_inside(&self, k: usize, q: DVec3) -> bool {
        let g = &self.facets[self.pieces[k].facet];
        let q = project(q, g.drop);
        let loops = self.piece_loops(k);
        loops.iter().all(|l| loop_distance(l, q) > self.tol)
            && loops.iter().filter(|l| inside_loop(l, q)).count() % 2 == 1
    }

    /// Finds an edge of one facet that pierces another facet's interior, or
    /// ends inside it (TetGen reports such input as self-intersecting).
    /// Candidate pairs come from a uniform grid over the pieces' boxes.
    /// Facets that overlap within one plane are found by `glue_sides` only
    /// where they share an edge.
    pub(super) fn check_intersections(
        &self,
        edges: &[([u32; 2], Vec<Incidence>)],
    ) -> Result<(), PlcError> {
        let np = self.pieces.len();
        let lo = self.pieces.iter().fold(DVec3::INFINITY, |a, p| a.min(p.lo));
        let hi = self
            .pieces
            .iter()
            .fold(DVec3::NEG_INFINITY, |a, p| a.max(p.hi));
        let ext = (hi - lo).max(DVec3::splat(self.tol));
        let h = (ext.x * ext.y * ext.z / np as f64).cbrt() * 1.5;
        let dims: [usize; 3] = [0, 1, 2].map(|a| ((ext[a] / h).ceil() as usize).clamp(1, 64));
        let cell = |x: DVec3| -> [usize; 3] {
            [0, 1, 2].map(|a| {
                (((x[a] - lo[a]) / ext[a] * dims[a] as f64).floor().max(0.0) as usize)
                    .min(dims[a] - 1)
            })
        };
        let grow = DVec3::splat(self.tol);
        let mut grid: Vec<Vec<u32>> = vec![Vec::new(); dims[0] * dims[1] * dims[2]];
        for (k, p) in self.pieces.iter().enumerate() {
            let (c0, c1) = (cell(p.lo - grow), cell(p.hi + grow));
            for i in c0[0]..=c1[0] {
                for j in c0[1]..=c1[1] {
                    for l in c0[2]..=c1[2] {
                        grid[(i * dims[1] + j) * dims[2] + l].push(k as u32);
                    }
                }
            }
        }
        let piece_verts: Vec<Vec<u32>> = (0..np)
            .map(|k| {
                let p = &self.pieces[k];
                let g = &self.facets[p.facet];
                let mut v: Vec<u32> = std::iter::once(p.outer)
                    .chain(p.inner.iter().copied())
                    .flat_map(|l| g.loops[l].verts.iter().copied())
                    .collect();
                v.sort_unstable();
                v
            })
            .collect();
        let mut stamp = vec![usize::MAX; np];
        for (ei, (e, incs)) in edges.iter().enumerate() {
            let (a, b) = (self.point(e[0]), self.point(e[1]));
            let (elo, ehi) = (a.min(b) - grow, a.max(b) + grow);
            let (c0, c1) = (cell(elo), cell(ehi));
            let own = self.pieces[incs[0].piece as usize].facet;
            for i in c0[0]..=c1[0] {
                for j in c0[1]..=c1[1] {
                    for l in c0[2]..=c1[2] {
                        for &k in &grid[(i * dims[1] + j) * dims[2] + l] {
                            let k = k as usize;
                            if stamp[k] == ei {
                                continue;
                            }
                            stamp[k] = ei;
                            let p = &self.pieces[k];
                            if piece_verts[k].binary_search(&e[0]).is_ok()
                                || piece_verts[k].binary_search(&e[1]).is_ok()
                                || ehi.cmplt(p.lo).any()
                                || elo.cmpgt(p.hi).any()
                            {
                                continue;
                            }
                            let g = &self.facets[p.facet];
                            let tolp = self.tol + g.deviation;
                            let (da, db) = (g.n.dot(a - g.o), g.n.dot(b - g.o));
                            let on_a = da.abs() <= tolp;
                            let on_b = db.abs() <= tolp;
                            let hit = if on_a && on_b {
                                None // in the plane: not tested here
                            } else if on_a || on_b {
                                let (v, q) = if on_a { (e[0], a) } else { (e[1], b) };
                                self.strictly_inside(k, q).then(|| {
                                    format!(
                                        "point {} of facet {} lies inside facet {}",
                                        v + 1,
                                        own + 1,
                                        p.facet + 1
                                    )
                                })
                            } else if (da > 0.0) != (db > 0.0) {
                                let q = a + (b - a) * (da / (da - db));
                                self.strictly_inside(k, q).then(|| {
                                    format!(
                                        "edge ({}, {}) of facet {} crosses facet {}",
                                        e[0] + 1,
                                        e[1] + 1,
                                        own + 1,
                                        p.facet + 1
                                    )
                                })
                            } else {
                                None
                            };
                            if let Some(detail) = hit {
                                return Err(PlcError::Intersect {
                                    facet: own + 1,
                                    other: p.facet + 1,
                                    detail,
                                });
                            }
                        }
                    }
                }
            }
        }
        Ok(())
    }
}
