//! `tetrefine surface`: each scheme end to end on a file, and bad input
//! refused with a one-line error, a non-zero exit and no output file.

use crate::shapes::*;
use glam::DVec3;
use std::path::Path;
use tetrefine_surface::{load_surface, write_surface};

/// [`crate::run`] as (success, stderr): what these tests look at.
fn run(args: &[&str]) -> (bool, String) {
    let out = crate::run(args);
    (out.status.success(), crate::stderr(&out))
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn every_scheme_writes_the_expected_counts() {
    let dir = tempfile::tempdir().unwrap();
    let tri = dir.path().join("ico.obj");
    let quad = dir.path().join("cube.off");
    write_surface(&tri, &icosahedron()).unwrap();
    write_surface(&quad, &cube()).unwrap();
    let weights = dir.path().join("w.json");
    std::fs::write(&weights, r#"{"iterations": [{"face_extrude": 0.1}]}"#).unwrap();
    // (scheme, input, steps, extra args, faces expected)
    let cases: Vec<(&str, &Path, usize, Vec<&str>, usize)> = vec![
        ("sqrt3", &tri, 2, vec![], 20 * 9),
        ("sqrt3-interp", &tri, 2, vec![], 20 * 9),
        ("sqrt3-linear", &tri, 1, vec![], 60),
        ("loop", &tri, 2, vec![], 20 * 16),
        ("catmull-clark", &quad, 2, vec![], 6 * 16),
        ("doo-sabin", &quad, 1, vec![], 26),
        (
            "catmull-clark-weighted",
            &quad,
            2,
            vec!["--weights", s(&weights)],
            6 * 16,
        ),
    ];
    for (scheme, input, steps, extra, faces) in cases {
        for ext in ["obj", "ply"] {
            let out = dir.path().join(format!("{scheme}.{ext}"));
            let steps = steps.to_string();
            let mut args = vec![
                "surface",
                scheme,
                s(input),
                "-o",
                s(&out),
                "--steps",
                &steps,
            ];
            args.extend(extra.iter());
            let (ok, err) = run(&args);
            assert!(ok, "{scheme}: {err}");
            let m = load_surface(&out).unwrap();
            assert_eq!(m.faces.len(), faces, "{scheme}");
            assert_eq!(m.euler_characteristic(), 2, "{scheme}");
        }
    }
    // Adaptive √3 with a selection box touching part of the surface.
    let out = dir.path().join("adaptive.vtp");
    let (ok, err) = run(&[
        "surface",
        "sqrt3",
        s(&tri),
        "-o",
        s(&out),
        "--select-box",
        "0,-5,-5,5,5,5",
    ]);
    assert!(ok, "{err}");
    assert!(out.exists());
}

#[test]
fn bad_input_fails_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let quad = dir.path().join("cube.obj");
    write_surface(&quad, &cube()).unwrap();
    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
    let out = dir.path().join("out.obj");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["surface", "loop", s(&quad), "-o", s(&out)],
            "triangle mesh",
        ),
        (
            vec!["surface", "sqrt3", s(&bad), "-o", s(&out)],
            "bad.obj:4:",
        ),
        (
            vec![
                "surface",
                "catmull-clark",
                s(&quad),
                "-o",
                s(&out),
                "--crease",
                "0-7",
            ],
            "not an edge",
        ),
        (
            vec![
                "surface",
                "catmull-clark",
                s(&quad),
                "-o",
                s(&out),
                "--crease",
                "0x1",
            ],
            "A-B",
        ),
        (
            vec![
                "surface",
                "doo-sabin",
                s(&quad),
                "-o",
                s(&out),
                "--corner",
                "1",
            ],
            "does not support",
        ),
        (
            vec![
                "surface",
                "loop",
                s(&quad),
                "-o",
                s(&out),
                "--weights",
                "w.json",
            ],
            "--weights",
        ),
        (
            vec![
                "surface",
                "catmull-clark",
                s(&quad),
                "-o",
                s(&out),
                "--steps",
                "40",
            ],
            "fewer steps",
        ),
        (
            vec!["surface", "catmull-clark", s(&quad), "-o", "out.3ds"],
            "'.3ds'",
        ),
    ];
    for (args, needle) in cases {
        fails_cleanly(&args, needle, &out);
    }
}

/// Runs `tetrefine` and asserts a clean failure: non-zero exit, one line on
/// stderr containing `needle`, and no output file.
fn fails_cleanly(args: &[&str], needle: &str, out: &Path) {
    let (ok, err) = run(args);
    assert!(!ok, "{args:?} succeeded");
    assert!(err.contains(needle), "{args:?}: {err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(!out.exists(), "{args:?} left {}", out.display());
}

/// Topology of a polygon mesh, counted here without the crate's adjacency:
/// every undirected edge must lie in exactly two faces that run along it in
/// opposite directions (closed and consistently oriented); faces are joined
/// through shared edges by union–find.
struct ClosedTopology {
    vertices: i64,
    edges: i64,
    faces: i64,
    components: usize,
}

impl ClosedTopology {
    fn of(m: &tetrefine_surface::PolyMesh) -> ClosedTopology {
        use std::collections::{HashMap, HashSet};
        let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
        for (f, face) in m.faces.iter().enumerate() {
            for k in 0..face.len() {
                let d = (face[k], face[(k + 1) % face.len()]);
                assert!(directed.insert(d, f).is_none(), "directed edge {d:?} twice");
            }
        }
        let mut parent: Vec<usize> = (0..m.faces.len()).collect();
        fn root(parent: &mut [usize], mut x: usize) -> usize {
            while parent[x] != x {
                parent[x] = parent[parent[x]];
                x = parent[x];
            }
            x
        }
        for (&(a, b), &f) in &directed {
            let g = *directed
                .get(&(b, a))
                .unwrap_or_else(|| panic!("edge {a}->{b} has no opposite: open or misoriented"));
            let (rf, rg) = (root(&mut parent, f), root(&mut parent, g));
            parent[rf] = rg;
        }
        let components = (0..m.faces.len())
            .filter(|&f| root(&mut parent, f) == f)
            .count();
        let used: HashSet<u32> = m.faces.iter().flatten().copied().collect();
        ClosedTopology {
            vertices: used.len() as i64,
            edges: directed.len() as i64 / 2,
            faces: m.faces.len() as i64,
            components,
        }
    }

    fn euler(&self) -> i64 {
        self.vertices - self.edges + self.faces
    }
}

#[test]
fn sierpinski_writes_one_closed_surface_of_the_stated_genus() {
    let dir = tempfile::tempdir().unwrap();
    // (name, mesh, V, E, genus after steps 1 and 2 from the paper's counts:
    // k corner pieces joined at E midpoints give genus E − pieces + 1, then
    // g_k = 1 − V + E(4^k + 2)/6).
    let shapes = [
        ("tetrahedron", tetrahedron(), 4, 6, [3, 15]),
        ("cube", cube(), 8, 12, [5, 29]),
        ("octahedron", octahedron(), 6, 12, [7, 31]),
    ];
    for (name, mesh, v, e, genus) in shapes {
        let input = dir.path().join(format!("{name}.obj"));
        write_surface(&input, &mesh).unwrap();
        for k in 1..=2u32 {
            let out = dir.path().join(format!("{name}-s{k}.obj"));
            let steps = k.to_string();
            let (ok, err) = run(&[
                "surface",
                "sierpinski",
                s(&input),
                "-o",
                s(&out),
                "--steps",
                &steps,
                "--neck",
                "0.1",
            ]);
            assert!(ok, "{name}: {err}");
            let t = ClosedTopology::of(&load_surface(&out).unwrap());
            assert_eq!(t.components, 1, "{name}, {k} steps: one surface");
            let g = 1 - t.euler() / 2;
            assert_eq!(g, genus[k as usize - 1], "{name}, {k} steps: genus");
            assert_eq!(g, 1 - v + e * (4i64.pow(k) + 2) / 6);
            // Pieces, joints and apex valence sum from the construction:
            // every joint is a tube of 3 quads with 4 vertices' worth of cuts.
            let q = 4i64.pow(k - 1);
            let sum = 2 * e * q;
            let pieces = v + 2 * e * (q - 1) / 3;
            let joints = e * (4 * q - 1) / 3;
            assert_eq!(t.vertices, sum + pieces + 4 * joints, "{name}, {k}: V");
            assert_eq!(t.edges, 2 * sum + 9 * joints, "{name}, {k}: E");
            assert_eq!(t.faces, sum + pieces + 3 * joints, "{name}, {k}: F");
        }
    }
}

#[test]
fn truncate_makes_every_vertex_3_valent_with_the_closed_form_counts() {
    let dir = tempfile::tempdir().unwrap();
    for (name, mesh) in [("cube", cube()), ("octahedron", octahedron())] {
        let input = dir.path().join(format!("{name}.off"));
        write_surface(&input, &mesh).unwrap();
        let t0 = ClosedTopology::of(&mesh);
        for k in 1..=3u32 {
            let out = dir.path().join(format!("{name}-t{k}.ply"));
            let steps = k.to_string();
            let (ok, err) = run(&[
                "surface",
                "truncate",
                s(&input),
                "-o",
                s(&out),
                "--steps",
                &steps,
            ]);
            assert!(ok, "{name}: {err}");
            let m = load_surface(&out).unwrap();
            let t = ClosedTopology::of(&m);
            // E_k = 3^k E, V_k = 2·3^(k−1) E, F_k = F + V + (3^(k−1) − 1) E.
            let p = 3i64.pow(k - 1);
            assert_eq!(t.edges, 3 * p * t0.edges, "{name}, {k}: E");
            assert_eq!(t.vertices, 2 * p * t0.edges, "{name}, {k}: V");
            assert_eq!(
                t.faces,
                t0.faces + t0.vertices + (p - 1) * t0.edges,
                "{name}, {k}: F"
            );
            let mut valence = vec![0; m.points.len()];
            for [a, b] in m.edge_list() {
                valence[a as usize] += 1;
                valence[b as usize] += 1;
            }
            assert!(valence.iter().all(|&d| d == 3), "{name}, {k}: 3-valent");
        }
    }
    // --cut 0.1: every new point lies at 1/10 or 9/10 of an input edge.
    let input = dir.path().join("cube.off");
    let out = dir.path().join("cube-cut.obj");
    let (ok, err) = run(&[
        "surface",
        "truncate",
        s(&input),
        "-o",
        s(&out),
        "--cut",
        "0.1",
    ]);
    assert!(ok, "{err}");
    let m = load_surface(&out).unwrap();
    let c = cube();
    for p in &m.points {
        let on_cut = c.edge_list().iter().any(|&[a, b]| {
            let (pa, pb) = (c.points[a as usize], c.points[b as usize]);
            [0.1, 0.9]
                .iter()
                .any(|&t| p.distance(pa + t * (pb - pa)) < 1e-12)
        });
        assert!(on_cut, "{p} is not a 1/10 point of a cube edge");
    }
}

/// The polylines of a CSV written by `surface ifs`.
fn read_polylines_csv(path: &Path) -> Vec<Vec<DVec3>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("polyline,point,x,y,z"));
    let mut out: Vec<Vec<DVec3>> = Vec::new();
    for row in lines {
        let f: Vec<&str> = row.split(',').collect();
        let (l, i): (usize, usize) = (f[0].parse().unwrap(), f[1].parse().unwrap());
        if l == out.len() {
            out.push(Vec::new());
        }
        assert_eq!((l + 1, i), (out.len(), out[l].len()), "rows in order");
        let x: Vec<f64> = f[2..5].iter().map(|t| t.parse().unwrap()).collect();
        out[l].push(DVec3::new(x[0], x[1], x[2]));
    }
    out
}

/// The value of `attr="N"` in the first line of a `.vtp` that has it.
fn vtp_count(text: &str, attr: &str) -> usize {
    let key = format!("{attr}=\"");
    let start = text.find(&key).unwrap() + key.len();
    let end = start + text[start..].find('"').unwrap();
    text[start..end].parse().unwrap()
}

fn close(a: DVec3, b: DVec3) -> bool {
    a.distance(b) < 1e-12
}

#[test]
fn ifs_writes_koch_and_gasket_from_the_builtin_controls() {
    let dir = tempfile::tempdir().unwrap();
    // Koch curve: the k-th Koch polygon has 4^k segments of length 3^-k from
    // (0,0) to (1,0).
    let k = 4;
    let out = dir.path().join("koch.csv");
    let (ok, err) = run(&[
        "surface",
        "ifs",
        "-o",
        s(&out),
        "--kind",
        "koch",
        "--iterations",
        "4",
    ]);
    assert!(ok, "{err}");
    let lines = read_polylines_csv(&out);
    assert_eq!(lines.len(), 1);
    let koch = &lines[0];
    assert_eq!(koch.len(), 4usize.pow(k) + 1);
    assert!(close(koch[0], DVec3::ZERO), "{}", koch[0]);
    assert!(close(koch[koch.len() - 1], DVec3::X));
    for w in koch.windows(2) {
        let len = w[0].distance(w[1]);
        assert!((len - 3f64.powi(-(k as i32))).abs() < 1e-12, "{len}");
    }
    // The same in .vtp: one Lines cell over 4^k + 1 points.
    let vtp = dir.path().join("koch.vtp");
    let (ok, err) = run(&[
        "surface",
        "ifs",
        "-o",
        s(&vtp),
        "--kind",
        "koch",
        "--steps",
        "4",
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&vtp).unwrap();
    assert_eq!(vtp_count(&text, "NumberOfPoints"), 4usize.pow(k) + 1);
    assert_eq!(vtp_count(&text, "NumberOfLines"), 1);
    assert_eq!(vtp_count(&text, "NumberOfVerts"), 0);
    // Sierpinski gasket: 3^k closed triangles of side 2^-k.
    let out = dir.path().join("gasket.csv");
    let (ok, err) = run(&[
        "surface",
        "ifs",
        "-o",
        s(&out),
        "--kind",
        "gasket",
        "--steps",
        "3",
    ]);
    assert!(ok, "{err}");
    let tris = read_polylines_csv(&out);
    assert_eq!(tris.len(), 27);
    for t in &tris {
        assert_eq!(t.len(), 4);
        assert!(close(t[0], t[3]), "closed");
        for w in t.windows(2) {
            assert!((w[0].distance(w[1]) - 0.125).abs() < 1e-12);
        }
    }
}

#[test]
fn ifs_curves_and_patches_from_input_control_points() {
    let dir = tempfile::tempdir().unwrap();
    let write_points = |name: &str, pts: &[DVec3]| {
        let path = dir.path().join(name);
        let text: String = pts
            .iter()
            .map(|p| format!("v {} {} {}\n", p.x, p.y, p.z))
            .collect();
        std::fs::write(&path, text).unwrap();
        path
    };
    let p: Vec<DVec3> = [
        (0.0, 0.0, 0.0),
        (1.0, 2.0, 0.5),
        (2.5, -1.0, 1.0),
        (3.0, 1.5, -0.5),
        (4.5, 0.0, 0.0),
        (5.0, 2.0, 1.0),
        (6.5, -0.5, 0.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z))
    .collect();
    // Cubic B-spline on 5 points: two uniform pieces from knot 1 to knot 3;
    // the polyline has 2^k + 1 points, with the knot values
    // (p_(i−1) + 4 p_i + p_(i+1))/6 at its ends and middle.
    let spline = write_points("spline.obj", &p[..5]);
    let out = dir.path().join("spline.csv");
    let (ok, err) = run(&[
        "surface",
        "ifs",
        s(&spline),
        "-o",
        s(&out),
        "--kind",
        "cubic-bspline",
        "--steps",
        "5",
    ]);
    assert!(ok, "{err}");
    let line = &read_polylines_csv(&out)[0];
    assert_eq!(line.len(), 33);
    let knot = |i: usize| (p[i - 1] + 4.0 * p[i] + p[i + 1]) / 6.0;
    assert!(close(line[0], knot(1)), "{} vs {}", line[0], knot(1));
    assert!(close(line[16], knot(2)));
    assert!(close(line[32], knot(3)));
    // Four-point scheme on 7 points: the attractor runs from p_2 to p_4 and,
    // the scheme being interpolating, passes through p_3 half way.
    let four = write_points("four.obj", &p);
    let out = dir.path().join("four.vtp");
    let (ok, err) = run(&[
        "surface",
        "ifs",
        s(&four),
        "-o",
        s(&out),
        "--kind",
        "four-point",
        "--steps",
        "3",
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(vtp_count(&text, "NumberOfPoints"), 9);
    assert_eq!(vtp_count(&text, "NumberOfLines"), 1);
    let csv = dir.path().join("four.csv");
    let (ok, err) = run(&[
        "surface",
        "ifs",
        s(&four),
        "-o",
        s(&csv),
        "--kind",
        "four-point",
        "--steps",
        "3",
    ]);
    assert!(ok, "{err}");
    let line = &read_polylines_csv(&csv)[0];
    assert_eq!(line.len(), 9);
    assert!(close(line[0], p[2]) && close(line[4], p[3]) && close(line[8], p[4]));
    // Bicubic 4 × 4 patch: a triangle mesh on the (2^k + 1)² grid of patch
    // points, two triangles per grid square; the corner (0,0) is
    // Σ (1,4,1)ᵢ(1,4,1)ⱼ/36 over the first 3 × 3 control points.
    let grid: Vec<DVec3> = (0..16)
        .map(|i| {
            let (u, v) = ((i / 4) as f64, (i % 4) as f64);
            DVec3::new(u, v, (u * v).sin())
        })
        .collect();
    let patch = write_points("patch.obj", &grid);
    let out = dir.path().join("patch_out.obj");
    let (ok, err) = run(&[
        "surface",
        "ifs",
        s(&patch),
        "-o",
        s(&out),
        "--kind",
        "bicubic",
        "--grid",
        "4,4",
        "--steps",
        "2",
    ]);
    assert!(ok, "{err}");
    let mesh = load_surface(&out).unwrap();
    assert_eq!(mesh.points.len(), 25);
    assert_eq!(mesh.faces.len(), 32);
    assert!(mesh.faces.iter().all(|f| f.len() == 3));
    let w = [1.0, 4.0, 1.0];
    let corner: DVec3 = (0..3)
        .flat_map(|a| (0..3).map(move |b| (a, b)))
        .map(|(a, b)| grid[a * 4 + b] * w[a] * w[b] / 36.0)
        .sum();
    assert!(
        mesh.points.iter().any(|&x| close(x, corner)),
        "corner {corner} missing"
    );
}

/// The regular triangular net of `surface ifs --kind loop` (12 points) or
/// `sqrt3` (27 points), lattice point (i, j) at i e1 + j e2, lifted by a
/// bump: the order of the README (corners of the patch triangle first, then
/// by distance from it, then by j, then by i).
fn triangle_net_file(dir: &Path, name: &str, radius: i64) -> std::path::PathBuf {
    let hex = |i: i64, j: i64| (i.abs() + j.abs() + (i + j).abs()) / 2;
    let corners = [(0, 0), (1, 0), (0, 1)];
    let mut pts = Vec::new();
    for j in -4..=4i64 {
        for i in -4..=4i64 {
            let d = corners
                .iter()
                .map(|&(a, b)| hex(i - a, j - b))
                .min()
                .unwrap();
            if d <= radius {
                let c = corners.iter().position(|&q| q == (i, j)).unwrap_or(3);
                pts.push((d, c, j, i));
            }
        }
    }
    pts.sort();
    let text: String = pts
        .iter()
        .map(|&(_, _, j, i)| {
            let (x, y) = (i as f64 + 0.5 * j as f64, 0.75f64.sqrt() * j as f64);
            format!(
                "v {x} {y} {}\n",
                0.5 * (-(x - 0.5).powi(2) - (y - 0.3).powi(2)).exp()
            )
        })
        .collect();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// `element NAME N` from a binary or ASCII PLY header.
fn ply_count(path: &Path, element: &str) -> usize {
    let bytes = std::fs::read(path).unwrap();
    let end = bytes.windows(10).position(|w| w == b"end_header").unwrap();
    let header = String::from_utf8_lossy(&bytes[..end]).into_owned();
    let key = format!("element {element} ");
    let line = header.lines().find(|l| l.starts_with(&key)).unwrap();
    line[key.len()..].trim().parse().unwrap()
}

#[test]
fn ifs_loop_sqrt3_surfaces_map_subsets_and_start_sets() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = |name: &str| d.join(name);
    // Loop, builtin planar net, 3 steps: (2^3+1)(2^3+2)/2 = 45 vertices and
    // 4^3 triangles, the patch triangle itself (z = 0).
    let o = out("loop.obj");
    let (ok, err) = run(&[
        "surface",
        "ifs",
        "-o",
        s(&o),
        "--kind",
        "loop",
        "--steps",
        "3",
    ]);
    assert!(ok, "{err}");
    let m = load_surface(&o).unwrap();
    assert_eq!((m.points.len(), m.faces.len()), (45, 64));
    assert!(m.points.iter().all(|p| p.z == 0.0));
    // √3 from a bumpy 27-point net, 2 steps: (9+1)(9+2)/2 = 55 vertices, 81
    // triangles, binary PLY.
    let net = triangle_net_file(d, "net27.obj", 2);
    let o = out("sqrt3.ply");
    let (ok, err) = run(&[
        "surface",
        "ifs",
        s(&net),
        "-o",
        s(&o),
        "--kind",
        "sqrt3",
        "--steps",
        "2",
    ]);
    assert!(ok, "{err}");
    assert_eq!((ply_count(&o, "vertex"), ply_count(&o, "face")), (55, 81));
    // Loop with the three corner maps: a gasket on the surface, 3^4
    // triangles on (3^5 + 3)/2 = 123 vertices, in .vtp.
    let net12 = triangle_net_file(d, "net12.obj", 1);
    let o = out("gasket.vtp");
    let (ok, err) = run(&[
        "surface",
        "ifs",
        s(&net12),
        "-o",
        s(&o),
        "--kind",
        "loop",
        "--maps",
        "0,1,2",
        "--steps",
        "4",
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&o).unwrap();
    assert_eq!(vtp_count(&text, "NumberOfPoints"), 123);
    assert_eq!(vtp_count(&text, "NumberOfPolys"), 81);
    // Clamped B-spline and Bézier: start at the first control point, end at
    // the last, 2^k + 1 points.
    let curve: Vec<String> = [
        (0.0, 0.0, 0.0),
        (1.0, 2.0, 0.0),
        (3.0, 2.0, 1.0),
        (4.0, 0.0, 0.0),
        (5.0, -1.0, 2.0),
    ]
    .iter()
    .map(|(x, y, z)| format!("v {x} {y} {z}\n"))
    .collect();
    let cp = out("curve.obj");
    std::fs::write(&cp, curve.concat()).unwrap();
    for kind in ["clamped-bspline", "bezier"] {
        let o = out(&format!("{kind}.csv"));
        let (ok, err) = run(&[
            "surface",
            "ifs",
            s(&cp),
            "-o",
            s(&o),
            "--kind",
            kind,
            "--steps",
            "5",
        ]);
        assert!(ok, "{err}");
        let lines = read_polylines_csv(&o);
        assert_eq!(lines.len(), 1);
        assert_eq!(lines[0].len(), 33);
        assert!(close(lines[0][0], DVec3::ZERO));
        assert!(close(lines[0][32], DVec3::new(5.0, -1.0, 2.0)), "{kind}");
    }
    // Start sets: Koch from the segment (0,0)–(1,0) is the Koch polygon
    // (4^k segments of length 3^-k); a point start gives q^k points; a
    // triangle q^k triangles; a mesh file q^k copies.
    let o = out("koch.csv");
    let (ok, err) = run(&[
        "surface",
        "ifs",
        "-o",
        s(&o),
        "--kind",
        "koch",
        "--start",
        "segment",
        "--steps",
        "2",
    ]);
    assert!(ok, "{err}");
    let segs = read_polylines_csv(&o);
    assert_eq!(segs.len(), 16);
    assert!(segs
        .iter()
        .all(|l| (l[0].distance(l[1]) - 1.0 / 9.0).abs() < 1e-12));
    let o = out("points.csv");
    let (ok, err) = run(&[
        "surface",
        "ifs",
        "-o",
        s(&o),
        "--kind",
        "sqrt3",
        "--start",
        "point",
        "--maps",
        "0,8",
        "--steps",
        "3",
    ]);
    assert!(ok, "{err}");
    let rows = std::fs::read_to_string(&o).unwrap().lines().count();
    assert_eq!(rows, 1 + 8);
    let o = out("tris.obj");
    let (ok, err) = run(&[
        "surface",
        "ifs",
        s(&cp),
        "-o",
        s(&o),
        "--kind",
        "bezier",
        "--start",
        "triangle",
        "--steps",
        "4",
    ]);
    assert!(ok, "{err}");
    let m = tetrefine_surface::read_surface(&o).unwrap().mesh;
    assert_eq!((m.points.len(), m.faces.len()), (48, 16));
    let start = out("start.obj");
    std::fs::write(
        &start,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n",
    )
    .unwrap();
    let o = out("copies.ply");
    let (ok, err) = run(&[
        "surface",
        "ifs",
        "-o",
        s(&o),
        "--kind",
        "loop",
        "--start",
        s(&start),
        "--steps",
        "2",
        "--ascii",
    ]);
    assert!(ok, "{err}");
    assert_eq!((ply_count(&o, "vertex"), ply_count(&o, "face")), (64, 32));
    assert!(std::fs::read_to_string(&o)
        .unwrap()
        .contains("format ascii"));
    let (ok, err) = run(&[
        "surface",
        "ifs",
        "-o",
        s(&out("k.csv")),
        "--kind",
        "koch",
        "--ascii",
    ]);
    assert!(!ok && err.contains("--ascii is for .ply and .stl"), "{err}");
    // Refused: bad maps, an unreadable start file, a wrong control count,
    // a curve extension for a surface; no output file, no panic.
    let o = out("bad.obj");
    for (args, want) in [
        (
            vec!["--kind", "loop", "--maps", "0,4"],
            "map 4 does not exist",
        ),
        (
            vec!["--kind", "loop", "--maps", "1,1"],
            "map 1 is given twice",
        ),
        (
            vec!["--kind", "loop", "--start", "missing.obj"],
            "missing.obj",
        ),
        (
            vec![s(&cp), "--kind", "loop"],
            "Loop needs exactly 12 control points, got 5",
        ),
        (
            vec![s(&net12), "--kind", "sqrt3"],
            "Sqrt3 needs exactly 27 control points, got 12",
        ),
        (vec!["--kind", "koch", "--maps", "x"], "invalid value"),
    ] {
        let mut full = vec!["surface", "ifs", "-o", s(&o)];
        full.extend(args.iter().copied());
        let (ok, err) = run(&full);
        assert!(!ok && err.contains(want), "{full:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(!o.exists(), "{full:?} wrote a file");
    }
    let (ok, err) = run(&["surface", "ifs", "-o", s(&out("x.csv")), "--kind", "loop"]);
    assert!(!ok && err.contains("triangle mesh"), "{err}");
    let (ok, err) = run(&["surface", "loop", s(&net12), "-o", s(&o), "--maps", "0"]);
    assert!(!ok && err.contains("--maps is for ifs"), "{err}");
}

#[test]
fn sierpinski_truncate_and_ifs_refuse_bad_options_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let quad = dir.path().join("cube.obj");
    write_surface(&quad, &cube()).unwrap();
    let mut open_cube = cube();
    open_cube.faces.pop();
    let open = dir.path().join("open.obj");
    write_surface(&open, &open_cube).unwrap();
    let four = dir.path().join("four.obj");
    std::fs::write(&four, "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 3 0 0\n").unwrap();
    let mesh_out = dir.path().join("out.obj");
    let lines_out = dir.path().join("out.vtp");
    let (m, l, q) = (s(&mesh_out), s(&lines_out), s(&quad));
    let cases: Vec<(Vec<&str>, &str, &Path)> = vec![
        (
            vec!["surface", "sierpinski", q, "-o", m, "--neck", "0.5"],
            "neck",
            &mesh_out,
        ),
        (
            vec!["surface", "truncate", q, "-o", m, "--cut", "0"],
            "cut",
            &mesh_out,
        ),
        (
            vec!["surface", "truncate", q, "-o", m, "--neck", "0.1"],
            "--neck is for sierpinski",
            &mesh_out,
        ),
        (
            vec!["surface", "loop", q, "-o", m, "--cut", "0.1"],
            "--cut is for truncate",
            &mesh_out,
        ),
        (
            vec!["surface", "sierpinski", q, "-o", m, "--kind", "koch"],
            "--kind is for ifs",
            &mesh_out,
        ),
        (
            vec!["surface", "sierpinski", q, "-o", m, "--corner", "1"],
            "creases or corners",
            &mesh_out,
        ),
        (
            vec!["surface", "sierpinski", s(&open), "-o", m],
            "boundary",
            &mesh_out,
        ),
        (
            vec!["surface", "truncate", s(&open), "-o", m],
            "boundary",
            &mesh_out,
        ),
        (
            vec!["surface", "sierpinski", "-o", m],
            "input surface",
            &mesh_out,
        ),
        (
            vec!["surface", "truncate", q, "-o", l.trim_end_matches("vtp")],
            "extension",
            &mesh_out,
        ),
        (vec!["surface", "ifs", q, "-o", l], "--kind", &lines_out),
        (
            vec!["surface", "ifs", "-o", l, "--kind", "cubic-bspline"],
            "control points",
            &lines_out,
        ),
        (
            vec!["surface", "ifs", "-o", l, "--kind", "bicubic"],
            "--grid",
            &lines_out,
        ),
        (
            vec!["surface", "ifs", "-o", l, "--kind", "koch", "--grid", "4,4"],
            "--grid",
            &lines_out,
        ),
        (
            vec!["surface", "ifs", s(&four), "-o", l, "--kind", "koch"],
            "exactly 5",
            &lines_out,
        ),
        (
            vec![
                "surface",
                "ifs",
                s(&four),
                "-o",
                l,
                "--kind",
                "bicubic",
                "--grid",
                "2,2",
            ],
            "4 × 4",
            &lines_out,
        ),
        (
            vec![
                "surface", "ifs", "-o", l, "--kind", "gasket", "--steps", "40",
            ],
            "points",
            &lines_out,
        ),
        (
            vec!["surface", "ifs", "-o", m, "--kind", "koch"],
            ".vtp or .csv",
            &mesh_out,
        ),
    ];
    for (args, needle, out) in cases {
        fails_cleanly(&args, needle, out);
    }
}

/// The `generation` cell array of a `.vtp`, read by vtkio.
fn vtp_cell_array(path: &Path, name: &str) -> Vec<u32> {
    let vtk = vtkio::Vtk::import(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let piece = match vtk.data {
        vtkio::model::DataSet::PolyData { pieces, .. } => match pieces.into_iter().next() {
            Some(vtkio::model::Piece::Inline(p)) => *p,
            _ => panic!("inline piece expected"),
        },
        _ => panic!("PolyData expected"),
    };
    for attr in piece.data.cell {
        if let vtkio::model::Attribute::DataArray(arr) = attr {
            if arr.name == name {
                return arr.data.cast_into().expect("u32 values");
            }
        }
    }
    panic!("{}: no cell array {name}", path.display())
}

#[test]
fn stl_and_ply_are_binary_unless_ascii_and_stl_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let ico = dir.path().join("ico.obj");
    write_surface(&ico, &icosahedron()).unwrap();
    let cube_in = dir.path().join("cube.off");
    write_surface(&cube_in, &cube()).unwrap();
    // Loop ×2 on the icosahedron: 20·4² triangles, 84 + 50 bytes each.
    let stl = dir.path().join("ico2.stl");
    let (ok, err) = run(&["surface", "loop", s(&ico), "-o", s(&stl), "--steps", "2"]);
    assert!(ok, "{err}");
    let bytes = std::fs::read(&stl).unwrap();
    assert_eq!(bytes.len(), 84 + 50 * 320);
    assert_eq!(
        u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]),
        320
    );
    // Catmull–Clark ×1 on the cube: 24 quads, each two STL triangles.
    let cc = dir.path().join("cc.stl");
    let (ok, err) = run(&["surface", "catmull-clark", s(&cube_in), "-o", s(&cc)]);
    assert!(ok, "{err}");
    assert_eq!(std::fs::metadata(&cc).unwrap().len(), 84 + 50 * 48);
    // --ascii: text, one "facet normal" per triangle.
    let asc = dir.path().join("cc-ascii.stl");
    let (ok, err) = run(&[
        "surface",
        "catmull-clark",
        s(&cube_in),
        "-o",
        s(&asc),
        "--ascii",
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&asc).unwrap();
    assert!(text.starts_with("solid "));
    assert_eq!(text.matches("facet normal").count(), 48);
    assert_eq!(text.matches("endfacet").count(), 48);
    // STL as input: the ASCII file of 48 triangles is a closed surface of
    // 26 vertices; Loop ×1 gives 4 × 48 triangles.
    let again = dir.path().join("again.obj");
    let (ok, err) = run(&["surface", "loop", s(&asc), "-o", s(&again)]);
    assert!(ok, "{err}");
    let m = load_surface(&again).unwrap();
    assert_eq!(m.faces.len(), 4 * 48);
    assert_eq!(m.euler_characteristic(), 2);
    // PLY: binary by default, ASCII on request; both read back.
    for (flag, format) in [
        (None, "binary_little_endian 1.0"),
        (Some("--ascii"), "ascii 1.0"),
    ] {
        let ply = dir.path().join("ico.ply");
        let mut args = vec!["surface", "loop", s(&ico), "-o", s(&ply)];
        args.extend(flag);
        let (ok, err) = run(&args);
        assert!(ok, "{err}");
        let bytes = std::fs::read(&ply).unwrap();
        let end = bytes
            .windows(11)
            .position(|w| w == b"end_header\n")
            .unwrap();
        let head = String::from_utf8_lossy(&bytes[..end]).into_owned();
        assert!(head.contains(&format!("format {format}\n")), "{head}");
        assert!(head.contains("property uint generation"), "{head}");
        assert_eq!(load_surface(&ply).unwrap().faces.len(), 80);
    }
    // --ascii is refused where it means nothing.
    let obj = dir.path().join("x.obj");
    fails_cleanly(
        &["surface", "loop", s(&ico), "-o", s(&obj), "--ascii"],
        "--ascii is for .ply and .stl outputs",
        &obj,
    );
}

#[test]
fn every_step_writes_each_generation_with_its_attributes() {
    let dir = tempfile::tempdir().unwrap();
    let ico = dir.path().join("ico.obj");
    write_surface(&ico, &icosahedron()).unwrap();
    let out = dir.path().join("loop.vtp");
    let (ok, err) = run(&[
        "surface",
        "loop",
        s(&ico),
        "-o",
        s(&out),
        "--steps",
        "3",
        "--every-step",
    ]);
    assert!(ok, "{err}");
    assert!(!out.exists(), "OUTPUT itself is not written");
    for k in 0..=3u32 {
        let path = dir.path().join(format!("loop_{k}.vtp"));
        let text = std::fs::read_to_string(&path).unwrap();
        let faces = 20 * 4usize.pow(k);
        assert_eq!(vtp_count(&text, "NumberOfPolys"), faces, "step {k}");
        // Loop replaces every face: all of generation k, 4^k per input
        // face, and 4^(k−1) of each of the 4 child groups per input face.
        let generation = vtp_cell_array(&path, "generation");
        assert_eq!(generation, vec![k; faces], "step {k}");
        let origin = vtp_cell_array(&path, "origin");
        for f in 0..20 {
            let n = origin.iter().filter(|&&o| o == f).count();
            assert_eq!(n, 4usize.pow(k), "step {k}, input face {f}");
        }
        let group = vtp_cell_array(&path, "group");
        let top = if k == 0 { 0 } else { 3 };
        assert!(group.iter().all(|&g| g <= top), "step {k}");
    }
    assert!(!dir.path().join("loop_4.vtp").exists());
    // Doo–Sabin on the cube, ASCII PLY: the group property counts the
    // F-faces (6), E-faces (12) and V-faces (8) of one step.
    let cube_in = dir.path().join("cube.obj");
    write_surface(&cube_in, &cube()).unwrap();
    let ply = dir.path().join("ds.ply");
    let (ok, err) = run(&[
        "surface",
        "doo-sabin",
        s(&cube_in),
        "-o",
        s(&ply),
        "--every-step",
        "--ascii",
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(dir.path().join("ds_1.ply")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let end = lines.iter().position(|l| *l == "end_header").unwrap();
    let nv: usize = lines[..end]
        .iter()
        .find_map(|l| l.strip_prefix("element vertex "))
        .unwrap()
        .parse()
        .unwrap();
    let mut groups = [0; 3];
    for l in &lines[end + 1 + nv..] {
        let nums: Vec<usize> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
        let n = nums[0];
        assert_eq!(nums.len(), n + 4, "{l}");
        groups[nums[n + 3]] += 1;
    }
    assert_eq!(groups, [6, 12, 8]);
    let first = std::fs::read_to_string(dir.path().join("ds_0.ply")).unwrap();
    assert!(first.contains("element face 6\n"));
}

#[test]
fn sierpinski_output_fed_back_goes_on_as_one_run() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("tet.obj");
    write_surface(&input, &tetrahedron()).unwrap();
    let sierpinski = |from: &Path, to: &Path, steps: &str| {
        let (ok, err) = run(&[
            "surface",
            "sierpinski",
            s(from),
            "-o",
            s(to),
            "--steps",
            steps,
        ]);
        assert!(ok, "{err}");
        ClosedTopology::of(&load_surface(to).unwrap())
    };
    // One step, fed back for one more (through .obj and through binary
    // .ply), is the two-step surface: V = 4, E = 6 give genus
    // 1 − V + E(4² + 2)/6 = 15 and S = 48, P = 16, J = 30.
    let once = dir.path().join("once.obj");
    sierpinski(&input, &once, "1");
    let once_ply = dir.path().join("once.ply");
    sierpinski(&input, &once_ply, "1");
    let direct = sierpinski(&input, &dir.path().join("direct.obj"), "2");
    for fed in [&once, &once_ply] {
        let t = sierpinski(fed, &dir.path().join("again.obj"), "1");
        assert_eq!(t.components, 1);
        assert_eq!(1 - t.euler() / 2, 15);
        assert_eq!(
            (t.vertices, t.edges, t.faces),
            (48 + 16 + 4 * 30, 2 * 48 + 9 * 30, 48 + 16 + 3 * 30)
        );
        assert_eq!(
            (t.vertices, t.edges, t.faces),
            (direct.vertices, direct.edges, direct.faces)
        );
    }
    // --every-step: a generation refused (step 2's tubes round onto their
    // joints at --neck 1e-17) leaves none of the files, not even those of
    // steps 0 and 1, and no temporary file.
    let sub = dir.path().join("sub");
    std::fs::create_dir(&sub).unwrap();
    let every = sub.join("s.obj");
    let (ok, err) = run(&[
        "surface",
        "sierpinski",
        s(&input),
        "-o",
        s(&every),
        "--steps",
        "2",
        "--every-step",
        "--neck",
        "1e-17",
    ]);
    assert!(!ok);
    assert!(
        err.contains("step 2: the result has coincident points"),
        "{err}"
    );
    assert_eq!(std::fs::read_dir(&sub).unwrap().count(), 0);
    // --every-step is not for ifs.
    let lines = dir.path().join("koch.csv");
    fails_cleanly(
        &[
            "surface",
            "ifs",
            "--kind",
            "koch",
            "-o",
            s(&lines),
            "--every-step",
        ],
        "--every-step is for the subdivision schemes, not ifs",
        &lines,
    );
}

/// The block of kind `kind` (```` ```kind ````) after byte `from` of `text`.
fn block_after<'a>(text: &'a str, from: usize, kind: &str) -> (&'a str, usize) {
    let open = format!("```{kind}\n");
    let start = from + text[from..].find(&open).expect(&open) + open.len();
    let len = text[start..].find("```").expect("closing fence");
    (&text[start..start + len], start + len)
}

/// Every path to a member of an object in `v` (at any depth).
fn member_paths(
    v: &serde_json::Value,
    path: &mut Vec<serde_json::Value>,
    out: &mut Vec<Vec<serde_json::Value>>,
) {
    match v {
        serde_json::Value::Object(m) => {
            for (k, x) in m {
                path.push(k.clone().into());
                out.push(path.clone());
                member_paths(x, path, out);
                path.pop();
            }
        }
        serde_json::Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                path.push(i.into());
                member_paths(x, path, out);
                path.pop();
            }
        }
        _ => {}
    }
}

/// `v` without the member at `path`.
fn without(v: &serde_json::Value, path: &[serde_json::Value]) -> serde_json::Value {
    let mut v = v.clone();
    let mut node = &mut v;
    for step in &path[..path.len() - 1] {
        node = match step {
            serde_json::Value::String(k) => node.get_mut(k.as_str()).unwrap(),
            serde_json::Value::Number(i) => node.get_mut(i.as_u64().unwrap() as usize).unwrap(),
            _ => unreachable!(),
        };
    }
    let key = path.last().unwrap().as_str().unwrap();
    assert!(node.as_object_mut().unwrap().remove(key).is_some());
    v
}

#[test]
fn readme_weighted_example_every_setting_matters() {
    // The README's cube.obj, w.json and command, run as written; then each
    // member of w.json removed in turn must change out.obj, or (for the
    // settings that cannot be left out) be refused naming the member, with
    // nothing written.
    let readme = std::fs::read_to_string(crate::support::path("README.md")).unwrap();
    let at = readme
        .find("Example: the unit cube `cube.obj`")
        .expect("README example");
    let (cube_obj, end) = block_after(&readme, at, "text");
    let (json, end) = block_after(&readme, end, "json");
    let (cmd, _) = block_after(&readme, end, "sh");
    let args: Vec<&str> = cmd
        .trim()
        .strip_prefix("tetrefine ")
        .expect("a tetrefine command")
        .split_whitespace()
        .collect();
    assert_eq!(args[..2], ["surface", "catmull-clark-weighted"]);
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("cube.obj"), cube_obj).unwrap();
    // The README's cube is the unit cube of the shapes module.
    assert_eq!(load_surface(&dir.path().join("cube.obj")).unwrap(), cube());
    let run_with = |cfg: &str| {
        std::fs::write(dir.path().join("w.json"), cfg).unwrap();
        let out = dir.path().join("out.obj");
        let _ = std::fs::remove_file(&out);
        let o = crate::tetrefine_command()
            .args(&args)
            .current_dir(dir.path())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr).into_owned();
        match o.status.success() {
            true => Ok(std::fs::read(&out).unwrap()),
            false => {
                assert!(!out.exists(), "{err}");
                Err(err)
            }
        }
    };
    let full = run_with(json).expect("the README example runs");
    // Plain Catmull–Clark differs too (the file is not a no-op).
    assert_ne!(Ok(full.clone()), run_with("{}"));
    let value: serde_json::Value = serde_json::from_str(json).unwrap();
    let mut paths = Vec::new();
    member_paths(&value, &mut Vec::new(), &mut paths);
    assert!(paths.len() > 60, "{}", paths.len());
    let required = ["axis.axis", "axis.from", "axis.to", "radial.direction"];
    let mut refused = 0;
    for path in &paths {
        let name: Vec<String> = path
            .iter()
            .map(|p| match p {
                serde_json::Value::String(s) => s.clone(),
                other => other.to_string(),
            })
            .collect();
        let name = name.join(".");
        let cfg = serde_json::to_string_pretty(&without(&value, path)).unwrap();
        match run_with(&cfg) {
            Ok(out) => assert_ne!(out, full, "removing {name} changes nothing"),
            Err(err) => {
                let key = path.last().unwrap().as_str().unwrap();
                let allowed = required.contains(&name.as_str())
                    || key == "stops"
                    || (key == "at" && !name.ends_with(".0.at"));
                assert!(allowed, "removing {name} is refused: {err}");
                assert!(
                    err.contains(&format!("`{key}`")) || err.contains(&format!(".{key}`")),
                    "{name}: {err}"
                );
                assert_eq!(err.trim().lines().count(), 1, "{err}");
                refused += 1;
            }
        }
    }
    assert!(
        refused < paths.len() / 4,
        "{refused} of {} refused",
        paths.len()
    );
}

#[test]
fn bad_weight_files_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let quad = dir.path().join("cube.obj");
    write_surface(&quad, &cube()).unwrap();
    let out = dir.path().join("out.obj");
    let cases = [
        (
            r#"{ "spherical": { "center": [0, 0, 0], "radius": 1 } }"#,
            "radius",
        ),
        (
            "{\n  \"iterations\": [ { \"vertex\": NaN } ]\n}",
            "`vertex`",
        ),
        (
            r#"{ "attractors": { "tightness": -2 } }"#,
            "attractors.tightness",
        ),
        (
            r#"{ "edge_distance": { "stops": [ { "at": 1 }, { "at": 1 } ] } }"#,
            "edge_distance.stops[1].at",
        ),
        (r#"{ "merge_distance": -1 }"#, "merge_distance"),
    ];
    for (k, (text, field)) in cases.iter().enumerate() {
        let w = dir.path().join(format!("w{k}.json"));
        std::fs::write(&w, text).unwrap();
        let args = [
            "surface",
            "catmull-clark-weighted",
            s(&quad),
            "-o",
            s(&out),
            "--weights",
            s(&w),
        ];
        fails_cleanly(&args, field, &out);
        fails_cleanly(&args, s(&w), &out);
    }
    // Finite weights whose result overflows: refused, nothing written.
    let w = dir.path().join("huge.json");
    std::fs::write(
        &w,
        r#"{ "iterations": [ { "face_extrude": 1e300, "edge": 1e308 } ] }"#,
    )
    .unwrap();
    let args = [
        "surface",
        "catmull-clark-weighted",
        s(&quad),
        "-o",
        s(&out),
        "--steps",
        "3",
        "--weights",
        s(&w),
    ];
    fails_cleanly(&args, "out of range", &out);
}
