//! Medit from the command line: other tools' keywords give one note on
//! stderr, `--fields FILE.sol` with a wrong count is an error at its line
//! with nothing written, and `--fields-out` writes the fields back.

use crate::run;
use crate::support::path;

#[test]
fn foreign_keywords_give_exactly_one_note_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(path("meshes/mmg_cube.mesh")).unwrap();
    let text = text.replacen(
        "Dimension 3\n",
        "Dimension 3\nIdentifier\n\"from another tool\"\nAngleOfCornerBound\n45\nTetrahedraP2\n0\nIdentifier\n\"twice\"\n",
        1,
    );
    let p = dir.path().join("foreign.mesh");
    std::fs::write(&p, text).unwrap();
    let o = run(&["quality", p.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    let notes: Vec<&str> = err.lines().filter(|l| l.starts_with("note:")).collect();
    assert_eq!(notes.len(), 1, "{err}");
    for k in ["Identifier", "AngleOfCornerBound", "TetrahedraP2"] {
        assert!(notes[0].contains(k), "{k}: {err}");
    }
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["tets"], 373);
}

#[test]
fn fields_from_a_sol_go_out_again_and_a_wrong_count_is_an_error_at_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = path("meshes/mmg_cube.mesh");
    let sol = dir.path().join("h.sol");
    // 152 points: h = 1 + x + 2y + 3z is not needed exactly, only carried.
    let pts = tetrefine::io::read_mesh(&mesh).unwrap().points;
    let mut text = format!(
        "MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n{}\n1 1\n",
        pts.len()
    );
    for p in &pts {
        text += &format!("{:?}\n", 1.0 + p[0] + 2.0 * p[1] + 3.0 * p[2]);
    }
    std::fs::write(&sol, &text).unwrap();
    let out = dir.path().join("o.meshb");
    let solb = dir.path().join("o.solb");
    let o = run(&[
        "convert",
        mesh.to_str().unwrap(),
        out.to_str().unwrap(),
        "--fields",
        sol.to_str().unwrap(),
        "--fields-out",
        solb.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let back = tetrefine::io::read_sol(&solb).unwrap();
    assert_eq!(back.entries, pts.len());
    for (i, p) in pts.iter().enumerate() {
        assert_eq!(
            back.solutions[0].field.values[i],
            1.0 + p[0] + 2.0 * p[1] + 3.0 * p[2]
        );
    }

    // One entry fewer than the mesh has points.
    let short = dir.path().join("short.sol");
    std::fs::write(
        &short,
        text.replacen(
            &format!("\n{}\n1 1\n", pts.len()),
            &format!("\n{}\n1 1\n", pts.len() - 1),
            1,
        ),
    )
    .unwrap();
    let out2 = dir.path().join("o2.meshb");
    let o = run(&[
        "convert",
        mesh.to_str().unwrap(),
        out2.to_str().unwrap(),
        "--fields",
        short.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains(&format!("{}:4:", short.display())) && err.contains("151 entries"),
        "{err}"
    );
    assert!(!out2.exists());

    // A NaN.
    let nan = dir.path().join("nan.sol");
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    lines[7] = "NaN".into();
    std::fs::write(&nan, lines.join("\n")).unwrap();
    let o = run(&[
        "convert",
        mesh.to_str().unwrap(),
        out2.to_str().unwrap(),
        "--fields",
        nan.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains(&format!("{}:8:", nan.display())) && err.contains("finite"),
        "{err}"
    );
    assert!(!out2.exists());
}
