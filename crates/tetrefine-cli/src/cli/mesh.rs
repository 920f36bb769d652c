//! `tetrefine mesh IN -o OUT [--min-ratio R] [--min-dihedral DEG] [--max-volume V] [--switches S]
//! [--time-limit SECONDS]`: a surface to a tetrahedral mesh with TetGen (opt-in feature `tetgen`).

use std::path::PathBuf;

/// Arguments of `mesh`.
#[derive(clap::Args)]
pub struct Args {
    /// Input surface: TetGen .poly or .smesh, .off, .stl (ASCII or binary), or a
    /// Medit .mesh holding triangles only.
    pub input: PathBuf,
    /// Output mesh; the format follows the extension (.mesh, …).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Largest radius-edge ratio of a tet (TetGen -q; at least 1.0).
    #[arg(long, value_name = "R")]
    pub min_ratio: Option<f64>,
    /// Smallest dihedral angle in degrees (TetGen -q<R>/<DEG>; R defaults to 2.0).
    #[arg(long, value_name = "DEG")]
    pub min_dihedral: Option<f64>,
    /// Largest tet volume (TetGen -a).
    #[arg(long, value_name = "V")]
    pub max_volume: Option<f64>,
    /// More TetGen switches, appended after the ones above (e.g. pq1.414a0.002A).
    #[arg(long, value_name = "S", allow_hyphen_values = true)]
    pub switches: Option<String>,
    /// Stop TetGen after this many seconds with an error and no output
    /// (0: no limit). Some switch combinations make TetGen refine for hours.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 600.0,
        allow_hyphen_values = true
    )]
    pub time_limit: f64,
}

/// Ends the process when TetGen is still running after the time limit.
///
/// TetGen runs in this process (through the FFI crate) and cannot be
/// interrupted, so the watchdog thread ends the whole process with `_exit`
/// (no atexit handlers or C++ destructors run under TetGen's feet). Nothing
/// can be half-written then: the output is written only after TetGen has
/// returned and the main thread has disarmed the watchdog, and disarming
/// takes the same lock under which the watchdog exits, so it happens either
/// wholly before the output starts or not at all.
#[cfg(feature = "tetgen")]
struct Watchdog {
    armed: std::sync::Arc<(std::sync::Mutex<bool>, std::sync::Condvar)>,
}

#[cfg(feature = "tetgen")]
impl Watchdog {
    /// Arms a watchdog of `seconds` (none when 0); `input` names the file
    /// in the message.
    fn arm(seconds: f64, input: &std::path::Path) -> Option<Watchdog> {
        if seconds == 0.0 {
            return None;
        }
        let armed = std::sync::Arc::new((std::sync::Mutex::new(true), std::sync::Condvar::new()));
        let state = armed.clone();
        let input = input.display().to_string();
        std::thread::spawn(move || {
            let (lock, cv) = &*state;
            let guard = lock.lock().unwrap_or_else(|e| e.into_inner());
            let limit = std::time::Duration::from_secs_f64(seconds);
            let (guard, _) = cv
                .wait_timeout_while(guard, limit, |armed| *armed)
                .unwrap_or_else(|e| e.into_inner());
            if *guard {
                eprintln!(
                    "error: {input}: TetGen did not finish within {seconds} s (--time-limit); \
                     it was stopped and nothing was written (a looser quality bound or a \
                     larger maximum volume finishes sooner)"
                );
                // SAFETY: `_exit` ends the process at once; the lock is held,
                // so the main thread cannot have begun writing.
                unsafe { libc::_exit(1) };
            }
        });
        Some(Watchdog { armed })
    }
}

#[cfg(feature = "tetgen")]
impl Drop for Watchdog {
    fn drop(&mut self) {
        let (lock, cv) = &*self.armed;
        *lock.lock().unwrap_or_else(|e| e.into_inner()) = false;
        cv.notify_all();
    }
}

/// The one line a build without TetGen answers.
#[cfg(not(feature = "tetgen"))]
const NO_TETGEN: &str = "built without TetGen: rebuild with `--features tetgen` (TetGen is AGPL-3)";

/// Runs `mesh`.
#[cfg(not(feature = "tetgen"))]
pub fn run(_a: Args) -> super::CliResult {
    Err(NO_TETGEN.to_string())
}

/// Runs `mesh`.
#[cfg(feature = "tetgen")]
pub fn run(a: Args) -> super::CliResult {
    use tetrefine::io::Plc;
    use tetrefine::tetgen::{tetrahedralize, Options};
    tetrefine::io::Format::for_writing(&a.output).map_err(|e| e.to_string())?;
    let opts = Options {
        min_ratio: a.min_ratio,
        min_dihedral: a.min_dihedral,
        max_volume: a.max_volume,
        switches: a.switches,
        size_field: None,
    };
    // Options are checked before the (possibly large) input is read.
    tetrefine::tetgen::switches(&opts, false, "").map_err(|e| e.to_string())?;
    if !(a.time_limit.is_finite() && a.time_limit >= 0.0 && a.time_limit < 1e9) {
        return Err(format!(
            "--time-limit {}: give a number of seconds (0 for no limit)",
            a.time_limit
        ));
    }
    let plc = Plc::read(&a.input).map_err(|e| e.to_string())?;
    let watchdog = Watchdog::arm(a.time_limit, &a.input);
    let mesh = tetrahedralize(&plc, &opts).map_err(|e| format!("{}: {e}", a.input.display()));
    drop(watchdog);
    let mesh = mesh?;
    super::write_mesh(&a.output, &mesh)?;
    if let Some(want) = opts.min_dihedral {
        let worst = tetrefine::MeshStats::compute(&mesh).min_dihedral_deg.worst;
        if worst < want {
            eprintln!(
                "note: the worst dihedral angle is {worst:.2}°, below the {want}° asked for: \
                 TetGen's dihedral bound is a goal, not a guarantee (see README)"
            );
        }
    }
    let mut regions: Vec<i32> = mesh.tet_ids().map(|t| mesh.region(t)).collect();
    regions.sort_unstable();
    regions.dedup();
    crate::say!(
        "{}: {} points, {} tetrahedra, regions {:?}",
        a.output.display(),
        mesh.n_points(),
        mesh.n_tets(),
        regions
    );
    Ok(())
}
