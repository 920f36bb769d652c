//! Face attributes through the schemes, checked against facts that do not
//! come from the tracking: counts from the schemes' closed forms, the old
//! vertex ids that the children of a face keep (Loop, Catmull–Clark), the
//! geometry of the input (truncation) and unsplit triangles equal to their
//! input triangle (adaptive √3).

use crate::shapes::*;
use glam::DVec3;
use std::ops::ControlFlow;
use tetrefine_surface::catmull_clark::catmull_clark_tracked;
use tetrefine_surface::catmull_clark_weighted::{
    catmull_clark_weighted_tracked, FaceGroup, WeightedConfig,
};
use tetrefine_surface::doo_sabin::doo_sabin_tracked;
use tetrefine_surface::loop_scheme::loop_subdivide_tracked;
use tetrefine_surface::sierpinski::{sierpinski_tracked, SierpinskiOptions};
use tetrefine_surface::sqrt3::{sqrt3_tracked, FaceSelection, Sqrt3Options, Sqrt3Rule};
use tetrefine_surface::truncate::truncate_tracked;
use tetrefine_surface::{FaceAttributes, Features, PolyMesh, StepObserver};

/// How many faces have each value.
fn histogram(values: &[u32]) -> Vec<usize> {
    let n = values.iter().max().map_or(0, |&m| m as usize + 1);
    let mut h = vec![0; n];
    for &v in values {
        h[v as usize] += 1;
    }
    h
}

#[test]
fn loop_children_keep_their_parents_corner_and_count_4_to_the_k() {
    let ico = icosahedron();
    let nv = ico.points.len() as u32;
    let one = loop_subdivide_tracked(&ico, 1, &Features::default(), None).unwrap();
    let a = &one.attributes;
    for (i, f) in one.mesh.faces.iter().enumerate() {
        let parent = &ico.faces[a.origin[i] as usize];
        match a.group[i] {
            // Old vertices keep their ids: the corner child holds the
            // parent's corner g.
            g @ 0..=2 => assert!(f.contains(&parent[g as usize]), "face {i}"),
            3 => assert!(f.iter().all(|&v| v >= nv), "central face {i}"),
            g => panic!("group {g}"),
        }
    }
    for k in 1..=3u32 {
        let s = loop_subdivide_tracked(&ico, k as usize, &Features::default(), None).unwrap();
        let a = &s.attributes;
        assert_eq!(s.mesh.faces.len(), 20 * 4usize.pow(k));
        assert!(a.generation.iter().all(|&g| g == k));
        assert_eq!(histogram(&a.origin), vec![4usize.pow(k); 20]);
        assert_eq!(histogram(&a.group), vec![20 * 4usize.pow(k - 1); 4]);
    }
}

#[test]
fn catmull_clark_corner_quads_start_at_their_parents_corner() {
    let c = cube();
    let s = catmull_clark_tracked(&c, 1, &Features::default(), None).unwrap();
    let a = &s.attributes;
    assert_eq!(s.mesh.faces.len(), 24);
    for (i, f) in s.mesh.faces.iter().enumerate() {
        let parent = &c.faces[a.origin[i] as usize];
        assert_eq!(f[0], parent[a.group[i] as usize], "face {i}");
    }
    let s = catmull_clark_tracked(&c, 3, &Features::default(), None).unwrap();
    assert_eq!(histogram(&s.attributes.origin), vec![64; 6]);
    assert_eq!(histogram(&s.attributes.group), vec![96; 4]);
}

#[test]
fn observer_sees_every_generation_and_can_stop() {
    let ico = icosahedron();
    let mut seen: Vec<(usize, usize, FaceAttributes)> = Vec::new();
    let mut obs = |k: usize, m: &PolyMesh, a: &FaceAttributes| {
        seen.push((k, m.faces.len(), a.clone()));
        ControlFlow::Continue(())
    };
    let s = loop_subdivide_tracked(&ico, 3, &Features::default(), Some(&mut obs)).unwrap();
    assert_eq!(
        seen.iter().map(|x| (x.0, x.1)).collect::<Vec<_>>(),
        vec![(0, 20), (1, 80), (2, 320), (3, 1280)]
    );
    assert_eq!(seen[0].2, FaceAttributes::input(20));
    assert_eq!(seen[3].2, s.attributes);
    assert_eq!(s.steps, 3);
    // Stopping after the first step: one step done.
    let mut stop: Box<StepObserver> = Box::new(|k, _, _| {
        if k == 1 {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    });
    let s = loop_subdivide_tracked(&ico, 3, &Features::default(), Some(&mut *stop)).unwrap();
    assert_eq!((s.steps, s.mesh.faces.len()), (1, 80));
    // Every tracked scheme calls it once per generation.
    let count = |run: &mut dyn FnMut(&mut StepObserver) -> usize| {
        let mut gens = Vec::new();
        let mut obs = |k: usize, m: &PolyMesh, a: &FaceAttributes| {
            assert_eq!(a.len(), m.faces.len());
            gens.push(k);
            ControlFlow::Continue(())
        };
        let done = run(&mut obs);
        (gens, done)
    };
    let c = cube();
    let t = tetrahedron();
    let f = Features::default();
    let expect = (vec![0, 1, 2], 2);
    let opts = Sqrt3Options::default();
    assert_eq!(
        count(&mut |o| catmull_clark_tracked(&c, 2, &f, Some(o)).unwrap().steps),
        expect
    );
    assert_eq!(
        count(&mut |o| doo_sabin_tracked(&c, 2, Some(o)).unwrap().steps),
        expect
    );
    assert_eq!(
        count(&mut |o| truncate_tracked(&c, 2, 0.25, Some(o)).unwrap().steps),
        expect
    );
    assert_eq!(
        count(&mut |o| {
            sierpinski_tracked(&t, 2, &SierpinskiOptions::default(), Some(o))
                .unwrap()
                .steps
        }),
        expect
    );
    assert_eq!(
        count(&mut |o| {
            sqrt3_tracked(&ico, Sqrt3Rule::Approximating, 2, &opts, Some(o))
                .unwrap()
                .steps
        }),
        expect
    );
}

#[test]
fn doo_sabin_groups_follow_the_face_edge_vertex_counts() {
    // Cube: V 8, E 12, F 6. Step 1: 6 F-faces (generation 0), 12 E-faces,
    // 8 V-faces. The step-1 mesh has E' = 4E = 48 edges and V' = 2E = 24
    // vertices.
    let c = cube();
    let s = doo_sabin_tracked(&c, 1, None).unwrap();
    let a = &s.attributes;
    assert_eq!(histogram(&a.group), vec![6, 12, 8]);
    for i in 0..a.len() {
        assert_eq!(a.generation[i], (a.group[i] != 0) as u32, "face {i}");
    }
    // An F-face continues its face (generation and group kept), so step 2
    // adds 48 E-faces and 24 V-faces: groups 6, 12 + 48, 8 + 24;
    // generations 6, 20, 72.
    let s = doo_sabin_tracked(&c, 2, None).unwrap();
    let a = &s.attributes;
    assert_eq!(histogram(&a.group), vec![6, 60, 32]);
    assert_eq!(histogram(&a.generation), vec![6, 20, 72]);
}

#[test]
fn truncated_vertex_faces_descend_from_a_face_at_their_corner() {
    let c = cube();
    let s = truncate_tracked(&c, 1, 0.25, None).unwrap();
    let a = &s.attributes;
    assert_eq!(histogram(&a.group), vec![6, 8]);
    for (i, f) in s.mesh.faces.iter().enumerate() {
        let centroid = f.iter().map(|&v| s.mesh.points[v as usize]).sum::<DVec3>() / f.len() as f64;
        let origin = &c.faces[a.origin[i] as usize];
        if a.group[i] == 0 {
            // The shrunk face: same centroid as its input face.
            assert_eq!(a.generation[i], 0);
            let want =
                origin.iter().map(|&v| c.points[v as usize]).sum::<DVec3>() / origin.len() as f64;
            assert!(centroid.distance(want) < 1e-12, "face {i}");
        } else {
            // The corner cut off: its nearest cube corner is a corner of
            // the origin face.
            assert_eq!(a.generation[i], 1);
            let corner = (0..c.points.len() as u32)
                .min_by(|&p, &q| {
                    let d = |v: u32| c.points[v as usize].distance(centroid);
                    d(p).total_cmp(&d(q))
                })
                .unwrap();
            assert!(origin.contains(&corner), "face {i}");
        }
    }
    let s = truncate_tracked(&c, 3, 0.25, None).unwrap();
    // The input faces are never replaced; step k adds one face per vertex
    // of the mesh before it: V = 8, then V_1 = 2E = 24, V_2 = 6E = 72.
    assert_eq!(histogram(&s.attributes.generation), vec![6, 8, 24, 72]);
}

#[test]
fn sierpinski_groups_count_pieces_and_tubes() {
    // Tetrahedron, V = 4, E = 6: after k steps S = 2E·4^(k−1) corner
    // triangles, P = V + 2E(4^(k−1) − 1)/3 back faces and 3J tube quads,
    // J = E(4^k − 1)/3; J_1 = 6 joints were made by step 1, 24 by step 2.
    let t = tetrahedron();
    let s = sierpinski_tracked(&t, 2, &SierpinskiOptions::default(), None).unwrap();
    let a = &s.attributes;
    let (sum, pieces, joints) = (2 * 6 * 4, 4 + 2 * 6 * 3 / 3, 6 * 15 / 3);
    assert_eq!(histogram(&a.group), vec![sum, pieces, 3 * joints]);
    let tubes: Vec<u32> = (0..a.len())
        .filter(|&i| a.group[i] == 2)
        .map(|i| a.generation[i])
        .collect();
    assert_eq!(histogram(&tubes), vec![0, 3 * 6, 3 * 24]);
    assert!((0..a.len())
        .filter(|&i| a.group[i] != 2)
        .all(|i| a.generation[i] == 2));
    // After one step every corner triangle (cut at the joints) lies in the
    // plane of the input face it descends from.
    let s = sierpinski_tracked(&t, 1, &SierpinskiOptions::default(), None).unwrap();
    let a = &s.attributes;
    assert_eq!(histogram(&a.group), vec![12, 4, 18]);
    for (i, f) in s.mesh.faces.iter().enumerate() {
        if a.group[i] != 0 {
            continue;
        }
        let o = &t.faces[a.origin[i] as usize];
        let [p0, p1, p2] = [0, 1, 2].map(|k| t.points[o[k] as usize]);
        let n = (p1 - p0).cross(p2 - p0).normalize();
        for &v in f {
            let d = (s.mesh.points[v as usize] - p0).dot(n);
            assert!(d.abs() < 1e-12, "corner triangle {i}: {d}");
        }
    }
}

#[test]
fn unsplit_sqrt3_triangles_keep_their_attributes() {
    let ico = icosahedron();
    let opts = Sqrt3Options {
        features: Features::default(),
        selection: FaceSelection::Box {
            min: DVec3::new(0.0, -5.0, -5.0),
            max: DVec3::new(5.0, 5.0, 5.0),
        },
    };
    let s = sqrt3_tracked(&ico, Sqrt3Rule::Linear, 1, &opts, None).unwrap();
    let a = &s.attributes;
    let kept = a.generation.iter().filter(|&&g| g == 0).count();
    assert!(kept > 0 && kept < 20, "{kept}");
    // Split faces give 3 children each.
    assert_eq!(s.mesh.faces.len(), kept + 3 * (20 - kept));
    for (i, f) in s.mesh.faces.iter().enumerate() {
        let parent = &ico.faces[a.origin[i] as usize];
        if a.generation[i] == 0 {
            assert_eq!(f, parent, "face {i}");
        } else {
            assert!(a.group[i] < 3);
            assert!(!ico.faces.contains(f), "face {i}");
        }
    }
}

#[test]
fn weighted_groups_are_the_face_groups_plus_one() {
    let c = cube();
    let cfg = WeightedConfig {
        face_groups: vec![
            FaceGroup {
                faces: vec![1],
                weights: Default::default(),
            },
            FaceGroup {
                faces: vec![2, 4],
                weights: Default::default(),
            },
        ],
        ..Default::default()
    };
    let s = catmull_clark_weighted_tracked(&c, 2, &cfg, &Features::default(), None).unwrap();
    let a = &s.attributes;
    assert_eq!(histogram(&a.group), vec![3 * 16, 16, 2 * 16]);
    for i in 0..a.len() {
        let want = match a.origin[i] {
            1 => 1,
            2 | 4 => 2,
            _ => 0,
        };
        assert_eq!(a.group[i], want, "face {i}");
    }
}
