//! The phases of one √3 step (see the module docs of [`crate::refine`]).

use super::{NoProgress, Phase, PhaseReport, Progress, RefineOptions, StepReport};
use crate::geom::{TET_EDGES, TET_FACES};
use crate::mesh::{edge_key, TetMesh, NO_ADJ};
use crate::ops::{
    flip23, flip23_valid, remove_edge, split14, split_boundary_face, EdgeRing, OpError,
};
use crate::smooth::{ball_stays_positive, improve, ImproveOptions};
use crate::surface::sqrt3::sqrt3_positions;
use glam::DVec3;
use std::collections::{HashMap, HashSet};
use std::time::Instant;

/// Runs `steps` refinement steps; one report per step.
pub fn refine(mesh: &mut TetMesh, steps: usize, opts: &RefineOptions) -> Vec<StepReport> {
    (1..=steps).map(|s| refine_step(mesh, s, opts)).collect()
}

/// State carried from phase to phase within one step.
struct StepState {
    /// Points with ids at or above this are the barycentres of this step.
    first_barycentre: u32,
    /// Points with ids at or above this are the face points of this step.
    first_face_point: u32,
    /// Old boundary faces that were split, outward-oriented, with their new point.
    split_faces: Vec<([u32; 3], u32)>,
}

/// One √3 step. `step` is 1-based (odd and even steps differ on creases).
pub fn refine_step(mesh: &mut TetMesh, step: usize, opts: &RefineOptions) -> StepReport {
    refine_step_with_progress(mesh, step, opts, &NoProgress)
}

/// [`refine_step`] with progress callbacks.
pub fn refine_step_with_progress(
    mesh: &mut TetMesh,
    step: usize,
    opts: &RefineOptions,
    progress: &dyn Progress,
) -> StepReport {
    let _ = step;
    let start = Instant::now();
    let mut report = StepReport::default();
    let mut st = StepState {
        first_barycentre: mesh.n_points() as u32,
        first_face_point: u32::MAX,
        split_faces: Vec::new(),
    };
    for phase in Phase::ALL {
        let t0 = Instant::now();
        progress.phase_start(phase, mesh.n_tets() as u64);
        match phase {
            Phase::Split => split_phase(mesh, opts, &mut report),
            Phase::Flip => flip_phase(mesh, &st, &mut report),
            Phase::BoundarySplit => boundary_split_phase(mesh, &mut st, &mut report),
            Phase::BoundaryFlip => boundary_flip_phase(mesh, &st, &mut report),
            Phase::BoundarySmooth => boundary_smooth_phase(mesh, &st, opts, &mut report),
            Phase::Optimize => {
                if opts.opt_passes > 0 {
                    report.improve = improve(
                        mesh,
                        &ImproveOptions {
                            passes: opts.opt_passes,
                            threshold: opts.threshold,
                            ..Default::default()
                        },
                    );
                }
            }
        }
        progress.phase_end();
        report.phases.push(PhaseReport {
            name: phase.name(),
            tets: mesh.n_tets(),
            seconds: t0.elapsed().as_secs_f64(),
        });
        if opts.stop_after == Some(phase) {
            break;
        }
    }
    report.seconds = start.elapsed().as_secs_f64();
    report
}

/// Phase 1: 1-4 split of every selected tet at its barycentre.
fn split_phase(mesh: &mut TetMesh, opts: &RefineOptions, report: &mut StepReport) {
    let ids: Vec<u32> = mesh
        .tet_ids()
        .filter(|&t| match &opts.selection {
            Some(sel) => sel.get(t as usize).copied().unwrap_or(false),
            None => true,
        })
        .collect();
    mesh.reserve(3 * ids.len(), ids.len());
    for t in ids {
        let p = mesh.tet_points(t);
        let c = (p[0] + p[1] + p[2] + p[3]) * 0.25;
        let level = mesh.level(t);
        // The barycentre of a positive tet is strictly inside it, so the split
        // cannot be refused; should rounding ever say otherwise, the tet stays.
        if let Ok(children) = split14(mesh, t, c) {
            for ch in children {
                mesh.set_level(ch, level.saturating_add(1));
            }
            report.split += 1;
        }
    }
}

/// Phase 2: 2-3 flip of each old interior face whose two tets were both split:
/// the children holding it have the two barycentres as apexes.
fn flip_phase(mesh: &mut TetMesh, st: &StepState, report: &mut StepReport) {
    let first = st.first_barycentre;
    let mut faces = Vec::new();
    for t in mesh.tet_ids() {
        let v = mesh.tet(t);
        // A child of this step's split has exactly one barycentre, opposite
        // the old face it holds.
        let Some(i) = (0..4).find(|&i| v[i] >= first) else {
            continue;
        };
        if (0..4).filter(|&j| v[j] >= first).count() != 1 {
            continue;
        }
        let h = mesh.adj(t)[i];
        if h == NO_ADJ {
            continue;
        }
        let (u, g) = TetMesh::half_face(h);
        if u > t && mesh.tet(u)[g] >= first {
            faces.push((t, i));
        }
    }
    make_flips_valid(mesh, first, &faces, report);
    for (t, f) in faces {
        match flip23(mesh, t, f) {
            Ok(_) => report.flipped += 1,
            Err(_) => report.refused_flips += 1,
        }
    }
}

/// Where the segment between two barycentres misses their shared face (the
/// input violates the precondition the paper borrows from Lehner), both
/// barycentres are pulled towards the face's centroid — they stay strictly
/// inside their parents, so the children stay valid — as long as no other
/// flip of theirs that was valid becomes invalid. The optimize phase moves
/// these points again later. Counted in `StepReport::moved_barycentres`.
fn make_flips_valid(
    mesh: &mut TetMesh,
    first: u32,
    faces: &[(u32, usize)],
    report: &mut StepReport,
) {
    let invalid: Vec<(u32, usize)> = faces
        .iter()
        .copied()
        .filter(|&(t, f)| !flip23_valid(mesh, t, f))
        .collect();
    if invalid.is_empty() {
        return;
    }
    // The flip faces around each barycentre, to re-check its other flips.
    let mut around: HashMap<u32, Vec<(u32, usize)>> = HashMap::new();
    for &(t, f) in faces {
        let p = mesh.tet(t)[f];
        let h = mesh.adj(t)[f];
        let (u, g) = TetMesh::half_face(h);
        let q = mesh.tet(u)[g];
        around.entry(p).or_default().push((t, f));
        around.entry(q).or_default().push((t, f));
    }
    let mut ball = Vec::new();
    for (t, f) in invalid {
        let h = mesh.adj(t)[f];
        let (u, g) = TetMesh::half_face(h);
        let (p, q) = (mesh.tet(t)[f], mesh.tet(u)[g]);
        debug_assert!(p >= first && q >= first);
        let fv = mesh.face_vertices(t, f);
        let centroid = (mesh.point(fv[0]) + mesh.point(fv[1]) + mesh.point(fv[2])) / 3.0;
        let (p0, q0) = (mesh.point(p), mesh.point(q));
        let others: Vec<(u32, usize)> = around[&p]
            .iter()
            .chain(&around[&q])
            .copied()
            .filter(|&x| x != (t, f))
            .collect();
        let was_valid: Vec<bool> = others
            .iter()
            .map(|&(a, b)| flip23_valid(mesh, a, b))
            .collect();
        let mut fixed = false;
        for s in [0.7, 0.5, 0.3, 0.15, 0.05] {
            let (p1, q1) = (
                centroid + (p0 - centroid) * s,
                centroid + (q0 - centroid) * s,
            );
            mesh.ball(p, &mut ball);
            let p_ok = ball_stays_positive(mesh, p, &ball, p1);
            mesh.ball(q, &mut ball);
            let q_ok = ball_stays_positive(mesh, q, &ball, q1);
            if !(p_ok && q_ok) {
                continue;
            }
            mesh.set_point(p, p1);
            mesh.set_point(q, q1);
            let ok = flip23_valid(mesh, t, f)
                && others
                    .iter()
                    .zip(&was_valid)
                    .all(|(&(a, b), &w)| !w || flip23_valid(mesh, a, b));
            if ok {
                fixed = true;
                break;
            }
            mesh.set_point(p, p0);
            mesh.set_point(q, q0);
        }
        if fixed {
            report.moved_barycentres += 2;
        }
    }
}

/// Phase 3: 1-3 split of every boundary face of a split tet, at its barycentre.
fn boundary_split_phase(mesh: &mut TetMesh, st: &mut StepState, report: &mut StepReport) {
    let first = st.first_barycentre;
    st.first_face_point = mesh.n_points() as u32;
    let mut faces = Vec::new();
    for t in mesh.tet_ids() {
        let v = mesh.tet(t);
        for f in 0..4 {
            if v[f] >= first
                && mesh.is_boundary_face(t, f)
                && (0..4).all(|j| j == f || v[j] < first)
            {
                faces.push((t, f));
            }
        }
    }
    for (t, f) in faces {
        let fv = mesh.face_vertices(t, f);
        let p = fv.map(|x| mesh.point(x));
        let c = (p[0] + p[1] + p[2]) / 3.0;
        if let Ok((m, _)) = split_boundary_face(mesh, t, f, c) {
            st.split_faces.push((fv, m));
            report.boundary_split += 1;
        }
    }
}

/// Phase 4: every old boundary edge whose two boundary faces were split is
/// removed; the new boundary edge joins the two face points.
fn boundary_flip_phase(mesh: &mut TetMesh, st: &StepState, report: &mut StepReport) {
    let fp = st.first_face_point;
    // Old edges seen from the split faces; flip those seen twice (both sides).
    let mut seen: HashMap<[u32; 2], (u32, u8)> =
        HashMap::with_capacity(3 * st.split_faces.len() / 2);
    for &(f, m) in &st.split_faces {
        for i in 0..3 {
            let k = edge_key(f[i], f[(i + 1) % 3]);
            seen.entry(k).and_modify(|e| e.1 += 1).or_insert((m, 1));
        }
    }
    let mut edges: Vec<([u32; 2], u32)> = seen
        .into_iter()
        .filter(|(_, (_, n))| *n == 2)
        .map(|(k, (m, _))| (k, m))
        .collect();
    edges.sort_unstable();
    let mut ball = Vec::new();
    let mut ring = EdgeRing::default();
    for ([a, b], m) in edges {
        if mesh.is_feature_edge(a, b) {
            report.refused_boundary_flips += 1;
            continue;
        }
        // A tet holding a, b and the face point m.
        mesh.ball(m, &mut ball);
        let found = ball.iter().find_map(|&t| {
            let v = mesh.tet(t);
            let ia = v.iter().position(|&x| x == a)?;
            let ib = v.iter().position(|&x| x == b)?;
            let e = TET_EDGES
                .iter()
                .position(|&[i, j]| (i == ia && j == ib) || (i == ib && j == ia))?;
            Some((t, e))
        });
        let Some((t, e)) = found else {
            report.refused_boundary_flips += 1;
            continue;
        };
        ring.gather_into(mesh, t, e);
        let ends_ok = !ring.closed
            && ring.verts.first().is_some_and(|&x| x >= fp)
            && ring.verts.last().is_some_and(|&x| x >= fp);
        let (p0, pm) = (ring.verts[0], *ring.verts.last().unwrap_or(&0));
        let same_marker = mesh.face_marker([a, b, p0]) == mesh.face_marker([a, b, pm]);
        if !ends_ok || !same_marker {
            report.refused_boundary_flips += 1;
            continue;
        }
        match remove_edge(mesh, &ring, f64::NEG_INFINITY) {
            Ok(_) => report.boundary_flipped += 1,
            Err(OpError::WouldInvert) | Err(_) => report.refused_boundary_flips += 1,
        }
    }
}

/// Phase 5: the √3 stencils on the old boundary points and the new face
/// points; each move is checked against inversion and halved (up to six
/// times) or skipped.
fn boundary_smooth_phase(
    mesh: &mut TetMesh,
    st: &StepState,
    opts: &RefineOptions,
    report: &mut StepReport,
) {
    if st.split_faces.is_empty() {
        return;
    }
    let tris: Vec<[u32; 3]> = st.split_faces.iter().map(|(f, _)| *f).collect();
    let creases: HashSet<[u32; 2]> = mesh.feature_edges().keys().copied().collect();
    let corners: HashSet<u32> = mesh
        .corners()
        .iter()
        .chain(mesh.required_vertices())
        .copied()
        .collect();
    let pos = sqrt3_positions(
        mesh.points(),
        &tris,
        opts.boundary.sqrt3_rule(),
        &creases,
        &corners,
    );
    // Targets: old boundary vertices, then face points.
    let mut targets: Vec<(u32, DVec3)> = Vec::new();
    let mut old: Vec<u32> = tris.iter().flatten().copied().collect();
    old.sort_unstable();
    old.dedup();
    for v in old {
        targets.push((v, pos.vertices[v as usize]));
    }
    for (i, &(_, m)) in st.split_faces.iter().enumerate() {
        targets.push((m, pos.faces[i]));
    }
    let mut ball = Vec::new();
    for (v, target) in targets {
        let from = mesh.point(v);
        if target == from {
            continue;
        }
        mesh.ball(v, &mut ball);
        let mut t = 1.0;
        let mut moved = false;
        for attempt in 0..7 {
            let x = from + (target - from) * t;
            if ball_stays_positive(mesh, v, &ball, x) {
                mesh.set_point(v, x);
                if attempt == 0 {
                    report.full_moves += 1;
                } else {
                    report.shortened_moves += 1;
                }
                moved = true;
                break;
            }
            t *= 0.5;
        }
        if !moved {
            report.skipped_moves += 1;
        }
    }
    let _ = TET_FACES;
}
