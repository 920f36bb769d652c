//! Doo–Sabin subdivision of polygon meshes (D. Doo, M. Sabin, "Behaviour of
//! recursive division surfaces near extraordinary points", CAD 10(6), 1978).
//!
//! Every corner k of a face of n vertices becomes a new point
//! Σⱼ αₖⱼ pⱼ with αₖₖ = (n + 5)/(4n) and αₖⱼ = (3 + 2 cos(2π(k − j)/n))/(4n)
//! (the Doo–Sabin weights; for quads 9/16, 3/16, 3/16, 1/16, the tensor
//! product of Chaikin's corner cutting). The new faces are: one *F-face* per
//! old face (its corner points), one quad *E-face* per interior edge and one
//! *V-face* per interior vertex (the corner points around it). On a regular
//! quad mesh the limit surface is the uniform biquadratic B-spline.
//!
//! Every F-face keeps the centroid of its old face (the weights of each old
//! vertex over the n corners sum to 1), so the limit point of a face is its
//! centroid.
//!
//! Boundaries: edges and vertices on an open boundary get no E- or V-face,
//! so the boundary recedes (the simple, common treatment); tagged creases
//! are not supported by this scheme.
//!
//! Counts per step on a closed mesh: V' = Σ|f| = 2E, F' = F + E + V,
//! E' = 4E. Output order: F-faces (old face order), E-faces (edge order of
//! [`super::polymesh::HalfEdges::edges`]), V-faces (vertex order); new point
//! ids are the half-edge ids of the corners.

use super::features::SubdivisionError;
use super::lineage::{observe, FaceAttributes, StepObserver, Subdivided};
use super::polymesh::{PolyMesh, NO_TWIN};
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::PI;

/// The Doo–Sabin weight of vertex j for the corner k of an n-gon, with
/// d = (k − j) mod n.
pub fn doo_sabin_weight(n: usize, d: usize) -> f64 {
    let nf = n as f64;
    if d % n == 0 {
        (nf + 5.0) / (4.0 * nf)
    } else {
        (3.0 + 2.0 * (2.0 * PI * d as f64 / nf).cos()) / (4.0 * nf)
    }
}

/// `steps` Doo–Sabin steps.
pub fn doo_sabin(mesh: &PolyMesh, steps: usize) -> Result<PolyMesh, SubdivisionError> {
    doo_sabin_tracked(mesh, steps, None).map(|s| s.mesh)
}

/// [`doo_sabin`] with the face attributes of [`super::lineage`] (an F-face
/// continues its face: generation and group kept; an E-face is in group 1,
/// from the face of the edge's first half-edge; a V-face in group 2, from
/// the face of the vertex's first outgoing half-edge) and an observer of
/// every generation.
pub fn doo_sabin_tracked(
    mesh: &PolyMesh,
    steps: usize,
    mut observer: Option<&mut StepObserver<'_>>,
) -> Result<Subdivided, SubdivisionError> {
    mesh.validate()?;
    let mut cur = mesh.clone();
    let mut attrs = FaceAttributes::input(mesh.faces.len());
    let mut done = 0;
    if observe(&mut observer, 0, &cur, &attrs) {
        for k in 0..steps {
            (cur, attrs) = doo_sabin_step(&cur, &attrs, k as u32 + 1)?;
            done = k + 1;
            if !observe(&mut observer, done, &cur, &attrs) {
                break;
            }
        }
    }
    Ok(Subdivided {
        mesh: cur,
        attributes: attrs,
        steps: done,
    })
}

fn doo_sabin_step(
    mesh: &PolyMesh,
    attrs: &FaceAttributes,
    generation: u32,
) -> Result<(PolyMesh, FaceAttributes), SubdivisionError> {
    let he = mesh.half_edges()?;
    let p = &mesh.points;
    let corner_pts: Vec<Vec<DVec3>> = mesh
        .faces
        .par_iter()
        .map(|f| {
            let n = f.len();
            let w: Vec<f64> = (0..n).map(|d| doo_sabin_weight(n, d)).collect();
            (0..n)
                .map(|k| {
                    let mut q = DVec3::ZERO;
                    for (j, &v) in f.iter().enumerate() {
                        q += p[v as usize] * w[(k + n - j) % n];
                    }
                    q
                })
                .collect()
        })
        .collect();
    let points: Vec<DVec3> = corner_pts.into_iter().flatten().collect();
    let n = mesh.faces.len() + he.edges.len() + p.len();
    let mut faces: Vec<Vec<u32>> = Vec::with_capacity(n);
    let mut out = FaceAttributes::with_capacity(n);
    for f in 0..mesh.faces.len() {
        faces.push((he.face_start[f]..he.face_start[f + 1]).collect());
        out.push_kept(attrs, f as u32);
    }
    for &h in &he.edge_half {
        let t = he.twin[h as usize];
        if t == NO_TWIN {
            continue;
        }
        // h: u→w in f, t: w→u in g; corner ids are half-edge ids.
        faces.push(vec![he.next(h), h, he.next(t), t]);
        out.push_child(attrs, he.face[h as usize], generation, 1);
    }
    for v in 0..p.len() as u32 {
        if he.vertex_out[v as usize] == NO_TWIN || he.is_boundary_vertex(v) {
            continue;
        }
        faces.push(he.outgoing(v));
        let first = he.vertex_out[v as usize];
        out.push_child(attrs, he.face[first as usize], generation, 2);
    }
    Ok((PolyMesh { points, faces }, out))
}
