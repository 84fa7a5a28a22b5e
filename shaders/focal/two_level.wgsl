#define_import_path focal::two_level

// Two-level rendering in the march (src/region/appearance.rs; reference: trace::State::part and
// trace::Gathered): the segment of a segmented region the ray is in, what it has
// gathered, and one sample of it by its part's mode.

#import focal::types::{Region, MODE_ISO, MODE_OFF, REGION_ON_GRID, REGION_OCCUPANCY}
#import focal::bindings::{scene, regions, occupancy_word}
#import focal::camera::Ray
#import focal::regions::to_voxel
#import focal::sampling::{lut_texel, trilinear, trilinear_box, nearest_code, count_sample, at_full_resolution, brick_of}
#ifdef HAS_BRICKED
#import focal::bricked::{is_bricked, level_zero}
#endif
#import focal::transfer::classify
#import focal::compositing::composite
#import focal::segments::{DONE, HAS_PREV}
#import focal::samples::{is_projection, projected, dvr_classified, classified, iso_surface, iso_hit, projection_takes}

#ifdef HAS_TWO_LEVEL
// Two-level rendering (src/region/appearance.rs): the segment of a segmented region the ray is in
// and what it has gathered (reference: trace::State::part and trace::Gathered).
const NO_PART: u32 = 0xffffffffu;

struct Open {
    part: u32,
    max: f32,
    min: f32,
    sum: f32,
    count: u32,
    prev_t: f32,
    prev_v: f32,
    // HAS_PREV; DONE once an iso-surface part was hit in this segment.
    flags: u32,
}

fn fresh(part: u32) -> Open {
    return Open(part, -3.4e38, 3.4e38, 0.0, 0u, 0.0, 0.0, 0u);
}

// The part (object, or the rest: the last part) of a sample of segmented region r at
// world point p with normalised value v: the first candidate object of its label code
// whose value range holds v (reference: region::ObjectTable::object). `labels` is
// r's label record.
fn part_of(r: Region, labels: Region, p: vec3<f32>, v: f32) -> u32 {
    let code = nearest_code(labels, to_voxel(labels, p));
    let rest = r.objects.y - 1u;
    if code >= labels.lut_width {
        return rest;
    }
    let candidates = lut_texel(labels.lut_offset + code);
#ifdef VALUE_RANGES
    for (var i = 0; i < 4; i++) {
        let k = u32(candidates[i] + 0.5);
        if k == 0u {
            break;
        }
        let index = r.objects.x + k - 1u;
        if regions[index].value_lo <= v && v <= regions[index].value_hi {
            return k - 1u;
        }
    }
    return rest;
#else
    // No object in the scene has a value range: the first candidate takes every value
    // (reading the ranges, two loads in each lane at every sample, cost dvr + mip +
    // xray ×1.66 → ×1.57, bench --twolevel).
    let k = u32(candidates.x + 0.5);
    return select(rest, k - 1u, k != 0u);
#endif
}

// The class of label code `code` (twolevel::code_classes: codes of the same objects),
// from the texels after the label record's candidates.
fn code_class(labels: Region, code: u32) -> u32 {
    if code >= labels.lut_width {
        return 0xffffu;
    }
    return u32(lut_texel(labels.lut_offset + labels.lut_width + code).x + 0.5);
}

// Whether the cell of label voxel q may hold more than one label: its brick's bit in
// the label record's occupancy (render::pack, twolevel::boundary_bricks).
fn boundary_brick(labels: Region, q: vec3<f32>) -> bool {
    if (labels.flags & REGION_OCCUPANCY) == 0u {
        return true;
    }
    let b = brick_of(labels, q);
    let i = (b.z * labels.bricks.y + b.y) * labels.bricks.x + b.x;
    return ((occupancy_word(labels.occupancy_offset + i / 32u) >> (i % 32u)) & 1u) != 0u;
}

// The value of a sample of segmented region r at data voxel q (plain trilinear value v)
// from the voxels of its own label alone (reference: PreparedObjects::own_value): the
// trilinear weights of the cell's eight voxels renormalised over those with the label
// of q's nearest voxel, so no other object's values bleed into this one's beside their
// boundary. v where the cell holds one label, the labels are not on the data's grid
// (REGION_ON_GRID; for bricked data, on level 0's: the cell is level 0's), or the
// sample is from a mip level. The eight labels first: their values only at a boundary.
fn own_value(r: Region, labels: Region, q: vec3<f32>, v: f32) -> f32 {
#ifndef OWN_VALUES
    return v;
#else
    if (r.flags & REGION_ON_GRID) == 0u || !at_full_resolution() {
        return v;
    }
    var qi = q;
#ifdef HAS_BRICKED
    if is_bricked(r) {
        qi = level_zero(r, q);
    }
#endif
    if !boundary_brick(labels, qi) {
        return v;
    }
    let own_code = nearest_code(labels, qi);
    let own_class = code_class(labels, own_code);
    let last = labels.dims.xyz - 1.0;
    let base = floor(qi);
    let f = qi - base;
    var mine = 0u;
    for (var i = 0u; i < 8u; i++) {
        let o = vec3<f32>(f32(i & 1u), f32((i >> 1u) & 1u), f32((i >> 2u) & 1u));
        let code = nearest_code(labels, clamp(base + o, vec3(0.0), last));
        // (The class's texel only where the code differs.)
        if code == own_code || code_class(labels, code) == own_class {
            mine |= 1u << i;
        }
    }
    if mine == 255u || mine == 0u {
        return v;
    }
    var sum = 0.0;
    var weights = 0.0;
    for (var i = 0u; i < 8u; i++) {
        if (mine & (1u << i)) == 0u {
            continue;
        }
        let o = vec3<f32>(f32(i & 1u), f32((i >> 1u) & 1u), f32((i >> 2u) & 1u));
        let c = clamp(base + o, vec3(0.0), last);
        let w3 = abs(1.0 - o - f + 2.0 * o * f);
        let w = w3.x * w3.y * w3.z;
        var value = 0.0;
#ifdef HAS_BRICKED
        if is_bricked(r) {
            // (Level-0 voxel c as the region's coarse index: its centre, exact where its
            // level-0 brick is resident.)
            value = trilinear(r, (c + 0.5) / r.bricked_scale.x - 0.5);
        } else {
            value = trilinear_box(r.atlas_offset.xyz, r.dims.xyz, c);
        }
#else
        value = trilinear_box(r.atlas_offset.xyz, r.dims.xyz, c);
#endif
        sum += w * value;
        weights += w;
    }
    return select(v, sum / weights, weights > 0.0);
#endif
}

// Ends the open segment, whose part record is `part`: a projection part emits its value
// as one sample (reference: trace::close).
fn close_segment(r: Region, part: Region, open: ptr<function, Open>, acc: vec4<f32>) -> vec4<f32> {
    var out = acc;
    let o = *open;
    if o.part < r.objects.y && o.count > 0u && is_projection(part.mode) {
        let rgba = classify(part, projected(part.mode, o.max, o.min, o.sum, o.count));
        out = composite(acc, rgba.rgb, rgba.a);
    }
    *open = fresh(o.part);
    return out;
}

// Ends the open segment where the ray skips an empty brick: the next sample starts a
// new one (what the brick's own samples would have done: no part there draws).
fn end_segment(r: Region, part: Region, open: ptr<function, Open>, acc: vec4<f32>) -> vec4<f32> {
    let out = close_segment(r, part, open, acc);
    (*open).part = NO_PART;
    return out;
}

// One sample of segmented region r at voxel q (world: ray at t): a new segment where
// the part changes, then the part's mode (reference: the Some(objects) arm of trace).
// `labels` is r's label record; `part` holds the record of the open segment's part
// (loaded here when the part changes, so a segment reads it once).
fn two_level_sample(r: Region, labels: Region, part: ptr<function, Region>, open: ptr<function, Open>, q: vec3<f32>, ratio: f32, ray: Ray, t: f32, acc: vec4<f32>) -> vec4<f32> {
    count_sample();
    let v = trilinear(r, q);
    let k = part_of(r, labels, ray.origin + ray.dir * t, v);
    var out = acc;
    if k != (*open).part {
        out = close_segment(r, *part, open, out);
        (*open).part = k;
        *part = part_record(r, k);
    }
    if (*part).mode == MODE_OFF || ((*open).flags & DONE) != 0u {
        return out;
    }
#ifdef HAS_PROJECTION
    if is_projection((*part).mode) {
        let own = own_value(r, labels, q, v);
        if projection_takes(*part, own) {
            (*open).max = max((*open).max, own);
            (*open).min = min((*open).min, own);
            (*open).sum += own;
            (*open).count++;
        }
        return out;
    }
#endif
#ifdef HAS_ISO
    if (*part).mode == MODE_ISO {
        let vi = v - (*part).iso;
        if ((*open).flags & HAS_PREV) == 0u && vi >= 0.0 {
            // The segment starts inside the surface: the object's boundary is its surface.
            out = iso_surface(*part, q, ray.dir, out);
            (*open).flags |= DONE;
        } else if ((*open).flags & HAS_PREV) != 0u && (((*open).prev_v < 0.0) != (vi < 0.0)) {
            out = iso_hit(*part, ray, (*open).prev_t, (*open).prev_v, t, out);
            (*open).flags |= DONE;
        } else {
            (*open).prev_t = t;
            (*open).prev_v = vi;
            (*open).flags |= HAS_PREV;
        }
        return out;
    }
#endif
#ifdef HAS_DVR
    let own = own_value(r, labels, q, v);
    out = dvr_classified(*part, q, classified(own, classify(*part, own)), ratio, ray, t, out, false);
#endif
    return out;
}

// The record of part k of segmented region r: r's own with the part's look. A part's
// record is its region's but for the look (render::pack::pack_objects: the same volume,
// box, levels and bricks; a pack test holds it), so only the look is read, field by
// field: read whole, a part's record was a gather of every field in every lane at
// every sample where the part could change (llvmpipe runs such a branch in every lane):
// objects alike ×1.62–1.67 → ×1.55–1.59, dvr + mip + xray ×1.75–1.78 → ×1.65–1.68
// (bench --twolevel, two probes each beside the previous build).
fn part_record(r: Region, k: u32) -> Region {
    let i = r.objects.x + k;
    var p = r;
    p.mode = regions[i].mode;
    p.flags = regions[i].flags;
    p.lut_offset = regions[i].lut_offset;
    p.lut_width = regions[i].lut_width;
    p.lut_a = regions[i].lut_a;
    p.lut_b = regions[i].lut_b;
    p.iso = regions[i].iso;
    p.shading = regions[i].shading;
    p.context = regions[i].context;
    p.projection = regions[i].projection;
    return p;
}

// The record of the open segment's part (a blank one before the first segment).
fn open_part(r: Region, o: Open) -> Region {
    var part: Region;
    if o.part < r.objects.y {
        part = part_record(r, o.part);
    }
    return part;
}
#endif
