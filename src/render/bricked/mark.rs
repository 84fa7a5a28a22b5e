//! Marks the packed regions of bricked volumes: every record whose volume is bricked
//! (the region itself, an exploded view's parts, a segmentation's parts) gets its place
//! in the page directory, brick layout, coarse level, level-0 dims and table directory
//! level, and the ray caster's bound on loop iterations grows by `2^C` (a ray under a
//! magnifier may step at level 0). Where every record is bricked the scene may take the
//! `BRICKED_ONLY` shader (once the atlas holds every coarse brick: [`pipeline_features`]).

use glam::{Mat4, UVec4, Vec3, Vec4};

use super::page_table::directory_level;
use crate::region::RenderScene;
use crate::render::gpu_types::{GpuRegion, features, mode, region_flags};
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
        let mut own_values = false;
        // A segmented region's labels on level 0's grid: each part's samples come from
        // its own label's level-0 voxels (`region_flags::ON_GRID`).
        let on_level0 = |r: &GpuRegion, labels: Option<&GpuRegion>| {
            let to_level0 =
                Mat4::from_translation(Vec3::splat(0.5 * (scale - 1.0))) * Mat4::from_scale(Vec3::splat(scale)) * r.world_to_voxel;
            labels.is_some_and(|l| l.dims.truncate() == level0.as_vec3() && l.world_to_voxel.abs_diff_eq(to_level0, 1e-3))
        };
        for i in 0..packed.regions.len() {
            let r = packed.regions[i];
            if r.atlas_offset.truncate() != offset || r.dims.truncate() != dims {
                continue;
            }
            let on_grid = r.mode == mode::TWO_LEVEL
                && r.flags & region_flags::OWN_VALUES != 0
                && on_level0(&r, packed.regions.get(r.objects.z as usize));
            let r = &mut packed.regions[i];
            r.bricked = UVec4::new(entry, frame.layout.size, frame.layout.apron, frame.coarse as u32);
            r.bricked_scale = Vec4::new(scale, volume.grid.min_spacing() / scale, 0.0, 0.0);
            r.bricked_dims = level0.extend(directory_level as u32);
            r.flags = if on_grid { r.flags | region_flags::ON_GRID } else { r.flags & !region_flags::ON_GRID };
            own_values |= on_grid;
            any = true;
        }
        if own_values {
            packed.features |= features::OWN_VALUES;
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
        if !packed.regions.iter().any(crate::render::pack::reads_mips) {
            packed.features &= !features::MIP_READS;
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
