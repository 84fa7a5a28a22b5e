//! The angular lens (Wang et al. 2005, §3.4): an angular fisheye in which a pixel's
//! distance from the lens centre is proportional to the angle between its ray and the
//! central ray, `θ = (r/lr)·Θ/2` for a lens of radius `lr` and field of view `Θ` (up to
//! 360°, so the rim of a 360° lens looks straight back). The ray turns from the central
//! direction `c` towards the pixel's direction on the image,
//! `d = c·cos θ + u·sin θ` with `u` the unit image-plane direction of the pixel's offset.
//! All rays start at the central ray's origin (the eye), so a camera inside the volume
//! sees all around it (the paper's virtual colonoscopy). As a whole-view lens the circle
//! touches the top and bottom of the image and the corners outside it stay empty.

use glam::{Vec2, Vec3};

use crate::region::Ray;

/// The fisheye ray of offset `v` (lens units) from the centre of a lens of radius `lr`
/// with half field of view `half_angle`; `right`, `up` are the camera's axes.
pub fn fisheye(central: Ray, right: Vec3, up: Vec3, v: Vec2, lr: f32, half_angle: f32) -> Ray {
    let r = v.length();
    if r <= 1e-9 {
        return central;
    }
    let theta = r / lr * half_angle;
    let side = right * (v.x / r) + up * (v.y / r);
    let u = (side - central.dir * side.dot(central.dir)).normalize_or_zero();
    Ray { origin: central.origin, dir: (central.dir * theta.cos() + u * theta.sin()).normalize() }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::PI;

    fn central() -> Ray {
        Ray { origin: Vec3::ZERO, dir: Vec3::NEG_Z }
    }

    #[test]
    fn the_rim_maps_to_the_requested_angle() {
        for fov_deg in [90.0f32, 180.0, 270.0, 360.0] {
            let half = fov_deg.to_radians() / 2.0;
            for v in [Vec2::new(0.4, 0.0), Vec2::new(0.0, -0.4), Vec2::new(0.2828427, 0.2828427)] {
                let ray = fisheye(central(), Vec3::X, Vec3::Y, v, 0.4, half);
                let angle = ray.dir.dot(Vec3::NEG_Z).clamp(-1.0, 1.0).acos();
                assert!((angle - half.min(PI)).abs() < 1e-3, "fov {fov_deg}: {angle}");
            }
        }
        // 360°: the rim looks straight back.
        let back = fisheye(central(), Vec3::X, Vec3::Y, Vec2::new(0.0, 0.4), 0.4, PI);
        assert!((back.dir - Vec3::Z).length() < 1e-5);
    }

    #[test]
    fn angle_is_proportional_to_distance() {
        // Half way to the rim of a 180° lens: 45°, turned towards +x (right).
        let ray = fisheye(central(), Vec3::X, Vec3::Y, Vec2::new(0.2, 0.0), 0.4, PI / 2.0);
        let want = Vec3::new((PI / 4.0).sin(), 0.0, -(PI / 4.0).cos());
        assert!((ray.dir - want).length() < 1e-6);
    }
}
