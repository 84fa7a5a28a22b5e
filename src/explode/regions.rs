//! Parts as regions (DESIGN.md, "One rendering idea"): each part is its rest polyhedron
//! moved by its rigid body, sampling the volume through the inverse of that motion, so
//! the data inside a part travels with it. Pure; the ECS system calls it.
//!
//! What the ray caster is given is also kept as small as the picture allows (each
//! region a ray crosses costs it a segment, each overlap a sample of both):
//! - parts that all move alike (at rest, before the explosion) draw as one region, the
//!   dataset's box under that motion ([`moving_as_one`]);
//! - the selection's region is the dataset's box cut to the box of the selection's
//!   non-zero bricks ([`selection_box`]): outside it every degree of interest is 0; and
//!   to the bricks its look can draw in ([`drawn_part`]);
//! - only parts over the selection's non-zero bricks need its weight (elsewhere
//!   `1 − doi` is 1: [`holds_selection`]).
//!
//! At rest the selection's region lies inside the parts' one region under the same
//! map, and the GPU draws it in that region's samples (`render::pack::companions`);
//! with the selection on the data's grid its degree of interest comes with the data's
//! own fetch (`render::pack::doi_channels`).

use glam::{Affine3A, Vec3};

use super::parts::Polyhedron;
use super::splitters::in_part_frame;
use crate::clip::Clipping;
use crate::region::{Appearance, Plane, Region, bounding_planes, box_planes};
use crate::volume::{Grid, Volume};

/// A part placed for rendering: its rest polyhedron (dataset frame) and its motion
/// (dataset frame → dataset frame).
pub struct PlacedPart<'a> {
    pub rest: &'a Polyhedron,
    pub motion: Affine3A,
}

/// The region of each part of dataset `index` (volume and appearance `index`), placed
/// by `dataset_to_world`. The dataset's clip planes and box move with each part (they
/// cut the data, wherever it is pushed).
pub fn part_regions(grid: &Grid, dataset_to_world: Affine3A, clip: &Clipping, index: usize, parts: &[PlacedPart]) -> Vec<Region> {
    parts
        .iter()
        .map(|p| {
            let to_world = dataset_to_world * p.motion;
            let from_world = to_world.inverse();
            let mut planes: Vec<_> = p.rest.planes.iter().map(|pl| in_part_frame(*pl, from_world)).collect();
            planes.extend(clip.world_planes(&to_world));
            Region { planes, holes: Vec::new(), world_to_voxel: grid.world_to_index() * from_world, volume: index, appearance: index }
        })
        .collect()
}

/// The box of `selection`'s non-zero bricks (their one-voxel aprons included, so every
/// trilinear sample outside it is 0) as planes in the dataset's frame; `None` when
/// nothing is selected.
pub fn selection_box(selection: &Volume) -> Option<Vec<Plane>> {
    let bricks = selection.bricks();
    let selected: Vec<bool> = bricks.max.iter().map(|m| *m > 0).collect();
    let (lo, hi) = bricks.bounds_where(&selected)?;
    let dims = selection.dims().as_vec3();
    Some(box_planes(&selection.grid.world_to_index(), lo.max(Vec3::splat(-0.5)), hi.min(dims - 0.5)))
}

/// The selection's region: `dataset` (a dataset's region) cut to `selection_box` (dataset
/// frame) placed by `dataset_to_world`.
pub fn selection_region(dataset: Region, selection_box: &[Plane], dataset_to_world: Affine3A) -> Region {
    let to_dataset = dataset_to_world.inverse();
    let mut planes = dataset.planes.clone();
    planes.extend(selection_box.iter().map(|pl| in_part_frame(*pl, to_dataset)));
    Region { planes: bounding_planes(&planes), ..dataset }
}

/// `region` (showing `volume`) cut to the box of the bricks `look` can draw in (its
/// occupancy; for the selection's look, where the data is visible and selected);
/// `None` when it draws nowhere.
pub fn drawn_part(region: Region, look: &Appearance, volume: &Volume) -> Option<Region> {
    let Some(occupied) = look.brick_occupancy(volume) else { return Some(region) };
    let (lo, hi) = volume.bricks().bounds_where(&occupied)?;
    let dims = volume.dims().as_vec3();
    Some(region.cut_to_index_box(lo.max(Vec3::splat(-0.5)), hi.min(dims - 0.5)))
}

/// The order of points along a Z-order (Morton) curve through their bounding box, 10
/// bits an axis: parts drawn in this order are neighbours in the list of regions, so a
/// renderer that tests runs of consecutive regions behind one bounding sphere (the GPU
/// ray caster does) finds them compact.
pub fn spatial_order(points: &[Vec3]) -> Vec<usize> {
    let lo = points.iter().copied().fold(Vec3::splat(f32::INFINITY), Vec3::min);
    let hi = points.iter().copied().fold(Vec3::splat(f32::NEG_INFINITY), Vec3::max);
    let scale = 1023.0 / (hi - lo).max(Vec3::splat(1e-6));
    let spread = |v: u32| (0..10).fold(0u32, |acc, b| acc | (((v >> b) & 1) << (3 * b)));
    let code = |p: &Vec3| {
        let q = ((*p - lo) * scale).round().clamp(Vec3::ZERO, Vec3::splat(1023.0)).as_uvec3();
        spread(q.x) | (spread(q.y) << 1) | (spread(q.z) << 2)
    };
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by_key(|&i| code(&points[i]));
    order
}

/// Whether a part (rest polyhedron, dataset frame) may hold a non-zero degree of
/// interest: some brick of `selection` under the box of its vertices (in the
/// selection's voxel index) has a non-zero code. A brick's code range covers its
/// one-voxel apron, so every trilinear sample in a part without one is 0 and its weight
/// `1 − doi` is 1: the part needs none (on llvmpipe a weighted sample costs about a
/// fifth more).
pub fn holds_selection(rest: &Polyhedron, selection: &Volume) -> bool {
    let to_index = selection.grid.world_to_index();
    let (lo, hi) = rest
        .vertices
        .iter()
        .map(|v| to_index.transform_point3(*v))
        .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(a, b), p| (a.min(p), b.max(p)));
    if !(lo.is_finite() && hi.is_finite()) {
        return true;
    }
    let bricks = selection.bricks();
    // (A face on a brick boundary takes its samples from the voxels of the brick inside:
    // those on the boundary are in that brick's apron.)
    let inset = Vec3::splat(1e-3).min((hi - lo) * 0.25);
    let (a, b) = (bricks.brick_at(lo + inset), bricks.brick_at(hi - inset));
    (a.z..=b.z).any(|z| (a.y..=b.y).any(|y| (a.x..=b.x).any(|x| bricks.max[bricks.index(glam::UVec3::new(x, y, z))] > 0)))
}

/// The motion every part has when all `motions` are the same (to 10⁻⁴ mm over the
/// dataset's `extent` and in rotation), so the parts together are the dataset's box
/// moved by it: they draw as one region. `None` when they differ or there are none.
pub fn moving_as_one(motions: &[Affine3A], extent: f32) -> Option<Affine3A> {
    let first = *motions.first()?;
    let tolerance = 1e-4 * extent.max(1.0);
    let alike = |m: &Affine3A| {
        let probe = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z].map(|v| v * extent);
        probe.iter().all(|p| m.transform_point3(*p).distance(first.transform_point3(*p)) <= tolerance)
    };
    motions.iter().all(alike).then_some(first)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Quat, UVec3, Vec3};

    #[test]
    fn a_moved_part_carries_its_data() {
        // Voxels 0..9 at 1 mm; the part the half x ≤ 4.5, pushed 20 mm along +y and
        // turned 90° about z, in a dataset moved 100 mm along x.
        let g = Grid::new(UVec3::splat(10), Vec3::ONE);
        let whole = Polyhedron::cuboid(Vec3::splat(-0.5), Vec3::splat(9.5));
        let (half, _) = whole.split(crate::region::Plane::through(Vec3::new(4.5, 0.0, 0.0), Vec3::X)).unwrap();
        let motion = Affine3A::from_rotation_translation(Quat::from_rotation_z(std::f32::consts::FRAC_PI_2), Vec3::new(0.0, 20.0, 0.0));
        let dataset = Affine3A::from_translation(Vec3::new(100.0, 0.0, 0.0));
        let r = &part_regions(&g, dataset, &Clipping::default(), 3, &[PlacedPart { rest: &half, motion }])[0];
        assert_eq!((r.volume, r.appearance), (3, 3));
        // Voxel (2, 5, 5) of the half is now at dataset ∘ motion of it, and the region
        // holds it there and maps it back to the same voxel.
        let at = (dataset * motion).transform_point3(Vec3::new(2.0, 5.0, 5.0));
        assert!(r.contains(at));
        assert!((r.world_to_voxel.transform_point3(at) - Vec3::new(2.0, 5.0, 5.0)).length() < 1e-4);
        // Voxel (7, 5, 5) belongs to the other half: not in this region, wherever it is.
        assert!(!r.contains((dataset * motion).transform_point3(Vec3::new(7.0, 5.0, 5.0))));
        assert!(!r.contains(dataset.transform_point3(Vec3::new(2.0, 5.0, 5.0))), "the part left its place");
    }

    #[test]
    fn the_selection_box_its_region_and_the_parts_that_hold_it() {
        use crate::volume::SelectionVolume;
        // 32³ voxels of 2 mm; voxels 10..=13 along x, 4..=5 along y and z selected. The
        // bricks (8 voxels) holding them, aprons included: x 8..16 → index box
        // [7.5, 15.5], y and z brick 0 → [−0.5, 7.5].
        let g = Grid::new(glam::UVec3::splat(32), Vec3::splat(2.0));
        let mut codes = vec![0u8; 32 * 32 * 32];
        for x in 10..=13 {
            for yz in 4..=5 {
                codes[(yz * 32 + yz) * 32 + x] = 255;
            }
        }
        let sel = SelectionVolume::from_codes(g.clone(), codes).unwrap().volume;
        let planes = selection_box(&sel).unwrap();
        let to_world = g.index_to_world();
        let inside = |p: Vec3| planes.iter().all(|pl| pl.distance(to_world.transform_point3(p)) <= 1e-4);
        assert!(inside(Vec3::new(7.6, -0.4, 7.4)) && inside(Vec3::new(15.4, 7.4, 0.0)));
        assert!(!inside(Vec3::new(7.4, 3.0, 3.0)) && !inside(Vec3::new(15.6, 3.0, 3.0)) && !inside(Vec3::new(10.0, 7.6, 3.0)));
        assert!(selection_box(&SelectionVolume::empty(g.clone()).volume).is_none());
        // Its region in a dataset moved 100 mm along z: the box moved too.
        let dataset = Affine3A::from_translation(Vec3::new(0.0, 0.0, 100.0));
        let whole = Region::volume_box_at(&g, dataset, 0, 0);
        let r = selection_region(whole, &planes, dataset);
        let at = |q: Vec3| dataset.transform_point3(to_world.transform_point3(q));
        assert!(r.contains(at(Vec3::new(11.0, 4.0, 4.0))) && !r.contains(at(Vec3::new(20.0, 4.0, 4.0))));
        // Only brick (1, 0, 0) holds selected voxels. A part over brick x 0 only (index
        // up to 7.5, its boundary) holds none of it; one reaching past 7.5 into brick
        // x 1 does, and so does a small one whose corner lies in it; one over x 8..16
        // but in y brick 2 does not.
        let part = |lo: Vec3, hi: Vec3| Polyhedron::cuboid(to_world.transform_point3(lo), to_world.transform_point3(hi));
        assert!(!holds_selection(&part(Vec3::splat(-0.5), Vec3::new(7.5, 31.5, 31.5)), &sel), "a face on the boundary");
        assert!(holds_selection(&part(Vec3::splat(-0.5), Vec3::new(7.6, 31.5, 31.5)), &sel));
        assert!(holds_selection(&part(Vec3::new(10.0, 7.0, 7.0), Vec3::new(12.0, 9.0, 9.0)), &sel));
        assert!(!holds_selection(&part(Vec3::new(8.0, 16.0, 0.0), Vec3::new(15.0, 23.0, 7.0)), &sel));
    }

    #[test]
    fn neighbours_come_together_in_spatial_order() {
        // The centres of a 4×4×4 grid, listed x fastest: in Z order every run of 8 is
        // one 2×2×2 block (its corners within one cell's span of each other).
        let centres: Vec<Vec3> = (0..64).map(|i| Vec3::new((i % 4) as f32, ((i / 4) % 4) as f32, (i / 16) as f32)).collect();
        let order = spatial_order(&centres);
        let mut seen = order.clone();
        seen.sort();
        assert_eq!(seen, (0..64).collect::<Vec<_>>());
        for run in order.chunks(8) {
            let lo = run.iter().map(|&i| centres[i]).fold(Vec3::splat(9.0), Vec3::min);
            let hi = run.iter().map(|&i| centres[i]).fold(Vec3::splat(-9.0), Vec3::max);
            assert_eq!(hi - lo, Vec3::ONE, "run {run:?}");
        }
        assert_eq!(order[0], 0);
        assert!(spatial_order(&[]).is_empty());
        assert_eq!(spatial_order(&[Vec3::ONE]), vec![0]);
    }

    #[test]
    fn parts_moving_alike_draw_as_one() {
        let shift = Affine3A::from_translation(Vec3::new(0.0, 5.0, 0.0));
        assert_eq!(moving_as_one(&[Affine3A::IDENTITY; 3], 200.0), Some(Affine3A::IDENTITY));
        assert_eq!(moving_as_one(&[shift, shift], 200.0), Some(shift));
        assert_eq!(moving_as_one(&[Affine3A::IDENTITY, shift], 200.0), None);
        // A turn of 10⁻⁵ rad moves the box's far corner 2 µm: alike; 10⁻³ rad: not.
        let turn = |a: f32| Affine3A::from_rotation_z(a);
        assert!(moving_as_one(&[Affine3A::IDENTITY, turn(1e-5)], 200.0).is_some());
        assert!(moving_as_one(&[Affine3A::IDENTITY, turn(1e-3)], 200.0).is_none());
        assert_eq!(moving_as_one(&[], 200.0), None);
    }
}
