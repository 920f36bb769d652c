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

/// The centroid of tet `t` of `d`.
fn centroid(d: &MeshData, t: usize) -> [f64; 3] {
    let mut c = [0.0; 3];
    for &v in &d.tets[t] {
        for (a, x) in c.iter_mut().zip(d.points[v as usize]) {
            *a += x / 4.0;
        }
    }
    c
}

/// The cell field `name` of `meta`.
fn cell_field<'a>(meta: &'a MeshMeta, name: &str, what: &str) -> &'a tetrefine::io::Field {
    meta.cell_fields
        .iter()
        .find(|f| f.name == name)
        .unwrap_or_else(|| panic!("{what}: no cell field {name}: {:?}", meta.cell_fields))
}

/// Gmsh's density view: 7.85 in box 1 (x < 1), 8.96 in box 2.
fn density_at(c: [f64; 3]) -> f64 {
    if c[0] < 1.0 {
        7.85
    } else {
        8.96
    }
}

#[test]
fn gmsh_element_data_is_read_in_every_layout_and_carried_over_by_parent() {
    // The views Gmsh wrote (tests/data/make_gmsh_tagged.py): "density" by
    // box, "centroid" = each tet's centroid; the values are checked against
    // the geometry of the tets they land on, so a value on the wrong tet shows.
    let mut centroids = Vec::new();
    for f in [
        "gmsh_tagged_v22.msh",
        "gmsh_tagged_v41.msh",
        "gmsh_tagged_v41_binary.msh",
    ] {
        let (d, meta) = read_mesh_with_meta(&data(f)).unwrap();
        assert_eq!(d.tets.len(), 1455, "{f}");
        assert_eq!(meta.cell_fields.len(), 2, "{f}");
        let rho = cell_field(&meta, "density", f);
        let cen = cell_field(&meta, "centroid", f);
        assert_eq!((rho.components, rho.len()), (1, 1455), "{f}");
        assert_eq!((cen.components, cen.len()), (3, 1455), "{f}");
        for t in 0..d.tets.len() {
            let c = centroid(&d, t);
            assert_eq!(rho.values[t], density_at(c), "{f}: tet {t}");
            for (x, y) in cen.entry(t).iter().zip(c) {
                assert!((x - y).abs() <= 1e-12, "{f}: tet {t}");
            }
        }
        centroids = (0..d.tets.len()).map(|t| centroid(&d, t)).collect();
    }
    // Through refine, in every MSH variant and as .vtu: every child has its
    // parent's values (density by the box it lies in; a centroid of an
    // input tet), read back by tetrefine's readers (meshio and Gmsh read
    // them in python/tests/test_meshio.py and tests/gmsh_roundtrip.py).
    let dir = tempfile::tempdir().unwrap();
    let input = data("gmsh_tagged_v22.msh").to_string_lossy().into_owned();
    for (out, format) in [
        ("o22.msh", "2.2"),
        ("o41.msh", "4.1"),
        ("o41b.msh", "4.1-binary"),
        ("o.vtu", "4.1"),
    ] {
        let out = dir.path().join(out);
        let o = tetrefine(&[
            "refine",
            &input,
            "-o",
            out.to_str().unwrap(),
            "--msh-format",
            format,
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{err}");
        assert!(err.contains("transfer: 1 point and 2 cell fields"), "{err}");
        let (d, meta) = read_mesh_with_meta(&out).unwrap();
        let what = format!("{}", out.display());
        assert!(d.tets.len() > 1455 * 6, "{what}");
        let rho = cell_field(&meta, "density", &what);
        let cen = cell_field(&meta, "centroid", &what);
        assert_eq!(rho.len(), d.tets.len(), "{what}");
        assert_eq!(cen.len(), d.tets.len(), "{what}");
        for t in 0..d.tets.len() {
            assert_eq!(
                rho.values[t],
                density_at(centroid(&d, t)),
                "{what}: tet {t}"
            );
            let e = cen.entry(t);
            assert!(
                centroids
                    .iter()
                    .any(|c| (0..3).all(|a| (c[a] - e[a]).abs() <= 1e-12)),
                "{what}: tet {t}: {e:?} is no input centroid"
            );
        }
    }
}

#[test]
fn bad_element_data_is_an_error_at_its_line_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    // The density view's entries start after its header (11 lines).
    let edit_density = |name: &str, edit: &dyn Fn(&mut Vec<String>, usize)| {
        edited(dir.path(), name, |t| {
            let mut lines: Vec<String> = t.lines().map(str::to_string).collect();
            let h = lines
                .iter()
                .position(|l| l == "\"density\"")
                .expect("the density view")
                - 2;
            edit(&mut lines, h);
            lines.join("\n") + "\n"
        })
    };
    let short = edit_density("short.msh", &|l, h| {
        // One tet fewer: count and entries agree, a tet is left out.
        assert_eq!(l[h + 9], "1455");
        l[h + 9] = "1454".into();
        l.remove(h + 11);
    });
    let ghost = edit_density("ghost.msh", &|l, h| {
        l[h + 20] = "99999 7.85".into();
    });
    let nan = edit_density("nan.msh", &|l, h| {
        let tag = l[h + 30].split_whitespace().next().unwrap().to_string();
        l[h + 30] = format!("{tag} nan");
    });
    let differ = edit_density("twice.msh", &|l, h| {
        // The same tet given twice with different values.
        let tag = l[h + 11].split_whitespace().next().unwrap().to_string();
        l[h + 12] = format!("{tag} 1.5");
    });
    let truncated = edit_density("truncated.msh", &|l, h| {
        l.truncate(h + 40);
    });
    // The file ends in the middle of the last view, 1000 entries in.
    let cut = edited(dir.path(), "cut.msh", |t| {
        let mut lines: Vec<&str> = t.lines().collect();
        let h = lines.iter().position(|l| *l == "\"centroid\"").unwrap() - 2;
        lines.truncate(h + 11 + 1000);
        lines.join("\n") + "\n"
    });
    let n_cut = std::fs::read_to_string(&cut).unwrap().lines().count();
    let before = edited(dir.path(), "before.msh", |t| {
        let (head, rest) = t.split_once("$Elements\n").unwrap();
        let (elements, tail) = rest.split_once("$EndElements\n").unwrap();
        let view = tail.split_once("$ElementData").unwrap().1;
        let density = view.split_once("$EndElementData\n").unwrap().0;
        format!("{head}$ElementData{density}$EndElementData\n$Elements\n{elements}$EndElements\n")
    });
    let cases = [
        (
            &short,
            line_of(&short, "\"density\"") + 7,
            "1454 of the 1455 tetrahedra",
        ),
        (&ghost, line_of(&ghost, "\"density\"") + 18, "element 99999"),
        (
            &nan,
            line_of(&nan, "\"density\"") + 28,
            "not a finite number",
        ),
        (
            &differ,
            line_of(&differ, "\"density\"") + 10,
            "was given [7.85]",
        ),
        (
            &truncated,
            line_of(&truncated, "\"density\"") + 7,
            "more than the rest of the file can hold (truncated?)",
        ),
        // The end of the file: just past its last line end.
        (
            &cut,
            n_cut + 1,
            "file ends where an element tag was expected (truncated?)",
        ),
        (
            &before,
            line_of(&before, "$ElementData"),
            "comes before $Elements",
        ),
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
        assert!(!err.contains("panicked"), "{err}");
        assert!(!out.exists(), "nothing is written");
    }
}
