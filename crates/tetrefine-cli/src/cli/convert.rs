//! `tetrefine convert IN OUT`.

use std::path::PathBuf;

/// Arguments of `convert`.
#[derive(clap::Args)]
pub struct Args {
    /// Input mesh (.mesh, .meshb, .msh, .vtu, .node/.ele, GiD .msh).
    pub input: PathBuf,
    /// Output mesh; the format follows the extension (.mesh, .meshb, .msh, .vtu, .node/.ele).
    pub output: PathBuf,
    /// Point or cell fields of the input from a Medit solution (.sol or
    /// .solb: SolAtVertices → point fields, SolAtTetrahedra → cell fields).
    #[arg(long)]
    pub fields: Option<PathBuf>,
    /// Write the point fields as a Medit solution (.solb binary, .sol ASCII).
    #[arg(long)]
    pub fields_out: Option<PathBuf>,
    /// MSH variant of a `.msh` output: 2.2, 4.1 or 4.1-binary.
    #[arg(long, default_value = "4.1")]
    pub msh_format: tetrefine::io::MshFormat,
}

/// Runs `convert`.
pub fn run(a: Args) -> super::CliResult {
    tetrefine::io::Format::for_writing(&a.output).map_err(|e| e.to_string())?;
    let (mut mesh, mut meta) = super::load_with_meta(&a.input)?;
    if let Some(f) = &a.fields {
        mesh.compact();
        tetrefine::io::add_sol_fields(f, &mut meta, mesh.n_points(), mesh.n_tets())
            .map_err(|e| e.to_string())?;
    }
    if a.fields_out.is_some() && !meta.point_fields.iter().any(|f| f.len() == mesh.n_points()) {
        return Err(format!(
            "--fields-out: {} carries no point field to write (give one with --fields FILE.sol)",
            a.input.display()
        ));
    }
    let options = tetrefine::io::WriteOptions {
        msh_format: a.msh_format,
    };
    super::write_mesh_with(&a.output, &mesh, &meta, &options)?;
    if let Some(f) = &a.fields_out {
        tetrefine::io::write_point_fields(f, &meta, mesh.n_points()).map_err(|e| e.to_string())?;
    }
    Ok(())
}
