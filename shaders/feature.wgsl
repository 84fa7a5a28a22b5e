// The feature lens's silhouette on the GPU (reference: src/lens/feature.rs, which
// holds the algorithm; keep the two in step). Three entry points run per feature lens
// and frame over a grid of cells covering the view:
//   mask:   the camera's ray through each cell centre marches the label volume
//           (nearest voxel, fixed world step); a cell meeting the label seeds the
//           "inside" map, the others the "outside" map; atomics count the inside
//           cells and sum their coordinates (centroid and area).
//   flood:  one jump-flooding pass (Rong and Tan 2006) of step `jump` over both maps:
//           each cell keeps the nearest seed among its own and those of the eight
//           cells `jump` away. Steps n/2, n/4, …, 1 and one more of 1 (JFA+1).
//   finish: signed distance to the silhouette per cell (half a cell off the seed
//           distances, as the reference's exact transform) and the header: centroid,
//           equivalent radius √(area/π), in view.

#import focal::types::Region
#import focal::bindings::regions
#import focal::regions::{region_interval, in_hole, to_voxel, cut_by_plane}
#import focal::sampling::nearest_code
#import focal::camera::camera_ray

struct FeatureParams {
    cols: u32,
    rows: u32,
    // Offset of the lens's header in `fields`.
    offset: u32,
    region: u32,
    label: u32,
    jump: u32,
    // Which seed buffer a flood pass reads (0: a, 1: b); the mask writes a.
    source: u32,
    // The lens's four counters in `counts`.
    slot: u32,
    // Lens coordinates of cell (0, 0) and the cell size.
    origin: vec2<f32>,
    cell: vec2<f32>,
    // Marching step (world units).
    step: f32,
    // 1 where the volume holds the label: the world planes (n, d: n·x − d ≤ 0 inside)
    // of a box outside which no sample meets it (lens::feature::FeatureJob::within).
    present: u32,
    pad_b: f32,
    pad_c: f32,
    within: array<vec4<f32>, 6>,
}

@group(1) @binding(0) var<uniform> job: FeatureParams;
@group(1) @binding(1) var<storage, read_write> seeds_a: array<vec2<u32>>;
@group(1) @binding(2) var<storage, read_write> seeds_b: array<vec2<u32>>;
@group(1) @binding(3) var<storage, read_write> counts: array<atomic<u32>>;
@group(1) @binding(4) var<storage, read_write> fields: array<f32>;

const NONE: u32 = 0xffffffffu;
// Most samples one mask ray takes (a bound for malformed inputs).
const MAX_MARCH: u32 = 65536u;

fn in_grid(id: vec3<u32>) -> bool {
    return id.x < job.cols && id.y < job.rows;
}

// The march of the samples start + (k + ½)·step of the region's span that lie in the
// label's box (reference: lens::feature::feature_mask, first_sample).
fn marches_into_feature(uv: vec2<f32>) -> bool {
    if job.present == 0u {
        return false;
    }
    let ray = camera_ray(uv);
    var within = vec2(-3.4e38, 3.4e38);
    for (var i = 0u; i < 6u; i++) {
        within = cut_by_plane(within, job.within[i], ray.origin, ray.dir);
    }
    if within.x > within.y {
        return false;
    }
    let r = regions[job.region];
    let span = region_interval(r, ray.origin, ray.dir);
    let start = max(span.x, 0.0);
    let end = min(span.y, within.y);
    let first = floor((within.x - start) / job.step - 0.5);
    if first >= f32(MAX_MARCH) {
        return false;
    }
    for (var k = u32(max(first, 0.0)); k < MAX_MARCH; k++) {
        let t = start + (f32(k) + 0.5) * job.step;
        if t >= end {
            break;
        }
        let p = ray.origin + ray.dir * t;
        if nearest_code(r, to_voxel(r, p)) == job.label && !in_hole(r, p) {
            return true;
        }
    }
    return false;
}

@compute @workgroup_size(8, 8, 1)
fn mask(@builtin(global_invocation_id) id: vec3<u32>) {
    if !in_grid(id) {
        return;
    }
    let cell = id.y * job.cols + id.x;
    let uv = (vec2<f32>(id.xy) + 0.5) / vec2(f32(job.cols), f32(job.rows));
    if marches_into_feature(uv) {
        seeds_a[cell] = vec2(cell, NONE);
        atomicAdd(&counts[job.slot * 4u], 1u);
        atomicAdd(&counts[job.slot * 4u + 1u], id.x);
        atomicAdd(&counts[job.slot * 4u + 2u], id.y);
    } else {
        seeds_a[cell] = vec2(NONE, cell);
    }
}

fn read_seeds(cell: u32) -> vec2<u32> {
    if job.source == 0u {
        return seeds_a[cell];
    }
    return seeds_b[cell];
}

fn write_seeds(cell: u32, s: vec2<u32>) {
    if job.source == 0u {
        seeds_b[cell] = s;
    } else {
        seeds_a[cell] = s;
    }
}

// Squared distance in cells from p to seed s (NONE: farther than any).
fn seed_d2(p: vec2<i32>, s: u32) -> u32 {
    if s == NONE {
        return NONE;
    }
    let d = vec2(i32(s % job.cols), i32(s / job.cols)) - p;
    return u32(d.x * d.x + d.y * d.y);
}

@compute @workgroup_size(8, 8, 1)
fn flood(@builtin(global_invocation_id) id: vec3<u32>) {
    if !in_grid(id) {
        return;
    }
    let p = vec2<i32>(id.xy);
    let cell = id.y * job.cols + id.x;
    var best = read_seeds(cell);
    var d_in = seed_d2(p, best.x);
    var d_out = seed_d2(p, best.y);
    let jump = i32(job.jump);
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = p + vec2(dx, dy) * jump;
            if (dx == 0 && dy == 0) || q.x < 0 || q.y < 0 || q.x >= i32(job.cols) || q.y >= i32(job.rows) {
                continue;
            }
            let s = read_seeds(u32(q.y) * job.cols + u32(q.x));
            let a = seed_d2(p, s.x);
            if a < d_in {
                d_in = a;
                best.x = s.x;
            }
            let b = seed_d2(p, s.y);
            if b < d_out {
                d_out = b;
                best.y = s.y;
            }
        }
    }
    write_seeds(cell, best);
}

@compute @workgroup_size(8, 8, 1)
fn finish(@builtin(global_invocation_id) id: vec3<u32>) {
    if !in_grid(id) {
        return;
    }
    let o = job.offset;
    if id.x == 0u && id.y == 0u {
        let n = atomicLoad(&counts[job.slot * 4u]);
        if n == 0u {
            fields[o + 3u] = 0.0;
        } else {
            let mean = vec2(f32(atomicLoad(&counts[job.slot * 4u + 1u])), f32(atomicLoad(&counts[job.slot * 4u + 2u]))) / f32(n);
            let centroid = job.origin + vec2(mean.x * job.cell.x, -mean.y * job.cell.y);
            let area = f32(n) * job.cell.x * job.cell.y;
            fields[o] = centroid.x;
            fields[o + 1u] = centroid.y;
            fields[o + 2u] = sqrt(area / 3.14159265);
            fields[o + 3u] = 1.0;
        }
    }
    let p = vec2<i32>(id.xy);
    let cell = id.y * job.cols + id.x;
    let s = read_seeds(cell);
    var d: f32;
    if s.x != cell {
        // Outside (no inside cell at all leaves the lens out of view: any value).
        d = (sqrt(f32(seed_d2(p, s.x))) - 0.5) * job.cell.y;
    } else if s.y != NONE {
        d = -(sqrt(f32(seed_d2(p, s.y))) - 0.5) * job.cell.y;
    } else {
        // A feature covering the whole grid: the distance to the grid's edge.
        let edge = min(min(id.x, job.cols - 1u - id.x), min(id.y, job.rows - 1u - id.y)) + 1u;
        d = -(f32(edge) - 0.5) * job.cell.y;
    }
    fields[o + 4u + cell] = d;
}
