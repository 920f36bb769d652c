//! `refine` carries fields over (issue 17, point 1): point fields from a
//! Medit `.sol`, a `.vtu` or Gmsh `$NodeData` come back interpolated in
//! `.vtu` point data (read here with vtkio, an independent reader), Gmsh
//! `$NodeData` and a `.sol` beside a `.mesh`; cell fields follow `parent`;
//! the vertex parent map of `--parent-map` rebuilds every point; bad fields
//! are refused with file and line, and nothing is written.

use std::path::Path;
use std::process::Output;
use tetrefine::io::load_mesh;

fn f(p: [f64; 3]) -> f64 {
    2.0 + 0.5 * p[0] - 1.5 * p[1] + 0.25 * p[2]
}

fn v(p: [f64; 3]) -> [f64; 3] {
    [p[0] - p[1], 3.0 * p[2], -1.0 + p[0]]
}

use crate::{files_in, run as tetrefine, run_ok as ok};

/// The tripod's points, as its file lists them.
fn tripod_points() -> Vec<[f64; 3]> {
    let (m, _) = load_mesh(&crate::support::path("meshes/tripod.mesh")).unwrap();
    m.points().iter().map(|p| p.to_array()).collect()
}

/// `f.sol`: the scalar `f` and the vector `v` at the tripod's points;
/// `cells.sol`: 1.5 × the tet number at its tets.
fn fields(dir: &Path) -> (String, String) {
    let pts = tripod_points();
    let rows: Vec<Vec<f64>> = pts
        .iter()
        .map(|&p| {
            let mut r = vec![f(p)];
            r.extend(v(p));
            r
        })
        .collect();
    let fp = dir.join("f.sol");
    crate::write_sol(&fp, "SolAtVertices", &[1, 2], &rows);
    let cp = dir.join("cells.sol");
    let rows: Vec<Vec<f64>> = (0..2799).map(|t| vec![1.5 * t as f64]).collect();
    crate::write_sol(&cp, "SolAtTetrahedra", &[1], &rows);
    (
        fp.to_str().unwrap().to_string(),
        cp.to_str().unwrap().to_string(),
    )
}

/// The points, point arrays and cell arrays of a `.vtu`, by vtkio.
struct Vtu {
    points: Vec<[f64; 3]>,
    point: Vec<(String, usize, Vec<f64>)>,
    cell: Vec<(String, usize, Vec<f64>)>,
}

/// Linear-rule refinement of the tripod into `out`, carrying the fields of
/// [`fields`], with `extra` options (one step without).
fn refine_tripod_with_fields(out: &Path, extra: &[&str]) -> Output {
    let inputs = tempfile::tempdir().unwrap();
    let (fp, cp) = fields(inputs.path());
    let mut args = vec![
        "refine",
        "meshes/tripod.mesh",
        "-o",
        out.to_str().unwrap(),
        "--boundary",
        "linear",
        "--fields",
        &fp,
        "--fields",
        &cp,
    ];
    args.extend_from_slice(extra);
    ok(&args)
}

fn read_vtu(path: &Path) -> Vtu {
    use vtkio::model::{Attribute, DataSet, Piece};
    let vtk = vtkio::Vtk::import(path).expect("vtkio reads the .vtu");
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid")
    };
    let Some(Piece::Inline(p)) = pieces.into_iter().next() else {
        panic!("no inline piece")
    };
    let arrays = |a: &[Attribute]| {
        a.iter()
            .filter_map(|a| match a {
                Attribute::DataArray(d) => Some((
                    d.name.clone(),
                    d.num_comp(),
                    d.data.cast_into::<f64>().unwrap(),
                )),
                _ => None,
            })
            .collect::<Vec<_>>()
    };
    let xyz = p.points.cast_into::<f64>().unwrap();
    Vtu {
        points: xyz.chunks(3).map(|c| [c[0], c[1], c[2]]).collect(),
        point: arrays(&p.data.point),
        cell: arrays(&p.data.cell),
    }
}

fn array<'a>(a: &'a [(String, usize, Vec<f64>)], name: &str) -> &'a (String, usize, Vec<f64>) {
    a.iter()
        .find(|x| x.0 == name)
        .unwrap_or_else(|| panic!("no array {name}"))
}

#[test]
fn sol_fields_through_two_steps_in_the_vtu_and_the_parent_map() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.vtu");
    let map = dir.path().join("map.txt");
    let o = refine_tripod_with_fields(
        &out,
        &["--steps", "2", "--parent-map", map.to_str().unwrap()],
    );
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("transfer: 2 point and 1 cell fields"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let vtu = read_vtu(&out);
    let (_, c, scalar) = array(&vtu.point, "f_0");
    assert_eq!(*c, 1);
    let (_, c, vector) = array(&vtu.point, "f_1");
    assert_eq!(*c, 3);
    for (i, &p) in vtu.points.iter().enumerate() {
        assert!((scalar[i] - f(p)).abs() <= 1e-9, "point {i}");
        for k in 0..3 {
            assert!((vector[3 * i + k] - v(p)[k]).abs() <= 1e-9, "point {i}");
        }
    }
    let (_, _, parent) = array(&vtu.cell, "parent");
    let (_, _, cells) = array(&vtu.cell, "cells");
    assert!(!parent.is_empty());
    for (t, (&c, &p)) in cells.iter().zip(parent).enumerate() {
        assert_eq!(c, 1.5 * p, "tet {t}");
    }
    // The vertex parent map: in the file and as point arrays, the same, and
    // each point is the barycentric combination of its input tet's corners.
    let input = tripod_points();
    let text = std::fs::read_to_string(&map).unwrap();
    let (tets, points) = text.split_once("# points").expect("a points section");
    assert_eq!(
        tets.lines().filter(|l| !l.starts_with('#')).count(),
        parent.len()
    );
    let rows: Vec<Vec<f64>> = points
        .lines()
        .skip(1)
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), vtu.points.len());
    let (_, _, ptet) = array(&vtu.point, "parent_tet");
    let (_, _, pbary) = array(&vtu.point, "parent_bary");
    for (i, r) in rows.iter().enumerate() {
        assert_eq!(r.len(), 11);
        assert_eq!(r[0] as usize, i);
        assert_eq!(r[1], ptet[i]);
        let mut x = [0.0; 3];
        for k in 0..4 {
            assert_eq!(r[6 + k], pbary[4 * i + k]);
            let q = input[r[2 + k] as usize];
            for a in 0..3 {
                x[a] += r[6 + k] * q[a];
            }
        }
        for a in 0..3 {
            assert!((x[a] - vtu.points[i][a]).abs() <= 1e-9, "point {i}: {x:?}");
        }
    }
}

#[test]
fn fields_come_back_from_a_vtu_input_and_in_gmsh_and_medit_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let step1 = dir.path().join("step1.vtu");
    refine_tripod_with_fields(&step1, &[]);
    // Its point and cell data are the second step's fields (the derived
    // arrays — quality, parent, the parent map — are not).
    for out in ["step2.msh", "step2.mesh"] {
        let out = dir.path().join(out);
        let o = ok(&[
            "refine",
            step1.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--boundary",
            "linear",
        ]);
        assert!(
            String::from_utf8_lossy(&o.stderr).contains("transfer: 2 point and 1 cell fields"),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        let (data, meta) = if out.extension().unwrap() == "msh" {
            tetrefine::io::read_mesh_with_meta(&out).unwrap()
        } else {
            let mut meta = tetrefine::io::MeshMeta::default();
            let d = tetrefine::io::read_mesh(&out).unwrap();
            let sol = dir.path().join("step2.sol");
            let tets = dir.path().join("step2.tets.sol");
            tetrefine::io::add_sol_fields(&sol, &mut meta, d.points.len(), d.tets.len()).unwrap();
            tetrefine::io::add_sol_fields(&tets, &mut meta, d.points.len(), d.tets.len()).unwrap();
            (d, meta)
        };
        let scalar = meta
            .point_fields
            .iter()
            .find(|x| x.components == 1)
            .unwrap_or_else(|| panic!("{out:?}: {:?}", meta.point_fields));
        assert_eq!(scalar.values.len(), data.points.len());
        for (i, &p) in data.points.iter().enumerate() {
            assert!((scalar.values[i] - f(p)).abs() <= 1e-9, "{out:?} point {i}");
        }
        let cells = &meta.cell_fields[0];
        assert_eq!(cells.values.len(), data.tets.len());
        // Two steps of parents: each value is one the input had.
        assert!(cells
            .values
            .iter()
            .all(|&x| x >= 0.0 && (x / 1.5).fract() == 0.0 && x / 1.5 < 2799.0));
    }
}

#[test]
fn no_transfer_drops_the_fields_and_transfer_without_fields_is_refused() {
    let inputs = tempfile::tempdir().unwrap();
    let (fp, _) = fields(inputs.path());
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.vtu");
    let o = out.to_str().unwrap();
    ok(&[
        "refine",
        "meshes/tripod.mesh",
        "-o",
        o,
        "--fields",
        &fp,
        "--no-transfer",
        "--opt-passes",
        "0",
    ]);
    let vtu = read_vtu(&out);
    assert!(vtu.point.iter().all(|a| !a.0.starts_with("f_")));
    assert!(vtu.point.iter().any(|a| a.0 == "parent_tet"));
    std::fs::remove_file(&out).unwrap();
    let r = tetrefine(&["refine", "meshes/tripod.mesh", "-o", o, "--transfer"]);
    assert_eq!(r.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&r.stderr).contains("carries no point or cell field"));
    assert!(files_in(dir.path()).is_empty());
}

#[test]
fn a_bad_field_names_its_file_and_line_and_nothing_is_written() {
    let inputs = tempfile::tempdir().unwrap();
    let pts = tripod_points();
    let short = inputs.path().join("short.sol");
    let rows: Vec<Vec<f64>> = pts.iter().skip(1).map(|&p| vec![f(p)]).collect();
    crate::write_sol(&short, "SolAtVertices", &[1], &rows);
    let nan = inputs.path().join("nan.sol");
    let mut rows: Vec<Vec<f64>> = pts.iter().map(|&p| vec![f(p)]).collect();
    rows[10][0] = f64::NAN;
    crate::write_sol(&nan, "SolAtVertices", &[1], &rows);
    let dir = tempfile::tempdir().unwrap();
    for (bad, line, what) in [
        (&short, 6, "entries but the mesh has"),
        (&nan, 18, "not a finite number"),
    ] {
        for out in ["o.vtu", "o.mesh", "o.msh"] {
            let o = tetrefine(&[
                "refine",
                "meshes/tripod.mesh",
                "-o",
                dir.path().join(out).to_str().unwrap(),
                "--fields",
                bad.to_str().unwrap(),
                "--parent-map",
                dir.path().join("map.txt").to_str().unwrap(),
            ]);
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(1), "{err}");
            let at = format!("{}:{line}:", bad.display());
            assert!(
                err.contains(&at) && err.contains(what),
                "{at} {what}: {err}"
            );
            assert!(
                files_in(dir.path()).is_empty(),
                "{:?}",
                files_in(dir.path())
            );
        }
    }
}

#[test]
fn meshio_reads_the_transferred_fields() {
    let probe = std::process::Command::new("python3")
        .args(["-c", "import meshio"])
        .output();
    if !probe.is_ok_and(|o| o.status.success()) {
        eprintln!("skipped: python3 with meshio is not installed (pip install meshio)");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.vtu");
    refine_tripod_with_fields(&out, &[]);
    let script = r#"
import sys, meshio, numpy as np
m = meshio.read(sys.argv[1])
x, y, z = m.points.T
f = m.point_data["f_0"]
dev = np.abs(f - (2.0 + 0.5 * x - 1.5 * y + 0.25 * z)).max()
c = m.cell_data["cells"][0]
p = m.cell_data["parent"][0]
assert np.array_equal(c, 1.5 * p), "cells"
assert m.point_data["f_1"].shape == (len(x), 3)
print(dev)
"#;
    let o = std::process::Command::new("python3")
        .args(["-c", script, out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let dev: f64 = String::from_utf8_lossy(&o.stdout).trim().parse().unwrap();
    assert!(dev <= 1e-9, "{dev}");
    // Gmsh: $NodeData as meshio reads it. (Its `$ElementData`, which covers
    // every element as meshio needs: python/tests/test_meshio.py, which CI
    // runs with meshio installed.)
    let inputs = tempfile::tempdir().unwrap();
    let (fp, _) = fields(inputs.path());
    let msh = dir.path().join("o.msh");
    ok(&[
        "refine",
        "meshes/tripod.mesh",
        "-o",
        msh.to_str().unwrap(),
        "--boundary",
        "linear",
        "--fields",
        &fp,
    ]);
    let script = r#"
import sys, meshio, numpy as np
m = meshio.read(sys.argv[1])
x, y, z = m.points.T
dev = np.abs(m.point_data["f_0"] - (2.0 + 0.5 * x - 1.5 * y + 0.25 * z)).max()
assert m.point_data["f_1"].shape == (len(x), 3)
print(dev)
"#;
    let o = std::process::Command::new("python3")
        .args(["-c", script, msh.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let dev: f64 = String::from_utf8_lossy(&o.stdout).trim().parse().unwrap();
    assert!(dev <= 1e-9, "{dev}");
}
