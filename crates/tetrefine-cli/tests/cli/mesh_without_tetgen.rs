//! Without the `tetgen` feature, `tetrefine mesh` exists and fails with one
//! clear line.

#![cfg(not(feature = "tetgen"))]

#[test]
fn mesh_says_how_to_get_tetgen() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.mesh");
    let o = crate::tetrefine_command()
        .args(["mesh", "meshes/tetgen_example.poly", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(
        err,
        "error: built without TetGen: rebuild with `--features tetgen` (TetGen is AGPL-3)\n"
    );
    assert!(!out.exists());
}
