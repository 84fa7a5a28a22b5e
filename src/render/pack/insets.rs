//! Clip windows drawn in place ("insets"): a clip window showing its dataset where it
//! lies, with another transfer function (the cutaway of the windows paper's figure 3,
//! or the same look), is packed as the dataset's own region without the window's hole,
//! whose samples take the window's lookup table where the ray is inside the box.
//!
//! As regions, such a window cuts the dataset's region into three segments along every
//! ray through its box: the dataset before the box, the window, the dataset behind it
//! (`windows::regions`). On llvmpipe the lanes of a SIMD group wait at each segment's
//! end for the group's longest segment, and each segment scans the ray's intervals and
//! loads its region's record again: one clip window cost ×1.09–1.11 of the frame
//! without it, for the same samples. In place, the ray has one segment, cut into runs
//! of samples that share a table where it enters and leaves the box
//! (`shaders/focal/insets.wgsl`). The boxes ride in the scene's uniform buffer
//! ([`GpuInset`]): at most [`MAX_INSETS`] in a scene.
//!
//! The picture is the one the regions give (the CPU reference still draws regions): the
//! samples lie on the same grid and take the same steps, so only where is a sample's
//! table chosen differs. That holds where the window shows the same volume under the
//! same map, in the same mode (DVR or gradient-modulated DVR) and shading, its table
//! over the same values (every table of a volume is baked over its whole value range:
//! `transfer::Lut::for_volume`), so only the table's place in the atlas differs; where
//! the window's region is exactly the box cut from the dataset's (no clip plane of the
//! dataset's lies inside the box); and where no third region meets the window's (its
//! samples would come between the two looks). A scene takes at most [`MAX_INSETS`]
//! windows in place (the others stay regions); a host's empty-space skipping skips only
//! the bricks where none of its looks draws.

use super::super::gpu_types::GpuInset;
pub use super::super::gpu_types::MAX_INSETS;
use super::packed::PackedScene;
use crate::reference::prepare::{PreparedLookup, PreparedRegion};
use crate::region::{Mode, Plane, meet, vertices};

/// One window drawn in place: the region `host`, less its hole `hole`, draws region
/// `window`'s look inside that hole.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Inset {
    pub host: usize,
    pub hole: usize,
    pub window: usize,
}

/// The windows of `prepared` that can be drawn in place (module doc), at most
/// [`MAX_INSETS`]; each window and each hole at most once.
pub fn insets(prepared: &[PreparedRegion]) -> Vec<Inset> {
    let mut out: Vec<Inset> = Vec::new();
    for (w, pw) in prepared.iter().enumerate() {
        if !plain(pw) || !pw.region.holes.is_empty() {
            continue;
        }
        let corners = vertices(&pw.region.planes);
        // (The host's hole holds the window: `meet` says they do not meet.)
        if corners.is_empty() || (0..prepared.len()).any(|c| c != w && meet(&[pw.region, prepared[c].region])) {
            continue;
        }
        let found = prepared.iter().enumerate().find_map(|(h, ph)| {
            if h == w || !plain(ph) || !alike(ph, pw) || out.len() >= MAX_INSETS {
                return None;
            }
            let hole = ph.region.holes.iter().position(|box_| fills(&ph.region.planes, box_, &pw.region.planes, &corners))?;
            (!out.iter().any(|i| i.host == h && i.hole == hole)).then_some(Inset { host: h, hole, window: w })
        });
        out.extend(found);
    }
    out
}

/// A region whose samples the in-place look can take: DVR with a transfer function,
/// nothing else drawn in or over them.
fn plain(p: &PreparedRegion) -> bool {
    p.objects.is_none()
        && p.weight.is_none()
        && matches!(p.mode, Mode::Dvr | Mode::GradientDvr)
        && matches!(p.lookup, PreparedLookup::Transfer { .. })
}

/// Whether window `w` shows host `h`'s volume at the same voxels with the same steps,
/// mode and shading, and a table over the same values.
fn alike(h: &PreparedRegion, w: &PreparedRegion) -> bool {
    let table = |p: &PreparedRegion| match &p.lookup {
        PreparedLookup::Transfer { lut, a, b } => Some((lut.len(), *a, *b)),
        PreparedLookup::Labels(_) => None,
    };
    std::ptr::eq(h.volume, w.volume)
        && h.region.world_to_voxel.abs_diff_eq(w.region.world_to_voxel, 1e-5)
        && h.mode == w.mode
        && h.shading.enabled == w.shading.enabled
        && (!h.shading.enabled || h.shading == w.shading)
        && h.native_step == w.native_step
        && h.reference_length == w.reference_length
        && table(h).is_some()
        && table(h) == table(w)
}

/// Whether the window region `window` (its vertices `corners`) is exactly the part of
/// `host` that `hole` cuts out: inside both, and holding every vertex of their
/// intersection.
fn fills(host: &[Plane], hole: &[Plane; 6], window: &[Plane], corners: &[glam::Vec3]) -> bool {
    let within = |planes: &[Plane], p: glam::Vec3| planes.iter().all(|pl| pl.distance(p) <= 1e-4 * (1.0 + p.length()));
    let mut cut = host.to_vec();
    cut.extend_from_slice(hole);
    let cut_corners = vertices(&cut);
    !cut_corners.is_empty() && corners.iter().all(|&p| within(host, p) && within(hole, p)) && cut_corners.iter().all(|&p| within(window, p))
}

/// Draws the window record `window` in place in region record `host`, inside `hole`
/// (the box the window fills): the window's box and table go to the scene's insets,
/// and `host` skips only the bricks where neither draws.
pub(super) fn draw_in_place(out: &mut PackedScene, host: usize, window: usize, hole: &[Plane; 6]) {
    out.insets.push(GpuInset {
        planes: hole.map(|pl| super::packed::gpu_plane(&pl)),
        host: host as u32,
        lut_offset: out.regions[window].lut_offset,
    });
    super::selection::merge_occupancy(out, host, window);
}

/// The holes of each region left after `insets` took theirs.
pub fn kept_holes(prepared: &[PreparedRegion], insets: &[Inset]) -> Vec<Vec<[Plane; 6]>> {
    prepared
        .iter()
        .enumerate()
        .map(|(r, p)| {
            let taken = |h: usize| insets.iter().any(|i| i.host == r && i.hole == h);
            p.region.holes.iter().enumerate().filter(|(h, _)| !taken(*h)).map(|(_, b)| *b).collect()
        })
        .collect()
}

/// The shader features of the windows drawn in place, `insets`.
pub fn inset_features(insets: &[GpuInset]) -> u32 {
    use super::super::gpu_types::features::{INSETS, SEVERAL_INSETS};
    match insets.len() {
        0 => 0,
        1 => INSETS,
        _ => INSETS | SEVERAL_INSETS,
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use glam::{Affine3A, Vec3};

    use super::super::super::gpu_types::{GpuRegion, features};
    use super::super::pack;
    use super::*;
    use crate::region::{Appearance, Region, RenderScene};
    use crate::transfer::presets;
    use crate::volume::phantom;
    use crate::windows::boxes::OrientedBox;
    use crate::windows::regions::{PlacedContent, PlacedWindow, add_windows};

    fn look(tf: &str) -> Appearance {
        Appearance::new(Mode::Dvr, presets::builtin(tf).unwrap())
    }

    /// The 32³ sphere phantom (centred: voxel centres −15.5…15.5 mm) with clip windows of 8 mm at
    /// `centres`, each showing the volume in place with `content`'s look.
    fn scene(centres: &[Vec3], content: &Appearance) -> RenderScene {
        let v = Arc::new(phantom::sphere(32, 10.0).unwrap());
        let mut scene = RenderScene::single(v.clone(), look("grayscale_ramp"));
        let windows: Vec<PlacedWindow> = centres
            .iter()
            .map(|&c| {
                let b = OrientedBox::aligned(c - 4.0, c + 4.0);
                let content =
                    PlacedContent { volume: v.clone(), volume_index: 0, dataset_to_world: Affine3A::IDENTITY, appearance: content.clone() };
                PlacedWindow { window: b, source: b, fit: None, clip: true, contents: vec![content] }
            })
            .collect();
        add_windows(&mut scene, 1, &windows);
        scene
    }

    const FOUR: [Vec3; 4] = [Vec3::new(-8.0, -8.0, -8.0), Vec3::new(8.0, -8.0, -8.0), Vec3::new(-8.0, 8.0, 8.0), Vec3::new(8.0, 8.0, -8.0)];

    #[test]
    fn a_clip_window_showing_its_dataset_in_place_is_drawn_in_its_samples() {
        let bone = look("ct_bone");
        let s = scene(&FOUR[..1], &bone);
        assert_eq!(s.regions[0].holes.len(), 1, "the window cuts its box out of the dataset as regions");
        let packed = pack(&s, 2048).unwrap();
        // One region the ray traverses, without its hole; the window's box and table
        // (not its own) in the scene's insets, naming the host.
        assert_eq!(packed.region_count, 1);
        let (host, window) = (packed.regions[0], packed.regions[1]);
        assert_eq!(host.hole_count, 0);
        let box_ = s.regions[0].holes[0].map(|pl| super::super::packed::gpu_plane(&pl));
        assert_eq!(packed.insets, vec![GpuInset { planes: box_, host: 0, lut_offset: window.lut_offset }]);
        assert_ne!(host.lut_offset, window.lut_offset);
        assert_eq!((host.lut_width, host.lut_a, host.lut_b), (window.lut_width, window.lut_a, window.lut_b));
        // (One window: each sample compares with it alone.)
        assert_eq!(packed.features & (features::INSETS | features::SEVERAL_INSETS | features::HOLES), features::INSETS);
        // It skips only bricks where neither look draws.
        let words = |r: &GpuRegion| packed.occupancy[r.occupancy_offset as usize..][..3 * 8usize.div_ceil(32)].to_vec();
        assert!(words(&host).iter().zip(words(&window)).all(|(h, w)| h & w == w));
        // Four windows: four insets, each its own box.
        let packed = pack(&scene(&FOUR, &bone), 2048).unwrap();
        assert_eq!((packed.region_count, packed.insets.len()), (1, 4));
        assert_eq!(packed.features & (features::INSETS | features::SEVERAL_INSETS), features::INSETS | features::SEVERAL_INSETS);
        assert!(packed.insets.iter().all(|i| i.host == 0));
        assert!((1..4).all(|k| packed.insets[k].planes != packed.insets[0].planes));
    }

    #[test]
    fn each_dataset_draws_its_own_windows_in_place() {
        // Two datasets side by side (the second 40 mm along x), a window into each.
        let v = Arc::new(phantom::sphere(32, 10.0).unwrap());
        let beside = Affine3A::from_translation(Vec3::new(40.0, 0.0, 0.0));
        let mut s = RenderScene::single(v.clone(), look("grayscale_ramp"));
        s.regions.push(Region::volume_box_at(&v.grid, beside, 0, 0));
        let window = |at: Vec3, dataset_to_world: Affine3A| {
            let b = OrientedBox::aligned(at - 4.0, at + 4.0);
            let content = PlacedContent { volume: v.clone(), volume_index: 0, dataset_to_world, appearance: look("ct_bone") };
            PlacedWindow { window: b, source: b, fit: None, clip: true, contents: vec![content] }
        };
        add_windows(&mut s, 2, &[window(FOUR[0], Affine3A::IDENTITY), window(FOUR[1] + Vec3::new(40.0, 0.0, 0.0), beside)]);
        let packed = pack(&s, 2048).unwrap();
        assert_eq!(packed.region_count, 2);
        assert_eq!(packed.insets.iter().map(|i| i.host).collect::<Vec<_>>(), vec![0, 1]);
        assert!(packed.regions[..2].iter().all(|r| r.hole_count == 0));
        // Each inset is its own dataset's hole.
        for (k, inset) in packed.insets.iter().enumerate() {
            assert_eq!(inset.planes, s.regions[k].holes[0].map(|pl| super::super::packed::gpu_plane(&pl)));
        }
    }

    #[test]
    fn windows_that_would_draw_otherwise_in_place_stay_regions() {
        let bone = look("ct_bone");
        let stays = |s: &RenderScene, why: &str| {
            let packed = pack(s, 2048).unwrap();
            assert_eq!(packed.features & features::INSETS, 0, "{why}");
            assert!(packed.regions[0].hole_count > 0, "{why}");
            assert_eq!(packed.region_count as usize, s.regions.len(), "{why}");
        };
        // A fifth window in the scene: four in place, the fifth a hole.
        let mut five = FOUR.to_vec();
        five.push(Vec3::new(0.0, 0.0, 12.0));
        let packed = pack(&scene(&five, &bone), 2048).unwrap();
        assert_eq!((packed.region_count, packed.regions[0].hole_count), (2, 1));
        assert_ne!(packed.features & features::HOLES, 0);
        // Another mode, other shading, labels: another sample, not another table.
        stays(&scene(&FOUR[..1], &Appearance::new(Mode::Mip, presets::builtin("ct_bone").unwrap())), "MIP");
        let mut shaded = bone.clone();
        shaded.shading.enabled = !shaded.shading.enabled;
        stays(&scene(&FOUR[..1], &shaded), "shading");
        // Shown elsewhere (a magnifier's source beside the box): other voxels.
        let mut moved = scene(&FOUR[..1], &bone);
        moved.regions[1].world_to_voxel = Affine3A::from_translation(Vec3::X) * moved.regions[1].world_to_voxel;
        stays(&moved, "moved voxels");
        // A clip plane of the dataset through the box: the window's region is more than
        // what the hole cuts from the dataset's.
        let mut clipped = scene(&FOUR[..1], &bone);
        clipped.regions[0].planes.push(Plane::through(FOUR[0], Vec3::X));
        stays(&clipped, "clip plane");
        // Two windows overlapping: each meets the other's content.
        stays(&scene(&[FOUR[0], FOUR[0] + 2.0], &bone), "overlap");
    }
}
