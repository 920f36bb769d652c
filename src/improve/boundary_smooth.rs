//! Boundary-aware vertex smoothing: vertices on the boundary and on material
//! interfaces move inside their surface patch, projected back onto a
//! reference surface, so that the worst tets touching the boundary can be
//! repaired without changing the domain by more than a Hausdorff bound.
//!
//! The ideas are MMG3D's (Dapogny, Dobrzynski and Frey, "Three-dimensional
//! adaptive domain remeshing, implicit domain meshing, and applications to
//! free and moving boundary problems", JCP 2014: boundary points move on a
//! reference surface, ridge points along their ridge, corners never, under
//! a Hausdorff distance `hausd`) and Stellar's (Klingner and Shewchuk,
//! "Aggressive tetrahedral mesh improvement", IMR 2007: boundary vertices
//! smoothed on the worst-quality objective, constrained to their facet or
//! segment). The implementation here is our own:
//!
//! - A *surface vertex* lies on constrained faces (boundary, region
//!   interface, or marked faces) that all carry the same key (marker and
//!   region pair), form a closed disk around it, and has no feature edge.
//!   It moves tangentially and is projected onto the reference triangles
//!   of its patch near it (its own star and its neighbours' stars as they
//!   stood when the pass set began).
//! - A *line vertex* has exactly two collinear feature edges and is no
//!   corner: it slides along them (as they stood). A vertex where its line
//!   bends stays fixed, so that the feature edges stay on the input polyline.
//! - Every other vertex with a constrained face is fixed (corners, required
//!   vertices, junctions of patches).
//!
//! A move is kept only if every tet of the ball stays positive with the
//! exact `orient3d` and in f64, the worst tet of the ball rises (or, above
//! the optimisation bar, the worst does not fall and the mean rises), and the
//! new boundary triangles stay within the Hausdorff bound of the reference.
//! On a flat patch the projection keeps the vertex in the plane, and a
//! positive ball keeps the star's triangles tiling the same polygon, so the
//! domain and every region volume are unchanged (up to the rounding of the
//! projection, which is exact on axis-aligned planes).

use super::BallPoints;
use crate::geom::{closest_on_segment, closest_point_on_triangle};
use crate::mesh::fasthash::FastHashMap;
use crate::mesh::{edge_key, TetMesh, NO_ADJ};
use glam::DVec3;

/// Options of the boundary smoothing.
#[derive(Clone, Debug)]
pub struct BoundarySmoothOptions {
    /// Absolute Hausdorff bound (MMG's `-hausd`): the largest distance a new
    /// boundary triangle may stand from the reference surface. `None`: a
    /// fraction [`Self::hausd_rel`] of the local mean edge length.
    pub hausd: Option<f64>,
    /// The default bound as a fraction of the mean length of the surface
    /// edges at the vertex.
    pub hausd_rel: f64,
    /// The default bound of a cap removal, as a fraction of the cap's mean
    /// edge length. A sliver cap's height is a small fraction of its edges
    /// by its nature, and removing it makes the surface there flatter, not
    /// rougher; on the 1.97M-tet tripod one more step kept a 8.3° cap whose
    /// height was 0.1 of its mean edge (0.05 refused it, 0.15 removes it).
    pub cap_hausd_rel: f64,
    /// Vertices whose worst tet is below this (min sine) are optimised for
    /// the worst tet.
    pub threshold: f64,
    /// Vertices whose worst tet is below this get a tangential Laplacian
    /// try, kept only if the worst does not fall and the mean rises.
    pub laplacian_threshold: f64,
    /// A vertex whose star holds two neighbouring faces with normals more
    /// than this many degrees apart sits on a crease nobody tagged (features
    /// off, or a higher `--feature-angle`): it stays fixed, since moving it
    /// would cut the crease and change the domain by up to the Hausdorff
    /// bound even on a piecewise-planar part. 45° is MMG's ridge angle and
    /// the default of `--feature-angle`.
    pub crease_angle: f64,
    /// Remove boundary sliver caps (tets with two boundary faces) within
    /// the Hausdorff bound ([`crate::ops::remove_boundary_cap`]); off for
    /// the linear rule, whose domain must stay the input's exactly.
    pub remove_caps: bool,
    /// Flip boundary edges where it raises the worst tet of their ring and
    /// the surface stays within the Hausdorff bound
    /// ([`crate::ops::flip_boundary_edge`]; exactly coplanar faces only when
    /// `crease_angle` allows flat stars only, 1e-4° or less, as the linear
    /// rule sets it).
    pub flip_edges: bool,
    /// After the passes, contract boundary edges of the tets below the
    /// threshold ([`crate::ops::contract_boundary_edge`]) where the fan
    /// that replaces the merged vertex's faces stays within the Hausdorff
    /// bound (exactly in their plane when `crease_angle` allows flat stars
    /// only). On by default: with multi-face removal in the passes it
    /// lifts the slivers at boundary points crowded against a corner (the
    /// ladder at a 69° feature angle, two steps: 4.45° without, 6.81° with;
    /// input 5.34°) and mmg_cube's worst after two steps (13.97° → 17.48°),
    /// and lowers no shipped mesh's worst by more than 0.02°.
    pub contract_edges: bool,
}

impl Default for BoundarySmoothOptions {
    fn default() -> Self {
        BoundarySmoothOptions {
            hausd: None,
            hausd_rel: 0.05,
            cap_hausd_rel: 0.15,
            // Measured on tripod, gmsh_t16 and getfem_ladder (two steps):
            // 0.4 / 0.5 keeps the worst angles of 0.5 / 0.7 or better (15.3°,
            // 15.4°, 12.8° after step 2) at a third to a half of its time.
            threshold: 0.4,
            laplacian_threshold: 0.5,
            crease_angle: 45.0,
            remove_caps: true,
            flip_edges: false,
            contract_edges: true,
        }
    }
}

/// A [`BoundarySmoothOptions::crease_angle`] that lets only vertices of
/// flat stars move: at or below it, a star counts as flat only when all its
/// corners are coplanar by the exact `orient3d` (so no tolerance can let a
/// vertex leave the domain); the value itself, 1e-4°, is far below any real
/// crease.
pub const FLAT_ONLY: f64 = 1e-4;

/// A decided move: vertex, position, ball, the ball's new qualities.
type Decided = (u32, DVec3, Vec<u32>, Vec<f64>);

/// Below this worst min-sine a boundary move may lower its ball's mean.
const SLIVER: f64 = 0.2;

/// What a vertex may do.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// Not on a constrained face (the interior smoother's business).
    Interior,
    /// Fixed: a corner, a required vertex, a patch junction, a non-disk star.
    Fixed,
    /// Inside one patch: moves on the reference triangles.
    Surface,
    /// On a feature line, between its two line neighbours.
    Line(u32, u32),
}

/// Key of a constrained face: its marker (or `i32::MIN`) and the regions on
/// its two sides (`i32::MIN` for the outside), smaller first.
type Key = (i32, i32, i32);

/// The constrained faces as they stood when the smoother was set up: the
/// reference surface, with its topology (constrained faces are not changed
/// by interior edge removal or vertex moves).
pub struct BoundarySmoother {
    /// Vertices of each constrained face.
    faces: Vec<[u32; 3]>,
    /// Key of each face.
    keys: Vec<Key>,
    /// Reference corners of each face.
    ref_faces: Vec<[DVec3; 3]>,
    /// Faces at each vertex (CSR).
    start: Vec<u32>,
    at: Vec<u32>,
    kind: Vec<Kind>,
    /// Reference positions of the vertices.
    ref_pos: FastHashMap<u32, DVec3>,
    /// Feature edges at each line vertex are implied by `Kind::Line`; the
    /// reference polyline of a line vertex is gathered from here.
    line_nbrs: FastHashMap<u32, Vec<u32>>,
    opts: BoundarySmoothOptions,
}

/// The reference faces of one key near a vertex, and their plane if they
/// are flat.
struct RefSet {
    key: Key,
    faces: Vec<u32>,
    /// Unit normal and a point, when every corner lies on one plane.
    plane: Option<(DVec3, DVec3)>,
    /// Per axis, the coordinate every corner shares (axis-aligned planes).
    axes: [Option<f64>; 3],
}

/// What the boundary smoother did.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct BoundarySmoothReport {
    /// Surface vertices moved inside their patch.
    pub surface_moves: usize,
    /// Feature-line vertices moved along their line.
    pub line_moves: usize,
}

/// Keeps, on each axis where all corners of the triangle agree exactly,
/// that coordinate exactly (projection rounding would otherwise move points
/// off axis-aligned planes by an ulp).
fn snap_axes(mut x: DVec3, tri: &[DVec3; 3]) -> DVec3 {
    for k in 0..3 {
        if tri[0][k] == tri[1][k] && tri[1][k] == tri[2][k] {
            x[k] = tri[0][k];
        }
    }
    x
}

/// Whether `v` lies on the segment `ab` up to rounding: a line vertex may
/// slide only where its line is straight. At a bend of the polyline, moving
/// the vertex would turn its two feature edges into a chord that cuts the
/// bend, and every later point on them (the trisection of even steps) would
/// leave the input polyline. The relative bar 1e-12 on the sine of the bend
/// is some thousand ulps: points made by linear interpolation on a segment
/// (trisection, earlier slides) pass, any visible bend does not.
fn straight(a: DVec3, v: DVec3, b: DVec3) -> bool {
    let (da, db) = (a - v, b - v);
    da.dot(db) < 0.0 && da.cross(db).length() <= 1e-12 * da.length() * db.length()
}

/// Whether the faces of the star `fs` of `v` are connected through the
/// edges at `v` they share. At a pinch, where pieces of the domain touch at
/// `v` only, they are not, and neither is `v`'s ball: a walk from one of its
/// tets ([`TetMesh::ball`]) sees one piece, so a move judged on that piece
/// alone could invert a tet of another.
fn star_is_connected(faces: &[[u32; 3]], fs: &[u32], v: u32) -> bool {
    let Some(&first) = fs.first() else {
        return true;
    };
    let mut reached = vec![first];
    let mut i = 0;
    while i < reached.len() {
        let f = faces[reached[i] as usize];
        i += 1;
        for &g in fs {
            if !reached.contains(&g) && faces[g as usize].iter().any(|&u| u != v && f.contains(&u))
            {
                reached.push(g);
            }
        }
    }
    reached.len() == fs.len()
}

/// Whether two faces of the star `fs` of `v` that share an edge have
/// normals more than `angle` degrees apart. The faces' orientations are not
/// consistent across an interface (each is taken from one of its sides), so
/// the test uses the unsigned angle between the normals' lines, and a fold
/// sharper than 180° − `angle` counts as a crease too.
fn star_has_crease(mesh: &TetMesh, faces: &[[u32; 3]], fs: &[u32], v: u32, angle: f64) -> bool {
    if angle <= FLAT_ONLY {
        // Flat stars only: every corner of the star in the plane of its
        // first face, by the exact orient3d. A tolerance on normals would
        // let a vertex slide over a patch that bends by 1e-6 radians and
        // leave the domain by that much (fields carried over by the linear
        // rule must come back to round-off).
        let Some(&f0) = fs.first() else {
            return false;
        };
        let [a, b, c] = faces[f0 as usize].map(|u| mesh.point(u));
        return fs.iter().any(|&f| {
            faces[f as usize]
                .iter()
                .any(|&u| crate::geom::orient3d(a, b, c, mesh.point(u)) != 0.0)
        });
    }
    let cos_bar = angle.to_radians().cos();
    let normal = |f: u32| {
        let p = faces[f as usize].map(|u| mesh.point(u));
        (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero()
    };
    for (i, &f) in fs.iter().enumerate() {
        for &g in &fs[..i] {
            let shared = faces[f as usize]
                .iter()
                .filter(|&&u| u != v && faces[g as usize].contains(&u))
                .count();
            if shared == 0 {
                continue;
            }
            let c = normal(f).dot(normal(g)).abs();
            if c < cos_bar {
                return true;
            }
        }
    }
    false
}

fn face_key_of(mesh: &TetMesh, t: u32, f: usize) -> Key {
    let h = mesh.adj(t)[f];
    let r0 = mesh.region(t);
    let r1 = if h == NO_ADJ {
        i32::MIN
    } else {
        mesh.region(h >> 2)
    };
    let m = if mesh.face_markers().is_empty() {
        None
    } else {
        mesh.face_marker(mesh.face_vertices(t, f))
    };
    (m.unwrap_or(i32::MIN), r0.min(r1), r0.max(r1))
}

impl BoundarySmoother {
    /// Takes the constrained faces of `mesh` as the reference surface and
    /// classifies its vertices.
    pub fn new(mesh: &TetMesh, opts: BoundarySmoothOptions) -> BoundarySmoother {
        let mut faces = Vec::new();
        let mut keys = Vec::new();
        for t in mesh.tet_ids() {
            let adj = mesh.adj(t);
            for (f, &h) in adj.iter().enumerate() {
                let take = if h == NO_ADJ {
                    true
                } else {
                    (h >> 2) > t && mesh.is_interface_face(t, f)
                };
                if take {
                    faces.push(mesh.face_vertices(t, f));
                    keys.push(face_key_of(mesh, t, f));
                }
            }
        }
        let n = mesh.n_points();
        let mut start = vec![0u32; n + 1];
        for f in &faces {
            for &v in f {
                start[v as usize + 1] += 1;
            }
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut at = vec![0u32; start[n] as usize];
        for (i, f) in faces.iter().enumerate() {
            for &v in f {
                at[fill[v as usize] as usize] = i as u32;
                fill[v as usize] += 1;
            }
        }
        // Feature neighbours.
        let mut line_nbrs: FastHashMap<u32, Vec<u32>> = FastHashMap::default();
        let mut fe: Vec<[u32; 2]> = mesh.feature_edges().keys().copied().collect();
        fe.sort_unstable();
        for e in &fe {
            line_nbrs.entry(e[0]).or_default().push(e[1]);
            line_nbrs.entry(e[1]).or_default().push(e[0]);
        }
        let mut kind = vec![Kind::Interior; n];
        let mut edge_count: FastHashMap<u32, u32> = FastHashMap::default();
        for v in 0..n as u32 {
            let fs = &at[start[v as usize] as usize..start[v as usize + 1] as usize];
            if fs.is_empty() {
                continue;
            }
            // A partition face is frozen: the rank on its other side must
            // see the same points.
            let on_cut = fs
                .iter()
                .any(|&f| crate::mesh::partition::is_partition_marker(keys[f as usize].0));
            kind[v as usize] = if mesh.is_corner(v)
                || mesh.is_required(v)
                || on_cut
                || !star_is_connected(&faces, fs, v)
            {
                Kind::Fixed
            } else if let Some(nb) = line_nbrs.get(&v) {
                // Under the linear rule (flat stars only) a line vertex stays:
                // the patches on either side of its line may be curved, and
                // sliding would then move their faces off the input surface.
                if nb.len() == 2
                    && opts.crease_angle > FLAT_ONLY
                    && straight(mesh.point(nb[0]), mesh.point(v), mesh.point(nb[1]))
                {
                    Kind::Line(nb[0], nb[1])
                } else {
                    Kind::Fixed
                }
            } else {
                let k0 = keys[fs[0] as usize];
                // A disk: every star edge at v in exactly two star faces.
                edge_count.clear();
                let mut same = true;
                for &f in fs {
                    same &= keys[f as usize] == k0;
                    for &u in &faces[f as usize] {
                        if u != v {
                            *edge_count.entry(u).or_insert(0) += 1;
                        }
                    }
                }
                if same
                    && edge_count.values().all(|&c| c == 2)
                    && !star_has_crease(mesh, &faces, fs, v, opts.crease_angle)
                {
                    Kind::Surface
                } else {
                    Kind::Fixed
                }
            };
        }
        let ref_faces = faces
            .iter()
            .map(|f| f.map(|v| mesh.point(v)))
            .collect::<Vec<_>>();
        let mut ref_pos = FastHashMap::default();
        for f in &faces {
            for &v in f {
                ref_pos.insert(v, mesh.point(v));
            }
        }
        BoundarySmoother {
            faces,
            keys,
            ref_faces,
            start,
            at,
            kind,
            ref_pos,
            line_nbrs,
            opts,
        }
    }

    fn star(&self, v: u32) -> &[u32] {
        let v = v as usize;
        if v + 1 >= self.start.len() {
            return &[];
        }
        &self.at[self.start[v] as usize..self.start[v + 1] as usize]
    }

    /// Whether `v` may move at all (a surface or a line vertex).
    pub fn is_movable(&self, v: u32) -> bool {
        matches!(
            self.kind.get(v as usize),
            Some(Kind::Surface | Kind::Line(..))
        )
    }

    /// Reference faces of key `k` at `v` or at its star neighbours.
    fn ref_set(&self, v: u32, k: Key, out: &mut Vec<u32>) {
        out.clear();
        for &f in self.star(v) {
            for &u in &self.faces[f as usize] {
                for &g in self.star(u) {
                    if self.keys[g as usize] == k && !out.contains(&g) {
                        out.push(g);
                    }
                }
            }
        }
    }

    /// The reference sets of every key of `v`'s star.
    fn ref_sets(&self, v: u32) -> Vec<RefSet> {
        let mut keys: Vec<Key> = self
            .star(v)
            .iter()
            .map(|&f| self.keys[f as usize])
            .collect();
        keys.sort_unstable();
        keys.dedup();
        keys.into_iter()
            .map(|key| {
                let mut faces = Vec::new();
                self.ref_set(v, key, &mut faces);
                let r = &self.ref_faces[faces[0] as usize];
                let n = (r[1] - r[0]).cross(r[2] - r[0]);
                let scale = (r[1] - r[0]).length().max((r[2] - r[0]).length());
                let flat = n.length() > 0.0 && {
                    let n = n.normalize();
                    faces.iter().all(|&f| {
                        self.ref_faces[f as usize]
                            .iter()
                            .all(|&p| (p - r[0]).dot(n).abs() <= 1e-12 * scale)
                    })
                };
                let plane = flat.then(|| (n.normalize(), r[0]));
                let axes = [0, 1, 2].map(|k| {
                    let c = r[0][k];
                    faces
                        .iter()
                        .all(|&f| self.ref_faces[f as usize].iter().all(|p| p[k] == c))
                        .then_some(c)
                });
                RefSet {
                    key,
                    faces,
                    plane,
                    axes,
                }
            })
            .collect()
    }

    fn project_on(&self, x: DVec3, set: &[u32]) -> (DVec3, f64) {
        let mut best = (x, f64::INFINITY);
        for &f in set {
            let r = &self.ref_faces[f as usize];
            let y = snap_axes(closest_point_on_triangle(x, r[0], r[1], r[2]).0, r);
            let d = (y - x).length_squared();
            if d < best.1 {
                best = (y, d);
            }
        }
        (best.0, best.1.sqrt())
    }

    /// The reference polyline of line vertex `v`: its two feature edges, as
    /// segments of reference positions.
    fn ref_polyline(&self, v: u32) -> Vec<[DVec3; 2]> {
        let mut segs = Vec::new();
        let mut seen: Vec<[u32; 2]> = Vec::new();
        let pos = |u: u32| self.ref_pos.get(&u).copied();
        let mut push = |a: u32, b: u32, segs: &mut Vec<[DVec3; 2]>| {
            let k = edge_key(a, b);
            if !seen.contains(&k) {
                seen.push(k);
                if let (Some(p), Some(q)) = (pos(a), pos(b)) {
                    segs.push([p, q]);
                }
            }
        };
        // Only the vertex's own two edges: they are collinear (see
        // `straight`), and beyond its neighbours the line may bend.
        if let Some(nb) = self.line_nbrs.get(&v) {
            for &u in nb {
                push(v, u, &mut segs);
            }
        }
        segs
    }

    /// Largest distance of the new star of `v` at `x` from the reference:
    /// sample points of each new constrained triangle against the reference
    /// faces of its key nearby, and the reference position of `v` against
    /// the new triangles.
    fn deviation(&self, mesh: &TetMesh, v: u32, x: DVec3, sets: &[RefSet]) -> f64 {
        let mut dev: f64 = 0.0;
        let r0 = self.ref_pos.get(&v).copied().unwrap_or(x);
        for rs in sets {
            let (k, scratch) = (rs.key, &rs.faces);
            if let Some((n, c)) = rs.plane {
                // A flat reference: the new triangles lie in the star's
                // polygon, in the plane, when their corners do.
                dev = dev.max((x - c).dot(n).abs());
                continue;
            }
            let mut to_ref = f64::INFINITY;
            for &f in self.star(v) {
                if self.keys[f as usize] != k {
                    continue;
                }
                let fv = self.faces[f as usize];
                let p = fv.map(|u| if u == v { x } else { mesh.point(u) });
                let samples = [
                    (p[0] + p[1] + p[2]) / 3.0,
                    0.5 * (p[0] + p[1]),
                    0.5 * (p[1] + p[2]),
                    0.5 * (p[2] + p[0]),
                    x,
                ];
                for s in samples {
                    dev = dev.max(self.project_on(s, scratch).1);
                }
                to_ref =
                    to_ref.min((closest_point_on_triangle(r0, p[0], p[1], p[2]).0 - r0).length());
            }
            if to_ref.is_finite() {
                dev = dev.max(to_ref);
            }
        }
        dev
    }

    /// The Hausdorff cap at `v`.
    fn cap(&self, mesh: &TetMesh, v: u32) -> f64 {
        if let Some(d) = self.opts.hausd {
            return d;
        }
        let x = mesh.point(v);
        let mut sum = 0.0;
        let mut n = 0;
        for &f in self.star(v) {
            for &u in &self.faces[f as usize] {
                if u != v {
                    sum += (mesh.point(u) - x).length();
                    n += 1;
                }
            }
        }
        if n == 0 {
            0.0
        } else {
            self.opts.hausd_rel * sum / n as f64
        }
    }

    /// Projects a trial point for `v` onto its reference (triangles for a
    /// surface vertex, polyline for a line vertex).
    fn project(
        &self,
        v: u32,
        x: DVec3,
        set: &[u32],
        flat: Option<&RefSet>,
        line: &[[DVec3; 2]],
    ) -> DVec3 {
        match self.kind[v as usize] {
            Kind::Surface => match flat {
                Some(RefSet {
                    plane: Some((n, c)),
                    axes,
                    ..
                }) => {
                    let mut y = x - *n * (x - *c).dot(*n);
                    for k in 0..3 {
                        if let Some(a) = axes[k] {
                            y[k] = a;
                        }
                    }
                    y
                }
                _ => self.project_on(x, set).0,
            },
            Kind::Line(..) => {
                let mut best = (x, f64::INFINITY);
                for s in line {
                    let mut y = closest_on_segment(x, s[0], s[1]);
                    for k in 0..3 {
                        if s[0][k] == s[1][k] {
                            y[k] = s[0][k];
                        }
                    }
                    let d = (y - x).length_squared();
                    if d < best.1 {
                        best = (y, d);
                    }
                }
                best.0
            }
            _ => x,
        }
    }

    /// Where `v` (ball `ball`) should move, if anywhere: the new position
    /// and the ball's qualities there (in ball order). Reads only the ball.
    pub fn smooth_vertex(
        &self,
        mesh: &TetMesh,
        v: u32,
        ball: &[u32],
        bp: &mut BallPoints,
    ) -> Option<(DVec3, Vec<f64>)> {
        let kind = self.kind[v as usize];
        if !matches!(kind, Kind::Surface | Kind::Line(..)) || ball.is_empty() {
            return None;
        }
        bp.load(mesh, v, ball);
        let x0 = mesh.point(v);
        let qs0: Vec<f64> = (0..bp.len()).map(|i| bp.quality(i, x0)).collect();
        let q0 = qs0.iter().copied().fold(f64::INFINITY, f64::min);
        let m0 = qs0.iter().sum::<f64>() / qs0.len() as f64;
        if q0.is_nan() || q0 >= self.opts.laplacian_threshold.max(self.opts.threshold) {
            return None;
        }
        let mut set = Vec::new();
        let mut line = Vec::new();
        match kind {
            Kind::Surface => {
                let k = self.keys[self.star(v)[0] as usize];
                self.ref_set(v, k, &mut set);
            }
            _ => line = self.ref_polyline(v),
        }
        let set = &set[..];
        let line = &line[..];
        let cap = self.cap(mesh, v);
        let sets = self.ref_sets(v);
        let flat = match kind {
            Kind::Surface => sets.first().filter(|r| r.plane.is_some()),
            _ => None,
        };
        let mut scratch = ();
        // Evaluates a projected trial point: (min, mean) if it is valid and
        // passes `want` (checked before the costlier tests).
        let eval = |y: DVec3, _: &mut (), want: &dyn Fn(f64, f64) -> bool| -> Option<(f64, f64)> {
            let mut q = f64::INFINITY;
            let mut sum = 0.0;
            for i in 0..bp.len() {
                let s = bp.quality(i, y);
                if s.is_nan() || s <= 0.0 {
                    return None;
                }
                q = q.min(s);
                sum += s;
            }
            let m = sum / bp.len() as f64;
            if !want(q, m) || !bp.stays_positive(y) {
                return None;
            }
            if self.deviation(mesh, v, y, &sets) > cap {
                return None;
            }
            Some((q, m))
        };
        // Surface neighbours (the link of the star, or the line neighbours).
        let mut nbrs: Vec<u32> = Vec::new();
        match kind {
            Kind::Line(a, b) => nbrs.extend([a, b]),
            _ => {
                for &f in self.star(v) {
                    for &u in &self.faces[f as usize] {
                        if u != v && !nbrs.contains(&u) {
                            nbrs.push(u);
                        }
                    }
                }
            }
        }
        let mut best: Option<(DVec3, f64, f64)> = None;
        let better = |cand: (f64, f64), best: &Option<(DVec3, f64, f64)>| -> bool {
            let (q, m) = cand;
            let (bq, bm) = best.map_or((q0, m0), |b| (b.1, b.2));
            if q0 < self.opts.threshold {
                // The mean may fall only to save a sliver (below 0.2, about
                // 11.5°): elsewhere a move raising the worst at the cost of
                // the mean would lower the average.
                (m >= m0 || q0 < SLIVER)
                    && (q > bq + 1e-12 || (q >= bq && best.is_some() && m > bm + 1e-12))
            } else {
                q >= q0 && m > bm + 1e-12 && (best.is_none() || q >= bq - 1e-12)
            }
        };
        // 1. Tangential Laplacian (and halfway to it).
        let centroid = nbrs.iter().map(|&u| mesh.point(u)).sum::<DVec3>() / nbrs.len() as f64;
        for w in [1.0, 0.5] {
            let y = self.project(v, x0 + w * (centroid - x0), set, flat, line);
            if y == x0 {
                continue;
            }
            if let Some(c) = eval(y, &mut scratch, &|q, m| better((q, m), &best)) {
                best = Some((y, c.0, c.1));
            }
        }
        // 2. For poor balls: projected max-min ascent (active-set gradient,
        // as the interior optimiser) or, on a line, a search along it.
        if q0 < self.opts.threshold {
            match kind {
                Kind::Line(a, b) => {
                    for u in [a, b] {
                        let pu = mesh.point(u);
                        for s in [0.03, 0.06, 0.1, 0.15, 0.2, 0.27, 0.35, 0.45] {
                            let y = self.project(v, x0 + s * (pu - x0), set, flat, line);
                            if let Some(c) = eval(y, &mut scratch, &|q, m| better((q, m), &best)) {
                                best = Some((y, c.0, c.1));
                            }
                        }
                    }
                }
                _ => {
                    let (mut x, mut q, mut _m) = best.unwrap_or((x0, q0, m0));
                    let scale = nbrs
                        .iter()
                        .map(|&u| (mesh.point(u) - x0).length())
                        .sum::<f64>()
                        / nbrs.len() as f64;
                    let h = 1e-6 * scale;
                    let mut grads = Vec::new();
                    for _ in 0..8 {
                        // Tangent plane: normal of the nearest reference face.
                        let normal = if let Some(RefSet {
                            plane: Some((n, _)),
                            ..
                        }) = flat
                        {
                            *n
                        } else {
                            let mut bestf = (DVec3::Z, f64::INFINITY);
                            for &f in set {
                                let r = &self.ref_faces[f as usize];
                                let y = closest_point_on_triangle(x, r[0], r[1], r[2]).0;
                                let d = (y - x).length_squared();
                                if d < bestf.1 {
                                    bestf = ((r[1] - r[0]).cross(r[2] - r[0]).normalize(), d);
                                }
                            }
                            bestf.0
                        };
                        grads.clear();
                        for i in 0..bp.len() {
                            let qi = bp.quality(i, x);
                            if qi > q + 1e-3 {
                                continue;
                            }
                            let mut g = DVec3::ZERO;
                            for axis in 0..3 {
                                let mut e = DVec3::ZERO;
                                e[axis] = h;
                                g[axis] = (bp.quality(i, x + e) - bp.quality(i, x - e)) / (2.0 * h);
                            }
                            grads.push(g - normal * g.dot(normal));
                        }
                        if grads.is_empty() || !normal.is_finite() {
                            break;
                        }
                        let d = super::optimize::min_norm_in_hull(&grads);
                        let dn = d.length();
                        if dn < 1e-12 {
                            break;
                        }
                        let mut alpha = 0.2 * scale / dn;
                        let mut moved = false;
                        for _ in 0..8 {
                            let y = self.project(v, x + alpha * d, set, flat, line);
                            if let Some((qy, my)) = eval(y, &mut scratch, &|qy, _| qy > q + 1e-12) {
                                {
                                    x = y;
                                    q = qy;
                                    _m = my;
                                    moved = true;
                                    if better((q, my), &best) {
                                        best = Some((x, q, my));
                                    }
                                    break;
                                }
                            }
                            alpha *= 0.5;
                        }
                        if !moved {
                            break;
                        }
                    }
                }
            }
        }
        let (x, _, _) = best?;
        Some((x, (0..bp.len()).map(|i| bp.quality(i, x)).collect()))
    }

    /// One pass over `verts`, by colour classes (no two vertices of a class
    /// share a tet, so a class's moves are decided in parallel on the mesh
    /// as it stands and applied in order: the result does not depend on the
    /// number of threads). Returns the tets whose quality changed with their
    /// new quality.
    pub fn pass(
        &self,
        mesh: &mut TetMesh,
        verts: &[u32],
        report: &mut BoundarySmoothReport,
    ) -> Vec<(u32, f64)> {
        use rayon::prelude::*;
        let mut changed = Vec::new();
        for class in super::colour::colour_classes(mesh, verts) {
            let m = &*mesh;
            let moves: Vec<Option<Decided>> = class
                .par_iter()
                .with_min_len(16)
                .map_init(
                    || (Vec::new(), BallPoints::default()),
                    |(ball, bp), &v| {
                        m.ball(v, ball);
                        self.smooth_vertex(m, v, ball, bp)
                            .map(|(x, qs)| (v, x, ball.clone(), qs))
                    },
                )
                .collect();
            for (v, x, ball, qs) in moves.into_iter().flatten() {
                mesh.set_point(v, x);
                match self.kind[v as usize] {
                    Kind::Line(..) => report.line_moves += 1,
                    _ => report.surface_moves += 1,
                }
                changed.extend(ball.into_iter().zip(qs));
            }
        }
        changed
    }

    /// The movable surface and line vertices, in id order.
    pub fn movable_vertices(&self) -> Vec<u32> {
        (0..self.kind.len() as u32)
            .filter(|&v| self.is_movable(v))
            .collect()
    }
}

/// Whether every tet of `ball` is positive (exact and f64) — for tests.
#[cfg(test)]
pub fn ball_valid(mesh: &TetMesh, ball: &[u32]) -> bool {
    ball.iter().all(|&t| {
        let p = mesh.tet_points(t);
        crate::geom::orient3d(p[0], p[1], p[2], p[3]) > 0.0 && crate::geom::tet_min_sine(&p) > 0.0
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 6 Kuhn tets of each unit cube of an n³ block: the crate's
    /// generator (on the unit cube, x fastest) scaled by n, so that point
    /// (i, j, k) has id i + (n+1)(j + (n+1)k).
    fn kuhn(n: usize) -> TetMesh {
        let mut d = crate::mesh::generate::cube_grid(n);
        for p in &mut d.points {
            *p = p.map(|x| (x * n as f64).round());
        }
        TetMesh::from_data(&d).unwrap().0
    }

    #[test]
    fn face_vertex_moves_in_plane_and_keeps_volume() {
        let mut m = kuhn(3);
        // Disturb one vertex of the face z = 0 inside the plane.
        let v = 1 + 4; // (1, 1, 0)
        assert_eq!(m.point(v), DVec3::new(1.0, 1.0, 0.0));
        m.set_point(v, DVec3::new(1.6, 1.55, 0.0));
        let vol = |m: &TetMesh| -> f64 {
            m.tet_ids()
                .map(|t| crate::geom::tet_volume(&m.tet_points(t)))
                .sum()
        };
        assert!((vol(&m) - 27.0).abs() < 1e-12);
        let s = BoundarySmoother::new(&m, BoundarySmoothOptions::default());
        assert!(s.is_movable(v));
        let mut ball = Vec::new();
        m.ball(v, &mut ball);
        let before = crate::improve::ball_quality(&m, &ball);
        let mut report = BoundarySmoothReport::default();
        s.pass(&mut m, &[v], &mut report);
        assert_eq!(report.surface_moves, 1);
        let after = crate::improve::ball_quality(&m, &ball);
        assert!(after > before, "{before} -> {after}");
        assert_eq!(m.point(v).z, 0.0, "the vertex stays on its face plane");
        assert!(ball_valid(&m, &ball));
        m.check().unwrap();
        assert!((vol(&m) - 27.0).abs() < 1e-12, "volume {}", vol(&m));
    }

    /// Two square pyramids, one below the plane z = 0 and one above it
    /// (turned by 45°), share only the vertex `v` at the origin, the centre
    /// of both bases ([`crate::mesh::generate::pinched_pyramids`]). Each
    /// piece's star at `v` is a flat disk, so without the connectivity test
    /// `v` would count as a surface vertex, and a walk from one of its tets
    /// sees four of its eight tets.
    #[test]
    fn a_pinch_vertex_stays() {
        let data = crate::mesh::generate::pinched_pyramids([0.0; 3], std::f64::consts::SQRT_2, 1.0);
        let mut m = TetMesh::from_data(&data).expect("two pyramids").0;
        assert!(m
            .tet_ids()
            .all(|t| crate::geom::tet_volume(&m.tet_points(t)) > 0.0));
        let mut ball = Vec::new();
        m.ball(0, &mut ball);
        assert_eq!(ball.len(), 4, "the walk sees one pyramid");
        crate::refine::features::detect_features(&mut m, 45.0);
        let s = BoundarySmoother::new(&m, BoundarySmoothOptions::default());
        assert_eq!(s.kind[0], Kind::Fixed);
        // A base corner is on a crease of its own pyramid: fixed too.
        assert!(!s.is_movable(3));
        m.set_point(0, DVec3::new(0.3, 0.1, 0.0));
        let s = BoundarySmoother::new(&m, BoundarySmoothOptions::default());
        let mut report = BoundarySmoothReport::default();
        s.pass(&mut m, &[0], &mut report);
        assert_eq!(report.surface_moves, 0);
        assert_eq!(m.point(0), DVec3::new(0.3, 0.1, 0.0));
    }

    #[test]
    fn corners_and_edges_classified() {
        let mut m = kuhn(2);
        crate::refine::features::detect_features(&mut m, 45.0);
        let s = BoundarySmoother::new(&m, BoundarySmoothOptions::default());
        // Corner (0,0,0) fixed; edge midpoint (1,0,0) on a line; face centre
        // (1,1,0) on a surface; (1,1,1) interior.
        assert_eq!(s.kind[0], Kind::Fixed);
        assert!(matches!(s.kind[1], Kind::Line(..)));
        assert_eq!(s.kind[4], Kind::Surface);
        assert_eq!(s.kind[13], Kind::Interior);
    }

    #[test]
    fn line_vertex_slides_along_its_edge() {
        let mut m = kuhn(2);
        crate::refine::features::detect_features(&mut m, 45.0);
        let v = 1; // (1, 0, 0) on the edge y = z = 0
        m.set_point(v, DVec3::new(1.7, 0.0, 0.0));
        let s = BoundarySmoother::new(&m, BoundarySmoothOptions::default());
        let mut ball = Vec::new();
        m.ball(v, &mut ball);
        let before = crate::improve::ball_quality(&m, &ball);
        let mut report = BoundarySmoothReport::default();
        s.pass(&mut m, &[v], &mut report);
        assert_eq!(report.line_moves, 1);
        let p = m.point(v);
        assert_eq!((p.y, p.z), (0.0, 0.0), "stays on the line");
        assert!(p.x < 1.7 && p.x > 0.0);
        assert!(crate::improve::ball_quality(&m, &ball) > before);
        m.check().unwrap();
    }
}
