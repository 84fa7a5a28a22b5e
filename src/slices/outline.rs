//! Where a box (a volumetric window, a source box) cuts a slice: the polygon of the
//! box's section by the slice's plane, in the slice's continuous pixel coordinates, so
//! the slice views outline the windows they pass through.
//!
//! The plane is `q[n] = index` in voxel index coordinates; each of the box's 12 edges
//! that crosses it gives one point (`a + (b − a)·t`, `t = (a[n] − index)/(a[n] − b[n])`);
//! the section of a convex box is the convex polygon of those points, ordered by angle
//! about their mean.

use glam::{Affine3A, Vec2, Vec3};

use super::plane::SliceAxes;
use crate::volume::Grid;

/// The section of the box with `corners` (in the dataset's frame; corner `c` has bit 0,
/// 1, 2 for its x, y, z side, as `OrientedBox::corners` and `Grid::corners` order them)
/// by slice `index` of view `axes`, in continuous pixel coordinates; empty where the
/// box misses the slice.
pub fn section(corners: &[Vec3; 8], grid: &Grid, axes: &SliceAxes, index: u32) -> Vec<Vec2> {
    let to_index: Affine3A = grid.world_to_index();
    let q: Vec<Vec3> = corners.iter().map(|c| to_index.transform_point3(*c)).collect();
    let n = axes.normal;
    let level = index as f32;
    let mut points: Vec<Vec2> = Vec::new();
    for a in 0..8usize {
        for bit in [1usize, 2, 4] {
            let b = a | bit;
            if b == a {
                continue;
            }
            let (da, db) = (q[a][n] - level, q[b][n] - level);
            if (da <= 0.0 && db >= 0.0 || da >= 0.0 && db <= 0.0) && da != db {
                let p = q[a] + (q[b] - q[a]) * (da / (da - db));
                points.push(axes.pixel(grid.dims, p).0.truncate());
            }
        }
    }
    if points.len() < 3 {
        return Vec::new();
    }
    let mean = points.iter().copied().sum::<Vec2>() / points.len() as f32;
    points.sort_by(|a, b| (*a - mean).to_angle().total_cmp(&(*b - mean).to_angle()));
    points.dedup_by(|a, b| a.distance(*b) < 1e-4);
    points
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::slices::plane::Orientation;
    use glam::UVec3;

    fn boxed(lo: Vec3, hi: Vec3) -> [Vec3; 8] {
        std::array::from_fn(|c| {
            Vec3::new(if c & 1 == 0 { lo.x } else { hi.x }, if c & 2 == 0 { lo.y } else { hi.y }, if c & 4 == 0 { lo.z } else { hi.z })
        })
    }

    #[test]
    fn an_axis_aligned_box_cuts_a_rectangle() {
        // 20³ voxels of 1 mm from the origin; a box from (2, 3, 4) to (6, 9, 12) mm.
        let grid = Grid::new(UVec3::splat(20), Vec3::ONE);
        let axial = SliceAxes::of(grid.direction, Orientation::Axial);
        let s = section(&boxed(Vec3::new(2.0, 3.0, 4.0), Vec3::new(6.0, 9.0, 12.0)), &grid, &axial, 8);
        assert_eq!(s.len(), 4, "{s:?}");
        // Columns run from i = 19 at x = 0 (x = 19 − i), rows from j = 19 (y = 19 − j).
        let (lo, hi) = s.iter().fold((Vec2::splat(f32::MAX), Vec2::splat(f32::MIN)), |(l, h), p| (l.min(*p), h.max(*p)));
        assert!(lo.abs_diff_eq(Vec2::new(13.0, 10.0), 1e-4) && hi.abs_diff_eq(Vec2::new(17.0, 16.0), 1e-4), "{lo} {hi}");
        // Slices beside the box: nothing.
        assert!(section(&boxed(Vec3::new(2.0, 3.0, 4.0), Vec3::new(6.0, 9.0, 12.0)), &grid, &axial, 13).is_empty());
    }

    #[test]
    fn a_turned_box_cuts_a_polygon_in_order() {
        // A cube turned 45° about z, centred at (10, 10, 10): an axial section is a
        // square turned 45° (a diamond) whose vertices are ordered around it.
        let grid = Grid::new(UVec3::splat(20), Vec3::ONE);
        let turn = glam::Quat::from_rotation_z(std::f32::consts::FRAC_PI_4);
        let corners = boxed(Vec3::splat(-3.0), Vec3::splat(3.0)).map(|c| turn * c + Vec3::splat(10.0));
        let axial = SliceAxes::of(grid.direction, Orientation::Axial);
        let s = section(&corners, &grid, &axial, 10);
        assert_eq!(s.len(), 4, "{s:?}");
        let r = 3.0 * std::f32::consts::SQRT_2;
        for p in &s {
            assert!((p.distance(Vec2::new(9.0, 9.0)) - r).abs() < 1e-3, "{p}");
        }
        // Consecutive vertices are adjacent (a side apart), not opposite.
        assert!((s[0].distance(s[1]) - 6.0).abs() < 1e-3);
    }
}
