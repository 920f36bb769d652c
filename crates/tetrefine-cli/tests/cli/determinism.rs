//! The same input gives the same output, byte for byte, with 1 or 2 threads.

fn refine_with_threads(threads: &str, out: &std::path::Path, stats: &std::path::Path) {
    let o = crate::tetrefine_command()
        .env("RAYON_NUM_THREADS", threads)
        .args(["refine", "meshes/getfem_holed_bar.mesh", "-o"])
        .arg(out)
        .args(["--steps", "2", "--stats"])
        .arg(stats)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn one_and_two_threads_write_identical_files() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.vtu"), dir.path().join("b.vtu"));
    let (sa, sb) = (dir.path().join("a.json"), dir.path().join("b.json"));
    refine_with_threads("1", &a, &sa);
    refine_with_threads("2", &b, &sb);
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    // The statistics agree too (times and memory aside).
    let strip = |p: &std::path::Path| {
        let mut v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
        for s in v["steps"].as_array_mut().unwrap() {
            let o = s.as_object_mut().unwrap();
            o.remove("seconds");
            o.remove("phases");
            o.remove("peak_rss_bytes");
            if let Some(r) = o.get_mut("report").and_then(|r| r.as_object_mut()) {
                r.remove("seconds");
                r.remove("phases");
            }
        }
        v
    };
    assert_eq!(strip(&sa), strip(&sb));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&sa).unwrap()).unwrap();
    assert!(v["steps"][2]["peak_rss_bytes"].as_u64().unwrap() > 0);
}
