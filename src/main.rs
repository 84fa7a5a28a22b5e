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
    /// Volume file, DICOM or OME-Zarr folder to open (the built-in head phantom when omitted).
    volume: Option<PathBuf>,
    /// Where the run writes its picture when there is no display.
    #[arg(long, default_value = "out/focal.png")]
    out: PathBuf,
    /// Render headless even when a display is available.
    #[arg(long)]
    headless: bool,
    /// (Automation) In the app, save a screenshot to this path after --frames frames, then quit.
    #[arg(long, requires = "frames")]
    screenshot: Option<PathBuf>,
    /// (Automation) Frames to draw before the screenshot, counted once the data is loaded
    /// and drawn (and, when streamed, has converged).
    #[arg(long)]
    frames: Option<u32>,
    /// Window size WIDTHxHEIGHT.
    #[arg(long, default_value = "1440x900")]
    window: String,
    /// Open the app with the slice views (axial, coronal, sagittal) under the 3D view.
    #[arg(long)]
    slices: bool,
    /// Restore the view of the last session if it did not end cleanly (a crash, a kill),
    /// without asking.
    #[arg(long, conflicts_with = "volume")]
    restore: bool,
    /// (Testing) Destroy the GPU device after this many drawn frames, as a driver reset
    /// does: the app must keep the view and say why it stops.
    #[arg(long, hide = true)]
    lose_device_after: Option<u64>,
}

#[derive(Subcommand)]
enum Command {
    /// Print what a volume file holds: format, grid, orientation, values, histogram.
    Info(cli::info::InfoArgs),
    /// Render scene files, or a volume (or phantom), to PNG.
    Render(cli::render::RenderArgs),
    /// GPU frame times of fixed scenes, with ratios measured in the same run.
    Bench(cli::bench::BenchArgs),
    /// Write a volume as a multiscale OME-Zarr pyramid.
    Convert(cli::convert::ConvertArgs),
}

/// Whether a window can be opened (an X or Wayland display).
fn has_display() -> bool {
    ["DISPLAY", "WAYLAND_DISPLAY"].iter().any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()))
}

fn main() -> ExitCode {
    let args = Args::parse();
    let result = match args.command {
        Some(Command::Info(a)) => cli::info::run(&a),
        Some(Command::Render(a)) => cli::render::run(&a),
        Some(Command::Bench(a)) => cli::bench::run(&a),
        Some(Command::Convert(a)) => cli::convert::run(&a),
        None if args.headless || !has_display() => cli::render::run_headless(args.volume.as_deref(), &args.out),
        None => {
            let automation = args.screenshot.clone().zip(args.frames).map(|(p, n)| (n, p));
            let window: Option<(u32, u32)> = args.window.split_once('x').and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?)));
            let Some(window) = window else {
                eprintln!("error: window size '{}' is not WIDTHxHEIGHT", args.window);
                return ExitCode::FAILURE;
            };
            let options = focal::ui::RunOptions { slices: args.slices, restore: args.restore, lose_device_after: args.lose_device_after };
            match focal::ui::run(args.volume.clone(), automation, window, options) {
                bevy::app::AppExit::Success => Ok(()),
                bevy::app::AppExit::Error(code) => Err(format!("the app stopped with code {code}")),
            }
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
