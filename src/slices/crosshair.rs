//! The crosshair the slice views share with each other and with the 3D view: one point
//! of the dataset (its own frame, millimetres), each view showing the slice through it
//! and the other two planes as lines.
//!
//! Pixel coordinates are continuous with pixel centres at whole values (a slice's voxel
//! centres), so pixel `(x, y)` of slice `index` is voxel [`SliceAxes::voxel`] and a
//! point between pixels lies between voxels.

use glam::{Vec2, Vec3};

use super::plane::SliceAxes;
use crate::volume::Grid;

/// The slice of view `axes` through the point `p` (the dataset's frame): the nearest
/// one, clamped to the volume.
pub fn slice_through(axes: &SliceAxes, grid: &Grid, p: Vec3) -> u32 {
    let q = grid.world_to_index().transform_point3(p);
    axes.pixel(grid.dims, q).1
}

/// Where `p` (the dataset's frame) lies on view `axes`'s screen: continuous pixel
/// coordinates.
pub fn pixel_of(axes: &SliceAxes, grid: &Grid, p: Vec3) -> Vec2 {
    let q = grid.world_to_index().transform_point3(p);
    axes.pixel(grid.dims, q).0.truncate()
}

/// The point of slice `index` at continuous pixel `px` (the dataset's frame).
pub fn point_at(axes: &SliceAxes, grid: &Grid, index: u32, px: Vec2) -> Vec3 {
    let d = grid.dims.as_vec3();
    let mut q = Vec3::ZERO;
    q[axes.normal] = index as f32;
    q[axes.column.0] = if axes.column.1 { d[axes.column.0] - 1.0 - px.x } else { px.x };
    q[axes.row.0] = if axes.row.1 { d[axes.row.0] - 1.0 - px.y } else { px.y };
    grid.index_to_world().transform_point3(q)
}

/// The four corners of slice `index` (the pixels' outer edges; the dataset's frame), in
/// screen order: top left, top right, bottom right, bottom left.
pub fn corners(axes: &SliceAxes, grid: &Grid, index: u32) -> [Vec3; 4] {
    let (w, h) = axes.size(grid.dims);
    let (w, h) = (w as f32 - 0.5, h as f32 - 0.5);
    [Vec2::new(-0.5, -0.5), Vec2::new(w, -0.5), Vec2::new(w, h), Vec2::new(-0.5, h)].map(|px| point_at(axes, grid, index, px))
}

/// The size to draw a slice of `pixels` (width, height) whose pixels measure `pixel_mm`
/// in `room`: the largest with the slice's true proportions in millimetres.
pub fn fit(pixels: (u32, u32), pixel_mm: (f32, f32), room: Vec2) -> Vec2 {
    let mm = Vec2::new(pixels.0 as f32 * pixel_mm.0, pixels.1 as f32 * pixel_mm.1);
    if mm.min_element() <= 0.0 || room.min_element() <= 0.0 {
        return Vec2::ZERO;
    }
    mm * (room / mm).min_element()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::slices::plane::Orientation;
    use glam::UVec3;

    #[test]
    fn a_point_is_on_the_slice_and_pixel_each_view_shows_it_at() {
        // 10 × 8 × 6 voxels of 0.5 × 1 × 2 mm, origin (100, 200, 300).
        let grid = Grid { origin: Vec3::new(100.0, 200.0, 300.0), ..Grid::new(UVec3::new(10, 8, 6), Vec3::new(0.5, 1.0, 2.0)) };
        // The centre of voxel (7, 2, 4).
        let p = Vec3::new(103.5, 202.0, 308.0);
        let axial = SliceAxes::of(grid.direction, Orientation::Axial);
        assert_eq!(slice_through(&axial, &grid, p), 4);
        // Columns run from i = 9 (left) to 0: voxel 7 is pixel 2; rows from j = 7: pixel 5.
        assert_eq!(pixel_of(&axial, &grid, p), Vec2::new(2.0, 5.0));
        assert!(point_at(&axial, &grid, 4, Vec2::new(2.0, 5.0)).abs_diff_eq(p, 1e-4));
        let sagittal = SliceAxes::of(grid.direction, Orientation::Sagittal);
        assert_eq!(slice_through(&sagittal, &grid, p), 7);
        // Beyond the volume: the last slice.
        assert_eq!(slice_through(&axial, &grid, p + Vec3::Z * 100.0), 5);
        // The corners of an axial slice span the volume's box in x and y at the slice's z.
        let c = corners(&axial, &grid, 4);
        assert!(c[0].abs_diff_eq(Vec3::new(104.75, 207.5, 308.0), 1e-4), "{}", c[0]);
        assert!(c[2].abs_diff_eq(Vec3::new(99.75, 199.5, 308.0), 1e-4), "{}", c[2]);
    }

    #[test]
    fn slices_keep_their_proportions_in_millimetres() {
        // 100 × 50 pixels of 1 × 4 mm: 100 × 200 mm, in a 300 × 300 room: 150 × 300.
        assert_eq!(fit((100, 50), (1.0, 4.0), Vec2::new(300.0, 300.0)), Vec2::new(150.0, 300.0));
        assert_eq!(fit((100, 50), (1.0, 4.0), Vec2::new(0.0, 300.0)), Vec2::ZERO);
    }
}
