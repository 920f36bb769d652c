//! Sharp features and material regions survive refinement (issue: features).
//!
//! Independent figures: volumes of the input, planes of the input's boundary
//! faces, positions of the input's corners and feature segments, and the
//! feature count of an independent script on the tripod (294 edges at a
//! 67–71° normal deviation; DESIGN/issue text).

use glam::DVec3;
use std::collections::{BTreeMap, HashSet};
use std::path::Path;
use tetrefine::cube_grid;
use tetrefine::geom::{orient3d, tet_volume};
use tetrefine::io::load_mesh;
use tetrefine::{detect_features, detect_features_for, InterfaceRule};
use tetrefine::{locate_parents, refine, refine_step, RefineOptions, Sqrt3Rule};
use tetrefine::{MeshData, TetMesh, NO_ADJ};

fn load(name: &str) -> TetMesh {
    load_mesh(&Path::new("meshes").join(name)).unwrap().0
}

/// The centroid of tet `t` of `g`.
fn centroid_of(g: &MeshData, t: &[u32; 4]) -> DVec3 {
    t.iter()
        .map(|&v| DVec3::from_array(g.points[v as usize]))
        .sum::<DVec3>()
        / 4.0
}

/// An L-shaped block (the unit cube without the quarter x, y > 1/2) in two
/// regions (z below / above 1/2).
fn l_block() -> TetMesh {
    let g = cube_grid(4);
    let centroid = |t: &[u32; 4]| centroid_of(&g, t);
    let tets: Vec<[u32; 4]> = g
        .tets
        .iter()
        .copied()
        .filter(|t| {
            let c = centroid(t);
            !(c.x > 0.5 && c.y > 0.5)
        })
        .collect();
    let regions = tets
        .iter()
        .map(|t| if centroid(t).z < 0.5 { 1 } else { 2 })
        .collect();
    let data = MeshData {
        points: g.points.clone(),
        tets,
        tet_regions: regions,
        ..Default::default()
    };
    let (mut m, _) = TetMesh::from_data(&data).unwrap();
    m.compact();
    m
}

/// The unit cube (`cube_grid(4)`) in two regions: region 2 is the column
/// x, y > 1/2, so the interface bends by 90° along the interior line
/// x = y = 1/2 (a crease of the interface, from the bottom face to the top).
/// A second line, x = y = 1/4 inside region 1, is tagged by hand: a feature
/// line through the interior on no constrained face, ending on the boundary.
/// With `three`, the column x < 1/2 < y is region 3, and the first line is
/// where three regions meet instead.
fn block_with_interior_lines(three: bool) -> TetMesh {
    let g = cube_grid(4);
    let centroid = |t: &[u32; 4]| centroid_of(&g, t);
    let regions = g
        .tets
        .iter()
        .map(|t| {
            let c = centroid(t);
            if c.x > 0.5 && c.y > 0.5 {
                2
            } else if three && c.y > 0.5 {
                3
            } else {
                1
            }
        })
        .collect();
    let data = MeshData {
        tet_regions: regions,
        ..g
    };
    let (mut m, _) = TetMesh::from_data(&data).unwrap();
    // Point (i, j, k) of cube_grid(4) has id i + 5 (j + 5 k).
    let id = |i: u32, j: u32, k: u32| i + 5 * (j + 5 * k);
    for k in 0..4 {
        m.set_feature_edge(id(1, 1, k), id(1, 1, k + 1), Some(7));
    }
    m
}

fn region_volumes(m: &TetMesh) -> BTreeMap<i32, f64> {
    let mut v = BTreeMap::new();
    for t in m.tet_ids() {
        *v.entry(m.region(t)).or_insert(0.0) += tet_volume(&m.tet_points(t));
    }
    v
}

fn boundary_faces(m: &TetMesh) -> Vec<[DVec3; 3]> {
    m.tet_ids()
        .flat_map(|t| {
            (0..4)
                .filter(move |&f| m.is_boundary_face(t, f))
                .map(move |f| (t, f))
        })
        .map(|(t, f)| m.face_vertices(t, f).map(|v| m.point(v)))
        .collect()
}

/// Distinct planes (unit normal, offset) of the boundary faces.
fn planes(m: &TetMesh) -> Vec<(DVec3, f64)> {
    let mut out: Vec<(DVec3, f64)> = Vec::new();
    for f in boundary_faces(m) {
        let n = (f[1] - f[0]).cross(f[2] - f[0]).normalize();
        let d = n.dot(f[0]);
        if !out
            .iter()
            .any(|(m, e)| (*m - n).length() < 1e-9 && (e - d).abs() < 1e-9)
        {
            out.push((n, d));
        }
    }
    out
}

fn bits(p: DVec3) -> [u64; 3] {
    [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]
}

fn feature_segments(m: &TetMesh) -> Vec<[DVec3; 2]> {
    m.feature_edges()
        .keys()
        .map(|e| [m.point(e[0]), m.point(e[1])])
        .collect()
}

/// Two steps as one run (`--steps 2`: the second keeps the input's worst,
/// not the first step's, so it does not run again holding tets back; run
/// as two single steps, mmg_tinyBoxt's 5M-tet second step ran twice),
/// with `check()` after every phase.
fn two_steps(m: &mut TetMesh, rule: Sqrt3Rule) {
    let opts = RefineOptions {
        boundary: rule,
        check_each_phase: true,
        ..Default::default()
    };
    for r in refine(m, 2, &opts) {
        assert!(r.check_failures.is_empty(), "{:?}", r.check_failures);
    }
}

#[test]
fn piecewise_planar_domains_keep_volumes_planes_and_corners() {
    let cases: Vec<(&str, TetMesh)> = vec![
        ("mmg_cube", load("mmg_cube.mesh")),
        ("tetgen_example", load("tetgen_example.mesh")),
        ("l_block", l_block()),
    ];
    for (name, input) in cases {
        for rule in [Sqrt3Rule::Linear, Sqrt3Rule::Interpolating] {
            let mut m = input.clone();
            detect_features(&mut m, 45.0);
            let corners: Vec<DVec3> = m.corners().iter().map(|&v| m.point(v)).collect();
            assert!(!corners.is_empty(), "{name}");
            let vol0 = region_volumes(&m);
            let planes0 = planes(&m);
            let diag = {
                let b = m
                    .points()
                    .iter()
                    .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
                        (lo.min(*p), hi.max(*p))
                    });
                (b.1 - b.0).length()
            };
            two_steps(&mut m, rule);
            let vol = region_volumes(&m);
            assert_eq!(
                vol.keys().collect::<Vec<_>>(),
                vol0.keys().collect::<Vec<_>>(),
                "{name}"
            );
            let (t0, t1): (f64, f64) = (vol0.values().sum(), vol.values().sum());
            assert!(
                (t1 - t0).abs() <= 1e-9 * t0,
                "{name} {rule:?}: volume {t0} -> {t1}"
            );
            for (r, v0) in &vol0 {
                assert!(
                    (vol[r] - v0).abs() <= 1e-9 * v0,
                    "{name} {rule:?} region {r}: {v0} -> {}",
                    vol[r]
                );
            }
            // Every output boundary face lies in one input facet plane.
            for f in boundary_faces(&m) {
                let on = planes0
                    .iter()
                    .any(|(n, d)| f.iter().all(|p| (n.dot(*p) - d).abs() <= 1e-9 * diag));
                assert!(
                    on,
                    "{name} {rule:?}: boundary face {f:?} left the input planes"
                );
            }
            let out: HashSet<[u64; 3]> = m.points().iter().map(|&p| bits(p)).collect();
            for c in &corners {
                assert!(out.contains(&bits(*c)), "{name} {rule:?}: corner {c} moved");
            }
        }
    }
}

#[test]
fn feature_edges_are_kept_in_step_1_and_trisected_in_step_2() {
    for (name, input) in [
        ("mmg_cube", load("mmg_cube.mesh")),
        ("l_block", l_block()),
        ("block, interface crease", block_with_interior_lines(false)),
        ("block, three regions", block_with_interior_lines(true)),
    ] {
        let mut m = input.clone();
        detect_features(&mut m, 45.0);
        let segs0 = feature_segments(&m);
        if name.starts_with("block") {
            // Both interior lines are features: 4 segments each.
            for c in [0.25, 0.5] {
                let on = |p: &DVec3| p.x == c && p.y == c;
                let n = segs0.iter().filter(|s| s.iter().all(on)).count();
                assert_eq!(n, 4, "{name}: line x = y = {c}");
            }
        }
        let key = |s: &[DVec3; 2]| {
            let (a, b) = (bits(s[0]), bits(s[1]));
            if a < b {
                (a, b)
            } else {
                (b, a)
            }
        };
        let set0: HashSet<_> = segs0.iter().map(key).collect();
        // The crease rule of the step itself: `fast` keeps the optimize
        // phase from sliding feature-line vertices along their lines.
        let opts = RefineOptions {
            boundary: Sqrt3Rule::Linear,
            effort: tetrefine::Effort::Fast,
            ..Default::default()
        };
        refine_step(&mut m, 1, &opts);
        let set1: HashSet<_> = feature_segments(&m).iter().map(key).collect();
        assert_eq!(
            set1, set0,
            "{name}: step 1 must keep the feature edges as they are"
        );
        refine_step(&mut m, 2, &opts);
        let segs2 = feature_segments(&m);
        assert_eq!(segs2.len(), 3 * segs0.len(), "{name}");
        // Each output piece lies on one input segment and is a third of it;
        // each input segment carries exactly three pieces.
        let mut pieces = vec![0usize; segs0.len()];
        for s in &segs2 {
            let i = segs0
                .iter()
                .position(|[a, b]| {
                    let ab = *b - *a;
                    let l = ab.length();
                    s.iter().all(|p| {
                        let t = (*p - *a).dot(ab) / (l * l);
                        (-1e-12..=1.0 + 1e-12).contains(&t)
                            && (*p - (*a + ab * t)).length() <= 1e-12 * l
                    }) && ((s[1] - s[0]).length() - l / 3.0).abs() <= 1e-12 * l
                })
                .unwrap_or_else(|| panic!("{name}: feature piece {s:?} is on no input segment"));
            pieces[i] += 1;
        }
        assert!(pieces.iter().all(|&n| n == 3), "{name}: {pieces:?}");
    }
}

/// Area of the faces between each pair of regions.
fn interface_areas(m: &TetMesh) -> BTreeMap<(i32, i32), f64> {
    let mut out = BTreeMap::new();
    for t in m.tet_ids() {
        for (f, &h) in m.adj(t).iter().enumerate() {
            if h == NO_ADJ {
                continue;
            }
            let (r0, r1) = (m.region(t), m.region(h >> 2));
            if r0 < r1 {
                let p = m.face_vertices(t, f).map(|v| m.point(v));
                *out.entry((r0, r1)).or_insert(0.0) +=
                    0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
            }
        }
    }
    out
}

#[test]
fn multi_region_meshes_keep_every_region() {
    for name in ["gmsh_t16.mesh", "mmg_tinyBoxt.mesh", "tetgen_example.mesh"] {
        let mut input = load(name);
        detect_features(&mut input, 45.0);
        let vol0 = region_volumes(&input);
        let area0 = interface_areas(&input);
        assert!(vol0.len() >= 2 && !area0.is_empty(), "{name}");
        let mut m = input.clone();
        two_steps(&mut m, Sqrt3Rule::Linear);
        let vol = region_volumes(&m);
        for (r, v0) in &vol0 {
            assert!((vol[r] - v0).abs() <= 1e-9 * v0, "{name} region {r}");
        }
        // A flipped two-region face would move area between interfaces.
        let area = interface_areas(&m);
        assert_eq!(
            area.keys().collect::<Vec<_>>(),
            area0.keys().collect::<Vec<_>>(),
            "{name}"
        );
        for (k, a0) in &area0 {
            assert!(
                (area[k] - a0).abs() <= 1e-9 * a0,
                "{name} interface {k:?}: {a0} -> {}",
                area[k]
            );
        }
        // Each output tet's centroid lies in an input tet of its own region.
        locate_parents(&input, &mut m);
        for t in m.tet_ids() {
            let p = m.tet_points(t);
            let c = (p[0] + p[1] + p[2] + p[3]) / 4.0;
            let parent = m.parent(t);
            let q = input.tet_points(parent);
            let inside = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]]
                .iter()
                .all(|l| orient3d(q[l[0]], q[l[1]], q[l[2]], c) <= 0.0);
            assert!(
                inside,
                "{name}: centroid of tet {t} not inside any input tet"
            );
            assert_eq!(input.region(parent), m.region(t), "{name}: tet {t}");
        }
        // The per-region tet counts are reported.
        let s = tetrefine::MeshStats::compute(&m);
        assert_eq!(s.regions.len(), vol0.len());
        assert_eq!(s.regions.values().sum::<usize>(), s.tets);
    }
}

#[test]
fn tripod_features_match_the_independent_count_and_stay_put() {
    for angle in [67.0, 69.0, 71.0] {
        let mut m = load("tripod.mesh");
        let r = detect_features(&mut m, angle);
        assert_eq!(r.feature_edges, 294, "at {angle}°: {r:?}");
    }
    let mut m = load("tripod.mesh");
    detect_features(&mut m, 69.0);
    // The input's feature polyline and corners, before any step.
    let polyline = feature_segments(&m);
    let corners: Vec<DVec3> = m.corners().iter().map(|&v| m.point(v)).collect();
    assert!(!corners.is_empty());
    let (lo, hi) = m.tet_ids().flat_map(|t| m.tet_points(t)).fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    );
    let diag = (hi - lo).length();
    let shortest = m
        .tet_ids()
        .flat_map(|t| {
            let p = m.tet_points(t);
            [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)].map(|(i, j)| (p[i] - p[j]).length())
        })
        .fold(f64::INFINITY, f64::min);
    assert!(
        1e-10 * diag < 1e-6 * shortest,
        "diag {diag}, shortest edge {shortest}"
    );
    two_steps(&mut m, Sqrt3Rule::Interpolating);
    // Feature edges are kept in step 1 and trisected in step 2: 3 × 294,
    // and more where the long-edge round split a long feature edge (one
    // segment more each). Whatever the count, the segments cover the input
    // polyline exactly once: their lengths add up to its length (a segment
    // cutting a bend of the line would be shorter, one off the line longer
    // or shorter), to rounding of a few ulps per segment.
    let n = m.feature_edges().len();
    assert!(n >= 3 * 294, "{n} feature edges after two steps");
    let length =
        |segments: &[[DVec3; 2]]| -> f64 { segments.iter().map(|s| (s[1] - s[0]).length()).sum() };
    let (before, after) = (length(&polyline), length(&feature_segments(&m)));
    assert!(
        (after - before).abs() <= 1e-9 * before,
        "feature lines of length {after} after two steps, {before} before"
    );
    // Feature-line vertices may slide (boundary smoothing moves them along
    // their line), but only along the input polyline. Every such point is
    // computed as a + s·(b − a) from the input's endpoints (trisection and
    // the projection of a slide), which rounds by a few ulps of the
    // coordinates (|x| ≤ diag, ulp ≈ 2.2e-16·diag); 1e-10·diag leaves a
    // margin of about a million over that and is still far below the
    // shortest input edge (checked below), so a point that left its line by
    // any visible amount fails.
    let tol = 1e-10 * diag;
    let dist = |p: DVec3| {
        polyline
            .iter()
            .map(|s| {
                let d = s[1] - s[0];
                let u = ((p - s[0]).dot(d) / d.length_squared()).clamp(0.0, 1.0);
                (p - (s[0] + u * d)).length()
            })
            .fold(f64::INFINITY, f64::min)
    };
    for e in m.feature_edges().keys() {
        for &v in e {
            let p = m.point(v);
            let d = dist(p);
            assert!(
                d <= tol,
                "feature vertex {v} at {p} is {d:e} off the input polyline (tol {tol:e})"
            );
        }
    }
    // Corners never move: each input corner is still a corner, bit for bit.
    let out_corners: HashSet<[u64; 3]> = m.corners().iter().map(|&v| bits(m.point(v))).collect();
    assert_eq!(m.corners().len(), corners.len());
    for p in corners {
        assert!(out_corners.contains(&bits(p)), "corner {p} moved");
    }
}

/// Mean distance to its true sphere of the interface vertices of each of
/// gmsh_t16's five spherical inclusions (regions 1–5: centre
/// (0.166 k, 0.75, 0.166 k), radius 0.09, from the `t16.geo` the mesh was
/// made from), with each inclusion's volume.
fn inclusions(m: &TetMesh) -> Vec<(f64, f64)> {
    let vol = region_volumes(m);
    (1..=5)
        .map(|k| {
            let mut on: HashSet<u32> = HashSet::new();
            for t in m.tet_ids().filter(|&t| m.region(t) == k) {
                for (f, &h) in m.adj(t).iter().enumerate() {
                    if h != NO_ADJ && m.region(h >> 2) != k {
                        on.extend(m.face_vertices(t, f));
                    }
                }
            }
            assert!(on.len() >= 60, "sphere {k}: {} points", on.len());
            let c = DVec3::new(0.166 * k as f64, 0.75, 0.166 * k as f64);
            let mean = on
                .iter()
                .map(|&v| ((m.point(v) - c).length() - 0.09).abs())
                .sum::<f64>()
                / on.len() as f64;
            (mean, vol[&k])
        })
        .collect()
}

/// Issue 20: `--interfaces sqrt3` refines gmsh_t16's spherical inclusions as
/// smooth surfaces: after two steps their points are closer to the true
/// spheres than with the linear rule, each inclusion's volume moves from the
/// inscribed polyhedron's towards the ball's without passing it (the
/// README's tolerance), the domain's volume is exact (its boundary is
/// planar), no tet is inverted and the worst angle is at least the input's.
#[test]
fn sqrt3_interfaces_bring_curved_inclusions_closer_to_their_spheres() {
    let input = load("gmsh_t16.mesh");
    let before = tetrefine::MeshStats::compute(&input);
    let ball = 4.0 / 3.0 * std::f64::consts::PI * 0.09f64.powi(3);
    let refined = |rule: InterfaceRule| {
        let mut m = input.clone();
        detect_features_for(&mut m, 45.0, rule);
        let opts = RefineOptions {
            interfaces: rule,
            ..Default::default()
        };
        refine(&mut m, 2, &opts);
        m.check().unwrap();
        let s = tetrefine::MeshStats::compute(&m);
        assert_eq!(s.inverted, 0, "{rule:?}");
        assert!(
            s.min_dihedral_deg.worst >= before.min_dihedral_deg.worst,
            "{rule:?}: worst {} < input {}",
            s.min_dihedral_deg.worst,
            before.min_dihedral_deg.worst
        );
        assert!(
            (s.volume - before.volume).abs() <= 1e-12 * before.volume,
            "{rule:?}: domain volume {} -> {}",
            before.volume,
            s.volume
        );
        inclusions(&m)
    };
    let start = inclusions(&input);
    let linear = refined(InterfaceRule::Linear);
    let smooth = refined(InterfaceRule::Sqrt3);
    for k in 0..5 {
        let (v0, (dl, vl), (ds, vs)) = (start[k].1, linear[k], smooth[k]);
        assert!(v0 < 0.95 * ball, "sphere {k}: the input is faceted");
        assert!((vl - v0).abs() <= 1e-12 * v0, "sphere {k}: linear volume");
        assert!(
            ds < 0.5 * dl,
            "sphere {k}: sqrt3 mean distance {ds:e} not below half of linear's {dl:e}"
        );
        assert!(
            v0 < vs && vs <= ball,
            "sphere {k}: volume {v0} -> {vs}, ball {ball}"
        );
    }
}
