// The per-pixel function of Focal on the GPU: one ray through every region, front to
// back. It computes what src/reference/trace.rs computes (see that file for the
// algorithm) on the same sample positions t_k = t_start + (k + j)·Δ, organised for
// speed: the ray is cut into segments where the set of regions it is inside does not
// change; a segment inside one region runs a tight loop for that region's mode, a
// segment inside several regions composites them sample by sample. Differences from
// the reference: hardware trilinear weights, the scene depth that ends every ray at
// the first mesh, and jumps over empty bricks (landing on the same sample grid).
//
// Shader defs select the code a scene needs (software rasterisers execute every branch
// of divergent code, so unused modes cost time even when no pixel takes them):
// HAS_DVR (DVR, gradient-modulated DVR, labels), HAS_GRADIENT_MODULATION, HAS_LABELS,
// HAS_PROJECTION (MIP, MinIP, X-ray), HAS_ISO, HAS_SHADING and MULTI_REGION (more than
// one region, so segments where regions overlap).

#import bevy_core_pipeline::fullscreen_vertex_shader::FullscreenVertexOutput
#import focal::types::{Region, MODE_MIP, MODE_MIN_IP, MODE_X_RAY, MODE_GRADIENT_DVR, MODE_ISO, REGION_LABELS, REGION_SHADING, REGION_OCCUPANCY, VIEW_JITTER, VIEW_SKIP_EMPTY, VIEW_EARLY_TERMINATION, EARLY_TERMINATION, ISO_REFINEMENT, MAX_RAY_REGIONS}
#import focal::bindings::{settings, scene, regions, depth_texture}
#import focal::camera::{Ray, pixel_ray, scene_depth_t, jitter}
#import focal::regions::{region_interval, to_voxel, dir_to_voxel, world_step}
#import focal::sampling::{trilinear, nearest_code, index_gradient, brick_occupied, brick_exit, brick_range}
#import focal::transfer::{classify, classify_label, correct_opacity}
#import focal::shading::shade
#import focal::compositing::composite

const DONE: u32 = 1u;
const HAS_PREV: u32 = 2u;

fn is_projection(mode: u32) -> bool {
    return mode == MODE_MIP || mode == MODE_MIN_IP || mode == MODE_X_RAY;
}

// Shaded colour of a DVR or iso sample at q.
fn shaded(r: Region, c: vec3<f32>, q: vec3<f32>, dir: vec3<f32>) -> vec3<f32> {
#ifdef HAS_SHADING
    if (r.flags & REGION_SHADING) != 0u {
        let g = (r.normal_matrix * vec4(index_gradient(r, q, scene.lut_atlas_width), 0.0)).xyz;
        return shade(c, g, dir, settings.light, r.shading, true);
    }
#endif
    return c;
}

// One DVR (or label, or gradient-modulated) sample composited under acc.
fn dvr_sample(r: Region, q: vec3<f32>, ratio: f32, dir: vec3<f32>, acc: vec4<f32>) -> vec4<f32> {
    var rgba: vec4<f32>;
#ifdef HAS_LABELS
    if (r.flags & REGION_LABELS) != 0u {
        rgba = classify_label(r, nearest_code(r, q), scene.lut_atlas_width);
    } else {
        rgba = classify(r, trilinear(r, q), scene.lut_atlas_width);
    }
#else
    rgba = classify(r, trilinear(r, q), scene.lut_atlas_width);
#endif
    if rgba.a <= 0.0 {
        return acc;
    }
    var alpha = correct_opacity(rgba.a, ratio);
#ifdef HAS_GRADIENT_MODULATION
    if r.mode == MODE_GRADIENT_DVR && (r.flags & REGION_LABELS) == 0u {
        alpha *= min(length(index_gradient(r, q, scene.lut_atlas_width)) / r.gradient_max, 1.0);
    }
#endif
    return composite(acc, shaded(r, rgba.rgb, q, dir), alpha);
}

// The iso-surface between two samples, refined by bisection (reference: trace::refine).
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

fn iso_hit(r: Region, ray: Ray, tp: f32, vp: f32, t: f32, acc: vec4<f32>) -> vec4<f32> {
    let th = refine_iso(r, ray, tp, vp, t);
    let rgba = classify(r, r.iso, scene.lut_atlas_width);
    return composite(acc, shaded(r, rgba.rgb, to_voxel(r, ray.origin + ray.dir * th), ray.dir), 1.0);
}

fn projected(mode: u32, vmax: f32, vmin: f32, vsum: f32, count: u32) -> f32 {
    if mode == MODE_MIP {
        return vmax;
    }
    if mode == MODE_MIN_IP {
        return vmin;
    }
    return vsum / f32(count);
}

@fragment
fn fragment(in: FullscreenVertexOutput) -> @location(0) vec4<f32> {
    let ray = pixel_ray(in.uv);
    let pixel = vec2<u32>(in.position.xy);
    let t_scene = scene_depth_t(ray, in.uv, textureLoad(depth_texture, vec2<i32>(in.position.xy), 0));

    // 1. Intervals of the regions the ray crosses.
    var ids: array<u32, MAX_RAY_REGIONS>;
    var t0s: array<f32, MAX_RAY_REGIONS>;
    var t1s: array<f32, MAX_RAY_REGIONS>;
    var n = 0u;
    var t_start = 3.4e38;
    var t_end = -3.4e38;
    var step = 3.4e38;
    for (var i = 0u; i < scene.region_count && n < MAX_RAY_REGIONS; i++) {
        let iv = region_interval(regions[i], ray.origin, ray.dir);
        let t0 = max(iv.x, 0.0);
        if t0 < iv.y {
            ids[n] = i;
            t0s[n] = t0;
            t1s[n] = iv.y;
            t_start = min(t_start, t0);
            t_end = max(t_end, iv.y);
            step = min(step, world_step(regions[i], ray.dir));
            n++;
        }
    }
    if n == 0u {
        return vec4(0.0);
    }
    // Per-region state along the ray.
    var ratios: array<f32, MAX_RAY_REGIONS>;
    var vmax: array<f32, MAX_RAY_REGIONS>;
    var vmin: array<f32, MAX_RAY_REGIONS>;
    var vsum: array<f32, MAX_RAY_REGIONS>;
    var count: array<u32, MAX_RAY_REGIONS>;
    var prev_t: array<f32, MAX_RAY_REGIONS>;
    var prev_v: array<f32, MAX_RAY_REGIONS>;
    var state: array<u32, MAX_RAY_REGIONS>;
    for (var s = 0u; s < n; s++) {
        ratios[s] = regions[ids[s]].native_step * (step / world_step(regions[ids[s]], ray.dir)) / regions[ids[s]].reference_length;
        vmax[s] = -3.4e38;
        vmin[s] = 3.4e38;
        vsum[s] = 0.0;
        count[s] = 0u;
        state[s] = 0u;
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
    let t_last = min(t_end, t_scene);

    // 2.–4. Walk the segments.
    var acc = vec4(0.0);
    var k = 0.0;
    loop {
        let t = t_start + (k + j) * step;
        if t > t_last || acc.a >= stop {
            break;
        }
        // Regions left behind emit their projections; find the inside set and where it
        // changes next.
        var inside = 0u;
        var only = 0u;
        var seg_end = t_last;
        for (var s = 0u; s < n; s++) {
            if (state[s] & DONE) != 0u {
                continue;
            }
            if t > t1s[s] {
                let r = regions[ids[s]];
                if is_projection(r.mode) && count[s] > 0u {
                    let rgba = classify(r, projected(r.mode, vmax[s], vmin[s], vsum[s], count[s]), scene.lut_atlas_width);
                    acc = composite(acc, rgba.rgb, rgba.a);
                }
                state[s] |= DONE;
            } else if t >= t0s[s] {
                inside++;
                only = s;
                seg_end = min(seg_end, t1s[s]);
            } else {
                seg_end = min(seg_end, t0s[s]);
            }
        }
        if acc.a >= stop {
            break;
        }
        let k_end = max(floor((seg_end - t_start) / step - j), k);
        if inside == 0u {
            // A gap between regions: go to the first sample of the next one.
            k = max(k + 1.0, ceil((seg_end - t_start) / step - j));
            continue;
        }
        if inside == 1u {
            // One region: a tight loop over the samples of this segment.
            let s = only;
            let r = regions[ids[s]];
            let q0 = to_voxel(r, ray.origin + ray.dir * t);
            let qd = dir_to_voxel(r, ray.dir);
            let dq = qd * step;
            var kk = k;
#ifdef HAS_PROJECTION
            if is_projection(r.mode) {
                var mx = vmax[s];
                var mn = vmin[s];
                var sum = vsum[s];
                var c = count[s];
                loop {
                    if kk > k_end {
                        break;
                    }
                    let q = q0 + dq * (kk - k);
                    // Bricks that cannot change the running max (min) need no samples.
                    if skip && c > 0u && r.mode != MODE_X_RAY {
                        let range = brick_range(r, q);
                        if (r.mode == MODE_MIP && range.y <= mx) || (r.mode == MODE_MIN_IP && range.x >= mn) {
                            let tk = t_start + (kk + j) * step;
                            kk = max(kk + 1.0, ceil((brick_exit(r, q, qd, tk) - t_start) / step - j));
                            continue;
                        }
                    }
                    let v = trilinear(r, q);
                    mx = max(mx, v);
                    mn = min(mn, v);
                    sum += v;
                    c++;
                    kk += 1.0;
                }
                vmax[s] = mx;
                vmin[s] = mn;
                vsum[s] = sum;
                count[s] = c;
            } else
#endif
#ifdef HAS_ISO
            if r.mode == MODE_ISO && (r.flags & REGION_LABELS) == 0u {
                var has = (state[s] & HAS_PREV) != 0u;
                var tp = prev_t[s];
                var vp = prev_v[s];
                loop {
                    if kk > k_end {
                        break;
                    }
                    let tk = t_start + (kk + j) * step;
                    let v = trilinear(r, q0 + dq * (kk - k)) - r.iso;
                    if has && ((vp < 0.0) != (v < 0.0)) {
                        acc = iso_hit(r, ray, tp, vp, tk, acc);
                        state[s] |= DONE;
                        break;
                    }
                    has = true;
                    tp = tk;
                    vp = v;
                    kk += 1.0;
                }
                if has {
                    state[s] |= HAS_PREV;
                }
                prev_t[s] = tp;
                prev_v[s] = vp;
            } else
#endif
            {
#ifdef HAS_DVR
                // With skipping off this is plain marching: every sample is classified.
                let occupancy = skip && (r.flags & REGION_OCCUPANCY) != 0u;
                loop {
                    if kk > k_end || acc.a >= stop {
                        break;
                    }
                    let q = q0 + dq * (kk - k);
                    if occupancy && !brick_occupied(r, q) {
                        let tk = t_start + (kk + j) * step;
                        kk = max(kk + 1.0, ceil((brick_exit(r, q, qd, tk) - t_start) / step - j));
                        continue;
                    }
                    acc = dvr_sample(r, q, ratios[s], ray.dir, acc);
                    kk += 1.0;
                }
#endif
            }
            k = k_end + 1.0;
            continue;
        }
#ifdef MULTI_REGION
        // Several regions overlap here: all of them at this one sample, in region order.
        let p = ray.origin + ray.dir * t;
        for (var s = 0u; s < n; s++) {
            if (state[s] & DONE) != 0u || t < t0s[s] || t > t1s[s] {
                continue;
            }
            let r = regions[ids[s]];
            let q = to_voxel(r, p);
#ifdef HAS_PROJECTION
            if is_projection(r.mode) {
                let v = trilinear(r, q);
                vmax[s] = max(vmax[s], v);
                vmin[s] = min(vmin[s], v);
                vsum[s] += v;
                count[s]++;
                continue;
            }
#endif
#ifdef HAS_ISO
            if r.mode == MODE_ISO && (r.flags & REGION_LABELS) == 0u {
                let v = trilinear(r, q) - r.iso;
                if (state[s] & HAS_PREV) != 0u && ((prev_v[s] < 0.0) != (v < 0.0)) {
                    acc = iso_hit(r, ray, prev_t[s], prev_v[s], t, acc);
                    state[s] |= DONE;
                } else {
                    prev_t[s] = t;
                    prev_v[s] = v;
                    state[s] |= HAS_PREV;
                }
                continue;
            }
#endif
#ifdef HAS_DVR
            if !skip || (r.flags & REGION_OCCUPANCY) == 0u || brick_occupied(r, q) {
                acc = dvr_sample(r, q, ratios[s], ray.dir, acc);
            }
#endif
        }
#endif
        k += 1.0;
    }
    // Projections still open at the end of the march.
    for (var s = 0u; s < n; s++) {
        let r = regions[ids[s]];
        if (state[s] & DONE) == 0u && is_projection(r.mode) && count[s] > 0u && acc.a < stop {
            let rgba = classify(r, projected(r.mode, vmax[s], vmin[s], vsum[s], count[s]), scene.lut_atlas_width);
            acc = composite(acc, rgba.rgb, rgba.a);
        }
    }
    return acc;
}
