#define_import_path focal::insets

// Clip windows drawn in place in their dataset's region (render::pack::insets): inside a
// window's box the region's samples take the window's lookup table. The ray's interval
// in each window of the region is found once per segment (set_insets); each sample
// then chooses its table by comparing its ray parameter with those intervals: two
// comparisons and a select a window, where the windows as regions of their own cost a
// segment each (on llvmpipe the lanes of a SIMD group wait at every segment's end for
// the group's longest one).
//
// The windows' boxes come from the scene's uniform buffer (SceneInfo.insets), in a loop
// of constant length that the compiler unrolls: every lane reads the same planes. Read
// through the region's record (its windows' records, then their planes in the storage
// buffer, at addresses each lane loaded for itself), the same intervals once per
// segment cost more than all the samples' choices: one window ×1.09 of the frame
// without it, four ×1.36, against ×1.05 and ×1.04 (bench --windows, llvmpipe on an AMD
// EPYC, 2026-12-07).

#import focal::types::MAX_INSETS
#import focal::bindings::scene
#import focal::regions::cut_by_plane

// The current region's windows on this ray, one in each component (MAX_INSETS): the
// ray's interval in each (empty where none) and the window's table offset in the
// lookup atlas. (Vectors read at constant components: registers.)
struct Insets {
    enter: vec4<f32>,
    leave: vec4<f32>,
    lut: vec4<u32>,
}

var<private> insets: Insets;

// The windows drawn in place in region record `record`, whose own table is at `own`,
// on the ray from origin along dir (none where it draws none).
fn set_insets(record: u32, own: u32, origin: vec3<f32>, dir: vec3<f32>) {
    var enter = vec4(3.4e38);
    var leave = vec4(-3.4e38);
    var lut = vec4(own);
    for (var w = 0u; w < MAX_INSETS; w++) {
        if w < scene.inset_count && scene.insets[w].host == record {
            var iv = vec2(-3.4e38, 3.4e38);
            for (var i = 0u; i < 6u; i++) {
                iv = cut_by_plane(iv, scene.insets[w].planes[i], origin, dir);
            }
            enter[w] = iv.x;
            leave[w] = iv.y;
            lut[w] = scene.insets[w].lut_offset;
        }
    }
    insets = Insets(enter, leave, lut);
}

// The table offset of the sample at ray parameter t of a region whose own is `own`
// (windows are disjoint: at most one holds t). With one window in the scene it is the
// first (SEVERAL_INSETS: more): the others' comparisons cost a one-window view ×1.055
// → ×1.015 of its frame without windows (bench --windows, llvmpipe on an AMD EPYC,
// 2026-12-07; a branch on the uniform count instead read ×1.07–1.09).
fn inset_lut(own: u32, t: f32) -> u32 {
    var lut = select(own, insets.lut.x, t >= insets.enter.x && t <= insets.leave.x);
#ifdef SEVERAL_INSETS
    lut = select(lut, insets.lut.y, t >= insets.enter.y && t <= insets.leave.y);
    lut = select(lut, insets.lut.z, t >= insets.enter.z && t <= insets.leave.z);
    lut = select(lut, insets.lut.w, t >= insets.enter.w && t <= insets.leave.w);
#endif
    return lut;
}
