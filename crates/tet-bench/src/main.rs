//! `tet-bench`: the user-facing command-line tool and benchmark harness.
//! See the README for every subcommand and the `--json` schema.
//!
//! The modules lie in layers; each uses only the layers below it (and,
//! within a layer, the modules named before it):
//!
//! 1. commands — [`commands`] (`build`, `info`, `render`, `accuracy`,
//!    `iso`, `convert`, and the job commands `build --plan`, `build-part`,
//!    `merge`, `job status`, `submit`, `gpu-bench`) and [`tables`] (one
//!    module per paper table, the driver, and the report writers: Markdown,
//!    CSV, JSON, SVG figures); `gpu-bench` alone reads from [`tables`]:
//!    the published figures it prints beside its own;
//! 2. the command line — [`cli`] (the subcommands and their arguments; the
//!    values they name are defined below);
//! 3. measurement, returning plain serialisable data — [`timing`] (speed,
//!    CPU and GPU), [`accuracy`] (against an f64 reference), [`iso`]
//!    (isosurfaces of tet volumes) and [`outofcore`] (builds under a
//!    memory limit);
//! 4. the traversal methods — [`methods`] (what a `--method` names, the
//!    tracers that are not in `tet-trace-cpu`, the bytes of each layout);
//! 5. plumbing — [`load`] (scenes and mesh files, the build flags, the
//!    camera) and [`output`] (stdout and error text).
#![deny(missing_docs)]
// A binary exports nothing, so `missing_docs` checks only the crate root;
// clippy's lint holds every module, item and field to the same rule.
#![deny(clippy::missing_docs_in_private_items)]
#![deny(clippy::print_stdout)]

mod accuracy;
mod cli;
mod commands;
mod iso;
mod load;
mod methods;
mod outofcore;
mod output;
mod tables;
mod timing;

use std::process::ExitCode;

use clap::Parser;
use cli::{Cli, Command};

/// Parses the arguments, runs the subcommand, and maps its result to the
/// exit code.
fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::TetgenWorker => return tetgen_worker(),
        Command::Build(a) => commands::build::run(a, cli.json),
        Command::Info(a) => commands::info::run(a, cli.json),
        Command::Render(a) => commands::render::run(a, cli.json),
        Command::Accuracy(a) => commands::accuracy::run(a, cli.json),
        Command::Tables(a) => tables::run(a, cli.json),
        Command::Iso(a) => commands::iso::run(a, cli.json),
        Command::Convert(a) => commands::convert::run(a, cli.json),
        Command::BuildPart(a) => commands::job::build_part(a, cli.json),
        Command::Merge(a) => commands::job::merge(a, cli.json),
        Command::Job(a) => commands::job::job(a, cli.json),
        Command::Submit(a) => commands::job::submit(a, cli.json),
        Command::GpuBench(a) => commands::gpu_bench::run(a, cli.json),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // The reader has gone (`… | head`): stop quietly, as Unix tools do.
        Err(e) if output::is_stdout_closed(&e) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", output::error_chain(&e));
            ExitCode::FAILURE
        }
    }
}

/// `tet-bench tetgen-worker`: one TetGen request on stdin/stdout.
#[cfg(feature = "tetgen")]
fn tetgen_worker() -> ExitCode {
    ExitCode::from(tet_build::tetgen::worker::serve_stdio().clamp(0, 255) as u8)
}

/// Without TetGen there is no worker.
#[cfg(not(feature = "tetgen"))]
fn tetgen_worker() -> ExitCode {
    eprintln!("error: built without the `tetgen` feature");
    ExitCode::FAILURE
}
