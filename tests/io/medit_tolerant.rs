//! Medit without surprises: other tools' keywords are skipped (a malformed
//! known section is still an error at its line), and binary `.meshb` files
//! MMG wrote read as the same mesh as the ASCII file it wrote in the same run
//! (`tests/data/mmg_cube_by_mmg.*`, `mmg3d_O3` 5.8 with every remeshing
//! operation off). MMG's own reader checks tetrefine's `.meshb` and `.solb`
//! in CI (`tests/mmg_roundtrip.py`).

use crate::support::path;
use tetrefine::io::read_mesh;

/// `meshes/mmg_cube.mesh` with other tools' sections inserted after
/// `Dimension 3` and before `End`.
fn with_foreign_keywords(extra_at_end: &str) -> String {
    let text = std::fs::read_to_string(path("meshes/mmg_cube.mesh")).unwrap();
    let foreign = "\nIdentifier\n\"cube 3 by MMG, 2 regions\"\n\nAngleOfCornerBound\n45\n\nSubDomainFromGeom\n1\n3 1 1\n\nTetrahedraP2\n1\n1 2 3 4 5 6 7 8 9 10 1\n\n";
    let text = text.replacen("Dimension 3\n", &format!("Dimension 3\n{foreign}"), 1);
    match text.rfind("End") {
        Some(i) => format!("{}{extra_at_end}\nEnd\n", &text[..i]),
        None => format!("{text}{extra_at_end}\n"),
    }
}

#[test]
fn other_tools_keywords_are_skipped_and_the_mesh_is_the_same() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("foreign.mesh");
    std::fs::write(&p, with_foreign_keywords("ISolAtVertices\n2\n1\n2\n")).unwrap();
    let plain = read_mesh(&path("meshes/mmg_cube.mesh")).unwrap();
    let mut got = read_mesh(&p).unwrap();
    got.tet_lines = plain.tet_lines.clone(); // the inserted lines shift them
    assert_eq!(got, plain);
}

#[test]
fn a_malformed_known_section_after_foreign_ones_is_still_an_error_at_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bad.mesh");
    // Two corners announced, one given, then a keyword.
    let text = with_foreign_keywords("Corners\n2\n1\nTetrahedraP2\n0\n");
    std::fs::write(&p, &text).unwrap();
    let line = text
        .lines()
        .position(|l| l == "TetrahedraP2")
        .map(|i| i + 1);
    let last = text
        .lines()
        .enumerate()
        .filter(|(_, l)| *l == "TetrahedraP2")
        .last()
        .unwrap()
        .0
        + 1;
    let err = read_mesh(&p).unwrap_err();
    assert_eq!(
        err.line,
        Some(last),
        "{err} (first TetrahedraP2 at {line:?})"
    );
    assert!(err.message().contains("vertex index"), "{err}");
}

#[test]
fn a_file_without_the_version_line_is_not_taken_for_a_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("text.mesh");
    std::fs::write(&p, "hello world\n").unwrap();
    let err = read_mesh(&p).unwrap_err();
    assert_eq!(err.line, Some(1));
}

#[test]
fn the_meshb_mmg_wrote_is_the_mesh_of_its_ascii_twin() {
    let b = read_mesh(&path("tests/data/mmg_cube_by_mmg.meshb")).unwrap();
    let a = read_mesh(&path("tests/data/mmg_cube_by_mmg.mesh")).unwrap();
    assert_eq!(b.tets, a.tets);
    assert_eq!(b.tet_regions, a.tet_regions);
    assert_eq!(b.triangles, a.triangles);
    assert_eq!(b.edges, a.edges);
    assert_eq!(b.corners, a.corners);
    assert_eq!(b.required_vertices, a.required_vertices);
    assert_eq!(b.points.len(), a.points.len());
    // MMG prints 15 significant digits in ASCII and stores doubles in binary.
    for (p, q) in b.points.iter().zip(&a.points) {
        for i in 0..3 {
            assert!(
                (p[i] - q[i]).abs() <= 1e-14 * (1.0 + q[i].abs()),
                "{p:?} {q:?}"
            );
        }
    }
    assert_eq!(a.tets.len(), 373);
    assert!(!a.edges.is_empty() && !a.corners.is_empty());
}

#[test]
fn a_truncated_or_corrupt_meshb_is_an_error_naming_a_byte() {
    let bytes = std::fs::read(path("tests/data/mmg_cube_by_mmg.meshb")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    for cut in [7, 20, 100, bytes.len() / 2, bytes.len() - 9] {
        let p = dir.path().join(format!("cut{cut}.meshb"));
        std::fs::write(&p, &bytes[..cut]).unwrap();
        let err = read_mesh(&p).unwrap_err();
        assert!(err.to_string().contains(p.to_str().unwrap()), "{err}");
    }
    // A vertex count larger than the file.
    let mut bad = bytes.clone();
    bad[28..32].copy_from_slice(&1_000_000i32.to_le_bytes());
    let p = dir.path().join("count.meshb");
    std::fs::write(&p, &bad).unwrap();
    let err = read_mesh(&p).unwrap_err().to_string();
    assert!(
        err.contains("at byte 28") && err.contains("1000000"),
        "{err}"
    );
}
