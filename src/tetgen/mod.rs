//! Tetrahedral meshing and refinement with TetGen (Hang Si, WIAS Berlin,
//! <https://tetgen.org>), through the crate's own FFI crate `tetgen-ffi` over
//! Debian's `libtet`. Opt-in: build with `--features tetgen`. TetGen is
//! AGPL-3, and so is a binary built with this feature.
//!
//! * [`tetrahedralize`]: a [`Plc`] (surface, holes, region seeds) to a
//!   [`TetMesh`] (TetGen's `-p`); region attributes become the tets'
//!   `region` (`-A`), facet markers become boundary face markers.
//! * [`refine`]: a [`TetMesh`] refined by TetGen (`-r`), optionally driven by a
//!   per-vertex size field (`-m`), so that benchmarks can compare TetGen's
//!   refinement with the crate's own.
//!
//! Both check their input in Rust first (TetGen aborts the process on some
//! degenerate input; see [`Plc::validate`]) and their result after: at least
//! one tet, [`TetMesh::check`] passes, and the volume equals the volume the
//! input encloses (relative 1e-9, plus the slack of non-planar facets).
//! TetGen's own errors come back as [`TetgenError::Tetgen`]; the process
//! survives them, and calls are serialised (TetGen is not thread-safe).
//!
//! With [`Options::isolation`] = [`Isolation::Child`], TetGen runs in a child
//! process forked for the call (Unix): a TetGen that crashes comes back as
//! [`TetgenError::Crashed`] naming the signal, and one that runs longer than
//! the time limit is killed and comes back as [`TetgenError::TimedOut`]. The
//! caller survives both. The result is the same mesh as in-process (TetGen
//! is deterministic; its output arrays are sent back over a pipe unchanged).

mod child;

use crate::geom::tet_volume;
use crate::io::plc::{Plc, PlcError};
use crate::mesh::{face_key, MeshData, TetMesh, NO_ADJ};
use std::collections::{BTreeMap, HashMap};
use std::time::Duration;

/// Where TetGen runs; see [`Options::isolation`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Isolation {
    /// In the calling process (the default). Fastest, but a crash of TetGen
    /// (an assertion or a segmentation fault on input the checks let
    /// through) ends the process, and nothing can stop a run that does not
    /// finish.
    #[default]
    InProcess,
    /// In a child process forked for the call (`fork`, the result sent back
    /// over a pipe; Unix only). A child that dies by a signal gives
    /// [`TetgenError::Crashed`]; with `time_limit`, a child still running
    /// after that long is killed (`SIGKILL`) and the call gives
    /// [`TetgenError::TimedOut`]. On Linux the child also dies with the
    /// thread that forked it, so a caller killed meanwhile leaves no TetGen
    /// running. Costs a fork and a copy of the output (milliseconds).
    Child {
        /// Longest time TetGen may run (`None`: no limit).
        time_limit: Option<Duration>,
    },
}

/// How to mesh or refine. Every field is optional.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Options {
    /// Largest radius-edge ratio of a tet (TetGen `-q<ratio>`; TetGen's
    /// default 2.0 applies when only `min_dihedral` is given).
    pub min_ratio: Option<f64>,
    /// Smallest dihedral angle in degrees (TetGen `-q<ratio>/<angle>`).
    pub min_dihedral: Option<f64>,
    /// Largest tet volume everywhere (TetGen `-a<volume>`).
    pub max_volume: Option<f64>,
    /// More TetGen switches, without the dash, appended after the ones above
    /// (TetGen keeps the last value of a repeated switch).
    pub switches: Option<String>,
    /// [`refine`] only: target edge length at each point of the mesh, indexed
    /// like its points (TetGen `-m` with one size per point).
    pub size_field: Option<Vec<f64>>,
    /// Where TetGen runs: in this process (the default) or in a child
    /// process, with an optional time limit.
    pub isolation: Isolation,
}

/// Why meshing or refining failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TetgenError {
    /// The surface is not something TetGen may be given.
    #[error("{0}")]
    Input(#[from] PlcError),
    /// The mesh to refine is not valid.
    #[error("the mesh to refine is not valid: {0}")]
    InvalidMesh(String),
    /// An option or switch is out of range or not allowed.
    #[error("{0}")]
    Options(String),
    /// TetGen stopped with an error.
    #[error("{0}")]
    Tetgen(String),
    /// TetGen returned no tetrahedra.
    #[error("TetGen produced no tetrahedra (switches -{0})")]
    Empty(String),
    /// TetGen's result is not a valid mesh.
    #[error("TetGen's output is not a valid mesh: {0}")]
    InvalidOutput(String),
    /// TetGen ran longer than the time limit of [`Isolation::Child`]; its
    /// process was killed.
    #[error("TetGen did not finish within {seconds} s and was stopped (switches -{switches})")]
    TimedOut {
        /// The time limit, in seconds.
        seconds: f64,
        /// The switches used.
        switches: String,
    },
    /// TetGen's child process ([`Isolation::Child`]) died by a signal: TetGen
    /// crashed (or the process was killed from outside), and no mesh came
    /// back. The caller's process is unharmed.
    #[error(
        "TetGen crashed: its process died by signal {signal} ({}) while {input} (switches -{switches})",
        child::signal_name(*.signal)
    )]
    Crashed {
        /// The signal number (`11` is `SIGSEGV`, `6` `SIGABRT`).
        signal: i32,
        /// The switches used.
        switches: String,
        /// What TetGen was given, e.g. "meshing 8 points and 6 facets".
        input: String,
    },
    /// TetGen's child process could not be started or ended without a
    /// result (fork or pipe failure, an exit without a result).
    #[error("{0}")]
    Child(String),
    /// TetGen's mesh does not fill the volume it should.
    #[error(
        "TetGen's mesh has volume {got} but the input encloses {expected} (switches -{switches})"
    )]
    VolumeMismatch {
        /// Volume of the input.
        expected: f64,
        /// Volume of TetGen's mesh.
        got: f64,
        /// The switches used.
        switches: String,
    },
}

fn ffi_error(e: tetgen_ffi::Error) -> TetgenError {
    TetgenError::Tetgen(e.message())
}

/// TetGen's result (or error) as bytes, for the pipe of a child process.
fn encode(r: &Result<tetgen_ffi::Output, tetgen_ffi::Error>) -> Vec<u8> {
    use child::wire::{put_f64s, put_i32s, put_len};
    let mut b = Vec::new();
    match r {
        Ok(o) => {
            b.push(0);
            b.reserve(
                8 * (o.points.len() + o.tet_attributes.len() + 5)
                    + 4 * (o.tets.len() + o.trifaces.len() + o.trifacemarkers.len()),
            );
            put_f64s(&mut b, &o.points);
            put_i32s(&mut b, &o.tets);
            put_f64s(&mut b, &o.tet_attributes);
            put_i32s(&mut b, &o.trifaces);
            put_i32s(&mut b, &o.trifacemarkers);
        }
        Err(tetgen_ffi::Error::InvalidInput(m)) => {
            b.push(1);
            put_len(&mut b, m.len());
            b.extend_from_slice(m.as_bytes());
        }
        Err(tetgen_ffi::Error::Tetgen(code)) => {
            b.push(2);
            put_i32s(&mut b, &[*code]);
        }
    }
    b
}

/// The inverse of [`encode`]; `None` for bytes it did not write.
fn decode(bytes: &[u8]) -> Option<Result<tetgen_ffi::Output, tetgen_ffi::Error>> {
    let mut r = child::wire::Reader(bytes);
    let v = match r.u8()? {
        0 => Ok(tetgen_ffi::Output {
            points: r.f64s()?,
            tets: r.i32s()?,
            tet_attributes: r.f64s()?,
            trifaces: r.i32s()?,
            trifacemarkers: r.i32s()?,
        }),
        1 => Err(tetgen_ffi::Error::InvalidInput(r.string()?)),
        2 => match r.i32s()?.as_slice() {
            [code] => Err(tetgen_ffi::Error::Tetgen(*code)),
            _ => return None,
        },
        _ => return None,
    };
    r.is_empty().then_some(v)
}

/// Runs TetGen on `input` with switches `sw`, where `isolation` says;
/// `what` says what the input is for [`TetgenError::Crashed`].
fn run_tetgen(
    sw: &str,
    input: &tetgen_ffi::Input,
    isolation: Isolation,
    what: impl FnOnce() -> String,
) -> Result<tetgen_ffi::Output, TetgenError> {
    let time_limit = match isolation {
        Isolation::InProcess => {
            return quiet_stdout(|| tetgen_ffi::tetrahedralize(sw, input)).map_err(ffi_error)
        }
        Isolation::Child { time_limit } => time_limit,
    };
    if let Some(t) = time_limit {
        if t.is_zero() {
            return Err(TetgenError::Options(
                "a time limit of 0 s leaves TetGen no time (use None for no limit)".into(),
            ));
        }
    }
    // Flush what the caller printed, so that the child does not print it again.
    {
        use std::io::Write;
        let _ = std::io::stdout().flush();
        let _ = std::io::stderr().flush();
        // SAFETY: fflush(NULL) flushes every C stream; no preconditions.
        unsafe { libc::fflush(std::ptr::null_mut()) };
    }
    let lock = tetgen_ffi::lock();
    let bytes = child::run(time_limit, lock, |lock| {
        encode(&tetgen_ffi::tetrahedralize_locked(lock, sw, input))
    });
    match bytes {
        Ok(b) => match decode(&b) {
            Some(r) => r.map_err(ffi_error),
            None => Err(TetgenError::Child(format!(
                "TetGen's child process sent back {} bytes that are not a whole result",
                b.len()
            ))),
        },
        Err(child::ChildError::TimedOut) => Err(TetgenError::TimedOut {
            seconds: time_limit.map_or(0.0, |t| t.as_secs_f64()),
            switches: sw.to_string(),
        }),
        Err(child::ChildError::Signal(signal)) => Err(TetgenError::Crashed {
            signal,
            switches: sw.to_string(),
            input: what(),
        }),
        Err(child::ChildError::Failed(m)) => Err(TetgenError::Child(m)),
    }
}

/// Switches this crate never passes to TetGen, with the reason.
const REFUSED: [(char, &str); 10] = [
    ('r', "use `refine` to refine a mesh (-r)"),
    (
        'c',
        "-c keeps the convex hull, so the mesh would not match the surface",
    ),
    ('d', "-d only detects self-intersections and makes no mesh"),
    ('w', "-w (weighted Delaunay) is not supported"),
    ('v', "-v (Voronoi output) is not supported"),
    ('k', "-k writes files of its own"),
    ('g', "-g writes files of its own"),
    ('i', "-i inserts points from a file"),
    ('N', "-N suppresses the output points"),
    ('E', "-E suppresses the output tetrahedra"),
];

/// Longest user switch string accepted (TetGen's own buffer holds 1,024).
pub const MAX_SWITCHES_LEN: usize = 256;

/// The switches of `s` that take a number, with their number text
/// (`q1.414/18` → `('q', "1.414/18")`), in order.
fn switch_values(s: &str) -> Vec<(char, &str)> {
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i] as char;
        i += 1;
        if matches!(c, 'q' | 'a' | 'O' | 'T' | 'S') {
            let start = i;
            while i < b.len() && (b[i].is_ascii_digit() || b"./eE+-".contains(&b[i])) {
                // An 'e' is an exponent only right after a digit or '.'.
                if (b[i] == b'e' || b[i] == b'E')
                    && !(i > start && (b[i - 1].is_ascii_digit() || b[i - 1] == b'.'))
                {
                    break;
                }
                i += 1;
            }
            out.push((c, &s[start..i]));
        }
    }
    out
}

/// The last maximum volume of a switch string (`a<V>`), if any.
pub fn max_volume_switch(s: &str) -> Option<f64> {
    switch_values(s)
        .into_iter()
        .filter(|(c, v)| *c == 'a' && !v.is_empty())
        .filter_map(|(_, v)| v.parse::<f64>().ok())
        .next_back()
}

/// Checks the user's switches: printable ASCII, no refused switch,
/// no second-order elements.
fn check_switches(s: &str, refine: bool) -> Result<(), TetgenError> {
    // TetGen copies the switches into a 1 KiB buffer (and aborts beyond it).
    if s.len() > MAX_SWITCHES_LEN {
        return Err(TetgenError::Options(format!(
            "TetGen switches of {} characters: at most {MAX_SWITCHES_LEN} are accepted",
            s.len()
        )));
    }
    for (letter, value) in switch_values(s) {
        let bad = |why: &str| {
            Err(TetgenError::Options(format!(
                "TetGen switch -{letter}{value}: {why}"
            )))
        };
        let mut parts = value.split('/');
        let first = parts.next().unwrap_or("");
        let num = |t: &str| t.parse::<f64>().ok().filter(|x| x.is_finite());
        match letter {
            'q' => {
                if let Some(r) = (!first.is_empty()).then(|| num(first)).flatten() {
                    if r < 1.0 {
                        return bad("a radius-edge bound below 1.0, where TetGen's refinement need not terminate");
                    }
                } else if !first.is_empty() {
                    return bad("the radius-edge bound is not a number");
                }
                if let Some(d) = parts.next() {
                    match num(d) {
                        Some(d) if d > 0.0 && d < 70.0 => {}
                        _ => return bad("the minimum dihedral angle must lie in (0, 70) degrees"),
                    }
                }
            }
            'a' if !first.is_empty() => match num(first) {
                Some(v) if v > 0.0 => {}
                _ => return bad("the maximum volume must be a positive number"),
            },
            _ => {}
        }
    }
    if let Some(c) = s.chars().find(|c| !c.is_ascii_graphic()) {
        return Err(TetgenError::Options(format!(
            "TetGen switches must be printable ASCII without spaces, found {c:?}"
        )));
    }
    for (c, why) in REFUSED {
        if c == 'r' && refine {
            continue;
        }
        // A lowercase 'e' may be an exponent; none of the refused letters can.
        if s.contains(c) {
            return Err(TetgenError::Options(format!(
                "TetGen switch -{c} is not allowed here: {why}"
            )));
        }
    }
    if s.contains("o2") {
        return Err(TetgenError::Options(
            "TetGen switch -o2 (second-order elements) is not supported".into(),
        ));
    }
    Ok(())
}

fn positive(x: f64, what: &str) -> Result<f64, TetgenError> {
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(TetgenError::Options(format!(
            "{what} must be a positive number, got {x}"
        )))
    }
}

/// The switch string for `opts`: `p` for meshing a PLC or `r` for refining,
/// the bounds of `opts`, `extra` (switches the input implies: `A`, `m`), the
/// user's `opts.switches` (checked; a leading `-` is dropped), then `Q`.
pub fn switches(opts: &Options, refine: bool, extra: &str) -> Result<String, TetgenError> {
    let mut s = String::from(if refine { "r" } else { "p" });
    if opts.min_ratio.is_some() || opts.min_dihedral.is_some() {
        let r = match opts.min_ratio {
            Some(r) => {
                let r = positive(r, "the radius-edge ratio bound")?;
                if r < 1.0 {
                    return Err(TetgenError::Options(format!(
                        "the radius-edge ratio bound {r} is below 1.0, where TetGen's refinement need not terminate"
                    )));
                }
                r
            }
            None => 2.0,
        };
        s += &format!("q{r}");
        if let Some(d) = opts.min_dihedral {
            let d = positive(d, "the minimum dihedral angle")?;
            if d >= 70.0 {
                return Err(TetgenError::Options(format!(
                    "a minimum dihedral angle of {d}° is impossible (the regular tetrahedron has 70.53°)"
                )));
            }
            s += &format!("/{d}");
        }
    }
    if let Some(v) = opts.max_volume {
        s += &format!("a{}", positive(v, "the maximum volume")?);
    }
    s += extra;
    if let Some(user) = &opts.switches {
        // A leading dash, as on TetGen's command line, is accepted.
        let user = user.strip_prefix('-').unwrap_or(user);
        check_switches(user, refine)?;
        s += user;
    }
    if !s.contains('V') && !s.contains('Q') {
        s.push('Q');
    }
    Ok(s)
}

/// Turns TetGen's output into a checked [`TetMesh`].
fn build_mesh(out: tetgen_ffi::Output, switches: &str) -> Result<TetMesh, TetgenError> {
    if out.n_tets() == 0 {
        return Err(TetgenError::Empty(switches.to_string()));
    }
    // Keep only the points the tets use (TetGen lists the input points
    // outside the domain too).
    let np = out.n_points();
    let mut new_id = vec![u32::MAX; np];
    let mut points = Vec::new();
    for &v in &out.tets {
        let v = v as usize;
        if new_id[v] == u32::MAX {
            new_id[v] = points.len() as u32;
            points.push([
                out.points[3 * v],
                out.points[3 * v + 1],
                out.points[3 * v + 2],
            ]);
        }
    }
    let tets: Vec<[u32; 4]> = out
        .tets
        .chunks_exact(4)
        .map(|t| [0, 1, 2, 3].map(|i| new_id[t[i] as usize]))
        .collect();
    let mut tet_regions = Vec::new();
    if !out.tet_attributes.is_empty() {
        tet_regions.reserve(tets.len());
        for &a in &out.tet_attributes {
            if a.fract() != 0.0 || a < i32::MIN as f64 || a > i32::MAX as f64 {
                return Err(TetgenError::InvalidOutput(format!(
                    "region attribute {a} is not an integer"
                )));
            }
            tet_regions.push(a as i32);
        }
    }
    let mut triangles = Vec::with_capacity(out.trifaces.len() / 3);
    for (i, f) in out.trifaces.chunks_exact(3).enumerate() {
        let ids = [0, 1, 2].map(|k| new_id[f[k] as usize]);
        if ids.contains(&u32::MAX) {
            continue; // a face of no tet (TetGen lists removed facets too)
        }
        triangles.push((ids, out.trifacemarkers.get(i).copied().unwrap_or(0)));
    }
    let data = MeshData {
        points,
        tets,
        tet_regions,
        triangles,
        ..Default::default()
    };
    let (mesh, _report) =
        TetMesh::from_data(&data).map_err(|e| TetgenError::InvalidOutput(e.to_string()))?;
    mesh.check()
        .map_err(|e| TetgenError::InvalidOutput(e.to_string()))?;
    Ok(mesh)
}

/// Total volume of the live tets.
fn mesh_volume(mesh: &TetMesh) -> f64 {
    mesh.tet_ids()
        .map(|t| tet_volume(&mesh.tet_points(t)))
        .sum()
}

/// Volume per region.
fn region_volumes(mesh: &TetMesh) -> BTreeMap<i32, f64> {
    let mut v = BTreeMap::new();
    for t in mesh.tet_ids() {
        *v.entry(mesh.region(t)).or_insert(0.0) += tet_volume(&mesh.tet_points(t));
    }
    v
}

/// Runs `f` with the process's standard output sent to standard error, so
/// that what TetGen prints (it writes messages with `printf` even with `-Q`
/// on some errors) never mixes with the command's own output.
fn quiet_stdout<R>(f: impl FnOnce() -> R) -> R {
    use std::io::Write;
    let _ = std::io::stdout().flush();
    // SAFETY: dup/dup2/close on the standard descriptors; the saved copy is
    // restored and closed before returning. TetGen calls are serialised.
    let saved = unsafe { libc::dup(1) };
    if saved >= 0 {
        // SAFETY: points descriptor 1 at the open descriptor 2; undone below.
        unsafe { libc::dup2(2, 1) };
    }
    let r = f();
    if saved >= 0 {
        // SAFETY: as above; C's stdout buffer is flushed first.
        unsafe {
            libc::fflush(std::ptr::null_mut());
            libc::dup2(saved, 1);
            libc::close(saved);
        }
    }
    r
}

/// TetGen's bytes per output tet, generously (its mesh, pools and the
/// output arrays).
const TETGEN_BYTES_PER_TET: f64 = 400.0;

/// Refuses a maximum volume bound whose mesh would not fit in memory:
/// TetGen makes at least `enclosed / V` tets (about six times as many in
/// practice), each taking [`TETGEN_BYTES_PER_TET`].
fn check_size(enclosed: f64, sw: &str) -> Result<(), TetgenError> {
    let Some(v) = max_volume_switch(sw) else {
        return Ok(());
    };
    let tets = 6.0 * enclosed / v;
    let need = tets * TETGEN_BYTES_PER_TET;
    let available = std::fs::read_to_string("/proc/meminfo").ok().and_then(|t| {
        t.lines()
            .find(|l| l.starts_with("MemAvailable:"))
            .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
            .map(|kb| kb * 1024.0)
    });
    match available {
        Some(a) if need > a => Err(TetgenError::Options(format!(
            "a maximum tet volume of {v:e} for an enclosed volume of {enclosed:e} means about {tets:.2e} tets and {:.1} GiB, more than the {:.1} GiB available",
            need / (1u64 << 30) as f64,
            a / (1u64 << 30) as f64
        ))),
        _ => Ok(()),
    }
}

fn check_volume(expected: f64, got: f64, slack: f64, switches: &str) -> Result<(), TetgenError> {
    if (got - expected).abs() <= 1e-9 * expected.abs() + 2.0 * slack {
        Ok(())
    } else {
        Err(TetgenError::VolumeMismatch {
            expected,
            got,
            switches: switches.to_string(),
        })
    }
}

/// Meshes the volume a PLC encloses with TetGen (`-p`).
///
/// The PLC is validated first ([`Plc::analyze`]); exactly coincident points
/// are merged before TetGen sees them. Switches: `p`, the quality and volume
/// bounds of `opts`, `A` when the PLC has region seeds (their attributes
/// become the tets' regions), then `opts.switches`, and `Q` unless `V` or `Q`
/// is there already. As in TetGen, the regions' maximum volumes apply only
/// when the switches contain a bare `a` (e.g. `switches: Some("a".into())`).
/// With `A`, a cell that no region seed names gets an attribute TetGen
/// chooses (TetGen 1.5: one more than the largest given).
pub fn tetrahedralize(plc: &Plc, opts: &Options) -> Result<TetMesh, TetgenError> {
    if opts.size_field.is_some() {
        return Err(TetgenError::Options(
            "a size field applies to `refine`, not to meshing a surface".into(),
        ));
    }
    let analysis = plc.analyze()?;
    let sw = switches(opts, false, if plc.regions.is_empty() { "" } else { "A" })?;
    check_size(analysis.enclosed, &sw)?;

    // Merge coincident points: TetGen would warn and drop them itself.
    let canon = plc.coincident_point_map();
    let mut new_id = vec![0i32; plc.points.len()];
    let mut points = Vec::with_capacity(3 * plc.points.len());
    for (i, &c) in canon.iter().enumerate() {
        if c as usize == i {
            new_id[i] = (points.len() / 3) as i32;
            points.extend_from_slice(&plc.points[i]);
        } else {
            new_id[i] = new_id[c as usize];
        }
    }
    let mut facet_polygon_counts = Vec::with_capacity(plc.facets.len());
    let mut polygon_vertex_counts = Vec::new();
    let mut polygon_vertices = Vec::new();
    let mut facet_markers = Vec::with_capacity(plc.facets.len());
    let mut facet_hole_counts = Vec::with_capacity(plc.facets.len());
    let mut facet_holes = Vec::new();
    for f in &plc.facets {
        facet_polygon_counts.push(f.polygons.len() as i32);
        for poly in &f.polygons {
            polygon_vertex_counts.push(poly.len() as i32);
            polygon_vertices.extend(poly.iter().map(|&v| new_id[v as usize]));
        }
        facet_markers.push(f.marker);
        facet_hole_counts.push(f.holes.len() as i32);
        facet_holes.extend(f.holes.iter().flatten());
    }
    let holes: Vec<f64> = plc.holes.iter().flatten().copied().collect();
    let regions: Vec<f64> = plc
        .regions
        .iter()
        .flat_map(|r| {
            [
                r.point[0],
                r.point[1],
                r.point[2],
                r.attribute as f64,
                r.max_volume.unwrap_or(-1.0),
            ]
        })
        .collect();
    let input = tetgen_ffi::Input {
        points: &points,
        facet_polygon_counts: &facet_polygon_counts,
        polygon_vertex_counts: &polygon_vertex_counts,
        polygon_vertices: &polygon_vertices,
        facet_markers: Some(&facet_markers),
        facet_hole_counts: Some(&facet_hole_counts),
        facet_holes: &facet_holes,
        holes: &holes,
        regions: &regions,
        ..Default::default()
    };
    let out = run_tetgen(&sw, &input, opts.isolation, || {
        format!(
            "meshing {} points and {} facets",
            points.len() / 3,
            plc.facets.len()
        )
    })?;
    let mesh = build_mesh(out, &sw)?;
    check_volume(
        analysis.enclosed,
        mesh_volume(&mesh),
        analysis.planarity_slack,
        &sw,
    )?;
    Ok(mesh)
}

/// Refines a tet mesh with TetGen (`-r`), keeping its boundary, its region
/// interfaces and their markers, and its regions.
///
/// Switches: `r`, the bounds of `opts`, `m` with a size field (and `q`,
/// TetGen's default quality bound, when `opts` has none: TetGen applies the
/// size field only while it refines for quality), then `opts.switches`. The mesh is compacted first; `opts.size_field` is
/// indexed like `mesh`'s point slots. The result has the same volume per
/// region as the input.
pub fn refine(mesh: &TetMesh, opts: &Options) -> Result<TetMesh, TetgenError> {
    mesh.check()
        .map_err(|e| TetgenError::InvalidMesh(e.to_string()))?;
    if mesh.n_tets() == 0 {
        return Err(TetgenError::InvalidMesh("it has no tetrahedra".into()));
    }
    let mut m = mesh.clone();
    let remap = m.compact();
    let sizes: Option<Vec<f64>> = match &opts.size_field {
        None => None,
        Some(f) => {
            if f.len() != mesh.n_points() {
                return Err(TetgenError::Options(format!(
                    "the size field has {} values for {} points",
                    f.len(),
                    mesh.n_points()
                )));
            }
            let mut s = vec![0.0; m.n_points()];
            for (old, &new) in remap.points.iter().enumerate() {
                if new != u32::MAX {
                    s[new as usize] = positive(f[old], "every size in the size field")?;
                }
            }
            Some(s)
        }
    };
    // TetGen applies a size field while it refines for quality: with a size
    // field and no quality bound, ask for TetGen's default bound (`q`).
    let quality = opts.min_ratio.is_some()
        || opts.min_dihedral.is_some()
        || opts.switches.as_deref().is_some_and(|s| s.contains('q'));
    let extra = match (&sizes, quality) {
        (None, _) => "",
        (Some(_), true) => "m",
        (Some(_), false) => "mq",
    };
    let sw = switches(opts, true, extra)?;
    let points: Vec<f64> = m.points().iter().flat_map(|p| p.to_array()).collect();
    let ids: Vec<u32> = m.tet_ids().collect();
    let tets: Vec<i32> = ids
        .iter()
        .flat_map(|&t| m.tet(t).map(|v| v as i32))
        .collect();
    let attributes: Vec<f64> = ids.iter().map(|&t| m.region(t) as f64).collect();
    // Faces TetGen must keep: the boundary, faces between regions, and
    // every marked face, with their markers (0 when unmarked).
    let mut keep: HashMap<[u32; 3], i32> = HashMap::new();
    for &t in &ids {
        let adj = m.adj(t);
        for (f, &a) in adj.iter().enumerate() {
            let fv = m.face_vertices(t, f);
            let k = face_key(fv);
            let interface = a != NO_ADJ && m.region(a >> 2) != m.region(t);
            if a == NO_ADJ || interface || m.face_marker(fv).is_some() {
                keep.insert(k, m.face_marker(fv).unwrap_or(0));
            }
        }
    }
    let mut faces: Vec<([u32; 3], i32)> = keep.into_iter().collect();
    faces.sort_unstable();
    let trifaces: Vec<i32> = faces
        .iter()
        .flat_map(|(f, _)| f.map(|v| v as i32))
        .collect();
    let trifacemarkers: Vec<i32> = faces.iter().map(|&(_, mk)| mk).collect();
    let input = tetgen_ffi::Input {
        points: &points,
        tets: &tets,
        tet_attributes: Some(&attributes),
        point_sizes: sizes.as_deref(),
        trifaces: &trifaces,
        trifacemarkers: &trifacemarkers,
        ..Default::default()
    };
    let out = run_tetgen(&sw, &input, opts.isolation, || {
        format!("refining {} points and {} tets", m.n_points(), ids.len())
    })?;
    let refined = build_mesh(out, &sw)?;
    let before = region_volumes(&m);
    let after = region_volumes(&refined);
    for (r, &v) in &before {
        check_volume(v, after.get(r).copied().unwrap_or(0.0), 0.0, &sw)?;
    }
    if after.keys().any(|r| !before.contains_key(r)) {
        return Err(TetgenError::InvalidOutput(
            "refinement created a region the input does not have".into(),
        ));
    }
    Ok(refined)
}
