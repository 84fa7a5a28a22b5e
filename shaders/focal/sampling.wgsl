#define_import_path focal::sampling

// Sampling volumes in the atlas like the reference's Sampler: trilinear at clamped
// continuous voxel indices (the clamp keeps every filter tap inside the volume's own
// box of the atlas), central-difference gradients, nearest label codes, brick occupancy
// and min-max (reference: volume::sample, volume::bricks).

#import focal::types::{Region, REGION_LABELS, LUT_ATLAS_WIDTH}
#import focal::bindings::{scene, volume_atlas, brick_atlas, volume_sampler, occupancy_word, lut_atlas, brick_cache}
#import focal::bricked::{is_bricked, level_zero, bricked_locate, bricked_texel, bricked_uvw, bricked_box_exit, box_exit, bricked_step_factor, sub_block_visible, sub_block_exit, bricked_gradient, bricked_gradient_max, bc_kind, bc_code, BRICKED_TEXEL, BRICKED_EMPTY}

// The ray's samples taken (sample positions marched, not fetches) and page look-ups of
// bricked volumes, shown with VIEW_DEBUG_COUNTS (render::counts; one add each).
var<private> ray_samples: u32 = 0u;

fn count_sample() {
    ray_samples += 1u;
}

fn ray_sample_count() -> u32 {
    return ray_samples;
}

// Mip level the samples come from: set per sample under lenses with anti-aliasing
// (focal::lens::update_lod), 0 otherwise (reference: PreparedRegion::sample).
var<private> sample_lod: f32 = 0.0;

fn set_lod(lod: f32) {
    sample_lod = lod;
}

// Whether samples come from the volume itself (brick ranges and occupancy hold only
// then).
fn at_full_resolution() -> bool {
    return sample_lod <= 0.0;
}

// Trilinear sample of the atlas box at offset with dims, clamped to its edge voxels:
// every channel (the second holds a selection's degree of interest where
// render::pack::doi_channels put it there).
fn atlas_texel(offset: vec3<f32>, dims: vec3<f32>, q: vec3<f32>) -> vec4<f32> {
    let c = clamp(q, vec3(0.0), dims - 1.0);
    return textureSampleLevel(volume_atlas, volume_sampler, (offset + c + 0.5) * scene.inv_atlas_size.xyz, 0.0);
}

fn trilinear_box(offset: vec3<f32>, dims: vec3<f32>, q: vec3<f32>) -> f32 {
    return atlas_texel(offset, dims, q).r;
}

// Sample of mip level k (volume::pyramid: index (q + ½)/2^k − ½, size ⌈dims/2^k⌉; level
// 0 is the volume itself): the level's box is chosen by selects and fetched once.
fn level_sample(r: Region, q: vec3<f32>, k: u32) -> f32 {
    var offset = r.atlas_offset.xyz;
    if k == 1u {
        offset = r.mips[0].xyz;
    } else if k == 2u {
        offset = r.mips[1].xyz;
    } else if k >= 3u {
        offset = r.mips[2].xyz;
    }
    let s = exp2(f32(min(k, 3u)));
    return trilinear_box(offset, ceil(r.dims.xyz / s), (q + 0.5) / s - 0.5);
}

// Trilinear sample (normalised) at continuous voxel index q, clamped to the edge voxels;
// under lenses from the current mip level (two levels blended).
fn trilinear_memory(r: Region, q: vec3<f32>) -> f32 {
#ifdef LENS_ANTIALIAS
    // (A shader def, not the view's flag: llvmpipe runs an `if` in every lane whatever
    // the condition, and this code made every sample under a lens three times as
    // expensive without anti-aliasing. With it, two fetches per sample, the levels on
    // either side of the sample's, at full resolution the volume twice.)
    // (The second level under a branch of its own: where the level is a constant 0,
    // rays that compress nothing, the compiler drops it and the level's selects.)
    let l = clamp(sample_lod, 0.0, f32(r.mip_count));
    let k = u32(floor(l));
    var v = level_sample(r, q, k);
    let f = l - f32(k);
    if f > 0.0 {
        v = mix(v, level_sample(r, q, min(k + 1u, r.mip_count)), f);
    }
    return v;
#else
    return trilinear_box(r.atlas_offset.xyz, r.dims.xyz, q);
#endif
}

// Sample of a bricked region: the finest drawn brick holding q, an empty brick's lowest
// code (invisible under every look of the volume), else the coarse volume (never with
// BRICKED_ONLY: the coarse level's bricks are in the atlas).
fn bricked_sample(r: Region, q: vec3<f32>) -> f32 {
    return bricked_sample_at(r, q, false);
}

// bricked_sample where `located` (a literal) says the last page look-up's answer holds
// for q (q lies in the brick or sub-block it found: index_gradient_at).
fn bricked_sample_at(r: Region, q: vec3<f32>, located: bool) -> f32 {
    let q0 = level_zero(r, q);
    if !located {
        bricked_locate(r, q0);
    }
#ifdef BRICKED_ONLY
    return select(bc_code / r.dims.w, textureSampleLevel(brick_cache, volume_sampler, bricked_uvw(q0), 0.0).r, bc_kind == BRICKED_TEXEL);
#else
    if bc_kind == BRICKED_TEXEL {
        return textureSampleLevel(brick_cache, volume_sampler, bricked_uvw(q0), 0.0).r;
    }
    if bc_kind == BRICKED_EMPTY {
        return bc_code / r.dims.w;
    }
    return trilinear_box(r.atlas_offset.xyz, r.dims.xyz, q);
#endif
}

// Trilinear sample (normalised) at continuous voxel index q of the region's volume
// (bricked volumes through their page table). With BRICKED_ONLY every region is bricked
// and the volume atlas's path is left out: llvmpipe runs both sides of a branch, which
// made every sample of a bricked volume twice as dear as one in memory.
fn trilinear(r: Region, q: vec3<f32>) -> f32 {
    return trilinear_at(r, q, false);
}

// trilinear where `located` (a literal) says the last page look-up's answer holds for q
// (bricked_sample_at).
fn trilinear_at(r: Region, q: vec3<f32>, located: bool) -> f32 {
#ifdef BRICKED_ONLY
    return bricked_sample_at(r, q, located);
#else
#ifdef HAS_BRICKED
    if is_bricked(r) {
        return bricked_sample_at(r, q, located);
    }
#endif
    return trilinear_memory(r, q);
#endif
}

// The sample at q (x, as trilinear) and the degree of interest its volume carries in
// the second channel (y, the selection's normalised sample): one fetch; under lenses
// with anti-aliasing the value may come from the mip levels, and the degree of
// interest, which only the volume itself carries, from a fetch of its own.
fn trilinear_with_doi(r: Region, q: vec3<f32>) -> vec2<f32> {
#ifdef HAS_BRICKED
    if is_bricked(r) {
        return vec2(bricked_sample(r, q), atlas_texel(r.atlas_offset.xyz, r.dims.xyz, q).g);
    }
#endif
#ifdef LENS_ANTIALIAS
    return vec2(trilinear(r, q), atlas_texel(r.atlas_offset.xyz, r.dims.xyz, q).g);
#else
    return atlas_texel(r.atlas_offset.xyz, r.dims.xyz, q).rg;
#endif
}

// Code of the voxel nearest to q (label volumes).
fn nearest_code(r: Region, q: vec3<f32>) -> u32 {
#ifdef HAS_BRICKED
    if is_bricked(r) {
        let q0 = level_zero(r, q);
        bricked_locate(r, q0);
#ifdef BRICKED_ONLY
        let texel = u32(round(textureLoad(brick_cache, vec3<i32>(floor(bricked_texel(q0))), 0).r * r.dims.w));
        return select(u32(bc_code), texel, bc_kind == BRICKED_TEXEL);
#else
        if bc_kind == BRICKED_TEXEL {
            return u32(round(textureLoad(brick_cache, vec3<i32>(floor(bricked_texel(q0))), 0).r * r.dims.w));
        }
        if bc_kind == BRICKED_EMPTY {
            return u32(bc_code);
        }
#endif
    }
#endif
#ifdef BRICKED_ONLY
    return 0u;
#else
    let c = clamp(floor(q + 0.5), vec3(0.0), r.dims.xyz - 1.0);
    return u32(round(textureLoad(volume_atlas, vec3<i32>(r.atlas_offset.xyz + c), 0).r * r.dims.w));
#endif
}

// Texel `index` of the lookup-table atlas, rows of LUT_ATLAS_WIDTH: its bits, and the f32
// colour they hold in every table but a pair table.
fn lut_bits(index: u32) -> vec4<u32> {
    // (A constant width, a power of two: a mask and a shift. A uniform one made
    // llvmpipe divide lane by lane, twice a texel.)
    return textureLoad(lut_atlas, vec2<i32>(i32(index % LUT_ATLAS_WIDTH), i32(index / LUT_ATLAS_WIDTH)), 0);
}

fn lut_texel(index: u32) -> vec4<f32> {
    return bitcast<vec4<f32>>(lut_bits(index));
}

fn label_alpha(r: Region, q: vec3<f32>) -> f32 {
    let code = nearest_code(r, q);
    if code >= r.lut_width {
        return 0.0;
    }
    return lut_texel(r.lut_offset + code).a;
}

// Central-difference gradient in normalised units per voxel (index axes). Label
// volumes use the gradient of the label opacity field.
fn index_gradient(r: Region, q: vec3<f32>) -> vec3<f32> {
    return index_gradient_at(r, q, false);
}

// index_gradient where `located` (a literal at each call site) says the last page
// look-up was of q itself (the sample's own value was just fetched): a bricked region
// then takes its answer as it stands. (On llvmpipe a look-up is a dozen loads and a
// page walk, and a shaded DVR sample of a bricked volume made four at the same place.)
fn index_gradient_at(r: Region, q: vec3<f32>, located: bool) -> vec3<f32> {
    var g = vec3(0.0);
#ifdef HAS_LABELS
    if (r.flags & REGION_LABELS) != 0u {
        for (var a = 0; a < 3; a++) {
            var e = vec3(0.0);
            e[a] = 1.0;
            g[a] = label_alpha(r, q + e) - label_alpha(r, q - e);
        }
        return 0.5 * g;
    }
#endif
    // (A bricked region's differences span one voxel of the level its ray steps at.)
    var h = 1.0;
#ifdef HAS_BRICKED
    if is_bricked(r) {
        h = bricked_step_factor();
        let q0 = level_zero(r, q);
        if !located {
            bricked_locate(r, q0);
        }
#ifdef BRICKED_ONLY
        // (An empty brick's value is one code throughout.)
        return select(vec3(0.0), bricked_gradient(r, q0, h), bc_kind == BRICKED_TEXEL);
#else
        if bc_kind == BRICKED_TEXEL {
            return bricked_gradient(r, q0, h);
        }
#endif
    }
#endif
#ifdef BRICKED_ONLY
    return g;
#else
    for (var a = 0; a < 3; a++) {
        var e = vec3(0.0);
        e[a] = h;
        g[a] = trilinear(r, q + e) - trilinear(r, q - e);
    }
    return 0.5 * g;
#endif
}

// What r's gradient magnitudes are divided by: the volume's largest, or for a bricked
// region the largest of the level its ray steps at (set with the ray's level).
fn gradient_norm(r: Region) -> f32 {
#ifdef BRICKED_ONLY
    return bricked_gradient_max();
#else
#ifdef HAS_BRICKED
    return select(r.gradient_max, bricked_gradient_max(), is_bricked(r));
#else
    return r.gradient_max;
#endif
#endif
}

// The brick holding q (reference: BrickGrid::brick_at).
fn brick_of(r: Region, q: vec3<f32>) -> vec3<u32> {
    let size = f32(r.bricks.w);
    let b = max(floor((q + 0.5) / size), vec3(0.0));
    return min(vec3<u32>(b), r.bricks.xyz - 1u);
}

// Whether q's brick holds anything visible (a bricked region's: its sub-block), for
// samples of the current mip level.
fn brick_occupied(r: Region, q: vec3<f32>) -> bool {
#ifdef HAS_BRICKED
    if is_bricked(r) {
        let q0 = level_zero(r, q);
        bricked_locate(r, q0);
#ifdef BRICKED_ONLY
        return bc_kind == BRICKED_TEXEL && sub_block_visible(q0);
#else
        if bc_kind == BRICKED_EMPTY {
            return false;
        }
        if bc_kind == BRICKED_TEXEL {
            return sub_block_visible(q0);
        }
#endif
    }
#endif
#ifdef BRICKED_ONLY
    return false;
#else
    // (A sample from the mip chain blends in neighbouring voxels: the second set of
    // bits up to level 1, the third beyond, render::pack, Appearance::mip_brick_occupancy.)
    let b = brick_of(r, q);
    let i = (b.z * r.bricks.y + b.y) * r.bricks.x + b.x;
    let words = (r.bricks.x * r.bricks.y * r.bricks.z + 31u) / 32u;
    let bits = select(0u, 1u, sample_lod > 0.0) + select(0u, 1u, sample_lod > 1.0);
    let word = occupancy_word(r.occupancy_offset + bits * words + i / 32u);
    return ((word >> (i % 32u)) & 1u) != 0u;
#endif
}

// Ray parameter where the ray leaves q's brick (voxel-space direction qd per unit t);
// `located` (a literal) says the last page look-up was of q (index_gradient_at).
fn brick_exit_at(r: Region, q: vec3<f32>, qd: vec3<f32>, t: f32, located: bool) -> f32 {
#ifdef BRICKED_ONLY
    let q0 = level_zero(r, q);
    if !located {
        bricked_locate(r, q0);
    }
    let exit = bricked_box_exit(r, q, qd, t, 3.4e38);
    return select(exit, sub_block_exit(r, q0, q, qd, t, exit), bc_kind == BRICKED_TEXEL);
#else
    let b = vec3<f32>(brick_of(r, q));
    let size = f32(r.bricks.w);
    let lo = b * size - 0.5;
    let hi = (b + 1.0) * size - 0.5;
    let exit = box_exit(lo, hi, q, qd, t);
#ifdef HAS_BRICKED
    if is_bricked(r) {
        let q0 = level_zero(r, q);
        if !located {
            bricked_locate(r, q0);
        }
        if bc_kind == BRICKED_TEXEL {
            return sub_block_exit(r, q0, q, qd, t, bricked_box_exit(r, q, qd, t, 3.4e38));
        }
        return bricked_box_exit(r, q, qd, t, exit);
    }
#endif
    return exit;
#endif
}

// Code range of q's brick, normalised.
fn brick_range(r: Region, q: vec3<f32>) -> vec2<f32> {
    // (The coarse level's ranges do not bound its finer levels.)
#ifdef BRICKED_ONLY
    return vec2(0.0, 1.0);
#else
#ifdef HAS_BRICKED
    if is_bricked(r) {
        return vec2(0.0, 1.0);
    }
#endif
    let b = brick_of(r, q) + r.brick_offset.xyz;
    return vec2<f32>(textureLoad(brick_atlas, vec3<i32>(b), 0).rg) / r.dims.w;
#endif
}
