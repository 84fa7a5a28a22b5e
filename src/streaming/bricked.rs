//! What a bricked dataset is, and what the renderer is told of it each frame.
//!
//! A source with more than one level is drawn brick by brick: its coarse level `C` (the
//! finest level of at most [`COARSE_VOXELS`] voxels) is read whole into the dataset's
//! [`Volume`] (what the CPU side — picking, statistics, the reference renderer — and
//! the ray caster's last fallback use), and the levels `0 … C−1` stream as bricks of
//! [`BRICK`] through a [`BrickCache`]. The coarse level is also cut into bricks once, at
//! open ([`BrickedDataset::coarse_bricks`]), drawn every frame: with them in the brick
//! atlas every sample of the volume reads the atlas, and the ray caster needs no path to
//! the volume atlas (`BRICKED_ONLY`, `render::bricked`). Levels must halve exactly (`⌈n/2⌉` voxels per
//! axis, twice the spacing): bricks of neighbouring levels then nest, which the page
//! table relies on (`render::bricked::page_table`); a pyramid that does not (ome-zarr-py
//! often halves only y and x) is shown from one whole level instead, with a warning.

use std::sync::{Arc, Mutex};

use bevy::prelude::*;

use crate::volume::Volume;
use crate::volume::source::brick::BrickLayout;
use crate::volume::source::cache::{BrickCache, BrickData, BrickKey};
use crate::volume::source::level::read_level;
use crate::volume::source::memory::MemorySource;
use crate::volume::source::{SourceError, SourceLevel, VoxelSource};

/// Bricks of 32³ voxels with an apron of two: trilinear filtering anywhere in the brick,
/// and the gradient's neighbours one voxel away, read the brick alone.
pub const BRICK: BrickLayout = BrickLayout::new(32, 2);

/// Most voxels of the coarse level read whole (64³).
pub const COARSE_VOXELS: u64 = 1 << 18;

/// Memory budgets of streaming.
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct StreamBudget {
    /// Bytes of decoded bricks kept in memory per dataset.
    pub cpu_bytes: u64,
    /// Bytes of the GPU brick atlas.
    pub gpu_bytes: u64,
    /// Bricks uploaded to the GPU per frame at most.
    pub uploads_per_frame: usize,
}

/// Environment variables that set the budgets in MiB (decoded bricks per dataset, the
/// GPU atlas).
pub const CPU_BUDGET_VAR: &str = "FOCAL_CACHE_MB";
pub const GPU_BUDGET_VAR: &str = "FOCAL_GPU_CACHE_MB";

impl Default for StreamBudget {
    /// 512 MiB of decoded bricks, a 256 MiB GPU atlas, 64 uploads a frame; the budgets
    /// from [`CPU_BUDGET_VAR`] and [`GPU_BUDGET_VAR`] where set (a value that is not a
    /// number of MiB ≥ 1 is ignored with a warning).
    fn default() -> Self {
        let mib = |var: &str, default: u64| match std::env::var(var) {
            Ok(v) => match v.trim().parse::<u64>() {
                Ok(n) if n >= 1 => n << 20,
                _ => {
                    warn!("{var}={v} is not a number of MiB: {} MiB used", default >> 20);
                    default
                }
            },
            Err(_) => default,
        };
        Self { cpu_bytes: mib(CPU_BUDGET_VAR, 512 << 20), gpu_bytes: mib(GPU_BUDGET_VAR, 256 << 20), uploads_per_frame: 64 }
    }
}

impl StreamBudget {
    /// Bricks the GPU atlas holds for codes of `bits` (the same count the renderer's
    /// slots come to, `render::bricked::slots`): the most a view may want at once.
    pub fn gpu_bricks(&self, bits: u32) -> usize {
        let edge = BRICK.stored() as u64;
        (self.gpu_bytes / (edge * edge * edge * (bits as u64 / 8).max(1))).max(1) as usize
    }
}

/// A dataset drawn from a pyramid brick by brick (beside its [`crate::dataset::Dataset`],
/// whose volume is the coarse level).
#[derive(Component, Clone)]
pub struct BrickedDataset {
    pub cache: Arc<BrickCache>,
    /// Every level of the source, finest first.
    pub levels: Vec<SourceLevel>,
    /// The level the dataset's volume holds.
    pub coarse: usize,
    /// That level cut into bricks of [`BRICK`] (keys of level `coarse`).
    pub coarse_bricks: Arc<Vec<(BrickKey, Arc<BrickData>)>>,
}

impl std::fmt::Debug for BrickedDataset {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BrickedDataset").field("levels", &self.levels.len()).field("coarse", &self.coarse).finish()
    }
}

impl BrickedDataset {
    /// Opens `source` for streaming: `None` (with the reason) when one whole level
    /// serves as well (a single level, or levels that do not halve exactly).
    pub fn open(source: Arc<dyn VoxelSource>, cpu_bytes: u64) -> Result<Result<(BrickedDataset, Volume), String>, String> {
        let info = source.info().clone();
        if info.levels.len() < 2 {
            return Ok(Err(format!("{}: one level only, shown whole", info.name)));
        }
        if let Some(k) = (1..info.levels.len()).find(|&k| !halves(&info.levels[k - 1], &info.levels[k])) {
            return Ok(Err(format!(
                "{}: level {k} is not level {} halved on every axis; shown from one whole level, not streamed",
                info.name,
                k - 1
            )));
        }
        let coarse = (0..info.levels.len())
            .find(|&k| info.levels[k].grid.voxel_count() as u64 <= COARSE_VOXELS)
            .unwrap_or(info.levels.len() - 1)
            .max(1);
        let (mut volume, faults) = read_level(source.as_ref(), coarse, &|_| {}).map_err(|e| e.to_string())?;
        // A coarse level's means span less than the data, and a look's table covers the
        // dataset's range (values past it take its edge): the source's own range where it
        // knows it, else every code's.
        let codes = {
            let (a, b) = (info.values.to_real(0.0), info.values.to_real(info.code_max() as f64));
            (a.min(b), a.max(b))
        };
        let range = info.range.filter(|(lo, hi)| lo.is_finite() && hi.is_finite() && lo <= hi).unwrap_or(codes);
        {
            let (lo, hi) = range;
            volume.stats.min = volume.stats.min.min(lo);
            volume.stats.max = volume.stats.max.max(hi);
        }
        if let Some(summary) = crate::volume::source::level::summarize(&faults) {
            warn!("{summary}");
        }
        let levels = info.levels.clone();
        let coarse_bricks = Arc::new(bricks_of(&volume, coarse).map_err(|e| e.to_string())?);
        let cache = Arc::new(BrickCache::new(source, BRICK, cpu_bytes));
        Ok(Ok((BrickedDataset { cache, levels, coarse, coarse_bricks }, volume)))
    }

    /// Voxel dims of the levels `0 … C` the page table covers.
    pub fn table_dims(&self) -> Vec<UVec3> {
        self.levels[..=self.coarse].iter().map(|l| l.grid.dims).collect()
    }

    pub fn bits(&self) -> u32 {
        self.cache.source().info().bits
    }
}

/// `volume` (level `level` of its pyramid) cut into bricks of [`BRICK`], apron included.
fn bricks_of(volume: &Volume, level: usize) -> Result<Vec<(BrickKey, Arc<BrickData>)>, SourceError> {
    let source = MemorySource::new(Arc::new(volume.clone()), u32::MAX);
    let n = BRICK.bricks(volume.dims());
    let mut out = Vec::with_capacity((n.x * n.y * n.z) as usize);
    for z in 0..n.z {
        for y in 0..n.y {
            for x in 0..n.x {
                let b = UVec3::new(x, y, z);
                out.push((BrickKey::new(level, b), Arc::new(BrickData::new(BRICK, BRICK.read(&source, 0, b)?))));
            }
        }
    }
    Ok(out)
}

/// Whether `b` is `a` halved: `⌈n/2⌉` voxels and twice the spacing on every axis.
fn halves(a: &SourceLevel, b: &SourceLevel) -> bool {
    let dims = (a.grid.dims + 1) / 2 == b.grid.dims;
    let spacing = (b.grid.spacing - 2.0 * a.grid.spacing).abs().cmple(a.grid.spacing * 1e-3).all();
    dims && spacing
}

/// The renderer's view of one bricked scene volume this frame.
#[derive(Clone)]
pub struct BrickFrame {
    /// Voxel dims of the levels the page table covers (`0 … C`) and the brick layout.
    pub table_dims: Vec<UVec3>,
    pub layout: BrickLayout,
    /// The coarse level's index `C`.
    pub coarse: usize,
    /// Bits per code.
    pub bits: u32,
    /// Bricks to draw that hold something visible, coarse first, with their codes and
    /// which of their 8³ sub-blocks do (bit `x + 4y + 16z`).
    pub drawn: Arc<Vec<(BrickKey, Arc<BrickData>, u64)>>,
    /// Bricks to draw whose codes are all invisible (skipped, never uploaded), with
    /// their lowest code.
    pub empty: Arc<Vec<(BrickKey, u16)>>,
    /// Whether every wanted brick is among them.
    pub complete: bool,
}

/// The bricked frames of [`crate::dataset::SceneRegions`]' volumes (same order; `None`
/// for volumes in memory).
#[derive(Resource, Clone, Default)]
pub struct BrickedScene {
    pub volumes: Vec<Option<BrickFrame>>,
}

/// What streaming is doing, shared by the main and render worlds (the app's status line,
/// the headless render's wait for convergence).
#[derive(Resource, Clone, Default)]
pub struct StreamStatus(pub Arc<Mutex<StreamCounts>>);

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StreamCounts {
    /// Bricked volumes in the scene, and views that asked for bricks.
    pub bricked: usize,
    pub views: usize,
    /// Bricks the views want, resident in memory, on their way, failed.
    pub wanted: usize,
    pub resident: usize,
    pub pending: usize,
    pub failed: u64,
    /// Bricks in the GPU atlas, and those drawn but not yet uploaded (render world).
    pub on_gpu: usize,
    pub not_uploaded: usize,
    /// The finest level wanted anywhere.
    pub finest_wanted: Option<usize>,
}

impl StreamStatus {
    pub fn counts(&self) -> StreamCounts {
        self.0.lock().map(|c| *c).unwrap_or_default()
    }

    pub fn update(&self, f: impl FnOnce(&mut StreamCounts)) {
        if let Ok(mut c) = self.0.lock() {
            f(&mut c);
        }
    }

    /// Whether the picture has converged: everything wanted is drawn.
    pub fn converged(&self) -> bool {
        let c = self.counts();
        c.bricked == 0 || (c.views > 0 && c.pending == 0 && c.resident + c.failed as usize >= c.wanted && c.not_uploaded == 0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::{Grid, Source, ValueMap, Voxels};

    #[test]
    fn the_coarse_level_is_cut_into_the_bricks_the_source_gives() {
        let dims = UVec3::new(150, 90, 70);
        let codes = (0..dims.x * dims.y * dims.z).map(|i| ((i as u64 * 7919) % 4093) as u16).collect();
        let v =
            Volume::new("noise", Grid::new(dims, Vec3::ONE), Voxels::U16(codes), ValueMap::IDENTITY, Source::default()).expect("volume");
        let source: Arc<dyn VoxelSource> = Arc::new(MemorySource::new(Arc::new(v), 16));
        let Ok(Ok((bricked, coarse))) = BrickedDataset::open(source.clone(), 1 << 20) else { panic!("streamed") };
        // 75 × 45 × 35 voxels: the first level within 64³.
        assert_eq!((bricked.coarse, coarse.dims()), (1, UVec3::new(75, 45, 35)));
        assert_eq!(bricked.table_dims().len(), 2, "the page table covers levels 0 … C");
        assert_eq!(bricked.coarse_bricks.len(), 3 * 2 * 2);
        for (k, data) in bricked.coarse_bricks.iter() {
            assert_eq!(k.level, 1);
            let Ok(block) = BRICK.read(source.as_ref(), 1, k.coords()) else { panic!("brick {k:?}") };
            assert!(data.voxels == block.voxels, "brick {k:?} differs from the source's");
            assert_eq!(data.range, crate::volume::source::brick::code_range(&block.voxels));
        }
    }
}
