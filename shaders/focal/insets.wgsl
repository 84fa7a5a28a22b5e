#define_import_path focal::insets

// Clip windows drawn in place in their dataset's region (render::pack::insets): inside a
// window's box the region's samples take the window's lookup table. The ray's interval
// in each window of the region is found once per segment (set_insets); each sample
// then chooses its table by comparing its ray parameter with those intervals: two
// comparisons and a select a window, where the windows as regions of their own cost a
// segment each (on llvmpipe the lanes of a SIMD group wait at every segment's end for
// the group's longest one).

#import focal::types::{Region, REGION_INSETS}
#import focal::bindings::regions
#import focal::regions::region_interval

#ifdef MANY_INSETS
// (render::pack::MAX_INSETS)
const INSET_SLOTS: u32 = 4u;
#else
const INSET_SLOTS: u32 = 1u;
#endif

// The current region's windows on this ray: the ray's interval in each (empty where none)
// and the window's table offset in the lookup atlas. (Arrays a loop of constant length
// reads: the compiler unrolls it and keeps them in registers.)
struct Insets {
    enter: array<f32, INSET_SLOTS>,
    leave: array<f32, INSET_SLOTS>,
    lut: array<u32, INSET_SLOTS>,
}

var<private> insets: Insets;

// The windows region r draws in place, on the ray from origin along dir (none when r
// draws none). (Each in its own slot: slots written at an index the loop computes
// would keep the arrays in memory, and each sample reads them.)
fn set_insets(r: Region, origin: vec3<f32>, dir: vec3<f32>) {
    let on = (r.flags & REGION_INSETS) != 0u;
    for (var i = 0u; i < INSET_SLOTS; i++) {
        insets.enter[i] = 3.4e38;
        insets.leave[i] = -3.4e38;
        insets.lut[i] = r.lut_offset;
        let record = r.objects[i];
        if on && record != 0u {
            let w = regions[record - 1u];
            let iv = region_interval(w, origin, dir);
            insets.enter[i] = max(iv.x, 0.0);
            insets.leave[i] = iv.y;
            insets.lut[i] = w.lut_offset;
        }
    }
}

// The table offset of the sample at ray parameter t of a region whose own is `own`
// (windows are disjoint: at most one holds t).
fn inset_lut(own: u32, t: f32) -> u32 {
    var lut = own;
    for (var i = 0u; i < INSET_SLOTS; i++) {
        lut = select(lut, insets.lut[i], t >= insets.enter[i] && t <= insets.leave[i]);
    }
    return lut;
}
