//! Parts as regions (DESIGN.md, "One rendering idea"): each part is its rest polyhedron
//! moved by its rigid body, sampling the volume through the inverse of that motion, so
//! the data inside a part travels with it. Pure; the ECS system calls it.

use glam::Affine3A;

use super::parts::Polyhedron;
use super::splitters::in_part_frame;
use crate::clip::Clipping;
use crate::region::Region;
use crate::volume::Grid;

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
}
