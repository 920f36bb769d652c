//! Weighted and extruded Catmull–Clark subdivision after M. Hansmeyer,
//! "Design by Subdivision" (seed `001_31332e039822df95.txt`): the
//! Catmull–Clark rules with weights that shift the new points between their
//! parents and extrude them along normals, weights that change from
//! iteration to iteration and across space, and groups of vertices, faces and
//! edges with their own weights or locked for a number of iterations.
//!
//! # The rules (numbers are the paper's equations)
//!
//! With all weights zero every rule below is the plain Catmull–Clark rule of
//! [`super::catmull_clark`], evaluated in the same order, so the result is
//! the same to the last bit.
//!
//! 1. Face point: F = (Σ cₖ Pₖ)/n + n_f·w, with cₖ = 1 (eq. 1), except from
//!    the second iteration on for a quad whose corners come from (vertex,
//!    edge, face, edge) points of the previous step (eq. 4, whose printed text
//!    is garbled in the seed; we read it as): c = 1 + `face_vertex` for the
//!    vertex-derived corner, 1 + `face_face` for the face-derived corner and
//!    1 − (`face_vertex` + `face_face`)/2 for the two edge-derived corners —
//!    an affine combination that reduces to the centroid. w = `face_extrude`.
//! 2. Edge point: E = ((F₁ + F₂)(1 + w_e) + (P₁ + P₂)(1 − w_e))/4 + n_e·w,
//!    w_e = `edge`, w = `edge_extrude`.
//! 3. Vertex point of valence i: V = (F̄(1 + w_v) + 2R̄(1 − w_v/2) + (i − 3)P)/i
//!    \+ n_v·w, w_v = `vertex`, w = `vertex_extrude`, F̄ the average of the
//!    new face points around, R̄ the average of the midpoints of the edges.
//! 4. Attraction/deflection (eqs. 10, 11): F ← F + w₆ Σ (Pₖ − F) μ(Pₖ)/n and
//!    E ← E + w₇ ((P₁ − E) μ(P₁) + (P₂ − E) μ(P₂)), w₆ = `face_attract`,
//!    w₇ = `edge_attract`, μ(P) the value of `mu_by_pattern` for the
//!    face/edge motif of P (the paper's figure 3: `"4F4E"` is a vertex in 4
//!    faces with 4 edges; on an open boundary or after joins the two
//!    differ), else of `mu_by_valence` for the valence
//!    of P (0 if absent).
//!
//! Normals: n_f is the unit face normal, n_e the normalised average of the
//! unit normals of the faces at the edge, n_v that of the faces at the
//! vertex; "each extrusion vector is scaled by the dimensions of the
//! incident faces": each is multiplied by the mean of √area of those faces.
//!
//! Boundary and tagged crease edges use the plain curve rules (midpoint,
//! (6P + a + b)/8, corners fixed) without weights.
//!
//! # Where the weights come from
//!
//! For an element (face, edge or vertex) in iteration k (from 0):
//! 1. a face group containing the face (for an edge: both its faces; for a
//!    vertex: a vertex group with weights) gives its weights;
//! 2. otherwise, if attractor sets are given (eqs. 8, 9): each set a, at
//!    normalised distance dₐ ∈ [0, 1] from the element (distances divided by
//!    the diagonal of the box around the input and the sets), has influence
//!    cₐ = (1 − dₐ)ᵗ hₐ / Σ_b (1 − d_b)ᵗ h_b (t the tightness, hₐ the
//!    strength) and the weights are Σ cₐ wₐ;
//! 3. otherwise, with an axis gradient, the weights are interpolated
//!    linearly between two stops along x, y or z (the nearer stop's weights
//!    outside them);
//! 4. otherwise the iteration's weights (`iterations[k]`, the last entry
//!    repeating; zero if there are none).
//!
//! Positions are those of the element: face centroid, edge midpoint, vertex.
//! Face groups pass to the faces a face is split into; vertex groups hold
//! original vertices (which keep their ids). A vertex group with
//! `lock_iterations` = L and `lock_start` = N keeps its vertices in place in
//! iterations N .. N + L (N = 0: the first L); a locked edge with
//! `iterations` = L and `start` = N keeps the endpoints of the chain it has
//! been split into by iteration N in place and their edge points at the
//! midpoints in iterations N .. N + L, so the chain stays exactly where it
//! was when the lock began (the paper's figure 9 locks after the 8th
//! iteration). Locks of one edge in several groups join into one range.

use super::catmull_clark::{
    catmull_clark_faces, crease_vertex_point, in_point_order, split_creases,
};
use super::features::{
    classify, corner_children, run_steps, sorted_pair, Features, Role, Step, SubdivisionError,
};
use super::lineage::{FaceAttributes, StepObserver, Subdivided};
use super::polymesh::{HalfEdges, PolyMesh, NO_TWIN};
use glam::DVec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::Path;
use tetrefine::io::IoError;

/// One set of weights (see the module docs for the equations).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Weights {
    /// Eq. 1/4: extrusion of face points along the face normal.
    pub face_extrude: f64,
    /// Eq. 2: shift of edge points towards the face points (w_e).
    pub edge: f64,
    /// Eq. 2: extrusion of edge points along the edge normal.
    pub edge_extrude: f64,
    /// Eq. 3: shift of vertex points towards the face points (w_v).
    pub vertex: f64,
    /// Eq. 3: extrusion of vertex points along the vertex normal.
    pub vertex_extrude: f64,
    /// Eq. 4: extra weight of the vertex-derived corner of a quad.
    pub face_vertex: f64,
    /// Eq. 4: extra weight of the face-derived corner of a quad.
    pub face_face: f64,
    /// Eq. 10: attraction (w₆) of face points towards vertices with μ ≠ 0.
    pub face_attract: f64,
    /// Eq. 11: attraction (w₇) of edge points towards endpoints with μ ≠ 0.
    pub edge_attract: f64,
}

impl Weights {
    fn add_scaled(&mut self, o: &Weights, s: f64) {
        self.face_extrude += o.face_extrude * s;
        self.edge += o.edge * s;
        self.edge_extrude += o.edge_extrude * s;
        self.vertex += o.vertex * s;
        self.vertex_extrude += o.vertex_extrude * s;
        self.face_vertex += o.face_vertex * s;
        self.face_face += o.face_face * s;
        self.face_attract += o.face_attract * s;
        self.edge_attract += o.edge_attract * s;
    }
}

/// A set of weights placed in space (eqs. 8, 9).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AttractorSet {
    /// Where the set is.
    pub position: [f64; 3],
    /// Its strength h.
    pub strength: f64,
    /// Its weights.
    pub weights: Weights,
}

/// Weights from sets placed in space.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Attractors {
    /// The tightness exponent t (the paper uses t > 1).
    pub tightness: f64,
    /// The sets.
    pub sets: Vec<AttractorSet>,
}

impl Default for Attractors {
    fn default() -> Self {
        Attractors {
            tightness: 2.0,
            sets: Vec::new(),
        }
    }
}

/// A coordinate axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Axis {
    /// x.
    X,
    /// y.
    Y,
    /// z.
    Z,
}

/// One end of an axis gradient.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AxisStop {
    /// Coordinate along the axis.
    pub at: f64,
    /// Weights there.
    pub weights: Weights,
}

/// Weights interpolated linearly along an axis between two stops.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisGradient {
    /// The axis.
    pub axis: Axis,
    /// First stop.
    pub from: AxisStop,
    /// Second stop.
    pub to: AxisStop,
}

/// A group of input vertices with its own weights and/or locked.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VertexGroup {
    /// Input vertex ids.
    pub vertices: Vec<u32>,
    /// Weights of these vertices' vertex points (none: the usual ones).
    pub weights: Option<Weights>,
    /// The vertices stay in place for this many iterations.
    pub lock_iterations: usize,
    /// The first locked iteration (from 0): the vertices are locked in
    /// iterations `lock_start .. lock_start + lock_iterations`.
    pub lock_start: usize,
}

/// A group of input faces with its own weights (passed to their children).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FaceGroup {
    /// Input face ids.
    pub faces: Vec<u32>,
    /// Weights of the faces' face points (and of edges inside the group).
    pub weights: Weights,
}

/// Input edges locked for a number of iterations.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LockedEdges {
    /// Input edges as vertex pairs.
    pub edges: Vec<[u32; 2]>,
    /// Number of iterations during which they stay fixed.
    pub iterations: usize,
    /// The first locked iteration (from 0): the lock holds in iterations
    /// `start .. start + iterations`, on the chain of edges the input edge
    /// has been split into by then.
    pub start: usize,
}

/// Everything that controls the weighted scheme; read from JSON with
/// [`WeightedConfig::from_json_file`]. Every field is optional.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WeightedConfig {
    /// Weights per iteration; the last entry repeats.
    pub iterations: Vec<Weights>,
    /// Attractor/deflector value μ by vertex valence (eqs. 10, 11).
    pub mu_by_valence: BTreeMap<u32, f64>,
    /// Attractor/deflector value μ by face/edge motif, `"<faces>F<edges>E"`
    /// (eqs. 10, 11; the paper's figure 3); it takes precedence over
    /// `mu_by_valence`.
    pub mu_by_pattern: BTreeMap<String, f64>,
    /// Weight sets placed in space.
    pub attractors: Option<Attractors>,
    /// A linear gradient along an axis.
    pub axis: Option<AxisGradient>,
    /// Vertex groups.
    pub vertex_groups: Vec<VertexGroup>,
    /// Face groups.
    pub face_groups: Vec<FaceGroup>,
    /// Locked edges.
    pub locked_edges: Vec<LockedEdges>,
}

impl WeightedConfig {
    /// Reads a configuration from a JSON file; errors name the file and line.
    pub fn from_json_file(path: &Path) -> Result<WeightedConfig, IoError> {
        let bytes = tetrefine::io::read_bytes(path)?;
        serde_json::from_slice(&bytes).map_err(|e| {
            let line = Some(e.line()).filter(|&l| l > 0);
            IoError::decode(path, line, "invalid weights file", e)
        })
    }

    /// The weights of iteration `k` without spatial or group variation.
    pub fn iteration_weights(&self, k: usize) -> Weights {
        match self.iterations.len() {
            0 => Weights::default(),
            n => self.iterations[k.min(n - 1)],
        }
    }
}

/// Evaluates the spatially varying weights.
struct Spatial<'a> {
    cfg: &'a WeightedConfig,
    scale: f64,
}

impl Spatial<'_> {
    fn at(&self, base: &Weights, pos: DVec3) -> Weights {
        if let Some(att) = &self.cfg.attractors {
            if !att.sets.is_empty() {
                let infl: Vec<f64> = att
                    .sets
                    .iter()
                    .map(|s| {
                        let d = (pos.distance(DVec3::from_array(s.position)) / self.scale).min(1.0);
                        (1.0 - d).powf(att.tightness) * s.strength
                    })
                    .collect();
                let total: f64 = infl.iter().sum();
                if total > 0.0 && total.is_finite() {
                    let mut w = Weights::default();
                    for (s, c) in att.sets.iter().zip(&infl) {
                        w.add_scaled(&s.weights, c / total);
                    }
                    return w;
                }
            }
        }
        if let Some(ax) = &self.cfg.axis {
            let x = match ax.axis {
                Axis::X => pos.x,
                Axis::Y => pos.y,
                Axis::Z => pos.z,
            };
            let (a, b) = (ax.from.at, ax.to.at);
            let t = if a == b {
                if x < a {
                    0.0
                } else {
                    1.0
                }
            } else {
                ((x - a) / (b - a)).clamp(0.0, 1.0)
            };
            let mut w = Weights::default();
            w.add_scaled(&ax.from.weights, 1.0 - t);
            w.add_scaled(&ax.to.weights, t);
            return w;
        }
        *base
    }
}

/// Where a point of the current mesh came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Origin {
    Input,
    Vertex,
    Edge,
    Face,
}

/// `steps` iterations of the weighted Catmull–Clark scheme.
pub fn catmull_clark_weighted(
    mesh: &PolyMesh,
    steps: usize,
    cfg: &WeightedConfig,
    features: &Features,
) -> Result<PolyMesh, SubdivisionError> {
    catmull_clark_weighted_tracked(mesh, steps, cfg, features, None).map(|s| s.mesh)
}

/// [`catmull_clark_weighted`] with the face attributes of
/// [`super::lineage`] (group: the face group of the configuration plus one,
/// 0 for faces in none; input faces included) and an observer of every
/// generation.
pub fn catmull_clark_weighted_tracked(
    mesh: &PolyMesh,
    steps: usize,
    cfg: &WeightedConfig,
    features: &Features,
    observer: Option<&mut StepObserver<'_>>,
) -> Result<Subdivided, SubdivisionError> {
    let he0 = mesh.half_edges()?;
    let (creases, corners) = features.resolve(mesh, &he0)?;
    // Validate the configuration against the input.
    let edge_set: HashSet<[u32; 2]> = he0.edges.iter().copied().collect();
    let mut vertex_group: HashMap<u32, usize> = HashMap::new();
    for (g, grp) in cfg.vertex_groups.iter().enumerate() {
        for &v in &grp.vertices {
            if v as usize >= mesh.points.len() || he0.vertex_out[v as usize] == NO_TWIN {
                return Err(SubdivisionError::NoSuchVertex(v));
            }
            vertex_group.insert(v, g);
        }
    }
    let mut face_group: Vec<Option<usize>> = vec![None; mesh.faces.len()];
    for (g, grp) in cfg.face_groups.iter().enumerate() {
        for &f in &grp.faces {
            match face_group.get_mut(f as usize) {
                Some(slot) => *slot = Some(g),
                None => return Err(SubdivisionError::NoSuchFace(f)),
            }
        }
    }
    // Locked edges with their range of iterations [start, end).
    let mut locked: HashMap<[u32; 2], (usize, usize)> = HashMap::new();
    for grp in &cfg.locked_edges {
        for &[a, b] in &grp.edges {
            let e = sorted_pair(a, b);
            if !edge_set.contains(&e) {
                return Err(SubdivisionError::NoSuchEdge(e));
            }
            if grp.iterations > 0 {
                let end = grp.start.saturating_add(grp.iterations);
                let l = locked.entry(e).or_insert((grp.start, end));
                *l = (l.0.min(grp.start), l.1.max(end));
            }
        }
    }
    if let Some(att) = &cfg.attractors {
        if att.tightness.is_nan() || att.tightness <= 0.0 || !att.tightness.is_finite() {
            return Err(SubdivisionError::BadParameter(format!(
                "attractor tightness must be a positive number, not {}",
                att.tightness
            )));
        }
        if att
            .sets
            .iter()
            .any(|s| s.strength < 0.0 || !s.strength.is_finite())
        {
            return Err(SubdivisionError::BadParameter(
                "attractor strengths must be non-negative numbers".into(),
            ));
        }
    }
    // Distance scale: the diagonal of the box around the input and the sets.
    let mut scale = 1.0;
    if let Some((mut lo, mut hi)) = mesh.bounding_box() {
        if let Some(att) = &cfg.attractors {
            for s in &att.sets {
                lo = lo.min(DVec3::from_array(s.position));
                hi = hi.max(DVec3::from_array(s.position));
            }
        }
        let d = lo.distance(hi);
        if d > 0.0 {
            scale = d;
        }
    }
    let spatial = Spatial { cfg, scale };
    let mut mu_pattern: HashMap<(u32, u32), f64> = HashMap::new();
    for (key, &mu) in &cfg.mu_by_pattern {
        let parsed = key
            .strip_suffix('E')
            .and_then(|k| k.split_once('F'))
            .and_then(|(f, e)| Some((f.parse::<u32>().ok()?, e.parse::<u32>().ok()?)));
        match parsed {
            Some(fe) => {
                mu_pattern.insert(fe, mu);
            }
            None => {
                return Err(SubdivisionError::BadParameter(format!(
                    "mu_by_pattern key '{key}' is not a face/edge motif such as \"4F4E\""
                )))
            }
        }
    }
    let mut origin = vec![Origin::Input; mesh.points.len()];
    let group_id = |g: Option<usize>| g.map_or(0, |g| g as u32 + 1);
    let mut attributes = FaceAttributes::input(mesh.faces.len());
    attributes.group = face_group.iter().map(|&g| group_id(g)).collect();
    run_steps(
        mesh,
        he0,
        creases,
        steps,
        attributes,
        observer,
        |it, cur, h, creases| {
            let base = cfg.iteration_weights(it);
            let (curve, roles) = classify(h, creases, &corners);
            let vertex_locked: Vec<bool> = (0..cur.points.len())
                .map(|v| {
                    vertex_group.get(&(v as u32)).is_some_and(|&g| {
                        let grp = &cfg.vertex_groups[g];
                        grp.lock_start <= it
                            && it < grp.lock_start.saturating_add(grp.lock_iterations)
                    })
                })
                .collect();
            let active_locks: HashSet<[u32; 2]> = locked
                .iter()
                .filter(|(_, &(start, end))| start <= it && it < end)
                .map(|(&e, _)| e)
                .collect();
            let ctx = StepContext {
                mesh: cur,
                he: h,
                curve: &curve,
                roles: &roles,
                origin: &origin,
                face_group: &face_group,
                vertex_group: &vertex_group,
                vertex_locked: &vertex_locked,
                locked: &active_locks,
                cfg,
                spatial: &spatial,
                mu_pattern: &mu_pattern,
                base,
                first: it == 0,
            };
            let points = ctx.points();
            let faces = catmull_clark_faces(cur, h);
            // Bookkeeping for the next iteration.
            let nv = cur.points.len();
            let ne = h.edges.len();
            let mut next_origin = vec![Origin::Vertex; nv];
            next_origin.extend(std::iter::repeat_n(Origin::Edge, ne));
            next_origin.extend(std::iter::repeat_n(Origin::Face, cur.faces.len()));
            let mut next_group = Vec::with_capacity(faces.len());
            for (f, face) in cur.faces.iter().enumerate() {
                next_group.extend(std::iter::repeat_n(face_group[f], face.len()));
            }
            let mut next_locked = HashMap::new();
            for (e, pair) in h.edges.iter().enumerate() {
                if let Some(&(start, end)) = locked.get(pair) {
                    if it + 1 < end {
                        let m = (nv + e) as u32;
                        next_locked.insert(sorted_pair(pair[0], m), (start, end));
                        next_locked.insert(sorted_pair(m, pair[1]), (start, end));
                    }
                }
            }
            origin = next_origin;
            let (parent, _) = corner_children(cur);
            let group = next_group.iter().map(|&g| group_id(g)).collect();
            face_group = next_group;
            locked = next_locked;
            Step {
                mesh: PolyMesh { points, faces },
                creases: split_creases(cur, h, creases),
                parent,
                group,
            }
        },
    )
}

struct StepContext<'a> {
    mesh: &'a PolyMesh,
    he: &'a HalfEdges,
    curve: &'a [bool],
    roles: &'a [Role],
    origin: &'a [Origin],
    face_group: &'a [Option<usize>],
    vertex_group: &'a HashMap<u32, usize>,
    vertex_locked: &'a [bool],
    locked: &'a HashSet<[u32; 2]>,
    cfg: &'a WeightedConfig,
    spatial: &'a Spatial<'a>,
    mu_pattern: &'a HashMap<(u32, u32), f64>,
    base: Weights,
    first: bool,
}

impl StepContext<'_> {
    fn face_weights(&self, f: usize, centroid: DVec3) -> Weights {
        match self.face_group[f] {
            Some(g) => self.cfg.face_groups[g].weights,
            None => self.spatial.at(&self.base, centroid),
        }
    }

    fn mu(&self, valence: &[u32], faces_at: &[u32], v: u32) -> f64 {
        let key = (faces_at[v as usize], valence[v as usize]);
        if let Some(&m) = self.mu_pattern.get(&key) {
            return m;
        }
        self.cfg
            .mu_by_valence
            .get(&valence[v as usize])
            .copied()
            .unwrap_or(0.0)
    }

    fn points(&self) -> Vec<DVec3> {
        let mesh = self.mesh;
        let he = self.he;
        let p = &mesh.points;
        let valence = he.valences();
        let faces_at = he.faces_at();
        // Unit normals and √area of the faces.
        let normals: Vec<(DVec3, f64)> = (0..mesh.faces.len())
            .into_par_iter()
            .map(|f| {
                let n = mesh.face_newell(f);
                (n.normalize_or_zero(), (n.length() * 0.5).sqrt())
            })
            .collect();
        // Face points, eqs. 1, 4, 10.
        let fp: Vec<DVec3> = (0..mesh.faces.len())
            .into_par_iter()
            .map(|f| {
                let face = &mesh.faces[f];
                let n = face.len();
                let mut c = DVec3::ZERO;
                for &v in face {
                    c += p[v as usize];
                }
                let centroid = c / n as f64;
                let w = self.face_weights(f, centroid);
                let kinds: Vec<Origin> = face.iter().map(|&v| self.origin[v as usize]).collect();
                let pattern = !self.first && n == 4 && {
                    let k = kinds.iter().position(|&o| o == Origin::Vertex);
                    k.is_some_and(|k| {
                        kinds[(k + 1) % 4] == Origin::Edge
                            && kinds[(k + 2) % 4] == Origin::Face
                            && kinds[(k + 3) % 4] == Origin::Edge
                    })
                };
                let mut s = DVec3::ZERO;
                for (k, &v) in face.iter().enumerate() {
                    let coef = if pattern {
                        match kinds[k] {
                            Origin::Vertex => 1.0 + w.face_vertex,
                            Origin::Face => 1.0 + w.face_face,
                            _ => 1.0 - (w.face_vertex + w.face_face) / 2.0,
                        }
                    } else {
                        1.0
                    };
                    s += p[v as usize] * coef;
                }
                let (nrm, size) = normals[f];
                let mut fpt = s / n as f64 + nrm * size * w.face_extrude;
                let mut att = DVec3::ZERO;
                for &v in face {
                    att += (p[v as usize] - fpt) * self.mu(&valence, &faces_at, v);
                }
                fpt += att / n as f64 * w.face_attract;
                fpt
            })
            .collect();
        // Edge points, eqs. 2, 11.
        let edge_pts: Vec<DVec3> = (0..he.edges.len())
            .into_par_iter()
            .map(|e| {
                let [a, b] = he.edges[e];
                let (pa, pb) = (p[a as usize], p[b as usize]);
                let pp = pa + pb;
                if self.curve[e] || self.locked.contains(&he.edges[e]) {
                    return pp * 0.5;
                }
                let h = he.edge_half[e];
                let t = he.twin[h as usize];
                let (f1, f2) = (he.face[h as usize] as usize, he.face[t as usize] as usize);
                let mid = pp * 0.5;
                let w = match (self.face_group[f1], self.face_group[f2]) {
                    (Some(g1), Some(g2)) if g1 == g2 => self.cfg.face_groups[g1].weights,
                    _ => self.spatial.at(&self.base, mid),
                };
                let ff = fp[f1] + fp[f2];
                let nrm = (normals[f1].0 + normals[f2].0).normalize_or_zero();
                let size = (normals[f1].1 + normals[f2].1) * 0.5;
                let mut ept = (ff * (1.0 + w.edge) + pp * (1.0 - w.edge)) * 0.25
                    + nrm * size * w.edge_extrude;
                let att = (pa - ept) * self.mu(&valence, &faces_at, a)
                    + (pb - ept) * self.mu(&valence, &faces_at, b);
                ept += att * w.edge_attract;
                ept
            })
            .collect();
        // Vertices at the end of a locked edge stay.
        let mut on_locked = vec![false; p.len()];
        for pair in self.locked {
            on_locked[pair[0] as usize] = true;
            on_locked[pair[1] as usize] = true;
        }
        // Vertex points, eq. 3.
        let vertex_pts: Vec<DVec3> = (0..p.len())
            .into_par_iter()
            .map(|v| {
                if self.vertex_locked[v] || on_locked[v] {
                    return p[v];
                }
                match self.roles[v] {
                    Role::Smooth => {
                        let w = match self.vertex_group.get(&(v as u32)) {
                            Some(&g) if self.cfg.vertex_groups[g].weights.is_some() => {
                                self.cfg.vertex_groups[g].weights.unwrap_or_default()
                            }
                            _ => self.spatial.at(&self.base, p[v]),
                        };
                        let mut fs = DVec3::ZERO;
                        let mut rs = DVec3::ZERO;
                        let mut nsum = DVec3::ZERO;
                        let mut size = 0.0;
                        let mut k = 0usize;
                        for h in he.outgoing(v as u32) {
                            let f = he.face[h as usize] as usize;
                            fs += fp[f];
                            rs += (p[v] + p[he.dest(h) as usize]) * 0.5;
                            nsum += normals[f].0;
                            size += normals[f].1;
                            k += 1;
                        }
                        let n = k as f64;
                        let (fbar, rbar) = (fs / n, rs / n);
                        let nrm = nsum.normalize_or_zero() * (size / n);
                        (fbar * (1.0 + w.vertex)
                            + rbar * (2.0 * (1.0 - w.vertex / 2.0))
                            + p[v] * (n - 3.0))
                            / n
                            + nrm * w.vertex_extrude
                    }
                    Role::Crease(curve_nbrs) => crease_vertex_point(p, v, curve_nbrs),
                    Role::Corner | Role::Unused => p[v],
                }
            })
            .collect();
        in_point_order(vertex_pts, &edge_pts, &fp)
    }
}
