//! An OME-Zarr image as a [`VoxelSource`]: each level one Zarr array, read through
//! `zarrs` (Zarr v2 and v3, sharded or not, gzip / zstd / blosc), a box at a time.
//!
//! Samples become codes under one map fixed on opening: `uint8` and `uint16` as they are,
//! `int8` and `int16` shifted by 2⁷ or 2¹⁵ (lossless), wider and floating-point types
//! quantised to 16 bits over the first channel's display window or, without one, over
//! the range of the coarsest level (values past it clamp; the opening says so). NaN and
//! infinite samples read as the window's low end and are reported per chunk.
//!
//! A box is read chunk by chunk (for a sharded array, only the inner chunks it touches
//! are decoded). A chunk the store does not have is the array's fill value, as Zarr
//! defines, and is reported as absent; a chunk that fails to read or decode is drawn at
//! the fill value too and reported with its key and the error.
//!
//! Streamed, the source keeps the chunks it decoded for the next boxes that touch them
//! (`chunks`, within the share of the memory budget the streaming gives it).

use std::path::Path;
use std::sync::Arc;

use glam::{DMat3, DVec3, UVec3};
use zarrs::array::data_type::{
    Float32DataType, Float64DataType, Int8DataType, Int16DataType, Int32DataType, UInt8DataType, UInt16DataType, UInt32DataType,
};
use zarrs::array::{Array, ArrayShardedExt, ArraySubset, ElementOwned};
use zarrs::storage::ReadableStorage;

use super::chunks::{ChunkCache, Decoded};
use super::metadata::{AxisKind, Multiscale};
use crate::volume::grid::{Grid, fmt_dims};
use crate::volume::source::{Block, Fault, FaultKind, SourceError, SourceInfo, SourceLevel, VoxelSource, check_box};
use crate::volume::{Source, ValueMap, Voxels};

/// Largest box edge read to find the value range of a pyramid without a display window.
const RANGE_BOX: u32 = 256;

/// How samples become codes.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Encoding {
    U8,
    I8,
    U16,
    I16,
    /// 16-bit codes over `[lo, hi]`.
    Quantised {
        ty: Wide,
        lo: f64,
        hi: f64,
    },
}

/// Sample types that are quantised.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Wide {
    U32,
    I32,
    F32,
    F64,
}

/// One level: its array and where the spatial axes are among the array's dimensions.
struct Level {
    array: Array<dyn zarrs::storage::ReadableStorageTraits>,
    /// Array dimension of x, y, z (`None`: the array has no such axis, size 1).
    spatial: [Option<usize>; 3],
    /// Index used along every other dimension (time 0, channel 0).
    fixed: Vec<u64>,
    /// Chunk (inner chunk when sharded) shape per array dimension.
    read_chunk: Vec<u64>,
}

/// Where a sharded array's index lies (at the end unless `index_location` says
/// `start`) and whether it carries a CRC32C, from its `sharding_indexed` codec.
fn shard_index(metadata: &serde_json::Value) -> Option<(bool, bool)> {
    let codecs = metadata.get("codecs")?.as_array()?;
    let sharding = codecs.iter().find(|c| c.get("name").and_then(|n| n.as_str()) == Some("sharding_indexed"))?;
    let config = sharding.get("configuration")?;
    let at_end = config.get("index_location").and_then(|l| l.as_str()) != Some("start");
    let checksum = config.get("index_codecs").is_some_and(|c| c.to_string().contains("\"crc32c\""));
    Some((at_end, checksum))
}

/// An opened OME-Zarr image.
pub struct ZarrSource {
    info: SourceInfo,
    levels: Vec<Level>,
    encoding: Encoding,
    chunks: ChunkCache,
}

impl ZarrSource {
    /// The key prefix and the limit of each level whose codecs include blosc
    /// ([`super::guard`]): the largest decoded chunk in bytes (the inner chunk's shape,
    /// where sharded, times 8, the widest sample type) and the shard index's layout.
    pub fn blosc_arrays(&self) -> Vec<(String, super::guard::Limit)> {
        self.levels
            .iter()
            .filter_map(|l| {
                let metadata = serde_json::to_value(l.array.metadata()).ok()?;
                if !metadata.to_string().contains("\"blosc\"") {
                    return None;
                }
                let zero = vec![0; l.fixed.len()];
                let outer = l.array.chunk_shape(&zero).ok()?;
                let inner = l.array.effective_subchunk_shape().unwrap_or_else(|| outer.clone());
                let elements = |s: &[std::num::NonZeroU64]| s.iter().map(|c| c.get()).fold(1u64, u64::saturating_mul);
                let shard = shard_index(&metadata).map(|(at_end, checksum)| super::guard::ShardIndex {
                    chunks: outer.iter().zip(&inner).map(|(o, i)| o.get().div_ceil(i.get())).fold(1u64, u64::saturating_mul),
                    at_end,
                    checksum,
                });
                // (An array at the store's root: every key.)
                let path = l.array.path().as_str().trim_matches('/');
                let prefix = if path.is_empty() { String::new() } else { format!("{path}/") };
                Some((prefix, super::guard::Limit { chunk: elements(&inner).saturating_mul(8), shard }))
            })
            .collect()
    }

    /// Opens the image group `meta` describes in `store` (`root` names it in messages).
    pub fn open(store: ReadableStorage, root: &Path, meta: &Multiscale) -> Result<ZarrSource, String> {
        let mut warnings = meta.warnings.clone();
        let axes = &meta.axes;
        let named = |n: &str| axes.iter().position(|a| a.kind == AxisKind::Space && a.name.eq_ignore_ascii_case(n));
        let mut spatial = [named("x"), named("y"), named("z")];
        if spatial.iter().all(Option::is_none) {
            // Unnamed space axes: the last three are z, y, x.
            let space: Vec<usize> = (0..axes.len()).filter(|&i| axes[i].kind == AxisKind::Space).collect();
            let n = space.len();
            if n == 0 {
                return Err("the image has no space axes".into());
            }
            spatial = [space.get(n - 1).copied(), n.checked_sub(2).map(|i| space[i]), n.checked_sub(3).map(|i| space[i])];
            warnings.push("space axes are not named x, y, z: the last three are taken as z, y, x".into());
        }
        if spatial[0].is_none() || spatial[1].is_none() {
            return Err("the image needs at least the x and y axes".into());
        }
        let units: Vec<f64> = spatial.iter().map(|a| a.map_or(1.0, |i| axes[i].mm_per_unit.unwrap_or(1.0))).collect();
        if spatial.iter().flatten().any(|&i| axes[i].mm_per_unit.is_none()) {
            let named: Vec<String> = spatial.iter().flatten().filter_map(|&i| axes[i].unit.clone()).collect();
            warnings.push(if named.is_empty() {
                "the axes give no unit: scale taken as millimetres".into()
            } else {
                format!("unit {} is not a length Focal knows: scale taken as millimetres", named.join(", "))
            });
        }
        let mut levels = Vec::new();
        let mut source_levels = Vec::new();
        let mut data_type = None;
        for (k, d) in meta.datasets.iter().enumerate() {
            let key = format!("/{}", d.path.trim_matches('/'));
            let array = Array::open(store.clone(), &key).map_err(|e| format!("level {k} (array \"{}\"): {e}", d.path))?;
            let shape = array.shape().to_vec();
            if shape.len() != axes.len() {
                return Err(format!("level {k} (array \"{}\") has {} dimensions for {} axes", d.path, shape.len(), axes.len()));
            }
            let dt = array.data_type().clone();
            match &data_type {
                None => data_type = Some(dt),
                Some(first) if *first != dt => return Err(format!("level {k} is {dt}, level 0 is {first}")),
                _ => {}
            }
            if k == 0 {
                for (i, a) in axes.iter().enumerate() {
                    if !spatial.contains(&Some(i)) && shape[i] > 1 {
                        warnings.push(format!("axis \"{}\" has {} entries: the first is shown", a.name, shape[i]));
                    }
                }
            }
            let size = |axis: usize| spatial[axis].map_or(1, |i| shape[i]);
            let dims64 = [size(0), size(1), size(2)];
            if dims64.iter().any(|&n| n == 0 || n > crate::volume::readers::common::MAX_AXIS) {
                return Err(format!("level {k} (array \"{}\") has dimensions {dims64:?}", d.path));
            }
            let dims = UVec3::new(dims64[0] as u32, dims64[1] as u32, dims64[2] as u32);
            let chunk_shape = array.effective_subchunk_shape().or_else(|| array.chunk_shape(&vec![0; shape.len()]).ok());
            let Some(chunk_shape) = chunk_shape else {
                return Err(format!("level {k} (array \"{}\") has no regular chunk grid", d.path));
            };
            let read_chunk: Vec<u64> = chunk_shape.iter().map(|c| c.get()).collect();
            let chunk = UVec3::new(
                spatial[0].map_or(1, |i| read_chunk[i]) as u32,
                spatial[1].map_or(1, |i| read_chunk[i]) as u32,
                spatial[2].map_or(1, |i| read_chunk[i]) as u32,
            );
            let scale = |axis: usize| spatial[axis].map_or(1.0, |i| d.scale[i]) * units[axis];
            let shift = |axis: usize| spatial[axis].map_or(0.0, |i| d.translation[i]) * units[axis];
            let spacing = DVec3::new(scale(0), scale(1), scale(2));
            let translation = DVec3::new(shift(0), shift(1), shift(2));
            source_levels.push((dims, spacing, translation, chunk));
            levels.push(Level { array, spatial, fixed: vec![0; shape.len()], read_chunk });
        }
        let Some(data_type) = data_type else {
            return Err("the image has no levels".into());
        };
        // Orientation and origin: Focal's own frame if it wrote one, else the axes as RAS.
        let (direction, origin0) = match meta.focal_frame {
            Some((d, o)) => (DMat3::from_cols_array_2d(&d), DVec3::from_array(o)),
            None => (DMat3::IDENTITY, source_levels[0].2),
        };
        let t0 = source_levels[0].2;
        let mut info_levels = Vec::new();
        for (k, (dims, spacing, translation, chunk)) in source_levels.iter().enumerate() {
            let origin = origin0 + direction * (*translation - t0);
            let grid = Grid { dims: *dims, spacing: spacing.as_vec3(), origin: origin.as_vec3(), direction: direction.as_mat3() };
            grid.validate().map_err(|e| format!("level {k}: {e}"))?;
            info_levels.push(SourceLevel { grid, chunk: *chunk });
        }
        let name = meta.name.clone().unwrap_or_else(|| zarr_name(root));
        let zarr_version = if matches!(levels[0].array.metadata(), zarrs::array::ArrayMetadata::V2(_)) { 2 } else { 3 };
        let mut info = SourceInfo {
            name,
            source: Source {
                format: format!("OME-Zarr {} (Zarr v{zarr_version})", meta.version),
                path: Some(root.to_path_buf()),
                sample_type: data_type.to_string().split(" / ").next().unwrap_or_default().to_owned(),
                details: vec![
                    ("levels".into(), info_levels.iter().map(|l| fmt_dims(l.grid.dims)).collect::<Vec<_>>().join(", ")),
                    ("chunk".into(), fmt_dims(info_levels[0].chunk)),
                ],
            },
            values: ValueMap::IDENTITY,
            bits: 16,
            levels: info_levels,
            warnings,
            range: meta.window,
        };
        let mut source = ZarrSource { info: info.clone(), levels, encoding: Encoding::U16, chunks: ChunkCache::default() };
        let (encoding, values, bits) = source.encoding_for(&data_type, meta.window, &mut info.warnings)?;
        info.values = values;
        info.bits = bits;
        source.info = info;
        source.encoding = encoding;
        Ok(source)
    }

    /// Picks the codes for the array's data type.
    fn encoding_for(
        &self,
        dt: &zarrs::array::DataType,
        window: Option<(f64, f64)>,
        warnings: &mut Vec<String>,
    ) -> Result<(Encoding, ValueMap, u32), String> {
        let simple = if dt.is::<UInt8DataType>() {
            Some((Encoding::U8, ValueMap::IDENTITY, 8))
        } else if dt.is::<Int8DataType>() {
            Some((Encoding::I8, ValueMap::new(1.0, -128.0), 8))
        } else if dt.is::<UInt16DataType>() {
            Some((Encoding::U16, ValueMap::IDENTITY, 16))
        } else if dt.is::<Int16DataType>() {
            Some((Encoding::I16, ValueMap::new(1.0, -32768.0), 16))
        } else {
            None
        };
        if let Some(s) = simple {
            return Ok(s);
        }
        let ty = if dt.is::<Float32DataType>() {
            Wide::F32
        } else if dt.is::<Float64DataType>() {
            Wide::F64
        } else if dt.is::<UInt32DataType>() {
            Wide::U32
        } else if dt.is::<Int32DataType>() {
            Wide::I32
        } else {
            return Err(format!("data type {dt} is not supported (uint8, int8, uint16, int16, uint32, int32, float32, float64 are)"));
        };
        let (lo, hi) = match window {
            Some(w) => w,
            None => {
                let coarsest = self.levels.len() - 1;
                let (lo, hi, sampled) = self.native_range(coarsest, ty)?;
                let of = if sampled {
                    format!("the central {RANGE_BOX}³ voxels of the coarsest level")
                } else {
                    "the coarsest level".to_owned()
                };
                warnings.push(format!(
                    "{dt} values quantised to 16 bits over [{lo}, {hi}], the range of {of} (no display window in the metadata): values outside it clamp"
                ));
                (lo, hi)
            }
        };
        let hi = if hi > lo { hi } else { lo + 1.0 };
        Ok((Encoding::Quantised { ty, lo, hi }, ValueMap::new((hi - lo) / 65535.0, lo), 16))
    }

    /// The finite range of a level in its own type: the whole level, or its central
    /// [`RANGE_BOX`]³ voxels when it is larger (`sampled` says so).
    fn native_range(&self, level: usize, ty: Wide) -> Result<(f64, f64, bool), String> {
        let l = &self.levels[level];
        let dims = self.info.levels[level].grid.dims;
        let size = dims.min(UVec3::splat(RANGE_BOX));
        let subset = l.subset((dims - size) / 2, size);
        let values: Vec<f64> = match ty {
            Wide::U32 => retrieve::<u32>(l, &subset)?.into_iter().map(f64::from).collect(),
            Wide::I32 => retrieve::<i32>(l, &subset)?.into_iter().map(f64::from).collect(),
            Wide::F32 => retrieve::<f32>(l, &subset)?.into_iter().map(f64::from).collect(),
            Wide::F64 => retrieve::<f64>(l, &subset)?,
        };
        let finite = values.iter().copied().filter(|v| v.is_finite());
        let (lo, hi) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
        let sampled = size != dims;
        if lo > hi { Ok((0.0, 1.0, sampled)) } else { Ok((lo, hi, sampled)) }
    }

    /// Reads `subset` of a level, putting element `i` (in the subset's order) at
    /// `out[targets[i]]`; returns how many samples were NaN or infinite (drawn as code 0).
    fn read_part(&self, l: &Level, subset: &ArraySubset, targets: &[usize], out: &mut [u16]) -> Result<usize, String> {
        fn put<T: ElementOwned + Copy>(
            l: &Level,
            subset: &ArraySubset,
            targets: &[usize],
            out: &mut [u16],
            code: impl Fn(T) -> Option<u16>,
        ) -> Result<usize, String> {
            let v = retrieve::<T>(l, subset)?;
            if v.len() != targets.len() {
                return Err(format!("{} values decoded for {} voxels", v.len(), targets.len()));
            }
            let mut bad = 0;
            for (&at, &x) in targets.iter().zip(&v) {
                out[at] = code(x).unwrap_or_else(|| {
                    bad += 1;
                    0
                });
            }
            Ok(bad)
        }
        match self.encoding {
            Encoding::U8 => put(l, subset, targets, out, |x: u8| Some(x as u16)),
            Encoding::I8 => put(l, subset, targets, out, |x: i8| Some(i8_code(x))),
            Encoding::U16 => put(l, subset, targets, out, |x: u16| Some(x)),
            Encoding::I16 => put(l, subset, targets, out, |x: i16| Some(i16_code(x))),
            Encoding::Quantised { ty, lo, hi } => {
                let q = move |x: f64| quantised_code(x, lo, hi);
                match ty {
                    Wide::U32 => put(l, subset, targets, out, |x: u32| q(x as f64)),
                    Wide::I32 => put(l, subset, targets, out, |x: i32| q(x as f64)),
                    Wide::F32 => put(l, subset, targets, out, |x: f32| q(x as f64)),
                    Wide::F64 => put(l, subset, targets, out, q),
                }
            }
        }
    }

    /// The code of level `l`'s fill value (what an unreadable chunk is drawn at, as
    /// zarrs draws an absent one); a fill value that is not a finite number (NaN is
    /// common for float arrays) takes code 0, as NaN samples do.
    fn fill_code(&self, l: &Level) -> u16 {
        let b = l.array.fill_value().as_ne_bytes();
        let get = |n: usize| b.get(..n).map(<[u8]>::to_vec);
        let code = match self.encoding {
            Encoding::U8 => get(1).map(|v| v[0] as u16),
            Encoding::I8 => get(1).map(|v| i8_code(v[0] as i8)),
            Encoding::U16 => get(2).map(|v| u16::from_ne_bytes([v[0], v[1]])),
            Encoding::I16 => get(2).map(|v| i16_code(i16::from_ne_bytes([v[0], v[1]]))),
            Encoding::Quantised { ty, lo, hi } => {
                let value = match ty {
                    Wide::U32 => get(4).map(|v| u32::from_ne_bytes([v[0], v[1], v[2], v[3]]) as f64),
                    Wide::I32 => get(4).map(|v| i32::from_ne_bytes([v[0], v[1], v[2], v[3]]) as f64),
                    Wide::F32 => get(4).map(|v| f32::from_ne_bytes([v[0], v[1], v[2], v[3]]) as f64),
                    Wide::F64 => get(8).map(|v| f64::from_ne_bytes([v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]])),
                };
                value.and_then(|x| quantised_code(x, lo, hi))
            }
        };
        code.unwrap_or(0)
    }
}

/// Codes of signed samples: offset by half the range (the value map subtracts it).
fn i8_code(x: i8) -> u16 {
    (x as i16 + 128) as u16
}

fn i16_code(x: i16) -> u16 {
    (x as i32 + 32768) as u16
}

/// The 16-bit code of a wide sample over `[lo, hi]` (clamped); `None` for NaN or ±∞.
fn quantised_code(x: f64, lo: f64, hi: f64) -> Option<u16> {
    x.is_finite().then(|| ((x - lo) / (hi - lo) * 65535.0).round().clamp(0.0, 65535.0) as u16)
}

impl Level {
    /// The array subset of the box `lo .. lo + size` (fixed indices elsewhere).
    fn subset(&self, lo: UVec3, size: UVec3) -> ArraySubset {
        let mut ranges: Vec<std::ops::Range<u64>> = self.fixed.iter().map(|&i| i..i + 1).collect();
        for axis in 0..3 {
            if let Some(d) = self.spatial[axis] {
                ranges[d] = lo[axis] as u64..(lo[axis] + size[axis]) as u64;
            }
        }
        ArraySubset::new_with_ranges(&ranges)
    }
}

fn retrieve<T: ElementOwned>(l: &Level, subset: &ArraySubset) -> Result<Vec<T>, String> {
    l.array.retrieve_array_subset::<Vec<T>>(subset).map_err(|e| e.to_string())
}

/// The image's name from its folder (`brain.ome.zarr` → `brain`).
fn zarr_name(root: &Path) -> String {
    let name = root.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "OME-Zarr".into());
    name.trim_end_matches('/').trim_end_matches(".zarr").trim_end_matches(".ome").to_owned()
}

impl VoxelSource for ZarrSource {
    fn info(&self) -> &SourceInfo {
        &self.info
    }

    fn read_box(&self, level: usize, lo: UVec3, size: UVec3) -> Result<Block, SourceError> {
        check_box(&self.info, level, lo, size)?;
        let l = &self.levels[level];
        let dims = self.info.levels[level].grid.dims;
        let n = size.x as usize * size.y as usize * size.z as usize;
        let mut codes = vec![self.fill_code(l); n];
        let mut faults = Vec::new();
        // The read chunks the box touches, along x, y, z.
        let chunk = |axis: usize| l.spatial[axis].map_or(1, |d| l.read_chunk[d]);
        let range = |axis: usize| (lo[axis] as u64 / chunk(axis))..=((lo[axis] + size[axis] - 1) as u64 / chunk(axis));
        let keep = self.chunks.keeps();
        for cz in range(2) {
            for cy in range(1) {
                for cx in range(0) {
                    let c = [cx, cy, cz];
                    let chunk_lo = UVec3::from_array([0, 1, 2].map(|a| (c[a] * chunk(a)) as u32));
                    let chunk_hi = UVec3::from_array([0, 1, 2].map(|a| (((c[a] + 1) * chunk(a)) as u32).min(dims[a])));
                    let part = if keep {
                        // The whole chunk, kept for the boxes beside this one.
                        let id = (level, c);
                        self.chunks.get(id).unwrap_or_else(|| {
                            let decoded = Arc::new(self.decode(l, chunk_lo, chunk_hi - chunk_lo));
                            if decoded.faults.iter().all(|f| f.kind != FaultKind::Unreadable) {
                                self.chunks.insert(id, decoded.clone());
                            }
                            decoded
                        })
                    } else {
                        // Only what the box takes of it.
                        let (a, b) = (chunk_lo.max(lo), chunk_hi.min(lo + size));
                        Arc::new(self.decode(l, a, b - a))
                    };
                    part.copy_into(lo, size, &mut codes);
                    faults.extend(part.faults.iter().cloned());
                }
            }
        }
        let voxels = if self.info.bits == 8 { Voxels::U8(codes.into_iter().map(|c| c as u8).collect()) } else { Voxels::U16(codes) };
        Ok(Block { voxels, faults })
    }

    fn keep_decoded(&self, bytes: u64) -> u64 {
        self.chunks.set_budget(bytes);
        bytes
    }
}

impl ZarrSource {
    /// The box `lo .. lo + size` of level `l`, which lies in one read chunk, decoded to
    /// codes (the fill value's where it could not be read), with what was wrong.
    fn decode(&self, l: &Level, lo: UVec3, size: UVec3) -> Decoded {
        let n = size.x as usize * size.y as usize * size.z as usize;
        let mut codes = vec![self.fill_code(l); n];
        let mut faults = Vec::new();
        let part = l.subset(lo, size);
        // The storage chunk (a whole shard when sharded) holding this part.
        let key = l.storage_chunk(&part).map(|idx| l.array.chunk_key(&idx));
        let key_name = key.as_ref().map_or_else(|| format!("{part}"), |k| k.to_string());
        if let Some(k) = &key
            && matches!(l.array.storage().size_key(k), Ok(None))
        {
            faults.push(Fault {
                chunk: key_name.clone(),
                kind: FaultKind::Absent,
                problem: "absent from the store: drawn at the fill value".into(),
            });
        }
        let targets = l.targets(lo, size, lo, size);
        match self.read_part(l, &part, &targets, &mut codes) {
            Ok(0) => {}
            Ok(n) => faults.push(Fault {
                chunk: key_name,
                kind: FaultKind::NotFinite,
                problem: format!("{n} samples NaN or infinite: drawn at the window's low end"),
            }),
            Err(e) => faults.push(Fault { chunk: key_name, kind: FaultKind::Unreadable, problem: e }),
        }
        Decoded { lo, size, codes, faults }
    }
}

impl Level {
    /// Where each element of the part `plo .. plo + psize` (in the array's C order) goes
    /// in the box `lo .. lo + size` (x fastest).
    fn targets(&self, plo: UVec3, psize: UVec3, lo: UVec3, size: UVec3) -> Vec<usize> {
        let ndim = self.fixed.len();
        let mut extent = vec![1u64; ndim];
        let mut stride = vec![0usize; ndim];
        let box_strides = [1, size.x as usize, size.x as usize * size.y as usize];
        let mut base = 0;
        for axis in 0..3 {
            if let Some(d) = self.spatial[axis] {
                extent[d] = psize[axis] as u64;
                stride[d] = box_strides[axis];
            }
            base += (plo[axis] - lo[axis]) as usize * box_strides[axis];
        }
        let count = psize.x as usize * psize.y as usize * psize.z as usize;
        let mut out = Vec::with_capacity(count);
        let mut index = vec![0u64; ndim];
        for _ in 0..count {
            out.push(base + index.iter().zip(&stride).map(|(&i, &s)| i as usize * s).sum::<usize>());
            // Odometer over the part, last dimension fastest.
            for d in (0..ndim).rev() {
                index[d] += 1;
                if index[d] < extent[d] {
                    break;
                }
                index[d] = 0;
            }
        }
        out
    }

    /// Indices of the storage chunk holding the start of `part`.
    fn storage_chunk(&self, part: &ArraySubset) -> Option<Vec<u64>> {
        let start = part.start().to_vec();
        let chunk = self.array.chunk_shape(&vec![0; start.len()]).ok()?;
        Some(start.iter().zip(chunk.iter()).map(|(s, c)| s / c.get()).collect())
    }
}
