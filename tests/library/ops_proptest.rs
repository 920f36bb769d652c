//! Local operations on random valid configurations: `check()` passes, volume
//! is conserved, the cavity's outer faces are unchanged, and an operation that
//! would invert a tet is refused with the mesh left as it was.

use glam::DVec3;
use proptest::prelude::*;
use std::collections::BTreeSet;
use tetrefine::geom::{orient3d, tet_volume};
use tetrefine::ops::{
    flip23, flip32, remove_edge, split14, split_boundary_face, EdgeRing, OpError,
};
use tetrefine::topo::face_key;
use tetrefine::{MeshData, TetMesh};

fn build(points: &[DVec3], tets: &[[u32; 4]]) -> Option<TetMesh> {
    let data = MeshData {
        points: points.iter().map(|p| p.to_array()).collect(),
        tets: tets.to_vec(),
        ..Default::default()
    };
    TetMesh::from_data(&data).ok().map(|(m, _)| m)
}

/// Total volume, each tet measured from the mesh's first point so that the
/// coordinates' magnitude does not swamp the comparison.
fn volume(m: &TetMesh) -> f64 {
    let o = m.point(0);
    m.tet_ids()
        .map(|t| tet_volume(&m.tet_points(t).map(|p| p - o)))
        .sum()
}

/// A tet whose shape does not make float volume comparisons meaningless.
fn shapely(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> bool {
    tetrefine::geom::tet_min_sine(&[a, b, c, d]).abs() > 0.05
}

fn boundary_faces(m: &TetMesh) -> BTreeSet<[u32; 3]> {
    m.tet_ids()
        .flat_map(|t| {
            (0..4)
                .filter(move |&f| m.is_boundary_face(t, f))
                .map(move |f| (t, f))
        })
        .map(|(t, f)| face_key(m.face_vertices(t, f)))
        .collect()
}

fn positions(m: &TetMesh) -> Vec<DVec3> {
    m.points().to_vec()
}

fn tet_slots(m: &TetMesh) -> Vec<[u32; 4]> {
    m.tet_slots().to_vec()
}

fn pt() -> impl Strategy<Value = DVec3> {
    (-10.0f64..10.0, -10.0f64..10.0, -10.0f64..10.0).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

/// A ring of `m` tets around the edge from (0,0,-h1) to (0,0,h2): ring points
/// at increasing angles (a full turn when `closed`, less than half a turn of
/// spread otherwise, ending exactly opposite for a coplanar boundary).
fn ring_config(
    angles: &[f64],
    radii: &[f64],
    heights: &[f64],
    closed: bool,
) -> (Vec<DVec3>, Vec<[u32; 4]>) {
    let mut pts = vec![DVec3::new(0.0, 0.0, 3.0), DVec3::new(0.0, 0.0, -3.0)];
    for i in 0..angles.len() {
        pts.push(DVec3::new(
            radii[i] * angles[i].cos(),
            radii[i] * angles[i].sin(),
            heights[i],
        ));
    }
    let r = angles.len() as u32;
    let n = if closed { r } else { r - 1 };
    let tets = (0..n).map(|i| [0, 1, 2 + i, 2 + (i + 1) % r]).collect();
    (pts, tets)
}

fn sorted_angles(raw: Vec<f64>, span: f64) -> Vec<f64> {
    // Distinct increasing angles in [0, span).
    let mut a: Vec<f64> = raw.into_iter().map(|x| x * span).collect();
    a.sort_by(f64::total_cmp);
    a.dedup_by(|x, y| (*x - *y).abs() < 1e-3);
    a
}

proptest! {
    // A fixed seed keeps CI reproducible; change it locally to explore.
    #![proptest_config(ProptestConfig {
        cases: 256,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x7e7_2e61e),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn split14_inside_conserves_and_outside_is_refused(
        a in pt(), b in pt(), c in pt(), d in pt(),
        w in (0.01f64..1.0, 0.01f64..1.0, 0.01f64..1.0, 0.01f64..1.0),
        out in (1.0f64..3.0),
    ) {
        let p = [a, b, c, d];
        prop_assume!(shapely(a, b, c, d));
        let mut m = build(&p, &[[0, 1, 2, 3]]).unwrap();
        let v0 = volume(&m);
        let faces0 = boundary_faces(&m);
        let s = w.0 + w.1 + w.2 + w.3;
        let inside = (a * w.0 + b * w.1 + c * w.2 + d * w.3) / s;
        // Outside: beyond vertex a, away from the opposite face's centroid.
        let outside = a + (a - (b + c + d) / 3.0) * out;
        let before = (positions(&m), tet_slots(&m));
        prop_assert_eq!(split14(&mut m, 0, outside), Err(OpError::WouldInvert));
        prop_assert_eq!((positions(&m), tet_slots(&m)), before);
        m.check().unwrap();
        split14(&mut m, 0, inside).unwrap();
        m.check().unwrap();
        prop_assert_eq!(m.n_tets(), 4);
        prop_assert!((volume(&m) - v0).abs() <= 1e-12 * v0.abs());
        prop_assert_eq!(boundary_faces(&m), faces0);
    }

    #[test]
    fn flip23_valid_iff_segment_crosses_face(
        a in pt(), b in pt(), c in pt(), w in (0.05f64..1.0, 0.05f64..1.0, 0.05f64..1.0),
        hp in 0.5f64..5.0, hq in 0.5f64..5.0, shift in pt(),
    ) {
        let n = (b - a).cross(c - a);
        prop_assume!(n.length() > 1e-2);
        let n = n.normalize();
        let s = w.0 + w.1 + w.2;
        let x = (a * w.0 + b * w.1 + c * w.2) / s; // crosses here
        let q = x + n * hq;
        // p below the face: straight below x (valid) or shifted sideways (maybe not)
        let p_valid = x - n * hp;
        let p_any = x - n * hp + (shift - n * shift.dot(n));
        for (p, must_be_valid) in [(p_valid, true), (p_any, false)] {
            let pts = [a, b, c, p, q];
            let Some(mut m) = build(&pts, &[[0, 1, 2, 3], [0, 1, 2, 4]]) else { continue };
            m.check().unwrap();
            let v0 = volume(&m);
            let faces0 = boundary_faces(&m);
            let before = (positions(&m), tet_slots(&m));
            let t = m.tet_ids().find(|&t| m.tet(t).contains(&3)).unwrap();
            let f = m.local_index(t, 3).unwrap();
            // The exact criterion: the three new tets all positive.
            let crosses = [[0u32, 1], [1, 2], [2, 0]].iter().all(|&[i, j]| {
                let (pi, pj) = (pts[i as usize], pts[j as usize]);
                let o = orient3d(pi, pj, p, q);
                // Orientation of (i, j, p, q) must agree with (a, b, c) seen from q.
                o != 0.0 && (o > 0.0) == (orient3d(a, b, c, q) > 0.0)
            });
            match flip23(&mut m, t, f) {
                Ok(_) => {
                    prop_assert!(crosses);
                    m.check().unwrap();
                    prop_assert_eq!(m.n_tets(), 3);
                    prop_assert!((volume(&m) - v0).abs() <= 1e-12 * v0.abs());
                    prop_assert_eq!(boundary_faces(&m), faces0);
                }
                Err(e) => {
                    prop_assert!(!must_be_valid || !crosses, "valid flip refused: {e}");
                    prop_assert!(!crosses);
                    prop_assert_eq!((positions(&m), tet_slots(&m)), before);
                }
            }
        }
    }

    #[test]
    fn interior_edge_removal_conserves_volume_and_outer_faces(
        raw in proptest::collection::vec(0.0f64..1.0, 3..9),
        radii in proptest::collection::vec(0.5f64..3.0, 9),
        heights in proptest::collection::vec(-1.0f64..1.0, 9),
    ) {
        let angles = sorted_angles(raw, std::f64::consts::TAU);
        prop_assume!(angles.len() >= 3);
        // Consecutive ring points less than π apart, or tets would fold.
        let gaps_ok = angles.windows(2).all(|w| w[1] - w[0] < 3.0)
            && angles[0] + std::f64::consts::TAU - angles[angles.len() - 1] < 3.0;
        prop_assume!(gaps_ok);
        let (pts, tets) = ring_config(&angles, &radii, &heights, true);
        let Some(mut m) = build(&pts, &tets) else { return Ok(()) };
        m.check().unwrap();
        let v0 = volume(&m);
        let faces0 = boundary_faces(&m);
        let t = m.tet_ids().next().unwrap();
        let e = tetrefine::topo::TET_EDGES
            .iter()
            .position(|&[i, j]| {
                let v = m.tet(t);
                let s = [v[i], v[j]];
                s.contains(&0) && s.contains(&1)
            })
            .unwrap();
        let ring = EdgeRing::gather(&m, t, e);
        prop_assert!(ring.closed);
        prop_assert_eq!(ring.tets.len(), angles.len());
        let mtets = ring.tets.len();
        let before = (positions(&m), tet_slots(&m));
        match remove_edge(&mut m, &ring, f64::NEG_INFINITY) {
            Ok(new) => {
                m.check().unwrap();
                prop_assert_eq!(new.len(), 2 * mtets - 4);
                prop_assert!((volume(&m) - v0).abs() <= 1e-12 * v0.abs());
                prop_assert_eq!(boundary_faces(&m), faces0);
            }
            Err(OpError::WouldInvert) => {
                // No triangulation of the ring has all tets positive: the mesh
                // must be untouched.
                prop_assert_eq!((positions(&m), tet_slots(&m)), before);
            }
            Err(e) => prop_assert!(false, "unexpected {e}"),
        }
    }

    #[test]
    fn flip32_on_three_tets(
        raw in proptest::collection::vec(0.0f64..1.0, 3),
        radii in proptest::collection::vec(0.5f64..3.0, 3),
        heights in proptest::collection::vec(-1.0f64..1.0, 3),
    ) {
        let angles = sorted_angles(raw, std::f64::consts::TAU);
        prop_assume!(angles.len() == 3);
        let (pts, tets) = ring_config(&angles, &radii, &heights, true);
        let Some(mut m) = build(&pts, &tets) else { return Ok(()) };
        let v0 = volume(&m);
        let t = m.tet_ids().next().unwrap();
        let e = (0..6).find(|&e| {
            let r = EdgeRing::gather(&m, t, e);
            (r.a == 0 && r.b == 1) || (r.a == 1 && r.b == 0)
        }).unwrap();
        // The tets (a,b,p_i,p_i+1) are positive, so the line a-b already passes
        // inside the ring triangle; the 3-2 flip is valid exactly when a and b
        // lie on opposite sides of the triangle's plane.
        let (a, b) = (pts[0], pts[1]);
        let (p0, p1, p2) = (pts[2], pts[3], pts[4]);
        let valid = orient3d(p0, p1, p2, a) * orient3d(p0, p1, p2, b) < 0.0;
        match flip32(&mut m, t, e) {
            Ok(_) => {
                prop_assert!(valid);
                m.check().unwrap();
                prop_assert_eq!(m.n_tets(), 2);
                prop_assert!((volume(&m) - v0).abs() <= 1e-12 * v0.abs());
            }
            Err(err) => {
                prop_assert!(!valid);
                prop_assert_eq!(err, OpError::WouldInvert);
                prop_assert_eq!(m.n_tets(), 3);
                m.check().unwrap();
            }
        }
    }

    #[test]
    fn boundary_edge_removal_on_a_flat_boundary(
        raw in proptest::collection::vec(0.0f64..1.0, 1..7),
        radii in proptest::collection::vec(0.5f64..3.0, 9),
        heights in proptest::collection::vec(-1.0f64..1.0, 9),
    ) {
        // Open ring from angle 0 to π with p0 and p_last in the plane y = 0
        // through the edge: the two boundary faces are coplanar, so the flip
        // keeps the volume exactly.
        let mut angles = vec![0.0];
        angles.extend(sorted_angles(raw, std::f64::consts::PI).into_iter().filter(|&x| x > 0.05 && x < 3.09));
        angles.push(std::f64::consts::PI);
        let gaps_ok = angles.windows(2).all(|w| w[1] - w[0] < 3.0);
        prop_assume!(gaps_ok);
        let mut h = heights.clone();
        let first = 0;
        let last = angles.len() - 1;
        h[first] = 0.0;
        h[last] = 0.0;
        let (mut pts, tets) = ring_config(&angles, &radii, &h, false);
        pts[2 + last].y = 0.0; // exactly on the plane y = 0
        let Some(mut m) = build(&pts, &tets) else { return Ok(()) };
        m.check().unwrap();
        let v0 = volume(&m);
        let t = m.tet_ids().next().unwrap();
        let e = (0..6).find(|&e| {
            let r = EdgeRing::gather(&m, t, e);
            (r.a == 0 && r.b == 1) || (r.a == 1 && r.b == 0)
        }).unwrap();
        let ring = EdgeRing::gather(&m, t, e);
        prop_assert!(!ring.closed);
        let mtets = ring.tets.len();
        match remove_edge(&mut m, &ring, f64::NEG_INFINITY) {
            Ok(new) => {
                m.check().unwrap();
                prop_assert_eq!(new.len(), 2 * mtets - 2);
                prop_assert!((volume(&m) - v0).abs() <= 1e-12 * v0.abs());
                // The old edge is gone and the ring's end points are joined.
                let ends = [ring.verts[0], *ring.verts.last().unwrap()];
                let has = |x: u32, y: u32| m.tet_ids().any(|t| m.tet(t).contains(&x) && m.tet(t).contains(&y));
                prop_assert!(!has(0, 1));
                prop_assert!(has(ends[0], ends[1]));
            }
            Err(e) => {
                prop_assert_eq!(e, OpError::WouldInvert);
                m.check().unwrap();
                prop_assert_eq!(m.n_tets(), mtets);
            }
        }
    }

    #[test]
    fn boundary_split13_conserves_volume(
        a in pt(), b in pt(), c in pt(), d in pt(), w in (0.05f64..1.0, 0.05f64..1.0, 0.05f64..1.0),
    ) {
        prop_assume!(shapely(a, b, c, d));
        let mut m = build(&[a, b, c, d], &[[0, 1, 2, 3]]).unwrap();
        let v0 = volume(&m);
        let t = m.tet_ids().next().unwrap();
        let f = m.local_index(t, 3).unwrap(); // the face (a,b,c)
        let fv = m.face_vertices(t, f).map(|x| m.point(x));
        let s = w.0 + w.1 + w.2;
        let x = (fv[0] * w.0 + fv[1] * w.1 + fv[2] * w.2) / s;
        let (_, new) = split_boundary_face(&mut m, t, f, x).unwrap();
        m.check().unwrap();
        prop_assert_eq!(new.len(), 3);
        prop_assert!((volume(&m) - v0).abs() <= 1e-12 * v0.abs());
        // Beyond the opposite vertex, the split must be refused.
        let mut m2 = build(&[a, b, c, d], &[[0, 1, 2, 3]]).unwrap();
        let beyond = d + (d - x) * 2.0;
        prop_assert_eq!(split_boundary_face(&mut m2, t, f, beyond).map(|_| ()), Err(OpError::WouldInvert));
        m2.check().unwrap();
    }
}
