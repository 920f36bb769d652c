//! √3 subdivision of triangle meshes: Kobbelt's approximating scheme and
//! Labsik and Greiner's interpolating scheme, with open-boundary and
//! tagged-crease rules, and adaptive refinement of selected faces.
//!
//! The stencils (where old points move, where face and trisection points
//! go) are the core's, [`tetrefine::stencil`], shared with the boundary of the
//! tetrahedral step; this module adds the topology of a surface step (1-to-3
//! splits, edge flips, trisected curve edges) and the adaptive selection.
//! See [`tetrefine::stencil`] for the rules.

pub use tetrefine::stencil::{
    kobbelt_alpha, labsik_greiner_weights, sqrt3_positions, sqrt3_positions_trisecting,
    Sqrt3Positions, Sqrt3Rule, Sqrt3Trisection,
};

use super::features::{Features, SubdivisionError};
use super::lineage::{observe, FaceAttributes, StepObserver, Subdivided};
use super::polymesh::PolyMesh;
use glam::DVec3;
use rayon::prelude::*;
use std::collections::{HashMap, HashSet};
use tetrefine::stencil::TriTopology;
use tetrefine::topo::edge_key;

/// No triangle, no point: a slot the step leaves empty.
const NONE: u32 = u32::MAX;
/// The child index of a triangle that a step left unsplit.
const KEPT: u8 = u8::MAX;

/// Which triangles an adaptive √3 step splits, decided on the triangle's
/// centroid.
#[derive(Clone, Debug, PartialEq)]
pub enum FaceSelection {
    /// Every triangle (uniform refinement).
    All,
    /// Triangles whose centroid lies in the axis-aligned box [min, max].
    Box {
        /// Lower corner.
        min: DVec3,
        /// Upper corner.
        max: DVec3,
    },
    /// Triangles whose centroid lies in the ball.
    Sphere {
        /// Centre.
        center: DVec3,
        /// Radius.
        radius: f64,
    },
}

impl FaceSelection {
    /// True when a triangle with this centroid is selected.
    pub fn contains(&self, c: DVec3) -> bool {
        match self {
            FaceSelection::All => true,
            FaceSelection::Box { min, max } => c.cmpge(*min).all() && c.cmple(*max).all(),
            FaceSelection::Sphere { center, radius } => c.distance(*center) <= *radius,
        }
    }
}

/// Options of [`sqrt3`] beyond the rule and the number of steps.
#[derive(Clone, Debug, PartialEq)]
pub struct Sqrt3Options {
    /// Tagged creases and corners.
    pub features: Features,
    /// Which triangles are split in each step.
    pub selection: FaceSelection,
}

impl Default for Sqrt3Options {
    fn default() -> Self {
        Sqrt3Options {
            features: Features::default(),
            selection: FaceSelection::All,
        }
    }
}

/// A triangle surface under √3 refinement, with its tags and its step count
/// (which decides whether the next step keeps or trisects curve edges).
#[derive(Clone, Debug, PartialEq)]
pub struct Sqrt3Surface {
    /// Points; old points keep their ids from step to step.
    pub points: Vec<DVec3>,
    /// Triangles.
    pub tris: Vec<[u32; 3]>,
    /// Tagged crease edges (sorted pairs).
    pub creases: HashSet<[u32; 2]>,
    /// Tagged corners.
    pub corners: HashSet<u32>,
    /// Steps done so far; step number `generation + 1` trisects curve edges
    /// when it is even.
    pub generation: usize,
}

impl Sqrt3Surface {
    /// One √3 step with `rule`, splitting the triangles `selection` picks.
    pub fn step(&mut self, rule: Sqrt3Rule, selection: &FaceSelection) {
        self.step_lineage(rule, selection);
    }

    /// [`Sqrt3Surface::step`], returning the face attributes of the new
    /// triangles from `attributes`, those of the current ones (see
    /// [`super::lineage`]: a split triangle's children are in group `i`, the
    /// half-edge they stand on; an unsplit triangle keeps its attributes).
    pub fn step_tracked(
        &mut self,
        rule: Sqrt3Rule,
        selection: &FaceSelection,
        attributes: &FaceAttributes,
    ) -> FaceAttributes {
        let lineage = self.step_lineage(rule, selection);
        let generation = self.generation as u32;
        let mut out = FaceAttributes::with_capacity(lineage.len());
        for (parent, child) in lineage {
            match child {
                KEPT => out.push_kept(attributes, parent),
                i => out.push_child(attributes, parent, generation, i as u32),
            }
        }
        out
    }

    /// One step; for each new triangle its parent and its child index
    /// (0, 1, 2), or [`KEPT`] for an unsplit triangle.
    fn step_lineage(&mut self, rule: Sqrt3Rule, selection: &FaceSelection) -> Vec<(u32, u8)> {
        let np = self.points.len();
        let nt = self.tris.len();
        let topo = TriTopology::build(np, &self.tris, &self.creases, &self.corners);
        let points = &self.points;
        let tris = &self.tris;
        let selected: Vec<bool> = tris
            .par_iter()
            .map(|t| {
                let c =
                    (points[t[0] as usize] + points[t[1] as usize] + points[t[2] as usize]) / 3.0;
                selection.contains(c)
            })
            .collect();
        let trisect_step = self.generation % 2 == 1;
        // Curve edges to trisect: every triangle at the edge is selected and
        // has no other curve edge.
        let mut trisected: HashSet<[u32; 2]> = HashSet::new();
        if trisect_step {
            let ncurve: Vec<u8> = (0..nt)
                .map(|t| (0..3).filter(|&i| topo.is_curve(3 * t + i)).count() as u8)
                .collect();
            let mut blocked: HashSet<[u32; 2]> = HashSet::new();
            for t in 0..nt {
                for i in 0..3 {
                    if topo.is_curve(3 * t + i) {
                        let e = edge_key(tris[t][i], tris[t][(i + 1) % 3]);
                        if selected[t] && ncurve[t] == 1 {
                            trisected.insert(e);
                        } else {
                            blocked.insert(e);
                        }
                    }
                }
            }
            trisected.retain(|e| !blocked.contains(e));
        }
        let geo = topo.positions(points, tris, rule, &trisected);
        // Old vertices move only when all their triangles are split.
        let mut complete = vec![true; np];
        for (t, tri) in tris.iter().enumerate() {
            if !selected[t] {
                for &v in tri {
                    complete[v as usize] = false;
                }
            }
        }
        let mut new_points: Vec<DVec3> = (0..np)
            .map(|v| {
                if complete[v] {
                    geo.positions.vertices[v]
                } else {
                    points[v]
                }
            })
            .collect();
        // Ids of the new points.
        let mut face_point = vec![NONE; nt];
        let mut tri_edge: Vec<Option<usize>> = vec![None; nt];
        for t in 0..nt {
            if !selected[t] {
                continue;
            }
            let te = (0..3).find(|&i| {
                topo.is_curve(3 * t + i)
                    && trisected.contains(&edge_key(tris[t][i], tris[t][(i + 1) % 3]))
            });
            tri_edge[t] = te;
            if te.is_none() {
                face_point[t] = new_points.len() as u32;
                new_points.push(geo.positions.faces[t]);
            }
        }
        let mut edge_ids: HashMap<[u32; 2], [u32; 2]> = HashMap::with_capacity(trisected.len());
        let mut order: Vec<[u32; 2]> = trisected.iter().copied().collect();
        order.sort_unstable();
        for e in order {
            let p = geo.edge_points[&e];
            let id = new_points.len() as u32;
            new_points.extend_from_slice(&p);
            edge_ids.insert(e, [id, id + 1]);
        }
        // Apex of the sub-triangle on each half-edge of a split triangle.
        let sub_apex = |h: u32| -> u32 {
            let t = (h / 3) as usize;
            let i = (h % 3) as usize;
            match tri_edge[t] {
                None => face_point[t],
                Some(k) => {
                    let (u, w) = (tris[t][k], tris[t][(k + 1) % 3]);
                    let ids = edge_ids[&edge_key(u, w)];
                    let (pu, pw) = if u < w {
                        (ids[0], ids[1])
                    } else {
                        (ids[1], ids[0])
                    };
                    if i == (k + 1) % 3 {
                        pw
                    } else {
                        pu
                    }
                }
            }
        };
        let flipped = |h: u32| -> bool {
            topo.twin(h)
                .is_some_and(|o| selected[(o / 3) as usize] && selected[(h / 3) as usize])
        };
        let out: Vec<[[u32; 3]; 3]> = (0..nt)
            .into_par_iter()
            .map(|t| {
                let tri = tris[t];
                if !selected[t] {
                    return [tri, [NONE; 3], [NONE; 3]];
                }
                let mut res = [[NONE; 3]; 3];
                for (i, r) in res.iter_mut().enumerate() {
                    let h = (3 * t + i) as u32;
                    if tri_edge[t] == Some(i) {
                        let (u, w, o) = (tri[i], tri[(i + 1) % 3], tri[(i + 2) % 3]);
                        let ids = edge_ids[&edge_key(u, w)];
                        let (pu, pw) = if u < w {
                            (ids[0], ids[1])
                        } else {
                            (ids[1], ids[0])
                        };
                        *r = [pu, pw, o];
                    } else if flipped(h) {
                        *r = [
                            tri[i],
                            sub_apex(topo.twin(h).expect("a flipped half-edge has a twin")),
                            sub_apex(h),
                        ];
                    } else {
                        *r = [tri[i], tri[(i + 1) % 3], sub_apex(h)];
                    }
                }
                res
            })
            .collect();
        let mut new_tris = Vec::with_capacity(nt * 3);
        let mut lineage = Vec::with_capacity(nt * 3);
        for (t, r) in out.into_iter().enumerate() {
            for (i, tri) in r.into_iter().enumerate() {
                if tri[0] != NONE {
                    new_tris.push(tri);
                    lineage.push((t as u32, if selected[t] { i as u8 } else { KEPT }));
                }
            }
        }
        // Creases: trisected ones are replaced by their three pieces.
        let mut new_creases = HashSet::with_capacity(self.creases.len() * 3);
        for &e in &self.creases {
            match edge_ids.get(&e) {
                Some(&[pa, pb]) => {
                    new_creases.insert(edge_key(e[0], pa));
                    new_creases.insert(edge_key(pa, pb));
                    new_creases.insert(edge_key(pb, e[1]));
                }
                None => {
                    new_creases.insert(e);
                }
            }
        }
        self.points = new_points;
        self.tris = new_tris;
        self.creases = new_creases;
        self.generation += 1;
        lineage
    }

    /// The surface as a polygon mesh.
    pub fn to_polymesh(&self) -> PolyMesh {
        PolyMesh::from_triangles(self.points.clone(), &self.tris)
    }
}

/// `steps` √3 steps of a triangle mesh with `rule` (Kobbelt's approximating,
/// Labsik–Greiner's interpolating, or linear), honouring tagged creases and
/// corners, open boundaries and an adaptive selection. The mesh must be an
/// oriented manifold triangle mesh; old points keep their ids, new points are
/// appended.
pub fn sqrt3(
    mesh: &PolyMesh,
    rule: Sqrt3Rule,
    steps: usize,
    options: &Sqrt3Options,
) -> Result<PolyMesh, SubdivisionError> {
    sqrt3_tracked(mesh, rule, steps, options, None).map(|s| s.mesh)
}

/// [`sqrt3`] with the face attributes of [`super::lineage`] and an observer
/// of every generation.
pub fn sqrt3_tracked(
    mesh: &PolyMesh,
    rule: Sqrt3Rule,
    steps: usize,
    options: &Sqrt3Options,
    mut observer: Option<&mut StepObserver<'_>>,
) -> Result<Subdivided, SubdivisionError> {
    let tris = mesh
        .triangles()
        .map_err(|f| SubdivisionError::NotTriangles {
            face: f,
            len: mesh.faces[f].len(),
        })?;
    let he = mesh.half_edges()?;
    let (creases, corners) = options.features.resolve(mesh, &he)?;
    let mut s = Sqrt3Surface {
        points: mesh.points.clone(),
        tris,
        creases,
        corners,
        generation: 0,
    };
    let mut attrs = FaceAttributes::input(mesh.faces.len());
    let mut done = 0;
    // The observer needs the mesh of every generation; without one only
    // the last is built.
    let watching = observer.is_some();
    if observe(&mut observer, 0, mesh, &attrs) {
        for k in 0..steps {
            attrs = s.step_tracked(rule, &options.selection, &attrs);
            done = k + 1;
            if watching && !observe(&mut observer, done, &s.to_polymesh(), &attrs) {
                break;
            }
        }
    }
    Ok(Subdivided {
        mesh: s.to_polymesh(),
        attributes: attrs,
        steps: done,
    })
}
