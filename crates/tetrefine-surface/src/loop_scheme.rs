//! Loop subdivision of triangle meshes (C. Loop, "Smooth Subdivision
//! Surfaces Based on Triangles", M.S. thesis, University of Utah, 1987), with
//! the boundary and crease rules of Hoppe et al. ("Piecewise Smooth Surface
//! Reconstruction", SIGGRAPH 1994).
//!
//! Each triangle is split in four at its edge points.
//! * Edge point of a smooth edge a-b with opposite vertices c, d:
//!   3/8 (a + b) + 1/8 (c + d); of a curve edge (boundary or crease): the
//!   midpoint.
//! * Smooth vertex of valence n: (1 − nβ) p + β Σ pᵢ with
//!   β = (5/8 − (3/8 + cos(2π/n)/4)²)/n; crease vertex: 3/4 p + 1/8 (a + b)
//!   with a, b its curve neighbours (the cubic B-spline curve rule); corners
//!   stay.
//!
//! On a regular (valence-6) mesh the surface is the three-direction quartic
//! box spline, whose limit position at a vertex is p/2 + Σ pᵢ/12.
//!
//! Counts per step: V' = V + E, E' = 2E + 3F, F' = 4F.

use super::features::{classify, run_steps, sorted_pair, Features, Role, Step, SubdivisionError};
use super::lineage::{FaceAttributes, StepObserver, Subdivided};
use super::polymesh::{HalfEdges, PolyMesh, NO_TWIN};
use glam::DVec3;
use rayon::prelude::*;
use std::collections::HashSet;
use std::f64::consts::PI;

/// Loop's vertex weight β(n) = (5/8 − (3/8 + cos(2π/n)/4)²)/n.
pub fn loop_beta(n: usize) -> f64 {
    if n == 0 {
        return 0.0;
    }
    let c = 3.0 / 8.0 + (2.0 * PI / n as f64).cos() / 4.0;
    (5.0 / 8.0 - c * c) / n as f64
}

/// `steps` Loop steps of a triangle mesh with tagged features. Old points
/// keep their ids; the edge points follow, one per edge in the order of
/// [`HalfEdges::edges`].
pub fn loop_subdivide(
    mesh: &PolyMesh,
    steps: usize,
    features: &Features,
) -> Result<PolyMesh, SubdivisionError> {
    loop_subdivide_tracked(mesh, steps, features, None).map(|s| s.mesh)
}

/// [`loop_subdivide`] with the face attributes of [`super::lineage`] (the
/// four children of a triangle are its corner triangles at its vertices 0,
/// 1, 2, groups 0, 1, 2, then the central one, group 3) and an observer of
/// every generation.
pub fn loop_subdivide_tracked(
    mesh: &PolyMesh,
    steps: usize,
    features: &Features,
    observer: Option<&mut StepObserver<'_>>,
) -> Result<Subdivided, SubdivisionError> {
    if let Err(f) = mesh.triangles() {
        return Err(SubdivisionError::NotTriangles {
            face: f,
            len: mesh.faces[f].len(),
        });
    }
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
            let (mesh, creases) = loop_step(cur, he, creases, &corners);
            let n = cur.faces.len() as u32;
            Step {
                mesh,
                creases,
                parent: (0..n).flat_map(|f| [f; 4]).collect(),
                group: (0..n).flat_map(|_| [0, 1, 2, 3]).collect(),
            }
        },
    )
}

/// One Loop step; returns the refined mesh and its crease set.
fn loop_step(
    mesh: &PolyMesh,
    he: &HalfEdges,
    creases: &HashSet<[u32; 2]>,
    corners: &HashSet<u32>,
) -> (PolyMesh, HashSet<[u32; 2]>) {
    let np = mesh.points.len();
    let p = &mesh.points;
    let (curve, roles) = classify(he, creases, corners);
    // Vertex points.
    let mut sum = vec![DVec3::ZERO; np];
    let mut cnt = vec![0u32; np];
    for e in &he.edges {
        sum[e[0] as usize] += p[e[1] as usize];
        sum[e[1] as usize] += p[e[0] as usize];
        cnt[e[0] as usize] += 1;
        cnt[e[1] as usize] += 1;
    }
    let mut points: Vec<DVec3> = (0..np)
        .into_par_iter()
        .map(|v| match roles[v] {
            Role::Smooth => {
                let n = cnt[v] as usize;
                let b = loop_beta(n);
                p[v] * (1.0 - n as f64 * b) + sum[v] * b
            }
            Role::Crease([a, b]) => p[v] * 0.75 + (p[a as usize] + p[b as usize]) * 0.125,
            Role::Corner | Role::Unused => p[v],
        })
        .collect();
    // Edge points.
    let edge_pts: Vec<DVec3> = (0..he.edges.len())
        .into_par_iter()
        .map(|e| {
            let [a, b] = he.edges[e];
            let (pa, pb) = (p[a as usize], p[b as usize]);
            if curve[e] {
                (pa + pb) * 0.5
            } else {
                let h = he.edge_half[e];
                let t = he.twin[h as usize];
                debug_assert!(t != NO_TWIN);
                let c = he.origin[he.prev(h) as usize];
                let d = he.origin[he.prev(t) as usize];
                (pa + pb) * 0.375 + (p[c as usize] + p[d as usize]) * 0.125
            }
        })
        .collect();
    points.extend_from_slice(&edge_pts);
    let ep = |h: u32| np as u32 + he.edge[h as usize];
    let mut faces = Vec::with_capacity(mesh.faces.len() * 4);
    for f in 0..mesh.faces.len() {
        let s = he.face_start[f];
        let (h0, h1, h2) = (s, s + 1, s + 2);
        let (a, b, c) = (
            he.origin[h0 as usize],
            he.origin[h1 as usize],
            he.origin[h2 as usize],
        );
        let (ab, bc, ca) = (ep(h0), ep(h1), ep(h2));
        faces.push(vec![a, ab, ca]);
        faces.push(vec![b, bc, ab]);
        faces.push(vec![c, ca, bc]);
        faces.push(vec![ab, bc, ca]);
    }
    let mut next_creases = HashSet::with_capacity(creases.len() * 2);
    for (e, pair) in he.edges.iter().enumerate() {
        if creases.contains(pair) {
            let m = np as u32 + e as u32;
            next_creases.insert(sorted_pair(pair[0], m));
            next_creases.insert(sorted_pair(m, pair[1]));
        }
    }
    (PolyMesh { points, faces }, next_creases)
}
