#define_import_path focal::bricked

// Sampling bricked volumes through their page tables (render::bricked: the CPU
// reference of the look-up is page_table::PageTree::locate). A region's coarse index
// q_C becomes the level-0 index q = (q_C + ½)·2^C − ½; its level-0 brick b₀ names the
// directory word (b₀ >> G) and, where that is a block, the block's word for the ray's
// level l (capped at G) at b₀ >> l: the finest drawn brick of level l or coarser
// holding q (resolved on the CPU), the level m over whose brick the answer holds, and
// the brick's atlas slot. Two reads and no loop or cache: llvmpipe
// runs every branch in every lane and one pass of every loop, so anything conditional
// costs every sample.

#import focal::types::Region
#import focal::bindings::{pages, brick_cache, volume_sampler}

const BRICKED_COARSE: u32 = 0u;
const BRICKED_EMPTY: u32 = 1u;
const BRICKED_TEXEL: u32 = 2u;
const BRICKED_BLOCK: u32 = 3u;
// Words before the page directory (render::bricked::atlas::PAGE_HEADER).
const PAGE_HEADER: u32 = 8u;
// Bits of a slot coordinate in a page word.
const SLOT_BITS: u32 = 7u;

// The answer of the last look-up: its level-0 box, what it is, and for a brick the
// level, the level's dims and texel = clamp(q_k) + shift.
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
// 1 / the brick atlas's size (from the page buffer's header).
var<private> bc_inv: vec3<f32>;
const SUB_BLOCK: f32 = 8.0;
// Words before a volume's page tree: its levels' gradient normalisation
// (render::bricked::atlas::GRADIENT_NORMS).
const GRADIENT_NORMS: u32 = 16u;
// The ray's step at its level over the coarse step, 2^(L − C), and the largest gradient
// of level L (set per ray).
var<private> bricked_step: f32 = 1.0;
var<private> bricked_gradient_norm: f32 = 1.0;
// The finest level c the ray reads (its footprint's: no data finer than it needs, at
// most the directory's G), and where a block's words of level c start: (2^(G−c))³ of
// them after 8^G + … + 8^(G−c+1) (page_table::block_offset). Per ray, not per look-up.
var<private> bricked_cap: u32 = 0u;
var<private> bricked_block_offset: u32 = 0u;
// The brick atlas's header, the same for every look-up of every region, read once with
// the ray's level: the slot edge, the masks' first word and the slot grid's x and y.
// (Only the atlas's words: a region's own, such as its page tree, are read per look-up,
// since a ray may cross bricked regions of different volumes.)
var<private> bricked_atlas: vec4<u32>;

// Sets the ray's level l (of 0 … C) in bricked region r, and the finest level it reads
// (`cap`: l, or under a lens with context steps the lens's footprint's level where it is
// finer); returns its step factor.
fn set_bricked_level(r: Region, l: f32, cap: f32) -> f32 {
    let f = exp2(l - f32(r.bricked.w));
    bricked_step = f;
    let g = r.bricked_dims.w;
    bricked_cap = min(u32(max(cap, 0.0)), g);
    bricked_block_offset = ((1u << (3u * (g + 1u))) - (1u << (3u * (g - bricked_cap + 1u)))) / 7u;
    let tree = pages[PAGE_HEADER + r.bricked.x - 1u];
    bricked_gradient_norm = bitcast<f32>(pages[tree - GRADIENT_NORMS + u32(l)]);
    bricked_atlas = vec4(pages[3], pages[7], pages[0], pages[1]);
    bc_inv = vec3(bitcast<f32>(pages[4]), bitcast<f32>(pages[5]), bitcast<f32>(pages[6]));
    return f;
}

// The largest gradient magnitude of the ray's level (the normalisation of a bricked
// region's gradients, BrickedDataset::gradient_max).
fn bricked_gradient_max() -> f32 {
    return bricked_gradient_norm;
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

// Voxel dims of level k of a pyramid whose levels halve exactly (⌈n/2ᵏ⌉).
fn level_dims(d0: vec3<u32>, k: u32) -> vec3<u32> {
    return (d0 + (1u << k) - 1u) >> vec3(k);
}

// Bricks of `size` voxels along each axis of `dims`.
fn brick_count(dims: vec3<u32>, size: u32) -> vec3<u32> {
    return vec3<u32>(ceil(vec3<f32>(dims) / f32(size)));
}

// Page look-ups of this ray (VIEW_DEBUG_COUNTS).
var<private> page_lookups: u32 = 0u;

fn page_lookup_count() -> u32 {
    return page_lookups;
}

// Looks q0 (level-0 index) up in r's page table.
fn bricked_locate(r: Region, q0: vec3<f32>) {
    page_lookups += 1u;
    let tree = pages[PAGE_HEADER + r.bricked.x - 1u];
    let size = r.bricked.y;
    let d0 = r.bricked_dims.xyz;
    let g = r.bricked_dims.w;
    let fsize = f32(size);
    let b0 = min(vec3<u32>(max(floor((clamp(q0, vec3(0.0), vec3<f32>(d0) - 1.0) + 0.5) / fsize), vec3(0.0))), brick_count(d0, size) - 1u);
    let bg = b0 >> vec3(g);
    let ng = brick_count(level_dims(d0, g), size);
    var word = pages[tree + (bg.z * ng.y + bg.y) * ng.x + bg.x];
    // (The block's words of the ray's level c.)
    let c = bricked_cap;
    let w = 1u << (g - c);
    let l = (b0 >> vec3(c)) - bg * w;
    let in_block = pages[tree + (word & 0x3fffffffu) + bricked_block_offset + (l.z * w + l.y) * w + l.x];
    word = select(word, in_block, (word >> 30u) == BRICKED_BLOCK);
    let kind = word >> 30u;
    let k = (word >> 26u) & 15u;
    let m = (word >> 22u) & 15u;
    let bk = b0 >> vec3(k);
    bc_kind = kind;
    bc_level = k;
    bc_code = f32(word & 0xffffu);
    bc_dims = vec3<f32>(level_dims(d0, k));
    let slot = vec3<u32>(word & 127u, (word >> SLOT_BITS) & 127u, (word >> (2u * SLOT_BITS)) & 127u);
    let edge = bricked_atlas.x;
    bc_origin = vec3<f32>(bk * size);
    bc_shift = vec3<f32>(slot * edge) + f32(r.bricked.z) + 0.5 - bc_origin;
    let mask_at = bricked_atlas.y + 2u * (slot.x + bricked_atlas.z * (slot.y + bricked_atlas.w * slot.z));
    bc_mask = vec2<u32>(pages[mask_at], pages[mask_at + 1u]);
    // The box of level m's brick, open past the level's first and last bricks.
    let bm = b0 >> vec3(m);
    let span = f32(size << m);
    let n = brick_count(level_dims(d0, m), size);
    bc_lo = select(vec3<f32>(bm) * span - 0.5, vec3(-3.4e38), bm == vec3(0u));
    bc_hi = select(vec3<f32>(bm + 1u) * span - 0.5, vec3(3.4e38), bm + 1u >= n);
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
