//! Catmull–Clark subdivision of polygon meshes (E. Catmull, J. Clark,
//! "Recursively generated B-spline surfaces on arbitrary topological meshes",
//! CAD 10(6), 1978), with the boundary and crease rules of DeRose, Kass and
//! Truong ("Subdivision Surfaces in Character Animation", SIGGRAPH 1998).
//!
//! Each face of n vertices becomes n quads joining its face point, the edge
//! points of its edges and the vertex points of its vertices.
//! * Face point: the average of the face's vertices.
//! * Edge point of a smooth edge: ((F₁ + F₂) + (P₁ + P₂))/4; of a curve edge
//!   (boundary or crease): the midpoint.
//! * Smooth vertex of valence n: (F̄ + 2R̄ + (n − 3) P)/n, with F̄ the average
//!   of the adjacent face points and R̄ the average of the midpoints of the
//!   incident edges; crease vertex: (6P + a + b)/8 (the cubic B-spline curve
//!   rule); corners stay.
//!
//! On a regular quad mesh (valence 4 everywhere) the limit surface is the
//! uniform bicubic tensor-product B-spline of the control net.
//!
//! Counts per step: V' = V + E + F, E' = 2E + Σ|f|, F' = Σ|f|. New points:
//! old vertices keep their ids, then one edge point per edge (in the order of
//! [`HalfEdges::edges`]), then one face point per face.

use super::features::{
    classify, corner_children, run_steps, sorted_pair, Features, Role, Step, SubdivisionError,
};
use super::lineage::{FaceAttributes, StepObserver, Subdivided};
use super::polymesh::{HalfEdges, PolyMesh};
use glam::DVec3;
use rayon::prelude::*;
use std::collections::HashSet;

/// `steps` Catmull–Clark steps with tagged features.
pub fn catmull_clark(
    mesh: &PolyMesh,
    steps: usize,
    features: &Features,
) -> Result<PolyMesh, SubdivisionError> {
    catmull_clark_tracked(mesh, steps, features, None).map(|s| s.mesh)
}

/// [`catmull_clark`] with the face attributes of [`super::lineage`] (the
/// quad at corner `k` of a face is in group `k`) and an observer of every
/// generation.
pub fn catmull_clark_tracked(
    mesh: &PolyMesh,
    steps: usize,
    features: &Features,
    observer: Option<&mut StepObserver<'_>>,
) -> Result<Subdivided, SubdivisionError> {
    let he = mesh.half_edges()?;
    let (creases, corners) = features.resolve(mesh, &he)?;
    let attributes = FaceAttributes::input(mesh.faces.len());
    run_steps(
        mesh,
        he,
        creases,
        steps,
        attributes,
        observer,
        |_, cur, he, creases| {
            let (curve, roles) = classify(he, creases, &corners);
            let points = catmull_clark_points(cur, he, &curve, &roles);
            let faces = catmull_clark_faces(cur, he);
            let (parent, group) = corner_children(cur);
            Step {
                mesh: PolyMesh { points, faces },
                creases: split_creases(cur, he, creases),
                parent,
                group,
            }
        },
    )
}

/// Face points: the averages of the faces' vertices (summed in face order).
pub(crate) fn face_points(mesh: &PolyMesh) -> Vec<DVec3> {
    mesh.faces
        .par_iter()
        .map(|f| {
            let mut s = DVec3::ZERO;
            for &v in f {
                s += mesh.points[v as usize];
            }
            s / f.len() as f64
        })
        .collect()
}

/// The new points of one plain step: vertex points, edge points, face points.
fn catmull_clark_points(
    mesh: &PolyMesh,
    he: &HalfEdges,
    curve: &[bool],
    roles: &[Role],
) -> Vec<DVec3> {
    let p = &mesh.points;
    let fp = face_points(mesh);
    let edge_pts: Vec<DVec3> = (0..he.edges.len())
        .into_par_iter()
        .map(|e| {
            let [a, b] = he.edges[e];
            let pp = p[a as usize] + p[b as usize];
            if curve[e] {
                pp * 0.5
            } else {
                let h = he.edge_half[e];
                let t = he.twin[h as usize];
                let ff = fp[he.face[h as usize] as usize] + fp[he.face[t as usize] as usize];
                (ff + pp) * 0.25
            }
        })
        .collect();
    let vertex_pts: Vec<DVec3> = (0..p.len())
        .into_par_iter()
        .map(|v| match roles[v] {
            Role::Smooth => {
                let (fbar, rbar, n) = vertex_averages(mesh, he, &fp, v as u32);
                (fbar + rbar * 2.0 + p[v] * (n - 3.0)) / n
            }
            Role::Crease(curve_nbrs) => crease_vertex_point(p, v, curve_nbrs),
            Role::Corner | Role::Unused => p[v],
        })
        .collect();
    in_point_order(vertex_pts, &edge_pts, &fp)
}

/// The cubic B-spline vertex rule on a crease or boundary curve,
/// `(6 p_v + p_a + p_b) / 8` for the curve neighbours `a`, `b` of `v`.
pub(crate) fn crease_vertex_point(p: &[DVec3], v: usize, [a, b]: [u32; 2]) -> DVec3 {
    (p[v] * 6.0 + p[a as usize] + p[b as usize]) / 8.0
}

/// The new points in the numbering of [`catmull_clark_faces`]: vertex
/// points, then edge points, then face points.
pub(crate) fn in_point_order(
    mut vertex_pts: Vec<DVec3>,
    edge_pts: &[DVec3],
    face_pts: &[DVec3],
) -> Vec<DVec3> {
    vertex_pts.extend_from_slice(edge_pts);
    vertex_pts.extend_from_slice(face_pts);
    vertex_pts
}

/// For a smooth vertex: the average of its face points, the average of the
/// midpoints of its edges and its valence (as f64), summed in the order of
/// its outgoing half-edges.
pub(crate) fn vertex_averages(
    mesh: &PolyMesh,
    he: &HalfEdges,
    fp: &[DVec3],
    v: u32,
) -> (DVec3, DVec3, f64) {
    let p = &mesh.points;
    let mut fs = DVec3::ZERO;
    let mut rs = DVec3::ZERO;
    let mut n = 0usize;
    for h in he.outgoing(v) {
        fs += fp[he.face[h as usize] as usize];
        rs += (p[v as usize] + p[he.dest(h) as usize]) * 0.5;
        n += 1;
    }
    let nf = n as f64;
    (fs / nf, rs / nf, nf)
}

/// The quads of one step: face f of n vertices gives n quads
/// (vₖ, e(vₖ, vₖ₊₁), F, e(vₖ₋₁, vₖ)), in face order.
pub(crate) fn catmull_clark_faces(mesh: &PolyMesh, he: &HalfEdges) -> Vec<Vec<u32>> {
    let nv = mesh.points.len() as u32;
    let ne = he.edges.len() as u32;
    let mut faces = Vec::with_capacity(he.len());
    for (f, face) in mesh.faces.iter().enumerate() {
        let s = he.face_start[f];
        let n = face.len() as u32;
        let fid = nv + ne + f as u32;
        for k in 0..n {
            let h = s + k;
            let hp = s + (k + n - 1) % n;
            faces.push(vec![
                face[k as usize],
                nv + he.edge[h as usize],
                fid,
                nv + he.edge[hp as usize],
            ]);
        }
    }
    faces
}

/// Creases after a step: each crease a-b becomes a-m, m-b through its edge
/// point m.
pub(crate) fn split_creases(
    mesh: &PolyMesh,
    he: &HalfEdges,
    creases: &HashSet<[u32; 2]>,
) -> HashSet<[u32; 2]> {
    let nv = mesh.points.len() as u32;
    let mut out = HashSet::with_capacity(creases.len() * 2);
    for (e, pair) in he.edges.iter().enumerate() {
        if creases.contains(pair) {
            let m = nv + e as u32;
            out.insert(sorted_pair(pair[0], m));
            out.insert(sorted_pair(m, pair[1]));
        }
    }
    out
}
