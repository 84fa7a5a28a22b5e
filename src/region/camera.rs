//! The viewing camera of the per-pixel function: perspective or orthographic.
//!
//! Conventions follow Bevy: the camera looks down its local −Z axis with +Y up. Pixel
//! `(px, py)` (top-left origin, centres at half-integers) maps to normalised device
//! coordinates `x = 2·px/w − 1`, `y = 1 − 2·py/h`. A perspective ray leaves the eye
//! towards `R·(x·tan(fov/2)·aspect, y·tan(fov/2), −1)`; an orthographic ray starts at
//! `eye + R·(x·height/2·aspect, y·height/2, 0)` and runs along `R·(0, 0, −1)`.

use glam::{Quat, Vec3};
use serde::{Deserialize, Serialize};

/// Projection of a camera.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Projection {
    /// Vertical field of view in radians.
    Perspective { fov_y: f32 },
    /// World-space height of the view.
    Orthographic { height: f32 },
}

/// A camera pose and projection.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    pub position: Vec3,
    pub rotation: Quat,
    pub projection: Projection,
}

/// A ray with a unit direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
}

impl Ray {
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

impl Camera {
    /// A camera at `eye` looking at `target` with `up` roughly up.
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3, projection: Projection) -> Camera {
        let forward = (target - eye).normalize();
        let right = forward.cross(up).normalize();
        let up = right.cross(forward);
        let rotation = Quat::from_mat3(&glam::Mat3::from_cols(right, up, -forward));
        Camera { position: eye, rotation, projection }
    }

    /// Unit viewing direction (local −Z).
    pub fn forward(&self) -> Vec3 {
        self.rotation * Vec3::NEG_Z
    }

    pub fn up(&self) -> Vec3 {
        self.rotation * Vec3::Y
    }

    pub fn right(&self) -> Vec3 {
        self.rotation * Vec3::X
    }

    /// Normalised device coordinates (x right, y up, −1…1 across the image) of a world
    /// point seen in an image of aspect `width / height`; `None` behind a perspective
    /// camera. The inverse of [`Self::ray`].
    pub fn to_ndc(&self, p: Vec3, aspect: f32) -> Option<(f32, f32)> {
        let q = self.rotation.inverse() * (p - self.position);
        match self.projection {
            Projection::Perspective { fov_y } => {
                let k = (fov_y * 0.5).tan();
                (q.z < -1e-6).then(|| (q.x / (-q.z * k * aspect), q.y / (-q.z * k)))
            }
            Projection::Orthographic { height } => Some((q.x / (height * 0.5 * aspect), q.y / (height * 0.5))),
        }
    }

    /// Pixel position (from the top left) of a world point in a `width × height` image.
    pub fn to_pixel(&self, p: Vec3, width: f32, height: f32) -> Option<glam::Vec2> {
        let (x, y) = self.to_ndc(p, width / height.max(1e-6))?;
        Some(glam::Vec2::new((x + 1.0) * 0.5 * width, (1.0 - y) * 0.5 * height))
    }

    /// The ray through pixel position `(px, py)` of a `width × height` image.
    pub fn ray(&self, px: f32, py: f32, width: u32, height: u32) -> Ray {
        let aspect = width as f32 / height as f32;
        let x = 2.0 * px / width as f32 - 1.0;
        let y = 1.0 - 2.0 * py / height as f32;
        match self.projection {
            Projection::Perspective { fov_y } => {
                let k = (fov_y * 0.5).tan();
                let d = Vec3::new(x * k * aspect, y * k, -1.0);
                Ray { origin: self.position, dir: (self.rotation * d).normalize() }
            }
            Projection::Orthographic { height: h } => {
                let o = Vec3::new(x * h * 0.5 * aspect, y * h * 0.5, 0.0);
                Ray { origin: self.position + self.rotation * o, dir: self.forward() }
            }
        }
    }
}

/// Standard views of a dataset, named from the patient's side (RAS world: +x right,
/// +y anterior, +z superior).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum View {
    /// From the front (anterior), head up.
    #[default]
    Anterior,
    Posterior,
    Left,
    Right,
    /// From above.
    Superior,
    Inferior,
    /// Three-quarter view from front-left-above.
    Oblique,
}

impl View {
    pub const ALL: [View; 7] = [View::Anterior, View::Posterior, View::Left, View::Right, View::Superior, View::Inferior, View::Oblique];

    pub fn name(self) -> &'static str {
        match self {
            View::Anterior => "anterior",
            View::Posterior => "posterior",
            View::Left => "left",
            View::Right => "right",
            View::Superior => "superior",
            View::Inferior => "inferior",
            View::Oblique => "oblique",
        }
    }

    /// Direction from the target towards the eye, and the up vector.
    pub fn direction_and_up(self) -> (Vec3, Vec3) {
        match self {
            View::Anterior => (Vec3::Y, Vec3::Z),
            View::Posterior => (-Vec3::Y, Vec3::Z),
            View::Left => (-Vec3::X, Vec3::Z),
            View::Right => (Vec3::X, Vec3::Z),
            View::Superior => (Vec3::Z, Vec3::Y),
            View::Inferior => (-Vec3::Z, Vec3::Y),
            View::Oblique => (Vec3::new(-0.55, 0.75, 0.38).normalize(), Vec3::Z),
        }
    }

    /// A camera that shows a sphere of `radius` around `center` whole.
    pub fn frame(self, center: Vec3, radius: f32, orthographic: bool) -> Camera {
        let (dir, up) = self.direction_and_up();
        let fov_y = 30f32.to_radians();
        let distance = radius / (fov_y * 0.5).sin() * 1.02;
        let projection = if orthographic { Projection::Orthographic { height: 2.04 * radius } } else { Projection::Perspective { fov_y } };
        Camera::look_at(center + dir * distance, center, up, projection)
    }
}

impl View {
    /// A camera from this side that fits the box `[lo, hi]` tightly into a view of the
    /// given aspect ratio (width / height), with a small margin.
    pub fn frame_box(self, lo: Vec3, hi: Vec3, aspect: f32, orthographic: bool) -> Camera {
        let (dir, up) = self.direction_and_up();
        let center = (lo + hi) * 0.5;
        let probe = Camera::look_at(center + dir, center, up, Projection::Orthographic { height: 1.0 });
        let (right, up, back) = (probe.right(), probe.up(), dir);
        let corners = (0..8).map(|c| {
            Vec3::new(if c & 1 == 0 { lo.x } else { hi.x }, if c & 2 == 0 { lo.y } else { hi.y }, if c & 4 == 0 { lo.z } else { hi.z })
                - center
        });
        let margin = 1.05;
        let aspect = aspect.max(1e-3);
        if orthographic {
            let half = corners.fold(0.0f32, |m, c| m.max(c.dot(up).abs()).max(c.dot(right).abs() / aspect));
            let depth = (hi - lo).length();
            return Camera::look_at(center + dir * depth, center, probe.up(), Projection::Orthographic { height: 2.0 * half * margin });
        }
        let fov_y = 30f32.to_radians();
        let tan = (fov_y * 0.5).tan() / margin;
        // Every corner c must satisfy |c·up| ≤ (D − c·back)·tan and |c·right| ≤ (D − c·back)·tan·aspect.
        let distance =
            corners.fold(0.0f32, |d, c| d.max(c.dot(back) + c.dot(up).abs() / tan).max(c.dot(back) + c.dot(right).abs() / (tan * aspect)));
        Camera::look_at(center + dir * distance, center, probe.up(), Projection::Perspective { fov_y })
    }
}

/// A camera orbiting a target: azimuth around the superior (+z) axis, measured from the
/// anterior side (azimuth 0° looks at the face, 90° at the patient's left side),
/// elevation above the axial plane. Direction from the target to the eye:
/// `(−sin az·cos el, cos az·cos el, sin el)`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Orbit {
    pub target: Vec3,
    pub azimuth_deg: f32,
    pub elevation_deg: f32,
    pub distance: f32,
    pub projection: Projection,
}

impl Orbit {
    /// Unit direction from the target to the eye.
    pub fn direction(&self) -> Vec3 {
        let (az, el) = (self.azimuth_deg.to_radians(), self.elevation_deg.to_radians());
        Vec3::new(-az.sin() * el.cos(), az.cos() * el.cos(), el.sin())
    }

    pub fn camera(&self) -> Camera {
        let dir = self.direction();
        // Looking straight down or up, "up" is anterior instead of superior.
        let up = if dir.z.abs() > 0.999 { Vec3::Y * -dir.z.signum() } else { Vec3::Z };
        Camera::look_at(self.target + dir * self.distance, self.target, up, self.projection)
    }
}

impl std::str::FromStr for View {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let s = s.trim().to_ascii_lowercase();
        let alias = match s.as_str() {
            "front" | "+y" | "y" => "anterior",
            "back" | "-y" => "posterior",
            "top" | "+z" | "z" => "superior",
            "bottom" | "-z" => "inferior",
            "+x" | "x" => "right",
            "-x" => "left",
            "iso" | "three_quarter" => "oblique",
            other => other,
        };
        View::ALL.into_iter().find(|v| v.name() == alias).ok_or_else(|| {
            format!(
                "unknown view '{s}' (anterior/front/+y, posterior/back/-y, left/-x, right/+x, superior/top/+z, inferior/bottom/-z, oblique)"
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rays_follow_the_conventions() {
        let cam = Camera::look_at(Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO, Vec3::Y, Projection::Perspective { fov_y: 90f32.to_radians() });
        assert!((cam.forward() - Vec3::NEG_Z).length() < 1e-6);
        // Centre pixel looks straight ahead.
        let r = cam.ray(50.0, 50.0, 100, 100);
        assert!((r.dir - Vec3::NEG_Z).length() < 1e-6);
        // Top-right corner with a 90° fov and square image: direction (1, 1, −1)/√3.
        let r = cam.ray(100.0, 0.0, 100, 100);
        assert!((r.dir - Vec3::new(1.0, 1.0, -1.0).normalize()).length() < 1e-6, "{}", r.dir);
        let ortho = Camera { projection: Projection::Orthographic { height: 4.0 }, ..cam };
        let r = ortho.ray(0.0, 100.0, 200, 100);
        assert!((r.origin - Vec3::new(-4.0, -2.0, 10.0)).length() < 1e-5, "{}", r.origin);
        assert!((r.dir - Vec3::NEG_Z).length() < 1e-6);
    }

    #[test]
    fn framed_views_see_the_whole_sphere() {
        for v in View::ALL {
            let cam = v.frame(Vec3::new(1.0, 2.0, 3.0), 10.0, false);
            let to_center = (Vec3::new(1.0, 2.0, 3.0) - cam.position).normalize();
            assert!((cam.forward() - to_center).length() < 1e-5, "{v:?}");
            // The edge ray at the top of the image passes outside the sphere.
            let top = cam.ray(50.0, 0.0, 100, 100);
            let d = (Vec3::new(1.0, 2.0, 3.0) - top.origin).cross(top.dir).length();
            assert!(d > 10.0, "{v:?} {d}");
        }
        assert_eq!("top".parse::<View>().unwrap(), View::Superior);
        // A tight box fit: every corner projects inside the image, one touches the margin.
        let (lo, hi) = (Vec3::new(-10.0, -4.0, -2.0), Vec3::new(10.0, 4.0, 2.0));
        for ortho in [false, true] {
            let cam = View::Oblique.frame_box(lo, hi, 1.5, ortho);
            let mut widest = 0.0f32;
            for c in 0..8 {
                let p = Vec3::new(
                    if c & 1 == 0 { lo.x } else { hi.x },
                    if c & 2 == 0 { lo.y } else { hi.y },
                    if c & 4 == 0 { lo.z } else { hi.z },
                );
                let (x, y) = cam.to_ndc(p, 1.5).unwrap();
                assert!(x.abs() <= 1.0 && y.abs() <= 1.0, "{ortho} {x} {y}");
                widest = widest.max(x.abs()).max(y.abs());
            }
            assert!(widest > 0.9, "{ortho}: {widest}");
        }
    }

    #[test]
    fn orbit_angles_follow_the_convention() {
        let o = Orbit {
            target: Vec3::ZERO,
            azimuth_deg: 0.0,
            elevation_deg: 0.0,
            distance: 10.0,
            projection: Projection::Perspective { fov_y: 0.5 },
        };
        assert!((o.camera().position - Vec3::new(0.0, 10.0, 0.0)).length() < 1e-5);
        let left = Orbit { azimuth_deg: 90.0, ..o };
        assert!((left.camera().position - Vec3::new(-10.0, 0.0, 0.0)).length() < 1e-4);
        let top = Orbit { elevation_deg: 90.0, ..o };
        let cam = top.camera();
        assert!((cam.position - Vec3::new(0.0, 0.0, 10.0)).length() < 1e-4);
        assert!((cam.forward() + Vec3::Z).length() < 1e-4);
        assert_eq!("-x".parse::<View>().unwrap(), View::Left);
    }

    #[test]
    fn pixels_of_points_on_a_pixel_ray_are_that_pixel() {
        let (lo, hi) = (Vec3::new(-10.0, -4.0, -2.0), Vec3::new(10.0, 4.0, 2.0));
        for ortho in [false, true] {
            let cam = View::Oblique.frame_box(lo, hi, 1.5, ortho);
            for (px, py) in [(10.5, 20.5), (150.0, 99.5), (299.0, 0.5)] {
                let ray = cam.ray(px, py, 300, 200);
                let p = cam.to_pixel(ray.at(37.0), 300.0, 200.0).unwrap();
                assert!((p.x - px).abs() < 1e-2 && (p.y - py).abs() < 1e-2, "{ortho}: {p} vs {px}, {py}");
            }
        }
        let cam = View::Oblique.frame_box(lo, hi, 1.5, false);
        assert!(cam.to_pixel(cam.position - cam.forward() * 5.0, 300.0, 200.0).is_none());
    }
}
