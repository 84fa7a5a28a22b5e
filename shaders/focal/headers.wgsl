#define_import_path focal::headers

// What the ray's interval loop reads of region i (render::gpu_types::GpuRegionHeader):
// from the scene's uniform buffer where every traversed region's header and every plane
// fit there (UNIFORM_HEADERS), else from the region records and planes in storage. The
// loop visits the regions in the same order in every lane, yet on llvmpipe each field
// read from a storage buffer cost a gather of the SIMD group's lanes; a uniform load at
// an index all lanes share is one load (64 exploded parts: 481 → 288 ms a frame).
// One accessor per group of fields, called where the loop needs it: a read from
// storage stays behind the tests that skip it (the bounding spheres).

#import focal::bindings::{scene, regions, planes}
#import focal::regions::cut_by_plane

// The sphere around the run of REGION_CLUSTER regions that region i begins.
fn cluster_of(i: u32) -> vec4<f32> {
#ifdef UNIFORM_HEADERS
    return scene.headers[i].cluster;
#else
    return regions[i].cluster;
#endif
}

// The bounding sphere of region i's polyhedron.
fn bounds_of(i: u32) -> vec4<f32> {
#ifdef UNIFORM_HEADERS
    return scene.headers[i].bounds;
#else
    return regions[i].bounds;
#endif
}

// plane_offset, plane_count, hole_offset, hole_count of region i.
fn planes_of(i: u32) -> vec4<u32> {
#ifdef UNIFORM_HEADERS
    return scene.headers[i].planes;
#else
    return vec4(regions[i].plane_offset, regions[i].plane_count, regions[i].hole_offset, regions[i].hole_count);
#endif
}

// mode, flags, bricked.x and projection group of region i.
fn kind_of(i: u32) -> vec4<u32> {
#ifdef UNIFORM_HEADERS
    return scene.headers[i].kind;
#else
    return vec4(regions[i].mode, regions[i].flags, regions[i].bricked.x, u32(regions[i].projection.z));
#endif
}

// The world step that advances region i's native step along `dir` (x), and its
// opacity-correction factor per unit step (y: a finer level's shorter steps each take
// less, Volume::opacity_reference; reference: PreparedRegion::world_step).
fn step_of(i: u32, dir: vec3<f32>) -> vec2<f32> {
#ifdef UNIFORM_HEADERS
    let h = scene.headers[i];
    let native = h.native[0].xyz * dir.x + h.native[1].xyz * dir.y + h.native[2].xyz * dir.z;
    let native_step = h.native[0].w;
    let reference_length = h.native[1].w;
#else
    let native = (regions[i].to_native * vec4(dir, 0.0)).xyz;
    let native_step = regions[i].native_step;
    let reference_length = regions[i].reference_length;
#endif
    let ws = native_step / max(length(native), 1e-9);
    return vec2(ws, native_step / (ws * reference_length));
}

fn plane_at(k: u32) -> vec4<f32> {
#ifdef UNIFORM_HEADERS
    return scene.header_planes[k];
#else
    return planes[k];
#endif
}

// [t0, t1] of the ray inside the `count` half-spaces from plane `offset`; t0 > t1 when
// it misses (reference: region::ray_convex; focal::regions::convex_interval).
fn planes_interval(offset: u32, count: u32, origin: vec3<f32>, dir: vec3<f32>) -> vec2<f32> {
    var iv = vec2(-3.4e38, 3.4e38);
    for (var i = 0u; i < count; i++) {
        iv = cut_by_plane(iv, plane_at(offset + i), origin, dir);
    }
    return iv;
}
