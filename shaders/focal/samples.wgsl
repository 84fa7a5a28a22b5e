#define_import_path focal::samples

// One sample of a region along the ray, by mode (reference: src/reference/trace.rs):
// DVR (labels, gradient-modulated and context-preserving DVR included, weighted by a
// selection in exploded views), the iso-surface between two samples, and a projection's
// value when its region closes.

#import focal::types::{Region, MODE_TWO_LEVEL, MODE_OFF, MODE_MIP, MODE_MIN_IP, MODE_X_RAY, MODE_GRADIENT_DVR, MODE_ISO, MODE_CONTEXT, REGION_LABELS, REGION_SHADING, REGION_LAMBDA, ISO_REFINEMENT}
#import focal::bindings::{settings, scene}
#import focal::camera::Ray
#import focal::regions::to_voxel
#import focal::sampling::{trilinear, trilinear_at, trilinear_with_doi, nearest_code, index_gradient, index_gradient_at, gradient_norm, count_sample}
#import focal::transfer::{classify, classify_label, classify_lambda, correct_opacity, filtered, filtered_looks}
#import focal::shading::{shade, shade_with, blinn_phong}
#import focal::context::{context_opacity, eye_distance}
#import focal::compositing::composite
#import focal::selection::{weight_at, companion}

fn is_projection(mode: u32) -> bool {
    return mode == MODE_MIP || mode == MODE_MIN_IP || mode == MODE_X_RAY;
}

// Shaded colour of a DVR or iso sample at q.
fn shaded(r: Region, c: vec3<f32>, q: vec3<f32>, dir: vec3<f32>) -> vec3<f32> {
#ifdef HAS_SHADING
    if (r.flags & REGION_SHADING) != 0u {
        let g = (r.normal_matrix * vec4(index_gradient(r, q), 0.0)).xyz;
        return shade(c, g, dir, settings.light, r.shading, true);
    }
#endif
    return c;
}

// The value at q: fetched with the degree of interest (vd.x) or on its own.
fn value_at(r: Region, q: vec3<f32>, vd: vec2<f32>, located: bool) -> f32 {
#ifdef DOI_CHANNEL
    return vd.x;
#else
    return trilinear_at(r, q, located);
#endif
}

// One DVR (label, gradient-modulated or context-preserving) sample at q, ray parameter
// t, composited under acc, weighted by the current selection weight. The gradient is
// fetched once for shading and modulation.
fn dvr_sample(r: Region, q: vec3<f32>, ratio: f32, ray: Ray, t: f32, acc: vec4<f32>) -> vec4<f32> {
    return dvr_classified(r, q, dvr_classify(r, q), ratio, ray, t, acc, true);
}

// A DVR sample classified: its value (0 for labels), colour and opacity, the
// selection's weight of that opacity, and (with COMPANION) the colour and opacity of
// the current companion's look at the same value, before its weight.
struct Classified {
    v: f32,
    rgba: vec4<f32>,
    weight: f32,
    other: vec4<f32>,
}

// A sample of value v and colour rgba that no selection weighs and no companion shares.
fn classified(v: f32, rgba: vec4<f32>) -> Classified {
    return Classified(v, rgba, 1.0, vec4(0.0));
}

// Whether a classified sample can add anything to the ray (the companion's look left
// out of account where the ray is outside it: a sample too many is only classified).
fn adds_something(c: Classified) -> bool {
#ifdef COMPANION
    return c.rgba.a * c.weight > 0.0 || c.other.a * (1.0 - c.weight) > 0.0;
#else
    return c.rgba.a * c.weight > 0.0;
#endif
}

// The first half of dvr_sample: the sample at q classified.
fn dvr_classify(r: Region, q: vec3<f32>) -> Classified {
    return dvr_classify_at(r, q, false, r.lut_offset);
}

// dvr_classify where `located` (a literal) says the last page look-up's answer holds for
// q (sampling::trilinear_at; labels and the degree-of-interest channel look up anyway),
// with the transfer function's table at `lut` (r's own, or a window's drawn in place:
// focal::insets).
fn dvr_classify_at(r: Region, q: vec3<f32>, located: bool, lut: u32) -> Classified {
    count_sample();
    var rgba: vec4<f32>;
    var v = 0.0;
    // The value and the selection's sample, in one fetch with DOI_CHANNEL (labels or not).
    var vd = vec2(0.0);
    var other = vec4(0.0);
#ifdef DOI_CHANNEL
    vd = trilinear_with_doi(r, q);
#endif
#ifdef HAS_LABELS
    if (r.flags & REGION_LABELS) != 0u {
        rgba = classify_label(r, nearest_code(r, q));
    } else {
        v = value_at(r, q, vd, located);
        rgba = classify_at(r, lut, v, &other);
    }
#else
    v = value_at(r, q, vd, located);
    rgba = classify_at(r, lut, v, &other);
#endif
    var w = 1.0;
#ifdef HAS_SELECTION
    w = weight_at(q, vd.y);
#endif
    return Classified(v, rgba, w, other);
}

// Value v through table `lut` of region r; with a companion, r's own look and (in
// `other`) the companion's, both from their pair table (companion.table).
fn classify_at(r: Region, lut: u32, v: f32, other: ptr<function, vec4<f32>>) -> vec4<f32> {
#ifdef COMPANION
    let looks = filtered_looks(select(lut, companion.table, companion.on), r.lut_width, r.lut_a, r.lut_b, v, companion.on);
    *other = looks.second;
    return looks.first;
#else
    return filtered(r, lut, v);
#endif
}

// The companion's share other_alpha, which lay behind the host's opacity `before`, behind
// the host's opacity `after` that its mode (gradient modulation, equation 5 of
// context-preserving DVR) made of it: the reference composites the companion under the
// host's final opacity (exact at ratio 1).
fn behind(other_alpha: f32, before: f32, after: f32) -> f32 {
    return select(other_alpha, other_alpha * (1.0 - after) / (1.0 - before), before < 1.0);
}

// dvr_sample after classification: the sample's value (0 for labels) gave its colour,
// whose opacity takes its weight (1 for segmented regions' parts). With COMPANION the
// current companion region's look (classified with it) follows at the same voxel,
// where the ray is inside it, with the 1 − weight left over (render::pack::companions:
// the same volume under the same map, a DVR look with the same shading, so it shares
// the gradient and the Blinn-Phong terms; on llvmpipe a second shading of its own cost
// a third of the frame).
// `located` (a literal): the last page look-up was of q, as after dvr_classify
// (sampling::index_gradient_at).
fn dvr_classified(r: Region, q: vec3<f32>, sample: Classified, ratio: f32, ray: Ray, t: f32, acc: vec4<f32>, located: bool) -> vec4<f32> {
    let v = sample.v;
    let rgba = sample.rgba;
    let a = rgba.a * sample.weight;
    // The companion's opacity o (0 without one, or outside it).
    var o = 0.0;
#ifdef COMPANION
    if companion.on && t >= companion.t_enter && t <= companion.t_leave {
        o = sample.other.a * (1.0 - sample.weight);
    }
#endif
    if a <= 0.0 && o <= 0.0 {
        return acc;
    }
    // Both looks take one opacity correction, of their joint opacity 1 − (1 − a)(1 − o)
    // (a step's transparency ((1 − a)(1 − o))^ratio is the reference's, compositing a
    // then o at one ratio: render::pack::companions), shared in proportion to a and
    // (1 − a)·o: the reference's shares where either is 0 and at ratio 1, within a
    // level elsewhere (on llvmpipe the companion's own correction, a pow, cost 7 % of
    // the frame). Without a companion, alpha is a corrected.
    // (Written a + o·(1 − a): positive where either is, and exactly a where o is 0.)
    var joint = a;
#ifdef COMPANION
    joint = a + o * (1.0 - a);
#endif
    let corrected = correct_opacity(joint, ratio);
    // (Where a ≤ 0 this is 0, and composites nothing.)
    var alpha = corrected * select(1.0, a / joint, o > 0.0 && joint > 0.0);
    var other_alpha = corrected - alpha;
    var c = rgba.rgb;
    let labels = (r.flags & REGION_LABELS) != 0u;
    var needs_gradient = false;
    let shading = (r.flags & REGION_SHADING) != 0u;
    var terms = vec2(1.0, 0.0);
#ifdef HAS_GRADIENT_MODULATION
    needs_gradient = needs_gradient || (r.mode == MODE_GRADIENT_DVR && !labels);
#endif
#ifdef HAS_CONTEXT
    needs_gradient = needs_gradient || (r.mode == MODE_CONTEXT && !labels);
#endif
#ifdef HAS_SHADING
    needs_gradient = needs_gradient || (r.flags & REGION_SHADING) != 0u;
#endif
    if needs_gradient {
        let gi = index_gradient_at(r, q, located);
        let g = (r.normal_matrix * vec4(gi, 0.0)).xyz;
        let magnitude = min(length(gi) / gradient_norm(r), 1.0);
#ifdef HAS_GRADIENT_MODULATION
        if r.mode == MODE_GRADIENT_DVR && !labels {
            let before = alpha;
            alpha *= magnitude;
#ifdef COMPANION
            other_alpha = behind(other_alpha, before, alpha);
#endif
        }
#endif
        // The Blinn-Phong terms serve both the shading and s(P) of equation 5.
        if shading || r.mode == MODE_CONTEXT {
            terms = blinn_phong(g, ray.dir, settings.light, r.shading);
        }
#ifdef HAS_CONTEXT
        if r.mode == MODE_CONTEXT && !labels {
            var lambda = vec2(1.0);
            if (r.flags & REGION_LAMBDA) != 0u {
                lambda = classify_lambda(r, v);
            }
            let eye = eye_distance(r, ray.origin, ray.dir, t);
            let before = alpha;
            alpha = context_opacity(r, alpha, magnitude, clamp(terms.x + terms.y, 0.0, 1.0), eye, acc.a, lambda);
#ifdef COMPANION
            other_alpha = behind(other_alpha, before, alpha);
#endif
        }
#endif
#ifdef HAS_SHADING
        if shading {
            c = shade_with(c, terms);
        }
#endif
    }
#ifdef COMPANION
    var oc = sample.other.rgb;
    if shading {
        oc = shade_with(oc, terms);
    }
    // (The host's share as its mode left it, then the companion's.)
    let w = 1.0 - acc.a;
    return acc + vec4((c * alpha + oc * other_alpha) * w, (alpha + other_alpha) * w);
#else
    return composite(acc, c, alpha);
#endif
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

// The iso-surface at voxel position q, shaded and opaque (reference: trace::iso_surface).
fn iso_surface(r: Region, q: vec3<f32>, dir: vec3<f32>, acc: vec4<f32>) -> vec4<f32> {
    let rgba = classify(r, r.iso);
    return composite(acc, shaded(r, rgba.rgb, q, dir), 1.0);
}

fn iso_hit(r: Region, ray: Ray, tp: f32, vp: f32, t: f32, acc: vec4<f32>) -> vec4<f32> {
    let th = refine_iso(r, ray, tp, vp, t);
    return iso_surface(r, to_voxel(r, ray.origin + ray.dir * th), ray.dir, acc);
}

// Whether a region composites every sample at once (DVR, gradient-modulated and
// context-preserving DVR, label volumes): two of them can share one tight loop.
fn is_dvr_like(mode: u32, flags: u32) -> bool {
    if mode == MODE_TWO_LEVEL || mode == MODE_OFF {
        return false;
    }
    return (flags & REGION_LABELS) != 0u || !(is_projection(mode) || mode == MODE_ISO);
}

// Whether a projection of r takes normalised sample v (Appearance::projection_range).
fn projection_takes(r: Region, v: f32) -> bool {
    return v >= r.projection.x && v <= r.projection.y;
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

// A projection region's value as one sample composited under acc (reference:
// trace::close).
fn emit_projection(r: Region, vmax: f32, vmin: f32, vsum: f32, count: u32, acc: vec4<f32>) -> vec4<f32> {
    if !is_projection(r.mode) || count == 0u {
        return acc;
    }
    let rgba = classify(r, projected(r.mode, vmax, vmin, vsum, count));
    return composite(acc, rgba.rgb, rgba.a);
}
