#define_import_path focal::regions

// Convex regions: ray intervals, the world→voxel map, step lengths
// (reference: region::ray_convex, PreparedRegion::world_step).

#import focal::types::Region
#import focal::bindings::planes

// [t0, t1] of the ray inside the region's planes; t0 > t1 when it misses.
fn region_interval(r: Region, origin: vec3<f32>, dir: vec3<f32>) -> vec2<f32> {
    var t0 = -3.4e38;
    var t1 = 3.4e38;
    for (var i = 0u; i < r.plane_count; i++) {
        let p = planes[r.plane_offset + i];
        let denom = dot(p.xyz, dir);
        let dist = p.w - dot(p.xyz, origin);
        if abs(denom) < 1e-12 {
            if dist < 0.0 {
                return vec2(1.0, 0.0);
            }
            continue;
        }
        let t = dist / denom;
        if denom < 0.0 {
            t0 = max(t0, t);
        } else {
            t1 = min(t1, t);
        }
    }
    return vec2(t0, t1);
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
