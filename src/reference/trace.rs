//! The per-pixel function: one ray through every region, front to back.
//!
//! 1. Intersect the ray with each region: intervals `[t0, t1]` (clamped to `t ≥ 0`); a
//!    region with holes (clip windows) has one interval more per hole it splits.
//! 2. March one sample sequence over the union, `t_k = t_start + (k + j)·Δ`, with `Δ` the
//!    smallest world step of the regions on the ray and `j` the jitter offset (0.5 without
//!    jitter: the midpoint rule, so an axis-aligned ray with `Δ` = one voxel samples the
//!    voxel centres exactly).
//! 3. At each sample, every region whose interval contains it contributes, in region
//!    order (overlapping regions combine sample by sample):
//!    - DVR: `rgba = TF(f(q))` (its opacity times a selection's weight when the
//!      appearance has one: `region::SelectionWeight`), opacity corrected for the step,
//!      `α = 1 − (1 − α_TF)^(Δ_native/Δ₀)`, colour Blinn-Phong shaded with the gradient
//!      normal, composited front to back `C += (1 − A)·α·c`, `A += (1 − A)·α`;
//!    - gradient-modulated DVR: as DVR with `α ·= |∇f| / max|∇f|`;
//!    - context-preserving DVR: as DVR with α from equation 5 of Bruckner et al.
//!      ([`crate::context::model`]; the accumulated opacity in front is `A`);
//!    - MIP / MinIP / X-ray: the region keeps the max / min / mean of its samples and
//!      emits `TF(value)` as one sample when the ray leaves its interval;
//!    - iso-surface: the first sign change of `f − iso` between samples is refined by
//!      bisection, shaded and composited as an opaque sample;
//!    - segmented regions ([`crate::twolevel`]): each sample's object (from the label
//!      volume and the value) selects the part whose mode applies; where the object
//!      changes, a segment ends and its projection is emitted; an iso-surface object
//!      whose segment starts at or above the iso-value has its surface there (its
//!      label's boundary).
//! 4. Stop early once `A ≥ 0.99` (or at the pick threshold when picking).
//!
//! The GPU shader implements the same function; keep them in step.

use glam::{Vec3, Vec4};

use super::prepare::PreparedRegion;
use crate::context::model as context;
use crate::lens::antialias::Footprint;
use crate::region::{Light, Mode, Ray, Shading};
use crate::transfer::opacity;
use crate::volume::pyramid::MIP_LEVELS;

/// Accumulated opacity at which a ray stops.
pub const EARLY_TERMINATION: f32 = 0.99;
/// Bisection steps refining an iso-surface crossing (interval shrinks by 2⁻⁸).
pub const ISO_REFINEMENT: u32 = 8;

/// What one ray produced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Traced {
    /// Premultiplied colour and accumulated opacity.
    pub color: Vec4,
    /// Projected value of the first projection region (normalised), or NaN.
    pub value: f32,
    /// Ray parameter where the accumulated opacity first reached the depth threshold
    /// (or the iso-surface hit), else infinity.
    pub depth: f32,
    /// Region that was being composited at `depth`.
    pub region: Option<usize>,
    /// Sample positions visited along the ray.
    pub samples: u32,
    /// Samples a region took (over all regions, so an overlap counts each): a DVR sample
    /// in a brick its look draws in, every projection and iso-surface sample. What a
    /// picture costs a ray caster that skips empty space, whatever its hardware.
    pub classified: u32,
}

impl Traced {
    /// A pixel without a ray.
    pub const EMPTY: Traced = Traced { color: Vec4::ZERO, value: f32::NAN, depth: f32::INFINITY, region: None, samples: 0, classified: 0 };
}

/// What a projection or iso-surface has gathered: over a region's interval, or over
/// the current segment of a segmented region.
#[derive(Clone, Copy)]
struct Gathered {
    max: f32,
    min: f32,
    sum: f32,
    count: u32,
    prev: Option<(f32, f32)>,
    /// The iso-surface was hit: nothing more to do here.
    done: bool,
}

impl Gathered {
    const EMPTY: Gathered = Gathered { max: f32::NEG_INFINITY, min: f32::INFINITY, sum: 0.0, count: 0, prev: None, done: false };
}

/// State along the ray of one interval of a region (a region with holes has several).
#[derive(Clone, Copy)]
struct State {
    /// Index of the region.
    region: usize,
    t0: f32,
    t1: f32,
    gathered: Gathered,
    /// The ray has left the region (or an iso-surface ended it).
    done: bool,
    /// Segmented regions: the part (object, or the rest) of the current segment.
    part: Option<usize>,
    /// Native length of one march step over the opacity reference length.
    ratio: f32,
}

/// What every sample of a ray shares.
struct Sampling<'r> {
    ray: &'r Ray,
    light: Light,
    level: f32,
    depth_threshold: f32,
}

/// Where one sample is taken: its continuous voxel index, its ray parameter and the
/// index of the region it samples.
#[derive(Clone, Copy)]
struct SamplePoint {
    q: Vec3,
    t: f32,
    region: usize,
    /// The sample's value where it is not the plain trilinear one (a two-level part's
    /// own value at a boundary, `PreparedObjects::own_value`).
    value: Option<f32>,
}

/// Traces one ray. `jitter` ∈ [0, 1) offsets the samples; `depth_threshold` is the
/// accumulated opacity that defines the depth (and ends the ray when `stop_at_depth`).
pub fn trace(regions: &[PreparedRegion], light: Light, ray: Ray, jitter: f32, depth_threshold: f32, stop_at_depth: bool) -> Traced {
    trace_antialiased(regions, light, ray, jitter, depth_threshold, stop_at_depth, None)
}

/// [`trace`] under lenses with anti-aliasing: each sample comes from the mip level the
/// pixel's footprint gives at its depth (`crate::lens::antialias`, eq. 4).
pub fn trace_antialiased(
    regions: &[PreparedRegion],
    light: Light,
    ray: Ray,
    jitter: f32,
    depth_threshold: f32,
    stop_at_depth: bool,
    footprint: Option<&Footprint>,
) -> Traced {
    let mut out = Traced { color: Vec4::ZERO, value: f32::NAN, depth: f32::INFINITY, region: None, samples: 0, classified: 0 };
    // The intervals of every region (in region order, each region's in increasing t).
    let mut states: Vec<State> = Vec::with_capacity(regions.len());
    let (mut t_start, mut t_end, mut step) = (f32::INFINITY, f32::NEG_INFINITY, f32::INFINITY);
    for (region, r) in regions.iter().enumerate() {
        let before = states.len();
        for (t0, t1) in r.region.intersect(ray.origin, ray.dir).into_iter().map(|(a, b)| (a.max(0.0), b)).filter(|(a, b)| a < b) {
            t_start = t_start.min(t0);
            t_end = t_end.max(t1);
            states.push(State { region, t0, t1, gathered: Gathered::EMPTY, done: false, part: None, ratio: 0.0 });
        }
        if states.len() > before {
            step = step.min(r.world_step(ray.dir));
        }
    }
    if !t_start.is_finite() {
        return out;
    }
    let footprint = footprint.map(|f| f.over(t_start, t_end));
    for st in &mut states {
        let r = &regions[st.region];
        st.ratio = r.native_step * (step / r.world_step(ray.dir)) / r.reference_length;
    }
    let stop = if stop_at_depth { depth_threshold } else { EARLY_TERMINATION };
    let mut k = 0u32;
    loop {
        let t = t_start + (k as f32 + jitter) * step;
        if t > t_end {
            break;
        }
        k += 1;
        out.samples = k;
        let p = ray.at(t);
        let at = Sampling { ray: &ray, light, level: footprint.map_or(0.0, |f| f.level(t, MIP_LEVELS as f32)), depth_threshold };
        for si in 0..states.len() {
            let (i, r) = (states[si].region, &regions[states[si].region]);
            if states[si].done {
                continue;
            }
            if t > states[si].t1 {
                // Left this region: a projection (or the open segment) emits its value
                // now, or hands it on to a later interval of the same projection.
                leave(&mut out, regions, &mut states, si, t, depth_threshold);
                continue;
            }
            let st = &mut states[si];
            if t < st.t0 {
                continue;
            }
            let q = r.region.world_to_voxel.transform_point3(p);
            match &r.objects {
                None => {
                    sample(&mut out, r, &mut st.gathered, st.ratio, SamplePoint { q, t, region: i, value: None }, &at);
                    st.done = st.gathered.done;
                }
                Some(objects) => {
                    // Two-level: a new segment starts where the object changes.
                    let v = r.sample(q, at.level);
                    let part = objects.part_at(q, v);
                    if st.part != Some(part) {
                        close(&mut out, r, st, t, i, depth_threshold);
                        st.part = Some(part);
                    }
                    let shown = &objects.parts[part];
                    if !objects.visible[part] || st.gathered.done {
                        continue;
                    }
                    if shown.mode == Mode::Iso && st.gathered.prev.is_none() && shown.sample(q, at.level) >= shown.iso {
                        // The segment starts inside the iso-surface: the object's
                        // boundary is its surface.
                        iso_surface(&mut out, shown, q, t, i, &at);
                        st.gathered.done = true;
                    } else {
                        // (Boundaries at full resolution: a mip level blends neighbours anyway.)
                        let own = if at.level <= 0.0 { objects.own_value(&r.sampler, q, v) } else { v };
                        sample(&mut out, shown, &mut st.gathered, st.ratio, SamplePoint { q, t, region: i, value: Some(own) }, &at);
                    }
                }
            }
        }
        if out.color.w >= stop {
            break;
        }
    }
    // Projections (and segments) still open at the end of the march.
    for si in 0..states.len() {
        if !states[si].done && out.color.w < stop {
            let t1 = states[si].t1;
            leave(&mut out, regions, &mut states, si, t1, depth_threshold);
        }
    }
    out
}

/// One sample of region `r` (or of one part of a segmented region) at voxel position
/// `q`, ray parameter `t`: composited at once (DVR modes), gathered (projections) or
/// tested for a crossing (iso-surfaces).
fn sample(out: &mut Traced, r: &PreparedRegion, g: &mut Gathered, ratio: f32, p: SamplePoint, at: &Sampling) {
    let SamplePoint { q, t, region: i, value } = p;
    let (ray, light, level, depth_threshold) = (at.ray, at.light, at.level, at.depth_threshold);
    let view = ray.dir;
    match r.mode {
        Mode::Mip | Mode::MinIp | Mode::XRay => {
            out.classified += 1;
            let v = value.unwrap_or_else(|| r.sample(q, level));
            if !(r.projection.0..=r.projection.1).contains(&v) {
                return;
            }
            g.max = g.max.max(v);
            g.min = g.min.min(v);
            g.sum += v;
            g.count += 1;
        }
        Mode::Dvr | Mode::GradientDvr | Mode::Context => {
            // Occupancy holds for full-resolution samples only.
            if level <= 0.0 && !r.occupied(q) {
                return;
            }
            out.classified += 1;
            let v = value.unwrap_or_else(|| r.sample(q, level));
            let rgba = r.lookup.classify(v, r.sampler.nearest(q));
            let a = r.weight.as_ref().map_or(rgba[3], |w| rgba[3] * w.at(q));
            if a <= 0.0 {
                return;
            }
            let mut alpha = opacity::correct(a, ratio);
            let grad = r.index_gradient_at(q, level);
            let gradient = (grad.length() / r.gradient_max).min(1.0);
            let world_g = r.normal_matrix * grad;
            if r.mode == Mode::GradientDvr {
                alpha *= gradient;
            } else if r.mode == Mode::Context {
                let sample = context::Sample {
                    alpha,
                    gradient,
                    shading: shading_intensity(world_g, view, light, &r.shading),
                    eye_distance: context::eye_distance(t, ray.origin, ray.dir, r.sphere.0, r.sphere.1),
                    alpha_prev: out.color.w,
                    lambda: r.lookup.lambda(v),
                };
                alpha = context::opacity(&r.context, &sample);
            }
            let c = shade(Vec3::new(rgba[0], rgba[1], rgba[2]), world_g, view, light, &r.shading);
            composite(out, c, alpha, t, i, depth_threshold);
        }
        Mode::Iso => {
            out.classified += 1;
            let v = r.sample(q, level) - r.iso;
            if let Some((tp, vp)) = g.prev
                && (vp < 0.0) != (v < 0.0)
            {
                let th = refine(r, ray, (tp, vp), (t, v), level);
                iso_surface(out, r, r.region.world_to_voxel.transform_point3(ray.at(th)), th, i, at);
                g.done = true;
            } else {
                g.prev = Some((t, v));
            }
        }
    }
}

/// The iso-surface of region `r` at voxel position `qh` (ray parameter `th`), shaded
/// and opaque.
fn iso_surface(out: &mut Traced, r: &PreparedRegion, qh: Vec3, th: f32, i: usize, at: &Sampling) {
    let rgba = r.lookup.classify(r.iso, r.sampler.nearest(qh));
    let grad = r.index_gradient_at(qh, at.level);
    let c = shade(Vec3::new(rgba[0], rgba[1], rgba[2]), r.normal_matrix * grad, at.ray.dir, at.light, &r.shading);
    composite(out, c, 1.0, th, i, at.depth_threshold);
}

/// The ray leaves interval `si` at ray parameter `t`: what a projection gathered goes on
/// to a later interval of the same projection group that the ray has not left (so a MIP
/// of an exploded view, or of a dataset beside a same-look window, is the maximum along
/// the whole ray, emitted once after its last interval), else it is emitted ([`close`]).
fn leave(out: &mut Traced, regions: &[PreparedRegion], states: &mut [State], si: usize, t: f32, threshold: f32) {
    let st = states[si];
    let r = &regions[st.region];
    if r.objects.is_none() && r.mode.is_projection() {
        let later = |(h, o): &(usize, &State)| {
            *h != si && !o.done && regions[o.region].projection_group == r.projection_group && (o.t1 > st.t1 || (o.t1 == st.t1 && *h > si))
        };
        if let Some((h, _)) = states.iter().enumerate().find(|e| later(e)) {
            let (g, a) = (&mut states[h].gathered, st.gathered);
            (g.max, g.min, g.sum, g.count) = (g.max.max(a.max), g.min.min(a.min), g.sum + a.sum, g.count + a.count);
            states[si].gathered = Gathered::EMPTY;
            states[si].done = true;
            return;
        }
    }
    close(out, r, &mut states[si], t, st.region, threshold);
    states[si].done = true;
}

/// Ends what region `r` has gathered at ray parameter `t` (leaving the region, or its
/// segment ending): a projection emits its value as one sample; then it starts afresh.
fn close(out: &mut Traced, r: &PreparedRegion, st: &mut State, t: f32, i: usize, threshold: f32) {
    let part = match (&r.objects, st.part) {
        (None, _) => Some(r),
        (Some(objects), Some(k)) if objects.visible[k] => Some(&objects.parts[k]),
        _ => None,
    };
    if let Some(part) = part
        && part.mode.is_projection()
        && st.gathered.count > 0
    {
        emit_projection(out, part, projected(part.mode, &st.gathered), t, i, threshold);
    }
    st.gathered = Gathered::EMPTY;
}

fn projected(mode: Mode, st: &Gathered) -> f32 {
    match mode {
        Mode::Mip => st.max,
        Mode::MinIp => st.min,
        _ => st.sum / st.count as f32,
    }
}

fn emit_projection(out: &mut Traced, r: &PreparedRegion, v: f32, t: f32, i: usize, threshold: f32) {
    if out.value.is_nan() {
        out.value = v;
    }
    let rgba = r.lookup.classify(v, 0);
    composite(out, Vec3::new(rgba[0], rgba[1], rgba[2]), rgba[3], t, i, threshold);
}

/// Front-to-back "under" compositing of a non-premultiplied colour with opacity `alpha`.
#[inline]
fn composite(out: &mut Traced, c: Vec3, alpha: f32, t: f32, region: usize, threshold: f32) {
    let w = (1.0 - out.color.w) * alpha;
    out.color += Vec4::new(c.x * w, c.y * w, c.z * w, w);
    if out.color.w >= threshold && out.depth.is_infinite() {
        out.depth = t;
        out.region = Some(region);
    }
}

/// Bisection between two samples on either side of the iso-value.
fn refine(r: &PreparedRegion, ray: &Ray, (mut ta, va): (f32, f32), (mut tb, _): (f32, f32), level: f32) -> f32 {
    let below = va < 0.0;
    for _ in 0..ISO_REFINEMENT {
        let tm = 0.5 * (ta + tb);
        let v = r.sample(r.region.world_to_voxel.transform_point3(ray.at(tm)), level) - r.iso;
        if (v < 0.0) == below {
            ta = tm;
        } else {
            tb = tm;
        }
    }
    0.5 * (ta + tb)
}

/// Blinn-Phong shading of colour `c` with the (unnormalised) world gradient `g`, seen
/// along the ray direction `view`. Two-sided: the normal is turned towards the viewer.
/// A vanishing gradient (no surface) leaves the colour unshaded.
pub fn shade(c: Vec3, g: Vec3, view: Vec3, light: Light, s: &Shading) -> Vec3 {
    if !s.enabled {
        return c;
    }
    match blinn_phong(g, view, light, s) {
        Some((diffuse, specular)) => (c * diffuse + Vec3::splat(specular)).clamp(Vec3::ZERO, Vec3::ONE),
        None => c,
    }
}

/// The two terms of Blinn-Phong: `(ka + kd·max(N·L, 0), ks·max(N·H, 0)^shininess)`,
/// `None` where the gradient vanishes.
pub fn blinn_phong(g: Vec3, view: Vec3, light: Light, s: &Shading) -> Option<(f32, f32)> {
    let len = g.length();
    if len < 1e-6 {
        return None;
    }
    let v = -view;
    let mut n = g / len;
    if n.dot(v) < 0.0 {
        n = -n;
    }
    let l = match light {
        Light::Headlight => v,
        Light::Direction(d) => d.normalize_or(v),
    };
    let h = (l + v).normalize_or(v);
    Some((s.ambient + s.diffuse * n.dot(l).max(0.0), s.specular * n.dot(h).max(0.0).powf(s.shininess)))
}

/// s(P) of context-preserving rendering (equation 3): the Blinn-Phong intensity
/// clamped to [0, 1], whether or not colours are shaded; 1 where the gradient vanishes.
pub fn shading_intensity(g: Vec3, view: Vec3, light: Light, s: &Shading) -> f32 {
    blinn_phong(g, view, light, s).map_or(1.0, |(d, sp)| (d + sp).clamp(0.0, 1.0))
}

/// Deterministic per-pixel jitter in `[0, 1)` (the same integer hash as the shader).
pub fn jitter(x: u32, y: u32, frame: u32) -> f32 {
    let mut h = x.wrapping_mul(1_973).wrapping_add(y.wrapping_mul(9_277)).wrapping_add(frame.wrapping_mul(26_699)) | 1;
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    (h >> 8) as f32 / (1u32 << 24) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blinn_phong_matches_hand_values() {
        let s = Shading { enabled: true, ambient: 0.2, diffuse: 0.5, specular: 0.3, shininess: 2.0 };
        // Head-on surface: N·L = N·H = 1 → c·0.7 + 0.3.
        let c = shade(Vec3::splat(0.5), Vec3::Z, Vec3::NEG_Z, Light::Headlight, &s);
        assert!((c - Vec3::splat(0.65)).length() < 1e-6);
        // Light from 60° off the normal, viewer head-on: N·L = 0.5, H at 30°, N·H = cos 30°.
        let l = Vec3::new(3f32.sqrt() / 2.0, 0.0, 0.5);
        let c = shade(Vec3::ONE, -Vec3::Z * 3.0, Vec3::NEG_Z, Light::Direction(l), &s);
        let expect = 0.2 + 0.5 * 0.5 + 0.3 * (30f32.to_radians().cos()).powi(2);
        assert!((c.x - expect).abs() < 1e-5, "{} vs {expect}", c.x);
        // No gradient: unshaded.
        assert_eq!(shade(Vec3::splat(0.4), Vec3::ZERO, Vec3::NEG_Z, Light::Headlight, &s), Vec3::splat(0.4));
    }

    #[test]
    fn jitter_is_uniform_enough() {
        let n = 10_000;
        let mean: f32 = (0..n).map(|i| jitter(i % 100, i / 100, 0)).sum::<f32>() / n as f32;
        assert!((mean - 0.5).abs() < 0.02, "{mean}");
        assert!((0..n).all(|i| (0.0..1.0).contains(&jitter(i, 7, 3))));
    }
}
