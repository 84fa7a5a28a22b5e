#define_import_path focal::lens

// Ray generation under the view's lenses (reference: src/lens/stack.rs, which holds the
// algorithm and the paper's equations; keep the two in step). Lens coordinates:
// s = (x·aspect, y) in normalised device coordinates, one unit = half the view height.

#import focal::types::{Lens, LENS_DATA}
#import focal::sampling::set_lod
#import focal::bindings::{view, settings, feature_fields}
#import focal::camera::{Ray, pixel_ray, camera_ray}

const LENS_MAGNIFIER: u32 = 0u;
const LENS_SAMPLING: u32 = 1u;
const LENS_ANGULAR: u32 = 2u;
const SHAPE_SQUARE: u32 = 1u;
const SHAPE_POLYGON: u32 = 2u;
const SHAPE_FEATURE: u32 = 3u;
const PROFILE_SIMPLE: u32 = 0u;
const PROFILE_LINEAR: u32 = 1u;
const SAMPLING_TABLE: u32 = 64u;
// Floats before a silhouette's distances: centroid, equivalent radius, in view (feature.rs).
const FIELD_HEADER: u32 = 4u;
// Mip levels below this are level 0 (lens::antialias::LEVEL_DEAD_ZONE).
const LEVEL_DEAD_ZONE: f32 = 0.00390625;

fn view_aspect() -> f32 {
    return view.viewport.z / view.viewport.w;
}

fn to_lens(uv: vec2<f32>) -> vec2<f32> {
    return vec2((uv.x * 2.0 - 1.0) * view_aspect(), 1.0 - uv.y * 2.0);
}

fn lens_uv(s: vec2<f32>) -> vec2<f32> {
    return vec2((s.x / view_aspect() + 1.0) * 0.5, (1.0 - s.y) * 0.5);
}

fn outline_vertex(base: u32, i: u32) -> vec2<f32> {
    let v = settings.lens_data[base + i / 2u];
    if (i & 1u) == 0u {
        return v.xy;
    }
    return v.zw;
}

// Signed distance to the drawn outline (negative inside, even-odd rule).
fn outline_distance(base: u32, n: u32, p: vec2<f32>) -> f32 {
    var d2 = 3.4e38;
    var inside = false;
    for (var i = 0u; i < n; i++) {
        let a = outline_vertex(base, i);
        let b = outline_vertex(base, (i + 1u) % n);
        let e = b - a;
        let t = clamp(dot(p - a, e) / max(dot(e, e), 1e-12), 0.0, 1.0);
        let q = p - a - e * t;
        d2 = min(d2, dot(q, q));
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
    }
    if inside {
        return -sqrt(d2);
    }
    return sqrt(d2);
}

// Signed distance to a feature's silhouette at lens coordinates s: bilinear between
// cell centres, beyond the grid the edge value plus the distance to the edge
// (reference: FeatureField::distance_at).
fn feature_distance(base: u32, s: vec2<f32>) -> f32 {
    let g = settings.lens_data[base];
    let h = settings.lens_data[base + 1u];
    let cols = u32(g.x);
    let rows = u32(g.y);
    let gx = (s.x - g.z) / h.x;
    let gy = (g.w - s.y) / h.y;
    let x = clamp(gx, 0.0, g.x - 1.0);
    let y = clamp(gy, 0.0, g.y - 1.0);
    let beyond = length(vec2((gx - x) * h.x, (gy - y) * h.y));
    let x0 = u32(floor(x));
    let y0 = u32(floor(y));
    let x1 = min(x0 + 1u, cols - 1u);
    let y1 = min(y0 + 1u, rows - 1u);
    let fx = x - f32(x0);
    let fy = y - f32(y0);
    let o = u32(h.z) + FIELD_HEADER;
    let top = mix(feature_fields[o + y0 * cols + x0], feature_fields[o + y0 * cols + x1], fx);
    let bottom = mix(feature_fields[o + y1 * cols + x0], feature_fields[o + y1 * cols + x1], fx);
    return mix(top, bottom, fy) + beyond;
}

// (Each kind's and shape's code only where the view has such a lens, shader defs
// HAS_MAGNIFIER, HAS_SAMPLING_LENS, HAS_ANGULAR_LENS, HAS_POLYGON_LENS, HAS_FEATURE_LENS
// (render::pipeline::lens_kinds): llvmpipe runs all of it in every lane, for five rays
// a pixel with anti-aliasing.)
fn radial(lens: Lens, base: u32, v: vec2<f32>) -> f32 {
#ifdef HAS_FEATURE_LENS
    if lens.codes.y == SHAPE_FEATURE {
        return lens.geometry.z + feature_distance(base, lens.geometry.xy + v);
    }
#endif
    if lens.codes.y == SHAPE_SQUARE {
        return max(abs(v.x), abs(v.y));
    }
#ifdef HAS_POLYGON_LENS
    if lens.codes.y == SHAPE_POLYGON {
        return lens.geometry.z + outline_distance(base, lens.codes.w, v);
    }
#endif
    return length(v);
}

// LaMar's source radius rho(r) and the magnifier's blend weight (profile.rs).
fn source_radius(profile: u32, r: f32, lr: f32, lb: f32, m: f32) -> f32 {
    if r <= lr {
        return r / m;
    }
    if profile == PROFILE_SIMPLE || lb <= 0.0 || r >= lr + lb {
        return r;
    }
    let p0 = lr / m;
    let p3 = lr + lb;
    let u = (r - lr) / lb;
    if profile == PROFILE_LINEAR {
        return p0 + (p3 - p0) * u;
    }
    let p1 = p0 + lb / (3.0 * m);
    let p2 = p3 - lb / 3.0;
    let w = 1.0 - u;
    return w * w * w * p0 + 3.0 * w * w * u * p1 + 3.0 * w * u * u * p2 + u * u * u * p3;
}

fn blend_weight(profile: u32, r: f32, lr: f32, lb: f32, m: f32) -> f32 {
    if r <= lr {
        return 0.0;
    }
    if abs(m - 1.0) < 1e-6 {
        return 1.0;
    }
    let inv = 1.0 / m;
    return clamp((source_radius(profile, r, lr, lb, m) / r - inv) / (1.0 - inv), 0.0, 1.0);
}

// Magnifier (magnifier.rs, Wang et al. eq. 1-3).
fn bend(lens: Lens, central: Ray, below: Ray, r: f32) -> Ray {
    let c = central.dir;
    let p_o = central.origin + c * lens.params.x;
    let along = dot(below.dir, c);
    if along <= 1e-6 {
        return below;
    }
    let p = below.origin + below.dir * (dot(p_o - below.origin, c) / along);
    let focused = c + (p_o - p) * lens.params.y;
    let normal = below.dir / along;
    let w = blend_weight(lens.codes.z, r, lens.geometry.z, lens.geometry.w, lens.params.z);
    let dir = normalize(focused * (1.0 - w) + normal * w);
    let back = dot(central.origin - p, c) / dot(dir, c);
    if back > 0.0 {
        return Ray(p + dir * back, dir);
    }
    return Ray(p, dir);
}

fn sampling_source(base: u32, r: f32) -> f32 {
    let x = clamp(r, 0.0, 1.0) * f32(SAMPLING_TABLE - 1u);
    let i = min(u32(floor(x)), SAMPLING_TABLE - 2u);
    let f = x - f32(i);
    let a = settings.lens_data[base + i / 4u][i % 4u];
    let b = settings.lens_data[base + (i + 1u) / 4u][(i + 1u) % 4u];
    return a * (1.0 - f) + b * f;
}

// Angular fisheye (angular.rs).
fn fisheye(central: Ray, v: vec2<f32>, lr: f32, half_angle: f32) -> Ray {
    let r = length(v);
    if r <= 1e-9 {
        return central;
    }
    let theta = r / lr * half_angle;
    let side = view.world_from_view[0].xyz * (v.x / r) + view.world_from_view[1].xyz * (v.y / r);
    let u = side - central.dir * dot(side, central.dir);
    let ul = length(u);
    var un = vec3(0.0);
    if ul > 0.0 {
        un = u / ul;
    }
    return Ray(central.origin, normalize(central.dir * cos(theta) + un * sin(theta)));
}

// The ray of a pixel under the view's lenses; a zero direction means no ray.
fn lens_ray(uv: vec2<f32>) -> Ray {
    let s = to_lens(uv);
    var ray = camera_ray(uv);
    for (var i = 0u; i < settings.lens_count; i++) {
        var lens = settings.lenses[i];
        let base = i * LENS_DATA;
        // A feature lens is centred on its silhouette and sized by it; a feature out of
        // view leaves the rays alone.
#ifdef HAS_FEATURE_LENS
        if lens.codes.y == SHAPE_FEATURE {
            let o = u32(settings.lens_data[base + 1u].z);
            if feature_fields[o + 3u] < 0.5 {
                continue;
            }
            lens.geometry = vec4(feature_fields[o], feature_fields[o + 1u], feature_fields[o + 2u], lens.geometry.w);
        }
#endif
        let centre = lens.geometry.xy;
        let lr = lens.geometry.z;
        let v = s - centre;
        let r = radial(lens, base, v);
        // (One kind per lens: the `if`s exclude each other.)
#ifdef HAS_MAGNIFIER
        if lens.codes.x == LENS_MAGNIFIER {
            var reach = lr + lens.geometry.w;
            if lens.codes.z == PROFILE_SIMPLE {
                reach = lr;
            }
            if r < reach {
                ray = bend(lens, camera_ray(lens_uv(centre)), ray, r);
            }
        }
#endif
#ifdef HAS_SAMPLING_LENS
        if lens.codes.x == LENS_SAMPLING {
            if r < lr && r > 0.0 {
                let rho = sampling_source(base, r / lr) * lr;
                ray = camera_ray(lens_uv(centre + v * (rho / r)));
            }
        }
#endif
#ifdef HAS_ANGULAR_LENS
        if lens.codes.x == LENS_ANGULAR {
            if r < lr {
                ray = fisheye(camera_ray(lens_uv(centre)), v, lr, lens.params.x);
            } else if lens.params.y > 0.5 {
                return Ray(ray.origin, vec3(0.0));
            }
        }
#endif
    }
    return ray;
}

// Anti-aliasing (reference: src/lens/antialias.rs, eq. 4). A ray by view depth z is the
// line x(z) = p + q·z; the rays of a pixel and its right and lower neighbours lie
// Δp_x + Δq_x·z and Δp_y + Δq_y·z apart at depth z; the footprint's longest extent is
// the largest singular value of that pair, and the mip level log2(1/mf) with mf its
// plain over its lensed value.
struct Spread {
    px: vec3<f32>,
    qx: vec3<f32>,
    py: vec3<f32>,
    qy: vec3<f32>,
    depth_start: f32,
    depth_per_t: f32,
}

var<private> lensed_spread: Spread;
var<private> plain_spread: Spread;
var<private> has_footprint: bool = false;

// The line of a ray by view depth: (p, q) with x(z) = p + q·z.
fn depth_line(r: Ray, forward: vec3<f32>) -> array<vec3<f32>, 2> {
    let q = r.dir / max(dot(r.dir, forward), 1e-6);
    return array<vec3<f32>, 2>(r.origin - q * dot(r.origin - view.world_position, forward), q);
}

fn spread_of(r: Ray, rx: Ray, ry: Ray) -> Spread {
    let forward = -view.world_from_view[2].xyz;
    let a = depth_line(r, forward);
    let b = depth_line(rx, forward);
    let c = depth_line(ry, forward);
    return Spread(b[0] - a[0], b[1] - a[1], c[0] - a[0], c[1] - a[1], dot(r.origin - view.world_position, forward), dot(normalize(r.dir), forward));
}

fn spread_extent(s: Spread, z: f32) -> f32 {
    let x = s.px + s.qx * z;
    let y = s.py + s.qy * z;
    let a = dot(x, x);
    let b = dot(x, y);
    let c = dot(y, y);
    let h = 0.5 * (a - c);
    return sqrt(max(0.5 * (a + c) + sqrt(h * h + b * b), 0.0));
}

// The backward differences (pixel minus its left and upper neighbours), px qx py qy.
var<private> backward_deltas: array<vec3<f32>, 4>;

// Prepares the pixel's footprint (no anti-aliasing where a right or lower neighbour
// has no ray; forward differences only where a left or upper one has none).
// One pixel right and one down, in uv.
// The uv offsets of a ray's right and lower neighbours: the pixels drawn, which are
// larger than the view's at a reduced resolution (render::reduced).
fn pixel_steps() -> array<vec2<f32>, 2> {
    let drawn = view.viewport.zw * max(settings.resolution, 1e-3);
    return array<vec2<f32>, 2>(vec2(1.0 / drawn.x, 0.0), vec2(0.0, 1.0 / drawn.y));
}

fn lens_footprint(uv: vec2<f32>, ray: Ray) {
    let steps = pixel_steps();
    let px = steps[0];
    let py = steps[1];
    let rx = lens_ray(uv + px);
    let ry = lens_ray(uv + py);
    if dot(rx.dir, rx.dir) == 0.0 || dot(ry.dir, ry.dir) == 0.0 {
        return;
    }
    lensed_spread = spread_of(ray, rx, ry);
    plain_spread = spread_of(camera_ray(uv), camera_ray(uv + px), camera_ray(uv + py));
    backward_deltas = array<vec3<f32>, 4>(lensed_spread.px, lensed_spread.qx, lensed_spread.py, lensed_spread.qy);
    let bx = lens_ray(uv - px);
    let by = lens_ray(uv - py);
    if dot(bx.dir, bx.dir) > 0.0 && dot(by.dir, by.dir) > 0.0 {
        let b = spread_of(ray, bx, by);
        backward_deltas = array<vec3<f32>, 4>(-b.px, -b.qx, -b.py, -b.qy);
    }
    has_footprint = true;
}

// Longer of |p + q·z| at the two depths.
fn reach(p: vec3<f32>, q: vec3<f32>, z0: f32, z1: f32) -> f32 {
    return max(length(p + q * z0), length(p + q * z1));
}

// Per axis the one-sided difference smaller over [t0, t1] (reference:
// Footprint::over): no footprint across a jump of the lens map.
fn choose_sides(t0: f32, t1: f32) {
    let z0 = lensed_spread.depth_start + lensed_spread.depth_per_t * t0;
    let z1 = lensed_spread.depth_start + lensed_spread.depth_per_t * t1;
    if reach(backward_deltas[0], backward_deltas[1], z0, z1) < reach(lensed_spread.px, lensed_spread.qx, z0, z1) {
        lensed_spread.px = backward_deltas[0];
        lensed_spread.qx = backward_deltas[1];
    }
    if reach(backward_deltas[2], backward_deltas[3], z0, z1) < reach(lensed_spread.py, lensed_spread.qy, z0, z1) {
        lensed_spread.py = backward_deltas[2];
        lensed_spread.qy = backward_deltas[3];
    }
}

// Mip level at ray parameter t.
fn lod_at(t: f32) -> f32 {
    let depth = lensed_spread.depth_start + lensed_spread.depth_per_t * t;
    let lensed = spread_extent(lensed_spread, depth);
    let plain = spread_extent(plain_spread, depth);
    // As the reference: no spread (rays meeting at a point) is no compression.
    if lensed <= 0.0 {
        return 0.0;
    }
    if plain <= 0.0 {
        return 3.0;
    }
    // (Below a 256th of a level, none: antialias::LEVEL_DEAD_ZONE.)
    let l = log2(lensed / plain);
    return select(min(l, 3.0), 0.0, l < LEVEL_DEAD_ZONE);
}

// Restricts the footprint to the ray's interval [t0, t1]: the lensed extent is convex in
// the depth (the largest singular value of a matrix affine in it) and the plain one
// affine, and the depth is affine in t, so
// their ratio is quasi-convex and its maximum over the interval lies at an end. Level 0
// at both ends means level 0 throughout: the per-sample work is skipped (exactly).
fn restrict_footprint(t0: f32, t1: f32) {
    if !has_footprint {
        return;
    }
    choose_sides(t0, t1);
    if lod_at(t0) <= 0.0 && lod_at(t1) <= 0.0 {
        has_footprint = false;
    }
}

// After restrict_footprint: whether the ray's mip level may leave 0 along it.
fn level_varies() -> bool {
    return has_footprint;
}

// Sets the mip level of the samples at ray parameter t.
fn update_lod(t: f32) {
#ifdef LENS_ANTIALIAS
    if has_footprint {
        set_lod(lod_at(t));
    }
#endif
}
