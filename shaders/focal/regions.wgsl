#define_import_path focal::regions

// Convex regions: ray intervals, the world→voxel map, step lengths
// (reference: region::ray_convex, PreparedRegion::world_step).

#import focal::types::Region
#import focal::bindings::planes

// [t0, t1] of the ray inside the region's planes; t0 > t1 when it misses.
fn region_interval(r: Region, origin: vec3<f32>, dir: vec3<f32>) -> vec2<f32> {
    return convex_interval(r.plane_offset, r.plane_count, origin, dir);
}

// [t0, t1] of the ray inside hole h of the region (a box); t0 > t1 when it misses.
fn hole_interval(r: Region, h: u32, origin: vec3<f32>, dir: vec3<f32>) -> vec2<f32> {
    return convex_interval(r.hole_offset + 6u * h, 6u, origin, dir);
}

// Whether world point p lies inside one of the region's holes (off its boundary).
fn in_hole(r: Region, p: vec3<f32>) -> bool {
    for (var h = 0u; h < r.hole_count; h++) {
        var inside = true;
        for (var i = 0u; i < 6u; i++) {
            let pl = planes[r.hole_offset + 6u * h + i];
            inside = inside && dot(pl.xyz, p) - pl.w < -1e-5;
        }
        if inside {
            return true;
        }
    }
    return false;
}

// [t0, t1] of the ray inside the `count` half-spaces from planes[offset] (reference:
// region::ray_convex).
fn convex_interval(offset: u32, count: u32, origin: vec3<f32>, dir: vec3<f32>) -> vec2<f32> {
    var iv = vec2(-3.4e38, 3.4e38);
    // (No early return: a loop all lanes run alike keeps its loads uniform.)
    for (var i = 0u; i < count; i++) {
        iv = cut_by_plane(iv, planes[offset + i], origin, dir);
    }
    return iv;
}

// The ray's interval iv less the part outside half-space p (n·x − d ≤ 0: p = (n, d)).
fn cut_by_plane(iv: vec2<f32>, p: vec4<f32>, origin: vec3<f32>, dir: vec3<f32>) -> vec2<f32> {
    let denom = dot(p.xyz, dir);
    let dist = p.w - dot(p.xyz, origin);
    if abs(denom) < 1e-12 {
        return select(iv, vec2(3.4e38, iv.y), dist < 0.0);
    }
    let t = dist / denom;
    return select(vec2(iv.x, min(iv.y, t)), vec2(max(iv.x, t), iv.y), denom < 0.0);
}

// Whether the line origin + t·dir comes within the sphere (centre, radius).
fn meets_sphere(sphere: vec4<f32>, origin: vec3<f32>, dir: vec3<f32>) -> bool {
    let c = sphere.xyz - origin;
    let along = dot(c, dir) / max(dot(dir, dir), 1e-30);
    let off = c - dir * along;
    return dot(off, off) <= sphere.w * sphere.w;
}

fn to_voxel(r: Region, p: vec3<f32>) -> vec3<f32> {
    return (r.world_to_voxel * vec4(p, 1.0)).xyz;
}

fn dir_to_voxel(r: Region, d: vec3<f32>) -> vec3<f32> {
    return (r.world_to_voxel * vec4(d, 0.0)).xyz;
}

// World step that advances the region's native step in its volume along `dir`.
fn world_step(r: Region, dir: vec3<f32>) -> f32 {
    return r.native_step / max(length((r.to_native * vec4(dir, 0.0)).xyz), 1e-9);
}

fn pick_region(a: Region, b: Region, second: bool) -> Region {
    var r: Region;
    for (var c = 0; c < 4; c++) {
        r.world_to_voxel[c] = select(a.world_to_voxel[c], b.world_to_voxel[c], second);
        r.normal_matrix[c] = select(a.normal_matrix[c], b.normal_matrix[c], second);
        r.to_native[c] = select(a.to_native[c], b.to_native[c], second);
    }
    r.dims = select(a.dims, b.dims, second);
    r.shading = select(a.shading, b.shading, second);
    r.bricks = select(a.bricks, b.bricks, second);
    r.atlas_offset = select(a.atlas_offset, b.atlas_offset, second);
    r.brick_offset = select(a.brick_offset, b.brick_offset, second);
    r.plane_offset = select(a.plane_offset, b.plane_offset, second);
    r.plane_count = select(a.plane_count, b.plane_count, second);
    r.hole_offset = select(a.hole_offset, b.hole_offset, second);
    r.hole_count = select(a.hole_count, b.hole_count, second);
    r.mode = select(a.mode, b.mode, second);
    r.flags = select(a.flags, b.flags, second);
    r.lut_offset = select(a.lut_offset, b.lut_offset, second);
    r.lut_width = select(a.lut_width, b.lut_width, second);
    r.occupancy_offset = select(a.occupancy_offset, b.occupancy_offset, second);
    r.lut_a = select(a.lut_a, b.lut_a, second);
    r.lut_b = select(a.lut_b, b.lut_b, second);
    r.native_step = select(a.native_step, b.native_step, second);
    r.reference_length = select(a.reference_length, b.reference_length, second);
    r.iso = select(a.iso, b.iso, second);
    r.gradient_max = select(a.gradient_max, b.gradient_max, second);
    r.mip_count = select(a.mip_count, b.mip_count, second);
    r.value_lo = select(a.value_lo, b.value_lo, second);
    r.value_hi = select(a.value_hi, b.value_hi, second);
    for (var m = 0; m < 3; m++) {
        r.mips[m] = select(a.mips[m], b.mips[m], second);
    }
    r.context = select(a.context, b.context, second);
    r.sphere = select(a.sphere, b.sphere, second);
    r.bounds = select(a.bounds, b.bounds, second);
    r.objects = select(a.objects, b.objects, second);
    r.projection = select(a.projection, b.projection, second);
    return r;
}
