//! The GPU layout of a packed scene: what [`crate::render::pack::pack`] fills and the
//! upload sends.

use glam::{UVec3, Vec4};

use crate::render::gpu_types::GpuRegion;

/// Width of the lookup-table atlas in texels.
pub const LUT_ATLAS_WIDTH: u32 = 4096;

/// A scene in GPU layout.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PackedScene {
    pub regions: Vec<GpuRegion>,
    /// Plane `(normal, offset)` per entry; regions index ranges of it.
    pub planes: Vec<Vec4>,
    /// RGBA texels as bits, `LUT_ATLAS_WIDTH` per row, rows stacked: `f32` colours
    /// ([`texel`]), and the pair tables' 16-bit normalised pairs
    /// ([`crate::render::pack::pair_table`]).
    pub lut: Vec<[u32; 4]>,
    /// Occupancy bits (bit `i % 32` of word `i / 32` is brick `i`).
    pub occupancy: Vec<u32>,
    /// Scene volume indices placed in the atlases, in atlas order.
    pub volumes: Vec<usize>,
    /// The boxes of the volume atlas: each of `volumes`, followed by its mip levels
    /// when `mips`.
    pub atlas: Atlas,
    /// The atlas holds the mip chains too (it does when they fit).
    pub mips: bool,
    /// Atlas offsets of each of `volumes`: the volume, then its mip levels.
    pub levels: Vec<Vec<UVec3>>,
    /// Where each of `volumes`' brick grids lies in the brick atlas.
    pub brick_atlas: Atlas,
    /// Regions left out, with the reason (the atlas is full).
    pub dropped: Vec<String>,
    /// Per entry of `volumes`: the scene volume whose codes fill the second channel of
    /// its texels (a selection's degree of interest, [`crate::render::pack::doi_channels`]).
    pub doi_channels: Vec<Option<usize>>,
    /// Index in `regions` of every scene region (`None` for those dropped).
    pub region_slots: Vec<Option<u32>>,
    /// Regions the ray traverses: the first `region_count` of `regions` (the others
    /// are records: the regions drawn in others' samples ([`crate::render::pack::companions`]), the parts and
    /// labels of segmentations, the selections of weights).
    pub region_count: u32,
    /// The clip windows drawn in their hosts' samples ([`crate::render::pack::insets`]).
    pub insets: Vec<crate::render::gpu_types::GpuInset>,
    /// Shader features the regions need ([`crate::render::gpu_types::features`]).
    pub features: u32,
    /// Bound on the iterations of the ray caster's loops ([`crate::render::pack::march_bound`]).
    pub max_steps: u32,
}

/// Boxes placed in a 3D texture.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Atlas {
    pub size: UVec3,
    pub offsets: Vec<UVec3>,
}

/// Shelf packing: boxes stacked along z in columns, columns side by side along x, each
/// axis at most `max` texels. Returns `None` when they do not fit.
pub fn atlas_layout(sizes: &[UVec3], max: u32) -> Option<Atlas> {
    let mut offsets = Vec::with_capacity(sizes.len());
    let (mut column_x, mut column_w, mut z) = (0u32, 0u32, 0u32);
    let mut size = UVec3::ONE;
    for &b in sizes {
        if b.max_element() > max {
            return None;
        }
        if z + b.z > max {
            column_x += column_w;
            column_w = 0;
            z = 0;
        }
        if column_x + b.x > max {
            return None;
        }
        offsets.push(UVec3::new(column_x, 0, z));
        z += b.z;
        column_w = column_w.max(b.x);
        size = size.max(UVec3::new(column_x + b.x, b.y, z));
    }
    Some(Atlas { size, offsets })
}

impl PackedScene {
    /// Rows of the LUT atlas.
    pub fn lut_rows(&self) -> u32 {
        (self.lut.len() as u32).div_ceil(LUT_ATLAS_WIDTH).max(1)
    }
}

/// A lookup-atlas texel of an `f32` colour (its bits: the shader's `bitcast`).
pub fn texel(c: [f32; 4]) -> [u32; 4] {
    c.map(f32::to_bits)
}

/// The `f32` colour of a texel made by [`texel`].
pub fn texel_colour(t: [u32; 4]) -> [f32; 4] {
    t.map(f32::from_bits)
}

/// A plane as the shader reads it: `(n, d)`, `n·x − d` negative inside.
pub fn gpu_plane(pl: &crate::region::Plane) -> Vec4 {
    pl.normal.extend(pl.offset)
}
