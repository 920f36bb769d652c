//! `tetrefine quality IN [--json] [--histogram FILE.csv|.svg|.png] [--bins N] [-o OUT]`.

use std::path::{Path, PathBuf};
use tetrefine::report::DEFAULT_HIST_MAX_DEG;
use tetrefine::report::{format_table, Histogram};
use tetrefine::report::{write_histogram, HistogramFormat};
use tetrefine::MeshStats;

/// Most histogram bins accepted (0.0071° each over 0–71°); every parallel task
/// keeps its own counts, so the number is bounded.
const MAX_BINS: usize = 10_000;

/// Arguments of `quality`.
#[derive(clap::Args)]
pub struct Args {
    /// Input mesh (.mesh, .msh, .vtu, .node/.ele, GiD .msh).
    pub input: PathBuf,
    /// Print the statistics as one JSON object on stdout, and nothing else
    /// (notes go to stderr).
    #[arg(long)]
    pub json: bool,
    /// Write the histogram of the per-tet minimum dihedral angle: .csv
    /// (bin_lo_deg,bin_hi_deg,count), .svg or .png.
    #[arg(long, value_name = "FILE")]
    pub histogram: Option<PathBuf>,
    /// Number of equal histogram bins over 0–71° (71: bins of 1°; at most 10000).
    #[arg(long, value_name = "N", default_value_t = tetrefine::report::DEFAULT_BINS)]
    pub bins: usize,
    /// Also write the mesh (format by extension; .vtu carries the quality arrays).
    #[arg(short = 'o', long = "output", value_name = "OUT")]
    pub output: Option<PathBuf>,
}

/// File name of `path` for titles and headings.
fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// Runs `quality`: validates the options, loads the mesh, computes the
/// statistics once and prints / writes what was asked.
pub fn run(a: Args) -> super::CliResult {
    // Everything that can be refused without reading the mesh is refused first.
    if a.bins == 0 || a.bins > MAX_BINS {
        return Err(format!(
            "--bins must be between 1 and {MAX_BINS} (got {})",
            a.bins
        ));
    }
    if let Some(h) = &a.histogram {
        HistogramFormat::from_path(h).map_err(|e| e.to_string())?;
    }
    if let Some(o) = &a.output {
        tetrefine::io::Format::for_writing(o).map_err(|e| e.to_string())?;
    }
    super::outputs::refuse_shared_paths(&[
        ("-o", a.output.as_deref()),
        ("--histogram", a.histogram.as_deref()),
    ])?;

    let mesh = super::load(&a.input)?;
    let stats = MeshStats::compute_with(&mesh, Histogram::new(0.0, DEFAULT_HIST_MAX_DEG, a.bins));

    if a.json {
        let json = serde_json::to_string(&stats).map_err(|e| e.to_string())?;
        crate::say!("{json}");
    } else {
        let name = file_name(&a.input);
        super::outputs::say_text(&format_table(&[(name.as_str(), &stats)]));
    }

    // The mesh first: its writer is the likelier to refuse (format support),
    // and then no file at all is left behind.
    if let Some(o) = &a.output {
        super::write_mesh(o, &mesh)?;
        eprintln!("wrote mesh {}", o.display());
    }
    if let Some(h) = &a.histogram {
        let title = format!(
            "{}: minimum dihedral angle of {} tetrahedra",
            file_name(&a.input),
            stats.tets
        );
        write_histogram(h, &stats.histogram, &title).map_err(|e| e.to_string())?;
        eprintln!("wrote histogram {}", h.display());
    }
    Ok(())
}
