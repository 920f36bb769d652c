//! The README's commands, run as written there: the first is a `refine` of a
//! mesh in `meshes/` that writes a `.vtu` (read back with vtkio, an
//! independent reader) and a PNG histogram (decoded by `image`); the second
//! is `quality`.

use crate::support;
use std::path::Path;

/// The `cargo run --release -- …` lines of the README's first `sh` block,
/// as argument lists after the `--`.
fn readme_commands() -> Vec<Vec<String>> {
    let readme = std::fs::read_to_string(support::path("README.md")).expect("README.md");
    let block = readme
        .split("```sh\n")
        .nth(1)
        .and_then(|b| b.split("```").next())
        .expect("README has an sh block");
    block
        .lines()
        .filter_map(|l| l.trim().strip_prefix("cargo run --release -- "))
        .map(|rest| rest.split_whitespace().map(str::to_string).collect())
        .collect()
}

/// Runs one README command with the repository's `meshes/` as input and
/// every output in `dir`.
fn run_in(dir: &Path, args: &[String]) -> std::process::Output {
    let root = support::root();
    let args: Vec<String> = args
        .iter()
        .map(|a| {
            if a.starts_with("meshes/") {
                root.join(a).to_string_lossy().into_owned()
            } else {
                a.clone()
            }
        })
        .collect();
    let o = crate::tetrefine_command()
        .args(&args)
        .current_dir(dir)
        .output()
        .expect("runs the binary");
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// The value after `flag` in `args`.
fn arg_after<'a>(args: &'a [String], flag: &str) -> &'a str {
    let i = args.iter().position(|a| a == flag).expect(flag);
    &args[i + 1]
}

#[test]
fn the_first_command_refines_a_mesh_into_a_vtu_and_a_png_and_the_second_is_quality() {
    let cmds = readme_commands();
    assert!(cmds.len() >= 2, "{cmds:?}");
    let first = &cmds[0];
    assert_eq!(first[0], "refine", "the first command is the main job");
    assert!(first[1].starts_with("meshes/"), "{first:?}");
    assert_eq!(cmds[1][0], "quality", "the second is the report");

    let dir = tempfile::tempdir().unwrap();
    let o = run_in(dir.path(), first);
    let table = String::from_utf8_lossy(&o.stdout);
    // The tets of the last step, from the table the command printed.
    let tets: usize = table
        .lines()
        .rfind(|l| l.starts_with("step "))
        .and_then(|l| l.split_whitespace().nth(4))
        .and_then(|w| w.replace(',', "").parse().ok())
        .unwrap_or_else(|| panic!("no step row with a tet count in\n{table}"));

    let vtu = dir.path().join(arg_after(first, "-o"));
    assert_eq!(vtu.extension().unwrap(), "vtu");
    let vtk = vtkio::Vtk::import(&vtu).expect("vtkio reads the refined .vtu");
    let vtkio::model::DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid")
    };
    let piece = match pieces.into_iter().next() {
        Some(vtkio::model::Piece::Inline(p)) => *p,
        _ => panic!("no inline piece"),
    };
    assert!(piece
        .cells
        .types
        .iter()
        .all(|t| *t == vtkio::model::CellType::Tetra));
    assert_eq!(piece.cells.types.len(), tets, "{table}");
    assert!(tets > 2799 * 6, "one √3 step multiplies the tripod's tets");
    let names: Vec<String> = piece
        .data
        .cell
        .iter()
        .map(|a| match a {
            vtkio::model::Attribute::DataArray(d) => d.name.clone(),
            vtkio::model::Attribute::Field { name, .. } => name.clone(),
        })
        .collect();
    for want in ["region", "min_dihedral", "quality", "level", "parent"] {
        assert!(names.iter().any(|n| n == want), "{want} missing: {names:?}");
    }

    let png = dir.path().join(arg_after(first, "--histogram"));
    assert_eq!(png.extension().unwrap(), "png");
    let img = image::open(&png).expect("a PNG image").to_rgb8();
    assert!(img.width() >= 200 && img.height() >= 150);
    let distinct: std::collections::HashSet<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    assert!(distinct.len() > 2, "the histogram is drawn, not blank");

    let o = run_in(dir.path(), &cmds[1]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("2799"), "{out}");
}
