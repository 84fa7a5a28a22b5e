//! What a selection weight brings to the packing: its record (the degree of interest's
//! scale, the kinds of its bricks), its degree of interest in the second channel of its
//! data's texels ([`doi_channels`]), and the selection's look drawn in the samples of
//! the parts it rests in ([`companions`]).

use glam::Mat4;

use super::packed::{PackedScene, texel_colour};
use crate::reference::prepare::{PreparedLookup, PreparedRegion};
use crate::region::Mode;
use crate::region::meet;
use crate::render::gpu_types::{GpuRegion, mode, region_flags};

/// Per scene volume (`all`), the selection volume whose degree of interest can ride in
/// the second channel of its texels, so that one texture fetch gives a sample's value
/// and its weight (on llvmpipe the weight's own fetch and lookups cost a tenth of an
/// exploded view's frame at rest, and its selection needs no atlas room of its own).
/// `None` unless some region is weighted and every weighted region's selection lies on
/// its data's voxel grid (the same dimensions, the identity between their voxel
/// indices: the trilinear filter then weighs both channels alike, so the weight is the
/// reference's) and no volume has two selections.
pub fn doi_channels(prepared: &[PreparedRegion], all: &[std::sync::Arc<crate::volume::Volume>]) -> Option<Vec<Option<usize>>> {
    let mut channels = vec![None; all.len()];
    let mut any = false;
    for p in prepared {
        let Some(w) = &p.weight else { continue };
        let data = all.iter().position(|a| std::ptr::eq(a.as_ref(), p.volume))?;
        let selection = all.iter().position(|a| std::sync::Arc::ptr_eq(a, &w.weight.volume))?;
        let on_grid = w.weight.volume.dims() == p.volume.dims() && w.data_to_selection.abs_diff_eq(glam::Affine3A::IDENTITY, 1e-5);
        if !on_grid || channels[data].is_some_and(|s| s != selection) {
            return None;
        }
        channels[data] = Some(selection);
        any = true;
    }
    any.then_some(channels)
}

/// Draws region record `b` in the samples of region `a` ([`companions`]): `a` names it
/// (`objects.z`) and the pair table of both looks (`objects.y`, [`pair_table`]), and
/// skips only the bricks where neither draws.
pub(super) fn draw_in(out: &mut PackedScene, a: usize, b: usize) {
    out.regions[a].flags |= region_flags::COMPANION;
    out.regions[a].objects.y = pair_table(out, a, b);
    out.regions[a].objects.z = b as u32;
    merge_occupancy(out, a, b);
}

/// Appends the pair table of region records `a` and `b`, whose tables map a sample
/// alike (two looks of one volume: [`companions`]), and returns its offset: texel `i`
/// holds both looks' colours at texel `i` of their own tables as 16-bit normalised
/// numbers ([`unorm_pair`]), so that one filtered lookup classifies a sample under both
/// (`transfer.wgsl` filtered_looks). Each channel is off by at most 1/131070 (half
/// floats would keep more of a faint opacity but less of a nearly opaque one, whose
/// transparency the opacity correction raises to a power, and need a shader capability
/// that llvmpipe grants only with f16).
pub fn pair_table(out: &mut PackedScene, a: usize, b: usize) -> u32 {
    let (ra, rb) = (out.regions[a], out.regions[b]);
    let offset = out.lut.len() as u32;
    for i in 0..ra.lut_width.min(rb.lut_width) {
        let texel = unorm_pair(texel_colour(out.lut[(ra.lut_offset + i) as usize]), texel_colour(out.lut[(rb.lut_offset + i) as usize]));
        out.lut.push(texel);
    }
    offset
}

/// A pair table's texel: `first`'s colour then `second`'s (channels in 0…1), two
/// 16-bit normalised numbers to each 32 bits, the first in the lower half (WGSL's
/// pack2x16unorm: ⌊0.5 + 65535·x⌋).
pub fn unorm_pair(first: [f32; 4], second: [f32; 4]) -> [u32; 4] {
    let bits = |x: f32| (0.5 + 65535.0 * x.clamp(0.0, 1.0)).floor() as u32;
    let two = |lo: f32, hi: f32| bits(lo) | bits(hi) << 16;
    [two(first[0], first[1]), two(first[2], first[3]), two(second[0], second[1]), two(second[2], second[3])]
}

/// Region `a`, which draws region `b`'s look in its samples, skips only the bricks
/// where neither draws.
pub(super) fn merge_occupancy(out: &mut PackedScene, a: usize, b: usize) {
    let (ra, rb) = (out.regions[a], out.regions[b]);
    if ra.flags & region_flags::OCCUPANCY != 0 {
        if rb.flags & region_flags::OCCUPANCY == 0 {
            out.regions[a].flags &= !region_flags::OCCUPANCY;
            return;
        }
        // (Every set of bits: full-resolution samples' and mip samples'.)
        let words = 3 * (ra.bricks.x * ra.bricks.y * ra.bricks.z).div_ceil(32) as usize;
        for k in 0..words {
            let bits = out.occupancy[rb.occupancy_offset as usize + k];
            out.occupancy[ra.occupancy_offset as usize + k] |= bits;
        }
    }
}

/// Appends the selection record of a weighted region (the selection volume in atlas
/// slot `slot`, mapped from the data's voxel index, with its brick min-max grid) and
/// returns its index; one record per selection volume and data grid is shared by all
/// the regions that use it.
pub(super) fn pack_selection(p: &PreparedRegion, slot: usize, out: &mut PackedScene) -> u32 {
    let Some(w) = &p.weight else { return 0 };
    let volume = &w.weight.volume;
    let map = Mat4::from(w.data_to_selection);
    let (a, b) = ((volume.values.slope * volume.code_max() as f64) as f32, volume.values.intercept as f32);
    let bricks = volume.bricks();
    let record = GpuRegion {
        world_to_voxel: map,
        dims: volume.dims().as_vec3().extend(volume.code_max() as f32),
        bricks: bricks.dims.extend(bricks.size),
        occupancy_offset: out.occupancy.len() as u32,
        atlas_offset: out.levels[slot][0].as_vec3().extend(0.0),
        mode: mode::OFF,
        lut_a: a,
        lut_b: b,
        ..Default::default()
    };
    let first = out.region_count as usize;
    // (Equal but for where their brick kinds are: the same selection.)
    let key = |r: &GpuRegion| {
        let mut k = *r;
        k.occupancy_offset = 0;
        k
    };
    if let Some(i) = out.regions[first..].iter().position(|r| key(r) == key(&record)) {
        return (first + i) as u32;
    }
    out.occupancy.extend(constant_bricks(bricks, volume.voxels.code_max() as u16));
    out.regions.push(record);
    out.regions.len() as u32 - 1
}

/// Two bits per brick (16 a word, bricks in order): 0 when every code a sample in it
/// can read is 0, 1 when every one is `full`, 2 otherwise. The shader samples a
/// selection only in bricks of kind 2.
pub fn constant_bricks(bricks: &crate::volume::BrickGrid, full: u16) -> Vec<u32> {
    let mut words = vec![0u32; bricks.min.len().div_ceil(16)];
    for (i, (&lo, &hi)) in bricks.min.iter().zip(&bricks.max).enumerate() {
        let kind = match (lo, hi) {
            (0, 0) => 0,
            (a, b) if a == full && b == full => 1,
            _ => 2,
        };
        words[i / 16] |= kind << (2 * (i % 16));
    }
    words
}

/// Regions drawn in another's samples, "two looks in one region": an exploded view at
/// rest draws its parts as one region `a`, weighted by 1 − the degree of interest, and
/// the selection's region `b` (later in the list) inside it with the same map, weighted
/// by the degree of interest of the same selection. Every sample of `b` is then a
/// sample of `a` at the same voxel, so one fetch (the value and, with
/// [`doi_channels`], the degree of interest) serves both looks, composited `a` then
/// `b` as the reference's region order has them, and `b` costs the ray no region,
/// segment or pair loop of its own (on llvmpipe ×1.15 → ×1.06 of the plain frame for
/// an exploded head at rest). The shader draws `b` where the ray is inside it (its
/// interval, found once per segment). Only where `b` lies inside `a`, no third region
/// meets `b` (its samples would come between them; one that only touches it can take
/// a sample on their common face without `b`), neither has holes or objects, `b` is
/// plain DVR shaded as `a` is (it shares `a`'s gradient and Blinn-Phong terms) and
/// steps as `a` does (the ray's step is the finest of the regions it crosses, and `b`
/// no longer counts; one opacity correction serves both looks: `samples.wgsl`
/// dvr_classified), and both tables map a sample alike, with channels in 0…1 (one
/// [`pair_table`] holds both looks; tables of one volume map alike). Per region: the
/// one drawn in its samples.
pub fn companions(prepared: &[PreparedRegion], carried: bool) -> Vec<Option<usize>> {
    use crate::region::{Keep, vertices};
    let n = prepared.len();
    let mut out = vec![None; n];
    if !carried {
        return out;
    }
    let simple = |p: &PreparedRegion| {
        p.objects.is_none()
            && p.region.holes.is_empty()
            && matches!(p.mode, Mode::Dvr | Mode::GradientDvr | Mode::Context)
            && matches!(p.lookup, PreparedLookup::Transfer { .. })
    };
    let keeps = |p: &PreparedRegion, keep: Keep| p.weight.as_ref().is_some_and(|w| w.weight.keep == keep) && simple(p);
    let selection = |p: &PreparedRegion| p.weight.as_ref().map(|w| std::sync::Arc::as_ptr(&w.weight.volume));
    let mut drawn_in = vec![false; n];
    for b in 0..n {
        let pb = &prepared[b];
        let corners = vertices(&pb.region.planes);
        if !keeps(pb, Keep::Selected) || pb.mode != Mode::Dvr || corners.is_empty() {
            continue;
        }
        let shaded_alike =
            |pa: &PreparedRegion| pa.shading.enabled == pb.shading.enabled && (!pb.shading.enabled || pa.shading == pb.shading);
        let inside =
            |pa: &PreparedRegion| corners.iter().all(|p| pa.region.planes.iter().all(|pl| pl.distance(*p) <= 1e-4 * (1.0 + p.length())));
        // (One pair table serves both: their tables map a sample alike, and their
        // channels lie in 0…1.)
        let unit = |lut: &crate::transfer::Lut| lut.rgba.iter().flatten().all(|c| (0.0..=1.0).contains(c));
        let tables_alike = |pa: &PreparedRegion| match (&pa.lookup, &pb.lookup) {
            (PreparedLookup::Transfer { lut: la, a: aa, b: ba }, PreparedLookup::Transfer { lut: lb, a: ab, b: bb }) => {
                la.rgba.len() == lb.rgba.len() && aa == ab && ba == bb && unit(la) && unit(lb)
            }
            _ => false,
        };
        let host = (0..b).find(|&a| {
            let pa = &prepared[a];
            out[a].is_none()
                && !drawn_in[a]
                && keeps(pa, Keep::Unselected)
                && std::ptr::eq(pa.volume, pb.volume)
                && selection(pa) == selection(pb)
                && pa.region.world_to_voxel.abs_diff_eq(pb.region.world_to_voxel, 1e-5)
                && inside(pa)
                && shaded_alike(pa)
                && tables_alike(pa)
                && pb.native_step == pa.native_step
        });
        let Some(a) = host else { continue };
        if (0..n).all(|c| c == a || c == b || !meet(&[pb.region, prepared[c].region])) {
            out[a] = Some(b);
            drawn_in[b] = true;
        }
    }
    out
}
