#define_import_path focal::bindings

#import bevy_render::view::View
#import focal::types::{Region, Settings, SceneInfo, MAX_UNIFORM_REGIONS, MAX_UNIFORM_PLANES, MAX_UNIFORM_OCCUPANCY}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> settings: Settings;
@group(0) @binding(2) var<uniform> scene: SceneInfo;
// The region records, the planes and the occupancy bits in uniform buffers where they
// fit (UNIFORM_REGIONS, UNIFORM_PLANES, UNIFORM_OCCUPANCY: render::upload::
// UniformCopies), else in storage: on llvmpipe a storage load runs lane by lane, with a
// branch per lane and word; a uniform load is one load at an index all lanes share, one
// gather at a per-lane index. Each is declared under one name in either address space,
// so no line that reads it changes (the occupancy words through occupancy_word).
#ifdef UNIFORM_REGIONS
@group(0) @binding(14) var<uniform> regions: array<Region, MAX_UNIFORM_REGIONS>;
#else
@group(0) @binding(3) var<storage, read> regions: array<Region>;
#endif
#ifdef UNIFORM_PLANES
@group(0) @binding(15) var<uniform> planes: array<vec4<f32>, MAX_UNIFORM_PLANES>;
#else
@group(0) @binding(4) var<storage, read> planes: array<vec4<f32>>;
#endif
#ifdef UNIFORM_OCCUPANCY
@group(0) @binding(16) var<uniform> occupancy: array<vec4<u32>, MAX_UNIFORM_OCCUPANCY / 4u>;
#else
@group(0) @binding(5) var<storage, read> occupancy: array<u32>;
#endif

// Word i of the occupancy bits (render::pack: Region.occupancy_offset and on).
fn occupancy_word(i: u32) -> u32 {
#ifdef UNIFORM_OCCUPANCY
    return occupancy[i >> 2u][i & 3u];
#else
    return occupancy[i];
#endif
}
// The lookup tables' texels as bits: f32 colours (sampling::lut_texel), or two looks'
// colours as 16-bit normalised pairs in a pair table (transfer::filtered_looks).
@group(0) @binding(6) var lut_atlas: texture_2d<u32>;
@group(0) @binding(7) var volume_atlas: texture_3d<f32>;
@group(0) @binding(8) var brick_atlas: texture_3d<u32>;
@group(0) @binding(9) var volume_sampler: sampler;
@group(0) @binding(10) var depth_texture: texture_depth_2d;
@group(0) @binding(11) var<storage, read> feature_fields: array<f32>;
// The brick atlas of bricked volumes and their page tables (render::bricked::atlas).
@group(0) @binding(12) var brick_cache: texture_3d<f32>;
@group(0) @binding(13) var<storage, read> pages: array<u32>;
