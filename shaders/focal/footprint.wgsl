#define_import_path focal::footprint

// The pixel footprint of a ray, for the level a bricked region is stepped at
// (streaming::select chooses the bricks with the same footprint on the CPU): the world
// distance between this ray and its right and lower neighbours' at its depth (lenses
// included, so a magnifier's rays step finer), in the volume's own millimetres; level
// L = ⌊log₂(footprint / level-0 voxel)⌋ clamped to 0 … C, and the step 2^(L − C) of the
// coarse one. With VIEW_LENS_CONTEXT_STEPS the camera's footprint alone (the lens's
// finer bricks are still sampled, at the context's rate along the ray).

#import focal::types::{Region, VIEW_LENS_CONTEXT_STEPS}
#import focal::bindings::settings
#import focal::camera::Ray
#import focal::lens::{lens_ray, camera_ray, pixel_steps, Spread, spread_of, spread_extent}
#import focal::bricked::set_bricked_level

var<private> ray_spread: Spread;

fn prepare_ray_footprint(uv: vec2<f32>, ray: Ray) {
    // (The lens's footprint where both neighbours have lens rays, else the camera's:
    // the spread of the pixel's camera ray to its neighbours', measured along `ray`.)
    let steps = pixel_steps();
    let rx = lens_ray(uv + steps[0]);
    let ry = lens_ray(uv + steps[1]);
    let context_steps = (settings.flags & VIEW_LENS_CONTEXT_STEPS) != 0u;
    ray_spread = spread_of(ray, rx, ry);
    if context_steps || dot(rx.dir, rx.dir) == 0.0 || dot(ry.dir, ry.dir) == 0.0 {
        let plain = spread_of(camera_ray(uv), camera_ray(uv + steps[0]), camera_ray(uv + steps[1]));
        ray_spread = Spread(plain.px, plain.qx, plain.py, plain.qy, ray_spread.depth_start, ray_spread.depth_per_t);
    }
}

// The step factor 2^(L − C) of bricked region r for a ray along dir entering it at t.
fn bricked_step_at(r: Region, dir: vec3<f32>, t: f32) -> f32 {
    let depth = ray_spread.depth_start + ray_spread.depth_per_t * t;
    let native = spread_extent(ray_spread, depth) * length((r.to_native * vec4(dir, 0.0)).xyz);
    let c = f32(r.bricked.w);
    let l = clamp(floor(log2(max(native, 1e-30) / r.bricked_scale.y)), 0.0, c);
    return set_bricked_level(r, l);
}
