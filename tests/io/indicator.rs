//! Indicator files: every format gives the same values (bit for bit) and so
//! the same selection; `SolAtVertices` gives each tet the maximum of its
//! vertices; VTU cell arrays are read in each data layout VTK writes, at the
//! tetrahedra only; and each malformed file of tests/bad/indicator/ gives an
//! error naming the file, the line and what was expected.

use crate::support::{kuhn_mesh, Rng};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use tetrefine::io::{read_indicator, IndicatorSource};
use tetrefine::io::{write_vtu, CellArray};
use tetrefine::TetMesh;
use tetrefine::{select, MarkStrategy};

/// Values of all kinds of magnitudes, with ties and zeros.
fn sample_values(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|i| match i % 7 {
            0 => 0.0,
            1 => 0.5,
            _ => rng.next_f64().powi(3) * 10f64.powi(rng.below(9) as i32 - 4),
        })
        .collect()
}

fn spec(p: &Path) -> String {
    p.to_str().unwrap().to_string()
}

/// Writes `values` in every format and returns the specs.
fn write_all_formats(dir: &Path, mesh: &TetMesh, values: &[f64]) -> Vec<String> {
    let n = values.len();
    let mut specs = Vec::new();

    // Plain text, shortest round-trip notation, with comments and blank lines.
    let mut txt = String::from("# error indicator, one value per tet\n\n");
    for (t, v) in values.iter().enumerate() {
        if t % 10 == 3 {
            txt.push('\n');
        }
        writeln!(txt, "{v}  # tet {t}").unwrap();
    }
    let p = dir.join("eta.txt");
    std::fs::write(&p, &txt).unwrap();
    specs.push(spec(&p));

    // .dat in exponent notation (Fortran 'D' for every third value), CRLF lines.
    let mut dat = String::new();
    for (t, v) in values.iter().enumerate() {
        let s = format!("{v:e}");
        let s = if t % 3 == 0 { s.replace('e', "D") } else { s };
        write!(dat, "  {s}\r\n").unwrap();
    }
    let p = dir.join("eta.dat");
    std::fs::write(&p, &dat).unwrap();
    specs.push(spec(&p));

    // No extension.
    let p = dir.join("eta");
    std::fs::write(&p, &txt).unwrap();
    specs.push(spec(&p));

    // CSV, rows shuffled, with a header naming the columns in swapped order.
    let mut order: Vec<usize> = (0..n).collect();
    let mut rng = Rng(4242);
    for i in (1..n).rev() {
        order.swap(i, rng.below(i as u64 + 1) as usize);
    }
    assert_ne!(order, (0..n).collect::<Vec<_>>());
    let mut csv = String::from("\u{feff}value,tet\n"); // with a byte-order mark
    for &t in &order {
        writeln!(csv, "{},{t}", values[t]).unwrap();
    }
    let p = dir.join("eta_header.csv");
    std::fs::write(&p, &csv).unwrap();
    specs.push(spec(&p));

    // CSV without header, reverse order, spaces and a comment.
    let mut csv = String::from("# tet, value\n");
    for t in (0..n).rev() {
        writeln!(csv, "{t} , {:e}", values[t]).unwrap();
    }
    let p = dir.join("eta_plain.csv");
    std::fs::write(&p, &csv).unwrap();
    specs.push(spec(&p));

    // MMG .sol, SolAtTetrahedra.
    let mut sol = format!("MeshVersionFormatted 2\n\nDimension 3\n\nSolAtTetrahedra\n{n}\n1 1\n\n");
    for v in values {
        writeln!(sol, "{v:e}").unwrap();
    }
    sol.push_str("\nEnd\n");
    let p = dir.join("eta.sol");
    std::fs::write(&p, &sol).unwrap();
    specs.push(spec(&p));

    // A .vtu with the values as an extra cell array.
    let p = dir.join("eta.vtu");
    write_vtu(
        &p,
        mesh,
        None,
        &[CellArray::Float64("eta".into(), values.to_vec())],
    )
    .unwrap();
    specs.push(format!("{}:eta", spec(&p)));
    specs
}

#[test]
fn every_format_gives_the_same_values_and_selection() {
    let (_, mesh) = kuhn_mesh(3, 2, 2);
    let n = mesh.n_tets();
    assert_eq!(n, 72);
    let values = sample_values(n, 0x5eed);
    let dir = tempfile::tempdir().unwrap();
    let specs = write_all_formats(dir.path(), &mesh, &values);
    assert_eq!(specs.len(), 7);
    let strategies: Vec<MarkStrategy> =
        ["fraction:0.2", "doerfler:0.5", "max:0.3", "threshold:0.01"]
            .iter()
            .map(|s| s.parse().unwrap())
            .collect();
    let reference: Vec<Vec<bool>> = strategies
        .iter()
        .map(|s| select(s, Some(&values), &mesh).unwrap())
        .collect();
    for s in &specs {
        let got = read_indicator(s, &mesh).unwrap_or_else(|e| panic!("{s}: {e}"));
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&got), bits(&values), "{s}");
        for (st, want) in strategies.iter().zip(&reference) {
            assert_eq!(&select(st, Some(&got), &mesh).unwrap(), want, "{s} {st}");
        }
    }
}

#[test]
fn sol_at_vertices_gives_each_tet_the_max_of_its_vertices() {
    let (d, mesh) = kuhn_mesh(2, 2, 1);
    let np = d.points.len();
    let mut rng = Rng(31);
    let pv: Vec<f64> = (0..np).map(|_| (rng.below(1000) as f64) / 8.0).collect();
    let mut sol =
        format!("MeshVersionFormatted 1\nDimension 3\n# per vertex\nSolAtVertices\n{np}\n1 1\n");
    for v in &pv {
        writeln!(sol, "{v}").unwrap();
    }
    sol.push_str("End\n");
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("nodal.sol");
    std::fs::write(&p, sol).unwrap();
    let got = read_indicator(&spec(&p), &mesh).unwrap();
    // From the plain data: the file's tets, the file's vertex numbers.
    let want: Vec<f64> = d
        .tets
        .iter()
        .map(|t| t.iter().map(|&v| pv[v as usize]).fold(f64::MIN, f64::max))
        .collect();
    assert_eq!(got, want);
    // At least one tet whose max is not at its first vertex, so the test can
    // tell the maximum from a single vertex.
    assert!(d
        .tets
        .iter()
        .zip(&want)
        .any(|(t, &w)| pv[t[0] as usize] < w));
}

#[test]
fn sol_sections_that_are_not_the_indicator_are_skipped() {
    let (_, mesh) = kuhn_mesh(1, 1, 1);
    // A vector field on 2 triangles before the tets' scalar.
    let sol = "MeshVersionFormatted 2\nDimension 3\nSolAtTriangles\n2\n1 2\n1 2 3\n4 5 6\n\
               SolAtTetrahedra\n6\n1 1\n0 1 2 3 4 5\nEnd\n";
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("mixed.sol");
    std::fs::write(&p, sol).unwrap();
    assert_eq!(
        read_indicator(&spec(&p), &mesh).unwrap(),
        vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0]
    );
}

#[test]
fn vtu_array_is_read_at_the_tetrahedra_only() {
    // Two tets on either side of the triangle (1,2,3), listed with the
    // triangle between them: the array's middle value belongs to no tet.
    let vtu = r#"<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian">
  <UnstructuredGrid>
    <Piece NumberOfPoints="5" NumberOfCells="3">
      <Points>
        <DataArray type="Float64" NumberOfComponents="3" format="ascii">0 0 0 1 0 0 0 1 0 0 0 1 1 1 1</DataArray>
      </Points>
      <Cells>
        <DataArray type="Int32" Name="connectivity" format="ascii">0 1 2 3 1 2 3 1 2 3 4</DataArray>
        <DataArray type="Int32" Name="offsets" format="ascii">4 7 11</DataArray>
        <DataArray type="UInt8" Name="types" format="ascii">10 5 10</DataArray>
      </Cells>
      <CellData>
        <DataArray type="Float32" Name="err:h1" format="ascii">0.5 9 0.25</DataArray>
        <DataArray type="Int64" Name="count" format="ascii">3 99 7</DataArray>
      </CellData>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
"#;
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("mixed.vtu");
    std::fs::write(&p, vtu).unwrap();
    let (mesh, _) = tetrefine::io::load_mesh(&p).unwrap();
    assert_eq!(mesh.n_tets(), 2);
    // Tet 0 holds point 0, tet 1 point 4, as in the file.
    assert!(mesh.tet(0).contains(&0) && mesh.tet(1).contains(&4));
    let s = format!("{}:err:h1", spec(&p));
    assert_eq!(
        IndicatorSource::parse(&s).unwrap(),
        IndicatorSource::VtuArray(p.clone(), "err:h1".into())
    );
    assert_eq!(read_indicator(&s, &mesh).unwrap(), vec![0.5, 0.25]);
    assert_eq!(
        read_indicator(&format!("{}:count", spec(&p)), &mesh).unwrap(),
        vec![3.0, 7.0]
    );
}

#[test]
fn vtu_array_spans_every_piece_in_file_order() {
    // The same two tets as above, one per piece, the second piece numbering
    // its points from 0 again.
    let piece = |pts: &str, val: &str| {
        format!(
            r#"    <Piece NumberOfPoints="4" NumberOfCells="1">
      <Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">{pts}</DataArray></Points>
      <Cells>
        <DataArray type="Int32" Name="connectivity" format="ascii">0 1 2 3</DataArray>
        <DataArray type="Int32" Name="offsets" format="ascii">4</DataArray>
        <DataArray type="UInt8" Name="types" format="ascii">10</DataArray>
      </Cells>
      <CellData><DataArray type="Float64" Name="eta" format="ascii">{val}</DataArray></CellData>
    </Piece>
"#
        )
    };
    let vtu = format!(
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\">\n  <UnstructuredGrid>\n{}{}  </UnstructuredGrid>\n</VTKFile>\n",
        piece("0 0 0 1 0 0 0 1 0 0 0 1", "0.75"),
        piece("1 0 0 0 1 0 0 0 1 1 1 1", "2.5")
    );
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("pieces.vtu");
    std::fs::write(&p, vtu).unwrap();
    let (mesh, _) = tetrefine::io::load_mesh(&p).unwrap();
    assert_eq!(mesh.n_tets(), 2);
    // Tet 1 is the one with the point (1,1,1), from the second piece.
    let far = mesh
        .tet(1)
        .iter()
        .any(|&v| mesh.point(v).to_array() == [1.0, 1.0, 1.0]);
    assert!(far);
    let s = format!("{}:eta", spec(&p));
    assert_eq!(read_indicator(&s, &mesh).unwrap(), vec![0.75, 2.5]);
}

/// Volume of a tet from its corners, by the triple product.
fn volume(p: [[f64; 3]; 4]) -> f64 {
    let d = |i: usize| [p[i][0] - p[0][0], p[i][1] - p[0][1], p[i][2] - p[0][2]];
    let (a, b, c) = (d(1), d(2), d(3));
    let det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0]);
    det.abs() / 6.0
}

#[test]
fn vtu_arrays_in_every_layout_vtk_writes() {
    // MMG's unit cube written by VTK's own XML writer in four layouts
    // (tests/data/README.md); its `volume` cell array holds each tet's volume.
    let root = crate::support::root();
    let mut first: Option<Vec<f64>> = None;
    for layout in [
        "ascii",
        "inline_raw",
        "appended_raw",
        "appended_base64_zlib",
    ] {
        let p = root.join(format!("tests/data/mmg_cube_vtk_{layout}.vtu"));
        let (mesh, _) = tetrefine::io::load_mesh(&p).unwrap();
        let got = read_indicator(&format!("{}:volume", spec(&p)), &mesh).unwrap();
        assert_eq!(got.len(), 373);
        for (i, t) in mesh.tet_ids().enumerate() {
            let want = volume(mesh.tet_points(t).map(|q| q.to_array()));
            assert!((got[i] - want).abs() <= 1e-12 * want, "{layout}: tet {i}");
        }
        let total: f64 = got.iter().sum();
        assert!(
            (total - 1.0).abs() < 1e-12,
            "{layout}: the unit cube has volume {total}"
        );
        match &first {
            None => first = Some(got),
            Some(f) => assert_eq!(f, &got, "{layout}"),
        }
    }
}

#[test]
fn spec_parsing() {
    let cases = [
        (
            "a/eta.txt",
            IndicatorSource::Plain(PathBuf::from("a/eta.txt")),
        ),
        ("eta.DAT", IndicatorSource::Plain(PathBuf::from("eta.DAT"))),
        ("eta", IndicatorSource::Plain(PathBuf::from("eta"))),
        ("x.csv", IndicatorSource::Csv(PathBuf::from("x.csv"))),
        ("x.sol", IndicatorSource::Sol(PathBuf::from("x.sol"))),
        (
            "r/x.VTU:gmsh:physical",
            IndicatorSource::VtuArray(PathBuf::from("r/x.VTU"), "gmsh:physical".into()),
        ),
    ];
    for (s, want) in cases {
        assert_eq!(IndicatorSource::parse(s).unwrap(), want, "{s}");
    }
    for (s, word) in [
        ("x.vtu", "FILE.vtu:ARRAY"),
        ("x.vtu:", "FILE.vtu:ARRAY"),
        ("x.solb", "binary"),
        ("x.json", "unknown indicator extension"),
    ] {
        let e = IndicatorSource::parse(s).unwrap_err().to_string();
        assert!(e.contains(word), "{s}: {e}");
    }
}

// ---------------------------------------------------------------------------
// Malformed files
// ---------------------------------------------------------------------------

/// Each bad file (read for the 6-tet, 8-vertex cube), the cell array named
/// after `FILE.vtu:`, the line its error must name (None: a problem of the
/// whole file), and words the message must hold.
/// (file, cell array, line, words).
type BadCase = (
    &'static str,
    Option<&'static str>,
    Option<usize>,
    &'static [&'static str],
);

const BAD: &[BadCase] = &[
    (
        "wrong_count.txt",
        None,
        Some(7),
        &["after 5 values", "expected 6"],
    ),
    (
        "too_many.dat",
        None,
        Some(7),
        &["more values", "expected exactly 6"],
    ),
    (
        "empty.txt",
        None,
        Some(1),
        &["after 0 values", "expected 6"],
    ),
    ("nan.txt", None, Some(3), &["NaN", "tet 2"]),
    ("inf.txt", None, Some(2), &["infinite", "tet 1"]),
    ("negative.txt", None, Some(4), &["-0.5", "negative"]),
    (
        "not_a_number.txt",
        None,
        Some(3),
        &["expected a number", "0.5x"],
    ),
    ("garbage.txt", None, Some(1), &["not a text file"]),
    (
        "unknown_id.csv",
        None,
        Some(5),
        &["unknown tet id 6", "6 tets", "0-based"],
    ),
    ("negative_id.csv", None, Some(3), &["-1", "0-based"]),
    (
        "duplicate_id.csv",
        None,
        Some(6),
        &["tet 2", "twice", "line 4"],
    ),
    (
        "missing_id.csv",
        None,
        Some(5),
        &["expected 6", "missing", "0-based: 2"],
    ),
    ("inf.csv", None, Some(5), &["infinite", "tet 3"]),
    (
        "wrong_fields.csv",
        None,
        Some(2),
        &["expected 2", "found 3"],
    ),
    ("bad_header.csv", None, Some(1), &["header", "tet column"]),
    (
        "truncated.sol",
        None,
        Some(12),
        &["truncated", "announces 6, found 4"],
    ),
    ("wrong_type.sol", None, Some(7), &["type 2", "scalar"]),
    ("wrong_count.sol", None, Some(6), &["5 entries", "6 tets"]),
    (
        "two_solutions.sol",
        None,
        Some(7),
        &["2 solutions", "exactly one"],
    ),
    (
        "wrong_vertex_count.sol",
        None,
        Some(6),
        &["7 entries", "8 vertices"],
    ),
    (
        "negative_vertex.sol",
        None,
        Some(12),
        &["-3", "vertex 4", "negative"],
    ),
    (
        "no_section.sol",
        None,
        None,
        &["no SolAtTetrahedra", "6 values"],
    ),
    (
        "unknown_extension.eta",
        None,
        None,
        &["unknown indicator extension"],
    ),
    (
        "missing_array.vtu",
        Some("eta"),
        Some(13),
        &["no cell array 'eta'", "'error'"],
    ),
    ("nan_array.vtu", Some("eta"), Some(15), &["NaN", "tet 3"]),
    ("vector_array.vtu", Some("eta"), Some(14), &["2 components"]),
];

fn bad_dir() -> PathBuf {
    crate::support::root().join("tests/bad/indicator")
}

#[test]
fn every_bad_indicator_file_is_listed_and_there_are_enough() {
    let mut listed: Vec<&str> = BAD.iter().map(|c| c.0).collect();
    listed.push("README.md");
    listed.sort_unstable();
    let mut present: Vec<String> = std::fs::read_dir(bad_dir())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    present.sort_unstable();
    assert_eq!(present, listed);
    assert!(BAD.len() >= 10);
}

#[test]
fn bad_indicator_files_give_a_clear_error() {
    let (_, mesh) = kuhn_mesh(1, 1, 1);
    assert_eq!((mesh.n_tets(), mesh.n_points()), (6, 8));
    for &(file, array, line, words) in BAD {
        let mut s = bad_dir().join(file).display().to_string();
        if let Some(a) = array {
            s = format!("{s}:{a}");
        }
        let e = match read_indicator(&s, &mesh) {
            Ok(v) => panic!("{file}: read {v:?}"),
            Err(e) => e,
        };
        assert_eq!(e.path, bad_dir().join(file), "{file}");
        assert_eq!(e.line, line, "{file}: {e}");
        let msg = e.to_string();
        assert_eq!(msg.lines().count(), 1, "{file}: {msg}");
        match line {
            Some(l) => assert!(msg.contains(&format!("{file}:{l}: ")), "{file}: {msg}"),
            None => assert!(msg.contains(&format!("{file}: ")), "{file}: {msg}"),
        }
        for w in words {
            assert!(msg.contains(w), "{file}: '{w}' not in: {msg}");
        }
    }
}

#[test]
fn truncated_and_corrupted_indicators_never_panic() {
    // Every prefix and single-byte corruption of a valid file of each
    // format: an error or a value list, never a panic.
    let (_, mesh) = kuhn_mesh(2, 1, 1);
    let values = sample_values(mesh.n_tets(), 7);
    let dir = tempfile::tempdir().unwrap();
    let specs = write_all_formats(dir.path(), &mesh, &values);
    let work = tempfile::tempdir().unwrap();
    let mut rng = Rng(0xbad_5eed);
    for s in &specs {
        let (file, array) = match s.split_once(".vtu:") {
            Some((f, a)) => (format!("{f}.vtu"), Some(a.to_string())),
            None => (s.clone(), None),
        };
        let bytes = std::fs::read(&file).unwrap();
        let target = work.path().join(Path::new(&file).file_name().unwrap());
        let target_spec = match &array {
            Some(a) => format!("{}:{a}", target.display()),
            None => target.display().to_string(),
        };
        for k in 0..40 {
            std::fs::write(&target, &bytes[..bytes.len() * k / 40]).unwrap();
            let _ = read_indicator(&target_spec, &mesh);
            let mut bad = bytes.clone();
            let i = rng.below(bytes.len() as u64) as usize;
            bad[i] = rng.below(256) as u8;
            std::fs::write(&target, &bad).unwrap();
            if let Ok(v) = read_indicator(&target_spec, &mesh) {
                assert_eq!(v.len(), mesh.n_tets());
                assert!(v.iter().all(|x| x.is_finite() && *x >= 0.0));
            }
        }
    }
}
