//! Sierpinski polyhedra by subdivision (Akleman, Srinivasan,
//! Chen et al., "Generalized Sierpinski polyhedra", a subdivision-inspired
//! construction on top of Topological Mesh Modeling).
//!
//! One step of the paper's scheme on a closed manifold mesh: put a vertex at
//! the midpoint of every edge, cut every corner of every face off as a
//! triangle (old vertex, two adjacent midpoints), and remove the central face
//! that is left. Around each old vertex `v` of valence `n` the `n` corner
//! triangles form an open pyramid whose base is the `n`-gon of the midpoints
//! of the edges at `v`; the paper closes it with a "back face" and joins two
//! pyramids at every midpoint. Repeating the step on every pyramid gives a
//! connected polyhedron of fast-growing genus whose pieces approach
//! Sierpinski tetrahedra.
//!
//! ## How the joints are represented
//!
//! The paper joins the two pyramids that meet at a midpoint with a
//! zero-length *self-loop* edge (an edge from the midpoint to itself, inserted
//! with INSERTEDGE between the corners of the two central faces). Each back
//! face then carries a self-loop at each of its corners, and the self-loop
//! is a zero-length tube joining the two pyramids. Faces with self-loops
//! repeat a vertex and cannot be written to `.obj`, so this module uses an
//! equivalent manifold construction instead, a **tiny tube**:
//!
//! - every pyramid gets its own copy of each midpoint (the two copies at a
//!   joint are at the same position), so the pieces are closed polyhedra that
//!   touch at the joints;
//! - in the written mesh, the copy in each piece is cut off at a fraction
//!   `neck` of its three incident edges (a tiny triangular hole: the joint
//!   vertices are always 3-valent in their piece), and the two triangular
//!   holes are joined by a tube of three quadrilaterals.
//!
//! This is the connected sum the self-loop stands for, so the surface has the
//! genus the paper's construction has. Each joint adds 4 vertices, 9 edges
//! and 3 faces to the two touching pieces (Euler characteristic −2). Further
//! steps act on the pieces, never on the tubes. An input that holds the
//! tubes of an earlier run (three quads in a ring whose edges through the
//! rims meet in one point, the joint) is turned back into its pieces and
//! joints first (tubes removed, each rim closed into one vertex at the
//! joint), so that feeding an output back in goes on as if all steps had
//! been asked for at once (subdividing the tubes as ordinary faces would
//! give genus 39 instead of 15 for the one-step tetrahedron fed back); when
//! that does not give closed pieces the input is refused with
//! [`SurfaceError::SierpinskiJoint`]. Tubes are recognised in the exact
//! coordinates of `.obj`, `.off` and `.ply` outputs, not in an `.stl`
//! (there the quads are split into triangles and the points rounded).
//!
//! ## Counts
//!
//! Let the input be a closed oriented manifold with `V` (used) vertices and
//! `E` edges. After step `k ≥ 1`:
//!
//! - every piece is a pyramid (an `n`-gon base and `n` triangles); the sum of
//!   the apex valences is `S_k = 2E·4^(k−1)` (one step turns a pyramid with
//!   apex valence `n` into one `n`-pyramid and `n` tetrahedra: `S → 4S`);
//! - pieces: `P_k = V + 2E(4^(k−1) − 1)/3` (`P_(k+1) = P_k + S_k`);
//! - joints: `J_k = E(4^k − 1)/3` (`J_1 = E`, and each step keeps every joint
//!   and adds one per piece edge, `J_(k+1) = J_k + 2S_k`);
//! - the pieces alone have `S_k + P_k` vertices, `2S_k` edges and `S_k + P_k`
//!   faces;
//! - the written manifold has
//!   `V_k = S_k + P_k + 4J_k`, `E_k = 2S_k + 9J_k`, `F_k = S_k + P_k + 3J_k`,
//!   so `χ_k = V_k − E_k + F_k = 2P_k − 2J_k = 2V − E(4^k + 2)/3`;
//! - for a connected input the result is connected and its genus is
//!   `g_k = 1 − χ_k/2 = 1 − V + E(4^k + 2)/6`
//!   (tetrahedron `4^k − 1`: 3, 15, 63, …; cube `2·4^k − 3`: 5, 29, 125, …;
//!   octahedron `2·4^k − 1`: 7, 31, 127, …).
//!
//! The paper says that after the first iteration "each iteration increases
//! the genus of the shape four times": exactly, the increase per step
//! quadruples, `g_(k+1) − g_k = 2E·4^(k−1)`, and
//! `g_(k+1) = 4g_k + 3(V − 1) − E`, so `g_(k+1)/g_k → 4`.

use super::closed_manifold::closed_half_edges;
use super::error::SurfaceError;
use super::lineage::{observe, FaceAttributes, StepObserver, Subdivided};
use super::polymesh::{HalfEdges, PolyMesh, NO_TWIN};
use glam::{DMat3, DVec3};

/// Options of [`sierpinski_with`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SierpinskiOptions {
    /// Where the tube at a joint leaves each piece, as a fraction of the
    /// piece edges at the joint (0 < neck < 0.5). Small values make the
    /// pieces look as if they touched in a point, as in the paper.
    pub neck: f64,
}

impl Default for SierpinskiOptions {
    /// `neck = 0.05`.
    fn default() -> Self {
        SierpinskiOptions { neck: 0.05 }
    }
}

impl SierpinskiOptions {
    /// Checks the options: the neck lies strictly between 0 and 0.5.
    pub fn check(&self) -> Result<(), SurfaceError> {
        let neck = self.neck;
        if neck > 0.0 && neck < 0.5 {
            Ok(())
        } else {
            Err(SurfaceError::Parameter(format!(
                "the Sierpinski neck must lie strictly between 0 and 0.5, got {neck}"
            )))
        }
    }
}

/// `steps` Sierpinski steps (Akleman et al.'s construction) on a closed, consistently
/// oriented manifold polygon mesh, with the default [`SierpinskiOptions`].
///
/// Returns one closed oriented manifold per connected component of the
/// input, of the genus given in the [module documentation](self). `steps = 0`
/// returns the validated input unchanged. Vertices used by no face are
/// dropped.
pub fn sierpinski(mesh: &PolyMesh, steps: usize) -> Result<PolyMesh, SurfaceError> {
    sierpinski_with(mesh, steps, &SierpinskiOptions::default())
}

/// [`sierpinski`] with explicit options.
pub fn sierpinski_with(
    mesh: &PolyMesh,
    steps: usize,
    options: &SierpinskiOptions,
) -> Result<PolyMesh, SurfaceError> {
    sierpinski_tracked(mesh, steps, options, None).map(|s| s.mesh)
}

/// [`sierpinski_with`] with the face attributes of [`super::lineage`]
/// (group 0 corner triangle, 1 back face, 2 tube; a tube has the generation
/// of the step that made its joint and the origin of the face of the edge
/// whose midpoint the joint is; the joints of an earlier run's output fed
/// in count as generation 0, with the origin of their first tube face) and
/// an observer of every generation.
pub fn sierpinski_tracked(
    mesh: &PolyMesh,
    steps: usize,
    options: &SierpinskiOptions,
    mut observer: Option<&mut StepObserver<'_>>,
) -> Result<Subdivided, SurfaceError> {
    options.check()?;
    let neck = options.neck;
    let he = closed_half_edges(mesh)?;
    let input = FaceAttributes::input(mesh.faces.len());
    // Guard against counts that overflow 32-bit ids: V_k from the module docs.
    let e = he.edges.len() as f64;
    let v = he.vertex_out.iter().filter(|&&h| h != NO_TWIN).count() as f64;
    let q = 4f64.powi(steps.min(64) as i32 - 1);
    let estimate = 2.0 * e * q + (v + 2.0 * e * (q - 1.0) / 3.0) + 4.0 * e * (4.0 * q - 1.0) / 3.0;
    if estimate > i32::MAX as f64 {
        return Err(SurfaceError::TooLarge {
            steps,
            estimate,
            what: "vertices",
        });
    }
    if !observe(&mut observer, 0, mesh, &input) || steps == 0 {
        return Ok(Subdivided {
            mesh: mesh.clone(),
            attributes: input,
            steps: 0,
        });
    }
    // An earlier run's output: its tubes become joints again, so that the
    // steps go on from its pieces as if all had been asked for at once.
    let tubes = find_tubes(mesh, &he);
    let start = if tubes.is_empty() {
        // `pyramids` takes the mesh and its adjacency directly below.
        Pieces {
            mesh: PolyMesh::default(),
            joints: Vec::new(),
            attributes: input,
            joint_attributes: Vec::new(),
        }
    } else {
        let refuse = || SurfaceError::SierpinskiJoint {
            faces: tubes[0].faces.map(|f| f as usize),
            point: tubes[0].point.to_array(),
        };
        let pieces = untube(mesh, &tubes).ok_or_else(refuse)?;
        closed_half_edges(&pieces.mesh).map_err(|_| refuse())?;
        pieces
    };
    let mut pieces = if tubes.is_empty() {
        pyramids(mesh, &he, &start, 1)
    } else {
        start.step(1)?
    };
    let mut done = 1;
    if observer.is_some() {
        let (m, a) = pieces.with_tubes(neck)?;
        if !observe(&mut observer, 1, &m, &a) {
            return Ok(Subdivided {
                mesh: m,
                attributes: a,
                steps: 1,
            });
        }
    }
    for k in 1..steps {
        pieces = pieces.step(k as u32 + 1)?;
        done = k + 1;
        if observer.is_some() {
            let (m, a) = pieces.with_tubes(neck)?;
            if !observe(&mut observer, done, &m, &a) {
                return Ok(Subdivided {
                    mesh: m,
                    attributes: a,
                    steps: done,
                });
            }
        }
    }
    let (mesh, attributes) = pieces.with_tubes(neck)?;
    Ok(Subdivided {
        mesh,
        attributes,
        steps: done,
    })
}

/// A joint tube of an earlier run, found in an input mesh.
#[derive(Clone, Debug, PartialEq)]
struct Tube {
    /// Its three quads.
    faces: [u32; 3],
    /// The vertices of its two triangular rims, one rim per piece.
    rims: [[u32; 3]; 2],
    /// Where the edges through the rims meet: the joint.
    point: DVec3,
}

/// The joint tubes of an earlier run in a closed mesh.
///
/// A tube ([`Pieces::with_tubes`]) is three quads in a ring: in each, two
/// opposite sides are shared with the other two quads and the other two
/// sides lie on the two triangular rims, so the ring has six vertices. Each
/// rim vertex was cut at `neck` along a piece edge leaving the joint, so it
/// has exactly one neighbour outside the tube (on the same piece edge), and
/// the six lines from those neighbours through the rim vertices all meet at
/// the joint, beyond the rims.
/// The topology alone also fits an ordinary ring of three quads (a torus
/// three quads round); the concurrent lines are what make a joint.
fn find_tubes(mesh: &PolyMesh, he: &HalfEdges) -> Vec<Tube> {
    let p = &mesh.points;
    let quad = |f: u32| mesh.faces[f as usize].len() == 4;
    let mut in_tube = vec![false; mesh.faces.len()];
    let mut tubes = Vec::new();
    for f in 0..mesh.faces.len() as u32 {
        if !quad(f) || in_tube[f as usize] {
            continue;
        }
        let s = he.face_start[f as usize];
        for off in 0..2 {
            // Tube edges: sides off and off + 2 of f, and the side of g1
            // opposite its side shared with f.
            let (h1, h2) = (s + off, s + off + 2);
            let (t1, t2) = (he.twin[h1 as usize], he.twin[h2 as usize]);
            if t1 == NO_TWIN || t2 == NO_TWIN {
                continue;
            }
            let (g1, g2) = (he.face[t1 as usize], he.face[t2 as usize]);
            if g1 == g2 || g1 == f || g2 == f || !quad(g1) || !quad(g2) {
                continue;
            }
            let o1 = he.next(he.next(t1));
            let o2 = he.next(he.next(t2));
            if he.twin[o1 as usize] != o2 {
                continue;
            }
            let mut ring: Vec<u32> = [h1, h2, o1]
                .iter()
                .flat_map(|&h| [he.origin[h as usize], he.dest(h)])
                .collect();
            ring.sort_unstable();
            ring.dedup();
            if ring.len() != 6 {
                continue;
            }
            // One line per rim vertex, from its one neighbour outside.
            let mut lines = Vec::with_capacity(6);
            for &r in &ring {
                let (nbrs, _) = he.ring(r);
                let mut outside = nbrs.iter().filter(|v| !ring.contains(v));
                match (outside.next(), outside.next()) {
                    (Some(&u), None) => lines.push((p[u as usize], p[r as usize])),
                    _ => break,
                }
            }
            if lines.len() != 6 {
                continue;
            }
            let Some(point) = concurrent(&lines) else {
                continue;
            };
            // The rims: the sides that are not tube edges (each quad's
            // sides after its two tube edges) join the vertices of a rim.
            let mut rim_of = [0usize, 1, 2, 3, 4, 5];
            let slot = |v: u32| ring.iter().position(|&x| x == v).unwrap_or(0);
            for h in [h1, h2, t1, o1, t2, o2] {
                let side = he.next(h);
                let (a, b) = (slot(he.origin[side as usize]), slot(he.dest(side)));
                let (ra, rb) = (rim_of[a], rim_of[b]);
                for r in &mut rim_of {
                    if *r == rb {
                        *r = ra;
                    }
                }
            }
            let first: Vec<u32> = (0..6)
                .filter(|&k| rim_of[k] == rim_of[0])
                .map(|k| ring[k])
                .collect();
            let second: Vec<u32> = (0..6)
                .filter(|&k| rim_of[k] != rim_of[0])
                .map(|k| ring[k])
                .collect();
            let (Ok(a), Ok(b)) = (<[u32; 3]>::try_from(first), <[u32; 3]>::try_from(second)) else {
                continue;
            };
            for g in [f, g1, g2] {
                in_tube[g as usize] = true;
            }
            tubes.push(Tube {
                faces: [f, g1, g2],
                rims: [a, b],
                point,
            });
            break;
        }
    }
    tubes
}

/// The pieces and joints an earlier run's output was made from: every tube
/// removed and each of its rims collapsed back into one joint vertex at the
/// joint's position; faces, attributes and joints as [`pyramids`] expects
/// them (the input's faces are generation 0, a joint has generation 0 and
/// the origin of its first tube face). `None` when that does not give
/// closed pieces (rims sharing vertices, a face collapsing).
fn untube(mesh: &PolyMesh, tubes: &[Tube]) -> Option<Pieces> {
    let nf = mesh.faces.len();
    let mut points = mesh.points.clone();
    let mut map: Vec<u32> = (0..points.len() as u32).collect();
    let mut moved = vec![false; points.len()];
    let mut is_tube = vec![false; nf];
    let mut joints = Vec::with_capacity(tubes.len());
    let mut joint_attributes = Vec::with_capacity(tubes.len());
    for t in tubes {
        let mut ends = [0u32; 2];
        for (end, rim) in ends.iter_mut().zip(&t.rims) {
            *end = points.len() as u32;
            points.push(t.point);
            for &v in rim {
                if std::mem::replace(&mut moved[v as usize], true) {
                    return None;
                }
                map[v as usize] = *end;
            }
        }
        joints.push(ends);
        joint_attributes.push([0, t.faces[0]]);
        for f in t.faces {
            is_tube[f as usize] = true;
        }
    }
    let mut faces = Vec::with_capacity(nf);
    let mut attributes = FaceAttributes::with_capacity(nf);
    for (f, face) in mesh.faces.iter().enumerate() {
        if is_tube[f] {
            continue;
        }
        let mut out: Vec<u32> = face.iter().map(|&v| map[v as usize]).collect();
        out.dedup();
        while out.len() > 1 && out.first() == out.last() {
            out.pop();
        }
        if out.len() < 3 {
            return None;
        }
        faces.push(out);
        attributes.generation.push(0);
        attributes.origin.push(f as u32);
        attributes.group.push(0);
    }
    Some(Pieces {
        mesh: PolyMesh { points, faces },
        joints,
        attributes,
        joint_attributes,
    })
}

/// The point where the lines `u -> r` meet beyond every `r`, or `None`
/// when they do not (up to rounding).
fn concurrent(lines: &[(DVec3, DVec3)]) -> Option<DVec3> {
    // Least squares: Σ (I − d dᵀ) x = Σ (I − d dᵀ) r.
    let mut m = DMat3::ZERO;
    let mut b = DVec3::ZERO;
    let mut scale: f64 = 0.0;
    for &(u, r) in lines {
        let d = (r - u).normalize_or_zero();
        if d == DVec3::ZERO {
            return None;
        }
        scale = scale.max(u.distance(r));
        let proj = DMat3::IDENTITY - DMat3::from_cols(d * d.x, d * d.y, d * d.z);
        m += proj;
        b += proj * r;
    }
    if m.determinant().abs() < 1e-12 {
        return None;
    }
    let x = m.inverse() * b;
    let tol = 1e-9 * scale;
    lines
        .iter()
        .all(|&(u, r)| {
            let d = (r - u).normalize();
            let off = (x - r) - d * (x - r).dot(d);
            let along = (x - r).dot(d);
            off.length() <= tol && along > 0.0
        })
        .then_some(x)
}

/// Closed pieces that touch at joints: pairs of vertices (one in each piece)
/// at the same position.
struct Pieces {
    mesh: PolyMesh,
    joints: Vec<[u32; 2]>,
    /// Attributes of the faces of `mesh`.
    attributes: FaceAttributes,
    /// Generation and origin face of each joint (of its tube).
    joint_attributes: Vec<[u32; 2]>,
}

const NONE: u32 = u32::MAX;

/// The outgoing half-edges of `v` in clockwise order (the reverse of
/// [`HalfEdges::outgoing`]): consecutive entries `v -> u`, `v -> w` lie in the
/// one face in which `u` precedes and `w` follows `v`.
fn clockwise(he: &HalfEdges, v: u32) -> Vec<u32> {
    let mut ring = he.outgoing(v);
    ring.reverse();
    ring
}

impl Pieces {
    fn step(&self, generation: u32) -> Result<Pieces, SurfaceError> {
        let he = closed_half_edges(&self.mesh)?;
        Ok(pyramids(&self.mesh, &he, self, generation))
    }

    /// The manifold: every joint becomes a tube of three quadrilaterals
    /// between two triangular holes cut at `neck` along the joint's edges.
    fn with_tubes(&self, neck: f64) -> Result<(PolyMesh, FaceAttributes), SurfaceError> {
        let he = closed_half_edges(&self.mesh)?;
        let p = &self.mesh.points;
        let nv = p.len();
        let mut is_joint = vec![false; nv];
        for j in &self.joints {
            is_joint[j[0] as usize] = true;
            is_joint[j[1] as usize] = true;
        }
        let mut points = Vec::new();
        let mut new_id = vec![NONE; nv];
        // Truncation vertex on each half-edge leaving a joint vertex.
        let mut cut = vec![NONE; he.len()];
        for v in 0..nv as u32 {
            if he.vertex_out[v as usize] == NO_TWIN {
                continue;
            }
            if is_joint[v as usize] {
                let a = p[v as usize];
                for h in he.outgoing(v) {
                    cut[h as usize] = points.len() as u32;
                    points.push(a + neck * (p[he.dest(h) as usize] - a));
                }
            } else {
                new_id[v as usize] = points.len() as u32;
                points.push(p[v as usize]);
            }
        }
        let mut faces = Vec::with_capacity(self.mesh.faces.len() + 3 * self.joints.len());
        for (f, face) in self.mesh.faces.iter().enumerate() {
            let n = face.len();
            let mut out = Vec::with_capacity(2 * n);
            for (h, &v) in (he.face_start[f]..).zip(face) {
                if is_joint[v as usize] {
                    // u -> v -> w becomes u -> cut(v->u) -> cut(v->w) -> w.
                    out.push(cut[he.twin[he.prev(h) as usize] as usize]);
                    out.push(cut[h as usize]);
                } else {
                    out.push(new_id[v as usize]);
                }
            }
            faces.push(out);
        }
        let mut attributes = self.attributes.clone();
        for (&[a, b], &[generation, origin]) in self.joints.iter().zip(&self.joint_attributes) {
            // Rings: the face of ring[j + 1] holds cut(ring[j]) -> cut(ring[j + 1]).
            let ta: Vec<u32> = clockwise(&he, a).iter().map(|&h| cut[h as usize]).collect();
            let tb: Vec<u32> = clockwise(&he, b).iter().map(|&h| cut[h as usize]).collect();
            let d = ta.len();
            if tb.len() != d {
                return Err(SurfaceError::Parameter(format!(
                    "internal: joint {a}-{b} joins vertices of valence {d} and {}",
                    tb.len()
                )));
            }
            // Pair hole A (walked forwards) with hole B (walked backwards)
            // with the rotation that makes the tube shortest.
            let offset = (0..d)
                .min_by(|&c1, &c2| {
                    let len = |c: usize| -> f64 {
                        (0..d)
                            .map(|j| {
                                let k = (c + d - j) % d;
                                points[ta[j] as usize].distance_squared(points[tb[k] as usize])
                            })
                            .sum()
                    };
                    len(c1).total_cmp(&len(c2))
                })
                .unwrap_or(0);
            for j in 0..d {
                let k = (offset + d - j) % d;
                let k1 = (offset + 2 * d - j - 1) % d;
                faces.push(vec![ta[(j + 1) % d], ta[j], tb[k], tb[k1]]);
                attributes.generation.push(generation);
                attributes.origin.push(origin);
                attributes.group.push(2);
            }
        }
        Ok((PolyMesh { points, faces }, attributes))
    }
}

/// One step (number `generation`) on `mesh`, the mesh of `old` or the
/// input (then `old` holds the input's attributes and no joints): a pyramid
/// per used vertex (apex copy, its own midpoint copies, corner triangles,
/// back face), a joint per edge, and the old joints moved to the apex
/// copies.
fn pyramids(mesh: &PolyMesh, he: &HalfEdges, old: &Pieces, generation: u32) -> Pieces {
    let p = &mesh.points;
    let old_joints = &old.joints;
    let mut attributes = FaceAttributes::with_capacity(he.len() + p.len());
    let mut points = Vec::new();
    let mut apex = vec![NONE; p.len()];
    let mut mid = vec![NONE; he.len()];
    let mut faces = Vec::new();
    for v in 0..p.len() as u32 {
        if he.vertex_out[v as usize] == NO_TWIN {
            continue;
        }
        let ring = clockwise(he, v);
        apex[v as usize] = points.len() as u32;
        points.push(p[v as usize]);
        for &h in &ring {
            mid[h as usize] = points.len() as u32;
            points.push(0.5 * (p[v as usize] + p[he.dest(h) as usize]));
        }
        // ring[j] = v -> u and ring[j + 1] = v -> w lie in the face u -> v -> w:
        // its corner triangle is (mid(v,u), v, mid(v,w)).
        let n = ring.len();
        for j in 0..n {
            faces.push(vec![
                mid[ring[j] as usize],
                apex[v as usize],
                mid[ring[(j + 1) % n] as usize],
            ]);
            let parent = he.face[ring[(j + 1) % n] as usize];
            attributes.push_child(&old.attributes, parent, generation, 0);
        }
        // Back face: the base of the pyramid, against the triangles.
        faces.push(ring.iter().map(|&h| mid[h as usize]).collect());
        let first = he.face[he.vertex_out[v as usize] as usize];
        attributes.push_child(&old.attributes, first, generation, 1);
    }
    let mut joints: Vec<[u32; 2]> = old_joints
        .iter()
        .map(|&[a, b]| [apex[a as usize], apex[b as usize]])
        .collect();
    let mut joint_attributes = old.joint_attributes.clone();
    for (h, &t) in (0..).zip(&he.twin) {
        if h < t {
            joints.push([mid[h as usize], mid[t as usize]]);
            let origin = old.attributes.origin[he.face[h as usize] as usize];
            joint_attributes.push([generation, origin]);
        }
    }
    Pieces {
        mesh: PolyMesh { points, faces },
        joints,
        attributes,
        joint_attributes,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_shapes::*;
    use glam::DVec3;

    /// The closed forms of the module docs, computed here from V and E only.
    struct Predicted {
        vertices: i64,
        edges: i64,
        faces: i64,
        euler: i64,
        genus: i64,
    }

    fn predicted(v: i64, e: i64, k: u32) -> Predicted {
        let q = 4i64.pow(k - 1);
        let s = 2 * e * q;
        let pieces = v + 2 * e * (q - 1) / 3;
        let joints = e * (4 * q - 1) / 3;
        let vertices = s + pieces + 4 * joints;
        let edges = 2 * s + 9 * joints;
        let faces = s + pieces + 3 * joints;
        let euler = vertices - edges + faces;
        Predicted {
            vertices,
            edges,
            faces,
            euler,
            genus: 1 - v + e * (4 * q + 2) / 6,
        }
    }

    fn check_counts(name: &str, mesh: &PolyMesh, max_steps: u32) -> Vec<i64> {
        let input = closed_manifold_topology(mesh).expect("input is a closed manifold");
        let (v, e) = (input.vertices as i64, input.edges as i64);
        let mut genera = Vec::new();
        for k in 1..=max_steps {
            let out = sierpinski(mesh, k as usize).expect("sierpinski");
            let t = closed_manifold_topology(&out)
                .unwrap_or_else(|e| panic!("{name}, {k} steps: not a closed manifold: {e}"));
            let p = predicted(v, e, k);
            assert_eq!(t.components, 1, "{name}, {k} steps: connected");
            assert_eq!(t.vertices as i64, p.vertices, "{name}, {k} steps: V");
            assert_eq!(t.edges as i64, p.edges, "{name}, {k} steps: E");
            assert_eq!(t.faces as i64, p.faces, "{name}, {k} steps: F");
            assert_eq!(t.euler, p.euler, "{name}, {k} steps: χ");
            assert_eq!(t.euler, 2 * v - e * (4i64.pow(k) + 2) / 3);
            let genus = 1 - t.euler / 2;
            assert_eq!(genus, p.genus, "{name}, {k} steps: genus");
            genera.push(genus);
        }
        genera
    }

    #[test]
    fn tetrahedron_is_one_manifold_of_genus_4_to_the_k_minus_1() {
        let g = check_counts("tetrahedron", &tetrahedron(), 4);
        // Four tetrahedra joined at 6 points: genus 6 − 4 + 1 = 3; then 4^k − 1.
        assert_eq!(g, vec![3, 15, 63, 255]);
    }

    #[test]
    fn cube_is_one_manifold_of_predicted_genus() {
        let g = check_counts("cube", &cube(2.0), 4);
        // Eight corner tetrahedra joined at 12 points: genus 12 − 8 + 1 = 5.
        assert_eq!(g, vec![5, 29, 125, 509]);
    }

    #[test]
    fn octahedron_is_one_manifold_of_predicted_genus() {
        let g = check_counts("octahedron", &octahedron(), 4);
        // Six square pyramids joined at 12 points: genus 12 − 6 + 1 = 7.
        assert_eq!(g, vec![7, 31, 127, 511]);
    }

    #[test]
    fn torus_input_follows_the_same_formula() {
        // The formula depends on V and E only, not on the input genus.
        check_counts("torus", &torus(4, 3), 3);
    }

    #[test]
    fn genus_grows_fourfold_after_the_first_step() {
        // Paper: "After the first iteration, each iteration increases the
        // genus of the shape four times." The increase per step quadruples,
        // and the genus ratio tends to 4.
        for (name, mesh, v, e) in [
            ("tetrahedron", tetrahedron(), 4, 6),
            ("cube", cube(1.0), 8, 12),
            ("octahedron", octahedron(), 6, 12),
        ] {
            let g = check_counts(name, &mesh, 4);
            for k in 0..2 {
                assert_eq!(g[k + 2] - g[k + 1], 4 * (g[k + 1] - g[k]), "{name}");
            }
            for k in 0..3 {
                assert_eq!(g[k + 1], 4 * g[k] + 3 * (v - 1) - e, "{name}");
            }
            let ratios: Vec<f64> = (0..3).map(|k| g[k + 1] as f64 / g[k] as f64).collect();
            assert!(
                (ratios[2] - 4.0).abs() < (ratios[1] - 4.0).abs(),
                "{name}: {ratios:?}"
            );
            assert!(
                (ratios[1] - 4.0).abs() < (ratios[0] - 4.0).abs(),
                "{name}: {ratios:?}"
            );
            assert!((ratios[2] - 4.0).abs() < 0.1, "{name}: {ratios:?}");
        }
        // For the tetrahedron g + 1 quadruples exactly.
        let g = check_counts("tetrahedron", &tetrahedron(), 3);
        assert_eq!(g[1] + 1, 4 * (g[0] + 1));
        assert_eq!(g[2] + 1, 4 * (g[1] + 1));
    }

    #[test]
    fn written_obj_is_one_closed_surface_of_the_stated_genus() {
        let out = sierpinski(&tetrahedron(), 2).expect("sierpinski");
        let text = write_obj(&out);
        let back = read_obj(&text);
        let t = closed_manifold_topology(&back).expect("closed manifold from the .obj");
        assert_eq!(t.components, 1);
        assert_eq!(1 - t.euler / 2, 15);
        // No degenerate edges: the tube vertices are distinct points.
        let min_edge = back
            .faces
            .iter()
            .flat_map(|f| (0..f.len()).map(move |i| (f[i], f[(i + 1) % f.len()])))
            .map(|(a, b)| back.points[a as usize].distance(back.points[b as usize]))
            .fold(f64::INFINITY, f64::min);
        assert!(min_edge > 1e-3, "shortest edge {min_edge}");
    }

    #[test]
    fn pieces_are_the_sierpinski_tetrahedra() {
        // Every point lies within neck · (piece edge) of a corner of a level-k
        // Sierpinski sub-tetrahedron (barycentric coordinates in 2^-k Z), and
        // exactly the 4 input corners are kept unchanged.
        let tet = tetrahedron();
        let c = &tet.points;
        let edge = c[0].distance(c[1]);
        let neck = 0.01;
        for k in 1..=3u32 {
            let out = sierpinski_with(&tet, k as usize, &SierpinskiOptions { neck }).expect("ok");
            let n = 1i64 << k;
            let mut lattice = Vec::new();
            for a in 0..=n {
                for b in 0..=n - a {
                    for d in 0..=n - a - b {
                        let e = n - a - b - d;
                        let w = [a, b, d, e].map(|x| x as f64 / n as f64);
                        lattice.push(w[0] * c[0] + w[1] * c[1] + w[2] * c[2] + w[3] * c[3]);
                    }
                }
            }
            let tol = neck * edge / n as f64 * (1.0 + 1e-9);
            for p in &out.points {
                let d = lattice
                    .iter()
                    .map(|q| q.distance(*p))
                    .fold(f64::INFINITY, f64::min);
                assert!(d <= tol, "{k} steps: point {p} is {d} from the lattice");
            }
            let kept = out
                .points
                .iter()
                .filter(|p| c.iter().any(|q| q.distance(**p) < 1e-15))
                .count();
            assert_eq!(kept, 4);
        }
    }

    #[test]
    fn faces_point_outwards_and_enclose_the_sierpinski_volume() {
        // Tetrahedron: 4 half-size copies per step, volume × 1/2 per step.
        // Cube: the first step keeps 8 corner tetrahedra of volume (s/2)^3/6,
        // then every piece is a tetrahedron. The tubes and the cut-off tips
        // change the volume by O(neck^3) per joint.
        let neck = 1e-3;
        let opts = SierpinskiOptions { neck };
        let tet = tetrahedron();
        let v0 = signed_volume(&tet);
        assert!((v0 - 8.0 / 3.0).abs() < 1e-12);
        for k in 1..=3 {
            let v = signed_volume(&sierpinski_with(&tet, k, &opts).expect("ok"));
            let want = v0 / 2f64.powi(k as i32);
            assert!(
                (v - want).abs() < 1e-6 * v0,
                "tet, {k} steps: {v} vs {want}"
            );
        }
        let side = 2.0;
        let cube = cube(side);
        for k in 1..=3 {
            let v = signed_volume(&sierpinski_with(&cube, k, &opts).expect("ok"));
            let want = 8.0 * (side / 2.0).powi(3) / 6.0 / 2f64.powi(k as i32 - 1);
            assert!(
                (v - want).abs() < 1e-6 * side.powi(3),
                "cube, {k} steps: {v} vs {want}"
            );
        }
    }

    #[test]
    fn topology_does_not_depend_on_the_neck() {
        for neck in [1e-6, 0.05, 0.45] {
            let out = sierpinski_with(&cube(1.0), 2, &SierpinskiOptions { neck }).expect("ok");
            let t = closed_manifold_topology(&out).expect("manifold");
            assert_eq!((t.components, 1 - t.euler / 2), (1, 29));
        }
    }

    /// The points, quantized to 1e-9 and sorted: equal for two meshes
    /// whose points agree up to rounding, whatever their order.
    fn point_set(m: &PolyMesh) -> Vec<[i64; 3]> {
        let mut v: Vec<[i64; 3]> = m
            .points
            .iter()
            .map(|p| p.to_array().map(|c| (c * 1e9).round() as i64))
            .collect();
        v.sort_unstable();
        v
    }

    #[test]
    fn an_output_fed_back_in_goes_on_as_one_run() {
        for (name, mesh) in [("tetrahedron", tetrahedron()), ("cube", cube(1.0))] {
            let input = closed_manifold_topology(&mesh).expect("closed");
            let (v, e) = (input.vertices as i64, input.edges as i64);
            for neck in [1e-4, 0.05, 0.45] {
                let opts = SierpinskiOptions { neck };
                let run = |m: &PolyMesh, k: usize| sierpinski_with(m, k, &opts).expect("ok");
                let one = run(&mesh, 1);
                let tubes = find_tubes(&one, &one.half_edges().expect("manifold"));
                assert_eq!(tubes.len() as i64, e, "{name}: one tube per input edge");
                for (fed, k, total) in [(&one, 1, 2), (&one, 2, 3), (&run(&mesh, 2), 1, 3)] {
                    let out = run(fed, k);
                    let t = closed_manifold_topology(&out)
                        .unwrap_or_else(|err| panic!("{name}, neck {neck}: {err}"));
                    let p = predicted(v, e, total);
                    assert_eq!(
                        (
                            t.components,
                            t.vertices as i64,
                            t.edges as i64,
                            t.faces as i64
                        ),
                        (1, p.vertices, p.edges, p.faces),
                        "{name}, neck {neck}: {k} more steps after {}",
                        total as usize - k
                    );
                    assert_eq!(1 - t.euler / 2, p.genus);
                    // The same points as the run asked for all at once.
                    assert_eq!(
                        point_set(&out),
                        point_set(&run(&mesh, total as usize)),
                        "{name}"
                    );
                }
                // Zero steps still return the input unchanged.
                assert_eq!(sierpinski(&one, 0).expect("ok"), one);
            }
        }
    }

    #[test]
    fn tubes_that_cannot_be_undone_are_refused() {
        let one = sierpinski(&tetrahedron(), 1).expect("ok");
        let tubes = find_tubes(&one, &one.half_edges().expect("manifold"));
        assert_eq!(tubes.len(), 6);
        assert!(untube(&one, &tubes).is_some());
        // A rim claimed by two tubes cannot be closed twice.
        let twice = [tubes[0].clone(), tubes[0].clone()];
        assert!(untube(&one, &twice).is_none());
    }

    #[test]
    fn rings_of_three_quads_that_are_not_joints_are_accepted() {
        // A torus three quads round has rings of three quads with
        // triangular rims, but the edges through the rims are parallel.
        for (m, n) in [(4, 3), (3, 3), (5, 3)] {
            let t = torus(m, n);
            assert!(sierpinski(&t, 1).is_ok(), "torus {m}x{n}");
        }
    }

    #[test]
    fn zero_steps_returns_the_input() {
        let c = cube(1.0);
        assert_eq!(sierpinski(&c, 0).expect("ok"), c);
    }

    #[test]
    fn bad_input_is_refused_with_a_reason() {
        let mut open = cube(1.0);
        open.faces.pop();
        assert!(matches!(
            sierpinski(&open, 1),
            Err(SurfaceError::OpenEdge { .. })
        ));
        let mut flipped = cube(1.0);
        flipped.faces[0].reverse();
        assert!(matches!(
            sierpinski(&flipped, 1),
            Err(SurfaceError::EdgeOrientation { .. })
        ));
        let mut bad = cube(1.0);
        bad.faces[1][0] = 99;
        let err = sierpinski(&bad, 1).unwrap_err();
        assert_eq!(
            err.to_string(),
            "face 1 refers to vertex 99, but the mesh has 8 vertices"
        );
        let mut nan = cube(1.0);
        nan.points[3] = DVec3::NAN;
        assert!(matches!(
            sierpinski(&nan, 1),
            Err(SurfaceError::NonFinite { vertex: 3 })
        ));
        for neck in [0.0, 0.5, f64::NAN] {
            assert!(matches!(
                sierpinski_with(&cube(1.0), 1, &SierpinskiOptions { neck }),
                Err(SurfaceError::Parameter(_))
            ));
        }
        assert!(matches!(
            sierpinski(&cube(1.0), 40),
            Err(SurfaceError::TooLarge { .. })
        ));
        // Two cubes sharing one corner: a pinched, non-manifold vertex.
        let a = cube(1.0);
        let mut b = cube(1.0);
        for p in &mut b.points {
            *p = -*p;
        }
        let mut pinched = a.clone();
        let shift = pinched.points.len() as u32;
        pinched.points.extend(b.points.iter().skip(1));
        for f in &b.faces {
            pinched.faces.push(
                f.iter()
                    .map(|&v| if v == 0 { 0 } else { v + shift - 1 })
                    .collect(),
            );
        }
        assert!(matches!(
            sierpinski(&pinched, 1),
            Err(SurfaceError::NonManifoldVertex { vertex: 0 })
        ));
    }
}
