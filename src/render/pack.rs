//! Packing a [`RenderScene`] into the GPU layout: one [`GpuRegion`] per region, the
//! planes of all regions in one array, every lookup table in one RGBA atlas, the brick
//! occupancy bits of all regions in one word array, and the volumes in texture slots.
//!
//! Packing reuses the CPU reference's preparation ([`crate::reference::prepare`]), so
//! both renderers classify, step and shade with the same numbers. It decides nothing.

use glam::{Mat4, UVec4, Vec4};

use super::gpu_types::{GpuRegion, mode, region_flags};
use crate::reference::prepare::{PreparedLookup, PreparedRegion};
use crate::region::{Mode, RenderScene};

/// Volume texture slots of the ray-cast pass (WGSL cannot index textures dynamically
/// without binding arrays, which software Vulkan lacks).
pub const VOLUME_SLOTS: usize = 4;

/// Width of the lookup-table atlas in texels.
pub const LUT_ATLAS_WIDTH: u32 = 4096;

/// A scene in GPU layout.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PackedScene {
    pub regions: Vec<GpuRegion>,
    /// Plane `(normal, offset)` per entry; regions index ranges of it.
    pub planes: Vec<Vec4>,
    /// RGBA texels, `LUT_ATLAS_WIDTH` per row, rows stacked.
    pub lut: Vec<[f32; 4]>,
    /// Occupancy bits (bit `i % 32` of word `i / 32` is brick `i`).
    pub occupancy: Vec<u32>,
    /// Scene volume index held by each texture slot.
    pub slots: Vec<usize>,
    /// Regions left out, with the reason (more volumes than slots).
    pub dropped: Vec<String>,
}

impl PackedScene {
    /// Rows of the LUT atlas.
    pub fn lut_rows(&self) -> u32 {
        (self.lut.len() as u32).div_ceil(LUT_ATLAS_WIDTH).max(1)
    }
}

fn mode_number(m: Mode) -> u32 {
    match m {
        Mode::Dvr => mode::DVR,
        Mode::Mip => mode::MIP,
        Mode::MinIp => mode::MIN_IP,
        Mode::XRay => mode::X_RAY,
        Mode::GradientDvr => mode::GRADIENT_DVR,
        Mode::Iso => mode::ISO,
    }
}

/// Packs `scene`.
pub fn pack(scene: &RenderScene) -> Result<PackedScene, String> {
    let prepared = crate::reference::prepare(scene)?;
    let mut out = PackedScene::default();
    for p in &prepared {
        let slot = match out.slots.iter().position(|&v| v == p.region.volume) {
            Some(s) => s,
            None if out.slots.len() < VOLUME_SLOTS => {
                out.slots.push(p.region.volume);
                out.slots.len() - 1
            }
            None => {
                out.dropped.push(format!("region of '{}' left out: more than {VOLUME_SLOTS} volumes in one view", p.volume.name));
                continue;
            }
        };
        let region = pack_region(p, slot as u32, &mut out);
        out.regions.push(region);
    }
    if out.lut.is_empty() {
        out.lut.push([0.0; 4]);
    }
    let rows = out.lut_rows() as usize;
    out.lut.resize(rows * LUT_ATLAS_WIDTH as usize, [0.0; 4]);
    if out.occupancy.is_empty() {
        out.occupancy.push(0);
    }
    if out.planes.is_empty() {
        out.planes.push(Vec4::ZERO);
    }
    Ok(out)
}

fn pack_region(p: &PreparedRegion, slot: u32, out: &mut PackedScene) -> GpuRegion {
    let plane_offset = out.planes.len() as u32;
    out.planes.extend(p.region.planes.iter().map(|pl| pl.normal.extend(pl.offset)));
    let lut_offset = out.lut.len() as u32;
    let (lut_a, lut_b, lut_width, labels) = match &p.lookup {
        PreparedLookup::Transfer { lut, a, b } => {
            out.lut.extend_from_slice(&lut.rgba);
            (*a, *b, lut.rgba.len() as u32, false)
        }
        PreparedLookup::Labels(table) => {
            out.lut.extend_from_slice(table);
            (0.0, 0.0, table.len() as u32, true)
        }
    };
    let mut flags = 0;
    if labels {
        flags |= region_flags::LABELS;
    }
    if p.shading.enabled {
        flags |= region_flags::SHADING;
    }
    let occupancy_offset = out.occupancy.len() as u32;
    let mut bricks = UVec4::ZERO;
    if let Some((grid, occ)) = &p.occupancy {
        flags |= region_flags::OCCUPANCY;
        bricks = grid.dims.extend(grid.size);
        let mut words = vec![0u32; occ.len().div_ceil(32)];
        for (i, &o) in occ.iter().enumerate() {
            if o {
                words[i / 32] |= 1 << (i % 32);
            }
        }
        out.occupancy.extend(words);
    }
    let s = &p.shading;
    GpuRegion {
        world_to_voxel: Mat4::from(p.region.world_to_voxel),
        normal_matrix: Mat4::from_mat3(p.normal_matrix),
        to_native: Mat4::from_mat3(p.to_native),
        dims: p.volume.dims().as_vec3().extend(p.volume.code_max() as f32),
        shading: Vec4::new(s.ambient, s.diffuse, s.specular, s.shininess),
        bricks,
        plane_offset,
        plane_count: p.region.planes.len() as u32,
        slot,
        mode: mode_number(p.mode),
        flags,
        lut_offset,
        lut_width,
        occupancy_offset,
        lut_a,
        lut_b,
        native_step: p.native_step,
        reference_length: p.reference_length,
        iso: p.iso,
        gradient_max: p.gradient_max,
        pad_a: 0.0,
        pad_b: 0.0,
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::region::{Appearance, Plane, Region};
    use crate::transfer::presets;
    use crate::volume::phantom;

    #[test]
    fn packs_regions_planes_luts_and_slots() {
        let v = Arc::new(phantom::sphere(16, 5.0).unwrap());
        let tf = presets::builtin("grayscale_ramp").unwrap();
        let mut scene = RenderScene::single(v.clone(), Appearance::new(Mode::Mip, tf.clone()));
        scene.regions.push(Region::volume_box(&v.grid, 0, 0).clipped(Plane::through(glam::Vec3::ZERO, glam::Vec3::X)));
        let packed = pack(&scene).unwrap();
        assert_eq!(packed.regions.len(), 2);
        assert_eq!(packed.slots, vec![0]);
        assert_eq!((packed.regions[0].plane_offset, packed.regions[0].plane_count), (0, 6));
        assert_eq!((packed.regions[1].plane_offset, packed.regions[1].plane_count), (6, 7));
        assert_eq!(packed.regions[0].mode, mode::MIP);
        // 8-bit volume: a 256-texel table per region, both in the first atlas row.
        assert_eq!((packed.regions[1].lut_offset, packed.regions[1].lut_width), (256, 256));
        assert_eq!(packed.lut.len(), LUT_ATLAS_WIDTH as usize);
        assert_eq!(packed.regions[0].dims, glam::Vec4::new(16.0, 16.0, 16.0, 255.0));
    }

    #[test]
    fn more_volumes_than_slots_are_reported() {
        let tf = presets::builtin("grayscale_ramp").unwrap();
        let mut scene = RenderScene::default();
        scene.appearances.push(Appearance::new(Mode::Dvr, tf));
        for i in 0..(VOLUME_SLOTS + 1) {
            let v = Arc::new(phantom::sphere(8, 2.0).unwrap());
            scene.regions.push(Region::volume_box(&v.grid, i, 0));
            scene.volumes.push(v);
        }
        let packed = pack(&scene).unwrap();
        assert_eq!(packed.regions.len(), VOLUME_SLOTS);
        assert_eq!(packed.dropped.len(), 1);
        // DVR regions carry their occupancy bits.
        assert!(packed.regions.iter().all(|r| r.flags & region_flags::OCCUPANCY != 0));
        assert_eq!(packed.regions[1].occupancy_offset, 1);
    }
}
