//! [`PolyMesh`]: an indexed polygon mesh with faces of any size, and its
//! adjacency ([`HalfEdges`]), built on demand.
//!
//! The mesh itself is the plain indexed form (points and vertex loops) that
//! readers produce and writers consume. Everything that needs neighbours
//! builds a [`HalfEdges`] table once: half-edge `h` of face `f` runs from
//! `faces[f][k]` to `faces[f][k+1]`, half-edges are numbered face by face, and
//! `twin[h]` is the half-edge of the neighbouring face that runs the other way
//! ([`NO_TWIN`] on an open boundary). Building the table is also the
//! validation: a non-manifold edge, two faces that disagree about orientation,
//! a repeated vertex in a face or a vertex whose faces form more than one fan
//! is reported as a [`TopologyError`] that names the faces and vertices.

use glam::DVec3;
use rayon::prelude::*;
use std::fmt;

/// An indexed polygon mesh: points and faces as counter-clockwise (outward)
/// vertex loops.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PolyMesh {
    /// Vertex coordinates.
    pub points: Vec<DVec3>,
    /// Faces as vertex loops (at least three ids each).
    pub faces: Vec<Vec<u32>>,
}

/// Marks a half-edge without a twin (an open-boundary half-edge).
pub const NO_TWIN: u32 = u32::MAX;

/// Why a polygon soup is not an oriented 2-manifold (with boundary).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TopologyError {
    /// A face with fewer than three vertices.
    FaceTooSmall {
        /// The face.
        face: usize,
        /// Its number of vertices.
        len: usize,
    },
    /// A vertex id that is not a point of the mesh.
    IndexOutOfRange {
        /// The face.
        face: usize,
        /// The bad id.
        index: u32,
        /// Number of points.
        points: usize,
    },
    /// A face that visits the same vertex twice.
    RepeatedVertex {
        /// The face.
        face: usize,
        /// The vertex.
        vertex: u32,
    },
    /// An edge shared by more than two faces.
    NonManifoldEdge {
        /// The edge (sorted vertex ids).
        edge: [u32; 2],
        /// How many face sides use it.
        faces: usize,
    },
    /// Two faces traverse their common edge in the same direction, so their
    /// normals disagree (or the surface is not orientable).
    InconsistentOrientation {
        /// The edge, as both faces traverse it.
        edge: [u32; 2],
        /// The two faces.
        faces: [usize; 2],
    },
    /// A vertex whose incident faces form more than one fan (two cones
    /// touching at a point).
    NonManifoldVertex {
        /// The vertex.
        vertex: u32,
        /// Number of separate fans.
        fans: usize,
    },
}

impl fmt::Display for TopologyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TopologyError::FaceTooSmall { face, len } => {
                write!(f, "face {face} has {len} vertices; a face needs at least 3")
            }
            TopologyError::IndexOutOfRange {
                face,
                index,
                points,
            } => write!(
                f,
                "face {face} uses vertex {index}, but there are only {points} points"
            ),
            TopologyError::RepeatedVertex { face, vertex } => {
                write!(f, "face {face} visits vertex {vertex} twice")
            }
            TopologyError::NonManifoldEdge { edge, faces } => write!(
                f,
                "edge {}-{} is shared by {faces} faces (a manifold edge has at most 2)",
                edge[0], edge[1]
            ),
            TopologyError::InconsistentOrientation { edge, faces } => write!(
                f,
                "faces {} and {} both run along edge {}->{}: their orientations disagree",
                faces[0], faces[1], edge[0], edge[1]
            ),
            TopologyError::NonManifoldVertex { vertex, fans } => write!(
                f,
                "vertex {vertex} joins {fans} separate fans of faces (non-manifold vertex)"
            ),
        }
    }
}

impl std::error::Error for TopologyError {}

impl TopologyError {
    /// The face the error is about, where there is one (readers use it to
    /// name the line of that face).
    pub fn face(&self) -> Option<usize> {
        match self {
            TopologyError::FaceTooSmall { face, .. }
            | TopologyError::IndexOutOfRange { face, .. }
            | TopologyError::RepeatedVertex { face, .. } => Some(*face),
            TopologyError::InconsistentOrientation { faces, .. } => Some(faces[1]),
            _ => None,
        }
    }
}

/// Half-edge adjacency of a [`PolyMesh`] (see the module docs for the
/// numbering).
#[derive(Clone, Debug)]
pub struct HalfEdges {
    /// First half-edge of each face, plus one final entry = number of half-edges.
    pub face_start: Vec<u32>,
    /// Origin vertex of each half-edge.
    pub origin: Vec<u32>,
    /// Face of each half-edge.
    pub face: Vec<u32>,
    /// Opposite half-edge, or [`NO_TWIN`].
    pub twin: Vec<u32>,
    /// Undirected edge id of each half-edge.
    pub edge: Vec<u32>,
    /// Undirected edges as sorted vertex pairs.
    pub edges: Vec<[u32; 2]>,
    /// One half-edge per undirected edge (the one seen first).
    pub edge_half: Vec<u32>,
    /// One outgoing half-edge per vertex ([`NO_TWIN`] for unused points); for
    /// a boundary vertex it is the outgoing boundary half-edge, so that
    /// [`HalfEdges::ring`] starts at the boundary.
    pub vertex_out: Vec<u32>,
}

impl HalfEdges {
    /// Builds the adjacency and validates the mesh as an oriented manifold
    /// with boundary. Errors name faces and vertices.
    pub fn build(mesh: &PolyMesh) -> Result<HalfEdges, TopologyError> {
        let np = mesh.points.len();
        let mut face_start = Vec::with_capacity(mesh.faces.len() + 1);
        let mut n = 0u32;
        for (fi, f) in mesh.faces.iter().enumerate() {
            if f.len() < 3 {
                return Err(TopologyError::FaceTooSmall {
                    face: fi,
                    len: f.len(),
                });
            }
            for (k, &v) in f.iter().enumerate() {
                if v as usize >= np {
                    return Err(TopologyError::IndexOutOfRange {
                        face: fi,
                        index: v,
                        points: np,
                    });
                }
                if f[..k].contains(&v) {
                    return Err(TopologyError::RepeatedVertex {
                        face: fi,
                        vertex: v,
                    });
                }
            }
            face_start.push(n);
            n += f.len() as u32;
        }
        face_start.push(n);
        let nh = n as usize;
        let mut origin = Vec::with_capacity(nh);
        let mut face = Vec::with_capacity(nh);
        for (fi, f) in mesh.faces.iter().enumerate() {
            origin.extend_from_slice(f);
            face.extend(std::iter::repeat_n(fi as u32, f.len()));
        }
        let dest = |h: usize| -> u32 {
            let f = face[h] as usize;
            let s = face_start[f] as usize;
            let e = face_start[f + 1] as usize;
            if h + 1 == e {
                origin[s]
            } else {
                origin[h + 1]
            }
        };
        // Pair half-edges by sorting their undirected keys.
        let mut keys: Vec<(u64, u32)> = (0..nh)
            .into_par_iter()
            .map(|h| {
                let (a, b) = (origin[h], dest(h));
                let (lo, hi) = if a < b { (a, b) } else { (b, a) };
                (((lo as u64) << 32) | hi as u64, h as u32)
            })
            .collect();
        keys.par_sort_unstable();
        let mut twin = vec![NO_TWIN; nh];
        let mut edge = vec![0u32; nh];
        let mut edges = Vec::with_capacity(nh / 2 + 1);
        let mut edge_half = Vec::with_capacity(nh / 2 + 1);
        let mut i = 0;
        while i < keys.len() {
            let mut j = i + 1;
            while j < keys.len() && keys[j].0 == keys[i].0 {
                j += 1;
            }
            let key = keys[i].0;
            let pair = [(key >> 32) as u32, key as u32];
            if j - i > 2 {
                return Err(TopologyError::NonManifoldEdge {
                    edge: pair,
                    faces: j - i,
                });
            }
            let e = edges.len() as u32;
            edges.push(pair);
            let h0 = keys[i].1;
            edge_half.push(h0.min(if j - i == 2 { keys[i + 1].1 } else { h0 }));
            edge[h0 as usize] = e;
            if j - i == 2 {
                let h1 = keys[i + 1].1;
                edge[h1 as usize] = e;
                if origin[h0 as usize] == origin[h1 as usize] {
                    let (fa, fb) = (face[h0 as usize], face[h1 as usize]);
                    return Err(TopologyError::InconsistentOrientation {
                        edge: [origin[h0 as usize], dest(h0 as usize)],
                        faces: [fa.min(fb) as usize, fa.max(fb) as usize],
                    });
                }
                twin[h0 as usize] = h1;
                twin[h1 as usize] = h0;
            }
            i = j;
        }
        let mut he = HalfEdges {
            face_start,
            origin,
            face,
            twin,
            edge,
            edges,
            edge_half,
            vertex_out: vec![NO_TWIN; np],
        };
        // Outgoing half-edges, boundary ones preferred.
        for h in 0..nh {
            let v = he.origin[h] as usize;
            let cur = he.vertex_out[v];
            if cur == NO_TWIN || he.twin[h] == NO_TWIN {
                he.vertex_out[v] = h as u32;
            }
        }
        he.check_vertex_fans()?;
        Ok(he)
    }

    fn check_vertex_fans(&self) -> Result<(), TopologyError> {
        let np = self.vertex_out.len();
        let degree = self.faces_at();
        let bad = (0..np).into_par_iter().find_map_first(|v| {
            let start = self.vertex_out[v];
            if start == NO_TWIN {
                return None;
            }
            let mut count = 1u32;
            let mut h = start;
            loop {
                let t = self.twin[self.prev(h) as usize];
                if t == NO_TWIN || t == start {
                    break;
                }
                h = t;
                count += 1;
                if count > degree[v] {
                    break;
                }
            }
            if count == degree[v] {
                return None;
            }
            // Count the fans: walk each unvisited outgoing half-edge back to
            // the start of its fan, then forward, marking what it covers.
            let all: Vec<u32> = (0..self.origin.len() as u32)
                .filter(|&h| self.origin[h as usize] as usize == v)
                .collect();
            let mut visited = std::collections::HashSet::new();
            let mut fans = 0usize;
            for &h0 in &all {
                if visited.contains(&h0) {
                    continue;
                }
                fans += 1;
                let mut s = h0;
                loop {
                    let t = self.twin[s as usize];
                    if t == NO_TWIN {
                        break;
                    }
                    let p = self.next(t);
                    if p == h0 {
                        break;
                    }
                    s = p;
                }
                let mut h = s;
                while visited.insert(h) {
                    let t = self.twin[self.prev(h) as usize];
                    if t == NO_TWIN {
                        break;
                    }
                    h = t;
                }
            }
            Some(TopologyError::NonManifoldVertex {
                vertex: v as u32,
                fans,
            })
        });
        match bad {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// Number of half-edges.
    pub fn len(&self) -> usize {
        self.origin.len()
    }

    /// True when there are no faces.
    pub fn is_empty(&self) -> bool {
        self.origin.is_empty()
    }

    /// Next half-edge in the same face.
    #[inline]
    pub fn next(&self, h: u32) -> u32 {
        let f = self.face[h as usize] as usize;
        if h + 1 == self.face_start[f + 1] {
            self.face_start[f]
        } else {
            h + 1
        }
    }

    /// Previous half-edge in the same face.
    #[inline]
    pub fn prev(&self, h: u32) -> u32 {
        let f = self.face[h as usize] as usize;
        if h == self.face_start[f] {
            self.face_start[f + 1] - 1
        } else {
            h - 1
        }
    }

    /// Destination vertex of a half-edge.
    #[inline]
    pub fn dest(&self, h: u32) -> u32 {
        self.origin[self.next(h) as usize]
    }

    /// True for a half-edge on an open boundary.
    #[inline]
    pub fn is_boundary_half(&self, h: u32) -> bool {
        self.twin[h as usize] == NO_TWIN
    }

    /// True for an undirected edge with one face.
    pub fn is_boundary_edge(&self, e: u32) -> bool {
        self.twin[self.edge_half[e as usize] as usize] == NO_TWIN
    }

    /// True for a vertex on an open boundary (unused points are not).
    pub fn is_boundary_vertex(&self, v: u32) -> bool {
        let h = self.vertex_out[v as usize];
        h != NO_TWIN && self.twin[h as usize] == NO_TWIN
    }

    /// The outgoing half-edges of `v` in counter-clockwise order; for a
    /// boundary vertex the first one is the boundary half-edge.
    pub fn outgoing(&self, v: u32) -> Vec<u32> {
        let mut out = Vec::new();
        let start = self.vertex_out[v as usize];
        if start == NO_TWIN {
            return out;
        }
        let mut h = start;
        loop {
            out.push(h);
            let t = self.twin[self.prev(h) as usize];
            if t == NO_TWIN || t == start {
                break;
            }
            h = t;
        }
        out
    }

    /// The neighbours of `v` in counter-clockwise order and whether `v` is on
    /// a boundary. For a boundary vertex the ring starts and ends with its two
    /// boundary neighbours.
    pub fn ring(&self, v: u32) -> (Vec<u32>, bool) {
        let out = self.outgoing(v);
        let mut ring: Vec<u32> = out.iter().map(|&h| self.dest(h)).collect();
        let boundary = self.is_boundary_vertex(v);
        if boundary {
            if let Some(&last) = out.last() {
                ring.push(self.origin[self.prev(last) as usize]);
            }
        }
        (ring, boundary)
    }

    /// Number of faces at each vertex (0 for unused points): the half-edges
    /// leaving it, one per face corner.
    pub fn faces_at(&self) -> Vec<u32> {
        let mut n = vec![0u32; self.vertex_out.len()];
        for &v in &self.origin {
            n[v as usize] += 1;
        }
        n
    }

    /// Number of edges at each vertex (0 for unused points).
    pub fn valences(&self) -> Vec<u32> {
        let mut val = vec![0u32; self.vertex_out.len()];
        for e in &self.edges {
            val[e[0] as usize] += 1;
            val[e[1] as usize] += 1;
        }
        val
    }

    /// The closed boundary loops, each as a list of boundary half-edges in
    /// order (the loops run with the faces on their left).
    pub fn boundary_loops(&self) -> Vec<Vec<u32>> {
        let mut seen = vec![false; self.len()];
        let mut loops = Vec::new();
        for h0 in 0..self.len() as u32 {
            if self.twin[h0 as usize] != NO_TWIN || seen[h0 as usize] {
                continue;
            }
            let mut lp = Vec::new();
            let mut h = h0;
            loop {
                seen[h as usize] = true;
                lp.push(h);
                // Next boundary half-edge: from dest(h), rotate clockwise
                // until a boundary half-edge is found.
                let mut g = self.next(h);
                while self.twin[g as usize] != NO_TWIN {
                    g = self.next(self.twin[g as usize]);
                }
                h = g;
                if h == h0 || seen[h as usize] {
                    break;
                }
            }
            loops.push(lp);
        }
        loops
    }
}

/// Connected component of a mesh, with its topological figures.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Component {
    /// Faces of the component.
    pub faces: Vec<u32>,
    /// Number of vertices.
    pub vertices: usize,
    /// Number of edges.
    pub edges: usize,
    /// Number of boundary loops (0 for a closed surface).
    pub boundary_loops: usize,
    /// Euler characteristic V − E + F.
    pub euler: i64,
    /// Genus g from χ = 2 − 2g − b (b boundary loops).
    pub genus: i64,
}

impl PolyMesh {
    /// A mesh from points and faces.
    pub fn new(points: Vec<DVec3>, faces: Vec<Vec<u32>>) -> PolyMesh {
        PolyMesh { points, faces }
    }

    /// A mesh from triangles.
    pub fn from_triangles(points: Vec<DVec3>, tris: &[[u32; 3]]) -> PolyMesh {
        PolyMesh {
            points,
            faces: tris.iter().map(|t| t.to_vec()).collect(),
        }
    }

    /// The faces as triangles, or the first face that is not one.
    pub fn triangles(&self) -> Result<Vec<[u32; 3]>, usize> {
        self.faces
            .iter()
            .enumerate()
            .map(|(i, f)| {
                if f.len() == 3 {
                    Ok([f[0], f[1], f[2]])
                } else {
                    Err(i)
                }
            })
            .collect()
    }

    /// True when every face is a triangle.
    pub fn is_triangle_mesh(&self) -> bool {
        self.faces.iter().all(|f| f.len() == 3)
    }

    /// Builds the half-edge adjacency and validates manifoldness and
    /// consistent orientation.
    pub fn half_edges(&self) -> Result<HalfEdges, TopologyError> {
        HalfEdges::build(self)
    }

    /// Validates the mesh as an oriented 2-manifold with boundary.
    pub fn validate(&self) -> Result<(), TopologyError> {
        self.half_edges().map(|_| ())
    }

    /// Points used by at least one face.
    pub fn used_vertices(&self) -> usize {
        let mut used = vec![false; self.points.len()];
        for f in &self.faces {
            for &v in f {
                if let Some(u) = used.get_mut(v as usize) {
                    *u = true;
                }
            }
        }
        used.iter().filter(|&&u| u).count()
    }

    /// The side of every face as a sorted vertex pair, all of them sorted
    /// (an edge appears once per face that uses it), without validation.
    fn sorted_face_sides(&self) -> Vec<[u32; 2]> {
        let mut e: Vec<[u32; 2]> = self
            .faces
            .iter()
            .flat_map(|f| {
                (0..f.len()).map(move |k| {
                    let (a, b) = (f[k], f[(k + 1) % f.len()]);
                    [a.min(b), a.max(b)]
                })
            })
            .collect();
        e.par_sort_unstable();
        e
    }

    /// Undirected edges (sorted vertex pairs) of the faces, without
    /// validation, sorted.
    pub fn edge_list(&self) -> Vec<[u32; 2]> {
        let mut e = self.sorted_face_sides();
        e.dedup();
        e
    }

    /// Edges used by exactly one face (sorted pairs), without validation.
    pub fn boundary_edges(&self) -> Vec<[u32; 2]> {
        self.sorted_face_sides()
            .chunk_by(|a, b| a == b)
            .filter(|run| run.len() == 1)
            .map(|run| run[0])
            .collect()
    }

    /// Euler characteristic V − E + F, counting only points used by faces.
    pub fn euler_characteristic(&self) -> i64 {
        self.used_vertices() as i64 - self.edge_list().len() as i64 + self.faces.len() as i64
    }

    /// Connected components (through shared edges), each with its Euler
    /// characteristic, boundary loops and genus. Needs a valid mesh.
    pub fn components(&self) -> Result<Vec<Component>, TopologyError> {
        let he = self.half_edges()?;
        let nf = self.faces.len();
        let mut comp = vec![u32::MAX; nf];
        let mut out = Vec::new();
        for f0 in 0..nf {
            if comp[f0] != u32::MAX {
                continue;
            }
            let id = out.len() as u32;
            let mut stack = vec![f0 as u32];
            comp[f0] = id;
            let mut faces = Vec::new();
            while let Some(f) = stack.pop() {
                faces.push(f);
                for h in he.face_start[f as usize]..he.face_start[f as usize + 1] {
                    let t = he.twin[h as usize];
                    if t != NO_TWIN {
                        let g = he.face[t as usize];
                        if comp[g as usize] == u32::MAX {
                            comp[g as usize] = id;
                            stack.push(g);
                        }
                    }
                }
            }
            faces.sort_unstable();
            out.push(Component {
                faces,
                vertices: 0,
                edges: 0,
                boundary_loops: 0,
                euler: 0,
                genus: 0,
            });
        }
        let mut vcomp = vec![u32::MAX; self.points.len()];
        for (f, face) in self.faces.iter().enumerate() {
            for &v in face {
                vcomp[v as usize] = comp[f];
            }
        }
        for c in vcomp.iter().filter(|&&c| c != u32::MAX) {
            out[*c as usize].vertices += 1;
        }
        for (e, &h) in he.edge_half.iter().enumerate() {
            let _ = e;
            out[comp[he.face[h as usize] as usize] as usize].edges += 1;
        }
        for lp in he.boundary_loops() {
            out[comp[he.face[lp[0] as usize] as usize] as usize].boundary_loops += 1;
        }
        for c in &mut out {
            c.euler = c.vertices as i64 - c.edges as i64 + c.faces.len() as i64;
            c.genus = (2 - c.euler - c.boundary_loops as i64) / 2;
        }
        Ok(out)
    }

    /// Newell normal of a face: its direction is the face normal, its length
    /// twice the (vector) area.
    pub fn face_newell(&self, f: usize) -> DVec3 {
        let face = &self.faces[f];
        let mut n = DVec3::ZERO;
        for k in 0..face.len() {
            let a = self.points[face[k] as usize];
            let b = self.points[face[(k + 1) % face.len()] as usize];
            n += a.cross(b);
        }
        n
    }

    /// Centroid (average of the vertices) of a face.
    pub fn face_centroid(&self, f: usize) -> DVec3 {
        let face = &self.faces[f];
        let mut s = DVec3::ZERO;
        for &v in face {
            s += self.points[v as usize];
        }
        s / face.len() as f64
    }

    /// Axis-aligned bounding box of the points (`None` when there are none).
    pub fn bounding_box(&self) -> Option<(DVec3, DVec3)> {
        let mut it = self.points.iter();
        let first = *it.next()?;
        Some(it.fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))))
    }
}
