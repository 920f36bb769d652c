//! `tetrefine quality` from the outside: the JSON contract of issue 2, the
//! histogram files, the table and option errors. Figures for the tripod are
//! the independent reference figures of the tripod (967 nodes, 7.56° worst).

use serde::de::{DeserializeSeed, Deserializer, IgnoredAny, MapAccess, Visitor};
use std::fmt;
use std::path::Path;
use std::process::Output;

use crate::{run as tetrefine, run_ok as ok};

const TRIPOD: &str = "meshes/tripod.mesh";
const TRIPOD_TETS: u64 = 2799;

fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8(o.stderr.clone()).unwrap()
}

/// Collects the keys of a JSON object in document order, nested keys as
/// `outer.inner` (serde_json's `Value` would sort them).
struct KeyPaths<'a> {
    prefix: String,
    out: &'a mut Vec<String>,
}

impl<'de> DeserializeSeed<'de> for KeyPaths<'_> {
    type Value = ();
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> Visitor<'de> for KeyPaths<'_> {
    type Value = ();
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("any JSON value")
    }
    fn visit_map<A: MapAccess<'de>>(self, mut m: A) -> Result<(), A::Error> {
        while let Some(k) = m.next_key::<String>()? {
            let path = format!("{}{k}", self.prefix);
            self.out.push(path.clone());
            m.next_value_seed(KeyPaths {
                prefix: format!("{path}."),
                out: &mut *self.out,
            })?;
        }
        Ok(())
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut s: A) -> Result<(), A::Error> {
        while s.next_element::<IgnoredAny>()?.is_some() {}
        Ok(())
    }
    fn visit_bool<E>(self, _: bool) -> Result<(), E> {
        Ok(())
    }
    fn visit_i64<E>(self, _: i64) -> Result<(), E> {
        Ok(())
    }
    fn visit_u64<E>(self, _: u64) -> Result<(), E> {
        Ok(())
    }
    fn visit_f64<E>(self, _: f64) -> Result<(), E> {
        Ok(())
    }
    fn visit_str<E>(self, _: &str) -> Result<(), E> {
        Ok(())
    }
    fn visit_unit<E>(self) -> Result<(), E> {
        Ok(())
    }
}

fn key_paths(json: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut d = serde_json::Deserializer::from_str(json);
    KeyPaths {
        prefix: String::new(),
        out: &mut out,
    }
    .deserialize(&mut d)
    .unwrap();
    d.end().unwrap();
    out
}

#[test]
fn json_has_exactly_the_fixed_keys_in_order_and_the_reference_figures() {
    let o = ok(&["quality", TRIPOD, "--json"]);
    let text = stdout(&o);
    // One JSON object on one line, nothing else on stdout.
    assert_eq!(text.lines().count(), 1, "{text}");
    assert_eq!(
        key_paths(&text),
        [
            "nodes",
            "edges",
            "tets",
            "boundary_faces",
            "interior_faces",
            "min_dihedral_deg",
            "min_dihedral_deg.worst",
            "min_dihedral_deg.avg",
            "min_dihedral_deg.best",
            "max_dihedral_deg",
            "max_dihedral_deg.worst",
            "max_dihedral_deg.avg",
            "valence",
            "valence.avg",
            "valence.max",
            "inverted",
            "volume",
            "regions",
            "regions.0",
            "histogram",
            "histogram.edges_deg",
            "histogram.counts",
            // Added by the features issue (the fixed keys stay first).
            "feature_edges",
            "corners",
        ]
    );
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["nodes"], 967);
    assert_eq!(v["edges"], 4621);
    assert_eq!(v["tets"], TRIPOD_TETS);
    assert_eq!(v["boundary_faces"], 1710);
    assert_eq!(v["interior_faces"], 4743);
    let close = |x: &serde_json::Value, want: f64| (x.as_f64().unwrap() - want).abs() < 0.01;
    assert!(close(&v["min_dihedral_deg"]["worst"], 7.56));
    assert!(close(&v["min_dihedral_deg"]["avg"], 42.92));
    assert!(close(&v["min_dihedral_deg"]["best"], 65.15));
    assert!(close(&v["valence"]["avg"], 9.56));
    assert_eq!(v["valence"]["max"], 27);
    assert_eq!(v["inverted"], 0);
    // The tripod file has no region refs other than 0: all tets in region 0.
    assert_eq!(v["regions"]["0"], TRIPOD_TETS);
    // A max angle is never below the min angle, and angles lie in (0°, 180°).
    let worst_max = v["max_dihedral_deg"]["worst"].as_f64().unwrap();
    let avg_max = v["max_dihedral_deg"]["avg"].as_f64().unwrap();
    assert!(avg_max > 42.92 && avg_max < worst_max && worst_max < 180.0);
    assert!(v["volume"].as_f64().unwrap() > 0.0);
    // Default histogram: 72 edges 0, 1, …, 71 and 71 counts summing to the tets.
    let edges: Vec<f64> = v["histogram"]["edges_deg"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(edges, (0..=71).map(f64::from).collect::<Vec<_>>());
    let counts: Vec<u64> = v["histogram"]["counts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap())
        .collect();
    assert_eq!(counts.len(), 71);
    assert_eq!(counts.iter().sum::<u64>(), TRIPOD_TETS);
    // The worst tet (7.56°) is in bin [7, 8); nothing lies below it, nothing
    // above the best (65.15°), which is in bin [65, 66).
    assert!(counts[7] >= 1 && counts[..7].iter().all(|&c| c == 0));
    assert!(counts[65] >= 1 && counts[66..].iter().all(|&c| c == 0));
}

#[test]
fn table_shows_the_paper_rows_with_two_decimals() {
    let o = ok(&["quality", TRIPOD]);
    let t = stdout(&o);
    let row = |label: &str| -> String {
        t.lines()
            .find(|l| l.starts_with(label))
            .unwrap_or_else(|| panic!("no {label} row in\n{t}"))[label.len()..]
            .trim()
            .to_string()
    };
    assert_eq!(row("nodes"), "967");
    assert_eq!(row("edges"), "4621");
    assert_eq!(row("tets"), "2799");
    assert_eq!(row("worst min dihedral (deg)"), "7.56");
    assert_eq!(row("average min dihedral (deg)"), "42.92");
    assert_eq!(row("best min dihedral (deg)"), "65.15");
    assert_eq!(row("average valence (edges)"), "9.56");
    assert_eq!(row("max valence (edges)"), "27");
    assert_eq!(row("boundary faces"), "1710");
    assert_eq!(row("interior faces"), "4743");
    assert_eq!(row("inverted tets"), "0");
}

fn csv_rows(path: &Path) -> Vec<(f64, f64, u64)> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("bin_lo_deg,bin_hi_deg,count"));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), 3, "{l}");
            (
                f[0].parse().unwrap(),
                f[1].parse().unwrap(),
                f[2].parse().unwrap(),
            )
        })
        .collect()
}

#[test]
fn csv_histogram_default_is_71_bins_of_one_degree() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("h.csv");
    ok(&["quality", TRIPOD, "--histogram", csv.to_str().unwrap()]);
    let rows = csv_rows(&csv);
    assert_eq!(rows.len(), 71);
    for (i, &(lo, hi, _)) in rows.iter().enumerate() {
        assert_eq!((lo, hi), (i as f64, i as f64 + 1.0));
    }
    assert_eq!(rows.iter().map(|r| r.2).sum::<u64>(), TRIPOD_TETS);
}

#[test]
fn csv_histogram_with_ten_bins() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("h.csv");
    ok(&[
        "quality",
        TRIPOD,
        "--histogram",
        csv.to_str().unwrap(),
        "--bins",
        "10",
    ]);
    let rows = csv_rows(&csv);
    assert_eq!(rows.len(), 10);
    assert_eq!(rows[0].0, 0.0);
    assert_eq!(rows[9].1, 71.0);
    for w in rows.windows(2) {
        assert_eq!(w[0].1, w[1].0, "bins are contiguous");
    }
    for r in &rows {
        assert!((r.1 - r.0 - 7.1).abs() < 1e-9);
    }
    assert_eq!(rows.iter().map(|r| r.2).sum::<u64>(), TRIPOD_TETS);
    // The --json histogram follows --bins too.
    let o = ok(&["quality", TRIPOD, "--json", "--bins", "10"]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["histogram"]["counts"].as_array().unwrap().len(), 10);
    assert_eq!(v["histogram"]["edges_deg"].as_array().unwrap().len(), 11);
}

#[test]
fn svg_histogram_is_xml_with_axis_labels() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("h.svg");
    let o = ok(&[
        "quality",
        TRIPOD,
        "--json",
        "--histogram",
        svg.to_str().unwrap(),
    ]);
    // --json stays pure JSON even when a histogram is written.
    serde_json::from_str::<serde_json::Value>(&stdout(&o)).unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    let (root, texts) = parse_xml(&text);
    assert_eq!(root, "svg");
    assert!(
        texts
            .iter()
            .any(|t| t == "minimum dihedral angle (degrees)"),
        "{texts:?}"
    );
    assert!(texts.iter().any(|t| t == "tetrahedra"), "{texts:?}");
    assert!(
        texts.iter().any(|t| t.starts_with("tripod.mesh")),
        "{texts:?}"
    );
}

/// Parses `text` with quick-xml, requiring a well-formed document with one
/// root element; returns the root's name and the trimmed text nodes.
fn parse_xml(text: &str) -> (String, Vec<String>) {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_str(text);
    reader.config_mut().check_end_names = true;
    let (mut depth, mut roots, mut root) = (0usize, 0usize, String::new());
    let mut texts = Vec::new();
    loop {
        match reader.read_event().expect("well-formed XML") {
            Event::Start(e) | Event::Empty(e) if depth == 0 => {
                roots += 1;
                root = String::from_utf8(e.name().as_ref().to_vec()).unwrap();
                if !text[..reader.buffer_position() as usize].ends_with("/>") {
                    depth += 1;
                }
            }
            Event::Start(_) => depth += 1,
            Event::End(_) => depth -= 1,
            Event::Text(t) => {
                let t = t.unescape().unwrap().trim().to_string();
                if !t.is_empty() {
                    assert!(depth > 0, "text outside the root element: {t}");
                    texts.push(t);
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    assert_eq!(depth, 0, "unclosed elements");
    assert_eq!(roots, 1, "one root element");
    (root, texts)
}

#[test]
fn png_histogram_has_the_signature_and_the_chosen_size() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("h.png");
    ok(&["quality", TRIPOD, "--histogram", png.to_str().unwrap()]);
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    // The first chunk is IHDR (length 13): width and height, big-endian.
    assert_eq!(&bytes[8..16], b"\0\0\0\x0dIHDR");
    let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    assert_eq!((w, h), (1024, 640));
    // And it decodes.
    let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png).unwrap();
    assert_eq!((img.width(), img.height()), (1024, 640));
}

fn assert_one_line_error(o: &Output, mentions: &str) {
    assert!(!o.status.success());
    assert!(o.stdout.is_empty(), "stdout: {}", stdout(o));
    let err = stderr(o);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains(mentions), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn bad_histogram_extension_fails_with_one_line_and_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("h.jpg");
    let o = tetrefine(&["quality", TRIPOD, "--histogram", bad.to_str().unwrap()]);
    assert_one_line_error(&o, "h.jpg");
    assert!(stderr(&o).contains(".csv, .svg or .png"));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn zero_bins_is_refused() {
    let o = tetrefine(&["quality", TRIPOD, "--bins", "0"]);
    assert_one_line_error(&o, "--bins");
}

#[test]
fn absurd_bin_counts_are_refused_not_allocated() {
    for bins in ["10001", "1000000000000"] {
        let o = tetrefine(&["quality", TRIPOD, "--bins", bins]);
        assert_one_line_error(&o, "--bins");
    }
    let o = tetrefine(&["quality", TRIPOD, "--bins", "-3"]);
    assert!(!o.status.success());
    assert!(o.stdout.is_empty());
}

#[test]
fn missing_input_names_the_file() {
    let o = tetrefine(&["quality", "meshes/no_such_mesh.mesh", "--json"]);
    assert_one_line_error(&o, "no_such_mesh.mesh");
}

#[test]
fn output_mesh_reads_back_with_the_same_figures() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("copy.mesh");
    ok(&["quality", TRIPOD, "--json", "-o", out.to_str().unwrap()]);
    let o = ok(&["quality", out.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["nodes"], 967);
    assert_eq!(v["edges"], 4621);
    assert_eq!(v["tets"], TRIPOD_TETS);
    assert_eq!(v["boundary_faces"], 1710);
    assert!((v["min_dihedral_deg"]["worst"].as_f64().unwrap() - 7.56).abs() < 0.01);
}

#[test]
fn bad_output_extension_fails_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("copy.xyz");
    let csv = dir.path().join("h.csv");
    let o = tetrefine(&[
        "quality",
        TRIPOD,
        "--histogram",
        csv.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_one_line_error(&o, "copy.xyz");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}
