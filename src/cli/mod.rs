//! Subcommands of the `focal` binary.

pub mod info;
pub mod render;

use std::path::Path;

use focal::volume::Volume;
use focal::volume::phantom::Phantom;
use focal::volume::readers::{RawSpec, ReadOptions, read_volume};

/// Reads `path`, or generates a phantom when `path` is `phantom:NAME` or absent.
pub fn load(path: Option<&Path>, raw: Option<&RawSpec>, resolution: u32) -> Result<Volume, String> {
    match path {
        None => Phantom::Head.generate(resolution),
        Some(p) if p.to_string_lossy().starts_with("phantom:") => {
            let name = p.to_string_lossy()["phantom:".len()..].to_string();
            name.parse::<Phantom>()?.generate(resolution)
        }
        Some(p) => {
            let options = ReadOptions { raw: raw.cloned(), ..Default::default() };
            read_volume(p, &options).map_err(|e| e.to_string())
        }
    }
}
