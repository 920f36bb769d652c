//! Issue 21, "nothing silently lost": readers hold what a file declares
//! against what it holds, a command's outputs appear together or not at all,
//! requests that cannot fit or select nothing are refused, and PLC seeds
//! outside the domain are refused before TetGen sees them.

use std::path::{Path, PathBuf};
use std::process::Command;
use tetrefine::io::{Facet, Plc, PlcError, Region};

fn meshes() -> PathBuf {
    crate::support::root().join("meshes")
}

use crate::{files_in, load_checked, refine_ok, run as tetrefine, stderr};

/// The unit tetrahedron's surface as `tet.obj` in `dir`, faces outward.
fn unit_tet_obj(dir: &Path) -> PathBuf {
    let tet = dir.join("tet.obj");
    std::fs::write(
        &tet,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n",
    )
    .unwrap();
    tet
}

/// The byte range of the raw appended data of a `.vtu` (after `_`, before
/// the closing tag).
fn appended_range(bytes: &[u8]) -> (usize, usize) {
    let find = |n: &[u8]| bytes.windows(n.len()).position(|w| w == n).unwrap();
    let start = find(b"<AppendedData");
    let under = start + bytes[start..].iter().position(|&c| c == b'_').unwrap() + 1;
    let end = bytes
        .windows(15)
        .rposition(|w| w == b"</AppendedData>")
        .unwrap();
    (under, end)
}

#[test]
fn every_duplicated_line_of_the_appended_data_of_mmg_cube_is_an_error_naming_an_array() {
    let path = meshes().join("mmg_cube.vtu");
    let bytes = std::fs::read(&path).unwrap();
    let (lo, hi) = appended_range(&bytes);
    // Line starts inside the appended data (a line ends at a '\n' byte).
    let mut starts = vec![lo];
    starts.extend((lo..hi).filter(|&i| bytes[i] == b'\n').map(|i| i + 1));
    starts.retain(|&s| s < hi);
    assert!(starts.len() > 50, "{} lines", starts.len());
    let dir = tempfile::tempdir().unwrap();
    let original = tetrefine::io::read_mesh(&path).unwrap();
    let (mut refused, mut same) = (0, 0);
    for w in starts.windows(2) {
        let (a, b) = (w[0], w[1]);
        let mut m = bytes[..b].to_vec();
        m.extend_from_slice(&bytes[a..b]);
        m.extend_from_slice(&bytes[b..]);
        let p = dir.path().join("cube.vtu");
        std::fs::write(&p, &m).unwrap();
        match tetrefine::io::read_mesh(&p) {
            Err(err) => {
                let msg = err.to_string();
                assert!(msg.starts_with(&p.display().to_string()), "{msg}");
                assert!(msg.contains("DataArray '"), "line at byte {a}: {msg}");
                refused += 1;
            }
            // Duplicating a lone '\n' inside a run of them (VTK type 10 is
            // byte 10) that reaches the end of the data only appends
            // whitespace: the file is then the same mesh, which is fine.
            Ok(d) => {
                assert_eq!(
                    b - a,
                    1,
                    "a duplicated line of {} bytes at {a} passed",
                    b - a
                );
                assert_eq!(
                    (&d.points, &d.tets, &d.triangles),
                    (&original.points, &original.tets, &original.triangles),
                    "line at byte {a} read as a different mesh"
                );
                same += 1;
            }
        }
    }
    assert!(refused >= 19, "{refused} refused, {same} unchanged");
}

#[test]
fn the_issue_case_names_the_array_on_the_command_line_and_writes_nothing() {
    let bytes = std::fs::read(meshes().join("mmg_cube.vtu")).unwrap();
    let (lo, hi) = appended_range(&bytes);
    // The first non-empty line of the data, duplicated.
    let first_nl = lo + bytes[lo..hi].iter().position(|&c| c == b'\n').unwrap() + 1;
    let second_nl = first_nl
        + bytes[first_nl..hi]
            .iter()
            .position(|&c| c == b'\n')
            .unwrap()
        + 1;
    let mut m = bytes[..second_nl].to_vec();
    m.extend_from_slice(&bytes[first_nl..second_nl]);
    m.extend_from_slice(&bytes[second_nl..]);
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("cube.vtu");
    std::fs::write(&p, &m).unwrap();
    let out = dir.path().join("out.vtu");
    for args in [
        vec!["quality", p.to_str().unwrap()],
        vec!["refine", p.to_str().unwrap(), "-o", out.to_str().unwrap()],
    ] {
        let o = tetrefine(&args);
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("cube.vtu:") && e.contains("DataArray '"), "{e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
    assert_eq!(files_in(dir.path()), vec!["cube.vtu".to_string()]);
}

#[test]
fn a_mixed_cell_vtu_keeps_tets_and_triangles_and_says_what_it_dropped() {
    let vtu = meshes().join("mmg_cube.vtu");
    let (data, note) = tetrefine::io::read_vtu_noted(&vtu).unwrap();
    // The same mesh from the Medit file (an independent reader).
    let medit = tetrefine::io::read_mesh(&meshes().join("mmg_cube.mesh")).unwrap();
    assert_eq!(data.tets.len(), medit.tets.len());
    assert_eq!(data.triangles.len(), medit.triangles.len());
    let note = note.expect("the edges are dropped with a note");
    assert!(note.contains("VTK type 3"), "{note}");
    let o = tetrefine(&["quality", vtu.to_str().unwrap(), "--json"]);
    assert!(o.status.success());
    assert!(
        stderr(&o).contains("dropped the other cells"),
        "{}",
        stderr(&o)
    );
}

/// The ASCII `.vtu` of tests/data with one substitution in its text.
fn ascii_vtu_with(dir: &Path, from: &str, to: &str) -> PathBuf {
    let src = crate::support::root().join("tests/data/mmg_cube_vtk_ascii.vtu");
    let text = std::fs::read_to_string(src).unwrap();
    assert!(text.contains(from), "{from}");
    let p = dir.join("a.vtu");
    std::fs::write(&p, text.replacen(from, to, 1)).unwrap();
    p
}

#[test]
fn declared_counts_types_and_offsets_are_held_against_the_data() {
    let dir = tempfile::tempdir().unwrap();
    let src = crate::support::root().join("tests/data/mmg_cube_vtk_ascii.vtu");
    let text = std::fs::read_to_string(&src).unwrap();
    assert!(tetrefine::io::read_mesh(&src).is_ok());
    // NumberOfCells one more than the arrays hold.
    let nc = text.split("NumberOfCells=\"").nth(1).unwrap();
    let nc: usize = nc[..nc.find('"').unwrap()].parse().unwrap();
    let p = ascii_vtu_with(
        dir.path(),
        &format!("NumberOfCells=\"{nc}\""),
        &format!("NumberOfCells=\"{}\"", nc + 1),
    );
    let e = tetrefine::io::read_mesh(&p).unwrap_err().to_string();
    assert!(e.contains(&format!("for {} cells", nc + 1)), "{e}");
    // A cell type outside VTK's set.
    let types_at = text.find("Name=\"types\"").unwrap();
    let body = &text[types_at..];
    let first = body[body.find('>').unwrap() + 1..]
        .split_whitespace()
        .next()
        .unwrap()
        .to_string();
    let mut t2 = text.clone();
    let at = types_at + body.find('>').unwrap() + 1;
    let pos = at + t2[at..].find(&first).unwrap();
    t2.replace_range(pos..pos + first.len(), "99");
    let p = dir.path().join("t.vtu");
    std::fs::write(&p, &t2).unwrap();
    let e = tetrefine::io::read_mesh(&p).unwrap_err().to_string();
    assert!(
        e.contains("type 99") && e.contains("not a VTK cell type"),
        "{e}"
    );
    assert!(e.starts_with(&format!("{}:", p.display())), "{e}");
}

#[test]
fn header_counts_larger_than_the_file_are_refused_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let off = dir.path().join("big.off");
    std::fs::write(&off, "OFF\n1073741823 1 0\n0 0 0\n").unwrap();
    let e = Plc::read(&off).unwrap_err().to_string();
    assert!(e.contains("cannot fit"), "{e}");
    let e = tetrefine_surface::io::load_surface(&off)
        .unwrap_err()
        .to_string();
    assert!(e.contains("cannot fit"), "{e}");
    let face = dir.path().join("face.off");
    std::fs::write(
        &face,
        "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4611686018427387904 0 1 2\n",
    )
    .unwrap();
    let o = tetrefine(&[
        "surface",
        "sqrt3",
        face.to_str().unwrap(),
        "-o",
        dir.path().join("o.obj").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("face.off:6:"), "{}", stderr(&o));
    let poly = dir.path().join("big.poly");
    std::fs::write(&poly, "1073741823 3 0 0\n1 0 0 0\n").unwrap();
    let e = Plc::read(&poly).unwrap_err().to_string();
    assert!(
        e.contains("big.poly:1:") && e.contains("values left"),
        "{e}"
    );
}

#[test]
fn a_tetgen_set_whose_files_disagree_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.node");
    let b = dir.path().join("b.node");
    let cube = meshes().join("mmg_cube.mesh");
    let tripod = meshes().join("tripod.mesh");
    assert!(
        tetrefine(&["convert", cube.to_str().unwrap(), a.to_str().unwrap()])
            .status
            .success()
    );
    assert!(
        tetrefine(&["convert", tripod.to_str().unwrap(), b.to_str().unwrap()])
            .status
            .success()
    );
    assert!(tetrefine::io::read_mesh(&a).is_ok());
    // The tripod's points under the cube's tets: the cube uses fewer points.
    std::fs::copy(&b, &a).unwrap();
    let e = tetrefine::io::read_mesh(&a).unwrap_err().to_string();
    assert!(e.contains("do not belong together"), "{e}");
}

#[test]
fn a_tetgen_output_replaces_the_whole_old_set() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.node");
    let cube = meshes().join("mmg_cube.mesh");
    let tripod = meshes().join("tripod.mesh");
    assert!(
        tetrefine(&["convert", tripod.to_str().unwrap(), out.to_str().unwrap()])
            .status
            .success()
    );
    // A failing second command (its histogram cannot be written) keeps the old set whole.
    let o = tetrefine(&[
        "quality",
        cube.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--histogram",
        dir.path().join("no/such/dir/h.csv").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let (m, _) = tetrefine::io::load_mesh(&out).unwrap();
    assert_eq!(m.n_tets(), 2799, "the tripod's set is intact");
    assert_eq!(
        files_in(dir.path()),
        vec!["o.edge", "o.ele", "o.face", "o.node"]
    );
}

#[test]
fn outputs_of_a_failed_command_never_appear_and_shared_paths_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let tripod = meshes().join("tripod.mesh");
    let t = tripod.to_str().unwrap();
    // The last output cannot be written: none of the others may appear.
    let o = tetrefine(&[
        "refine",
        t,
        "-o",
        &d("o.vtu"),
        "--parent-map",
        &d("p.txt"),
        "--stats",
        &d("s.json"),
        "--features-out",
        &d("missing/f.vtp"),
        "--opt-passes",
        "0",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("f.vtp"), "{}", stderr(&o));
    assert!(
        files_in(dir.path()).is_empty(),
        "{:?}",
        files_in(dir.path())
    );
    // Two outputs on one file, even spelled differently.
    let same = format!("{}/./x.vtu", dir.path().display());
    let o = tetrefine(&["refine", t, "-o", &d("x.vtu"), "--stats", &same]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("both name"), "{}", stderr(&o));
    let o = tetrefine(&["quality", t, "-o", &d("x.vtu"), "--histogram", &d("x.vtu")]);
    assert_eq!(o.status.code(), Some(1));
    assert!(files_in(dir.path()).is_empty());
}

#[test]
fn a_failed_write_to_standard_output_fails_the_command() {
    let tripod = meshes().join("tripod.mesh");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.mesh");
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_tetrefine"))
        .args(["quality", tripod.to_str().unwrap(), "--json", "-o"])
        .arg(&out)
        .stdout(full)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("standard output"), "{}", stderr(&o));
    assert!(!out.exists(), "no output after a failed command");
    // `>&-`: standard output closed when the command starts.
    let o = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "'{}' quality '{}' --json -o '{}' >&-",
            env!("CARGO_BIN_EXE_tetrefine"),
            tripod.display(),
            out.display()
        ))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("standard output"), "{}", stderr(&o));
    assert!(!out.exists(), "no output after a failed command");
    // `> /dev/null` is a place to write to, not an error.
    let o = Command::new(env!("CARGO_BIN_EXE_tetrefine"))
        .args(["quality", tripod.to_str().unwrap(), "--json"])
        .stdout(std::process::Stdio::null())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    // So is `/dev/null` opened read-write, as Python's subprocess.DEVNULL
    // does: after Rust's runtime reopens a closed descriptor it looks the
    // same, which is why the closed one is detected before `main`.
    let o = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "'{}' quality '{}' --json -o '{}' 1<>/dev/null",
            env!("CARGO_BIN_EXE_tetrefine"),
            tripod.display(),
            out.display()
        ))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.exists(), "the output is written");
}

#[test]
fn stale_temporaries_of_dead_processes_are_removed_and_live_ones_kept() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("o.mesh");
    // A pid beyond the kernel's maximum cannot be alive.
    let dead = dir.path().join(".o.mesh.tetrefine-4194999.tmp");
    let live = dir
        .path()
        .join(format!(".o.mesh.tetrefine-{}.tmp", std::process::id()));
    let other = dir.path().join(".o.mesh.4194999.tmp");
    for p in [&dead, &other] {
        std::fs::write(p, "old").unwrap();
    }
    // This test process is alive; a child removes its own name only.
    std::fs::write(&live, "mine").unwrap();
    let o = tetrefine(&[
        "convert",
        meshes().join("mmg_cube.mesh").to_str().unwrap(),
        target.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!dead.exists());
    assert!(live.exists(), "a running process's temporary file is kept");
    assert!(
        other.exists(),
        "only the tetrefine naming scheme is touched"
    );
}

/// SIGINT, SIGTERM and SIGHUP during a write each leave no temporary file.
#[test]
fn a_signal_during_a_write_leaves_no_temporary_file() {
    use std::os::unix::process::ExitStatusExt;
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("cube.mesh");
    // 30^3 * 6 = 162,000 tets: writing the .vtu takes a noticeable time.
    let data = tetrefine::cube_grid(30);
    let (mesh, _) = tetrefine::TetMesh::from_data(&data).unwrap();
    tetrefine::io::write_mesh(&input, &mesh).unwrap();
    let out = dir.path().join("o.vtu");
    for signal in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
        let mut caught = false;
        for _ in 0..5 {
            let mut child = Command::new(env!("CARGO_BIN_EXE_tetrefine"))
                .args(["convert", input.to_str().unwrap(), out.to_str().unwrap()])
                .spawn()
                .unwrap();
            let mut seen = false;
            // Until the temporary file appears or the command ends.
            loop {
                if files_in(dir.path())
                    .iter()
                    .any(|f| f.contains(".tetrefine-"))
                {
                    seen = true;
                    break;
                }
                if child.try_wait().unwrap().is_some() {
                    break;
                }
                std::thread::sleep(std::time::Duration::from_micros(200));
            }
            if seen {
                // SAFETY: sending a signal to our own child process.
                unsafe { libc::kill(child.id() as i32, signal) };
            }
            let status = child.wait().unwrap();
            let _ = std::fs::remove_file(&out);
            if seen && status.signal() == Some(signal) {
                assert_eq!(
                    files_in(dir.path()),
                    vec!["cube.mesh".to_string()],
                    "signal {signal}"
                );
                caught = true;
                break;
            }
        }
        assert!(caught, "signal {signal} never arrived during the write");
    }
}

#[test]
fn degenerate_and_empty_selections_and_steps_zero_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.mesh");
    let o_ = out.to_str().unwrap();
    let tripod = meshes().join("tripod.mesh");
    let t = tripod.to_str().unwrap();
    let cases: [(&[&str], &str); 10] = [
        (&["--steps", "0"], "--steps 0"),
        (&["--box", "0,0,0,0,1,1"], "zero extent along x"),
        (&["--box", "1,1,1,0,0,0"], "inverted along x"),
        (&["--mark", "box:-50,50,-50,50,-50,50"], "inverted along y"),
        (&["--sphere", "0,0,0,0"], "radius"),
        (&["--mark", "region:0,99"], "no region 99"),
        (&["--sphere", "0,0,0,-1"], "radius"),
        (&["--region", "99"], "no region 99"),
        (&["--sphere", "1e6,1e6,1e6,1"], "selects none"),
        (&["--box", "1e6,1e6,1e6,2e6,2e6,2e6"], "selects none"),
    ];
    for (extra, word) in cases {
        let mut args = vec!["refine", t, "-o", o_];
        args.extend_from_slice(extra);
        let o = tetrefine(&args);
        assert_eq!(o.status.code(), Some(1), "{extra:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(word), "{extra:?}: {}", stderr(&o));
        assert!(!out.exists());
    }
    // Explicitly allowed: the mesh is written unrefined.
    for extra in [
        &["--steps", "0", "--allow-steps-zero"][..],
        &["--sphere", "1e6,1e6,1e6,1", "--allow-empty"][..],
    ] {
        let mut args = vec!["refine", t, "-o", o_];
        args.extend_from_slice(extra);
        let o = tetrefine(&args);
        assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
        let (m, _) = tetrefine::io::load_mesh(&out).unwrap();
        assert_eq!(m.n_tets(), 2799);
        std::fs::remove_file(&out).unwrap();
    }
}

#[test]
fn a_refinement_that_cannot_fit_is_refused_before_any_work_naming_the_step() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.mesh");
    let tripod = meshes().join("tripod.mesh");
    let t0 = std::time::Instant::now();
    let o = tetrefine(&[
        "refine",
        tripod.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--steps",
        "1000",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("would not fit in memory") && e.contains("MemAvailable"),
        "{e}"
    );
    // 2,799 tets grow ×6.3 per step: with 24 GB or less, step 9 cannot fit.
    let step: usize = e
        .split("step ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!((5..=12).contains(&step), "{e}");
    assert!(t0.elapsed().as_secs() < 20, "refused before the work");
    // With --max-memory 1M, even the first step (17.6k output tets, 1.8 MB) is refused.
    let o = tetrefine(&[
        "refine",
        tripod.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--max-memory",
        "1M",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("step 1 would not fit") && stderr(&o).contains("--max-memory"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
}

#[test]
fn a_mesh_read_from_a_named_pipe_works() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["p.msh", "p.vtu", "p.mesh"] {
        let fifo = dir.path().join(name);
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: mkfifo on a fresh path in our temporary directory.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let src = meshes().join(name.replace("p.", "mmg_cube."));
        let writer = std::thread::spawn({
            let fifo = fifo.clone();
            move || {
                let bytes = std::fs::read(src).unwrap();
                std::fs::write(fifo, bytes).unwrap();
            }
        });
        let o = tetrefine(&["quality", fifo.to_str().unwrap(), "--json"]);
        writer.join().unwrap();
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert!(v["tets"].as_u64().unwrap() > 300, "{name}");
    }
}

/// A unit cube as six quadrilateral facets.
fn cube() -> Plc {
    let points: Vec<[f64; 3]> = (0..8)
        .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
        .collect();
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    Plc {
        points,
        facets: quads
            .iter()
            .enumerate()
            .map(|(i, q)| Facet {
                polygons: vec![q.to_vec()],
                holes: Vec::new(),
                marker: i as i32,
            })
            .collect(),
        ..Default::default()
    }
}

#[test]
fn region_seeds_outside_the_domain_or_in_a_hole_are_refused() {
    let seed = |p: [f64; 3]| Region {
        point: p,
        attribute: 7,
        max_volume: None,
    };
    let mut ok = cube();
    ok.regions.push(seed([0.5, 0.5, 0.5]));
    assert!(ok.validate().is_ok());
    for p in [[0.5, 0.5, 2.0], [0.5, 1e308, 0.5], [-1e-300, 0.5, 0.5]] {
        let mut c = cube();
        c.regions.push(seed(p));
        assert!(
            matches!(c.validate(), Err(PlcError::SeedOutside { index: 1, .. })),
            "{p:?}: {:?}",
            c.validate()
        );
    }
    // A cube inside a cube, the inner one a hole: a seed there would vanish.
    let mut c = cube();
    let inner = cube();
    let base = c.points.len() as u32;
    c.points
        .extend(inner.points.iter().map(|p| p.map(|x| 0.25 + 0.5 * x)));
    for f in inner.facets {
        c.facets.push(Facet {
            polygons: vec![f.polygons[0].iter().map(|v| v + base).collect()],
            holes: Vec::new(),
            marker: 9,
        });
    }
    c.holes.push([0.5, 0.5, 0.5]);
    assert!(c.validate().is_ok());
    c.regions.push(seed([0.5, 0.5, 0.5]));
    assert!(
        matches!(
            c.validate(),
            Err(PlcError::SeedInHole {
                index: 1,
                hole: 1,
                ..
            })
        ),
        "{:?}",
        c.validate()
    );
}

#[test]
fn surfaces_at_1e300_and_1e_minus_300_are_judged_by_their_shape() {
    for scale in [1e300, 1e-300, 1e150, 3.0] {
        let mut c = cube();
        for p in &mut c.points {
            *p = p.map(|x| x * scale);
        }
        let v = c.analyze().unwrap_or_else(|e| panic!("{scale}: {e}"));
        assert_eq!(v.cells, 1, "{scale}");
        let want = scale * scale * scale;
        if want.is_finite() && want > 0.0 {
            assert!(
                (v.enclosed - want).abs() <= 1e-12 * want,
                "{scale}: {}",
                v.enclosed
            );
        }
        // Flat at any scale is still flat.
        let mut flat = c.clone();
        for p in &mut flat.points {
            p[2] = 0.0;
        }
        assert!(flat.validate().is_err(), "{scale}");
    }
}

#[test]
fn a_non_manifold_boundary_is_accepted_with_a_note_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, pts: &[[f64; 3]], tets: &[[u32; 4]]| {
        let mut s = String::from("MeshVersionFormatted 2\nDimension 3\nVertices\n");
        s += &format!("{}\n", pts.len());
        for p in pts {
            s += &format!("{} {} {} 0\n", p[0], p[1], p[2]);
        }
        s += &format!("Tetrahedra\n{}\n", tets.len());
        for t in tets {
            s += &format!("{} {} {} {} 1\n", t[0], t[1], t[2], t[3]);
        }
        s += "End\n";
        let p = dir.path().join(name);
        std::fs::write(&p, s).unwrap();
        p
    };
    // Two tets sharing only the edge 1-2 (1-based), on opposite sides.
    let edge = write(
        "edge.mesh",
        &[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, -1.0],
        ],
        &[[1, 2, 3, 4], [1, 2, 5, 6]],
    );
    // Two tets sharing only vertex 1.
    let vertex = write(
        "vertex.mesh",
        &[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [-1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, -1.0],
        ],
        &[[1, 2, 3, 4], [1, 5, 6, 7]],
    );
    let o = tetrefine(&["quality", edge.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("not a manifold") && e.contains("joins vertices 1 and 2"),
        "{e}"
    );
    let o = tetrefine(&["quality", vertex.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("not a manifold") && e.contains("the first is vertex 1"),
        "{e}"
    );
    // A manifold mesh gets no such note.
    let o = tetrefine(&[
        "quality",
        meshes().join("tripod.mesh").to_str().unwrap(),
        "--json",
    ]);
    assert!(!stderr(&o).contains("manifold"), "{}", stderr(&o));
}

#[test]
fn a_neck_or_cut_so_small_that_points_coincide_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let tet = unit_tet_obj(dir.path());
    let cube = dir.path().join("cube.obj");
    std::fs::write(
        &cube,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n",
    )
    .unwrap();
    let out = dir.path().join("o.obj");
    let o_ = out.to_str().unwrap();
    let surface = |scheme: &str, input: &Path, extra: &[&str]| {
        let mut args = vec!["surface", scheme, input.to_str().unwrap(), "-o", o_];
        args.extend_from_slice(&["--steps", "2"]);
        args.extend_from_slice(extra);
        tetrefine(&args)
    };
    for (scheme, input, opt, v) in [
        ("sierpinski", &tet, "--neck", "1e-300"),
        ("sierpinski", &tet, "--neck", "1e-17"),
        ("truncate", &cube, "--cut", "1e-300"),
        ("truncate", &cube, "--cut", "1e-17"),
    ] {
        let o = surface(scheme, input, &[opt, v]);
        assert_eq!(
            o.status.code(),
            Some(1),
            "{scheme} {opt} {v}: {}",
            stderr(&o)
        );
        let e = stderr(&o);
        assert!(
            e.contains("coincident") || e.contains("zero area") || e.contains(opt),
            "{e}"
        );
        assert!(!out.exists());
    }
    // The defaults are fine.
    for (scheme, input) in [("sierpinski", &tet), ("truncate", &cube)] {
        let o = surface(scheme, input, &[]);
        assert!(o.status.success(), "{scheme}: {}", stderr(&o));
    }
}

/// Tets whose Jacobian determinant in doubles is not positive.
fn solver_inverted(path: &Path) -> usize {
    let (m, _) = tetrefine::io::load_mesh(path).unwrap();
    m.tet_ids()
        .filter(|&t| {
            let p = m.tet_points(t);
            let det = (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0]));
            det.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
        })
        .count()
}

#[test]
fn refined_tets_are_positive_in_doubles_too() {
    // The issue's case: two steps without optimization, and stopping after
    // each topological phase.
    let dir = tempfile::tempdir().unwrap();
    for (mesh, extra) in [
        ("gmsh_t16.msh", &["--steps", "2", "--opt-passes", "0"][..]),
        (
            "gmsh_t16.msh",
            &["--steps", "2", "--stop-after", "flip"][..],
        ),
        (
            "gmsh_t16.msh",
            &["--steps", "2", "--stop-after", "boundary-flip"][..],
        ),
        ("mmg_cube.mesh", &["--steps", "2", "--opt-passes", "0"][..]),
    ] {
        let out = dir.path().join("o.mesh");
        let mut args = vec!["refine", "-o", out.to_str().unwrap()];
        let input = meshes().join(mesh);
        args.insert(1, input.to_str().unwrap());
        args.extend_from_slice(extra);
        let o = tetrefine(&args);
        assert!(o.status.success(), "{mesh} {extra:?}: {}", stderr(&o));
        assert_eq!(solver_inverted(&out), 0, "{mesh} {extra:?}");
    }
}

#[test]
fn the_linear_rule_keeps_a_flat_tet_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("flat.mesh");
    std::fs::write(
        &input,
        "MeshVersionFormatted 2\nDimension 3\nVertices\n4\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0.3 0.3 0.1 0\nTetrahedra\n1\n1 2 3 4 1\nEnd\n",
    )
    .unwrap();
    // Base area 1/2, height 0.1.
    let want = 0.5 * 0.1 / 3.0;
    for steps in ["1", "2"] {
        let out = dir.path().join("o.mesh");
        refine_ok(
            input.to_str().unwrap(),
            &out,
            &["--boundary", "linear", "--steps", steps],
        );
        let m = load_checked(&out);
        assert!(m.n_tets() > 1, "refined");
        let v: f64 = m
            .tet_ids()
            .map(|t| {
                let p = m.tet_points(t);
                (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / 6.0
            })
            .sum();
        assert!(
            (v - want).abs() <= 1e-12 * want,
            "{steps} steps: {v} vs {want}"
        );
    }
}

#[test]
fn fuzz_findings_in_tests_bad_surface_give_one_line_naming_the_file() {
    // A cube whose vertex order a mutation twisted: a valid oriented
    // manifold whose Catmull–Clark face points coincide (the fuzzer found
    // the error line did not name the file).
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.obj");
    let bad = crate::support::root().join("tests/bad/surface/twisted_cube.off");
    let o = tetrefine(&[
        "surface",
        "catmull-clark",
        bad.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(
        e.contains("twisted_cube.off") && e.contains("coincident"),
        "{e}"
    );
    assert!(!out.exists());
}

/// Issue 21: the memory guard also holds each refine step's real counts
/// against the budget (the tripod grows faster than the ×6.3 projection,
/// so a budget between the two lets the plan pass and refuses step 2 by
/// name), and it guards `bisect` and `improve`.
#[test]
fn the_memory_guard_checks_each_step_and_bisect_and_improve() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.mesh");
    let (t, o_) = (
        meshes().join("tripod.mesh"),
        out.to_str().unwrap().to_string(),
    );
    let t = t.to_str().unwrap();
    // Projected: step 2 needs 11.3 MB; really 34,056 tets enter it (with
    // the long-edge rounds): about 20.6 MiB, so 24M lets it through.
    let o = tetrefine(&[
        "refine",
        t,
        "-o",
        &o_,
        "--steps",
        "2",
        "--max-memory",
        "13M",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("step 2 would not fit") && stderr(&o).contains("--max-memory"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
    let o = tetrefine(&[
        "refine",
        t,
        "-o",
        &o_,
        "--steps",
        "2",
        "--max-memory",
        "24M",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::remove_file(&out).unwrap();
    // bisect: refused before any work, naming the step.
    let t0 = std::time::Instant::now();
    let o = tetrefine(&["bisect", t, "-o", &o_, "--steps", "30"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("bisect step") && stderr(&o).contains("would not fit"),
        "{}",
        stderr(&o)
    );
    assert!(t0.elapsed().as_secs() < 20 && !out.exists());
    // 22,392 output tets of step 1 at 100 bytes: more than 1 MiB.
    let o = tetrefine(&["bisect", t, "-o", &o_, "--max-memory", "1M"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("bisect step 1 would not fit"),
        "{}",
        stderr(&o)
    );
    assert!(o.stdout.is_empty() && !out.exists());
    let o = tetrefine(&["bisect", t, "-o", &o_, "--max-memory", "8M"]);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::remove_file(&out).unwrap();
    // improve: 2,799 tets at 200 bytes is more than 100 KiB.
    let o = tetrefine(&["improve", t, "-o", &o_, "--max-memory", "100K"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("improve would not fit"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
    let o = tetrefine(&["improve", t, "-o", &o_, "--max-memory", "0"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("--max-memory"), "{}", stderr(&o));
    let o = tetrefine(&[
        "improve",
        t,
        "-o",
        &o_,
        "--max-memory",
        "1G",
        "--opt-passes",
        "1",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Issue 21: `surface` steps are guarded by memory as `refine` is: a run
/// whose projected output would not fit `--max-memory` is refused before
/// any work, with no output.
#[test]
fn surface_steps_are_held_against_the_memory_budget() {
    let dir = tempfile::tempdir().unwrap();
    let tet = unit_tet_obj(dir.path());
    let out = dir.path().join("o.obj");
    let run = |steps: &str, mem: &str| {
        tetrefine(&[
            "surface",
            "loop",
            tet.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--steps",
            steps,
            "--max-memory",
            mem,
        ])
    };
    // 12 sides × 4⁵ = 12,288 projected faces at 300 bytes: 3.7 MB.
    let o = run("6", "1M");
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("6 steps would not fit in memory")
            && stderr(&o).contains("--max-memory"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
    let o = run("3", "1M");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.exists());
}
