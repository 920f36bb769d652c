//! The mutation fuzzer shared by `tests/fuzz.rs` (bounded, in CI) and
//! `examples/soak.rs` (as long as you let it run): seeded mutations of every
//! shipped input format, read in-process under `catch_unwind`, and a sample
//! of them through the command line.
//!
//! Each case asserts: no panic; an error names the file it is about; a
//! success builds a mesh that passes `check()` (or a surface that validates);
//! through the CLI, an error exits 1 with one line on stderr naming the file
//! and leaves no output and no temporary file behind, and a success writes an
//! output that reads back and checks.

#![allow(dead_code)]

use std::panic::AssertUnwindSafe;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The crate's seeded SplitMix64, behind the interface the mutators use.
pub struct Rng(tetrefine::SplitMix64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Rng {
        Rng(tetrefine::SplitMix64(seed))
    }
    /// The next 64 random bits.
    pub fn next(&mut self) -> u64 {
        self.0.next_u64()
    }
    /// Uniform in `0..n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// What a seed file is read as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A volume mesh (`load_mesh`, then `check`).
    Mesh,
    /// A per-tet indicator or size field of the reference mesh.
    Indicator,
    /// A polygon surface (`surface::io::load_surface`).
    Surface,
    /// A mesher's input (`Plc::read`, then `analyze`).
    Plc,
}

/// One seed: a name for the counts, the file name to write the mutant as,
/// its bytes, how it is read, and sibling files written unchanged beside it.
pub struct Seed {
    /// Name in the counts ("medit", "gmsh 4.1 binary", …).
    pub name: &'static str,
    /// File name of the mutant (its extension picks the reader).
    pub file: String,
    /// The unmutated bytes.
    pub bytes: Vec<u8>,
    /// How it is read.
    pub kind: Kind,
    /// Unchanged siblings (TetGen sets).
    pub siblings: Vec<(String, Vec<u8>)>,
}

/// The repository root (`$TETREFINE_ROOT` overrides it, for a soak run
/// from a snapshot while the tree changes).
fn root() -> PathBuf {
    std::env::var_os("TETREFINE_ROOT")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../.."))
}

fn read(rel: &str) -> Vec<u8> {
    std::fs::read(root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

fn seed(name: &'static str, file: &str, bytes: Vec<u8>, kind: Kind) -> Seed {
    Seed {
        name,
        file: file.to_string(),
        bytes,
        kind,
        siblings: Vec::new(),
    }
}

/// The reference mesh indicators refer to: `meshes/mmg_cube.mesh`.
pub fn reference_mesh() -> tetrefine::TetMesh {
    tetrefine::io::load_mesh(&root().join("meshes/mmg_cube.mesh"))
        .expect("reference mesh")
        .0
}

const CUBE_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
const CUBE_OFF: &str = "OFF\n8 6 12\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n\
4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";
const CUBE_PLY: &str =
    "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n\
property float z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n\
0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n\
4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";

/// The unit cube of [`CUBE_PLY`] as a binary little-endian `.ply`.
fn cube_ply_binary() -> Vec<u8> {
    let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 8\nproperty float x\n\
property float y\nproperty float z\nelement face 6\nproperty list uchar int vertex_indices\n\
end_header\n"
        .to_vec();
    for p in [
        [0f32, 0., 0.],
        [1., 0., 0.],
        [1., 1., 0.],
        [0., 1., 0.],
        [0., 0., 1.],
        [1., 0., 1.],
        [1., 1., 1.],
        [0., 1., 1.],
    ] {
        for c in p {
            b.extend_from_slice(&c.to_le_bytes());
        }
    }
    for f in [
        [0i32, 3, 2, 1],
        [4, 5, 6, 7],
        [0, 1, 5, 4],
        [1, 2, 6, 5],
        [2, 3, 7, 6],
        [3, 0, 4, 7],
    ] {
        b.push(4);
        for v in f {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    b
}

/// The triangles of the unit cube, outward.
fn cube_triangles() -> Vec<[[f32; 3]; 3]> {
    let p = |i: usize| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32];
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    quads
        .iter()
        .flat_map(|q| [[p(q[0]), p(q[1]), p(q[2])], [p(q[0]), p(q[2]), p(q[3])]])
        .collect()
}

fn stl_ascii() -> Vec<u8> {
    let mut s = String::from("solid cube\n");
    for t in cube_triangles() {
        s += " facet normal 0 0 0\n  outer loop\n";
        for v in t {
            s += &format!("   vertex {} {} {}\n", v[0], v[1], v[2]);
        }
        s += "  endloop\n endfacet\n";
    }
    s += "endsolid cube\n";
    s.into_bytes()
}

fn stl_binary() -> Vec<u8> {
    let tris = cube_triangles();
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&(tris.len() as u32).to_le_bytes());
    for t in tris {
        b.extend_from_slice(&[0u8; 12]);
        for v in t {
            for c in v {
                b.extend_from_slice(&c.to_le_bytes());
            }
        }
        b.extend_from_slice(&[0u8; 2]);
    }
    b
}

/// `mesh` as tetrefine writes it to a file named `name`.
fn written(mesh: &tetrefine::TetMesh, name: &str) -> Vec<u8> {
    let dir = tempfile::tempdir().expect("temp dir");
    let p = dir.path().join(name);
    tetrefine::io::write_mesh(&p, mesh).expect("write seed");
    std::fs::read(p).expect("read seed")
}

/// `mesh` as a GiD file of 4-node tets with a material column (GiD has no
/// writer here).
fn gid(mesh: &tetrefine::TetMesh) -> Vec<u8> {
    let d = mesh.to_data();
    let mut s = String::from("MESH dimension 3 ElemType Tetrahedra Nnode 4\nCoordinates\n");
    for (i, p) in d.points.iter().enumerate() {
        s += &format!("{} {} {} {}\n", i + 1, p[0], p[1], p[2]);
    }
    s += "End Coordinates\nElements\n";
    for (t, v) in d.tets.iter().enumerate() {
        s += &format!(
            "{} {} {} {} {} {}\n",
            t + 1,
            v[0] + 1,
            v[1] + 1,
            v[2] + 1,
            v[3] + 1,
            d.region(t)
        );
    }
    s += "End Elements\n";
    s.into_bytes()
}

/// Every seed: each shipped mesh format (the small mesh of each, in each
/// variant the readers know), indicators and size fields, surfaces, and
/// mesher inputs.
pub fn seeds() -> Vec<Seed> {
    let mesh = reference_mesh();
    let n = mesh.n_tets();
    let mut s = vec![
        seed("medit", "m.mesh", read("meshes/mmg_cube.mesh"), Kind::Mesh),
        seed(
            "medit (tetrefine)",
            "m.mesh",
            written(&mesh, "m.mesh"),
            Kind::Mesh,
        ),
        seed(
            "gmsh 2.2 ascii",
            "m.msh",
            read("meshes/mmg_cube.msh"),
            Kind::Mesh,
        ),
        seed(
            "gmsh 4.1 ascii",
            "m.msh",
            written(&mesh, "m.msh"),
            Kind::Mesh,
        ),
        seed(
            "gmsh 2.2 binary",
            "m.msh",
            read("tests/data/mmg_cube_v22_binary.msh"),
            Kind::Mesh,
        ),
        seed(
            "gmsh 4.1 binary",
            "m.msh",
            read("tests/data/mmg_cube_v41_binary.msh"),
            Kind::Mesh,
        ),
        seed(
            "vtu appended raw",
            "m.vtu",
            read("meshes/mmg_cube.vtu"),
            Kind::Mesh,
        ),
        seed(
            "vtu ascii",
            "m.vtu",
            read("tests/data/mmg_cube_vtk_ascii.vtu"),
            Kind::Mesh,
        ),
        seed(
            "vtu inline binary",
            "m.vtu",
            read("tests/data/mmg_cube_vtk_inline_raw.vtu"),
            Kind::Mesh,
        ),
        seed(
            "vtu appended base64 zlib",
            "m.vtu",
            read("tests/data/mmg_cube_vtk_appended_base64_zlib.vtu"),
            Kind::Mesh,
        ),
        seed(
            "vtu zlib (tetrefine)",
            "m.vtu",
            written(&mesh, "m.vtu"),
            Kind::Mesh,
        ),
        seed("gid", "m.GiD.msh", gid(&mesh), Kind::Mesh),
    ];
    // TetGen: mutate each file of the set in turn.
    let tg = ["node", "ele", "face", "edge"];
    for (i, ext) in tg.iter().enumerate() {
        let name: &'static str = [
            "tetgen .node",
            "tetgen .ele",
            "tetgen .face",
            "tetgen .edge",
        ][i];
        s.push(Seed {
            name,
            file: format!("m.{ext}"),
            bytes: read(&format!("tests/data/tetgen_example.1.{ext}")),
            kind: Kind::Mesh,
            siblings: tg
                .iter()
                .filter(|e| *e != ext)
                .map(|e| {
                    (
                        format!("m.{e}"),
                        read(&format!("tests/data/tetgen_example.1.{e}")),
                    )
                })
                .collect(),
        });
    }
    // Indicators of the reference mesh, and a size field at its vertices.
    let plain: String = (0..n)
        .map(|t| format!("{}\n", (t * 37 % 101) as f64 / 7.0))
        .collect();
    let csv: String = std::iter::once("tet,value\n".to_string())
        .chain((0..n).map(|t| format!("{t},{}\n", (t * 13 % 17) as f64)))
        .collect();
    let sol_t: String = format!(
        "MeshVersionFormatted 2\nDimension 3\nSolAtTetrahedra\n{n}\n1 1\n{}End\n",
        (0..n).map(|t| format!("{}\n", t % 9)).collect::<String>()
    );
    let np = mesh.n_points();
    let sol_v: String = format!(
        "MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n{np}\n1 1\n{}End\n",
        (0..np)
            .map(|v| format!("{}\n", 0.05 + (v % 5) as f64 * 0.01))
            .collect::<String>()
    );
    s.push(seed(
        "indicator text",
        "i.txt",
        plain.into_bytes(),
        Kind::Indicator,
    ));
    s.push(seed(
        "indicator csv",
        "i.csv",
        csv.into_bytes(),
        Kind::Indicator,
    ));
    s.push(seed(
        "indicator .sol",
        "i.sol",
        sol_t.into_bytes(),
        Kind::Indicator,
    ));
    s.push(seed(
        "size .sol (vertices)",
        "s.sol",
        sol_v.into_bytes(),
        Kind::Indicator,
    ));
    s.push(seed(
        "surface .obj",
        "s.obj",
        CUBE_OBJ.into(),
        Kind::Surface,
    ));
    s.push(seed(
        "surface .off",
        "s.off",
        CUBE_OFF.into(),
        Kind::Surface,
    ));
    s.push(seed(
        "surface .ply",
        "s.ply",
        CUBE_PLY.into(),
        Kind::Surface,
    ));
    s.push(seed(
        "surface .ply binary",
        "s.ply",
        cube_ply_binary(),
        Kind::Surface,
    ));
    s.push(seed(
        "surface .stl ascii",
        "s.stl",
        stl_ascii(),
        Kind::Surface,
    ));
    s.push(seed(
        "surface .stl binary",
        "s.stl",
        stl_binary(),
        Kind::Surface,
    ));
    s.push(seed(
        "plc .poly",
        "p.poly",
        read("meshes/tetgen_example.poly"),
        Kind::Plc,
    ));
    s.push(seed("plc .off", "p.off", CUBE_OFF.into(), Kind::Plc));
    s.push(seed("plc .stl ascii", "p.stl", stl_ascii(), Kind::Plc));
    s.push(seed("plc .stl binary", "p.stl", stl_binary(), Kind::Plc));
    s
}

/// Numbers a hostile user tries.
const NASTY: &[&str] = &[
    "nan",
    "NaN",
    "inf",
    "-inf",
    "-1",
    "0",
    "1e308",
    "-1e308",
    "1e-320",
    "1099511627776",
    "4611686018427387904",
    "1073741823",
    "4294967295",
    "18446744073709551616",
    "2147483648",
    "99999999999999999999999",
    "",
    "x",
];

/// Token spans (runs of non-whitespace) of a text.
fn tokens(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        while i < b.len() && b[i].is_ascii_whitespace() {
            i += 1;
        }
        let s = i;
        while i < b.len() && !b[i].is_ascii_whitespace() {
            i += 1;
        }
        if i > s {
            out.push((s, i));
        }
    }
    out
}

/// Line starts of a text.
fn line_starts(b: &[u8]) -> Vec<usize> {
    std::iter::once(0)
        .chain(
            b.iter()
                .enumerate()
                .filter(|(_, &c)| c == b'\n')
                .map(|(i, _)| i + 1),
        )
        .filter(|&i| i < b.len())
        .collect()
}

/// One seeded mutation of `b`; its name for the failure reports.
pub fn mutate(b: &[u8], rng: &mut Rng) -> (Vec<u8>, &'static str) {
    let mut m = b.to_vec();
    if m.is_empty() {
        return (m, "empty");
    }
    let kinds = 11;
    match rng.below(kinds) {
        0 => {
            let n = 1 + rng.below(8);
            for _ in 0..n {
                let i = rng.below(m.len());
                m[i] ^= 1 << rng.below(8);
            }
            (m, "bit flips")
        }
        1 => {
            m.truncate(rng.below(m.len()));
            (m, "truncation")
        }
        2 | 3 => {
            let toks = tokens(&m);
            if toks.is_empty() {
                return (m, "no token");
            }
            // Early tokens (headers, counts) more often.
            let k = if rng.below(2) == 0 {
                rng.below(toks.len().min(40))
            } else {
                rng.below(toks.len())
            };
            let (s, e) = toks[k];
            let with = NASTY[rng.below(NASTY.len())];
            m.splice(s..e, with.bytes());
            (m, "nasty number")
        }
        4 => {
            let ls = line_starts(&m);
            let k = rng.below(ls.len());
            let end = ls.get(k + 1).copied().unwrap_or(m.len());
            m.drain(ls[k]..end);
            (m, "deleted line")
        }
        5 => {
            let ls = line_starts(&m);
            let k = rng.below(ls.len());
            let end = ls.get(k + 1).copied().unwrap_or(m.len());
            let line = m[ls[k]..end].to_vec();
            let at = end;
            m.splice(at..at, line);
            (m, "duplicated line")
        }
        6 => {
            let ls = line_starts(&m);
            if ls.len() < 2 {
                return (m, "one line");
            }
            let (a, c) = (rng.below(ls.len()), rng.below(ls.len()));
            let la = ls[a]..ls.get(a + 1).copied().unwrap_or(m.len());
            let lc = ls[c]..ls.get(c + 1).copied().unwrap_or(m.len());
            let (x, y) = (m[la.clone()].to_vec(), m[lc.clone()].to_vec());
            if la.start < lc.start && la.end <= lc.start {
                m.splice(lc, x);
                m.splice(la, y);
            }
            (m, "swapped lines")
        }
        7 => {
            let i = rng.below(m.len());
            let n = 1 + rng.below(16);
            let junk: Vec<u8> = (0..n).map(|_| rng.next() as u8).collect();
            m.splice(i..i, junk);
            (m, "inserted bytes")
        }
        8 => {
            let i = rng.below(m.len());
            let n = (1 + rng.below(64)).min(m.len() - i);
            let v = if rng.below(2) == 0 { 0 } else { 0xFF };
            m[i..i + n].fill(v);
            (m, "overwritten bytes")
        }
        9 => {
            // A binary word overwritten with a large value (block sizes, counts).
            let i = rng.below(m.len());
            let w = [u32::MAX, 1 << 30, 0x7FFF_FFFF, 0, 1][rng.below(5)].to_le_bytes();
            for (k, c) in w.iter().enumerate() {
                if let Some(x) = m.get_mut(i + k) {
                    *x = *c;
                }
            }
            (m, "overwritten word")
        }
        _ => {
            let toks = tokens(&m);
            if toks.is_empty() {
                return (m, "no token");
            }
            let (s, e) = toks[rng.below(toks.len())];
            m.drain(s..e);
            (m, "deleted token")
        }
    }
}

/// The outcome of one case.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Read, and passed its checks.
    Ok,
    /// Refused with an error naming the file.
    Refused,
    /// A broken promise (a panic, an error not naming the file, a success
    /// that fails `check()`, a CLI output after an error, …).
    Failure(String),
}

/// Reads the mutant `path` as `kind`, in-process.
pub fn run_case(kind: Kind, path: &Path, mesh: &tetrefine::TetMesh, names: &[&str]) -> Outcome {
    let result = std::panic::catch_unwind(AssertUnwindSafe(|| -> Result<(), String> {
        match kind {
            Kind::Mesh => {
                let (m, _) = tetrefine::io::load_mesh(path).map_err(|e| e.to_string())?;
                m.check().map_err(|e| format!("CHECK: {e}"))?;
            }
            Kind::Indicator => {
                let v = tetrefine::io::read_indicator(path.to_str().unwrap(), mesh)
                    .map_err(|e| e.to_string())?;
                if v.len() != mesh.n_tets() {
                    return Err(format!(
                        "CHECK: {} values for {} tets",
                        v.len(),
                        mesh.n_tets()
                    ));
                }
            }
            Kind::Surface => {
                let s = tetrefine_surface::io::load_surface(path).map_err(|e| e.to_string())?;
                s.validate().map_err(|e| format!("CHECK: {e}"))?;
            }
            Kind::Plc => {
                let p = tetrefine::io::Plc::read(path).map_err(|e| e.to_string())?;
                // Analysis may refuse the surface; that is not the reader's error.
                let _ = p.analyze();
            }
        }
        Ok(())
    }));
    match result {
        Err(p) => {
            let msg = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            Outcome::Failure(format!("panic: {msg}"))
        }
        Ok(Ok(())) => Outcome::Ok,
        Ok(Err(e)) if e.starts_with("CHECK: ") => Outcome::Failure(e),
        Ok(Err(e)) => {
            if names.iter().any(|n| e.contains(n)) {
                Outcome::Refused
            } else {
                Outcome::Failure(format!("error does not name the file: {e}"))
            }
        }
    }
}

/// Runs a mutant through the CLI (`convert` for meshes, `refine --indicator`
/// for indicators, `surface` for surfaces; mesher inputs need TetGen, so
/// they are read in-process only) and checks the CLI's promises.
pub fn run_cli_case(kind: Kind, path: &Path, dir: &Path, names: &[&str]) -> Option<Outcome> {
    let exe = tetrefine_exe();
    let out = dir.join(match kind {
        Kind::Surface => "out.obj",
        _ => "out.mesh",
    });
    let reference = root().join("meshes/mmg_cube.mesh");
    let args: Vec<String> = match kind {
        Kind::Mesh => vec![
            "convert".into(),
            path.display().to_string(),
            out.display().to_string(),
        ],
        Kind::Indicator => vec![
            "refine".into(),
            reference.display().to_string(),
            "-o".into(),
            out.display().to_string(),
            "--indicator".into(),
            path.display().to_string(),
            "--mark".into(),
            "fraction:0.1".into(),
            "--opt-passes".into(),
            "0".into(),
            "--allow-empty".into(),
        ],
        Kind::Surface => vec![
            "surface".into(),
            "catmull-clark".into(),
            path.display().to_string(),
            "-o".into(),
            out.display().to_string(),
            "--steps".into(),
            "1".into(),
        ],
        Kind::Plc => return None,
    };
    let o = std::process::Command::new(exe).args(&args).output().ok()?;
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    let leftovers: Vec<String> = std::fs::read_dir(dir)
        .ok()?
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|f| f.contains(".tetrefine-"))
        .collect();
    let outcome = match o.status.code() {
        Some(0) => {
            if !out.exists() {
                Outcome::Failure("exit 0 but no output".into())
            } else if kind == Kind::Surface {
                match tetrefine_surface::io::load_surface(&out) {
                    Ok(_) => Outcome::Ok,
                    Err(e) => Outcome::Failure(format!("output does not read back: {e}")),
                }
            } else {
                match tetrefine::io::load_mesh(&out) {
                    Ok((m, _)) => match m.check() {
                        Ok(()) => Outcome::Ok,
                        Err(e) => Outcome::Failure(format!("output fails check(): {e}")),
                    },
                    Err(e) => Outcome::Failure(format!("output does not read back: {e}")),
                }
            }
        }
        Some(1) => {
            let last = err.lines().last().unwrap_or("");
            if out.exists() {
                Outcome::Failure(format!("an output after an error: {last}"))
            } else if !last.starts_with("error: ") || !names.iter().any(|n| last.contains(n)) {
                Outcome::Failure(format!("error line does not name the file: {err}"))
            } else {
                Outcome::Refused
            }
        }
        code => Outcome::Failure(format!("exit {code:?} (signal or panic): {err}")),
    };
    let _ = std::fs::remove_file(&out);
    if !leftovers.is_empty() && outcome != Outcome::Ok {
        return Some(Outcome::Failure(format!(
            "temporary files left: {leftovers:?}"
        )));
    }
    Some(outcome)
}

/// The `tetrefine` binary: Cargo's for tests, else `$TETREFINE_BIN`, else
/// `target/release/tetrefine`.
pub fn tetrefine_exe() -> PathBuf {
    option_env!("CARGO_BIN_EXE_tetrefine")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("TETREFINE_BIN").map(PathBuf::from))
        .unwrap_or_else(|| root().join("target/release/tetrefine"))
}

/// Counts per seed.
#[derive(Clone, Debug, Default)]
pub struct Counts {
    /// In-process cases.
    pub cases: usize,
    /// Of which read and checked.
    pub ok: usize,
    /// Of which refused with a good error.
    pub refused: usize,
    /// CLI cases.
    pub cli_cases: usize,
    /// Of which succeeded.
    pub cli_ok: usize,
    /// Of which refused correctly.
    pub cli_refused: usize,
    /// Broken promises: (mutation, message, saved file).
    pub failures: Vec<(String, String, PathBuf)>,
    /// The slowest case.
    pub slowest: Duration,
}

/// Runs seeded cases over every seed until `per_seed` in-process cases
/// each (every `cli_every`-th also through the CLI) or `budget` runs out
/// (shared evenly between seeds). Mutants that break a promise are kept in
/// `keep` for inspection.
pub fn fuzz(
    seed: u64,
    per_seed: usize,
    cli_every: usize,
    budget: Duration,
    keep: &Path,
) -> Vec<(&'static str, Counts)> {
    let seeds = seeds();
    let mesh = reference_mesh();
    let slice = budget / seeds.len() as u32;
    let mut all = Vec::new();
    for (si, sd) in seeds.iter().enumerate() {
        let dir = tempfile::tempdir().expect("temp dir");
        for (name, bytes) in &sd.siblings {
            std::fs::write(dir.path().join(name), bytes).expect("sibling");
        }
        let path = dir.path().join(&sd.file);
        let stem = Path::new(&sd.file)
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        let mut names: Vec<String> = vec![path.display().to_string()];
        if sd.kind == Kind::Mesh && !sd.siblings.is_empty() {
            // A TetGen error may name any file of the set.
            names.push(dir.path().join(&stem).display().to_string());
        }
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        let mut rng = Rng::new(seed ^ (si as u64).wrapping_mul(0x2545_F491_4F6C_DD1D));
        let mut c = Counts::default();
        let t0 = Instant::now();
        while c.cases < per_seed && t0.elapsed() < slice {
            let (m, how) = mutate(&sd.bytes, &mut rng);
            std::fs::write(&path, &m).expect("write mutant");
            let t = Instant::now();
            let outcome = run_case(sd.kind, &path, &mesh, &names);
            c.slowest = c.slowest.max(t.elapsed());
            c.cases += 1;
            let record = |c: &mut Counts, o: Outcome, via: &str| match o {
                Outcome::Ok => {}
                Outcome::Refused => {}
                Outcome::Failure(msg) => {
                    let _ = std::fs::create_dir_all(keep);
                    let kept = keep.join(format!(
                        "{}-{}-{}",
                        sd.name.replace([' ', '.', '(', ')'], "_"),
                        c.cases,
                        sd.file
                    ));
                    let _ = std::fs::write(&kept, &m);
                    c.failures.push((format!("{how} ({via})"), msg, kept));
                }
            };
            match &outcome {
                Outcome::Ok => c.ok += 1,
                Outcome::Refused => c.refused += 1,
                Outcome::Failure(_) => {}
            }
            record(&mut c, outcome, "library");
            if cli_every > 0 && c.cases % cli_every == 0 {
                if let Some(o) = run_cli_case(sd.kind, &path, dir.path(), &names) {
                    c.cli_cases += 1;
                    match &o {
                        Outcome::Ok => c.cli_ok += 1,
                        Outcome::Refused => c.cli_refused += 1,
                        Outcome::Failure(_) => {}
                    }
                    record(&mut c, o, "cli");
                }
            }
        }
        all.push((sd.name, c));
    }
    all
}

/// A table of the counts.
pub fn table(counts: &[(&'static str, Counts)]) -> String {
    let mut s = format!(
        "{:<28} {:>8} {:>8} {:>8} {:>6} {:>6} {:>6} {:>5} {:>9}\n",
        "seed", "cases", "ok", "refused", "cli", "ok", "ref", "fail", "slowest"
    );
    for (n, c) in counts {
        s += &format!(
            "{:<28} {:>8} {:>8} {:>8} {:>6} {:>6} {:>6} {:>5} {:>7.1}ms\n",
            n,
            c.cases,
            c.ok,
            c.refused,
            c.cli_cases,
            c.cli_ok,
            c.cli_refused,
            c.failures.len(),
            c.slowest.as_secs_f64() * 1e3
        );
    }
    s
}
