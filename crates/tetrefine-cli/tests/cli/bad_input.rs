//! Malformed inputs (tests/bad/) never panic: the CLI exits non-zero with one
//! line on stderr naming the file and, where the file has lines, the line of
//! the fault; no output file and no temporary file is left behind.

/// Each bad file, the line its error must name (None: no line, e.g. binary
/// data or a problem with the whole file), and a word the message must hold.
const CASES: &[(&str, Option<usize>, &str)] = &[
    ("empty.mesh", None, "empty"),
    ("truncated.mesh", Some(13), "truncated"),
    ("negative_count.mesh", Some(4), "-5"),
    ("wrong_count.mesh", Some(10), "Tetrahedra"),
    ("not_a_mesh.mesh", Some(1), "hello"),
    ("nonmanifold.mesh", Some(13), "manifold"),
    ("zero_volume.mesh", Some(14), "zero volume"),
    ("repeated_vertex.mesh", Some(13), "repeats"),
    ("overlap.mesh", Some(13), "overlaps"),
    ("nan.msh", Some(8), "NaN"),
    ("duplicate_tet.msh", Some(16), "duplicates"),
    ("extra_node.msh", Some(14), "more than 4 nodes"),
    ("missing_nodes.msh", Some(6), "$Nodes"),
    ("bad_version.msh", Some(2), "3.0"),
    ("undefined_node_v41.msh", Some(19), "42"),
    ("wrong_block_count_v41.msh", Some(5), "announced"),
    ("truncated_v41_binary.msh", None, "at byte"),
    ("index_out_of_range.ele", Some(4), "out of range"),
    ("missing_ele.node", None, "no such file"),
    ("undefined_node.GiD.msh", Some(11), "99"),
    ("index_out_of_range.vtu", Some(9), "point 7"),
    ("bad_base64.vtu", Some(6), "base64"),
    ("truncated.vtu", Some(7), "truncated"),
    ("garbage.vtu", Some(1), "not a text file"),
    ("unknown_extension.xyz", None, "extension"),
];

/// Files of tests/bad/ that are not inputs of their own (`indicator/` holds
/// the malformed indicator files of tests/indicator.rs).
const SIBLINGS: &[&str] = &["README.md", "index_out_of_range.node", "indicator"];

fn bad_dir() -> std::path::PathBuf {
    crate::support::root().join("tests/bad")
}

#[test]
fn every_bad_file_is_listed_and_there_are_enough() {
    let mut listed: Vec<&str> = CASES
        .iter()
        .map(|c| c.0)
        .chain(SIBLINGS.iter().copied())
        .collect();
    listed.sort_unstable();
    let mut present: Vec<String> = std::fs::read_dir(bad_dir())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    present.sort_unstable();
    assert_eq!(present, listed);
    assert!(CASES.len() >= 15);
}

#[test]
fn bad_input_gives_one_clear_line_and_no_output() {
    for &(name, line, word) in CASES {
        let input = bad_dir().join(name);
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("OUT.vtu");
        let run = crate::tetrefine_command()
            .arg("convert")
            .arg(&input)
            .arg(&out)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(
            !run.status.success(),
            "{name}: exit status {:?}",
            run.status
        );
        assert!(!stderr.contains("panicked"), "{name}: {stderr}");
        let lines: Vec<&str> = stderr.lines().collect();
        assert_eq!(lines.len(), 1, "{name}: stderr is not one line: {stderr}");
        let msg = lines[0];
        // The file is named (TetGen errors may name the sibling of the same stem).
        let stem = name.split('.').next().unwrap();
        assert!(msg.contains(stem), "{name}: file not named: {msg}");
        match line {
            Some(l) => assert!(
                msg.contains(&format!("{name}:{l}: ")),
                "{name}: line {l} not named: {msg}"
            ),
            None => assert!(
                !msg.contains(&format!("{name}:")) || msg.contains(&format!("{name}: ")),
                "{name}: {msg}"
            ),
        }
        assert!(msg.contains(word), "{name}: '{word}' not in: {msg}");
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert!(left.is_empty(), "{name}: files left behind: {left:?}");
    }
}

/// Every prefix (at CUTS cut points) and CUTS single-byte corruptions of a valid
/// file of each format are read without a panic: an error or a mesh.
const CUTS: usize = 41;

#[test]
fn truncated_and_corrupted_files_never_panic() {
    let root = crate::support::root();
    let dir = tempfile::tempdir().unwrap();
    let (mesh, _) = tetrefine::io::load_mesh(&root.join("meshes/mmg_cube.mesh")).unwrap();
    // Our own outputs (compressed VTU, Gmsh 4.1 ASCII, TetGen), the files in
    // meshes/ and Gmsh's binary files.
    for ext in ["vtu", "msh", "ele"] {
        tetrefine::io::write_mesh(&dir.path().join(format!("own.{ext}")), &mesh).unwrap();
    }
    let mut sources: Vec<std::path::PathBuf> = ["own.vtu", "own.msh", "own.ele", "own.node"]
        .iter()
        .map(|n| dir.path().join(n))
        .collect();
    for n in [
        "meshes/mmg_cube.mesh",
        "meshes/mmg_cube.msh",
        "meshes/mmg_cube.vtu",
        "meshes/tripod.vtu",
    ] {
        sources.push(root.join(n));
    }
    for n in [
        "tests/data/mmg_cube_v41_binary.msh",
        "tests/data/mmg_cube_v22_binary.msh",
        "tests/data/mmg_cube_vtk_ascii.vtu",
        "tests/data/mmg_cube_vtk_appended_raw.vtu",
        "tests/data/mmg_cube_vtk_appended_base64_zlib.vtu",
        "tests/data/tetgen_example.1.face",
    ] {
        sources.push(root.join(n));
    }
    let gid = std::fs::read(root.join("meshes/tripod.GiD.msh")).unwrap();
    let small_gid = dir.path().join("small.GiD.msh");
    std::fs::write(&small_gid, &gid[..60_000]).unwrap();
    sources.push(small_gid);

    let work = tempfile::tempdir().unwrap();
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    for src in &sources {
        let bytes = std::fs::read(src).unwrap();
        let name = src.file_name().unwrap().to_string_lossy().into_owned();
        let target = work.path().join(&name);
        // TetGen: corrupt the named file, keep its siblings intact.
        for ext in ["node", "ele", "face", "edge"] {
            let sibling = src.with_extension(ext);
            if sibling != *src && sibling.exists() {
                let to = work.path().join(sibling.file_name().unwrap());
                std::fs::copy(&sibling, to).unwrap();
            }
        }
        for k in 0..CUTS {
            let cut = bytes.len() * k / CUTS;
            std::fs::write(&target, &bytes[..cut]).unwrap();
            let _ = tetrefine::io::load_mesh(&target);
            let mut bad = bytes.clone();
            let i = (next() % bytes.len() as u64) as usize;
            bad[i] = (next() % 256) as u8;
            std::fs::write(&target, &bad).unwrap();
            let _ = tetrefine::io::load_mesh(&target);
        }
    }
}
