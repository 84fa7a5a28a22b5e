#define_import_path focal::sampling

// Sampling the volume slots like the reference's Sampler: trilinear at clamped
// continuous voxel indices, central-difference gradients, nearest label codes, brick
// occupancy and min-max (reference: volume::sample, volume::bricks).

#import focal::types::{Region, REGION_LABELS}
#import focal::bindings::{volume_a, volume_b, volume_c, volume_d, minmax_a, minmax_b, minmax_c, minmax_d, volume_sampler, occupancy, lut_atlas}

fn sample_slot(slot: u32, uvw: vec3<f32>) -> f32 {
    switch slot {
        case 0u: { return textureSampleLevel(volume_a, volume_sampler, uvw, 0.0).r; }
        case 1u: { return textureSampleLevel(volume_b, volume_sampler, uvw, 0.0).r; }
        case 2u: { return textureSampleLevel(volume_c, volume_sampler, uvw, 0.0).r; }
        default: { return textureSampleLevel(volume_d, volume_sampler, uvw, 0.0).r; }
    }
}

fn slot_texture_dims(slot: u32) -> vec3<f32> {
    switch slot {
        case 0u: { return vec3<f32>(textureDimensions(volume_a)); }
        case 1u: { return vec3<f32>(textureDimensions(volume_b)); }
        case 2u: { return vec3<f32>(textureDimensions(volume_c)); }
        default: { return vec3<f32>(textureDimensions(volume_d)); }
    }
}

fn load_slot(slot: u32, texel: vec3<i32>) -> f32 {
    switch slot {
        case 0u: { return textureLoad(volume_a, texel, 0).r; }
        case 1u: { return textureLoad(volume_b, texel, 0).r; }
        case 2u: { return textureLoad(volume_c, texel, 0).r; }
        default: { return textureLoad(volume_d, texel, 0).r; }
    }
}

fn minmax_slot(slot: u32, brick: vec3<i32>) -> vec2<u32> {
    switch slot {
        case 0u: { return textureLoad(minmax_a, brick, 0).rg; }
        case 1u: { return textureLoad(minmax_b, brick, 0).rg; }
        case 2u: { return textureLoad(minmax_c, brick, 0).rg; }
        default: { return textureLoad(minmax_d, brick, 0).rg; }
    }
}

// Trilinear sample (normalised) at continuous voxel index q, clamped to the edge voxels.
fn trilinear(r: Region, q: vec3<f32>) -> f32 {
    let dims = r.dims.xyz;
    let c = clamp(q, vec3(0.0), dims - 1.0);
    return sample_slot(r.slot, (c + 0.5) / dims);
}

// Code of the voxel nearest to q (label volumes); works on downsampled textures too.
fn nearest_code(r: Region, q: vec3<f32>) -> u32 {
    let dims = r.dims.xyz;
    let tex = slot_texture_dims(r.slot);
    let c = clamp(floor(q + 0.5), vec3(0.0), dims - 1.0);
    let texel = clamp(floor((c + 0.5) / dims * tex), vec3(0.0), tex - 1.0);
    return u32(round(load_slot(r.slot, vec3<i32>(texel)) * r.dims.w));
}

fn lut_texel(index: u32, atlas_width: u32) -> vec4<f32> {
    return textureLoad(lut_atlas, vec2<i32>(i32(index % atlas_width), i32(index / atlas_width)), 0);
}

// Central-difference gradient in normalised units per voxel (index axes). Label
// volumes use the gradient of the label opacity field.
fn index_gradient(r: Region, q: vec3<f32>, atlas_width: u32) -> vec3<f32> {
    if (r.flags & REGION_LABELS) != 0u {
        let ex = vec3(1.0, 0.0, 0.0);
        let ey = vec3(0.0, 1.0, 0.0);
        let ez = vec3(0.0, 0.0, 1.0);
        return 0.5 * vec3(
            label_alpha(r, q + ex, atlas_width) - label_alpha(r, q - ex, atlas_width),
            label_alpha(r, q + ey, atlas_width) - label_alpha(r, q - ey, atlas_width),
            label_alpha(r, q + ez, atlas_width) - label_alpha(r, q - ez, atlas_width),
        );
    }
    let dx = trilinear(r, q + vec3(1.0, 0.0, 0.0)) - trilinear(r, q - vec3(1.0, 0.0, 0.0));
    let dy = trilinear(r, q + vec3(0.0, 1.0, 0.0)) - trilinear(r, q - vec3(0.0, 1.0, 0.0));
    let dz = trilinear(r, q + vec3(0.0, 0.0, 1.0)) - trilinear(r, q - vec3(0.0, 0.0, 1.0));
    return 0.5 * vec3(dx, dy, dz);
}

fn label_alpha(r: Region, q: vec3<f32>, atlas_width: u32) -> f32 {
    let code = nearest_code(r, q);
    if code >= r.lut_width {
        return 0.0;
    }
    return lut_texel(r.lut_offset + code, atlas_width).a;
}

// The brick holding q (reference: BrickGrid::brick_at).
fn brick_of(r: Region, q: vec3<f32>) -> vec3<u32> {
    let size = f32(r.bricks.w);
    let b = max(floor((q + 0.5) / size), vec3(0.0));
    return min(vec3<u32>(b), r.bricks.xyz - 1u);
}

fn brick_occupied(r: Region, q: vec3<f32>) -> bool {
    let b = brick_of(r, q);
    let i = (b.z * r.bricks.y + b.y) * r.bricks.x + b.x;
    let word = occupancy[r.occupancy_offset + i / 32u];
    return ((word >> (i % 32u)) & 1u) != 0u;
}

// Ray parameter where the ray leaves q's brick (voxel-space direction qd per unit t).
fn brick_exit(r: Region, q: vec3<f32>, qd: vec3<f32>, t: f32) -> f32 {
    let b = vec3<f32>(brick_of(r, q));
    let size = f32(r.bricks.w);
    let lo = b * size - 0.5;
    let hi = (b + 1.0) * size - 0.5;
    var exit = 3.4e38;
    for (var a = 0; a < 3; a++) {
        if qd[a] > 1e-12 {
            exit = min(exit, (hi[a] - q[a]) / qd[a]);
        } else if qd[a] < -1e-12 {
            exit = min(exit, (lo[a] - q[a]) / qd[a]);
        }
    }
    return t + max(exit, 0.0);
}

// Largest normalised value in q's brick (for MIP skipping).
fn brick_max(r: Region, q: vec3<f32>) -> f32 {
    let b = brick_of(r, q);
    return f32(minmax_slot(r.slot, vec3<i32>(b)).y) / r.dims.w;
}

fn brick_min(r: Region, q: vec3<f32>) -> f32 {
    let b = brick_of(r, q);
    return f32(minmax_slot(r.slot, vec3<i32>(b)).x) / r.dims.w;
}
