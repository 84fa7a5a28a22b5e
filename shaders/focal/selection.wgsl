#define_import_path focal::selection

// Selection weights (exploded views, reference: region::SelectionWeight and
// PreparedWeight::at): a region's opacity times the degree of interest of a selection
// volume at the sample, or 1 minus it. The selection record (region objects.w) maps the
// data's voxel index to the selection's; doi = clamp(a·t + b, 0, 1) of its sample t.
//
// The record is read once per segment into `weight`, never per sample: on llvmpipe a
// record read by a per-lane index is a gather of every field for every lane, and that
// made a weighted sample cost twice an unweighted one.

#import focal::types::{Region, REGION_SELECTION, REGION_KEEP_UNSELECTED, REGION_COMPANION}
#import focal::bindings::{regions, occupancy_word}
#import focal::sampling::trilinear_box
#import focal::regions::region_interval

const KEEP_NONE: u32 = 0u;
const KEEP_SELECTED: u32 = 1u;
const KEEP_UNSELECTED: u32 = 2u;

struct Weight {
    // Data voxel index → selection voxel index.
    map: mat4x4<f32>,
    // The selection's atlas offset (xyz) and dims (xyz).
    offset: vec4<f32>,
    dims: vec4<f32>,
    // The selection's brick grid (dims, brick size) and where its bricks' kinds are in
    // the occupancy words (render::pack::constant_bricks).
    bricks: vec4<u32>,
    kinds: u32,
    // doi = clamp(ab.x · t + ab.y, 0, 1).
    ab: vec2<f32>,
    // KEEP_NONE (weight 1), KEEP_SELECTED (doi) or KEEP_UNSELECTED (1 − doi).
    keep: u32,
}

// The weight of the region whose samples come next (set per segment).
var<private> weight: Weight;

// The weight of region r (its record read field by field).
fn region_weight(r: Region) -> Weight {
    var w: Weight;
    w.keep = KEEP_NONE;
    if (r.flags & REGION_SELECTION) != 0u {
        let i = r.objects.w;
        w.map = regions[i].world_to_voxel;
        w.offset = regions[i].atlas_offset;
        w.dims = regions[i].dims;
        w.bricks = regions[i].bricks;
        w.kinds = regions[i].occupancy_offset;
        w.ab = vec2(regions[i].lut_a, regions[i].lut_b);
        w.keep = select(KEEP_SELECTED, KEEP_UNSELECTED, (r.flags & REGION_KEEP_UNSELECTED) != 0u);
    }
    return w;
}

fn set_weight(w: Weight) {
    weight = w;
}

// The region drawn in the current region's samples (render::pack::companions: the
// selection's look where an exploded view rests, weighted by the degree of interest the
// current weight leaves over; focal::samples::dvr_classified), set per segment like the
// weight. What its samples need of its record, not the record: on llvmpipe a record in
// a private variable cost a third of the frame.
struct Companion {
    // The pair table of both looks (render::pack::pair_table; the current region's
    // width and a·t + b).
    table: u32,
    // The ray's interval inside it: outside, the region adds nothing. (naga_oil
    // refuses module field names that end in digits.)
    t_enter: f32,
    t_leave: f32,
    on: bool,
}

var<private> companion: Companion;

// The companion of region r on a ray from origin along dir (none when r has none).
fn set_companion(r: Region, origin: vec3<f32>, dir: vec3<f32>) {
    companion.on = (r.flags & REGION_COMPANION) != 0u;
    if companion.on {
        let c = regions[r.objects.z];
        let iv = region_interval(c, origin, dir);
        companion.t_enter = max(iv.x, 0.0);
        companion.t_leave = iv.y;
        companion.table = r.objects.y;
    }
}

fn no_companion() {
    companion.on = false;
}

fn pick_weight(a: Weight, b: Weight, second: bool) -> Weight {
    var w: Weight;
    for (var c = 0; c < 4; c++) {
        w.map[c] = select(a.map[c], b.map[c], second);
    }
    w.offset = select(a.offset, b.offset, second);
    w.dims = select(a.dims, b.dims, second);
    w.bricks = select(a.bricks, b.bricks, second);
    w.kinds = select(a.kinds, b.kinds, second);
    w.ab = select(a.ab, b.ab, second);
    w.keep = select(a.keep, b.keep, second);
    return w;
}

// The current weight at data voxel q. With DOI_CHANNEL the selection's normalised
// sample is `carried`, fetched with the data (render::pack::doi_channels). Otherwise it
// is sampled here; where the selection's brick holds one code (none selected, or all:
// most of a dataset) that gives the degree of interest without a sample (GPUs that
// branch skip the fetch; llvmpipe runs both sides of a branch, so there it saves
// nothing).
fn weight_at(q: vec3<f32>, carried: f32) -> f32 {
    if weight.keep == KEEP_NONE {
        return 1.0;
    }
#ifdef DOI_CHANNEL
    let t = carried;
#else
    let qs = (weight.map * vec4(q, 1.0)).xyz;
    let size = f32(weight.bricks.w);
    let b = min(vec3<u32>(max(floor((qs + 0.5) / size), vec3(0.0))), weight.bricks.xyz - 1u);
    let i = (b.z * weight.bricks.y + b.y) * weight.bricks.x + b.x;
    let kind = (occupancy_word(weight.kinds + i / 16u) >> (2u * (i % 16u))) & 3u;
    var t = f32(kind);
    if kind == 2u {
        t = trilinear_box(weight.offset.xyz, weight.dims.xyz, qs);
    }
#endif
    let doi = clamp(weight.ab.x * t + weight.ab.y, 0.0, 1.0);
    return select(doi, 1.0 - doi, weight.keep == KEEP_UNSELECTED);
}
