//! [`TetMesh::check`]: verifies every invariant of the store.

use super::fasthash::{FastHashMap, FastHashSet};
use super::{
    edge_key, edges_present, face_key, faces_present, EdgeKey, FaceKey, TetMesh, DEAD, NO_ADJ,
};
use crate::geom::{orient3d_sign, Orientation};
use rayon::prelude::*;

/// An invariant that does not hold. Ids are the store's 0-based ids.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum CheckError {
    /// Side tables disagree in length.
    #[error("side tables have inconsistent lengths")]
    Lengths,
    /// A live tet names a vertex out of range or repeats one.
    #[error("tet {0} has an invalid vertex list {1:?}")]
    BadVertices(u32, [u32; 4]),
    /// A live tet is not positively oriented.
    #[error("tet {0} is inverted or flat ({1:?})")]
    Orientation(u32, Orientation),
    /// Adjacency is not mutual, points to a dead tet, or the faces differ.
    #[error("adjacency of tet {0} face {1} is broken: {2}")]
    Adjacency(u32, usize, &'static str),
    /// The free list and the dead slots disagree.
    #[error("free list inconsistent: {0}")]
    FreeList(&'static str),
    /// A boundary edge has an odd number of boundary faces.
    #[error("boundary edge {0:?} has {1} boundary faces (a closed boundary has an even number)")]
    NonManifoldBoundary([u32; 2], usize),
    /// A vertex's entry in the vertex → tet table names a tet that does
    /// not hold it, or none while a live tet holds it.
    #[error("vertex {0}: its tet entry is stale")]
    VertexTet(u32),
    /// A tag names a face, edge or vertex the mesh does not have.
    #[error("tag inconsistent: {0}")]
    Tag(String),
}

impl TetMesh {
    /// Verifies all invariants: side-table lengths, free list, vertex lists,
    /// exact positive orientation, mutual adjacency with equal and oppositely
    /// oriented shared faces, a closed boundary (each boundary edge in an even
    /// number of boundary faces, two where the boundary is manifold), and tags naming existing faces, edges and vertices.
    pub fn check(&self) -> Result<(), CheckError> {
        let n = self.tets.len();
        if self.adj.len() != n
            || self.generation.len() != n
            || self.region.len() != n
            || self.level.len() != n
            || self.parent.len() != n
        {
            return Err(CheckError::Lengths);
        }
        let dead = self.tets.iter().filter(|v| v[0] == DEAD).count();
        if dead != self.free.len() {
            return Err(CheckError::FreeList(
                "dead slot count differs from free list length",
            ));
        }
        if self
            .free
            .iter()
            .any(|&t| t as usize >= n || self.tets[t as usize][0] != DEAD)
        {
            return Err(CheckError::FreeList(
                "free list names a live or out-of-range slot",
            ));
        }
        let np = self.points.len() as u32;
        let first_err = (0..n as u32).into_par_iter().find_map_first(|t| {
            let v = self.tets[t as usize];
            if v[0] == DEAD {
                return None;
            }
            if v.iter().any(|&x| x >= np)
                || v[0] == v[1]
                || v[0] == v[2]
                || v[0] == v[3]
                || v[1] == v[2]
                || v[1] == v[3]
                || v[2] == v[3]
            {
                return Some(CheckError::BadVertices(t, v));
            }
            let p = self.tet_points(t);
            let o = orient3d_sign(p[0], p[1], p[2], p[3]);
            if o != Orientation::Positive {
                return Some(CheckError::Orientation(t, o));
            }
            for f in 0..4 {
                let h = self.adj[t as usize][f];
                if h == NO_ADJ {
                    continue;
                }
                let (u, g) = ((h >> 2) as usize, (h & 3) as usize);
                if u >= n || self.tets[u][0] == DEAD {
                    return Some(CheckError::Adjacency(
                        t,
                        f,
                        "neighbour is dead or out of range",
                    ));
                }
                if self.adj[u][g] != 4 * t + f as u32 {
                    return Some(CheckError::Adjacency(t, f, "not mutual"));
                }
                let mine = self.face_vertices(t, f);
                let theirs = self.face_vertices(u as u32, g);
                if face_key(mine) != face_key(theirs) {
                    return Some(CheckError::Adjacency(
                        t,
                        f,
                        "the two faces have different vertices",
                    ));
                }
                // Opposite orientation: theirs must be a rotation of mine reversed.
                let rev = [mine[0], mine[2], mine[1]];
                let rotations = [rev, [rev[1], rev[2], rev[0]], [rev[2], rev[0], rev[1]]];
                if !rotations.contains(&theirs) {
                    return Some(CheckError::Adjacency(
                        t,
                        f,
                        "shared face has the same orientation on both sides",
                    ));
                }
            }
            None
        });
        if let Some(e) = first_err {
            return Err(e);
        }
        // The vertex → tet table: an entry names a live tet holding the
        // vertex, and every vertex of a live tet has one.
        if self.v2t.len() != self.points.len() {
            return Err(CheckError::Lengths);
        }
        let mut used = vec![false; self.points.len()];
        for t in self.tet_ids() {
            for x in self.tets[t as usize] {
                used[x as usize] = true;
            }
        }
        let stale = (0..np).find(|&x| {
            let t = self.v2t[x as usize];
            if t == DEAD {
                used[x as usize]
            } else {
                t as usize >= n || !self.tets[t as usize].contains(&x)
            }
        });
        if let Some(x) = stale {
            return Err(CheckError::VertexTet(x));
        }

        // Boundary manifoldness: the boundary faces' edges, counted.
        let mut boundary_edge_count: FastHashMap<[u32; 2], usize> = FastHashMap::default();
        for t in self.tet_ids() {
            for f in 0..4 {
                if self.adj[t as usize][f] == NO_ADJ {
                    let fv = self.face_vertices(t, f);
                    for (a, b) in [(fv[0], fv[1]), (fv[1], fv[2]), (fv[2], fv[0])] {
                        *boundary_edge_count.entry(edge_key(a, b)).or_default() += 1;
                    }
                }
            }
        }
        // Two boundary faces per boundary edge, or an even number of them where
        // the domain touches itself along an edge (a valid FEM mesh, e.g. the
        // getfem ladder); an odd count means a hole in the boundary.
        if let Some((e, &c)) = boundary_edge_count.iter().find(|(_, &c)| c % 2 != 0) {
            return Err(CheckError::NonManifoldBoundary(*e, c));
        }
        if !self.face_markers.is_empty() {
            let wanted: FastHashSet<FaceKey> = self.face_markers.keys().copied().collect();
            let faces = faces_present(&self.tets, &wanted);
            if let Some(f) = self.face_markers.keys().find(|f| !faces.contains(*f)) {
                return Err(CheckError::Tag(format!(
                    "marked face {f:?} is not a face of the mesh"
                )));
            }
        }
        if !self.feature_edges.is_empty() {
            let wanted: FastHashSet<EdgeKey> = self.feature_edges.keys().copied().collect();
            let edges = edges_present(&self.tets, &wanted);
            if let Some(e) = self.feature_edges.keys().find(|e| !edges.contains(*e)) {
                return Err(CheckError::Tag(format!(
                    "feature edge {e:?} is not an edge of the mesh"
                )));
            }
        }
        if let Some(v) = self
            .corners
            .iter()
            .chain(&self.required)
            .find(|&&v| v >= np)
        {
            return Err(CheckError::Tag(format!(
                "tagged vertex {v} is out of range"
            )));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::cube_grid;

    #[test]
    fn a_stale_vertex_tet_entry_is_caught() {
        let (mut mesh, _) = TetMesh::from_data(&cube_grid(2)).unwrap();
        mesh.check().unwrap();
        // A vertex held by live tets with no entry (a point retired while
        // a tet still holds it).
        let v = mesh.tet(0)[0];
        let saved = mesh.v2t[v as usize];
        mesh.v2t[v as usize] = DEAD;
        assert_eq!(mesh.check(), Err(CheckError::VertexTet(v)));
        // An entry naming a tet that does not hold the vertex.
        let other = mesh
            .tet_ids()
            .find(|&t| !mesh.tet(t).contains(&v))
            .expect("a tet away from v");
        mesh.v2t[v as usize] = other;
        assert_eq!(mesh.check(), Err(CheckError::VertexTet(v)));
        mesh.v2t[v as usize] = saved;
        mesh.check().unwrap();
    }
}
