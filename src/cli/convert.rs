//! `focal convert INPUT OUT.ome.zarr`: any volume Focal reads as a multiscale OME-Zarr
//! pyramid, with a progress bar.

use std::path::PathBuf;
use std::time::Duration;

use clap::{Args, ValueEnum};
use focal::volume::convert::Downsample;
use focal::volume::convert::ome_zarr::{Compressor, WriteOptions, ZarrVersion, write};
use focal::volume::readers::{RawSpec, ReadOptions, read_volume};
use indicatif::{ProgressBar, ProgressStyle};

#[derive(Clone, Copy, ValueEnum)]
enum Version {
    /// Zarr v2 with OME-NGFF 0.4.
    #[value(name = "2")]
    V2,
    /// Zarr v3 with OME-NGFF 0.5.
    #[value(name = "3")]
    V3,
}

#[derive(Clone, Copy, ValueEnum)]
enum Codec {
    /// Zstandard.
    Zstd,
    /// Blosc with Zstandard inside and byte shuffle (what most OME-Zarr writers use).
    Blosc,
}

#[derive(Args)]
pub struct ConvertArgs {
    /// Volume file or DICOM folder to convert.
    input: PathBuf,
    /// The pyramid to write (a folder, by convention NAME.ome.zarr).
    output: PathBuf,
    /// Chunk edge in voxels (the inner chunk when sharded).
    #[arg(long, default_value_t = 64)]
    chunk: u32,
    /// Chunks per shard edge (Zarr v3): shards of (SHARD·CHUNK)³ voxels.
    #[arg(long)]
    shard: Option<u32>,
    /// Zarr format: 3 (OME-NGFF 0.5) or 2 (OME-NGFF 0.4).
    #[arg(long, value_enum, default_value = "3")]
    zarr: Version,
    /// Compression of Zarr v3 chunks (Zarr v2's are blosc).
    #[arg(long, value_enum, default_value = "zstd")]
    codec: Codec,
    /// A label map: levels take the first voxel of each block instead of the mean.
    #[arg(long)]
    labels: bool,
    /// Replace the output if it is already a Zarr pyramid.
    #[arg(long)]
    force: bool,
    /// Layout of a headerless raw input: DIMS:TYPE[:le|be][:s=SPACING][:skip=BYTES].
    #[arg(long)]
    raw: Option<RawSpec>,
}

pub fn run(args: &ConvertArgs) -> Result<(), String> {
    let options = ReadOptions { raw: args.raw.clone(), ..Default::default() };
    let volume = read_volume(&args.input, &options).map_err(|e| e.to_string())?;
    let opts = WriteOptions {
        chunk: args.chunk,
        shard: args.shard,
        version: match args.zarr {
            Version::V2 => ZarrVersion::V2,
            Version::V3 => ZarrVersion::V3,
        },
        downsample: if args.labels { Downsample::Nearest } else { Downsample::Mean },
        overwrite: args.force,
        compressor: match args.codec {
            Codec::Zstd => Compressor::Zstd,
            Codec::Blosc => Compressor::Blosc,
        },
    };
    let bar = ProgressBar::new(1);
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {percent:>3}% {elapsed}").map_err(|e| e.to_string())?.progress_chars("=> "),
    );
    bar.set_message(format!("writing {}", args.output.display()));
    bar.enable_steady_tick(Duration::from_millis(200));
    let written = write(&volume, &args.output, &opts, &|done, total| {
        bar.set_length(total);
        bar.set_position(done);
    });
    bar.finish_and_clear();
    let written = written?;
    let levels: Vec<String> = written.levels.iter().map(|d| focal::volume::grid::fmt_dims(*d)).collect();
    println!("{}: {} levels ({}), {}", args.output.display(), levels.len(), levels.join(", "), written.sample.name());
    Ok(())
}
