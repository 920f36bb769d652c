//! A validated half-edge view of a closed, consistently oriented polygon
//! mesh: the adjacency that the Sierpinski and truncation schemes walk.
//!
//! Half-edge `h` of face `f` at corner `i` runs from `f[i]` to `f[i + 1]`;
//! half-edge ids are consecutive per face. (Crate-private; a shared PolyMesh
//! adjacency may replace it later.)

use super::error::SurfaceError;
use super::PolyMesh;
use std::collections::HashMap;

/// Half-edge adjacency of a closed, oriented 2-manifold polygon mesh.
pub(crate) struct ClosedManifold<'a> {
    mesh: &'a PolyMesh,
    /// First half-edge of each face, plus one past the last.
    face_start: Vec<usize>,
    /// Face of each half-edge.
    he_face: Vec<u32>,
    /// Opposite half-edge.
    twin: Vec<u32>,
    /// One outgoing half-edge per vertex, `u32::MAX` for unused vertices.
    vertex_out: Vec<u32>,
}

const NONE: u32 = u32::MAX;

impl<'a> ClosedManifold<'a> {
    /// Validate `mesh` (faces of at least three distinct, existing vertices;
    /// finite points; every edge in exactly two faces with opposite
    /// directions; one fan of faces around every used vertex) and build the
    /// adjacency.
    pub(crate) fn new(mesh: &'a PolyMesh) -> Result<Self, SurfaceError> {
        if mesh.faces.is_empty() {
            return Err(SurfaceError::Empty);
        }
        let nv = mesh.points.len();
        if let Some(vertex) = mesh.points.iter().position(|p| !p.is_finite()) {
            return Err(SurfaceError::NonFinite { vertex });
        }
        let mut face_start = Vec::with_capacity(mesh.faces.len() + 1);
        let mut total = 0usize;
        for (f, face) in mesh.faces.iter().enumerate() {
            if face.len() < 3 {
                return Err(SurfaceError::FaceTooSmall {
                    face: f,
                    len: face.len(),
                });
            }
            for (i, &v) in face.iter().enumerate() {
                if v as usize >= nv {
                    return Err(SurfaceError::VertexOutOfRange {
                        face: f,
                        vertex: v,
                        count: nv,
                    });
                }
                if face[..i].contains(&v) {
                    return Err(SurfaceError::RepeatedVertex { face: f, vertex: v });
                }
            }
            face_start.push(total);
            total += face.len();
        }
        face_start.push(total);
        if total >= NONE as usize {
            return Err(SurfaceError::TooLarge {
                steps: 0,
                estimate: total as f64,
                what: "half-edges",
            });
        }
        let mut he_face = Vec::with_capacity(total);
        let mut directed: HashMap<(u32, u32), u32> = HashMap::with_capacity(total);
        let mut vertex_out = vec![NONE; nv];
        for (f, face) in mesh.faces.iter().enumerate() {
            let n = face.len();
            for i in 0..n {
                let h = (face_start[f] + i) as u32;
                let (a, b) = (face[i], face[(i + 1) % n]);
                he_face.push(f as u32);
                if let Some(&other) = directed.get(&(a, b)) {
                    return Err(SurfaceError::EdgeOrientation {
                        from: a,
                        to: b,
                        first: he_face[other as usize] as usize,
                        second: f,
                    });
                }
                directed.insert((a, b), h);
                vertex_out[a as usize] = h;
            }
        }
        let mut twin = vec![NONE; total];
        for (f, face) in mesh.faces.iter().enumerate() {
            let n = face.len();
            for i in 0..n {
                let h = face_start[f] + i;
                let (a, b) = (face[i], face[(i + 1) % n]);
                match directed.get(&(b, a)) {
                    Some(&t) => twin[h] = t,
                    None => {
                        return Err(SurfaceError::OpenEdge {
                            from: a,
                            to: b,
                            face: f,
                        })
                    }
                }
            }
        }
        let out = ClosedManifold {
            mesh,
            face_start,
            he_face,
            twin,
            vertex_out,
        };
        // One fan per vertex: the rotation from one outgoing half-edge must
        // reach every outgoing half-edge of the vertex.
        let mut out_degree = vec![0usize; nv];
        for h in 0..total {
            out_degree[out.from(h as u32) as usize] += 1;
        }
        for (v, &degree) in out_degree.iter().enumerate() {
            if out.vertex_out[v] != NONE && out.ring(v as u32).len() != degree {
                return Err(SurfaceError::NonManifoldVertex { vertex: v as u32 });
            }
        }
        Ok(out)
    }

    /// Number of half-edges (twice the number of edges).
    pub(crate) fn half_edge_count(&self) -> usize {
        self.he_face.len()
    }

    /// Number of undirected edges.
    pub(crate) fn edge_count(&self) -> usize {
        self.he_face.len() / 2
    }

    /// The half-edge of face `f` that starts at its corner `i`.
    pub(crate) fn half_edge(&self, f: usize, i: usize) -> u32 {
        (self.face_start[f] + i) as u32
    }

    fn corner(&self, h: u32) -> (usize, usize) {
        let f = self.he_face[h as usize] as usize;
        (f, h as usize - self.face_start[f])
    }

    /// Start vertex of `h`.
    pub(crate) fn from(&self, h: u32) -> u32 {
        let (f, i) = self.corner(h);
        self.mesh.faces[f][i]
    }

    /// End vertex of `h`.
    pub(crate) fn to(&self, h: u32) -> u32 {
        let (f, i) = self.corner(h);
        let face = &self.mesh.faces[f];
        face[(i + 1) % face.len()]
    }

    /// The half-edge after `h` in its face.
    pub(crate) fn next(&self, h: u32) -> u32 {
        let (f, i) = self.corner(h);
        let n = self.mesh.faces[f].len();
        (self.face_start[f] + (i + 1) % n) as u32
    }

    /// The opposite half-edge.
    pub(crate) fn twin(&self, h: u32) -> u32 {
        self.twin[h as usize]
    }

    /// Is `v` used by some face?
    pub(crate) fn is_used(&self, v: u32) -> bool {
        self.vertex_out[v as usize] != NONE
    }

    /// The outgoing half-edges of `v` in rotation order: after `v -> w` in
    /// face `f` comes `v -> x` in the face `g` that holds `w -> v`
    /// (`x` follows `v` in `g`). Consecutive entries `v -> u`, `v -> w` thus
    /// lie in the one face in which `u` precedes and `w` follows `v`.
    pub(crate) fn ring(&self, v: u32) -> Vec<u32> {
        let start = self.vertex_out[v as usize];
        let mut ring = Vec::new();
        if start == NONE {
            return ring;
        }
        let mut h = start;
        loop {
            ring.push(h);
            h = self.next(self.twin(h));
            if h == start || ring.len() > self.he_face.len() {
                break;
            }
        }
        ring
    }
}
