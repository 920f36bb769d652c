//! `tetrefine quality IN [--json]`.

use std::path::PathBuf;
use tetrefine::MeshStats;

/// Arguments of `quality`.
#[derive(clap::Args)]
pub struct Args {
    /// Input mesh.
    pub input: PathBuf,
    /// Print the statistics as one JSON object on stdout, and nothing else.
    #[arg(long)]
    pub json: bool,
}

/// Runs `quality`.
pub fn run(a: Args) -> super::CliResult {
    let mesh = super::load(&a.input)?;
    let s = MeshStats::compute(&mesh);
    if a.json {
        println!("{}", serde_json::to_string(&s).map_err(|e| e.to_string())?);
    } else {
        println!(
            "{}",
            serde_json::to_string_pretty(&s).map_err(|e| e.to_string())?
        );
    }
    Ok(())
}
