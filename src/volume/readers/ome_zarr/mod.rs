//! OME-Zarr (OME-NGFF 0.4 on Zarr v2, 0.5 on Zarr v3): multiscale image pyramids, read
//! through the `zarrs` crate from a folder or over HTTP(S) (`zarrs_http`).
//!
//! [`open`] gives the whole pyramid as a [`ZarrSource`] (a [`VoxelSource`] read a box at
//! a time); [`read`] gives one level as a [`Volume`], the finest whose codes fit in
//! [`WHOLE_LEVEL_BYTES`] (and the reader limits), for the paths that need a volume in
//! memory. Metadata is parsed by [`metadata`].

mod chunks;
pub mod guard;
pub mod metadata;
pub mod source;

use std::path::Path;
use std::sync::Arc;

use zarrs::filesystem::FilesystemStore;
use zarrs::group::Group;
use zarrs::storage::ReadableStorage;
use zarrs_http::HTTPStore;

pub use source::ZarrSource;

use super::common::{Problem, ReadError, ReadOptions};
use crate::volume::Volume;
use crate::volume::source::VoxelSource;
use crate::volume::source::level::{WHOLE_LEVEL_BYTES, finest_within, load_finest_within};

/// Whether `path` is a Zarr group: a folder with `zarr.json`, `.zgroup` or `.zattrs`, or
/// an `http://` or `https://` address.
pub fn is_zarr(path: &Path) -> bool {
    is_url(path) || (path.is_dir() && ["zarr.json", ".zgroup", ".zattrs"].iter().any(|f| path.join(f).is_file()))
}

/// Whether `path` is an HTTP(S) address rather than a file.
pub fn is_url(path: &Path) -> bool {
    let s = path.to_string_lossy();
    s.starts_with("http://") || s.starts_with("https://")
}

/// Opens the OME-Zarr image in the folder `path`, or at the address it names (read
/// through `zarrs_http`: a 404 is an absent chunk, another status or a dropped
/// connection an unreadable one).
pub fn open(path: &Path) -> Result<ZarrSource, ReadError> {
    let fail = |p: Problem| ReadError::new(path, p);
    let store: ReadableStorage = if is_url(path) {
        let url = path.to_string_lossy();
        Arc::new(HTTPStore::new(url.trim_end_matches('/')).map_err(|e| fail(Problem::Malformed(format!("not a usable address: {e}"))))?)
    } else {
        Arc::new(FilesystemStore::new(path).map_err(|e| fail(Problem::Io(std::io::Error::other(e.to_string()))))?)
    };
    let guarded = Arc::new(guard::Guarded::new(store));
    let store: ReadableStorage = guarded.clone();
    let group = Group::open(store.clone(), "/").map_err(|e| fail(Problem::Malformed(format!("not a readable Zarr group: {e}"))))?;
    let meta = metadata::parse(group.attributes()).map_err(|e| fail(Problem::Malformed(e)))?;
    let source = ZarrSource::open(store, path, &meta).map_err(|e| fail(Problem::Malformed(e)))?;
    for (prefix, limit) in source.blosc_arrays() {
        guarded.guard(prefix, limit);
    }
    Ok(source)
}

/// Reads one level of the image at `path` into memory (the finest within
/// [`WHOLE_LEVEL_BYTES`]).
pub fn read(path: &Path, options: &ReadOptions) -> Result<Volume, ReadError> {
    let source = open(path)?;
    read_source(&source, path, options)
}

/// The level of `source` that [`read`] loads, as a volume.
pub fn read_source(source: &dyn VoxelSource, path: &Path, options: &ReadOptions) -> Result<Volume, ReadError> {
    let info = source.info();
    let budget = WHOLE_LEVEL_BYTES.min(options.max_bytes).min(options.max_voxels.saturating_mul(info.bits as u64 / 8));
    let coarsest = &info.levels[info.levels.len() - 1].grid;
    if coarsest.voxel_count() as u64 > options.max_voxels {
        return Err(ReadError::new(path, Problem::TooLarge(format!("even the coarsest level has {} voxels", coarsest.voxel_count()))));
    }
    if let Some(p) = &options.progress {
        p.add_total(info.levels[finest_within(info, budget)].grid.voxel_count() as u64);
    }
    load_finest_within(source, budget, &|n| {
        if let Some(p) = &options.progress {
            p.add_done(n);
        }
    })
    .map_err(|e| ReadError::new(path, Problem::Malformed(e.problem)))
}
