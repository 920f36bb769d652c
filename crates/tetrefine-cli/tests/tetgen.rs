//! TetGen through `tetrefine::tetgen` and `tetrefine mesh` (feature `tetgen`).
//!
//! Expected figures are closed forms of the input geometry, not outputs of
//! the code under test.

#![cfg(feature = "tetgen")]

#[path = "../../../tests/support/mod.rs"]
mod support;

use glam::DVec3;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use tetrefine::geom::tet_volume;
use tetrefine::io::{Facet, Plc};
use tetrefine::tetgen::{refine, tetrahedralize, Options, TetgenError};
use tetrefine::NO_ADJ;
use tetrefine::{MeshStats, TetMesh};

const EXAMPLE: &str = "meshes/tetgen_example.poly";

/// The unit cube's corners: point `i` has coordinates given by its bits.
fn cube_points() -> Vec<[f64; 3]> {
    (0..8)
        .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
        .collect()
}

/// The six faces of the unit cube; face `m` gets marker `m + 1`:
/// 1: z = 0, 2: z = 1, 3: y = 0, 4: y = 1, 5: x = 0, 6: x = 1.
const CUBE_QUADS: [[u32; 4]; 6] = [
    [0, 2, 3, 1],
    [4, 5, 7, 6],
    [0, 1, 5, 4],
    [2, 6, 7, 3],
    [0, 4, 6, 2],
    [1, 3, 7, 5],
];

fn cube_plc() -> Plc {
    Plc {
        points: cube_points(),
        facets: CUBE_QUADS
            .iter()
            .enumerate()
            .map(|(m, q)| Facet {
                polygons: vec![q.to_vec()],
                holes: vec![],
                marker: m as i32 + 1,
            })
            .collect(),
        ..Default::default()
    }
}

fn cube_triangles() -> Vec<[u32; 3]> {
    CUBE_QUADS
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect()
}

fn volume(mesh: &TetMesh) -> f64 {
    mesh.tet_ids()
        .map(|t| tet_volume(&mesh.tet_points(t)))
        .sum()
}

fn region_volumes(mesh: &TetMesh) -> BTreeMap<i32, f64> {
    let mut v = BTreeMap::new();
    for t in mesh.tet_ids() {
        *v.entry(mesh.region(t)).or_insert(0.0) += tet_volume(&mesh.tet_points(t));
    }
    v
}

/// Every boundary face as (its three points, its marker).
fn boundary_faces(mesh: &TetMesh) -> Vec<([DVec3; 3], Option<i32>)> {
    let mut out = Vec::new();
    for t in mesh.tet_ids() {
        for f in 0..4 {
            if mesh.adj(t)[f] == NO_ADJ {
                let v = mesh.face_vertices(t, f);
                out.push((v.map(|i| mesh.point(i)), mesh.face_marker(v)));
            }
        }
    }
    out
}

/// A good call must still work (the process survived the failing one).
fn good_call_still_works() {
    let mesh = tetrahedralize(&cube_plc(), &Options::default()).unwrap();
    assert!((volume(&mesh) - 1.0).abs() < 1e-12);
}

#[test]
fn example_poly_two_regions_exact_volume_empty_cavities() {
    let plc = Plc::read(&support::path(EXAMPLE)).unwrap();
    let opts = Options {
        switches: Some("-pq1.414a0.002A".into()),
        ..Default::default()
    };
    let mesh = tetrahedralize(&plc, &opts).unwrap();
    mesh.check().unwrap();
    assert_eq!(MeshStats::compute(&mesh).inverted, 0);

    // The box [0,2]² × [0,5] cut by the plane z = 4 - y/2 (facet 2): region 10
    // below it (mean height 3.5 over the 2 × 2 base), region 20 above; the
    // cavity [0.25,1.75]×[0.25,1.5]×[0.5,1] and the notch
    // [0.25,1.75]×[0,1.5]×[2,2.5] are below the plane and are holes.
    let cavity = 1.5 * 1.25 * 0.5;
    let notch = 1.5 * 1.5 * 0.5;
    let r10 = 2.0 * 2.0 * 3.5 - cavity - notch;
    let r20 = 2.0 * 2.0 * 5.0 - 2.0 * 2.0 * 3.5;
    let total = volume(&mesh);
    let enclosed = plc.enclosed_volume().unwrap();
    assert!(
        (total - enclosed).abs() < 1e-9 * enclosed,
        "{total} vs {enclosed}"
    );
    assert!((total - (r10 + r20)).abs() < 1e-9 * total, "{total}");
    let regions = region_volumes(&mesh);
    assert_eq!(regions.keys().copied().collect::<Vec<_>>(), vec![10, 20]);
    assert!((regions[&10] - r10).abs() < 1e-9 * r10, "{regions:?}");
    assert!((regions[&20] - r20).abs() < 1e-9 * r20, "{regions:?}");

    // No tet in the cavity or the notch.
    let inside =
        |p: DVec3, lo: [f64; 3], hi: [f64; 3]| (0..3).all(|a| p[a] > lo[a] && p[a] < hi[a]);
    for t in mesh.tet_ids() {
        let c = mesh.tet_points(t).iter().sum::<DVec3>() / 4.0;
        assert!(
            !inside(c, [0.25, 0.25, 0.5], [1.75, 1.5, 1.0]),
            "tet {t} in the cavity"
        );
        assert!(
            !inside(c, [0.25, 0.0, 2.0], [1.75, 1.5, 2.5]),
            "tet {t} in the notch"
        );
    }

    // Facet markers on the faces: the cavity's walls are marker 4, the
    // bottom z = 0 is marker 1, the top z = 5 marker 2; the interface on
    // z = 4 - y/2 (facet 2) keeps marker 9 although it is interior.
    let faces = boundary_faces(&mesh);
    assert!(
        faces.iter().all(|(_, m)| m.is_some()),
        "unmarked boundary face"
    );
    for (p, m) in &faces {
        let c = (p[0] + p[1] + p[2]) / 3.0;
        if c.z.abs() < 1e-12 {
            assert_eq!(*m, Some(1));
        } else if (c.z - 5.0).abs() < 1e-12 {
            assert_eq!(*m, Some(2));
        } else if inside(c, [0.2, 0.2, 0.45], [1.8, 1.55, 1.05]) {
            assert_eq!(*m, Some(4), "cavity wall at {c}");
        }
    }
    let mut interface = 0;
    for (k, &m) in mesh.face_markers() {
        let c = k.iter().map(|&v| mesh.point(v)).sum::<DVec3>() / 3.0;
        let on_plane = (c.z - (4.0 - c.y / 2.0)).abs() < 1e-9;
        if on_plane && c.x > 1e-9 && c.x < 2.0 - 1e-9 {
            assert_eq!(m, 9, "interface face at {c}");
            interface += 1;
        }
    }
    assert!(interface > 0, "no face on the interface carries a marker");
}

#[test]
fn cube_from_binary_stl_and_ascii_off_has_volume_one() {
    let dir = tempfile::tempdir().unwrap();
    let pts = cube_points();
    let mut stl = vec![0u8; 80];
    stl.extend_from_slice(&12u32.to_le_bytes());
    for t in cube_triangles() {
        stl.extend_from_slice(&[0u8; 12]);
        for v in t {
            for c in pts[v as usize] {
                stl.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
        stl.extend_from_slice(&[0u8; 2]);
    }
    let stl_path = dir.path().join("cube.stl");
    std::fs::write(&stl_path, &stl).unwrap();
    let mut off = String::from("OFF\n8 6 0\n");
    for p in &pts {
        off += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    for q in CUBE_QUADS {
        off += &format!("4 {} {} {} {}\n", q[0], q[1], q[2], q[3]);
    }
    let off_path = dir.path().join("cube.off");
    std::fs::write(&off_path, off).unwrap();
    for path in [&stl_path, &off_path] {
        let plc = Plc::read(path).unwrap();
        for opts in [
            Options::default(),
            Options {
                min_ratio: Some(1.414),
                max_volume: Some(0.001),
                ..Default::default()
            },
        ] {
            let mesh = tetrahedralize(&plc, &opts).unwrap();
            mesh.check().unwrap();
            let v = volume(&mesh);
            assert!((v - 1.0).abs() < 1e-12, "{}: volume {v}", path.display());
            if opts.max_volume.is_some() {
                assert!(mesh.n_tets() >= 1000, "a0.001 needs at least 1000 tets");
            }
        }
    }
}

/// The marker a face of the unit cube must carry, from its plane.
fn cube_marker(c: DVec3) -> i32 {
    let eps = 1e-12;
    match () {
        _ if c.z.abs() < eps => 1,
        _ if (c.z - 1.0).abs() < eps => 2,
        _ if c.y.abs() < eps => 3,
        _ if (c.y - 1.0).abs() < eps => 4,
        _ if c.x.abs() < eps => 5,
        _ if (c.x - 1.0).abs() < eps => 6,
        _ => panic!("{c} is not on the cube's boundary"),
    }
}

#[test]
fn cube_poly_markers_land_on_the_boundary_faces() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cube.poly");
    write_poly(&path, &cube_plc());
    let plc = Plc::read(&path).unwrap();
    let markers: Vec<i32> = plc.facets.iter().map(|f| f.marker).collect();
    assert_eq!(markers, vec![1, 2, 3, 4, 5, 6]);
    let mesh = tetrahedralize(
        &plc,
        &Options {
            min_ratio: Some(1.5),
            max_volume: Some(0.01),
            ..Default::default()
        },
    )
    .unwrap();
    mesh.check().unwrap();
    assert!((volume(&mesh) - 1.0).abs() < 1e-12);
    let faces = boundary_faces(&mesh);
    let mut seen = [0usize; 7];
    for (p, m) in &faces {
        let c = (p[0] + p[1] + p[2]) / 3.0;
        assert_eq!(*m, Some(cube_marker(c)), "face at {c}");
        seen[cube_marker(c) as usize] += 1;
    }
    assert!(seen[1..].iter().all(|&n| n >= 2), "{seen:?}");
    // Each cube face is covered: its boundary triangles add up to area 1.
    let mut area = [0.0f64; 7];
    for (p, _) in &faces {
        let c = (p[0] + p[1] + p[2]) / 3.0;
        area[cube_marker(c) as usize] += 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
    }
    for a in &area[1..] {
        assert!((a - 1.0).abs() < 1e-12, "{area:?}");
    }
}

/// Bad surfaces: the library's error must contain `needle`.
fn bad_surfaces() -> Vec<(&'static str, Plc, &'static str)> {
    let mut out = Vec::new();
    // Two cubes that interpenetrate.
    let mut two = cube_plc();
    two.points
        .extend(cube_points().iter().map(|p| p.map(|c| c + 0.5)));
    for (m, q) in CUBE_QUADS.iter().enumerate() {
        two.facets.push(Facet {
            polygons: vec![q.iter().map(|v| v + 8).collect()],
            holes: vec![],
            marker: 10 + m as i32,
        });
    }
    out.push(("self_intersecting", two, "intersects itself"));
    let mut dup = cube_plc();
    dup.facets.push(dup.facets[3].clone());
    out.push(("duplicated", dup, "duplicates facet 4"));
    let mut open = cube_plc();
    open.facets.remove(1);
    out.push(("open", open, "not closed"));
    let mut flat = cube_plc();
    for p in &mut flat.points {
        p[2] = 0.5 * p[0] + 0.25 * p[1];
    }
    out.push(("coplanar", flat, "lie in one plane"));
    let mut nan = cube_plc();
    nan.points[5][0] = f64::NAN;
    out.push(("nan", nan, "non-finite"));
    let mut range = cube_plc();
    range.facets[2].polygons[0][1] = 8;
    out.push((
        "out_of_range",
        range,
        "refers to point 9 but there are 8 points",
    ));
    out
}

#[test]
fn bad_surfaces_are_clear_errors_and_the_process_survives() {
    for (name, plc, needle) in bad_surfaces() {
        let e = tetrahedralize(&plc, &Options::default()).unwrap_err();
        assert!(matches!(e, TetgenError::Input(_)), "{name}: {e:?}");
        let msg = e.to_string();
        assert!(msg.contains(needle), "{name}: {msg}");
        assert!(!msg.contains('\n'), "{name}: {msg}");
        good_call_still_works();
    }
    // Options TetGen must not see.
    for opts in [
        Options {
            min_ratio: Some(0.5),
            ..Default::default()
        },
        Options {
            min_dihedral: Some(75.0),
            ..Default::default()
        },
        Options {
            max_volume: Some(-1.0),
            ..Default::default()
        },
        Options {
            switches: Some("pr".into()),
            ..Default::default()
        },
        Options {
            switches: Some("po2".into()),
            ..Default::default()
        },
    ] {
        let e = tetrahedralize(&cube_plc(), &opts).unwrap_err();
        assert!(matches!(e, TetgenError::Options(_)), "{opts:?}: {e:?}");
        good_call_still_works();
    }
}

#[test]
fn refine_keeps_volume_regions_and_markers() {
    let plc = Plc::read(&support::path(EXAMPLE)).unwrap();
    let coarse = tetrahedralize(&plc, &Options::default()).unwrap();
    let fine = refine(
        &coarse,
        &Options {
            max_volume: Some(0.01),
            ..Default::default()
        },
    )
    .unwrap();
    fine.check().unwrap();
    assert!(
        fine.n_tets() as f64 >= 17.9 / 0.01,
        "{} tets",
        fine.n_tets()
    );
    let (a, b) = (region_volumes(&coarse), region_volumes(&fine));
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
    for (r, v) in &a {
        assert!((b[r] - v).abs() < 1e-9 * v, "region {r}: {} vs {v}", b[r]);
    }
    // Bottom and top keep their markers.
    for (p, m) in boundary_faces(&fine) {
        let c = (p[0] + p[1] + p[2]) / 3.0;
        if c.z.abs() < 1e-12 {
            assert_eq!(m, Some(1));
        } else if (c.z - 5.0).abs() < 1e-12 {
            assert_eq!(m, Some(2));
        }
    }
}

#[test]
fn refine_follows_a_size_field() {
    let coarse = tetrahedralize(&cube_plc(), &Options::default()).unwrap();
    // Target edge length 0.1 at every vertex: the unit cube then needs
    // roughly 1 / (0.1³ / 6√2) ≈ 8,500 regular tets; ask for a tenth of that.
    let sizes = vec![0.1; coarse.n_points()];
    let fine = refine(
        &coarse,
        &Options {
            size_field: Some(sizes),
            ..Default::default()
        },
    )
    .unwrap();
    fine.check().unwrap();
    assert!((volume(&fine) - 1.0).abs() < 1e-12);
    assert!(fine.n_tets() > 850, "{} tets", fine.n_tets());
    // The same quality bound without the size field refines far less, and a
    // coarser field gives fewer tets: the field is what drives it.
    let quality_only = refine(
        &coarse,
        &Options {
            min_ratio: Some(2.0),
            ..Default::default()
        },
    )
    .unwrap();
    let coarser = refine(
        &coarse,
        &Options {
            size_field: Some(vec![0.2; coarse.n_points()]),
            ..Default::default()
        },
    )
    .unwrap();
    eprintln!(
        "tets: quality only {}, size 0.2 {}, size 0.1 {}",
        quality_only.n_tets(),
        coarser.n_tets(),
        fine.n_tets()
    );
    assert!(quality_only.n_tets() < coarser.n_tets());
    assert!(coarser.n_tets() < fine.n_tets());
    let wrong = refine(
        &coarse,
        &Options {
            size_field: Some(vec![0.1; 3]),
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(matches!(wrong, TetgenError::Options(_)), "{wrong}");
}

// ----- the command line -------------------------------------------------------

fn tetrefine(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_tetrefine"))
        .current_dir(support::root())
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn cli_min_dihedral_18_on_the_example() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("example.mesh");
    let o = tetrefine(&[
        "mesh",
        EXAMPLE,
        "-o",
        out.to_str().unwrap(),
        "--min-dihedral",
        "18",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (mesh, _) = tetrefine::io::load_mesh(&out).unwrap();
    mesh.check().unwrap();
    let s = MeshStats::compute(&mesh);
    assert!(s.min_dihedral_deg.worst >= 18.0, "{:?}", s.min_dihedral_deg);
    assert_eq!(s.regions.keys().collect::<Vec<_>>(), vec!["10", "20"]);
    assert!((s.volume - 17.9375).abs() < 1e-9 * 17.9375, "{}", s.volume);
}

/// Writes `plc` as a 1-based `.poly` (markers, holes, regions).
fn write_poly(path: &Path, plc: &Plc) {
    let mut s = format!("{} 3 0 0\n", plc.points.len());
    for (i, p) in plc.points.iter().enumerate() {
        s += &format!("{} {:?} {:?} {:?}\n", i + 1, p[0], p[1], p[2]);
    }
    s += &format!("{} 1\n", plc.facets.len());
    for f in &plc.facets {
        s += &format!("{} {} {}\n", f.polygons.len(), f.holes.len(), f.marker);
        for poly in &f.polygons {
            s += &poly.len().to_string();
            for v in poly {
                s += &format!(" {}", v + 1);
            }
            s += "\n";
        }
    }
    s += "0\n0\n";
    std::fs::write(path, s).unwrap();
}

#[test]
fn cli_bad_surfaces_fail_with_one_line_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let good_in = dir.path().join("cube.poly");
    write_poly(&good_in, &cube_plc());
    for (name, plc, needle) in bad_surfaces() {
        let input = dir.path().join(format!("{name}.poly"));
        let output: PathBuf = dir.path().join(format!("{name}.mesh"));
        // The reader rejects NaN and bad indices with a line number itself.
        let text_needle = match name {
            "nan" => "not a finite number",
            "out_of_range" => "out of range",
            _ => needle,
        };
        if name == "nan" {
            let mut s = String::new();
            write_poly(&input, &plc);
            s += &std::fs::read_to_string(&input)
                .unwrap()
                .replace("NaN", "nan");
            std::fs::write(&input, s).unwrap();
        } else {
            write_poly(&input, &plc);
        }
        let o = tetrefine(&[
            "mesh",
            input.to_str().unwrap(),
            "-o",
            output.to_str().unwrap(),
        ]);
        assert!(!o.status.success(), "{name}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err.lines().count(), 1, "{name}: {err}");
        assert!(err.starts_with("error: "), "{name}: {err}");
        assert!(err.contains(text_needle), "{name}: {err}");
        assert!(!output.exists(), "{name}: partial output");
        // A good run still works.
        let good_out = dir.path().join("cube.mesh");
        let o = tetrefine(&[
            "mesh",
            good_in.to_str().unwrap(),
            "-o",
            good_out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    // An output format that cannot be written is refused before meshing.
    let o = tetrefine(&["mesh", good_in.to_str().unwrap(), "-o", "x.xyz"]);
    assert!(!o.status.success());
    assert_eq!(String::from_utf8_lossy(&o.stderr).lines().count(), 1);
}

/// Issue 21: seeds outside the domain and hostile switches give clean
/// one-line errors, never a crash of the process.
#[test]
fn outside_seeds_and_hostile_switches_are_refused_cleanly() {
    use tetrefine::io::Region;
    for z in [2.0, 1e308] {
        let mut plc = cube_plc();
        plc.regions.push(Region {
            point: [0.5, 0.5, z],
            attribute: 3,
            max_volume: None,
        });
        let e = tetrahedralize(&plc, &Options::default()).unwrap_err();
        assert!(e.to_string().contains("outside the surface"), "{z}: {e}");
    }
    // Through the command line: a .poly whose only seed is outside.
    let dir = tempfile::tempdir().unwrap();
    let poly = dir.path().join("cube.poly");
    let mut s = String::from("8 3 0 0\n");
    for (i, p) in cube_points().iter().enumerate() {
        s += &format!("{} {} {} {}\n", i + 1, p[0], p[1], p[2]);
    }
    s += "6 0\n";
    for q in [
        [1, 3, 4, 2],
        [5, 6, 8, 7],
        [1, 2, 6, 5],
        [3, 7, 8, 4],
        [1, 5, 7, 3],
        [2, 4, 8, 6],
    ] {
        s += &format!("1\n4 {} {} {} {}\n", q[0], q[1], q[2], q[3]);
    }
    std::fs::write(dir.path().join("plain.poly"), format!("{s}0\n0\n")).unwrap();
    s += "0\n1\n1 0.5 0.5 2 7\n";
    std::fs::write(&poly, s).unwrap();
    let out = dir.path().join("o.mesh");
    let run = |extra: &[&str]| {
        let input = if extra.is_empty() {
            poly.clone()
        } else {
            dir.path().join("plain.poly")
        };
        let mut c = Command::new(env!("CARGO_BIN_EXE_tetrefine"));
        c.args(["mesh", input.to_str().unwrap(), "-o", out.to_str().unwrap()]);
        c.args(extra);
        c.output().unwrap()
    };
    let o = run(&[]);
    assert_eq!(
        o.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    // The error names the file and the seed's line: 8 points after the
    // header, 6 facets of two lines, the hole count, the region count.
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.starts_with(&format!(
            "error: {}: region 1 (line {}) has its seed at",
            poly.display(),
            1 + 8 + 1 + 12 + 1 + 1 + 1
        )) && err.contains("outside the surface"),
        "{err}"
    );
    assert!(o.stdout.is_empty() && !out.exists());
    let long = "p".repeat(1024);
    assert!(
        run(&["--switches", "pq1.414"]).status.success(),
        "the plain cube meshes"
    );
    std::fs::remove_file(&out).unwrap();
    for sw in [long.as_str(), "q0.5", "q1.2/75", "a-1"] {
        let o = run(&["--switches", sw]);
        assert_eq!(o.status.code(), Some(1), "{sw}");
        assert!(
            String::from_utf8_lossy(&o.stderr).contains("switch"),
            "{sw}"
        );
        assert!(!out.exists());
    }
}

/// Issue 21: a seed inside the bounding box but outside the surface, and
/// one a single ulp outside a facet, are refused by the exact test before
/// TetGen sees them; a seed a single ulp inside meshes.
#[test]
fn seeds_are_located_exactly_before_tetgen() {
    use tetrefine::io::Region;
    let seed = |p: [f64; 3]| {
        let mut plc = cube_plc();
        plc.regions.push(Region {
            point: p,
            attribute: 3,
            max_volume: None,
        });
        tetrahedralize(&plc, &Options::default())
    };
    let up = f64::from_bits(1f64.to_bits() + 1);
    let down = f64::from_bits(1f64.to_bits() - 1);
    let e = seed([0.5, up, 0.5]).unwrap_err();
    assert!(e.to_string().contains("outside the surface"), "{e}");
    let m = seed([0.5, down, 0.5]).unwrap();
    assert!(m.tet_ids().all(|t| m.region(t) == 3));
    // Two cubes side by side with a gap: a seed in the gap.
    let mut two = cube_plc();
    let n = two.points.len() as u32;
    two.points
        .extend(cube_points().iter().map(|p| [p[0] + 2.0, p[1], p[2]]));
    for (m, q) in CUBE_QUADS.iter().enumerate() {
        two.facets.push(Facet {
            polygons: vec![q.iter().map(|&v| v + n).collect()],
            holes: vec![],
            marker: m as i32 + 7,
        });
    }
    two.regions.push(Region {
        point: [1.5, 0.5, 0.5],
        attribute: 3,
        max_volume: None,
    });
    let e = tetrahedralize(&two, &Options::default()).unwrap_err();
    assert!(e.to_string().contains("outside the surface"), "{e}");
}

/// Issue 21: `mesh --time-limit` stops a TetGen run that takes too long,
/// with a one-line error naming the limit and no output; the default
/// limit lets a normal run finish.
#[test]
fn mesh_time_limit_stops_a_long_tetgen_run_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.mesh");
    let input = support::root().join(EXAMPLE);
    // About five million tets: many seconds of TetGen on any machine.
    let o = tetrefine(&[
        "mesh",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--switches",
        "a0.00002",
        "--time-limit",
        "0.5",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--time-limit") && err.contains("0.5 s"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(o.stdout.is_empty());
    assert!(!out.exists());
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert!(left.is_empty(), "{left:?}");
    for bad in ["-1", "nan", "inf"] {
        let o = tetrefine(&[
            "mesh",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--time-limit",
            bad,
        ]);
        assert_eq!(o.status.code(), Some(1), "{bad}");
        assert!(String::from_utf8_lossy(&o.stderr).contains("--time-limit"));
    }
    let o = tetrefine(&["mesh", input.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    // TetGen runs in a child process: a crash of it (here a SIGSEGV sent
    // to the child) is a one-line error naming the input and the signal.
    std::fs::remove_file(&out).unwrap();
    let mut cli = Command::new(env!("CARGO_BIN_EXE_tetrefine"))
        .current_dir(support::root())
        .args(["mesh", input.to_str().unwrap(), "-o", out.to_str().unwrap()])
        .args(["--switches", "a0.00002"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let killed = kill_child_of(cli.id() as i32, None, libc::SIGSEGV, || {
        cli.try_wait().unwrap().is_some()
    });
    let o = cli.wait_with_output().unwrap();
    assert!(killed, "no TetGen child process was found");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with(&format!("error: {}: TetGen crashed", input.display()))
            && err.contains("signal 11 (SIGSEGV)")
            && err.contains("nothing was written"),
        "{err}"
    );
    assert!(o.stdout.is_empty() && !out.exists());
}

/// The children of process `parent` (from `/proc`), only those running
/// the program `exe` when given.
fn children_of(parent: i32, exe: Option<&Path>) -> Vec<i32> {
    let mut out = Vec::new();
    for e in std::fs::read_dir("/proc").unwrap().flatten() {
        let Ok(pid) = e.file_name().to_string_lossy().parse::<i32>() else {
            continue;
        };
        let Ok(stat) = std::fs::read_to_string(e.path().join("stat")) else {
            continue;
        };
        // pid (comm) state ppid …: comm may hold spaces, so split after ')'.
        let Some(rest) = stat.rsplit_once(')').map(|(_, r)| r) else {
            continue;
        };
        let ppid = rest.split_whitespace().nth(1).and_then(|x| x.parse().ok());
        if ppid != Some(parent) {
            continue;
        }
        if let Some(exe) = exe {
            if std::fs::read_link(e.path().join("exe")).ok().as_deref() != Some(exe) {
                continue;
            }
        }
        out.push(pid);
    }
    out
}

/// Whether process `pid` catches `signal` (its `SigCgt` mask in
/// `/proc/PID/status`); false once it is gone.
fn catches(pid: i32, signal: i32) -> bool {
    let Ok(status) = std::fs::read_to_string(format!("/proc/{pid}/status")) else {
        return false;
    };
    status
        .lines()
        .find_map(|l| l.strip_prefix("SigCgt:"))
        .and_then(|m| u64::from_str_radix(m.trim(), 16).ok())
        .is_some_and(|mask| mask & (1u64 << (signal - 1)) != 0)
}

/// Waits for a child of `parent` (running `exe` if given) to appear and
/// sends it `signal` once it no longer catches it; gives up when `done()`
/// says the run ended first.
/// Whether a child was signalled.
fn kill_child_of(
    parent: i32,
    exe: Option<&Path>,
    signal: i32,
    mut done: impl FnMut() -> bool,
) -> bool {
    loop {
        // A forked child still catches `signal` with the parent's handler
        // until it sets its own dispositions (Rust's runtime catches
        // SIGSEGV, and its handler lets one sent by `kill` pass): wait for
        // the child to stop catching it, or the signal can be lost.
        if let Some(&pid) = children_of(parent, exe)
            .iter()
            .find(|&&pid| !catches(pid, signal))
        {
            // SAFETY: kill has no memory preconditions; `pid` is a child of
            // `parent` that is still running or a zombie (not yet reaped).
            unsafe { libc::kill(pid, signal) };
            return true;
        }
        if done() {
            return false;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

/// Issue 21: `tetrefine::tetgen` runs TetGen in a child process when asked
/// (`Isolation::Child`): the result is the very mesh an in-process run
/// makes, a time limit stops a long run with `TimedOut`, and a child that
/// dies by a signal gives `Crashed` naming the signal, the caller unharmed.
/// One test, so that no other test's child process is mistaken for its own.
#[test]
fn tetgen_in_a_child_process_same_mesh_time_limit_and_crash() {
    use std::time::Duration;
    use tetrefine::tetgen::Isolation;
    let plc = Plc::read(&support::path(EXAMPLE)).unwrap();
    let base = Options {
        switches: Some("q1.414a0.01".into()),
        ..Default::default()
    };
    let in_process = tetrahedralize(&plc, &base).unwrap();
    let faces = |m: &TetMesh| {
        let mut f: Vec<_> = boundary_faces(m)
            .into_iter()
            .map(|(p, mk)| (p.map(|q| q.to_array().map(f64::to_bits)), mk))
            .collect();
        f.sort();
        f
    };
    let tets = |m: &TetMesh| -> Vec<([u32; 4], i32)> {
        m.tet_ids().map(|t| (m.tet(t), m.region(t))).collect()
    };
    for time_limit in [None, Some(Duration::from_secs(3600))] {
        let opts = Options {
            isolation: Isolation::Child { time_limit },
            ..base.clone()
        };
        let child = tetrahedralize(&plc, &opts).unwrap();
        assert_eq!(child.points(), in_process.points(), "{time_limit:?}");
        assert_eq!(tets(&child), tets(&in_process), "{time_limit:?}");
        assert_eq!(faces(&child), faces(&in_process), "{time_limit:?}");
        assert!(in_process.n_tets() > 1000);
    }
    // Refinement too.
    let coarse = tetrahedralize(&cube_plc(), &Options::default()).unwrap();
    let refine_opts = Options {
        max_volume: Some(0.01),
        ..Default::default()
    };
    let a = refine(&coarse, &refine_opts).unwrap();
    let b = refine(
        &coarse,
        &Options {
            isolation: Isolation::Child { time_limit: None },
            ..refine_opts
        },
    )
    .unwrap();
    assert_eq!(a.points(), b.points());
    assert_eq!(tets(&a), tets(&b));

    // A unit cube with a maximum volume of 2e-6: millions of tets, many
    // seconds of TetGen; the limit stops it.
    let long = Options {
        max_volume: Some(2e-6),
        isolation: Isolation::Child {
            time_limit: Some(Duration::from_millis(300)),
        },
        ..Default::default()
    };
    let e = tetrahedralize(&cube_plc(), &long).unwrap_err();
    assert!(matches!(e, TetgenError::TimedOut { .. }), "{e}");
    assert!(e.to_string().contains("did not finish within 0.3 s"), "{e}");
    good_call_still_works();
    let zero = Options {
        isolation: Isolation::Child {
            time_limit: Some(Duration::ZERO),
        },
        ..Default::default()
    };
    let e = tetrahedralize(&cube_plc(), &zero).unwrap_err();
    assert!(matches!(e, TetgenError::Options(_)), "{e}");

    // A crash: the same long run, its child killed with SIGSEGV.
    let me = std::process::id() as i32;
    let exe = std::env::current_exe().unwrap();
    let run = std::thread::spawn(|| {
        let opts = Options {
            max_volume: Some(2e-6),
            isolation: Isolation::Child {
                time_limit: Some(Duration::from_secs(600)),
            },
            ..Default::default()
        };
        tetrahedralize(&cube_plc(), &opts)
    });
    let killed = kill_child_of(me, Some(&exe), libc::SIGSEGV, || run.is_finished());
    let e = run.join().unwrap().unwrap_err();
    assert!(killed, "no TetGen child process was found");
    match &e {
        TetgenError::Crashed { signal, input, .. } => {
            assert_eq!(*signal, libc::SIGSEGV);
            assert_eq!(input, "meshing 8 points and 6 facets");
        }
        _ => panic!("{e}"),
    }
    assert!(e.to_string().contains("signal 11 (SIGSEGV)"), "{e}");
    good_call_still_works();
}
