//! The enclosed volume: sides of pieces glued into shells around every edge,
//! shells grouped into cells by ray casting (union-find), seeds located.

use super::geometry::*;
use super::validate::Analysis;
use super::{Plc, PlcError, PlcVolume};
use glam::DVec3;
use std::collections::HashMap;
use PlcError::SeedOutside;

impl Analysis {
    /// Sorts the pieces around each edge by angle and glues the sides that
    /// face the same wedge of space.
    pub(super) fn glue_sides(
        &self,
        edges: &[([u32; 2], Vec<Incidence>)],
        sides: &mut UnionFind,
    ) -> Result<(), PlcError> {
        for (e, incs) in edges {
            let u = (self.point(e[1]) - self.point(e[0])).normalize();
            let axis = (0..3)
                .min_by(|&i, &j| u[i].abs().total_cmp(&u[j].abs()))
                .unwrap_or(0);
            let e1 = u.cross(DVec3::AXES[axis]).normalize();
            let e2 = u.cross(e1);
            let mut around: Vec<(f64, f64, u32)> = incs
                .iter()
                .map(|i| {
                    let n = self.facets[self.pieces[i.piece as usize].facet].n;
                    // +1 when the piece's +n side faces increasing angles.
                    let s = if n.dot(u.cross(i.d)) >= 0.0 {
                        1.0
                    } else {
                        -1.0
                    };
                    (i.d.dot(e2).atan2(i.d.dot(e1)), s, i.piece)
                })
                .collect();
            around.sort_by(|a, b| a.0.total_cmp(&b.0));
            let m = around.len();
            for i in 0..m {
                let j = (i + 1) % m;
                let gap = if j == 0 {
                    around[0].0 + std::f64::consts::TAU - around[i].0
                } else {
                    around[j].0 - around[i].0
                };
                if gap < 1e-10 {
                    let (fa, fb) = (
                        self.pieces[around[i].2 as usize].facet,
                        self.pieces[around[j].2 as usize].facet,
                    );
                    return Err(PlcError::Overlap {
                        facet: fa.min(fb) + 1,
                        other: fa.max(fb) + 1,
                        a: e[0] as u64 + 1,
                        b: e[1] as u64 + 1,
                    });
                }
                let (_, si, ki) = around[i];
                let (_, sj, kj) = around[j];
                sides.union(side(ki as usize, si), side(kj as usize, -sj));
            }
        }
        Ok(())
    }

    /// A point strictly inside piece `k`, in centred 3-D coordinates.
    pub(super) fn piece_interior(&self, k: usize) -> Option<DVec3> {
        let g = &self.facets[self.pieces[k].facet];
        let [a, b] = interior_point(&self.piece_loops(k))?;
        // Lift (a, b) back onto the plane n·(x - o) = 0.
        let (iu, iv) = match g.drop {
            0 => (1, 2),
            1 => (2, 0),
            _ => (0, 1),
        };
        let mut p = DVec3::ZERO;
        p[iu] = a;
        p[iv] = b;
        p[g.drop] = g.o[g.drop] - (g.n[iu] * (a - g.o[iu]) + g.n[iv] * (b - g.o[iv])) / g.n[g.drop];
        Some(p)
    }

    /// Casts a ray from `x0` along the unit vector `dir`, skipping piece `skip`.
    pub(super) fn cast(&self, x0: DVec3, dir: DVec3, skip: Option<usize>) -> Ray {
        let mut hits = Vec::new();
        for (k, p) in self.pieces.iter().enumerate() {
            if Some(k) == skip || !ray_meets_box(x0, dir, p.lo, p.hi, self.tol) {
                continue;
            }
            let g = &self.facets[p.facet];
            let denom = g.n.dot(dir);
            let dist = g.n.dot(g.o - x0);
            if denom.abs() < 1e-9 {
                if dist.abs() <= self.tol {
                    return Ray::Degenerate; // the ray runs in the piece's plane
                }
                continue;
            }
            let t = dist / denom;
            if t < -self.tol {
                continue;
            }
            let q = project(x0 + t * dir, g.drop);
            let loops = self.piece_loops(k);
            if loops.iter().any(|l| loop_distance(l, q) <= self.tol) {
                return Ray::Degenerate; // through an edge or a vertex
            }
            let inside = loops.iter().filter(|l| inside_loop(l, q)).count() % 2 == 1;
            if !inside {
                continue;
            }
            if t <= self.tol {
                return Ray::OnPiece;
            }
            hits.push((t, k));
        }
        hits.sort_by(|a, b| a.0.total_cmp(&b.0));
        if hits.windows(2).any(|w| w[1].0 - w[0].0 <= self.tol) {
            return Ray::Degenerate;
        }
        Ray::Hits(hits)
    }

    /// Groups shells into cells, locates the seeds and adds up the volumes.
    pub(super) fn cells(
        &self,
        raw: &Plc,
        sides: &mut UnionFind,
        diag: f64,
    ) -> Result<PlcVolume, PlcError> {
        let np = self.pieces.len();
        // Shells: components of glued sides, numbered densely.
        let mut shell_of_root: HashMap<u32, usize> = HashMap::new();
        let mut shell_of_side = vec![0usize; 2 * np];
        for (s, slot) in shell_of_side.iter_mut().enumerate() {
            let r = sides.find(s as u32);
            let n = shell_of_root.len();
            *slot = *shell_of_root.entry(r).or_insert(n);
        }
        let ns = shell_of_root.len();
        // Volume integral of each shell, normals into the cell it bounds.
        let mut vol = vec![0.0f64; ns];
        for (k, p) in self.pieces.iter().enumerate() {
            let g = &self.facets[p.facet];
            let moment = g.n.dot(g.o) * p.area / 3.0;
            vol[shell_of_side[side(k, 1.0) as usize]] -= moment;
            vol[shell_of_side[side(k, -1.0) as usize]] += moment;
        }
        let eps = 1e-14 * diag * diag * diag;
        if let Some(s) = (0..ns).find(|&s| vol[s].abs() <= eps) {
            let k = (0..np)
                .find(|&k| shell_of_side[2 * k] == s || shell_of_side[2 * k + 1] == s)
                .unwrap_or(0);
            return Err(PlcError::Inconsistent(format!(
                "a closed part of the surface through facet {} encloses no volume",
                self.pieces[k].facet + 1
            )));
        }
        // A side of the largest piece of each shell, to cast rays from.
        let mut start: Vec<Option<(usize, f64)>> = vec![None; ns];
        for (k, p) in self.pieces.iter().enumerate() {
            for s in [1.0, -1.0] {
                let sh = shell_of_side[side(k, s) as usize];
                if start[sh].is_none_or(|(b, _)| self.pieces[b].area < p.area) {
                    start[sh] = Some((k, s));
                }
            }
        }
        // Cells: a positive shell is the outer boundary of a bounded cell; a
        // negative one belongs to the cell around it, found by a ray walk.
        let mut cells = UnionFind::new(ns);
        let mut escapes = vec![false; ns];
        for sh in (0..ns).filter(|&s| vol[s] < 0.0) {
            let (k, s) = start[sh].expect("every shell has a side");
            let g = &self.facets[self.pieces[k].facet];
            let x0 = self.piece_interior(k).ok_or_else(|| {
                PlcError::Inconsistent(format!(
                    "facet {} has no interior point",
                    self.pieces[k].facet + 1
                ))
            })?;
            let mut done = false;
            for gdir in ray_directions() {
                let dir = (s * g.n + 0.6 * gdir).normalize();
                let hits = match self.cast(x0, dir, Some(k)) {
                    Ray::Hits(h) => h,
                    Ray::Degenerate | Ray::OnPiece => continue,
                };
                // Walk along the ray keeping, for every shell crossed, the
                // change of its winding number; while all are zero the ray is
                // still in the cell it started in, and each side it meets
                // there bounds that cell.
                let mut winding: HashMap<usize, i32> = HashMap::new();
                let mut nonzero = 0usize;
                for (_, kh) in hits {
                    let nh = self.facets[self.pieces[kh].facet].n;
                    let facing = if nh.dot(dir) > 0.0 { -1.0 } else { 1.0 };
                    let near = shell_of_side[side(kh, facing) as usize];
                    let far = shell_of_side[side(kh, -facing) as usize];
                    if nonzero == 0 {
                        cells.union(sh as u32, near as u32);
                    }
                    for (x, dw) in [(near, -1), (far, 1)] {
                        let w = winding.entry(x).or_insert(0);
                        let was = *w != 0;
                        *w += dw;
                        match (was, *w != 0) {
                            (false, true) => nonzero += 1,
                            (true, false) => nonzero -= 1,
                            _ => {}
                        }
                    }
                }
                escapes[sh] = nonzero == 0;
                done = true;
                break;
            }
            if !done {
                return Err(PlcError::Inconsistent(
                    "every ray from a cavity grazes an edge".into(),
                ));
            }
        }
        // Each cell: at most one positive shell, and bounded exactly when it
        // has one.
        let mut outer_of_cell: HashMap<u32, usize> = HashMap::new();
        let mut escaping: HashMap<u32, bool> = HashMap::new();
        for sh in 0..ns {
            let c = cells.find(sh as u32);
            if vol[sh] > 0.0 && outer_of_cell.insert(c, sh).is_some() {
                return Err(PlcError::Inconsistent(
                    "a cell has two outer boundaries".into(),
                ));
            }
            *escaping.entry(c).or_default() |= escapes[sh];
        }
        for (c, esc) in &escaping {
            if *esc == outer_of_cell.contains_key(c) {
                return Err(PlcError::Inconsistent(if *esc {
                    "a bounded cell reaches infinity".into()
                } else {
                    "a cavity lies in no cell".into()
                }));
            }
        }
        let mut cell_volume: HashMap<u32, f64> = HashMap::new();
        for (sh, &v) in vol.iter().enumerate() {
            let c = cells.find(sh as u32);
            if outer_of_cell.contains_key(&c) {
                *cell_volume.entry(c).or_default() += v;
            }
        }
        if let Some(v) = cell_volume.values().find(|&&v| v <= eps) {
            return Err(PlcError::Inconsistent(format!(
                "a cell has volume {v:e} after its cavities are removed"
            )));
        }
        // Seeds are located exactly, in the input's own coordinates (see
        // `locate.rs`): the cell of every piece side, and which are bounded.
        let cell_of_side: Vec<usize> = shell_of_side
            .iter()
            .map(|&sh| cells.find(sh as u32) as usize)
            .collect();
        let bounded: Vec<bool> = (0..ns)
            .map(|c| outer_of_cell.contains_key(&(c as u32)))
            .collect();
        // Hole seeds.
        let mut emptied: Vec<u32> = Vec::new();
        let mut hole_of_cell: HashMap<u32, usize> = HashMap::new();
        for (i, h) in raw.holes.iter().enumerate() {
            if let Some(c) =
                self.locate_exact(*h, &raw.points, &cell_of_side, &bounded, "hole", i)?
            {
                emptied.push(c as u32);
                hole_of_cell.entry(c as u32).or_insert(i);
            }
        }
        // Region seeds: each must lie in a bounded cell that no hole empties.
        for (i, r) in raw.regions.iter().enumerate() {
            match self.locate_exact(r.point, &raw.points, &cell_of_side, &bounded, "region", i)? {
                Some(c) => {
                    if let Some(&h) = hole_of_cell.get(&(c as u32)) {
                        return Err(PlcError::SeedInHole {
                            index: i + 1,
                            hole: h + 1,
                            line: None,
                            hole_line: None,
                        });
                    }
                }
                None => {
                    return Err(SeedOutside {
                        index: i + 1,
                        coords: r.point,
                        line: None,
                    })
                }
            }
        }
        emptied.sort_unstable();
        emptied.dedup();
        let enclosed: f64 = cell_volume
            .iter()
            .filter(|(c, _)| !emptied.contains(c))
            .map(|(_, v)| v)
            .sum();
        if cell_volume.len() == emptied.len() {
            return Err(PlcError::NothingEnclosed);
        }
        let planarity_slack = self
            .pieces
            .iter()
            .map(|p| p.area * self.facets[p.facet].deviation)
            .sum();
        Ok(PlcVolume {
            enclosed,
            cells: cell_volume.len(),
            hole_cells: emptied.len(),
            planarity_slack,
        })
    }
}
