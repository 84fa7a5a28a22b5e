#define_import_path focal::two_level

// Two-level rendering in the march (src/region/appearance.rs; reference: trace::State::part and
// trace::Gathered): the segment of a segmented region the ray is in, what it has
// gathered, and one sample of it by its part's mode.

#import focal::types::{Region, MODE_ISO, MODE_OFF}
#import focal::bindings::{scene, regions}
#import focal::camera::Ray
#import focal::regions::to_voxel
#import focal::sampling::{lut_texel, trilinear, nearest_code, count_sample}
#import focal::transfer::classify
#import focal::compositing::composite
#import focal::segments::{DONE, HAS_PREV}
#import focal::samples::{is_projection, projected, dvr_classified, iso_surface, iso_hit, projection_takes}

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
    let candidates = lut_texel(labels.lut_offset + code, scene.lut_atlas_width);
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
}

// Ends the open segment, whose part record is `part`: a projection part emits its value
// as one sample (reference: trace::close).
fn close_segment(r: Region, part: Region, open: ptr<function, Open>, acc: vec4<f32>) -> vec4<f32> {
    var out = acc;
    let o = *open;
    if o.part < r.objects.y && o.count > 0u && is_projection(part.mode) {
        let rgba = classify(part, projected(part.mode, o.max, o.min, o.sum, o.count), scene.lut_atlas_width);
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
        *part = regions[r.objects.x + k];
    }
    if (*part).mode == MODE_OFF || ((*open).flags & DONE) != 0u {
        return out;
    }
#ifdef HAS_PROJECTION
    if is_projection((*part).mode) {
        if projection_takes(*part, v) {
            (*open).max = max((*open).max, v);
            (*open).min = min((*open).min, v);
            (*open).sum += v;
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
    out = dvr_classified(*part, q, v, classify(*part, v, scene.lut_atlas_width), 1.0, ratio, ray, t, out);
#endif
    return out;
}

// The record of the open segment's part (a blank one before the first segment).
fn open_part(r: Region, o: Open) -> Region {
    var part: Region;
    if o.part < r.objects.y {
        part = regions[r.objects.x + o.part];
    }
    return part;
}
#endif
