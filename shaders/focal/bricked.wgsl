#define_import_path focal::bricked

// Sampling bricked volumes through their page tables (render::bricked: the CPU
// reference of the look-up is page_table::PageTree::locate). A region's coarse index
// q_C becomes the level-0 index q = (q_C + ½)·2^C − ½; the tree of the drawn bricks is
// descended from the top node holding q while nodes have children, keeping the last
// page that is not missing. The answer holds over the box of the last node visited,
// kept per ray (consecutive samples mostly stay in one brick).

#import focal::types::Region
#import focal::bindings::{pages, brick_cache, volume_sampler}

const BRICKED_COARSE: u32 = 0u;
const BRICKED_EMPTY: u32 = 1u;
const BRICKED_TEXEL: u32 = 2u;
// Page codes: 0 missing, EMPTY_PAGE | lowest code empty, slot + 2 in the atlas.
const EMPTY_PAGE: u32 = 0x80000000u;
// Words before the page directory (render::bricked::atlas::PAGE_HEADER).
const PAGE_HEADER: u32 = 8u;

// The cached answer: the region's directory entry (0: none), its level-0 box, what
// it is, and for a brick the level, the level's dims and texel = clamp(q_k) + shift.
var<private> bc_entry: u32 = 0u;
var<private> bc_lo: vec3<f32>;
var<private> bc_hi: vec3<f32>;
var<private> bc_kind: u32 = 0u;
var<private> bc_level: u32 = 0u;
var<private> bc_dims: vec3<f32>;
var<private> bc_shift: vec3<f32>;
var<private> bc_code: f32 = 0.0;
// A brick's visible 8³ sub-blocks (bit x + 4y + 16z) and its owned box's origin in
// level-k voxels (b·B).
var<private> bc_mask: vec2<u32>;
var<private> bc_origin: vec3<f32>;
// 1 / the brick atlas's size (from the page buffer's header, read at a look-up).
var<private> bc_inv: vec3<f32>;
// Words per node (render::bricked::page_table::NODE) and the sub-block edge.
const NODE: u32 = 4u;
const SUB_BLOCK: f32 = 8.0;
// The ray's step at its level over the coarse step, 2^(L − C) (set per ray).
var<private> bricked_step: f32 = 1.0;

fn set_bricked_step(f: f32) {
    bricked_step = f;
}

fn bricked_step_factor() -> f32 {
    return bricked_step;
}

fn is_bricked(r: Region) -> bool {
    return r.bricked.x != 0u;
}

fn level_zero(r: Region, qc: vec3<f32>) -> vec3<f32> {
    return (qc + 0.5) * r.bricked_scale.x - 0.5;
}

fn level_dims(tree: u32, k: u32) -> vec3<u32> {
    let at = tree + 4u + 4u * k;
    return vec3<u32>(pages[at], pages[at + 1u], pages[at + 2u]);
}

fn clamped_index(q0: vec3<f32>, k: u32, dims: vec3<u32>) -> vec3<f32> {
    return clamp((q0 + 0.5) / f32(1u << k) - 0.5, vec3(0.0), vec3<f32>(dims) - 1.0);
}

fn brick_at(q0: vec3<f32>, k: u32, dims: vec3<u32>, size: u32) -> vec3<u32> {
    let b = vec3<u32>(max(floor((clamped_index(q0, k, dims) + 0.5) / f32(size)), vec3(0.0)));
    return min(b, (dims + size - 1u) / size - 1u);
}

// Looks q0 (level-0 index) up in r's tree unless the cached answer holds.
fn bricked_locate(r: Region, q0: vec3<f32>) {
    if bc_entry == r.bricked.x && all(q0 >= bc_lo) && all(q0 < bc_hi) {
        return;
    }
    let tree = pages[PAGE_HEADER + r.bricked.x - 1u];
    let top = pages[tree];
    let tb = vec3<u32>(pages[tree + 1u], pages[tree + 2u], pages[tree + 3u]);
    let size = r.bricked.y;
    var k = top;
    var dims = level_dims(tree, k);
    var b = brick_at(q0, k, dims, size);
    var node = tree + 4u + 4u * (top + 1u) + NODE * ((b.z * tb.y + b.y) * tb.x + b.x);
    bc_kind = BRICKED_COARSE;
    for (var i = 0u; i <= top; i++) {
        let page = pages[node];
        if page >= EMPTY_PAGE {
            bc_kind = BRICKED_EMPTY;
            bc_code = f32(page - EMPTY_PAGE);
            bc_level = k;
        } else if page >= 2u {
            let s = page - 2u;
            let g = vec3<u32>(pages[0], pages[1], pages[2]);
            let origin = vec3<f32>(vec3<u32>(s % g.x, (s / g.x) % g.y, s / (g.x * g.y)) * pages[3]);
            bc_kind = BRICKED_TEXEL;
            bc_level = k;
            bc_dims = vec3<f32>(dims);
            bc_shift = origin + f32(r.bricked.z) + 0.5 - vec3<f32>(b * size);
            bc_mask = vec2<u32>(pages[node + 2u], pages[node + 3u]);
            bc_origin = vec3<f32>(b * size);
            bc_inv = vec3(bitcast<f32>(pages[4]), bitcast<f32>(pages[5]), bitcast<f32>(pages[6]));
        }
        let children = pages[node + 1u];
        if children == 0u || k == 0u {
            break;
        }
        let below = level_dims(tree, k - 1u);
        let bb = brick_at(q0, k - 1u, below, size);
        let c = min(select(bb - 2u * b, vec3(0u), bb < 2u * b), vec3(1u));
        node = tree + children + NODE * (c.x + 2u * c.y + 4u * c.z);
        k -= 1u;
        dims = below;
        b = bb;
    }
    // The box of the last node, open past the level's first and last bricks.
    let span = f32(size << k);
    let n = (dims + size - 1u) / size;
    bc_lo = select(vec3<f32>(b) * span - 0.5, vec3(-3.4e38), b == vec3(0u));
    bc_hi = select(vec3<f32>(b + 1u) * span - 0.5, vec3(3.4e38), b + 1u >= n);
    bc_entry = r.bricked.x;
}

// After bricked_locate of a brick: the atlas texture coordinate of q0.
fn bricked_uvw(q0: vec3<f32>) -> vec3<f32> {
    return bricked_texel(q0) * bc_inv;
}

// After bricked_locate: the atlas texel of q0 in the located brick.
fn bricked_texel(q0: vec3<f32>) -> vec3<f32> {
    return clamp((q0 + 0.5) / f32(1u << bc_level) - 0.5, vec3(0.0), bc_dims - 1.0) + bc_shift;
}

// The ray parameter where a ray at index q (t, moving qd voxels per unit t) leaves the
// box [lo, hi] (reference: BrickGrid's exits; shared by the in-memory bricks).
fn box_exit(lo: vec3<f32>, hi: vec3<f32>, q: vec3<f32>, qd: vec3<f32>, t: f32) -> f32 {
    var exit = 3.4e38;
    for (var a = 0; a < 3; a++) {
        if qd[a] > 1e-12 {
            exit = min(exit, (hi[a] - q[a]) / qd[a]);
        } else if qd[a] < -1e-12 {
            exit = min(exit, (lo[a] - q[a]) / qd[a]);
        }
    }
    return t + max(exit, 0.0);
}

// After bricked_locate: the ray parameter where it leaves the answer's box (coarse
// index q_C, voxels qd per unit t), at most `coarse_exit`.
fn bricked_box_exit(r: Region, qc: vec3<f32>, qd: vec3<f32>, t: f32, coarse_exit: f32) -> f32 {
    let s = r.bricked_scale.x;
    let lo = (bc_lo + 0.5) / s - 0.5;
    let hi = (bc_hi + 0.5) / s - 0.5;
    return min(box_exit(lo, hi, qc, qd, t), coarse_exit);
}

// After bricked_locate of a brick: its sub-block holding q0 (level-k voxels of its lower
// corner).
fn sub_block_at(q0: vec3<f32>) -> vec3<f32> {
    let qk = clamp((q0 + 0.5) / f32(1u << bc_level) - 0.5, vec3(0.0), bc_dims - 1.0);
    return clamp(floor((qk + 0.5 - bc_origin) / SUB_BLOCK), vec3(0.0), vec3(3.0));
}

// After bricked_locate of a brick: whether q0's sub-block holds anything visible.
fn sub_block_visible(q0: vec3<f32>) -> bool {
    let s = vec3<u32>(sub_block_at(q0));
    let bit = s.x + 4u * s.y + 16u * s.z;
    let word = select(bc_mask.x, bc_mask.y, bit >= 32u);
    return ((word >> (bit % 32u)) & 1u) != 0u;
}

// After bricked_locate of a brick: the ray parameter where it leaves q0's sub-block
// (coarse index qc, voxels qd per unit t), at most `limit`.
fn sub_block_exit(r: Region, q0: vec3<f32>, qc: vec3<f32>, qd: vec3<f32>, t: f32, limit: f32) -> f32 {
    let lo_k = bc_origin + sub_block_at(q0) * SUB_BLOCK - 0.5;
    let f = f32(1u << bc_level) / r.bricked_scale.x;
    let lo = (lo_k + 0.5) * f - 0.5;
    let hi = (lo_k + SUB_BLOCK + 0.5) * f - 0.5;
    return min(box_exit(lo, hi, qc, qd, t), limit);
}

// After bricked_locate of a brick: the central-difference gradient at q0 from that brick
// alone (its apron of 2 holds every filter tap of the neighbours one voxel away), as
// sampling::index_gradient takes it: differences over `h` coarse voxels (h = 2^(L − C),
// one voxel of the ray's level L), here h·2^(C − k) voxels of the brick's level k, at
// most one (beyond, the difference is scaled to the same span).
fn bricked_gradient(r: Region, q0: vec3<f32>, h: f32) -> vec3<f32> {
    let qk = clamp((q0 + 0.5) / f32(1u << bc_level) - 0.5, vec3(0.0), bc_dims - 1.0);
    let want = h * r.bricked_scale.x / f32(1u << bc_level);
    let d = min(want, 1.0);
    var g = vec3(0.0);
    for (var a = 0; a < 3; a++) {
        var e = vec3(0.0);
        e[a] = d;
        let hi = clamp(qk + e, vec3(0.0), bc_dims - 1.0) + bc_shift;
        let lo = clamp(qk - e, vec3(0.0), bc_dims - 1.0) + bc_shift;
        g[a] = textureSampleLevel(brick_cache, volume_sampler, hi * bc_inv, 0.0).r - textureSampleLevel(brick_cache, volume_sampler, lo * bc_inv, 0.0).r;
    }
    return 0.5 * g * (want / d);
}
