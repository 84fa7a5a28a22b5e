//! Where a lens cuts a slice: the lens's outlines on the image plane (the rim of its
//! focus region and the outer edge of its border, see [`crate::lens::handles::outlines`])
//! carried along the camera's rays through them onto the slice's plane. What the slice
//! shows inside the rim curve is what the 3D view shows inside the lens, as the view
//! would see it without the lens (a magnifier bends the rays inside its border; its
//! outer edge, where the rays are straight, is exact).
//!
//! Each ray `o + t·d` (in voxel index coordinates) meets the plane `q[n] = index` at
//! `t = (index − o[n])/d[n]`; rays parallel to the plane or meeting it behind the eye
//! break the curve, which is otherwise closed.

use glam::{Affine3A, Vec2};

use super::plane::SliceAxes;
use crate::lens::{Lens, LensKind, Screen, Shape};
use crate::region::{Camera, Ray};
use crate::volume::Grid;

/// A lens as the slices outline it: the camera's rays through its focus rim and through
/// the outer edge of its border (world space).
#[derive(Clone, Debug)]
pub struct LensRays {
    pub rim: Vec<Ray>,
    pub outer: Vec<Ray>,
}

impl LensRays {
    /// The rays of `lens` on the view `screen` of `camera`; `None` for lenses without
    /// an outline on the image (a whole-view fisheye, a feature lens) and for lenses
    /// turned off.
    pub fn of(lens: &Lens, camera: &Camera, screen: Screen) -> Option<LensRays> {
        let whole_view = matches!(lens.kind, LensKind::Angular { whole_view: true, .. });
        if !lens.enabled || whole_view || matches!(lens.shape, Shape::Feature(_)) {
            return None;
        }
        let (rim, outer) = crate::lens::handles::outlines(lens);
        let rays = |points: Vec<Vec2>| points.into_iter().map(|s| screen.camera_ray(camera, s)).collect();
        Some(LensRays { rim: rays(rim), outer: if lens.border > 0.0 { rays(outer) } else { Vec::new() } })
    }
}

/// The curves where `rays` (world space) meet slice `index` of view `axes`, in the
/// slice's continuous pixel coordinates; `to_index` maps world to the dataset's voxel
/// indices. One closed curve (its first point repeated) where every ray meets the
/// plane, open pieces otherwise.
pub fn section(rays: &[Ray], to_index: Affine3A, grid: &Grid, axes: &SliceAxes, index: u32) -> Vec<Vec<Vec2>> {
    let n = axes.normal;
    let level = index as f32;
    // (Far outside the slice a point only makes the painter's numbers huge.)
    let reach = grid.dims.as_vec3().max_element() * 4.0;
    let hits: Vec<Option<Vec2>> = rays
        .iter()
        .map(|r| {
            let (o, d) = (to_index.transform_point3(r.origin), to_index.transform_vector3(r.dir));
            if d[n].abs() < 1e-6 {
                return None;
            }
            let t = (level - o[n]) / d[n];
            let p = axes.pixel(grid.dims, o + d * t).0.truncate();
            (t >= 0.0 && p.abs().max_element() <= reach).then_some(p)
        })
        .collect();
    let Some(gap) = hits.iter().position(Option::is_none) else {
        let mut closed: Vec<Vec2> = hits.into_iter().flatten().collect();
        if let Some(&first) = closed.first() {
            closed.push(first);
        }
        return vec![closed];
    };
    // Start after a gap so no piece is split across the end of the list.
    let mut pieces = Vec::new();
    let mut piece = Vec::new();
    for k in 1..=hits.len() {
        match hits[(gap + k) % hits.len()] {
            Some(p) => piece.push(p),
            None if piece.len() > 1 => pieces.push(std::mem::take(&mut piece)),
            None => piece.clear(),
        }
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::region::Projection;
    use crate::slices::Orientation;
    use glam::{UVec3, Vec3};

    fn axial_setup() -> (Grid, SliceAxes) {
        let grid = Grid::new(UVec3::splat(40), Vec3::ONE);
        let axes = SliceAxes::of(grid.direction, Orientation::Axial);
        (grid, axes)
    }

    fn look_down(projection: Projection) -> Camera {
        Camera::look_at(Vec3::new(20.0, 20.0, 60.0), Vec3::new(20.0, 20.0, 0.0), Vec3::Y, projection)
    }

    #[test]
    fn an_orthographic_lens_cuts_its_own_circle() {
        // Looking straight down at an axial slice, orthographic, 40 mm high on a square
        // view: lens units are 20 mm, so a lens of radius 0.25 is a circle of 5 mm (5
        // voxels) about the point under its centre.
        let (grid, axes) = axial_setup();
        let camera = look_down(Projection::Orthographic { height: 40.0 });
        let lens = Lens::magnifier(Vec2::ZERO, 0.25, 0.1, 2.0);
        let rays = LensRays::of(&lens, &camera, Screen::new(100, 100)).unwrap();
        let curves = section(&rays.rim, grid.world_to_index(), &grid, &axes, 10);
        assert_eq!(curves.len(), 1);
        let c = &curves[0];
        assert_eq!(c.first(), c.last(), "closed");
        let centre = axes.pixel(grid.dims, Vec3::new(20.0, 20.0, 10.0)).0.truncate();
        for p in c {
            assert!((p.distance(centre) - 5.0).abs() < 1e-3, "{p} from {centre}");
        }
        // The border's outer edge: 0.35 lens units, 7 mm.
        let outer = section(&rays.outer, grid.world_to_index(), &grid, &axes, 10);
        assert!((outer[0][0].distance(centre) - 7.0).abs() < 1e-3);
    }

    #[test]
    fn a_perspective_lens_widens_with_depth() {
        // The eye 60 mm above the plane z = 0, 20 mm above the slice z = 40: the cone
        // through the rim has a radius proportional to the distance from the eye, so the
        // section at z = 0 is three times the one at z = 40.
        let (grid, axes) = axial_setup();
        let camera = look_down(Projection::Perspective { fov_y: 40f32.to_radians() });
        let rays = LensRays::of(&Lens::magnifier(Vec2::ZERO, 0.3, 0.1, 2.0), &camera, Screen::new(100, 100)).unwrap();
        let radius = |index: u32| {
            let c = &section(&rays.rim, grid.world_to_index(), &grid, &axes, index)[0];
            let centre = c.iter().copied().sum::<Vec2>() / c.len() as f32;
            c[0].distance(centre)
        };
        // tan 20° · 0.3 · 20 mm at z = 40, the same times 60 mm at z = 0.
        let expected = 20f32.to_radians().tan() * 0.3 * 20.0;
        assert!((radius(40) - expected).abs() < 0.02 * expected, "{} vs {expected}", radius(40));
        assert!((radius(0) / radius(40) - 3.0).abs() < 0.01);
    }

    #[test]
    fn rays_along_the_slice_draw_nothing_and_fisheyes_have_no_outline() {
        // An orthographic camera looking along the axial planes (from the front): every
        // ray is parallel to an axial slice.
        let grid = Grid::new(UVec3::splat(40), Vec3::ONE);
        let axes = SliceAxes::of(grid.direction, Orientation::Axial);
        let camera =
            Camera::look_at(Vec3::new(20.0, -60.0, 20.0), Vec3::new(20.0, 20.0, 20.0), Vec3::Z, Projection::Orthographic { height: 40.0 });
        let rays = LensRays::of(&Lens::magnifier(Vec2::ZERO, 0.3, 0.1, 2.0), &camera, Screen::new(100, 100)).unwrap();
        assert!(section(&rays.rim, grid.world_to_index(), &grid, &axes, 20).is_empty());
        let fisheye =
            Lens { kind: LensKind::Angular { field_of_view: 180.0, whole_view: true }, ..Lens::magnifier(Vec2::ZERO, 0.3, 0.1, 2.0) };
        assert!(LensRays::of(&fisheye, &camera, Screen::new(100, 100)).is_none());
    }

    #[test]
    fn a_curve_cut_by_the_horizon_comes_in_one_piece() {
        // Rays 0, 1 meet the plane, 2 does not, 3, 4 do: one piece 3, 4, 0, 1.
        let grid = Grid::new(UVec3::splat(10), Vec3::ONE);
        let axes = SliceAxes::of(grid.direction, Orientation::Axial);
        let down = |x: f32| Ray { origin: Vec3::new(x, 5.0, 9.0), dir: Vec3::NEG_Z };
        let rays = [down(1.0), down(2.0), Ray { origin: Vec3::new(3.0, 5.0, 9.0), dir: Vec3::X }, down(4.0), down(5.0)];
        let pieces = section(&rays, grid.world_to_index(), &grid, &axes, 2);
        assert_eq!(pieces.len(), 1);
        let xs: Vec<f32> = pieces[0].iter().map(|p| 9.0 - p.x).collect();
        assert_eq!(xs, vec![4.0, 5.0, 1.0, 2.0]);
    }
}
