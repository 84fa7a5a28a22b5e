//! Marks the packed regions of bricked volumes: every record whose volume is bricked
//! (the region itself, an exploded view's parts, a segmentation's parts) gets its place
//! in the page directory, brick layout, coarse level, level-0 dims and table directory
//! level, and the ray caster's bound on loop iterations grows by `2^C` (a ray under a
//! magnifier may step at level 0). Where every record is bricked the scene may take the
//! `BRICKED_ONLY` shader (once the atlas holds every coarse brick: [`pipeline_features`]).

use glam::{UVec4, Vec4};

use super::page_table::directory_level;
use crate::region::RenderScene;
use crate::render::gpu_types::features;
use crate::render::pack::PackedScene;
use crate::streaming::bricked::BrickFrame;

/// Marks `packed`'s records of the bricked volumes of `frames` (by scene volume index);
/// returns the directory: the scene volume of each entry.
pub fn mark_bricked(packed: &mut PackedScene, scene: &RenderScene, frames: &[Option<BrickFrame>]) -> Vec<usize> {
    let mut directory = Vec::new();
    let mut growth = 1u32;
    for (v, frame) in frames.iter().enumerate() {
        let (Some(frame), Some(volume)) = (frame, scene.volumes.get(v)) else { continue };
        if frame.coarse == 0 {
            continue;
        }
        let Some(slot) = packed.volumes.iter().position(|&u| u == v) else { continue };
        let offset = packed.levels[slot][0].as_vec3();
        let dims = volume.dims().as_vec3();
        let scale = (1u32 << frame.coarse) as f32;
        let entry = directory.len() as u32 + 1;
        let Some(level0) = frame.table_dims.first().copied() else { continue };
        let directory_level = directory_level(frame.table_dims.len() - 1);
        let mut any = false;
        for r in packed.regions.iter_mut().filter(|r| r.atlas_offset.truncate() == offset && r.dims.truncate() == dims) {
            r.bricked = UVec4::new(entry, frame.layout.size, frame.layout.apron, frame.coarse as u32);
            r.bricked_scale = Vec4::new(scale, volume.grid.min_spacing() / scale, 0.0, 0.0);
            r.bricked_dims = level0.extend(directory_level as u32);
            any = true;
        }
        if any {
            directory.push(v);
            growth = growth.max(1 << frame.coarse);
        }
    }
    if !directory.is_empty() {
        packed.features |= features::BRICKED;
        packed.max_steps = packed.max_steps.saturating_mul(growth);
        if packed.regions.iter().all(|r| r.bricked.x != 0) {
            packed.features |= features::BRICKED_ONLY;
        }
    }
    directory
}

/// The shader features of a scene of `features` this frame: `BRICKED_ONLY` holds only
/// while the atlas has every coarse brick of every bricked volume (before, samples fall
/// back to the coarse volume in the volume atlas).
pub fn pipeline_features(features: u32, coarse_in_atlas: bool) -> u32 {
    if coarse_in_atlas { features } else { features & !features::BRICKED_ONLY }
}
