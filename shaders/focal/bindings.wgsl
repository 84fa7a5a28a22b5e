#define_import_path focal::bindings

#import bevy_render::view::View
#import focal::types::{Region, Settings, SceneInfo, MAX_UNIFORM_REGIONS}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> settings: Settings;
@group(0) @binding(2) var<uniform> scene: SceneInfo;
#ifdef UNIFORM_REGIONS
// The region records in a uniform buffer where they fit (render::gpu_types::
// MAX_UNIFORM_REGIONS): on llvmpipe a storage load runs lane by lane, with a branch per
// lane and word; a uniform load is one load at an index all lanes share, one gather at
// a per-lane index.
@group(0) @binding(14) var<uniform> regions: array<Region, MAX_UNIFORM_REGIONS>;
#else
@group(0) @binding(3) var<storage, read> regions: array<Region>;
#endif
@group(0) @binding(4) var<storage, read> planes: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> occupancy: array<u32>;
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
