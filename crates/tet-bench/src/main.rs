//! `tet-bench`: the user-facing command-line tool and benchmark harness.
//! See the README for every subcommand and the `--json` schema.

mod accuracy;
mod brute;
mod build;
mod bvh;
mod cli;
#[cfg(feature = "embree")]
mod embree;
mod exitface;
mod extremes;
mod gpu;
mod info;
mod load;
mod methods;
mod outofcore;
mod plots;
mod render;
mod tables;

use std::process::ExitCode;

use clap::Parser;
use cli::{Cli, Command};

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::TetgenWorker => return tetgen_worker(),
        Command::Build(a) => build::run(a, cli.json),
        Command::Info(a) => info::run(a, cli.json),
        Command::Render(a) => render::run(a, cli.json),
        Command::Accuracy(a) => accuracy::run(a, cli.json),
        Command::Tables(a) => tables::run(a, cli.json),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", error_chain(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes on one line; a cause whose text the message
/// already contains (many of our errors quote their source) is not repeated.
fn error_chain(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let c = cause.to_string();
        if !text.contains(&c) {
            if !text.is_empty() {
                text.push_str(": ");
            }
            text.push_str(&c);
        }
    }
    text
}

#[cfg(feature = "tetgen")]
fn tetgen_worker() -> ExitCode {
    ExitCode::from(tet_build::tetgen::worker::serve_stdio().clamp(0, 255) as u8)
}

#[cfg(not(feature = "tetgen"))]
fn tetgen_worker() -> ExitCode {
    eprintln!("error: built without the `tetgen` feature");
    ExitCode::FAILURE
}
