#define_import_path focal::camera

// Ray generation from Bevy's view (reverse-Z, infinite far plane for perspective) and
// the per-pixel jitter hash (reference: reference::trace::jitter).

#import focal::bindings::view

struct Ray {
    origin: vec3<f32>,
    dir: vec3<f32>,
}

fn unproject(ndc: vec3<f32>) -> vec3<f32> {
    let p = view.world_from_clip * vec4(ndc, 1.0);
    return p.xyz / p.w;
}

// The ray through a pixel: from the near plane (depth 1) towards the far plane.
fn pixel_ray(uv: vec2<f32>) -> Ray {
    let ndc = vec2(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0);
    let near = unproject(vec3(ndc, 1.0));
    let far = unproject(vec3(ndc, 1e-4));
    return Ray(near, normalize(far - near));
}

fn is_perspective() -> bool {
    return view.clip_from_view[3][3] < 0.5;
}

// The camera's own ray through uv, from the eye for a perspective view (as the CPU
// camera, reference::Camera::ray), from the camera plane for an orthographic one.
// (The ray caster's rays: from the near plane a frame of the head took 12 % longer on
// llvmpipe, at the same samples.)
fn camera_ray(uv: vec2<f32>) -> Ray {
    let r = pixel_ray(uv);
    if is_perspective() {
        return Ray(view.world_position, r.dir);
    }
    return r;
}

// Ray parameter of the scene surface behind a pixel (infinity where there is none):
// where the ray reaches the surface's depth along the view axis, which also holds for
// rays bent by lenses.
fn scene_depth_t(ray: Ray, uv: vec2<f32>, depth: f32) -> f32 {
    if depth <= 0.0 {
        return 3.4e38;
    }
    let ndc = vec2(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0);
    let forward = -view.world_from_view[2].xyz;
    let along = dot(ray.dir, forward);
    if along <= 1e-6 {
        return 3.4e38;
    }
    return dot(unproject(vec3(ndc, depth)) - ray.origin, forward) / along;
}

// Deterministic jitter in [0, 1).
fn jitter(x: u32, y: u32, frame: u32) -> f32 {
    var h = (x * 1973u + y * 9277u + frame * 26699u) | 1u;
    h ^= h >> 16u;
    h *= 0x7feb352du;
    h ^= h >> 15u;
    h *= 0x846ca68bu;
    h ^= h >> 16u;
    return f32(h >> 8u) / 16777216.0;
}
