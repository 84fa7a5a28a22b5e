// The per-pixel function of Focal on the GPU: one ray through every region, front to
// back. It mirrors src/reference/trace.rs step by step; see that file for the algorithm.
// Differences: texture filtering (hardware trilinear weights), the scene depth that
// ends every ray at the first mesh, and brick skipping by jumps that land on the same
// sample positions as the reference.

#import bevy_core_pipeline::fullscreen_vertex_shader::FullscreenVertexOutput
#import focal::types::{Region, MODE_DVR, MODE_MIP, MODE_MIN_IP, MODE_X_RAY, MODE_GRADIENT_DVR, MODE_ISO, REGION_LABELS, REGION_SHADING, REGION_OCCUPANCY, VIEW_JITTER, VIEW_SKIP_EMPTY, VIEW_EARLY_TERMINATION, EARLY_TERMINATION, ISO_REFINEMENT, MAX_RAY_REGIONS}
#import focal::bindings::{settings, scene, regions, depth_texture}
#import focal::camera::{Ray, pixel_ray, scene_depth_t, jitter}
#import focal::regions::{region_interval, to_voxel, dir_to_voxel, world_step}
#import focal::sampling::{trilinear, nearest_code, index_gradient, brick_occupied, brick_exit, brick_max, brick_min}
#import focal::transfer::{classify, classify_label, correct_opacity}
#import focal::shading::shade
#import focal::compositing::composite

// Per-region state along the ray.
struct State {
    index: u32,
    t0: f32,
    t1: f32,
    max_v: f32,
    min_v: f32,
    sum: f32,
    count: u32,
    prev_t: f32,
    prev_v: f32,
    has_prev: bool,
    done: bool,
    ratio: f32,
}

fn is_projection(mode: u32) -> bool {
    return mode == MODE_MIP || mode == MODE_MIN_IP || mode == MODE_X_RAY;
}

fn projected(mode: u32, s: State) -> f32 {
    if mode == MODE_MIP {
        return s.max_v;
    }
    if mode == MODE_MIN_IP {
        return s.min_v;
    }
    return s.sum / f32(s.count);
}

fn region_rgba(r: Region, t: f32, q: vec3<f32>) -> vec4<f32> {
    if (r.flags & REGION_LABELS) != 0u {
        return classify_label(r, nearest_code(r, q), scene.lut_atlas_width);
    }
    return classify(r, t, scene.lut_atlas_width);
}

fn refine_iso(r: Region, ray: Ray, ta_in: f32, va: f32, tb_in: f32) -> f32 {
    var ta = ta_in;
    var tb = tb_in;
    let below = va < 0.0;
    for (var i = 0u; i < ISO_REFINEMENT; i++) {
        let tm = 0.5 * (ta + tb);
        let v = trilinear(r, to_voxel(r, ray.origin + ray.dir * tm)) - r.iso;
        if (v < 0.0) == below {
            ta = tm;
        } else {
            tb = tm;
        }
    }
    return 0.5 * (ta + tb);
}

@fragment
fn fragment(in: FullscreenVertexOutput) -> @location(0) vec4<f32> {
    let ray = pixel_ray(in.uv);
    let pixel = vec2<u32>(in.position.xy);
    let depth = textureLoad(depth_texture, vec2<i32>(in.position.xy), 0);
    let t_scene = scene_depth_t(ray, in.uv, depth);

    // 1. Intervals.
    var states: array<State, MAX_RAY_REGIONS>;
    var n = 0u;
    var t_start = 3.4e38;
    var t_end = -3.4e38;
    var step = 3.4e38;
    for (var i = 0u; i < scene.region_count && n < MAX_RAY_REGIONS; i++) {
        let r = regions[i];
        let iv = region_interval(r, ray.origin, ray.dir);
        let t0 = max(iv.x, 0.0);
        let t1 = iv.y;
        if t0 < t1 {
            t_start = min(t_start, t0);
            t_end = max(t_end, t1);
            step = min(step, world_step(r, ray.dir));
            states[n] = State(i, t0, t1, -3.4e38, 3.4e38, 0.0, 0u, 0.0, 0.0, false, false, 0.0);
            n++;
        }
    }
    if n == 0u {
        return vec4(0.0);
    }
    for (var s = 0u; s < n; s++) {
        let r = regions[states[s].index];
        states[s].ratio = r.native_step * (step / world_step(r, ray.dir)) / r.reference_length;
    }
    var j = 0.5;
    if (settings.flags & VIEW_JITTER) != 0u {
        j = jitter(pixel.x, pixel.y, settings.frame);
    }
    let skip = (settings.flags & VIEW_SKIP_EMPTY) != 0u;
    var stop = 2.0;
    if (settings.flags & VIEW_EARLY_TERMINATION) != 0u {
        stop = EARLY_TERMINATION;
    }

    // 2.–4. March.
    var acc = vec4(0.0);
    var k = 0.0;
    loop {
        let t = t_start + (k + j) * step;
        if t > t_end || t > t_scene {
            break;
        }
        let p = ray.origin + ray.dir * t;
        // Where the next sample may jump to when every active region can skip ahead.
        var next_t = 3.4e38;
        var all_skip = skip;
        for (var s = 0u; s < n; s++) {
            if states[s].done {
                continue;
            }
            let r = regions[states[s].index];
            if t > states[s].t1 {
                if is_projection(r.mode) && states[s].count > 0u {
                    let v = projected(r.mode, states[s]);
                    let rgba = classify(r, v, scene.lut_atlas_width);
                    acc = composite(acc, rgba.rgb, rgba.a);
                }
                states[s].done = true;
                continue;
            }
            if t < states[s].t0 {
                next_t = min(next_t, states[s].t0);
                continue;
            }
            let q = to_voxel(r, p);
            let labels = (r.flags & REGION_LABELS) != 0u;
            if is_projection(r.mode) && !labels {
                // Bricks that cannot change the running max (min) need no samples.
                if skip && states[s].count > 0u && r.bricks.w > 0u
                    && ((r.mode == MODE_MIP && brick_max(r, q) <= states[s].max_v)
                        || (r.mode == MODE_MIN_IP && brick_min(r, q) >= states[s].min_v)) {
                    next_t = min(next_t, brick_exit(r, q, dir_to_voxel(r, ray.dir), t));
                    continue;
                }
                all_skip = false;
                let v = trilinear(r, q);
                states[s].max_v = max(states[s].max_v, v);
                states[s].min_v = min(states[s].min_v, v);
                states[s].sum += v;
                states[s].count += 1u;
            } else if r.mode == MODE_ISO && !labels {
                all_skip = false;
                let v = trilinear(r, q) - r.iso;
                if states[s].has_prev && ((states[s].prev_v < 0.0) != (v < 0.0)) {
                    let th = refine_iso(r, ray, states[s].prev_t, states[s].prev_v, t);
                    let qh = to_voxel(r, ray.origin + ray.dir * th);
                    let rgba = classify(r, r.iso, scene.lut_atlas_width);
                    let g = (r.normal_matrix * vec4(index_gradient(r, qh, scene.lut_atlas_width), 0.0)).xyz;
                    let c = shade(rgba.rgb, g, ray.dir, settings.light, r.shading, (r.flags & REGION_SHADING) != 0u);
                    acc = composite(acc, c, 1.0);
                    states[s].done = true;
                } else {
                    states[s].prev_t = t;
                    states[s].prev_v = v;
                    states[s].has_prev = true;
                }
            } else {
                // DVR, gradient-modulated DVR and label volumes.
                if (r.flags & REGION_OCCUPANCY) != 0u && !brick_occupied(r, q) {
                    if skip {
                        next_t = min(next_t, brick_exit(r, q, dir_to_voxel(r, ray.dir), t));
                    }
                    continue;
                }
                all_skip = false;
                let v = trilinear(r, q);
                let rgba = region_rgba(r, v, q);
                if rgba.a <= 0.0 {
                    continue;
                }
                var alpha = correct_opacity(rgba.a, states[s].ratio);
                let gi = index_gradient(r, q, scene.lut_atlas_width);
                if r.mode == MODE_GRADIENT_DVR && !labels {
                    alpha *= min(length(gi) / r.gradient_max, 1.0);
                }
                let g = (r.normal_matrix * vec4(gi, 0.0)).xyz;
                let c = shade(rgba.rgb, g, ray.dir, settings.light, r.shading, (r.flags & REGION_SHADING) != 0u);
                acc = composite(acc, c, alpha);
            }
        }
        if acc.a >= stop {
            break;
        }
        // Jump to the first sample position at or after next_t (the reference's grid).
        var k_next = k + 1.0;
        if all_skip && next_t < 3.0e38 {
            k_next = max(k_next, ceil((next_t - t_start) / step - j));
        }
        k = k_next;
    }
    // Projections still open at the end of the march.
    for (var s = 0u; s < n; s++) {
        let r = regions[states[s].index];
        if !states[s].done && is_projection(r.mode) && (r.flags & REGION_LABELS) == 0u && states[s].count > 0u && acc.a < stop {
            let rgba = classify(r, projected(r.mode, states[s]), scene.lut_atlas_width);
            acc = composite(acc, rgba.rgb, rgba.a);
        }
    }
    return acc;
}
