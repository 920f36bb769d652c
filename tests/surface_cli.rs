//! `tetrefine surface`: each scheme end to end on a file, and bad input
//! refused with a one-line error, a non-zero exit and no output file.

mod surface_common;

use std::path::Path;
use std::process::Command;
use surface_common::*;
use tetrefine::surface::{load_surface, write_surface};

fn run(args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_tetrefine"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
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
            vec!["surface", "catmull-clark", s(&quad), "-o", "out.stl"],
            "'.stl'",
        ),
    ];
    for (args, needle) in cases {
        let (ok, err) = run(&args);
        assert!(!ok, "{args:?} succeeded");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(!out.exists());
    }
}
