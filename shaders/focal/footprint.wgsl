#define_import_path focal::footprint

// The pixel footprint of a ray, for the level a bricked region is stepped at
// (streaming::select chooses the bricks with the same footprint on the CPU): the world
// distance between this ray and its right and lower neighbours' at its depth (lenses
// included, so a magnifier's rays step finer), in the volume's own millimetres; level
// L = ⌊log₂(footprint / level-0 voxel)⌋ clamped to 0 … C, and the step 2^(L − C) of the
// coarse one; the ray reads no level finer than L (render::bricked::page_table). With
// VIEW_LENS_CONTEXT_STEPS the step comes from the camera's footprint alone while the
// finest level read is still the lens's (its finer bricks are sampled at the context's
// rate along the ray).

#import focal::types::{Region, VIEW_LENS_CONTEXT_STEPS}
#import focal::bindings::settings
#import focal::camera::Ray
#import focal::camera::camera_ray
#import focal::lens::{lens_ray, pixel_steps, Spread, spread_of, spread_extent}
#import focal::bricked::set_bricked_level

var<private> ray_spread: Spread;
// The spread of the ray's own footprint (lenses included), for the finest level read.
var<private> read_spread: Spread;

fn prepare_ray_footprint(uv: vec2<f32>, ray: Ray) {
    // (The lens's footprint where both neighbours have lens rays, else the camera's:
    // the spread of the pixel's camera ray to its neighbours', measured along `ray`.)
    let steps = pixel_steps();
    let rx = lens_ray(uv + steps[0]);
    let ry = lens_ray(uv + steps[1]);
    let context_steps = (settings.flags & VIEW_LENS_CONTEXT_STEPS) != 0u;
    ray_spread = spread_of(ray, rx, ry);
    read_spread = ray_spread;
    let no_neighbours = dot(rx.dir, rx.dir) == 0.0 || dot(ry.dir, ry.dir) == 0.0;
    if context_steps || no_neighbours {
        let plain = spread_of(camera_ray(uv), camera_ray(uv + steps[0]), camera_ray(uv + steps[1]));
        ray_spread = Spread(plain.px, plain.qx, plain.py, plain.qy, ray_spread.depth_start, ray_spread.depth_per_t);
    }
    if no_neighbours {
        read_spread = ray_spread;
    }
}

// The step factor 2^(L − C) of bricked region r for a ray along dir entering it at t.
fn bricked_step_at(r: Region, dir: vec3<f32>, t: f32) -> f32 {
    let to_native = length((r.to_native * vec4(dir, 0.0)).xyz);
    let l = spread_level(r, ray_spread, to_native, t);
    // (With context steps the lens's own level where it magnifies, the context's where
    // it compresses: its border is then drawn as the context is, and skips empty space
    // at the context's granularity; its coarser level there took a third more samples.)
    let cap = spread_level(r, read_spread, to_native, t);
    return set_bricked_level(r, l, min(cap, l));
}

// The level ⌊log₂(footprint / level-0 voxel)⌋ (0 … C) of a footprint's spread at ray
// parameter t (to_native: native millimetres per unit t).
fn spread_level(r: Region, spread: Spread, to_native: f32, t: f32) -> f32 {
    let depth = spread.depth_start + spread.depth_per_t * t;
    let native = spread_extent(spread, depth) * to_native;
    return clamp(floor(log2(max(native, 1e-30) / r.bricked_scale.y)), 0.0, f32(r.bricked.w));
}
