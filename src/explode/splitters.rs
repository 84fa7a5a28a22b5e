//! The three splitters of Bruckner and Gröller 2006, section 3.1, as pure functions of
//! the current view: each gives a world plane, and [`in_part_frame`] carries it into a
//! part's rest frame (parts are split where they are now, exploded or not).
//!
//! - **Axis splitter**: a click on a part splits the first part hit along the plane
//!   through the hit point whose normal is the view direction × a screen axis (the
//!   plane holds the viewing ray and the other screen axis: it cuts the part into a
//!   left and a right, or a top and a bottom half as seen).
//! - **Depth splitter**: a click splits at the depth of the first visible background
//!   point, with the plane parallel to the image (normal: the view direction).
//! - **Line splitter**: a segment drawn on the screen splits every part whose
//!   projection it crosses, along the plane through the segment (the plane that holds
//!   the viewing rays through its ends).

use glam::{Affine3A, Vec2, Vec3};

use super::parts::Polyhedron;
use crate::region::{Camera, Plane};

/// The screen axes an axis splitter can use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScreenAxis {
    /// The plane holds the screen's horizontal: parts are cut into a top and a bottom.
    Horizontal,
    /// The plane holds the screen's vertical: parts are cut into a left and a right.
    Vertical,
}

/// The axis splitter's plane through `hit` seen by `camera`: normal = view direction ×
/// the screen axis.
pub fn axis_plane(camera: &Camera, hit: Vec3, axis: ScreenAxis) -> Plane {
    let view = (hit - camera.position).normalize_or(camera.forward());
    let along = match axis {
        ScreenAxis::Horizontal => camera.right(),
        ScreenAxis::Vertical => camera.up(),
    };
    Plane::through(hit, view.cross(along))
}

/// The depth splitter's plane through `hit`, parallel to the image.
pub fn depth_plane(camera: &Camera, hit: Vec3) -> Plane {
    Plane::through(hit, camera.forward())
}

/// The line splitter's plane through the screen segment `a`–`b` (pixels of a
/// `width`×`height` image): the plane holding the viewing rays through both ends. `None`
/// for a segment too short to give one.
pub fn line_plane(camera: &Camera, a: Vec2, b: Vec2, width: u32, height: u32) -> Option<Plane> {
    if a.distance(b) < 1.0 {
        return None;
    }
    let (ra, rb) = (camera.ray(a.x, a.y, width, height), camera.ray(b.x, b.y, width, height));
    // Perspective: the rays share the eye; orthographic: the rays are parallel.
    let n = ra.dir.cross(rb.dir);
    let n = if n.length() > 1e-6 { n } else { ra.dir.cross(rb.origin - ra.origin) };
    (n.length() > 1e-9).then(|| Plane::through(ra.origin, n))
}

/// Whether the segment `a`–`b` on the screen crosses the projection of `part` (in the
/// world, as `to_world` places it) along `plane` (the segment's [`line_plane`]): the
/// part's section by the plane, projected, overlaps the segment.
pub fn segment_crosses(camera: &Camera, part: &Polyhedron, to_world: Affine3A, plane: Plane, a: Vec2, b: Vec2, size: Vec2) -> bool {
    let Some((near, _)) = part.split(in_part_frame(plane, to_world)) else { return false };
    let local = in_part_frame(plane, to_world);
    let section: Vec<Vec3> = near.vertices.iter().copied().filter(|v| local.distance(*v).abs() < 1e-3 * (1.0 + v.length())).collect();
    let ab = b - a;
    let along: Vec<f32> = section
        .iter()
        .filter_map(|v| camera.to_pixel(to_world.transform_point3(*v), size.x, size.y))
        .map(|p| (p - a).dot(ab) / ab.length_squared())
        .collect();
    let lo = along.iter().copied().fold(f32::INFINITY, f32::min);
    let hi = along.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    lo <= 1.0 && hi >= 0.0
}

/// A world plane in the rest frame of a part that `to_world` places: `n·p ≤ d` with
/// `p = M·q` is `(Aᵀn)·q ≤ d − n·t` for `M = (A, t)` (a rigid motion keeps it unit).
pub fn in_part_frame(plane: Plane, to_world: Affine3A) -> Plane {
    let a = glam::Mat3::from(to_world.matrix3);
    let t = Vec3::from(to_world.translation);
    let n = a.transpose() * plane.normal;
    let len = n.length().max(1e-12);
    Plane { normal: n / len, offset: (plane.offset - plane.normal.dot(t)) / len }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::region::Projection;

    fn camera() -> Camera {
        // Looking down −y from (0, 10, 0), up +z: screen right is −x.
        Camera::look_at(Vec3::new(0.0, 10.0, 0.0), Vec3::ZERO, Vec3::Z, Projection::Perspective { fov_y: 0.8 })
    }

    #[test]
    fn axis_and_depth_planes() {
        let cam = camera();
        let hit = Vec3::new(0.5, 1.0, 0.2);
        // The plane holds the viewing ray and the screen's horizontal (±x): its normal is
        // ±z tilted towards the ray, and both the hit and the eye lie on it.
        let h = axis_plane(&cam, hit, ScreenAxis::Horizontal);
        assert!(h.distance(hit).abs() < 1e-5 && h.distance(cam.position).abs() < 1e-4);
        assert!(h.distance(hit + cam.right()).abs() < 1e-5, "holds the screen's horizontal");
        let v = axis_plane(&cam, hit, ScreenAxis::Vertical);
        assert!(v.distance(cam.position).abs() < 1e-4 && v.distance(hit + cam.up()).abs() < 1e-5);
        // By hand, the hit straight below the eye: normal (0, −1, 0) × (−1, 0, 0) = (0, 0, −1).
        let below = axis_plane(&cam, Vec3::ZERO, ScreenAxis::Horizontal);
        assert!((below.normal - Vec3::NEG_Z).length() < 1e-5 && below.offset.abs() < 1e-5);
        let d = depth_plane(&cam, hit);
        assert!((d.normal - Vec3::NEG_Y).length() < 1e-5 && (d.offset - -1.0).abs() < 1e-5);
    }

    #[test]
    fn line_planes_hold_the_rays_through_the_segment() {
        let cam = camera();
        let (a, b) = (Vec2::new(40.0, 50.0), Vec2::new(160.0, 120.0));
        let plane = line_plane(&cam, a, b, 200, 200).unwrap();
        for p in [a, b, (a + b) * 0.5] {
            let ray = cam.ray(p.x, p.y, 200, 200);
            assert!(plane.distance(ray.at(3.0)).abs() < 1e-4 && plane.distance(ray.at(17.0)).abs() < 1e-4, "{p}");
        }
        assert!(line_plane(&cam, a, a, 200, 200).is_none());
        // A cube at the centre: a segment across the middle of the screen crosses it, one
        // in a corner does not (though its plane may cut the cube).
        let cube = Polyhedron::cuboid(Vec3::splat(-1.0), Vec3::splat(1.0));
        let size = Vec2::splat(200.0);
        let across = (Vec2::new(20.0, 100.0), Vec2::new(180.0, 110.0));
        let p = line_plane(&cam, across.0, across.1, 200, 200).unwrap();
        assert!(segment_crosses(&cam, &cube, Affine3A::IDENTITY, p, across.0, across.1, size));
        let corner = (Vec2::new(0.0, 0.0), Vec2::new(30.0, 40.0));
        let p = line_plane(&cam, corner.0, corner.1, 200, 200).unwrap();
        assert!(!segment_crosses(&cam, &cube, Affine3A::IDENTITY, p, corner.0, corner.1, size));
        // The same cube moved 100 px worth to the side: the middle segment misses it.
        let moved = Affine3A::from_translation(Vec3::new(5.0, 0.0, 0.0));
        let p = line_plane(&cam, across.0, across.1, 200, 200).unwrap();
        assert!(!segment_crosses(&cam, &cube, moved, p, Vec2::new(90.0, 100.0), Vec2::new(110.0, 105.0), size));
    }

    #[test]
    fn planes_follow_a_part_into_its_rest_frame() {
        // A part turned 90° about z and moved by (1, 2, 3): the world plane x ≤ 1 is, in
        // its rest frame, q·(Aᵀx̂) ≤ 1 − 1 → −q_y ≤ 0 (a world x is a rest −y... by hand:
        // A x̂_rest = ŷ, A ŷ_rest = −x̂, so Aᵀ x̂ = −ŷ).
        let m = Affine3A::from_rotation_translation(glam::Quat::from_rotation_z(std::f32::consts::FRAC_PI_2), Vec3::new(1.0, 2.0, 3.0));
        let p = in_part_frame(Plane { normal: Vec3::X, offset: 1.0 }, m);
        assert!((p.normal - Vec3::NEG_Y).length() < 1e-5 && p.offset.abs() < 1e-5, "{p:?}");
        // Any rest point and its world image are on the same side by the same distance.
        let world = Plane::through(Vec3::new(0.3, -0.2, 1.0), Vec3::new(1.0, 2.0, -0.5));
        let local = in_part_frame(world, m);
        for q in [Vec3::ZERO, Vec3::new(1.0, -2.0, 0.5), Vec3::splat(3.0)] {
            assert!((local.distance(q) - world.distance(m.transform_point3(q))).abs() < 1e-4);
        }
    }
}
