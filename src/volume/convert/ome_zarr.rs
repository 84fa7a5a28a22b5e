//! Writing a volume as an OME-Zarr pyramid: NGFF 0.5 on Zarr v3 (zstd, or blosc with
//! zstd inside, optionally sharded) or NGFF 0.4 on Zarr v2 (blosc with zstd), arrays
//! `0`, `1`, … in (z, y, x)
//! order, chunks written in parallel through `zarrs`.
//!
//! Each level's `coordinateTransformations` give its voxel size (`scale`, millimetres)
//! and the centre of its first voxel (`translation`): level `k` voxel `j` is the mean of
//! level-0 voxels `2ᵏj … 2ᵏ(j + 1) − 1`, so its translation is level 0's plus
//! `(2ᵏ − 1)/2` level-0 voxels. NGFF has no orientation, so level 0's translation is the
//! volume's origin only when its axes are the RAS axes; the `focal` attribute keeps the
//! orientation and origin for Focal to read back. Floating-point output carries its
//! value range as the channel's display window (`omero`).

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use glam::UVec3;
use rayon::prelude::*;
use serde_json::{Value, json};
use zarrs::array::codec::ZstdCodec;
use zarrs::array::{Array, ArrayBuilder, ArrayMetadata, ArrayMetadataV2, Element, data_type};
use zarrs::filesystem::FilesystemStore;
use zarrs::group::{Group, GroupMetadata, GroupMetadataV3};
use zarrs::metadata::v2::GroupMetadataV2;
use zarrs::storage::ReadableWritableListableStorage;

use super::{Downsample, SampleKind, next_level};
use crate::volume::readers::ome_zarr::is_zarr;
use crate::volume::source::level_count;
use crate::volume::{ValueMap, Volume, Voxels, grid::fmt_dims};

/// Zarr format and NGFF version written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ZarrVersion {
    /// Zarr v2, NGFF 0.4.
    V2,
    /// Zarr v3, NGFF 0.5.
    V3,
}

/// How to write the pyramid.
#[derive(Clone, Debug)]
pub struct WriteOptions {
    /// Chunk edge in voxels (the inner chunk when sharded).
    pub chunk: u32,
    /// Chunks per shard edge (Zarr v3 only).
    pub shard: Option<u32>,
    pub version: ZarrVersion,
    pub downsample: Downsample,
    /// Replace an existing pyramid at the output path.
    pub overwrite: bool,
    /// How Zarr v3 chunks are compressed (v2's are blosc).
    pub compressor: Compressor,
}

/// Compression of Zarr v3 chunks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Compressor {
    /// Zstandard, level 3.
    #[default]
    Zstd,
    /// Blosc with Zstandard inside, level 5, byte shuffle (what most OME-Zarr writers use).
    Blosc,
}

impl Default for WriteOptions {
    fn default() -> Self {
        Self {
            chunk: 64,
            shard: None,
            version: ZarrVersion::V3,
            downsample: Downsample::Mean,
            overwrite: false,
            compressor: Compressor::Zstd,
        }
    }
}

/// What was written.
#[derive(Clone, Debug, PartialEq)]
pub struct Written {
    pub levels: Vec<UVec3>,
    pub sample: SampleKind,
}

/// Writes `volume` as a pyramid at `out`; `progress(done, total)` counts voxels.
pub fn write(volume: &Volume, out: &Path, opts: &WriteOptions, progress: &(dyn Fn(u64, u64) + Sync)) -> Result<Written, String> {
    if !(8..=1024).contains(&opts.chunk) {
        return Err(format!("chunk size {} is outside 8..1024 voxels", opts.chunk));
    }
    if let Some(s) = opts.shard {
        if opts.version == ZarrVersion::V2 {
            return Err("sharding needs Zarr v3".into());
        }
        if !(1..=64).contains(&s) {
            return Err(format!("{s} chunks per shard edge is outside 1..64"));
        }
    }
    prepare_folder(out, opts.overwrite)?;
    let store: ReadableWritableListableStorage = Arc::new(FilesystemStore::new(out).map_err(|e| format!("{}: {e}", out.display()))?);
    let sample = SampleKind::for_volume(volume);
    let n = level_count(volume.dims(), opts.chunk);
    let mut dims = vec![volume.dims()];
    for _ in 1..n {
        let last = dims[dims.len() - 1];
        dims.push(crate::volume::pyramid::half_dims(last));
    }
    let total: u64 = dims.iter().map(|d| d.x as u64 * d.y as u64 * d.z as u64).sum();
    let done = AtomicU64::new(0);
    let count = |voxels: u64| progress(done.fetch_add(voxels, Ordering::Relaxed) + voxels, total);
    // A group without the multiscales first: a conversion that stops half way leaves a
    // Zarr group that `--force` may replace, and that no reader takes for a pyramid.
    store_group(&store, out, opts, serde_json::Map::new())?;
    let mut above: Option<crate::volume::pyramid::Level> = None;
    for k in 0..n {
        let (voxels, d) = match &above {
            None => (&volume.voxels, volume.dims()),
            Some(l) => (&l.voxels, l.dims),
        };
        let array = create_array(&store, k, d, sample, opts).map_err(|e| format!("{}: level {k}: {e}", out.display()))?;
        write_level(&array, voxels, d, sample, &volume.values, &count).map_err(|e| format!("{}: level {k}: {e}", out.display()))?;
        if k + 1 < n {
            above = Some(next_level(voxels, d, opts.downsample));
        }
    }
    store_group(&store, out, opts, group_attributes(volume, &dims, sample, opts))?;
    Ok(Written { levels: dims, sample })
}

/// Writes the root group's metadata with `attributes`.
fn store_group(
    store: &ReadableWritableListableStorage,
    out: &Path,
    opts: &WriteOptions,
    attributes: serde_json::Map<String, serde_json::Value>,
) -> Result<(), String> {
    let group = match opts.version {
        ZarrVersion::V3 => {
            Group::new_with_metadata(store.clone(), "/", GroupMetadata::V3(GroupMetadataV3::new().with_attributes(attributes)))
        }
        ZarrVersion::V2 => {
            Group::new_with_metadata(store.clone(), "/", GroupMetadata::V2(GroupMetadataV2::new().with_attributes(attributes)))
        }
    }
    .map_err(|e| format!("{}: {e}", out.display()))?;
    group.store_metadata().map_err(|e| format!("{}: {e}", out.display()))
}

/// Makes `out` an empty folder, refusing to replace anything that is not a Zarr group.
fn prepare_folder(out: &Path, overwrite: bool) -> Result<(), String> {
    if out.exists() {
        let empty = out.read_dir().map(|mut d| d.next().is_none()).unwrap_or(false);
        if !empty {
            let is_zarr = is_zarr(out);
            if !overwrite || !is_zarr {
                return Err(format!(
                    "{} exists{}",
                    out.display(),
                    if is_zarr { " (pass --force to replace it)" } else { " and is not a Zarr pyramid: choose another path" }
                ));
            }
            std::fs::remove_dir_all(out).map_err(|e| format!("{}: cannot remove the old pyramid: {e}", out.display()))?;
        }
    }
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))
}

fn zyx(d: UVec3) -> Vec<u64> {
    vec![d.z as u64, d.y as u64, d.x as u64]
}

/// The array of level `k`.
fn create_array(
    store: &ReadableWritableListableStorage,
    k: usize,
    dims: UVec3,
    sample: SampleKind,
    opts: &WriteOptions,
) -> Result<Array<dyn zarrs::storage::ReadableWritableListableStorageTraits>, String> {
    let path = format!("/{k}");
    let chunk = vec![opts.chunk as u64; 3];
    let array = match opts.version {
        ZarrVersion::V3 => {
            let (dt, fill): (_, zarrs::array::FillValue) = match sample {
                SampleKind::U8 => (data_type::uint8(), 0u8.into()),
                SampleKind::U16 => (data_type::uint16(), 0u16.into()),
                SampleKind::I16 => (data_type::int16(), 0i16.into()),
                SampleKind::F32 => (data_type::float32(), 0f32.into()),
            };
            let outer: Vec<u64> = chunk.iter().map(|c| c * opts.shard.unwrap_or(1) as u64).collect();
            let mut b = ArrayBuilder::new(zyx(dims), outer, dt, fill);
            b.bytes_to_bytes_codecs(vec![compressor(opts.compressor, sample)?]);
            if opts.shard.is_some() {
                b.subchunk_shape(chunk.clone());
            }
            b.dimension_names(Some(["z", "y", "x"]));
            b.build(store.clone(), &path).map_err(|e| e.to_string())?
        }
        ZarrVersion::V2 => {
            let dtype = match sample {
                SampleKind::U8 => "|u1",
                SampleKind::U16 => "<u2",
                SampleKind::I16 => "<i2",
                SampleKind::F32 => "<f4",
            };
            let meta = json!({
                "zarr_format": 2, "shape": zyx(dims), "chunks": chunk, "dtype": dtype,
                "compressor": {"id": "blosc", "cname": "zstd", "clevel": 5, "shuffle": 1, "blocksize": 0},
                "fill_value": 0, "order": "C", "filters": null, "dimension_separator": "/"
            });
            let meta: ArrayMetadataV2 = serde_json::from_value(meta).map_err(|e| e.to_string())?;
            Array::new_with_metadata(store.clone(), &path, ArrayMetadata::V2(meta)).map_err(|e| e.to_string())?
        }
    };
    array.store_metadata().map_err(|e| e.to_string())?;
    Ok(array)
}

/// The bytes-to-bytes codec of Zarr v3 chunks.
fn compressor(c: Compressor, sample: SampleKind) -> Result<Arc<dyn zarrs::array::BytesToBytesCodecTraits>, String> {
    use zarrs::array::codec::{BloscCodec, BloscCompressionLevel, BloscCompressor, BloscShuffleMode};
    Ok(match c {
        Compressor::Zstd => Arc::new(ZstdCodec::new(3, false)),
        Compressor::Blosc => {
            let typesize = match sample {
                SampleKind::U8 => 1,
                SampleKind::U16 | SampleKind::I16 => 2,
                SampleKind::F32 => 4,
            };
            let level = BloscCompressionLevel::try_from(5u8).map_err(|l| format!("blosc level {l}"))?;
            Arc::new(
                BloscCodec::new(BloscCompressor::Zstd, level, None, BloscShuffleMode::Shuffle, Some(typesize))
                    .map_err(|e| e.to_string())?,
            )
        }
    })
}

/// Writes every storage chunk of one level, in parallel.
fn write_level(
    array: &Array<dyn zarrs::storage::ReadableWritableListableStorageTraits>,
    voxels: &Voxels,
    dims: UVec3,
    sample: SampleKind,
    map: &ValueMap,
    count: &(dyn Fn(u64) + Sync),
) -> Result<(), String> {
    let real = |c: u16| map.to_real(c as f64);
    match sample {
        SampleKind::U8 => write_chunks(array, voxels, dims, count, |c| real(c) as u8),
        SampleKind::U16 => write_chunks(array, voxels, dims, count, |c| real(c) as u16),
        SampleKind::I16 => write_chunks(array, voxels, dims, count, |c| real(c) as i16),
        SampleKind::F32 => write_chunks(array, voxels, dims, count, |c| real(c) as f32),
    }
}

fn write_chunks<T: Element + Copy + Default + Send + Sync + 'static>(
    array: &Array<dyn zarrs::storage::ReadableWritableListableStorageTraits>,
    voxels: &Voxels,
    dims: UVec3,
    count: &(dyn Fn(u64) + Sync),
    to_sample: impl Fn(u16) -> T + Sync,
) -> Result<(), String> {
    let grid = array.chunk_grid_shape();
    let (gz, gy, gx) = (grid[0], grid[1], grid[2]);
    let chunk = array.chunk_shape(&[0, 0, 0]).map_err(|e| e.to_string())?;
    let c = UVec3::new(chunk[2].get() as u32, chunk[1].get() as u32, chunk[0].get() as u32);
    let indices: Vec<[u64; 3]> = (0..gz).flat_map(|z| (0..gy).flat_map(move |y| (0..gx).map(move |x| [z, y, x]))).collect();
    indices.par_iter().try_for_each(|&[cz, cy, cx]| {
        let lo = UVec3::new(cx as u32, cy as u32, cz as u32) * c;
        let mut data = vec![T::default(); c.x as usize * c.y as usize * c.z as usize];
        let hi = (lo + c).min(dims);
        for z in lo.z..hi.z {
            for y in lo.y..hi.y {
                let src = (z as usize * dims.y as usize + y as usize) * dims.x as usize;
                let dst = ((z - lo.z) as usize * c.y as usize + (y - lo.y) as usize) * c.x as usize;
                for x in lo.x..hi.x {
                    data[dst + (x - lo.x) as usize] = to_sample(voxels.code(src + x as usize));
                }
            }
        }
        array.store_chunk(&[cz, cy, cx], data).map_err(|e| format!("chunk {}: {e}", array.chunk_key(&[cz, cy, cx])))?;
        let inside = hi - lo;
        count(inside.x as u64 * inside.y as u64 * inside.z as u64);
        Ok::<(), String>(())
    })
}

/// The image group's attributes: NGFF multiscales and Focal's frame.
fn group_attributes(volume: &Volume, dims: &[UVec3], sample: SampleKind, opts: &WriteOptions) -> serde_json::Map<String, Value> {
    let g = &volume.grid;
    let axis_aligned = g.direction == glam::Mat3::IDENTITY;
    let t0 = if axis_aligned { g.origin } else { glam::Vec3::ZERO };
    let datasets: Vec<Value> = (0..dims.len())
        .map(|k| {
            let f = (1u32 << k) as f32;
            let scale = g.spacing * f;
            let t = t0 + g.spacing * (f - 1.0) * 0.5;
            json!({"path": k.to_string(), "coordinateTransformations": [
                {"type": "scale", "scale": [scale.z as f64, scale.y as f64, scale.x as f64]},
                {"type": "translation", "translation": [t.z as f64, t.y as f64, t.x as f64]}]})
        })
        .collect();
    let axes: Vec<Value> = ["z", "y", "x"].iter().map(|n| json!({"name": n, "type": "space", "unit": "millimeter"})).collect();
    let mut multiscale = json!({
        "name": volume.name, "axes": axes, "datasets": datasets, "type": opts.downsample.name(),
        "metadata": {"description": "written by focal convert", "method": match opts.downsample {
            Downsample::Mean => "rounded mean of 2x2x2 blocks", Downsample::Nearest => "first voxel of 2x2x2 blocks" }},
    });
    let omero = json!({"channels": [{"label": volume.name, "window": {
        "min": volume.stats.min, "max": volume.stats.max, "start": volume.stats.p01, "end": volume.stats.p99}}]});
    let d = g.direction;
    let focal = json!({
        "direction": [d.x_axis.to_array(), d.y_axis.to_array(), d.z_axis.to_array()],
        "origin_mm": g.origin.to_array(),
        "levels": dims.iter().map(|&d| fmt_dims(d)).collect::<Vec<_>>(),
        "sample_type": sample.name(),
        "source": volume.source.path.as_ref().map(|p| p.display().to_string()),
    });
    let mut attrs = serde_json::Map::new();
    match opts.version {
        ZarrVersion::V2 => {
            multiscale["version"] = json!("0.4");
            attrs.insert("multiscales".into(), json!([multiscale]));
            attrs.insert("omero".into(), omero);
        }
        ZarrVersion::V3 => {
            attrs.insert("ome".into(), json!({"version": "0.5", "multiscales": [multiscale], "omero": omero}));
        }
    }
    attrs.insert("focal".into(), focal);
    attrs
}
