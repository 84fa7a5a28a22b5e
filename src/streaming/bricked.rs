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
    /// The largest gradient magnitude seen at each level `0 … C` (normalised units per
    /// voxel of the level): the largest over the bricks of that level drawn so far
    /// (it only grows), the whole coarse level's at `C`; taken only while a look of the
    /// volume needs it (`Appearance::uses_gradient_magnitude`). A volume in memory normalises
    /// by the largest over the whole volume, which a pyramid too large to read cannot
    /// know; once the bricks of a view are in, the view's is at hand.
    pub gradient_max: Vec<f32>,
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
                "{}: level {k} is not level {} halved on every axis (⌈n/2⌉ voxels of twice the spacing, centred on blocks of 2×2×2); shown from one whole level, not streamed",
                info.name,
                k - 1
            )));
        }
        let coarse = (0..info.levels.len())
            .find(|&k| info.levels[k].grid.voxel_count() as u64 <= COARSE_VOXELS)
            .unwrap_or(info.levels.len() - 1)
            .max(1);
        // An eighth of the memory budget for the source's decoded chunks (a brick's box
        // and its apron touch up to eight of them, each shared with the bricks beside
        // it), the rest for the bricks.
        let kept = source.keep_decoded(cpu_bytes / 8);
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
            warn!("{}: {summary}", info.location());
        }
        let levels = info.levels.clone();
        let coarse_bricks = Arc::new(bricks_of(&volume, coarse).map_err(|e| e.to_string())?);
        let cache = Arc::new(BrickCache::new(source, BRICK, cpu_bytes.saturating_sub(kept)));
        let gradient_max = vec![0.0; coarse + 1];
        Ok(Ok((BrickedDataset { cache, levels, coarse, coarse_bricks, gradient_max }, volume)))
    }

    /// The box of level 0's voxel cells in the coarse volume's continuous voxel index
    /// (`lo`, `hi`): the coarse level's own box reaches up to 2^C − 1 level-0 voxels
    /// past it on the far faces (where its last voxels average fewer than 2^C), which
    /// would draw the edge voxels repeated. `q₀ = (q_C + ½)·2^C − ½`, so level 0's
    /// `[−½, n₀ − ½]` is `[−½, n₀/2^C − ½]`.
    pub fn index_box(&self) -> (Vec3, Vec3) {
        let s = (1u32 << self.coarse) as f32;
        let n0 = self.levels.first().map_or(Vec3::ONE, |l| l.grid.dims.as_vec3());
        (Vec3::splat(-0.5), n0 / s - 0.5)
    }

    /// Voxel dims of the levels `0 … C` the page table covers.
    pub fn table_dims(&self) -> Vec<UVec3> {
        self.levels[..=self.coarse].iter().map(|l| l.grid.dims).collect()
    }

    pub fn bits(&self) -> u32 {
        self.cache.source().info().bits
    }

    /// Takes the gradients of `bricks` into [`Self::gradient_max`]; whether it grew.
    pub fn see_gradients<'a>(&mut self, bricks: impl IntoIterator<Item = (BrickKey, &'a BrickData)>) -> bool {
        let mut grew = false;
        for (k, b) in bricks {
            let g = b.gradient_max();
            if let Some(m) = self.gradient_max.get_mut(k.level as usize).filter(|m| **m < g) {
                *m = g;
                grew = true;
            }
        }
        grew
    }

    /// The normalisation of each level's gradients `0 … C`: its largest seen, or where
    /// none was yet (no brick of it drawn, or all flat) the next coarser level's.
    pub fn gradient_norms(&self) -> Vec<f32> {
        let mut out = self.gradient_max.clone();
        for k in (0..out.len().saturating_sub(1)).rev() {
            if out[k] <= 0.0 {
                out[k] = out[k + 1];
            }
        }
        out.iter().map(|m| m.max(1e-6)).collect()
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

/// Whether `b` is `a` halved: `⌈n/2⌉` voxels of twice the spacing on every axis, each
/// centred on its block of 2×2×2 voxels of `a` (the first at `a`'s origin plus half a
/// voxel; within a twentieth of a voxel). A pyramid sampled at every other voxel (its
/// levels' origins all alike) does not nest so: streamed, its finer levels would lie
/// up to half a coarse voxel off.
fn halves(a: &SourceLevel, b: &SourceLevel) -> bool {
    let dims = (a.grid.dims + 1) / 2 == b.grid.dims;
    let spacing = (b.grid.spacing - 2.0 * a.grid.spacing).abs().cmple(a.grid.spacing * 1e-3).all();
    let centre = a.grid.index_to_world().transform_point3(Vec3::splat(0.5));
    let offset = a.grid.world_to_index().transform_point3(b.grid.origin) - a.grid.world_to_index().transform_point3(centre);
    dims && spacing && offset.abs().cmple(Vec3::splat(0.05)).all()
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
    /// The gradient normalisation of each level `0 … C`
    /// ([`BrickedDataset::gradient_norms`]).
    pub gradient_norms: Vec<f32>,
}

impl BrickFrame {
    /// The level the ray caster samples at `q` (continuous voxel index of the coarse
    /// level): the finest whose brick there is drawn or marked empty, as the page table
    /// resolves it (`render::bricked::page_table`: the level-0 brick `b₀` holding the
    /// point, clamped to the volume, and at level `k` its ancestor `b₀ / 2ᵏ`). `None`
    /// outside the volume's box.
    pub fn level_at(&self, q: Vec3) -> Option<usize> {
        let d0 = self.table_dims.first()?.as_vec3();
        let q0 = (q + 0.5) * (1u32 << self.coarse) as f32 - 0.5;
        if !(q0.cmpge(Vec3::splat(-0.5)).all() && q0.cmple(d0 - 0.5).all()) {
            return None;
        }
        let size = self.layout.size as f32;
        let last = self.layout.bricks(d0.as_uvec3()).saturating_sub(UVec3::ONE);
        let b0 = ((q0.clamp(Vec3::ZERO, d0 - 1.0) + 0.5) / size).floor().as_uvec3().min(last);
        let present = |k: BrickKey| self.drawn.iter().any(|(d, ..)| *d == k) || self.empty.iter().any(|(e, _)| *e == k);
        (0..=self.coarse).find(|&k| present(BrickKey::new(k, b0 >> k as u32)))
    }
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

    /// A source whose levels' origins are all level 0's (sampled, not averaged).
    struct Sampled(Arc<dyn VoxelSource>, crate::volume::source::SourceInfo);

    impl VoxelSource for Sampled {
        fn info(&self) -> &crate::volume::source::SourceInfo {
            &self.1
        }

        fn read_box(&self, level: usize, lo: UVec3, size: UVec3) -> Result<crate::volume::source::Block, SourceError> {
            self.0.read_box(level, lo, size)
        }
    }

    #[test]
    fn levels_that_do_not_nest_are_not_streamed() {
        let dims = UVec3::new(80, 70, 66);
        let v = Volume::new(
            "zeros",
            Grid::new(dims, Vec3::new(0.5, 0.5, 2.0)),
            Voxels::U8(vec![0; (80 * 70 * 66) as usize]),
            ValueMap::IDENTITY,
            Source::default(),
        )
        .expect("volume");
        let nested: Arc<dyn VoxelSource> = Arc::new(MemorySource::new(Arc::new(v), 16));
        assert!(matches!(BrickedDataset::open(nested.clone(), 1 << 20), Ok(Ok(_))), "averaged levels nest");
        let mut info = nested.info().clone();
        let origin = info.levels[0].grid.origin;
        for l in &mut info.levels {
            l.grid.origin = origin;
        }
        let Ok(Err(why)) = BrickedDataset::open(Arc::new(Sampled(nested, info)), 1 << 20) else { panic!("streamed") };
        assert!(why.contains("level 1") && why.contains("centred"), "{why}");
    }

    #[test]
    fn the_level_at_a_point_is_the_finest_brick_present_there() {
        let layout = BrickLayout::new(8, 1);
        let data = Arc::new(BrickData::new(layout, crate::volume::source::Block { voxels: Voxels::U8(vec![1; 1000]), faults: Vec::new() }));
        // Level 0 of 40 × 20 × 20 voxels, coarse level 2 (10 × 5 × 5): bricks of level 0
        // (5 × 3 × 3) … level 2 (2 × 1 × 1).
        let frame = |drawn: &[BrickKey], empty: &[BrickKey]| BrickFrame {
            table_dims: vec![UVec3::new(40, 20, 20), UVec3::new(20, 10, 10), UVec3::new(10, 5, 5)],
            layout,
            coarse: 2,
            bits: 8,
            drawn: Arc::new(drawn.iter().map(|k| (*k, data.clone(), u64::MAX)).collect()),
            empty: Arc::new(empty.iter().map(|k| (*k, 0)).collect()),
            complete: false,
            gradient_norms: vec![1.0; 3],
        };
        let coarse = [BrickKey::new(2, UVec3::ZERO), BrickKey::new(2, UVec3::X)];
        let f = frame(&[coarse[0], coarse[1], BrickKey::new(1, UVec3::new(1, 0, 0))], &[BrickKey::new(0, UVec3::new(3, 1, 0))]);
        // Coarse voxel 1 → level-0 index (1.5 · 4 − 0.5) = 5.5: level-0 brick 0, level-1
        // brick 0: only the coarse brick.
        assert_eq!(f.level_at(Vec3::new(1.0, 1.0, 1.0)), Some(2));
        // Coarse x 4.2 → level 0 x 18.3: brick 2 of level 0, brick 1 of level 1 (drawn).
        assert_eq!(f.level_at(Vec3::new(4.2, 1.0, 1.0)), Some(1));
        // Coarse (6.3, 2.0, 0.2) → level 0 (26.7, 9.5, 2.3): brick (3, 1, 0), marked empty.
        assert_eq!(f.level_at(Vec3::new(6.3, 2.0, 0.2)), Some(0));
        // Past the box (coarse x ≥ 9.5) nothing; at its last voxel (level 0 x 39) the last
        // coarse brick.
        assert_eq!(f.level_at(Vec3::new(9.6, 1.0, 1.0)), None);
        assert_eq!(f.level_at(Vec3::new(9.4, 1.0, 1.0)), Some(2));
        assert_eq!(frame(&[coarse[0]], &[]).level_at(Vec3::new(9.4, 1.0, 1.0)), None, "its coarse brick missing");
        assert_eq!(frame(&[], &[]).level_at(Vec3::ONE), None, "nothing drawn: no level");
    }

    #[test]
    fn a_bricked_datasets_region_is_level_0s_box() {
        use crate::dataset::{Dataset, SceneRegions};
        // 71 voxels along x: level 1 has 36, whose box reaches half a level-1 voxel (one
        // level-0 voxel) past level 0's.
        let dims = UVec3::new(71, 40, 36);
        let v = Volume::new("v", Grid::new(dims, Vec3::ONE), Voxels::U8(vec![9; 71 * 40 * 36]), ValueMap::IDENTITY, Source::default())
            .expect("volume");
        let Ok(Ok((bricked, coarse))) = BrickedDataset::open(Arc::new(MemorySource::new(Arc::new(v), 16)), 1 << 20) else {
            panic!("streamed")
        };
        assert_eq!((bricked.coarse, coarse.dims().x), (1, 36));
        assert_eq!(bricked.index_box(), (Vec3::splat(-0.5), Vec3::new(35.0, 19.5, 17.5)));
        let mut app = App::new();
        app.add_plugins((MinimalPlugins, TransformPlugin, crate::dataset::DatasetPlugin))
            .add_systems(PostUpdate, crate::streaming::systems::data_boxes.before(crate::dataset::RegionSystems::Collect));
        let coarse = Arc::new(coarse);
        app.world_mut().spawn((
            Dataset::new(
                coarse.clone(),
                crate::region::Appearance::new(
                    crate::region::Mode::Dvr,
                    crate::transfer::presets::builtin("grayscale_ramp").expect("a preset"),
                ),
            ),
            Transform::default(),
            bricked,
        ));
        app.update();
        let scene = &app.world().resource::<SceneRegions>().scene;
        let region = &scene.regions[0];
        // Level 0's last voxel cell ends at x = 70.5 (its grid: voxel centres 0 … 70).
        let index_to_world = coarse.grid.world_to_index().inverse();
        let at = |q: Vec3| index_to_world.transform_point3(q);
        assert!(region.contains(at(Vec3::new(34.9, 10.0, 10.0))));
        assert!(!region.contains(at(Vec3::new(35.2, 10.0, 10.0))), "the coarse box's overhang is drawn");
        assert!((at(Vec3::new(35.0, 0.0, 0.0)).x - 70.5).abs() < 1e-4);
    }

    #[test]
    fn the_coarse_level_is_cut_into_the_bricks_the_source_gives() {
        let dims = UVec3::new(150, 90, 70);
        let codes = (0..dims.x * dims.y * dims.z).map(|i| ((i as u64 * 7919) % 4093) as u16).collect();
        let v =
            Volume::new("noise", Grid::new(dims, Vec3::ONE), Voxels::U16(codes), ValueMap::IDENTITY, Source::default()).expect("volume");
        let source: Arc<dyn VoxelSource> = Arc::new(MemorySource::new(Arc::new(v), 16));
        let Ok(Ok((mut bricked, coarse))) = BrickedDataset::open(source.clone(), 1 << 20) else { panic!("streamed") };
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
        // The coarse level's largest gradient, from its bricks, is the whole volume's
        // (taken when a look needs it: none was computed at opening).
        assert_eq!(bricked.gradient_max, vec![0.0, 0.0]);
        let coarse_bricks = bricked.coarse_bricks.clone();
        assert!(bricked.see_gradients(coarse_bricks.iter().map(|(k, d)| (*k, d.as_ref()))));
        let g = bricked.gradient_max[1];
        assert!((g - coarse.gradient_max()).abs() < 1e-6 && g > 0.0, "{g} vs {}", coarse.gradient_max());
        assert_eq!(bricked.gradient_max[0], 0.0, "no level-0 brick seen yet");
        assert_eq!(bricked.gradient_norms(), vec![g, g], "an unseen level takes the coarser one's");
    }

    #[test]
    fn a_levels_gradient_normalisation_is_the_largest_of_its_bricks_seen() {
        let dims = UVec3::new(70, 40, 36);
        let code = |p: UVec3| (((p.x * 37 + p.y * 11 + p.z * 5) % 23) * 100 + p.x * 3) as u16;
        let codes: Vec<u16> =
            (0..dims.z).flat_map(|z| (0..dims.y).flat_map(move |y| (0..dims.x).map(move |x| code(UVec3::new(x, y, z))))).collect();
        let v = Volume::new("ramp", Grid::new(dims, Vec3::ONE), Voxels::U16(codes), ValueMap::IDENTITY, Source::default()).expect("volume");
        let source: Arc<dyn VoxelSource> = Arc::new(MemorySource::new(Arc::new(v), 16));
        let Ok(Ok((mut bricked, _))) = BrickedDataset::open(source.clone(), 1 << 20) else { panic!("streamed") };
        // Brick (1, 0, 0) of level 0 owns x 32 … 63, y and z 0 … 31: central differences
        // of the codes (edges clamped) over 65535, worked out here without the sampler.
        let at = |x: i64, y: i64, z: i64| {
            let c = |v: i64, n: u32| v.clamp(0, n as i64 - 1) as u32;
            code(UVec3::new(c(x, dims.x), c(y, dims.y), c(z, dims.z))) as f32 / 65535.0
        };
        let mut expected = 0.0f32;
        for z in 0..32i64 {
            for y in 0..32i64 {
                for x in 32..64i64 {
                    let g =
                        Vec3::new(at(x + 1, y, z) - at(x - 1, y, z), at(x, y + 1, z) - at(x, y - 1, z), at(x, y, z + 1) - at(x, y, z - 1));
                    expected = expected.max((g * 0.5).length());
                }
            }
        }
        let key = BrickKey::new(0, UVec3::new(1, 0, 0));
        let Ok(block) = BRICK.read(source.as_ref(), 0, key.coords()) else { panic!("brick") };
        let brick = BrickData::new(BRICK, block);
        assert!((brick.gradient_max() - expected).abs() < 1e-6, "{} vs {expected}", brick.gradient_max());
        assert!(bricked.see_gradients([(key, &brick)]));
        assert!(!bricked.see_gradients([(key, &brick)]), "seen again: nothing grew");
        assert_eq!(bricked.gradient_norms()[0], expected);
        // A level's normalisation never shrinks (a flatter brick seen later keeps it).
        let flat = BrickData::new(BRICK, crate::volume::source::Block { voxels: Voxels::U16(vec![7; 36 * 36 * 36]), faults: Vec::new() });
        assert_eq!(flat.gradient_max(), 0.0);
        assert!(!bricked.see_gradients([(BrickKey::new(0, UVec3::ZERO), &flat)]));
        assert_eq!(bricked.gradient_norms()[0], expected);
    }
}
