#define_import_path focal::segments

// The ray's intervals and segments (reference: src/reference/trace.rs): per-interval
// state bits, the sample grid of a one-region segment, the jumps over empty bricks, and
// the cutting of intervals by a region's holes.

#import focal::types::{Region, MAX_RAY_REGIONS}
#import focal::bindings::{scene, regions}
#import focal::lens::update_lod
#import focal::sampling::{brick_occupied, brick_exit_at}

// Per-interval state bits: the region is done with; it has a previous sample (iso);
// it is DVR-like (two such share the DVR loop); it composites at its end (projections,
// two-level).
const DONE: u32 = 1u;
const HAS_PREV: u32 = 2u;
const PAIRABLE: u32 = 4u;
const CLOSES: u32 = 8u;

// The sample grid of a one-region segment: sample kk lies at t_start + (kk + j)·step on
// the ray and at q_first + dq·(kk − k_first) in the region's voxels (qd: voxels per unit t).
struct Segment {
    q_first: vec3<f32>,
    dq: vec3<f32>,
    qd: vec3<f32>,
    k_first: f32,
    t_start: f32,
    step: f32,
    j: f32,
}

fn segment_t(g: Segment, kk: f32) -> f32 {
    return g.t_start + (kk + g.j) * g.step;
}

// Voxel position of sample kk; under lenses also sets the mip level for it.
fn segment_point(g: Segment, kk: f32) -> vec3<f32> {
    return segment_point_at(g, kk, true);
}

// segment_point where `lensed` says whether the ray's mip level may change along it
// (a literal at each call site: with false the inlined code keeps the level it is
// given and the compiler folds the mip chain's blend away, focal::raycast's
// plain_segment).
fn segment_point_at(g: Segment, kk: f32, lensed: bool) -> vec3<f32> {
#ifdef HAS_LENSES
    if lensed {
        update_lod(segment_t(g, kk));
    }
#endif
    return g.q_first + g.dq * (kk - g.k_first);
}

// Index of the first sample past the brick that holds sample kk (at q).
fn past_brick(r: Region, g: Segment, q: vec3<f32>, kk: f32) -> f32 {
    return past_brick_at(r, g, q, kk, false);
}

// past_brick where the last page look-up was of q when `located` (a literal:
// sampling::brick_exit_at).
fn past_brick_at(r: Region, g: Segment, q: vec3<f32>, kk: f32, located: bool) -> f32 {
    return max(kk + 1.0, ceil((brick_exit_at(r, q, g.qd, segment_t(g, kk), located) - g.t_start) / g.step - g.j));
}

// The first sample from kk on (at most k_end + 1) that lies in an occupied brick (for
// a sample of the mip chain, under lenses with anti-aliasing, one whose neighbourhood
// may be visible: sampling::brick_occupied): empty bricks are crossed in a loop of
// their own, so the lanes of a SIMD group that skip wait for each other there, then
// all take the next (expensive) sample together.
fn past_empty_bricks(r: Region, g: Segment, kk_in: f32, k_end: f32) -> f32 {
    return past_empty_bricks_at(r, g, kk_in, k_end, true);
}

// past_empty_bricks with segment_point_at's `lensed`.
fn past_empty_bricks_at(r: Region, g: Segment, kk_in: f32, k_end: f32, lensed: bool) -> f32 {
    var kk = kk_in;
    for (var skip_steps = 0u; skip_steps < scene.max_steps; skip_steps++) {
        if kk > k_end {
            break;
        }
        let q = segment_point_at(g, kk, lensed);
        if brick_occupied(r, q) {
            break;
        }
        // (brick_occupied looked q up.)
        kk = past_brick_at(r, g, q, kk, true);
    }
    return kk;
}

// [`past_empty_bricks`] for two regions sampled together: the first sample from kk on
// where either lies in an occupied brick.
fn past_empty_pair(ra: Region, ga: Segment, rb: Region, gb: Segment, kk_in: f32, k_end: f32) -> f32 {
    var kk = kk_in;
    for (var skip_steps = 0u; skip_steps < scene.max_steps; skip_steps++) {
        if kk > k_end {
            break;
        }
        let qa = segment_point(ga, kk);
        let qb = gb.q_first + gb.dq * (kk - gb.k_first);
        if brick_occupied(ra, qa) || brick_occupied(rb, qb) {
            break;
        }
        kk = min(past_brick(ra, ga, qa, kk), past_brick(rb, gb, qb, kk));
    }
    return kk;
}

// Cuts the open interval `cut` out of intervals first..n of region i (reference:
// region::subtract_interval) and returns the new count: an interval split in two adds
// one at the end; one cut away whole is left empty (t0 > t1) for compact_intervals.
fn cut_intervals(i: u32, first: u32, n: u32, cut: vec2<f32>, ids: ptr<function, array<u32, MAX_RAY_REGIONS>>, t0s: ptr<function, array<f32, MAX_RAY_REGIONS>>, t1s: ptr<function, array<f32, MAX_RAY_REGIONS>>) -> u32 {
    var count = n;
    for (var e = first; e < n; e++) {
        let a = (*t0s)[e];
        let b = (*t1s)[e];
        if !(cut.x < b && cut.y > a && cut.x < cut.y) {
            continue;
        }
        if cut.x > a {
            (*t1s)[e] = cut.x;
            if cut.y < b && count < MAX_RAY_REGIONS {
                (*ids)[count] = i;
                (*t0s)[count] = cut.y;
                (*t1s)[count] = b;
                count++;
            }
        } else if cut.y < b {
            (*t0s)[e] = cut.y;
        } else {
            (*t0s)[e] = 1.0;
            (*t1s)[e] = 0.0;
        }
    }
    return count;
}

// Drops the empty intervals among first..n; returns the new count.
fn compact_intervals(first: u32, n: u32, ids: ptr<function, array<u32, MAX_RAY_REGIONS>>, t0s: ptr<function, array<f32, MAX_RAY_REGIONS>>, t1s: ptr<function, array<f32, MAX_RAY_REGIONS>>) -> u32 {
    var m = first;
    for (var e = first; e < n; e++) {
        if (*t0s)[e] < (*t1s)[e] {
            (*ids)[m] = (*ids)[e];
            (*t0s)[m] = (*t0s)[e];
            (*t1s)[m] = (*t1s)[e];
            m++;
        }
    }
    return m;
}

// Whether the sample after the last one of a segment (index k_end) lies past t1: the
// ray then leaves the region there, and what it gathered is emitted (the reference
// closes a region at its first sample past t1).
fn leaves(t_start: f32, k_end: f32, j: f32, step: f32, t1: f32) -> bool {
    return t_start + (k_end + 1.0 + j) * step > t1;
}
