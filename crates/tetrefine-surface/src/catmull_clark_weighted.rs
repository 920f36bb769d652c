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
//! # Where the weights come from: the composition rule
//!
//! For an element (face, edge or vertex) in iteration k (from 0), each of
//! the nine weights w is, separately,
//!
//! ```text
//! w = b · Π_{scale fields} s_F(x) + Σ_{add fields} a_F(x)
//! ```
//!
//! * b, the **base**: the iteration's weights `iterations[k]` (the last entry
//!   repeating, zero if there are none), unless a group gives the element its
//!   own — a face group for a face (for an edge: the group of both its
//!   faces), a vertex group with `weights` for a vertex.
//! * the **fields**, each with `"mode": "scale"` (the default) or `"add"`,
//!   and optionally `"active": [first, last]` (the iterations, inclusive, in
//!   which it acts): `attractors` (eqs. 8, 9), `axis`, `radial`,
//!   `spherical`, `edge_distance`, `vertex_distance` and `planarity`, each
//!   given as one object or a list of them (several gradients of one kind,
//!   say with different `active` iterations, which then compose too). A
//!   field's weight sets are partial: a set names only the weights it
//!   changes, the others get the mode's neutral value (factor 1, offset 0),
//!   so a set leaves them alone.
//!
//! Why this rule: the paper's weights are *non-stationary* (per iteration)
//! and *non-uniform* (in space), and its figures 9 and 10 use both at once.
//! Multiplying keeps the iteration schedule in charge of the magnitude and
//! lets space shape it — the paper's "amplify or attenuate" (planarity), and
//! a factor 0 switches a weight off where the schedule has it; adding lets a
//! field bring in a weight the schedule does not have (the sets of weights
//! placed in the environment). Products and sums commute, so the order of
//! the fields does not matter, and with no field acting the base is used
//! unchanged (bit for bit). Groups replace only the base, so tagged regions
//! still follow the gradients.
//!
//! What each field computes at the element's position x (face centroid, edge
//! midpoint, vertex), by piecewise-linear interpolation between its `stops`
//! (`{"at": a, "weights": {...}}`, `at` strictly increasing; the end stops'
//! values outside them):
//!
//! * `attractors`: Σₐ cₐ Wₐ with cₐ = (1 − dₐ)ᵗ hₐ / Σ_b (1 − d_b)ᵗ h_b
//!   (eqs. 8, 9; t the tightness, hₐ the strength, dₐ ∈ [0, 1] the distance
//!   divided by the diagonal of the box around the input and the sets);
//!   no effect where every influence is zero. As printed, the cₐ sum to 1,
//!   so a single set gives the same value everywhere; `background` h₀ > 0
//!   adds a set of neutral weights at distance 0 everywhere (a term h₀ in
//!   the denominator, h₀/Σ times the neutral value), so that sets fade out
//!   with distance;
//! * `axis`: linear between the stops `from` and `to` along x, y or z;
//! * `radial`: over the distance from the line through `center` along
//!   `direction`;
//! * `spherical`: over the distance from `center`;
//! * `edge_distance`, `vertex_distance`: over the distance from the nearest
//!   edge segment, or vertex, of the input mesh ("a subdivided face's
//!   distance to an original edge or an original point");
//! * `planarity`: over the scaled planarity — for a face of n ≥ 4 corners
//!   the mean over its corners of the distance of the corner from the plane
//!   through the next three corners divided by those three's perimeter (the
//!   paper's measure for a quad), 0 for a triangle; an edge takes the mean of
//!   its two faces, a vertex that of the faces around it.
//!
//! Distances are in model units (attractors excepted, as in the paper).
//! The distances to the input's edges and vertices are found by looking at
//! every one of them, which suits the small control meshes the paper starts
//! from (platonic solids), not inputs of many thousands of edges.
//!
//! # Locks and merging
//!
//! Face groups pass to the faces a face is split into; vertex groups hold
//! original vertices (which keep their ids). A vertex group with
//! `lock_iterations` = L and `lock_start` = N keeps its vertices in place in
//! iterations N .. N + L (N = 0: the first L); a locked edge with
//! `iterations` = L and `start` = N keeps the endpoints of the chain it has
//! been split into by iteration N in place and their edge points at the
//! midpoints in iterations N .. N + L, so the chain stays exactly where it
//! was when the lock began (the paper's figure 9 locks after the 8th
//! iteration). Locks of one edge in several groups join into one range.
//!
//! `merge_distance` d > 0 joins, after every iteration, the points closer
//! than d ("a minimum distance beneath which two close vertices are
//! joined"): in id order each point joins the first earlier kept point
//! closer than d (so the joined point is where that one was), faces are
//! renumbered, a face that now passes through a point twice is split there
//! into simple loops (each a face of the same parent and group), and loops
//! of fewer than three corners are removed; a point no face uses any more
//! stays in the list, where it was joined. The joined vertex takes the edges of both, which changes
//! the face/edge motifs of `mu_by_pattern`; if the surface is no longer an
//! oriented manifold the next iteration stops with the topology error.
//!
//! # The JSON file
//!
//! [`WeightedConfig::from_json_file`] reads the fields of
//! [`WeightedConfig`]; every field is optional, unknown fields are refused,
//! and [`WeightedConfig::validate`] checks the ranges. Example:
//!
//! ```json
//! {
//!   "iterations": [ { "vertex_extrude": 0.1 }, { "edge": 0.3, "vertex": -0.2 } ],
//!   "spherical": { "center": [0.5, 0.5, 0.5], "stops": [
//!       { "at": 0.5, "weights": { "edge": 0 } },
//!       { "at": 1.0, "weights": { "edge": 2 } } ] },
//!   "axis": { "axis": "z", "mode": "add", "active": [1, 1],
//!             "from": { "at": 0 }, "to": { "at": 1, "weights": { "face_extrude": 0.2 } } },
//!   "merge_distance": 1e-6
//! }
//! ```

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

/// Number of weights in a [`Weights`] set.
const NW: usize = 9;

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
    fn to_array(self) -> [f64; NW] {
        [
            self.face_extrude,
            self.edge,
            self.edge_extrude,
            self.vertex,
            self.vertex_extrude,
            self.face_vertex,
            self.face_face,
            self.face_attract,
            self.edge_attract,
        ]
    }

    fn from_array(a: [f64; NW]) -> Weights {
        Weights {
            face_extrude: a[0],
            edge: a[1],
            edge_extrude: a[2],
            vertex: a[3],
            vertex_extrude: a[4],
            face_vertex: a[5],
            face_face: a[6],
            face_attract: a[7],
            edge_attract: a[8],
        }
    }
}

/// The name of one weight of [`Weights`], as a key of a [`WeightSet`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WeightName {
    /// [`Weights::face_extrude`].
    FaceExtrude,
    /// [`Weights::edge`].
    Edge,
    /// [`Weights::edge_extrude`].
    EdgeExtrude,
    /// [`Weights::vertex`].
    Vertex,
    /// [`Weights::vertex_extrude`].
    VertexExtrude,
    /// [`Weights::face_vertex`].
    FaceVertex,
    /// [`Weights::face_face`].
    FaceFace,
    /// [`Weights::face_attract`].
    FaceAttract,
    /// [`Weights::edge_attract`].
    EdgeAttract,
}

/// A partial set of weights held by a spatial field: only the weights it
/// names are modulated; every other weight gets the field's neutral value
/// (1 for [`Mode::Scale`], 0 for [`Mode::Add`]), so the set leaves it alone.
pub type WeightSet = BTreeMap<WeightName, f64>;

fn filled(set: &WeightSet, neutral: f64) -> [f64; NW] {
    let mut a = [neutral; NW];
    for (&k, &v) in set {
        a[k as usize] = v;
    }
    a
}

/// How a spatial field acts on the base weights (module docs, "Composition").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// The field's value multiplies the base weight (neutral value 1).
    #[default]
    Scale,
    /// The field's value is added to the scaled base weight (neutral 0).
    Add,
}

impl Mode {
    fn neutral(self) -> f64 {
        match self {
            Mode::Scale => 1.0,
            Mode::Add => 0.0,
        }
    }
}

/// A set of weights placed in space (eqs. 8, 9).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AttractorSet {
    /// Where the set is.
    pub position: [f64; 3],
    /// Its strength h (non-negative).
    pub strength: f64,
    /// Its weights (factors or offsets, per the field's mode).
    pub weights: WeightSet,
}

/// Weights from sets placed in space (eqs. 8, 9).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Attractors {
    /// The tightness exponent t (positive; the paper uses t > 1).
    pub tightness: f64,
    /// The sets.
    pub sets: Vec<AttractorSet>,
    /// Strength h₀ of a background set of neutral weights that is at
    /// distance 0 everywhere (default 0, the paper's eqs. 8, 9): with
    /// h₀ > 0 a single set no longer gives uniform weights but fades to
    /// neutral away from its position.
    pub background: f64,
    /// Scale (default) or add.
    pub mode: Mode,
    /// Iterations `[first, last]` (0-based, inclusive) in which the field
    /// acts; all if absent.
    pub active: Option<[usize; 2]>,
}

impl Default for Attractors {
    fn default() -> Self {
        Attractors {
            tightness: 2.0,
            sets: Vec::new(),
            background: 0.0,
            mode: Mode::Scale,
            active: None,
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

/// One stop of a gradient: the field's weights at a coordinate, a distance
/// or a planarity `at`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Stop {
    /// Where the stop is (coordinate, distance or planarity).
    pub at: f64,
    /// The weights there (factors or offsets, per the field's mode).
    pub weights: WeightSet,
}

/// One end of an axis gradient (the same as a [`Stop`]).
pub type AxisStop = Stop;

/// Weights interpolated linearly along an axis between two stops (the
/// nearer stop's outside them).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisGradient {
    /// The axis.
    pub axis: Axis,
    /// First stop.
    pub from: Stop,
    /// Second stop.
    pub to: Stop,
    /// Scale (default) or add.
    #[serde(default)]
    pub mode: Mode,
    /// Iterations `[first, last]` in which it acts; all if absent.
    #[serde(default)]
    pub active: Option<[usize; 2]>,
}

/// Weights interpolated over the distance from a line (a radial gradient).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RadialGradient {
    /// A point of the line.
    pub center: [f64; 3],
    /// The line's direction (non-zero; need not be unit).
    pub direction: [f64; 3],
    /// Stops by distance from the line, `at` strictly increasing.
    pub stops: Vec<Stop>,
    /// Scale (default) or add.
    pub mode: Mode,
    /// Iterations `[first, last]` in which it acts; all if absent.
    pub active: Option<[usize; 2]>,
}

/// Weights interpolated over the distance from a point (a spherical
/// gradient).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SphericalGradient {
    /// The centre.
    pub center: [f64; 3],
    /// Stops by distance from the centre, `at` strictly increasing.
    pub stops: Vec<Stop>,
    /// Scale (default) or add.
    pub mode: Mode,
    /// Iterations `[first, last]` in which it acts; all if absent.
    pub active: Option<[usize; 2]>,
}

/// Weights interpolated over one scalar of the element (distance to the
/// input's edges or vertices, or planarity).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Ramp {
    /// Stops by the scalar, `at` strictly increasing.
    pub stops: Vec<Stop>,
    /// Scale (default) or add.
    pub mode: Mode,
    /// Iterations `[first, last]` in which it acts; all if absent.
    pub active: Option<[usize; 2]>,
}

/// A group of input vertices with its own weights and/or locked.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VertexGroup {
    /// Input vertex ids.
    pub vertices: Vec<u32>,
    /// Base weights of these vertices' vertex points (none: the
    /// iteration's), modulated by the spatial fields like those.
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
    /// Base weights of the faces' face points (and of edges inside the
    /// group), replacing the iteration's and modulated by the fields.
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
    /// Base weights per iteration; the last entry repeats.
    pub iterations: Vec<Weights>,
    /// Attractor/deflector value μ by vertex valence (eqs. 10, 11).
    pub mu_by_valence: BTreeMap<u32, f64>,
    /// Attractor/deflector value μ by face/edge motif, `"<faces>F<edges>E"`
    /// (eqs. 10, 11; the paper's figure 3); it takes precedence over
    /// `mu_by_valence`.
    pub mu_by_pattern: BTreeMap<String, f64>,
    /// Weight sets placed in space (eqs. 8, 9).
    #[serde(deserialize_with = "one_or_many")]
    pub attractors: Vec<Attractors>,
    /// A linear gradient along an axis.
    #[serde(deserialize_with = "one_or_many")]
    pub axis: Vec<AxisGradient>,
    /// A radial gradient (distance from a line).
    #[serde(deserialize_with = "one_or_many")]
    pub radial: Vec<RadialGradient>,
    /// A spherical gradient (distance from a point).
    #[serde(deserialize_with = "one_or_many")]
    pub spherical: Vec<SphericalGradient>,
    /// A gradient over the distance to the nearest edge of the input.
    #[serde(deserialize_with = "one_or_many")]
    pub edge_distance: Vec<Ramp>,
    /// A gradient over the distance to the nearest vertex of the input.
    #[serde(deserialize_with = "one_or_many")]
    pub vertex_distance: Vec<Ramp>,
    /// A gradient over the scaled planarity (module docs).
    #[serde(deserialize_with = "one_or_many")]
    pub planarity: Vec<Ramp>,
    /// Points of a step closer than this are joined into one (0: never).
    pub merge_distance: f64,
    /// Vertex groups.
    pub vertex_groups: Vec<VertexGroup>,
    /// Face groups.
    pub face_groups: Vec<FaceGroup>,
    /// Locked edges.
    pub locked_edges: Vec<LockedEdges>,
}

/// Reads one object or a list of them (a field given once, or several
/// times, each with its own `active` iterations).
fn one_or_many<'de, D, T>(d: D) -> Result<Vec<T>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    use serde::de::value::{MapAccessDeserializer, SeqAccessDeserializer};
    use serde::de::{MapAccess, SeqAccess, Visitor};
    struct OneOrMany<T>(std::marker::PhantomData<T>);
    impl<'de, T: Deserialize<'de>> Visitor<'de> for OneOrMany<T> {
        type Value = Vec<T>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("an object, a list of objects or null")
        }
        fn visit_unit<E: serde::de::Error>(self) -> Result<Vec<T>, E> {
            Ok(Vec::new())
        }
        fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Vec<T>, A::Error> {
            T::deserialize(MapAccessDeserializer::new(map)).map(|t| vec![t])
        }
        fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Vec<T>, A::Error> {
            Vec::<T>::deserialize(SeqAccessDeserializer::new(seq))
        }
    }
    d.deserialize_any(OneOrMany(std::marker::PhantomData))
}

/// Byte offset of (1-based) `line`, `column` in `text`.
fn offset_of(text: &str, line: usize, column: usize) -> usize {
    let mut off = 0;
    for (k, l) in text.split_inclusive('\n').enumerate() {
        if k + 1 == line {
            return (off + column.saturating_sub(1)).min(text.len());
        }
        off += l.len();
    }
    text.len()
}

/// The last `"key":` before byte `end` of `text`, for error messages.
fn key_before(text: &str, end: usize) -> Option<&str> {
    let head = text.get(..end)?;
    let colon = head.rfind(':')?;
    let before = head[..colon].trim_end();
    let close = before.strip_suffix('"')?;
    let open = close.rfind('"')?;
    Some(&close[open + 1..])
}

/// `field.sub` for a field given once, `field[n].sub` for one of a list
/// (`sub` empty: the field itself).
fn field_name(field: &str, n: usize, count: usize, sub: &str) -> String {
    let head = if count > 1 {
        format!("{field}[{n}]")
    } else {
        field.to_string()
    };
    if sub.is_empty() {
        head
    } else {
        format!("{head}.{sub}")
    }
}

fn check_finite(what: &str, x: f64) -> Result<(), String> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(format!("field `{what}` must be a finite number, not {x}"))
    }
}

fn check_weights(what: &str, w: &Weights) -> Result<(), String> {
    const NAMES: [&str; NW] = [
        "face_extrude",
        "edge",
        "edge_extrude",
        "vertex",
        "vertex_extrude",
        "face_vertex",
        "face_face",
        "face_attract",
        "edge_attract",
    ];
    for (k, x) in w.to_array().into_iter().enumerate() {
        check_finite(&format!("{what}.{}", NAMES[k]), x)?;
    }
    Ok(())
}

fn check_set(what: &str, set: &WeightSet) -> Result<(), String> {
    for (k, &x) in set {
        let name = serde_json::to_string(k).unwrap_or_default();
        check_finite(&format!("{what}.{}", name.trim_matches('"')), x)?;
    }
    Ok(())
}

fn check_active(what: &str, active: Option<[usize; 2]>) -> Result<(), String> {
    match active {
        Some([a, b]) if a > b => Err(format!(
            "field `{what}.active` must be [first, last] with first <= last, not [{a}, {b}]"
        )),
        _ => Ok(()),
    }
}

fn check_stops(what: &str, stops: &[Stop]) -> Result<(), String> {
    if stops.is_empty() {
        return Err(format!("field `{what}.stops` needs at least one stop"));
    }
    for (k, s) in stops.iter().enumerate() {
        check_finite(&format!("{what}.stops[{k}].at"), s.at)?;
        check_set(&format!("{what}.stops[{k}].weights"), &s.weights)?;
        if k > 0 && s.at <= stops[k - 1].at {
            return Err(format!(
                "field `{what}.stops[{k}].at` must be greater than the previous stop's ({} <= {})",
                s.at,
                stops[k - 1].at
            ));
        }
    }
    Ok(())
}

fn parse_pattern(key: &str) -> Option<(u32, u32)> {
    key.strip_suffix('E')
        .and_then(|k| k.split_once('F'))
        .and_then(|(f, e)| Some((f.parse::<u32>().ok()?, e.parse::<u32>().ok()?)))
}

impl WeightedConfig {
    /// Reads a configuration from a JSON file and checks it with
    /// [`WeightedConfig::validate`]; errors name the file, the field and,
    /// for JSON errors, the line.
    pub fn from_json_file(path: &Path) -> Result<WeightedConfig, IoError> {
        let bytes = tetrefine::io::read_bytes(path)?;
        let cfg: WeightedConfig = serde_json::from_slice(&bytes).map_err(|e| {
            let line = Some(e.line()).filter(|&l| l > 0);
            let text = String::from_utf8_lossy(&bytes);
            let near = line
                .and_then(|l| key_before(&text, offset_of(&text, l, e.column())))
                .map(str::to_string);
            match near {
                // serde names unknown and missing fields itself; a bad
                // value (NaN, a string for a number, …) is named here.
                Some(k)
                    if !["unknown", "missing field"]
                        .iter()
                        .any(|m| e.to_string().contains(m)) =>
                {
                    IoError::at(
                        path,
                        line.unwrap_or(1),
                        format!("invalid weights file: field `{k}`: {e}"),
                    )
                }
                _ => IoError::decode(path, line, "invalid weights file", e),
            }
        })?;
        cfg.validate()
            .map_err(|m| IoError::file(path, format!("invalid weights file: {m}")))?;
        Ok(cfg)
    }

    /// Checks every value against its range (finite weights, positive
    /// tightness, non-negative strengths and merge distance, increasing
    /// stops, `active` ranges, μ pattern keys); the error names the field.
    pub fn validate(&self) -> Result<(), String> {
        for (k, w) in self.iterations.iter().enumerate() {
            check_weights(&format!("iterations[{k}]"), w)?;
        }
        for (v, &mu) in &self.mu_by_valence {
            check_finite(&format!("mu_by_valence.{v}"), mu)?;
        }
        for (key, &mu) in &self.mu_by_pattern {
            if parse_pattern(key).is_none() {
                return Err(format!(
                    "field `mu_by_pattern`: key '{key}' is not a face/edge motif such as \"4F4E\""
                ));
            }
            check_finite(&format!("mu_by_pattern.{key}"), mu)?;
        }
        for (n, att) in self.attractors.iter().enumerate() {
            let at = |f: &str| field_name("attractors", n, self.attractors.len(), f);
            if !(att.tightness.is_finite() && att.tightness > 0.0) {
                return Err(format!(
                    "field `{}` must be a positive number, not {}",
                    at("tightness"),
                    att.tightness
                ));
            }
            if !(att.background.is_finite() && att.background >= 0.0) {
                return Err(format!(
                    "field `{}` must be a non-negative number, not {}",
                    at("background"),
                    att.background
                ));
            }
            for (k, s) in att.sets.iter().enumerate() {
                if !(s.strength.is_finite() && s.strength >= 0.0) {
                    return Err(format!(
                        "field `{}` must be a non-negative number, not {}",
                        at(&format!("sets[{k}].strength")),
                        s.strength
                    ));
                }
                for (j, &x) in s.position.iter().enumerate() {
                    check_finite(&at(&format!("sets[{k}].position[{j}]")), x)?;
                }
                check_set(&at(&format!("sets[{k}].weights")), &s.weights)?;
            }
            check_active(&at(""), att.active)?;
        }
        for (n, ax) in self.axis.iter().enumerate() {
            let at = |f: &str| field_name("axis", n, self.axis.len(), f);
            check_finite(&at("from.at"), ax.from.at)?;
            check_finite(&at("to.at"), ax.to.at)?;
            check_set(&at("from.weights"), &ax.from.weights)?;
            check_set(&at("to.weights"), &ax.to.weights)?;
            check_active(&at(""), ax.active)?;
        }
        for (n, r) in self.radial.iter().enumerate() {
            let at = |f: &str| field_name("radial", n, self.radial.len(), f);
            for (j, &x) in r.center.iter().chain(&r.direction).enumerate() {
                let f = if j < 3 { "center" } else { "direction" };
                check_finite(&at(&format!("{f}[{}]", j % 3)), x)?;
            }
            if DVec3::from_array(r.direction).length_squared() == 0.0 {
                return Err(format!("field `{}` must not be zero", at("direction")));
            }
            check_stops(&at(""), &r.stops)?;
            check_active(&at(""), r.active)?;
        }
        for (n, s) in self.spherical.iter().enumerate() {
            let at = |f: &str| field_name("spherical", n, self.spherical.len(), f);
            for (j, &x) in s.center.iter().enumerate() {
                check_finite(&at(&format!("center[{j}]")), x)?;
            }
            check_stops(&at(""), &s.stops)?;
            check_active(&at(""), s.active)?;
        }
        for (name, ramps) in [
            ("edge_distance", &self.edge_distance),
            ("vertex_distance", &self.vertex_distance),
            ("planarity", &self.planarity),
        ] {
            for (n, r) in ramps.iter().enumerate() {
                let at = field_name(name, n, ramps.len(), "");
                check_stops(&at, &r.stops)?;
                check_active(&at, r.active)?;
            }
        }
        if !(self.merge_distance.is_finite() && self.merge_distance >= 0.0) {
            return Err(format!(
                "field `merge_distance` must be a non-negative number, not {}",
                self.merge_distance
            ));
        }
        for (g, grp) in self.vertex_groups.iter().enumerate() {
            if let Some(w) = &grp.weights {
                check_weights(&format!("vertex_groups[{g}].weights"), w)?;
            }
        }
        for (g, grp) in self.face_groups.iter().enumerate() {
            check_weights(&format!("face_groups[{g}].weights"), &grp.weights)?;
        }
        Ok(())
    }

    /// The base weights of iteration `k` (no spatial or group variation).
    pub fn iteration_weights(&self, k: usize) -> Weights {
        match self.iterations.len() {
            0 => Weights::default(),
            n => self.iterations[k.min(n - 1)],
        }
    }

    /// Whether any spatial field acts in iteration `k`.
    fn any_field(&self, k: usize) -> bool {
        let on = |a: Option<[usize; 2]>| a.is_none_or(|[f, l]| f <= k && k <= l);
        self.attractors
            .iter()
            .any(|a| !a.sets.is_empty() && on(a.active))
            || self.axis.iter().any(|a| on(a.active))
            || self.radial.iter().any(|a| on(a.active))
            || self.spherical.iter().any(|a| on(a.active))
            || [&self.edge_distance, &self.vertex_distance, &self.planarity]
                .iter()
                .any(|r| r.iter().any(|r| on(r.active)))
    }
}

/// Piecewise-linear interpolation of the stops at `x` (the end stops'
/// values outside them).
fn ramp_at(stops: &[Stop], x: f64, neutral: f64) -> [f64; NW] {
    let k = stops.partition_point(|s| s.at <= x);
    if k == 0 {
        return filled(&stops[0].weights, neutral);
    }
    if k == stops.len() {
        return filled(&stops[k - 1].weights, neutral);
    }
    let (a, b) = (&stops[k - 1], &stops[k]);
    let t = (x - a.at) / (b.at - a.at);
    let (va, vb) = (filled(&a.weights, neutral), filled(&b.weights, neutral));
    std::array::from_fn(|i| va[i] * (1.0 - t) + vb[i] * t)
}

/// Distance from `p` to the segment `a`-`b`.
fn segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let d = b - a;
    let l = d.length_squared();
    let t = if l > 0.0 {
        ((p - a).dot(d) / l).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + d * t)
}

/// Scaled planarity of a face (module docs): the mean over its corners of
/// the distance of the corner from the plane through the next three,
/// divided by their perimeter.
fn face_planarity(mesh: &PolyMesh, f: usize) -> f64 {
    let face = &mesh.faces[f];
    let n = face.len();
    if n < 4 {
        return 0.0;
    }
    let p = |k: usize| mesh.points[face[k % n] as usize];
    let mut s = 0.0;
    for i in 0..n {
        let (a, b, c) = (p(i + 1), p(i + 2), p(i + 3));
        let normal = (b - a).cross(c - a).normalize_or_zero();
        let perimeter = a.distance(b) + b.distance(c) + c.distance(a);
        if perimeter > 0.0 {
            s += (p(i) - a).dot(normal).abs() / perimeter;
        }
    }
    s / n as f64
}

/// Where an element is, for the spatial fields.
#[derive(Clone, Copy)]
struct Place {
    pos: DVec3,
    planarity: f64,
}

/// Evaluates the spatial fields and composes them with the base weights.
struct Spatial<'a> {
    cfg: &'a WeightedConfig,
    scale: f64,
    input_points: Vec<DVec3>,
    input_edges: Vec<(DVec3, DVec3)>,
}

impl Spatial<'_> {
    /// The weights of an element at `place` in iteration `it` from its base
    /// weights: base ⊙ Π(scale fields) + Σ(add fields).
    fn at(&self, it: usize, base: &Weights, place: Place) -> Weights {
        if !self.cfg.any_field(it) {
            return *base;
        }
        let on = |a: Option<[usize; 2]>| a.is_none_or(|[f, l]| f <= it && it <= l);
        let mut mul = [1.0; NW];
        let mut add = [0.0; NW];
        let mut apply = |mode: Mode, v: [f64; NW]| {
            for i in 0..NW {
                match mode {
                    Mode::Scale => mul[i] *= v[i],
                    Mode::Add => add[i] += v[i],
                }
            }
        };
        let pos = place.pos;
        let cfg = self.cfg;
        for att in cfg.attractors.iter().filter(|a| on(a.active)) {
            let infl: Vec<f64> = att
                .sets
                .iter()
                .map(|s| {
                    let d = (pos.distance(DVec3::from_array(s.position)) / self.scale).min(1.0);
                    (1.0 - d).powf(att.tightness) * s.strength
                })
                .collect();
            let total: f64 = infl.iter().sum::<f64>() + att.background;
            if total > 0.0 && total.is_finite() {
                let mut v = [att.mode.neutral() * (att.background / total); NW];
                for (s, c) in att.sets.iter().zip(&infl) {
                    let w = filled(&s.weights, att.mode.neutral());
                    for i in 0..NW {
                        v[i] += w[i] * (c / total);
                    }
                }
                apply(att.mode, v);
            }
        }
        for ax in cfg.axis.iter().filter(|a| on(a.active)) {
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
            let n = ax.mode.neutral();
            let (va, vb) = (filled(&ax.from.weights, n), filled(&ax.to.weights, n));
            apply(
                ax.mode,
                std::array::from_fn(|i| va[i] * (1.0 - t) + vb[i] * t),
            );
        }
        for r in cfg.radial.iter().filter(|a| on(a.active)) {
            let c = DVec3::from_array(r.center);
            let d = DVec3::from_array(r.direction).normalize();
            let rel = pos - c;
            let dist = (rel - d * rel.dot(d)).length();
            apply(r.mode, ramp_at(&r.stops, dist, r.mode.neutral()));
        }
        for s in cfg.spherical.iter().filter(|a| on(a.active)) {
            let dist = pos.distance(DVec3::from_array(s.center));
            apply(s.mode, ramp_at(&s.stops, dist, s.mode.neutral()));
        }
        for r in cfg.edge_distance.iter().filter(|a| on(a.active)) {
            let dist = self
                .input_edges
                .iter()
                .map(|&(a, b)| segment_distance(pos, a, b))
                .fold(f64::INFINITY, f64::min);
            apply(r.mode, ramp_at(&r.stops, dist, r.mode.neutral()));
        }
        for r in cfg.vertex_distance.iter().filter(|a| on(a.active)) {
            let dist = self
                .input_points
                .iter()
                .map(|&q| pos.distance(q))
                .fold(f64::INFINITY, f64::min);
            apply(r.mode, ramp_at(&r.stops, dist, r.mode.neutral()));
        }
        for r in cfg.planarity.iter().filter(|a| on(a.active)) {
            apply(r.mode, ramp_at(&r.stops, place.planarity, r.mode.neutral()));
        }
        let b = base.to_array();
        Weights::from_array(std::array::from_fn(|i| b[i] * mul[i] + add[i]))
    }
}

/// Joins the points closer than `d`: each point, in id order, joins the
/// first earlier kept point closer than `d`, else is kept. Returns the new
/// id of every old point and the old ids of the kept points.
fn weld(points: &[DVec3], d: f64) -> (Vec<u32>, Vec<u32>) {
    let cell = |p: DVec3| {
        let c = (p / d).floor();
        (c.x as i64, c.y as i64, c.z as i64)
    };
    let mut grid: HashMap<(i64, i64, i64), Vec<u32>> = HashMap::new();
    let mut new_id = Vec::with_capacity(points.len());
    let mut kept: Vec<u32> = Vec::new();
    for (v, &p) in points.iter().enumerate() {
        let (cx, cy, cz) = cell(p);
        let mut best: Option<u32> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = grid.get(&(cx + dx, cy + dy, cz + dz)) {
                        for &k in list {
                            let q = points[kept[k as usize] as usize];
                            if p.distance(q) < d && best.is_none_or(|b| k < b) {
                                best = Some(k);
                            }
                        }
                    }
                }
            }
        }
        match best {
            Some(k) => new_id.push(k),
            None => {
                let k = kept.len() as u32;
                kept.push(v as u32);
                grid.entry((cx, cy, cz)).or_default().push(k);
                new_id.push(k);
            }
        }
    }
    (new_id, kept)
}

/// `face` renumbered by `new_id` and split into simple loops where it
/// passes through a point twice; loops of fewer than three corners (repeated
/// neighbours, slivers) are left out.
fn renumber_face(face: &[u32], new_id: &[u32]) -> Vec<Vec<u32>> {
    let mut stack: Vec<u32> = Vec::with_capacity(face.len());
    let mut loops = Vec::new();
    for &v in face {
        let n = new_id[v as usize];
        match stack.iter().position(|&x| x == n) {
            Some(k) => {
                let mut l = vec![n];
                l.extend(stack.drain(k + 1..));
                if l.len() >= 3 {
                    loops.push(l);
                }
            }
            None => stack.push(n),
        }
    }
    if stack.len() >= 3 {
        loops.push(stack);
    }
    loops
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
    cfg.validate().map_err(SubdivisionError::BadParameter)?;
    // The vertex group of every current vertex (input vertices keep their
    // ids unless points are merged, so this is carried along).
    let mut vgroup_of: Vec<Option<usize>> = vec![None; mesh.points.len()];
    for (g, grp) in cfg.vertex_groups.iter().enumerate() {
        for &v in &grp.vertices {
            if v as usize >= mesh.points.len() || he0.vertex_out[v as usize] == NO_TWIN {
                return Err(SubdivisionError::NoSuchVertex(v));
            }
            vgroup_of[v as usize] = Some(g);
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
    // Distance scale: the diagonal of the box around the input and the sets.
    let mut scale = 1.0;
    if let Some((mut lo, mut hi)) = mesh.bounding_box() {
        for att in &cfg.attractors {
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
    let spatial = Spatial {
        cfg,
        scale,
        input_points: (0..mesh.points.len())
            .filter(|&v| he0.vertex_out[v] != NO_TWIN)
            .map(|v| mesh.points[v])
            .collect(),
        input_edges: he0
            .edges
            .iter()
            .map(|&[a, b]| (mesh.points[a as usize], mesh.points[b as usize]))
            .collect(),
    };
    let mu_pattern: HashMap<(u32, u32), f64> = cfg
        .mu_by_pattern
        .iter()
        .filter_map(|(k, &mu)| Some((parse_pattern(k)?, mu)))
        .collect();
    let mut origin = vec![Origin::Input; mesh.points.len()];
    let group_id = |g: Option<usize>| g.map_or(0, |g| g as u32 + 1);
    let mut attributes = FaceAttributes::input(mesh.faces.len());
    attributes.group = face_group.iter().map(|&g| group_id(g)).collect();
    let done = run_steps(
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
                    vgroup_of[v].is_some_and(|g| {
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
                vgroup_of: &vgroup_of,
                vertex_locked: &vertex_locked,
                locked: &active_locks,
                cfg,
                spatial: &spatial,
                mu_pattern: &mu_pattern,
                base,
                first: it == 0,
                it,
            };
            let mut points = ctx.points();
            let mut faces = catmull_clark_faces(cur, h);
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
            let mut next_vgroup = vgroup_of.clone();
            next_vgroup.resize(points.len(), None);
            let (mut parent, _) = corner_children(cur);
            let mut next_creases = split_creases(cur, h, creases);
            if cfg.merge_distance > 0.0 {
                let (new_id, kept) = weld(&points, cfg.merge_distance);
                if kept.len() < points.len() {
                    let mut keep_faces = Vec::with_capacity(faces.len());
                    let mut renumbered = Vec::with_capacity(faces.len());
                    for (f, face) in faces.iter().enumerate() {
                        for nf in renumber_face(face, &new_id) {
                            keep_faces.push(f);
                            renumbered.push(nf);
                        }
                    }
                    faces = renumbered;
                    parent = keep_faces.iter().map(|&f| parent[f]).collect();
                    next_group = keep_faces.iter().map(|&f| next_group[f]).collect();
                    next_origin = kept.iter().map(|&v| next_origin[v as usize]).collect();
                    next_vgroup = kept.iter().map(|&v| next_vgroup[v as usize]).collect();
                    points = kept.iter().map(|&v| points[v as usize]).collect();
                    let remap = |pairs: &mut dyn Iterator<Item = [u32; 2]>| {
                        pairs
                            .map(|[a, b]| (new_id[a as usize], new_id[b as usize]))
                            .filter(|(a, b)| a != b)
                            .map(|(a, b)| sorted_pair(a, b))
                            .collect::<Vec<_>>()
                    };
                    next_creases = remap(&mut next_creases.into_iter()).into_iter().collect();
                    next_locked = next_locked
                        .into_iter()
                        .filter_map(|([a, b], r)| {
                            let (a, b) = (new_id[a as usize], new_id[b as usize]);
                            (a != b).then(|| (sorted_pair(a, b), r))
                        })
                        .collect();
                }
            }
            origin = next_origin;
            vgroup_of = next_vgroup;
            let group = next_group.iter().map(|&g| group_id(g)).collect();
            face_group = next_group;
            locked = next_locked;
            Step {
                mesh: PolyMesh { points, faces },
                creases: next_creases,
                parent,
                group,
            }
        },
    )?;
    // Finite weights can still overflow (an extrusion of 1e300, many steps).
    if let Some(p) = done.mesh.points.iter().find(|p| !p.is_finite()) {
        return Err(SubdivisionError::BadParameter(format!(
            "the weights drive the points out of range (a point at {p}); use smaller weights or fewer steps"
        )));
    }
    Ok(done)
}

struct StepContext<'a> {
    mesh: &'a PolyMesh,
    he: &'a HalfEdges,
    curve: &'a [bool],
    roles: &'a [Role],
    origin: &'a [Origin],
    face_group: &'a [Option<usize>],
    vgroup_of: &'a [Option<usize>],
    vertex_locked: &'a [bool],
    locked: &'a HashSet<[u32; 2]>,
    cfg: &'a WeightedConfig,
    spatial: &'a Spatial<'a>,
    mu_pattern: &'a HashMap<(u32, u32), f64>,
    base: Weights,
    first: bool,
    it: usize,
}

impl StepContext<'_> {
    fn face_weights(&self, f: usize, place: Place) -> Weights {
        let base = match self.face_group[f] {
            Some(g) => self.cfg.face_groups[g].weights,
            None => self.base,
        };
        self.spatial.at(self.it, &base, place)
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
        // Scaled planarity of the faces, when a field uses it.
        let planarity: Vec<f64> = if !self.cfg.planarity.is_empty() {
            (0..mesh.faces.len())
                .into_par_iter()
                .map(|f| face_planarity(mesh, f))
                .collect()
        } else {
            vec![0.0; mesh.faces.len()]
        };
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
                let w = self.face_weights(
                    f,
                    Place {
                        pos: centroid,
                        planarity: planarity[f],
                    },
                );
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
                let base = match (self.face_group[f1], self.face_group[f2]) {
                    (Some(g1), Some(g2)) if g1 == g2 => self.cfg.face_groups[g1].weights,
                    _ => self.base,
                };
                let place = Place {
                    pos: mid,
                    planarity: (planarity[f1] + planarity[f2]) * 0.5,
                };
                let w = self.spatial.at(self.it, &base, place);
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
                        let base = self.vgroup_of[v]
                            .and_then(|g| self.cfg.vertex_groups[g].weights)
                            .unwrap_or(self.base);
                        let mut plan = 0.0;
                        let mut count = 0usize;
                        for h in he.outgoing(v as u32) {
                            plan += planarity[he.face[h as usize] as usize];
                            count += 1;
                        }
                        let place = Place {
                            pos: p[v],
                            planarity: plan / count.max(1) as f64,
                        };
                        let w = self.spatial.at(self.it, &base, place);
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
