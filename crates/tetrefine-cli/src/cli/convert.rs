//! `tetrefine convert IN OUT`.

use std::path::PathBuf;

/// Arguments of `convert`.
#[derive(clap::Args)]
pub struct Args {
    /// Input mesh (.mesh, .msh, .vtu, .node/.ele, GiD .msh).
    pub input: PathBuf,
    /// Output mesh; the format follows the extension (.mesh, .msh, .vtu, .node/.ele).
    pub output: PathBuf,
    /// MSH variant of a `.msh` output: 2.2, 4.1 or 4.1-binary.
    #[arg(long, default_value = "4.1")]
    pub msh_format: tetrefine::io::gmsh::MshFormat,
}

/// Runs `convert`.
pub fn run(a: Args) -> super::CliResult {
    tetrefine::io::Format::for_writing(&a.output).map_err(|e| e.to_string())?;
    let (mesh, meta) = super::load_with_meta(&a.input)?;
    let options = tetrefine::io::WriteOptions {
        msh_format: a.msh_format,
    };
    tetrefine::io::write_mesh_with(&a.output, &mesh, &meta, &options).map_err(|e| e.to_string())
}
