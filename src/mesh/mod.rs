//! The tetrahedral mesh store.
//!
//! Indexed, struct-of-arrays, `u32` ids, in the manner of mmg and geogram:
//!
//! * `points[v]`: coordinates; `tets[t]`: four vertex ids, positively oriented
//!   (see [`crate::geom::predicates`]); face `i` of a tet is opposite its vertex `i`.
//! * `adj[t][i] = 4*t' + j` when face `i` of `t` is face `j` of `t'`, or
//!   [`NO_ADJ`] on the boundary. Every change goes through [`TetMesh::bond`],
//!   which writes both sides.
//! * Dead tets keep their slot (all four vertices [`DEAD`]) and go on a free list
//!   that [`TetMesh::alloc_tet`] reuses; ids only move in [`TetMesh::compact`].
//!   A generation counter per slot lets work queues detect stale ids.
//! * Sparse tags live in side tables keyed by sorted vertex ids, so that local
//!   operations never have to renumber them: face markers, feature edges,
//!   corners and required vertices. `region`, `level` and `parent` are dense.

mod build;
mod check;
mod compact;
mod data;
pub mod fasthash;
pub mod generate;
mod moves;
pub mod partition;
mod reorder;

/// The store's keys of sparse tags (defined once, in [`crate::topo`]).
pub use crate::topo::{edge_key, face_key, EdgeKey, FaceKey};
pub use build::{BuildReport, MeshError, Where};
pub use check::CheckError;
pub use compact::Remap;
pub use data::MeshData;
pub use moves::ball_stays_positive;

use crate::topo::scatter::Shared;
use crate::topo::{TET_EDGES, TET_EDGE_OPPOSITE, TET_FACES};
use fasthash::{FastHashMap, FastHashSet};
use glam::DVec3;
use rayon::prelude::*;

/// Adjacency value of a boundary face.
pub const NO_ADJ: u32 = u32::MAX;
/// Vertex id stored in every slot of a dead tet.
pub const DEAD: u32 = u32::MAX;

/// Per-slot marks for walks over tets (balls, cavities) without hashing: a
/// slot is marked when its stamp equals the current epoch, so clearing is O(1).
#[derive(Clone, Debug, Default)]
pub struct TetMarks {
    stamp: Vec<u32>,
    epoch: u32,
}

impl TetMarks {
    /// Starts a new walk over a mesh with `slots` tet slots: nothing is marked.
    pub fn begin(&mut self, slots: usize) {
        if self.stamp.len() < slots {
            self.stamp.resize(slots, 0);
        }
        self.epoch = self.epoch.wrapping_add(1);
        if self.epoch == 0 {
            self.stamp.iter_mut().for_each(|s| *s = 0);
            self.epoch = 1;
        }
    }

    /// Marks `t`; returns whether it was unmarked before.
    #[inline]
    pub fn mark(&mut self, t: u32) -> bool {
        let s = &mut self.stamp[t as usize];
        if *s == self.epoch {
            false
        } else {
            *s = self.epoch;
            true
        }
    }
}

/// An indexed tetrahedral mesh with face adjacency and tag side tables.
#[derive(Clone, Debug, Default)]
pub struct TetMesh {
    pub(crate) points: Vec<DVec3>,
    pub(crate) tets: Vec<[u32; 4]>,
    pub(crate) adj: Vec<[u32; 4]>,
    pub(crate) generation: Vec<u32>,
    pub(crate) free: Vec<u32>,
    pub(crate) region: Vec<i32>,
    pub(crate) level: Vec<u8>,
    pub(crate) parent: Vec<u32>,
    // Fast hashing: the hot loops of every phase look edges and faces up here.
    pub(crate) face_markers: FastHashMap<FaceKey, i32>,
    pub(crate) feature_edges: FastHashMap<EdgeKey, i32>,
    pub(crate) corners: FastHashSet<u32>,
    pub(crate) required: FastHashSet<u32>,
    /// One live tet holding each vertex (`DEAD` for unused points). Every
    /// operation re-creates tets over all vertices of the cavity it removes, and
    /// `alloc_tet` writes this entry, so it never goes stale.
    pub(crate) v2t: Vec<u32>,
}

/// [`TetMesh::shared_slots`]: the per-slot arrays, each shared by the
/// parallel tasks of a bulk operation.
pub(crate) struct SharedSlots<'a> {
    /// Vertices of each slot.
    pub(crate) tets: Shared<'a, [u32; 4]>,
    /// Face adjacency of each slot.
    pub(crate) adj: Shared<'a, [u32; 4]>,
    /// Generation of each slot.
    pub(crate) generation: Shared<'a, u32>,
    /// Region of each slot.
    pub(crate) region: Shared<'a, i32>,
    /// Refinement level of each slot.
    pub(crate) level: Shared<'a, u8>,
    /// Parent of each slot.
    pub(crate) parent: Shared<'a, u32>,
}

impl TetMesh {
    // ----- sizes and iteration -------------------------------------------------

    /// Number of point slots (including points no tet references).
    #[inline]
    pub fn n_points(&self) -> usize {
        self.points.len()
    }

    /// Number of tet slots, dead ones included.
    #[inline]
    pub fn n_tet_slots(&self) -> usize {
        self.tets.len()
    }

    /// Number of live tets.
    #[inline]
    pub fn n_tets(&self) -> usize {
        self.tets.len() - self.free.len()
    }

    /// Whether slot `t` holds a live tet.
    #[inline]
    pub fn is_alive(&self, t: u32) -> bool {
        self.tets[t as usize][0] != DEAD
    }

    /// Ids of the live tets, ascending.
    pub fn tet_ids(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.tets.len() as u32).filter(move |&t| self.is_alive(t))
    }

    /// Every edge of the live tets once, as [`edge_key`]s (lower id first),
    /// sorted.
    pub fn edges(&self) -> Vec<EdgeKey> {
        let mut edges: Vec<EdgeKey> = self
            .tet_ids()
            .flat_map(|t| {
                let v = self.tet(t);
                TET_EDGES.map(|[i, j]| edge_key(v[i], v[j]))
            })
            .collect();
        edges.sort_unstable();
        edges.dedup();
        edges
    }

    // ----- accessors (each asserts its id, as geogram does) --------------------

    /// Debug check of a tet id: in range and, for `live`, not a dead slot.
    #[inline]
    fn debug_check_tet(&self, t: u32, live: bool) {
        debug_assert!((t as usize) < self.tets.len(), "tet {t} out of range");
        debug_assert!(!live || self.tets[t as usize][0] != DEAD, "tet {t} is dead");
    }

    /// Coordinates of point `v`.
    #[inline]
    pub fn point(&self, v: u32) -> DVec3 {
        debug_assert!((v as usize) < self.points.len(), "point {v} out of range");
        self.points[v as usize]
    }

    /// All point coordinates.
    #[inline]
    pub fn points(&self) -> &[DVec3] {
        &self.points
    }

    /// Moves point `v`. The caller is responsible for orientation (see
    /// [`ball_stays_positive`]).
    #[inline]
    pub fn set_point(&mut self, v: u32, p: DVec3) {
        debug_assert!((v as usize) < self.points.len(), "point {v} out of range");
        debug_assert!(p.is_finite(), "point {v} moved to {p}");
        self.points[v as usize] = p;
    }

    /// Appends a point and returns its id.
    #[inline]
    pub fn add_point(&mut self, p: DVec3) -> u32 {
        self.points.push(p);
        self.v2t.push(DEAD);
        (self.points.len() - 1) as u32
    }

    /// Marks point `v` as used by no tet (after an operation such as an edge
    /// contraction took it out of every tet); [`Self::compact`] drops it.
    pub(crate) fn retire_point(&mut self, v: u32) {
        debug_assert!(
            self.tet_of_vertex(v)
                .is_none_or(|t| !self.is_alive(t) || !self.tets[t as usize].contains(&v)),
            "point {v} retired while a tet holds it"
        );
        self.v2t[v as usize] = DEAD;
    }

    /// Removes point `v` if it is the last one and no tet uses it (undoing an
    /// `add_point` of a refused operation).
    pub fn pop_unused_point(&mut self, v: u32) {
        if v as usize + 1 == self.points.len() && self.v2t[v as usize] == DEAD {
            self.points.pop();
            self.v2t.pop();
        }
    }

    /// The four vertex ids of tet `t`.
    #[inline]
    pub fn tet(&self, t: u32) -> [u32; 4] {
        self.debug_check_tet(t, true);
        self.tets[t as usize]
    }

    /// All tet slots (dead slots hold [`DEAD`]).
    #[inline]
    pub fn tet_slots(&self) -> &[[u32; 4]] {
        &self.tets
    }

    /// The four corner points of tet `t`.
    #[inline]
    pub fn tet_points(&self, t: u32) -> [DVec3; 4] {
        let v = self.tet(t);
        [
            self.points[v[0] as usize],
            self.points[v[1] as usize],
            self.points[v[2] as usize],
            self.points[v[3] as usize],
        ]
    }

    /// Adjacency of tet `t` (`4*t'+j` or [`NO_ADJ`] per face).
    #[inline]
    pub fn adj(&self, t: u32) -> [u32; 4] {
        self.debug_check_tet(t, true);
        self.adj[t as usize]
    }

    /// Generation counter of slot `t`: it changes whenever the slot is freed or
    /// reused, so a queue that stored `(t, generation)` can tell a stale entry.
    #[inline]
    pub fn generation(&self, t: u32) -> u32 {
        self.debug_check_tet(t, false);
        self.generation[t as usize]
    }

    /// Region id of tet `t`.
    #[inline]
    pub fn region(&self, t: u32) -> i32 {
        self.debug_check_tet(t, true);
        self.region[t as usize]
    }

    /// Sets the region id of tet `t`.
    #[inline]
    pub fn set_region(&mut self, t: u32, r: i32) {
        self.debug_check_tet(t, true);
        self.region[t as usize] = r;
    }

    /// Refinement level of tet `t` (0 for input tets).
    #[inline]
    pub fn level(&self, t: u32) -> u8 {
        self.debug_check_tet(t, true);
        self.level[t as usize]
    }

    /// Sets the refinement level of tet `t`.
    #[inline]
    pub fn set_level(&mut self, t: u32, l: u8) {
        self.debug_check_tet(t, true);
        self.level[t as usize] = l;
    }

    /// Input tet that tet `t` descends from (its own id for input tets).
    #[inline]
    pub fn parent(&self, t: u32) -> u32 {
        self.debug_check_tet(t, true);
        self.parent[t as usize]
    }

    /// Sets the input tet that tet `t` descends from.
    #[inline]
    pub fn set_parent(&mut self, t: u32, p: u32) {
        self.debug_check_tet(t, true);
        self.parent[t as usize] = p;
    }

    /// The outward-oriented vertex triple of face `f` of tet `t`.
    #[inline]
    pub fn face_vertices(&self, t: u32, f: usize) -> [u32; 3] {
        let v = self.tet(t);
        let l = TET_FACES[f];
        [v[l[0]], v[l[1]], v[l[2]]]
    }

    /// Whether face `f` of tet `t` is on the boundary.
    #[inline]
    pub fn is_boundary_face(&self, t: u32, f: usize) -> bool {
        self.debug_check_tet(t, true);
        debug_assert!(f < 4, "face {f} of a tet");
        self.adj[t as usize][f] == NO_ADJ
    }

    // ----- tags ----------------------------------------------------------------

    /// Marker of the face with these vertices, if it has one.
    pub fn face_marker(&self, f: [u32; 3]) -> Option<i32> {
        self.face_markers.get(&face_key(f)).copied()
    }

    /// Sets (or with `None` removes) the marker of a face.
    pub fn set_face_marker(&mut self, f: [u32; 3], m: Option<i32>) {
        match m {
            Some(m) => {
                self.face_markers.insert(face_key(f), m);
            }
            None => {
                self.face_markers.remove(&face_key(f));
            }
        }
    }

    /// All marked faces (sorted vertex keys) and their markers.
    pub fn face_markers(&self) -> &FastHashMap<FaceKey, i32> {
        &self.face_markers
    }

    /// Marker of feature edge `(a, b)`, if it is one.
    pub fn feature_edge(&self, a: u32, b: u32) -> Option<i32> {
        self.feature_edges.get(&edge_key(a, b)).copied()
    }

    /// Whether `(a, b)` is a feature edge.
    pub fn is_feature_edge(&self, a: u32, b: u32) -> bool {
        self.feature_edges.contains_key(&edge_key(a, b))
    }

    /// Tags (or with `None` untags) a feature edge.
    pub fn set_feature_edge(&mut self, a: u32, b: u32, m: Option<i32>) {
        match m {
            Some(m) => {
                self.feature_edges.insert(edge_key(a, b), m);
            }
            None => {
                self.feature_edges.remove(&edge_key(a, b));
            }
        }
    }

    /// All feature edges and their markers.
    pub fn feature_edges(&self) -> &FastHashMap<EdgeKey, i32> {
        &self.feature_edges
    }

    /// Whether vertex `v` is a corner.
    pub fn is_corner(&self, v: u32) -> bool {
        self.corners.contains(&v)
    }

    /// Marks or unmarks vertex `v` as a corner.
    pub fn set_corner(&mut self, v: u32, on: bool) {
        if on {
            self.corners.insert(v);
        } else {
            self.corners.remove(&v);
        }
    }

    /// Removes every feature edge and corner tag.
    pub fn clear_features(&mut self) {
        self.feature_edges.clear();
        self.corners.clear();
    }

    /// Corner vertices.
    pub fn corners(&self) -> &FastHashSet<u32> {
        &self.corners
    }

    /// Whether vertex `v` is required (must not move).
    pub fn is_required(&self, v: u32) -> bool {
        self.required.contains(&v)
    }

    /// Marks or unmarks vertex `v` as required.
    pub fn set_required(&mut self, v: u32, on: bool) {
        if on {
            self.required.insert(v);
        } else {
            self.required.remove(&v);
        }
    }

    /// Required vertices.
    pub fn required_vertices(&self) -> &FastHashSet<u32> {
        &self.required
    }

    // ----- the one rule for constrained faces and vertices -----------------------

    /// Whether the face `face` of tet `t`, whose other side is the tet
    /// `other` (`None` on the boundary), is *constrained*: it must survive
    /// every operation as the boundary does. That is the case on the
    /// boundary, between two regions, and for a marked face. Every
    /// operation, the improvement passes and the √3 step ask this one rule.
    #[inline]
    pub fn face_is_constrained(&self, t: u32, other: Option<u32>, face: [u32; 3]) -> bool {
        match other {
            None => true,
            Some(u) => {
                self.region(u) != self.region(t)
                    || (!self.face_markers.is_empty() && self.face_marker(face).is_some())
            }
        }
    }

    /// Whether interior face `f` of `t` is constrained ([`Self::face_is_constrained`]):
    /// it separates two regions or carries a marker. False for boundary faces.
    #[inline]
    pub fn is_interface_face(&self, t: u32, f: usize) -> bool {
        let h = self.adj(t)[f];
        h != NO_ADJ && self.face_is_constrained(t, Some(h >> 2), self.face_vertices(t, f))
    }

    /// Per point: must it stay where it is? The vertices of constrained
    /// faces ([`Self::face_is_constrained`]), of feature edges, corners and
    /// required vertices.
    pub fn fixed_vertices(&self) -> Vec<bool> {
        let mut fixed = vec![false; self.n_points()];
        for t in self.tet_ids() {
            let adj = self.adj(t);
            for (f, &h) in adj.iter().enumerate() {
                let fv = self.face_vertices(t, f);
                if self.face_is_constrained(t, (h != NO_ADJ).then_some(h >> 2), fv) {
                    for v in fv {
                        fixed[v as usize] = true;
                    }
                }
            }
        }
        for e in self.feature_edges().keys() {
            fixed[e[0] as usize] = true;
            fixed[e[1] as usize] = true;
        }
        for &v in self.corners().iter().chain(self.required_vertices()) {
            fixed[v as usize] = true;
        }
        fixed
    }

    // ----- topology edits ------------------------------------------------------

    /// Links half-face `a = 4*t+i` with half-face `b = 4*t'+j` (both sides), or
    /// marks `a` as boundary when `b` is [`NO_ADJ`].
    ///
    /// Crate-private, as are `alloc_tet` and `kill_tet`: a
    /// sequence such as `bond(a, b); bond(c, b)` leaves `a` pointing at a
    /// face that points elsewhere, and the bulk operations' one writer per
    /// adjacency entry (so their determinism) relies on adjacency being
    /// mutual. Users change the mesh through the checked operations only:
    ///
    /// ```compile_fail
    /// let mut mesh = tetrefine::TetMesh::default();
    /// mesh.bond(0, 5); // error[E0624]: method `bond` is private
    /// ```
    #[inline]
    pub(crate) fn bond(&mut self, a: u32, b: u32) {
        debug_assert!(a != NO_ADJ);
        self.adj[(a >> 2) as usize][(a & 3) as usize] = b;
        if b != NO_ADJ {
            self.adj[(b >> 2) as usize][(b & 3) as usize] = a;
        }
    }

    /// Creates a tet (reusing a free slot if there is one) with no adjacency yet.
    /// The caller must bond all four faces.
    pub(crate) fn alloc_tet(&mut self, v: [u32; 4], region: i32) -> u32 {
        debug_assert!(v.iter().all(|&x| (x as usize) < self.points.len()));
        let t = self.alloc_slot(v, region);
        for x in v {
            self.v2t[x as usize] = t;
        }
        t
    }

    fn alloc_slot(&mut self, v: [u32; 4], region: i32) -> u32 {
        if let Some(t) = self.free.pop() {
            let i = t as usize;
            self.tets[i] = v;
            self.adj[i] = [NO_ADJ; 4];
            self.generation[i] = self.generation[i].wrapping_add(1);
            self.region[i] = region;
            self.level[i] = 0;
            self.parent[i] = t;
            t
        } else {
            let t = self.tets.len() as u32;
            self.tets.push(v);
            self.adj.push([NO_ADJ; 4]);
            self.generation.push(0);
            self.region.push(region);
            self.level.push(0);
            self.parent.push(t);
            t
        }
    }

    /// Frees tet `t`; its neighbours still point to it until re-bonded.
    pub(crate) fn kill_tet(&mut self, t: u32) {
        let i = t as usize;
        debug_assert!(self.tets[i][0] != DEAD, "tet {t} killed twice");
        self.tets[i] = [DEAD; 4];
        self.adj[i] = [NO_ADJ; 4];
        self.generation[i] = self.generation[i].wrapping_add(1);
        self.free.push(t);
    }

    /// Removes tet `t` and opens the mesh there: each neighbour's face that
    /// `t` shared becomes a boundary face of that neighbour (adjacency stays
    /// mutual), and a vertex whose `v2t` entry was `t` is re-pointed at a
    /// neighbour holding it. Every vertex of `t` must lie in a neighbour
    /// across one of its faces (the caller checks; a vertex left in no tet
    /// would be orphaned).
    pub(crate) fn remove_tet_opening(&mut self, t: u32) {
        let v = self.tet(t);
        let adj = self.adj(t);
        for &h in &adj {
            if h != NO_ADJ {
                self.bond(h, NO_ADJ);
            }
        }
        for x in v {
            if self.v2t[x as usize] == t {
                let holder = adj
                    .iter()
                    .filter(|&&h| h != NO_ADJ)
                    .map(|&h| h >> 2)
                    .find(|&u| self.tets[u as usize].contains(&x))
                    .expect(
                        "remove_tet_opening: every vertex lies in a neighbour (caller's check)",
                    );
                self.v2t[x as usize] = holder;
            }
        }
        self.kill_tet(t);
    }

    /// Reserves room for `n` more tets and `p` more points.
    pub fn reserve(&mut self, n: usize, p: usize) {
        self.tets.reserve(n);
        self.adj.reserve(n);
        self.generation.reserve(n);
        self.region.reserve(n);
        self.level.reserve(n);
        self.parent.reserve(n);
        self.points.reserve(p);
        self.v2t.reserve(p);
    }

    /// Reserves room for exactly `n` more tet slots (no `Vec` doubling).
    pub(crate) fn reserve_tets_exact(&mut self, n: usize) {
        self.tets.reserve_exact(n);
        self.adj.reserve_exact(n);
        self.generation.reserve_exact(n);
        self.region.reserve_exact(n);
        self.level.reserve_exact(n);
        self.parent.reserve_exact(n);
    }

    /// The per-slot arrays viewed for the parallel tasks of a bulk
    /// operation (see [`crate::topo::scatter::Shared`]); the points and the
    /// vertex → tet table stay as they are.
    pub(crate) fn shared_slots(&mut self) -> SharedSlots<'_> {
        SharedSlots {
            tets: Shared::new(&mut self.tets),
            adj: Shared::new(&mut self.adj),
            generation: Shared::new(&mut self.generation),
            region: Shared::new(&mut self.region),
            level: Shared::new(&mut self.level),
            parent: Shared::new(&mut self.parent),
        }
    }

    /// Claims `n` tet slots for a bulk operation, in the order `n` calls of
    /// [`TetMesh::alloc_tet`] would hand them out: first the free list from its
    /// end, then new slots appended at the end of the arrays (reserved exactly,
    /// without the doubling of `Vec` growth). Reused slots get their generation
    /// bumped as `alloc_tet` does; every claimed slot holds a dead tet until
    /// the caller fills it (vertices, adjacency, region, level, parent) — the
    /// mesh is inconsistent until then.
    pub(crate) fn claim_slots(&mut self, n: usize) -> NewSlots {
        let r = n.min(self.free.len());
        let reused: Vec<u32> = self.free.drain(self.free.len() - r..).rev().collect();
        for &t in &reused {
            let g = &mut self.generation[t as usize];
            *g = g.wrapping_add(1);
        }
        let base = self.tets.len();
        let len = base + (n - r);
        self.reserve_tets_exact(n - r);
        // Filled in parallel so that both threads take the page faults of
        // fresh memory.
        let extra = len - base;
        self.tets
            .par_extend(rayon::iter::repeat_n([DEAD; 4], extra));
        self.adj
            .par_extend(rayon::iter::repeat_n([NO_ADJ; 4], extra));
        self.generation.par_extend(rayon::iter::repeat_n(0, extra));
        self.region.par_extend(rayon::iter::repeat_n(0, extra));
        self.level.par_extend(rayon::iter::repeat_n(0, extra));
        self.parent.par_extend(rayon::iter::repeat_n(0, extra));
        NewSlots {
            reused,
            base: base as u32,
        }
    }

    // ----- derived topology ----------------------------------------------------

    /// Local index of vertex `v` in tet `t`, if present.
    #[inline]
    pub fn local_index(&self, t: u32, v: u32) -> Option<usize> {
        self.tets[t as usize].iter().position(|&x| x == v)
    }

    /// Walks around the edge `(tets[t][TET_EDGES[e][0]], tets[t][TET_EDGES[e][1]])`
    /// through face adjacency and calls `visit` on each tet of its ring (starting
    /// with `t`); stops early when `visit` returns `false`. Returns whether the
    /// ring is closed (an interior edge) — meaningful only if not stopped early.
    pub fn for_each_tet_around_edge(
        &self,
        t: u32,
        e: usize,
        mut visit: impl FnMut(u32) -> bool,
    ) -> bool {
        let v = self.tets[t as usize];
        let (a, b) = (v[TET_EDGES[e][0]], v[TET_EDGES[e][1]]);
        if !visit(t) {
            return false;
        }
        // Leave t through one of the two faces holding the edge; if the walk hits
        // the boundary, come back and go the other way.
        for (pass, &first_exit) in TET_EDGE_OPPOSITE[e].iter().enumerate() {
            let mut cur = t;
            let mut exit = first_exit;
            loop {
                let n = self.adj[cur as usize][exit];
                if n == NO_ADJ {
                    break;
                }
                let (nt, entered) = (n >> 2, (n & 3) as usize);
                if nt == t {
                    // Closed ring: every tet already visited on the first pass.
                    debug_assert_eq!(pass, 0);
                    return true;
                }
                if !visit(nt) {
                    return false;
                }
                let nv = self.tets[nt as usize];
                // The next exit is the local vertex of nt that is neither a, b nor
                // the one opposite the face we came in by.
                exit = (0..4)
                    .find(|&i| i != entered && nv[i] != a && nv[i] != b)
                    .expect("edge ring broken: adjacency inconsistent");
                cur = nt;
            }
        }
        false
    }

    /// Splits a half-face id `4*t+f` into `(t, f)`.
    #[inline]
    pub fn half_face(h: u32) -> (u32, usize) {
        (h >> 2, (h & 3) as usize)
    }

    /// A live tet holding vertex `v`, or `None` if no tet uses it.
    #[inline]
    pub fn tet_of_vertex(&self, v: u32) -> Option<u32> {
        let t = self.v2t[v as usize];
        (t != DEAD).then_some(t)
    }

    /// Rebuilds the vertex → tet table from scratch.
    pub fn rebuild_v2t(&mut self) {
        self.v2t.clear();
        self.v2t.resize(self.points.len(), DEAD);
        for (t, v) in self.tets.iter().enumerate() {
            if v[0] != DEAD {
                for &x in v {
                    self.v2t[x as usize] = t as u32;
                }
            }
        }
    }

    /// [`TetMesh::ball`] with caller-owned marks: O(ball size).
    pub fn ball_marked(&self, v: u32, out: &mut Vec<u32>, marks: &mut TetMarks) {
        out.clear();
        let Some(start) = self.tet_of_vertex(v) else {
            return;
        };
        marks.begin(self.tets.len());
        marks.mark(start);
        out.push(start);
        let mut i = 0;
        while i < out.len() {
            let t = out[i];
            i += 1;
            let tv = self.tets[t as usize];
            let adj = self.adj[t as usize];
            for f in 0..4 {
                if tv[f] != v && adj[f] != NO_ADJ && marks.mark(adj[f] >> 2) {
                    out.push(adj[f] >> 2);
                }
            }
        }
    }

    /// The zone of [`Self::grow_zone`] seeded with the vertices of `tets`
    /// and grown through any tet.
    pub(crate) fn zone_around_tets(&self, tets: &[u32], rings: usize) -> (Vec<bool>, Vec<bool>) {
        let mut seeds = vec![false; self.n_points()];
        for &t in tets {
            for v in self.tet(t) {
                seeds[v as usize] = true;
            }
        }
        self.grow_zone(seeds, rings, |_| true)
    }

    /// A zone grown from the vertices `seeds` (per point) by `rings` rings
    /// of tets: each ring takes every live tet `through` admits with a
    /// vertex in the zone, and that tet's vertices. Returns the zone's
    /// vertices (per point) and tets (per tet slot).
    pub(crate) fn grow_zone(
        &self,
        seeds: Vec<bool>,
        rings: usize,
        through: impl Fn(u32) -> bool,
    ) -> (Vec<bool>, Vec<bool>) {
        assert_eq!(seeds.len(), self.n_points(), "one seed flag per point");
        let mut tets = vec![false; self.n_tet_slots()];
        let mut verts = seeds;
        for _ in 0..rings {
            let mut next = verts.clone();
            for t in self.tet_ids() {
                let v = self.tet(t);
                if through(t) && v.iter().any(|&x| verts[x as usize]) {
                    tets[t as usize] = true;
                    for x in v {
                        next[x as usize] = true;
                    }
                }
            }
            verts = next;
        }
        (verts, tets)
    }

    /// The tets holding edge `(a, b)` (its shell), ascending, into `out`
    /// (cleared first), found through the ball of `a` ([`Self::ball`]); empty
    /// when the walk from `a`'s stored tet does not reach the edge. Returns
    /// the number of tets the walk saw: fewer than the tets at `a` only at a
    /// pinch, where pieces of the domain touch at `a`.
    pub(crate) fn edge_shell(&self, a: u32, b: u32, out: &mut Vec<u32>) -> usize {
        self.ball(a, out);
        let walked = out.len();
        out.retain(|&t| self.tets[t as usize].contains(&b));
        out.sort_unstable();
        walked
    }

    /// The tets around vertex `v` (its ball), found by walking face adjacency
    /// from one incident tet; appended to `out` (cleared first).
    pub fn ball(&self, v: u32, out: &mut Vec<u32>) {
        out.clear();
        let Some(start) = self.tet_of_vertex(v) else {
            return;
        };
        debug_assert!(self.tets[start as usize].contains(&v), "v2t stale for {v}");
        out.push(start);
        let mut i = 0;
        while i < out.len() {
            let t = out[i];
            i += 1;
            let tv = self.tets[t as usize];
            for (f, &opposite) in tv.iter().enumerate() {
                // Only faces that contain v lead to other tets of the ball.
                if opposite == v {
                    continue;
                }
                let h = self.adj[t as usize][f];
                if h != NO_ADJ {
                    let n = h >> 2;
                    if !out.contains(&n) {
                        out.push(n);
                    }
                }
            }
        }
    }
}

/// The keys of `wanted` that are faces of the live tets of `tets`.
pub(crate) fn faces_present(
    tets: &[[u32; 4]],
    wanted: &FastHashSet<FaceKey>,
) -> FastHashSet<FaceKey> {
    keys_present(tets, wanted, |v| {
        TET_FACES.map(|l| face_key([v[l[0]], v[l[1]], v[l[2]]]))
    })
}

/// The keys of `wanted` that are edges of the live tets of `tets`.
pub(crate) fn edges_present(
    tets: &[[u32; 4]],
    wanted: &FastHashSet<EdgeKey>,
) -> FastHashSet<EdgeKey> {
    keys_present(tets, wanted, |v| {
        TET_EDGES.map(|[i, j]| edge_key(v[i], v[j]))
    })
}

/// The keys of `wanted` among the keys (faces or edges) `keys_of` gives
/// for each live tet of `tets`. Each tet's keys are looked up in `wanted`
/// (a mesh's tags: thousands of keys) in parallel, rather than gathered
/// into a set of every face or edge: tens of millions of keys on a refined
/// mesh, hashed on one thread, for each `check` and each mesh built from
/// data.
fn keys_present<K, const N: usize>(
    tets: &[[u32; 4]],
    wanted: &FastHashSet<K>,
    keys_of: fn(&[u32; 4]) -> [K; N],
) -> FastHashSet<K>
where
    K: Copy + Eq + std::hash::Hash + Send + Sync,
{
    tets.par_iter()
        .with_min_len(4096)
        .filter(|v| v[0] != DEAD)
        .flat_map_iter(keys_of)
        .filter(|k| wanted.contains(k))
        .collect()
}

/// Tet slots claimed by [`TetMesh::claim_slots`]: the `j`-th is
/// [`NewSlots::get`]`(j)`.
#[derive(Clone, Debug)]
pub(crate) struct NewSlots {
    reused: Vec<u32>,
    base: u32,
}

impl NewSlots {
    /// The `j`-th claimed slot.
    #[inline]
    pub(crate) fn get(&self, j: usize) -> u32 {
        match self.reused.get(j) {
            Some(&t) => t,
            None => self.base + (j - self.reused.len()) as u32,
        }
    }
}
