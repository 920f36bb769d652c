//! `tetrefine convert IN OUT`.

use std::path::PathBuf;

/// Arguments of `convert`.
#[derive(clap::Args)]
pub struct Args {
    /// Input mesh (.mesh, .msh, .vtu, .node/.ele, GiD .msh).
    pub input: PathBuf,
    /// Output mesh; the format follows the extension (.mesh, .msh, .vtu, .node/.ele).
    pub output: PathBuf,
}

/// Runs `convert`.
pub fn run(a: Args) -> super::CliResult {
    tetrefine::io::Format::for_writing(&a.output).map_err(|e| e.to_string())?;
    let mesh = super::load(&a.input)?;
    tetrefine::io::write_mesh(&a.output, &mesh).map_err(|e| e.to_string())
}
