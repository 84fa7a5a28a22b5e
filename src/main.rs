//! The `focal` command line. See `focal --help`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod cli;

/// Focal: a focus+context volume explorer.
#[derive(Parser)]
#[command(version, about, long_about = None)]
struct Args {
    #[command(subcommand)]
    command: Option<Command>,
    /// Volume file or DICOM folder to open (the built-in head phantom when omitted).
    volume: Option<PathBuf>,
    /// Where the headless run writes its picture.
    #[arg(long, default_value = "out/focal.png")]
    out: PathBuf,
}

#[derive(Subcommand)]
enum Command {
    /// Print what a volume file holds: format, grid, orientation, values, histogram.
    Info(cli::info::InfoArgs),
    /// Render a volume (or phantom) to a PNG.
    Render(cli::render::RenderArgs),
}

fn main() -> ExitCode {
    let args = Args::parse();
    let result = match args.command {
        Some(Command::Info(a)) => cli::info::run(&a),
        Some(Command::Render(a)) => cli::render::run(&a),
        None => cli::render::run_headless(args.volume.as_deref(), &args.out),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
