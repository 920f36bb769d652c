//! Gmsh without loss: `$PhysicalNames` and every physical tag of an entity
//! are read, kept through refinement and written back in MSH 2.2, 4.1 and 4.1
//! binary. The input is two unit boxes meshed by Gmsh itself
//! (`tests/data/make_gmsh_tagged.py`), so the areas and volumes of the
//! physical groups are known in closed form. (Gmsh's own reader checks the
//! written files in CI: `tests/gmsh_roundtrip.py`.)

use crate::run as tetrefine;
use crate::support;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use tetrefine::io::MeshMeta;
use tetrefine::io::{load_mesh_with_meta, read_mesh_with_meta};
use tetrefine::MeshData;

/// A file of `tests/data`.
fn data(name: &str) -> PathBuf {
    support::path(&format!("tests/data/{name}"))
}

fn names() -> BTreeMap<(i32, i32), String> {
    [
        ((0, 2), "box 2 corners"),
        ((1, 3), "box 2 edges"),
        ((2, 5), "outer walls"),
        ((2, 6), "ground"),
        ((2, 7), "interface"),
        ((3, 10), "steel"),
        ((3, 11), "copper"),
        ((3, 30), "all solids"),
    ]
    .into_iter()
    .map(|(k, v)| (k, v.to_string()))
    .collect()
}

fn volume(p: [[f64; 3]; 4]) -> f64 {
    let d = |a: [f64; 3], b: [f64; 3]| [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let (u, v, w) = (d(p[0], p[1]), d(p[0], p[2]), d(p[0], p[3]));
    (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
        + u[2] * (v[0] * w[1] - v[1] * w[0]))
        .abs()
        / 6.0
}

fn area(p: [[f64; 3]; 3]) -> f64 {
    let d = |a: [f64; 3], b: [f64; 3]| [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let (u, v) = (d(p[0], p[1]), d(p[0], p[2]));
    let c = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt() / 2.0
}

/// Volume (dim 3) or area (dim 2) of every physical group, from the stored
/// values and the tag lists behind them.
fn measures(d: &MeshData, meta: &MeshMeta) -> BTreeMap<(i32, i32), f64> {
    let mut m = BTreeMap::new();
    for (t, v) in d.tets.iter().enumerate() {
        let vol = volume(v.map(|i| d.points[i as usize]));
        for p in meta.physical_tags(3, d.region(t)) {
            *m.entry((3, p)).or_insert(0.0) += vol;
        }
    }
    for (f, value) in &d.triangles {
        let a = area(f.map(|i| d.points[i as usize]));
        for p in meta.physical_tags(2, *value) {
            *m.entry((2, p)).or_insert(0.0) += a;
        }
    }
    m
}

/// The closed forms: two unit boxes side by side.
fn check_measures(m: &BTreeMap<(i32, i32), f64>, what: &str) {
    for (key, want) in [
        ((3, 10), 1.0),
        ((3, 11), 1.0),
        ((3, 30), 2.0),
        ((2, 5), 5.0),
        ((2, 6), 1.0),
        ((2, 7), 1.0),
    ] {
        let got = m.get(&key).copied().unwrap_or(0.0);
        assert!(
            (got - want).abs() < 1e-9,
            "{what}: group {key:?} measures {got}, not {want}"
        );
    }
}

/// Physical tags of the corners and the edge count of each curve group.
fn point_and_curve_tags(d: &MeshData, meta: &MeshMeta) -> (usize, usize) {
    let corners = d
        .corners
        .iter()
        .filter(|&&v| {
            meta.point_physical_tags(d.points[v as usize])
                .is_some_and(|t| t.contains(&2))
        })
        .count();
    let edges = d
        .edges
        .iter()
        .filter(|(_, m)| meta.physical_tags(1, *m).contains(&3))
        .count();
    (corners, edges)
}

/// Elements per (element type, physical tag) in a Gmsh MSH 2.2 ASCII file,
/// counted from its raw lines (Gmsh writes an element once per group).
fn raw_v22_counts(path: &Path) -> BTreeMap<(i64, i64), usize> {
    let text = std::fs::read_to_string(path).unwrap();
    let body = text
        .split("$Elements\n")
        .nth(1)
        .unwrap()
        .split("$EndElements")
        .next()
        .unwrap();
    let mut m = BTreeMap::new();
    for l in body.lines().skip(1) {
        let w: Vec<i64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
        *m.entry((w[1], w[3])).or_insert(0) += 1;
    }
    m
}

#[test]
fn the_three_layouts_gmsh_wrote_give_every_name_and_every_tag_of_an_entity() {
    let raw = raw_v22_counts(&data("gmsh_tagged_v22.msh"));
    let mut tets = None;
    for f in [
        "gmsh_tagged_v22.msh",
        "gmsh_tagged_v41.msh",
        "gmsh_tagged_v41_binary.msh",
    ] {
        let (d, meta) = read_mesh_with_meta(&data(f)).unwrap();
        assert_eq!(meta.physical_names, names(), "{f}");
        // Every tet is in "all solids" and in exactly one of the two metals,
        // as many as Gmsh wrote in each group.
        let count = |p: i32| {
            (0..d.tets.len())
                .filter(|&t| meta.physical_tags(3, d.region(t)).contains(&p))
                .count()
        };
        assert_eq!(count(30), d.tets.len(), "{f}");
        assert_eq!(count(10) + count(11), d.tets.len(), "{f}");
        assert_eq!(count(10), raw[&(4, 10)], "{f}");
        assert_eq!(count(11), raw[&(4, 11)], "{f}");
        assert_eq!(count(30), raw[&(4, 30)], "{f}");
        let tri = |p: i32| {
            d.triangles
                .iter()
                .filter(|(_, m)| meta.physical_tags(2, *m).contains(&p))
                .count()
        };
        for p in [5, 6, 7] {
            assert_eq!(tri(p), raw[&(2, p as i64)], "{f}: surface group {p}");
        }
        assert_eq!(point_and_curve_tags(&d, &meta), (8, raw[&(1, 3)]), "{f}");
        check_measures(&measures(&d, &meta), f);
        // The 2.2 file lists each tet once per group (twice): read as one.
        assert_eq!(*tets.get_or_insert(d.tets.len()), d.tets.len(), "{f}");
    }
}

#[test]
fn names_and_every_tag_survive_refine_and_convert_in_each_msh_format() {
    let dir = tempfile::tempdir().unwrap();
    let input = data("gmsh_tagged_v41.msh").to_string_lossy().into_owned();
    let (_, input_meta) = read_mesh_with_meta(Path::new(&input)).unwrap();
    for format in ["2.2", "4.1", "4.1-binary"] {
        for cmd in ["refine", "convert"] {
            let out = dir.path().join(format!("{cmd}_{format}.msh"));
            let o = if cmd == "refine" {
                tetrefine(&[
                    "refine",
                    &input,
                    "-o",
                    out.to_str().unwrap(),
                    "--msh-format",
                    format,
                ])
            } else {
                tetrefine(&[
                    "convert",
                    &input,
                    out.to_str().unwrap(),
                    "--msh-format",
                    format,
                ])
            };
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            let head = std::fs::read(&out).unwrap();
            let want = match format {
                "2.2" => "$MeshFormat\n2.2 0 8\n",
                "4.1" => "$MeshFormat\n4.1 0 8\n",
                _ => "$MeshFormat\n4.1 1 8\n",
            };
            assert!(head.starts_with(want.as_bytes()), "{cmd} {format}");
            let (mesh, _, meta) = load_mesh_with_meta(&out).unwrap();
            mesh.check().unwrap();
            let what = format!("{cmd} --msh-format {format}");
            assert_eq!(meta.physical_names, names(), "{what}");
            // The tag lists behind the stored values are the input's.
            let lists: BTreeSet<Vec<i32>> = meta.tag_sets.values().cloned().collect();
            let input_lists: BTreeSet<Vec<i32>> = input_meta.tag_sets.values().cloned().collect();
            assert_eq!(lists, input_lists, "{what}");
            let d = mesh.to_data();
            check_measures(&measures(&d, &meta), &what);
            let (corners, edges) = point_and_curve_tags(&d, &meta);
            assert_eq!(corners, 8, "{what}");
            assert!(edges >= 12, "{what}: {edges} edges in 'box 2 edges'");
            if cmd == "refine" {
                assert!(d.tets.len() > 1455 * 6, "{what}: {} tets", d.tets.len());
            } else {
                assert_eq!(d.tets.len(), 1455, "{what}");
            }
        }
    }
}

/// A copy of the 4.1 ASCII fixture with `edit` applied to its text.
fn edited(dir: &Path, name: &str, edit: impl Fn(&str) -> String) -> std::path::PathBuf {
    let text = std::fs::read_to_string(data("gmsh_tagged_v41.msh")).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, edit(&text)).unwrap();
    p
}

fn line_of(path: &Path, needle: &str) -> usize {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .position(|l| l.contains(needle))
        .unwrap()
        + 1
}

#[test]
fn a_name_for_an_unknown_tag_or_a_bad_field_is_an_error_at_its_line_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let ghost = edited(dir.path(), "ghost.msh", |t| {
        t.replace("$PhysicalNames\n8\n", "$PhysicalNames\n9\n3 99 \"ghost\"\n")
    });
    let short = edited(dir.path(), "short.msh", |t| {
        // One node fewer in the view than in the mesh.
        let (head, view) = t.split_once("$NodeData").unwrap();
        let view = view.replacen("\n428\n0\n", "\n427\n0\n", 1);
        let mut lines: Vec<&str> = view.lines().collect();
        let last = lines.iter().position(|l| *l == "$EndNodeData").unwrap();
        lines.remove(last - 1);
        format!("{head}$NodeData{}\n", lines.join("\n"))
    });
    let nan = edited(dir.path(), "nan.msh", |t| {
        let (head, view) = t.split_once("$NodeData").unwrap();
        let mut lines: Vec<String> = view.lines().map(str::to_string).collect();
        let i = lines.iter().position(|l| l.starts_with("5 ")).unwrap();
        lines[i] = "5 nan".into();
        format!("{head}$NodeData{}\n", lines.join("\n"))
    });
    let cases = [
        (&ghost, line_of(&ghost, "ghost"), "physical tag 99"),
        (
            &short,
            line_of(&short, "$NodeData") + 8,
            "427 of the 428 nodes",
        ),
        (&nan, line_of(&nan, "5 nan"), "not a finite number"),
    ];
    for (path, line, words) in cases {
        let out = dir.path().join("out.msh");
        let o = tetrefine(&[
            "refine",
            path.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(!o.status.success());
        let err = String::from_utf8_lossy(&o.stderr);
        let want = format!("{}:{line}:", path.display());
        assert!(
            err.contains(&want) && err.contains(words),
            "{want} {words}: {err}"
        );
        assert!(!out.exists(), "nothing is written");
    }
}
