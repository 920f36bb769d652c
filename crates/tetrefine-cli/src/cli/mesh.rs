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
    /// Smallest dihedral angle in degrees (TetGen -q R/DEG; R defaults to 2.0).
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
    use tetrefine::tetgen::{tetrahedralize, Isolation, Options, TetgenError};
    tetrefine::io::Format::for_writing(&a.output).map_err(|e| e.to_string())?;
    if !(a.time_limit.is_finite() && a.time_limit >= 0.0 && a.time_limit < 1e9) {
        return Err(format!(
            "--time-limit {}: give a number of seconds (0 for no limit)",
            a.time_limit
        ));
    }
    let time_limit = (a.time_limit > 0.0).then(|| {
        std::time::Duration::from_secs_f64(a.time_limit).max(std::time::Duration::from_nanos(1))
    });
    let opts = Options {
        min_ratio: a.min_ratio,
        min_dihedral: a.min_dihedral,
        max_volume: a.max_volume,
        switches: a.switches,
        size_field: None,
        // TetGen runs in a child process: a crash of TetGen is a one-line
        // error, and the time limit kills the child, not this process.
        isolation: Isolation::Child { time_limit },
    };
    // Options are checked before the (possibly large) input is read.
    tetrefine::tetgen::switches(&opts, false, "").map_err(|e| e.to_string())?;
    let plc = Plc::read(&a.input).map_err(|e| e.to_string())?;
    let input = a.input.display();
    let mesh = tetrahedralize(&plc, &opts).map_err(|e| match e {
        TetgenError::TimedOut { .. } => format!(
            "{input}: TetGen did not finish within {} s (--time-limit); it was stopped and \
             nothing was written (a looser quality bound or a larger maximum volume finishes sooner)",
            a.time_limit
        ),
        TetgenError::Crashed { .. } => format!("{input}: {e}; nothing was written"),
        e => format!("{input}: {e}"),
    })?;
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
