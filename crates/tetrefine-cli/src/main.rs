//! `tetrefine` command line: a thin layer over the library.

mod cli;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Refine tetrahedral meshes for finite-element simulation and keep them well shaped.
#[derive(Parser)]
#[command(name = "tetrefine", version, about, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print mesh statistics (the rows of Table 1 of the √3 paper and more).
    Quality(cli::quality::Args),
    /// Convert a mesh between formats, keeping regions, markers and features.
    Convert(cli::convert::Args),
    /// Refine with the √3 tetrahedral subdivision (uniform).
    Refine(Box<cli::refine::Args>),
    /// Improve a mesh (edge removal and smoothing), boundary fixed.
    Improve(cli::improve::Args),
    /// Subdivide a polygon surface (√3, Loop, Catmull–Clark, Doo–Sabin, weighted Catmull–Clark,
    /// Sierpinski, vertex truncation) or draw a subdivision IFS attractor.
    Surface(Box<cli::surface::Args>),
    /// Mesh the volume a closed surface encloses, with TetGen (opt-in feature `tetgen`).
    Mesh(cli::mesh::Args),
    /// Uniform 1:8 red refinement by edge bisection (the speed-of-light reference).
    Bisect(cli::bisect::Args),
}

fn main() -> ExitCode {
    tetrefine::io::install_signal_cleanup();
    let cli = Cli::parse();
    // Every file the command writes appears at the end, together, or not at all.
    let outputs = tetrefine::io::OutputSet::begin();
    let result = match cli.command {
        Command::Quality(a) => cli::quality::run(a),
        Command::Convert(a) => cli::convert::run(a),
        Command::Refine(a) => cli::refine::run(*a),
        Command::Improve(a) => cli::improve::run(a),
        Command::Surface(a) => cli::surface::run(*a),
        Command::Mesh(a) => cli::mesh::run(a),
        Command::Bisect(a) => cli::bisect::run(a),
    };
    let result = result
        .and_then(|()| cli::outputs::finish_stdout())
        .and_then(|()| outputs.commit().map_err(|e| e.to_string()));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // A distributed run's failing rank printed its message before
            // the ranks parted (see `Comm::agree`).
            #[cfg(feature = "mpi")]
            let printed = tetrefine::distributed::failure_printed();
            #[cfg(not(feature = "mpi"))]
            let printed = false;
            if !printed {
                eprintln!("error: {e}");
            }
            ExitCode::FAILURE
        }
    }
}
