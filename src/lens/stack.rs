//! The lenses of one view, resolved for its camera, and the ray of every pixel under
//! them: the ray-generation stage of the per-pixel function (the shader's
//! `focal::lens` does the same).
//!
//! Lenses apply in order, each to the ray the lenses before it produced: a magnifier
//! bends that ray (inside its border it blends back to it, so a magnifier over another
//! lens stays continuous), a sampling or angular lens replaces it with the camera ray it
//! computes. Where two lenses overlap, the later one (on top) therefore decides the
//! focus of its own area and its border blends into the lens underneath.

use glam::{Vec2, Vec3};

use std::sync::Arc;

use super::angular::fisheye;
use super::feature::{FeatureField, FeatureJob, feature_mask};
use super::magnifier::Magnifier;
use super::sampling::{TABLE_SIZE, lookup};
use super::screen::Screen;
use super::shape::Shape;
use super::spec::{Lens, LensKind};
use crate::region::{Camera, Projection, Ray, RenderScene};

/// Most lenses per view (the GPU keeps them in the view uniform).
pub const MAX_LENSES: usize = 4;

/// What a resolved lens does.
#[derive(Clone, Debug, PartialEq)]
pub enum Effect {
    Magnifier(Magnifier),
    /// Baked `ρ/lr` table of the sampling function.
    Sampling(Box<[f32; TABLE_SIZE]>),
    Angular {
        half_angle: f32,
        whole_view: bool,
    },
}

/// A lens resolved for one camera and image.
#[derive(Clone, Debug, PartialEq)]
pub struct ResolvedLens {
    pub center: Vec2,
    /// Focus radius (the equivalent radius for a drawn shape or a feature).
    pub radius: f32,
    pub border: f32,
    pub shape: Shape,
    pub effect: Effect,
    /// A feature lens's silhouette in this view (found on the CPU).
    pub field: Option<Arc<FeatureField>>,
    /// A feature lens's silhouette search; with no `field`, the GPU finds it and the
    /// centre and radius here are placeholders.
    pub job: Option<FeatureJob>,
}

/// Where feature lenses find their silhouettes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Silhouettes {
    Cpu,
    /// Left to the GPU's compute passes (the render pass).
    Gpu,
}

/// Resolves `lens` for `camera`; `scene` is the bounding sphere of what is shown
/// (centre, radius), used for the default focus depth.
pub fn resolve(lens: &Lens, camera: &Camera, screen: Screen, scene: (Vec3, f32)) -> ResolvedLens {
    let perspective = matches!(camera.projection, Projection::Perspective { .. });
    let mut radius = lens.shape.focus_radius(lens.radius);
    let effect = match &lens.kind {
        LensKind::Magnifier { magnification, profile, focus_depth, plane_depth } => {
            let central = screen.camera_ray(camera, lens.center);
            let to_centre = (scene.0 - central.origin).dot(central.dir);
            let focus = focus_depth.unwrap_or(if to_centre > scene.1 * 0.05 { to_centre } else { scene.1.max(1e-3) });
            Effect::Magnifier(Magnifier::resolve(*magnification, *profile, perspective, focus, *plane_depth, scene.1))
        }
        LensKind::Sampling(s) => Effect::Sampling(Box::new(s.table())),
        LensKind::Angular { field_of_view, whole_view } => {
            if *whole_view {
                radius = 1.0;
            }
            Effect::Angular { half_angle: field_of_view.to_radians() * 0.5, whole_view: *whole_view }
        }
    };
    let center = if matches!(effect, Effect::Angular { whole_view: true, .. }) { Vec2::ZERO } else { lens.center };
    ResolvedLens { center, radius, border: lens.border, shape: lens.shape.clone(), effect, field: None, job: None }
}

/// Resolves `lens` for `camera` in `scene`: a feature lens finds its feature's
/// silhouette ([`super::feature`]) and centres on it; `None` when its feature is not in
/// view.
pub fn resolve_in(lens: &Lens, camera: &Camera, screen: Screen, scene: &RenderScene) -> Option<ResolvedLens> {
    resolve_with(lens, camera, screen, scene, Silhouettes::Cpu)
}

/// [`resolve_in`], leaving the silhouettes to the GPU when asked (`None` then only when
/// no region shows the feature).
pub fn resolve_with(lens: &Lens, camera: &Camera, screen: Screen, scene: &RenderScene, silhouettes: Silhouettes) -> Option<ResolvedLens> {
    let bounds = scene.bounding_sphere();
    let Shape::Feature(feature) = &lens.shape else { return Some(resolve(lens, camera, screen, bounds)) };
    let job = FeatureJob::new(scene, feature, screen)?;
    // The focus depth on the view axis: the centroid is not known yet.
    let placed = Lens { center: Vec2::ZERO, shape: Shape::Circle, ..lens.clone() };
    let mut resolved = resolve(&placed, camera, screen, bounds);
    resolved.shape = lens.shape.clone();
    resolved.job = Some(job);
    match silhouettes {
        Silhouettes::Gpu => Some(resolved),
        Silhouettes::Cpu => resolved.with_silhouette(camera, screen, scene),
    }
}

impl ResolvedLens {
    /// This lens with its feature's silhouette found on the CPU when it was left to the
    /// GPU (other lenses unchanged); `None` when the feature is not in view.
    pub fn with_silhouette(mut self, camera: &Camera, screen: Screen, scene: &RenderScene) -> Option<ResolvedLens> {
        let Some(job) = self.job.filter(|_| self.field.is_none()) else { return Some(self) };
        let field = FeatureField::from_mask(&feature_mask(scene, &job, camera, screen), job.grid)?;
        self.center = field.centroid;
        self.radius = field.equivalent_radius();
        self.field = Some(Arc::new(field));
        Some(self)
    }

    /// Radial coordinate of offset `v` from the centre: the shape's, or for a feature
    /// `lr + d` with `d` the signed distance to its silhouette.
    pub fn radial(&self, v: Vec2) -> f32 {
        match &self.field {
            Some(field) => self.radius + field.distance_at(self.center + v),
            None => self.shape.radial(v),
        }
    }

    /// The ray at lens coordinates `s` given the ray `below` of the lenses before this
    /// one; `None` where the lens shows nothing (outside a whole-view fisheye).
    pub fn apply(&self, camera: &Camera, screen: Screen, s: Vec2, below: Ray) -> Option<Ray> {
        let v = s - self.center;
        let r = self.radial(v);
        match &self.effect {
            Effect::Magnifier(m) => {
                let reach = if m.profile == super::Profile::Simple { self.radius } else { self.radius + self.border };
                Some(if r < reach { m.bend(screen.camera_ray(camera, self.center), below, r, self.radius, self.border) } else { below })
            }
            Effect::Sampling(table) => {
                if r >= self.radius || r <= 0.0 {
                    return Some(below);
                }
                let rho = lookup(table, r / self.radius) * self.radius;
                Some(screen.camera_ray(camera, self.center + v * (rho / r)))
            }
            Effect::Angular { half_angle, whole_view } => {
                if r >= self.radius {
                    return if *whole_view { None } else { Some(below) };
                }
                let central = screen.camera_ray(camera, self.center);
                Some(fisheye(central, camera.right(), camera.up(), v, self.radius, *half_angle))
            }
        }
    }
}

/// The ray of pixel position `(px, py)` under `lenses` (`None`: no ray, an empty pixel).
pub fn lens_ray(camera: &Camera, screen: Screen, lenses: &[ResolvedLens], px: f32, py: f32) -> Option<Ray> {
    let s = screen.to_lens(px, py);
    let mut ray = camera.ray(px, py, screen.width as u32, screen.height as u32);
    for lens in lenses {
        ray = lens.apply(camera, screen, s, ray)?;
    }
    Some(ray)
}

/// Local magnification at pixel `(px, py)` for structures at view depth `depth`
/// (distance along the camera's forward axis): the square root of the ratio of the
/// areas a small pixel square covers at that depth without and with the lenses.
pub fn local_magnification(camera: &Camera, screen: Screen, lenses: &[ResolvedLens], px: f32, py: f32, depth: f32) -> Option<f32> {
    let fwd = camera.forward();
    let at_depth = |ray: Ray| {
        let along = ray.dir.dot(fwd);
        (along > 1e-6).then(|| ray.at((depth - (ray.origin - camera.position).dot(fwd)) / along))
    };
    let h = 0.5;
    let corners = |f: &dyn Fn(f32, f32) -> Option<Ray>| -> Option<f32> {
        let a = at_depth(f(px - h, py - h)?)?;
        let b = at_depth(f(px + h, py - h)?)?;
        let c = at_depth(f(px - h, py + h)?)?;
        Some((b - a).cross(c - a).length())
    };
    let plain = corners(&|x, y| Some(camera.ray(x, y, screen.width as u32, screen.height as u32)))?;
    let lensed = corners(&|x, y| lens_ray(camera, screen, lenses, x, y))?;
    (lensed > 0.0).then(|| (plain / lensed).sqrt())
}

/// Checks a view's lenses: at most [`MAX_LENSES`], each valid (named by its index
/// and kind in the message).
pub fn validate_lenses(lenses: &[Lens]) -> Result<(), String> {
    if lenses.len() > MAX_LENSES {
        return Err(format!("{} lenses, at most {} are supported per view", lenses.len(), MAX_LENSES));
    }
    for (i, l) in lenses.iter().enumerate() {
        l.validate().map_err(|e| format!("lens {i} ({}): {e}", l.kind_name()))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lens::{Profile, Sampling};

    fn camera(perspective: bool) -> Camera {
        let projection = if perspective { Projection::Perspective { fov_y: 0.6 } } else { Projection::Orthographic { height: 200.0 } };
        Camera::look_at(Vec3::new(0.0, 0.0, 500.0), Vec3::ZERO, Vec3::Y, projection)
    }

    #[test]
    fn lens_coordinates_round_trip() {
        let screen = Screen::new(320, 200);
        let s = screen.to_lens(40.0, 150.0);
        let (x, y) = screen.to_pixel(s);
        assert!((x - 40.0).abs() < 1e-4 && (y - 150.0).abs() < 1e-4);
        assert_eq!(screen.to_lens(160.0, 100.0), Vec2::ZERO);
        assert!((screen.to_lens(320.0, 0.0) - Vec2::new(1.6, 1.0)).length() < 1e-6);
    }

    #[test]
    fn magnifier_magnifies_the_focus_at_its_depth_and_leaves_the_outside() {
        let screen = Screen::new(200, 200);
        for perspective in [true, false] {
            let cam = camera(perspective);
            let lens = Lens::magnifier(Vec2::ZERO, 0.3, 0.2, 3.0);
            let resolved = [resolve(&lens, &cam, screen, (Vec3::ZERO, 100.0))];
            let m = local_magnification(&cam, screen, &resolved, 105.0, 95.0, 500.0).unwrap();
            assert!((m - 3.0).abs() < 0.01, "{perspective}: m = {m}");
            // Outside the border (radius 0.5 = 50 pixels): the camera's own ray.
            let outside = lens_ray(&cam, screen, &resolved, 170.0, 100.0).unwrap();
            assert_eq!(outside, cam.ray(170.0, 100.0, 200, 200));
            let m = local_magnification(&cam, screen, &resolved, 170.0, 100.0, 500.0).unwrap();
            assert!((m - 1.0).abs() < 1e-3);
        }
    }

    #[test]
    fn rays_are_continuous_across_both_edges() {
        let screen = Screen::new(400, 400);
        let cam = camera(true);
        for profile in [Profile::Linear, Profile::Cubic] {
            let mut lens = Lens::magnifier(Vec2::ZERO, 0.3, 0.2, 4.0);
            lens.kind = LensKind::Magnifier { magnification: 4.0, profile, focus_depth: None, plane_depth: None };
            let resolved = [resolve(&lens, &cam, screen, (Vec3::ZERO, 100.0))];
            // Pixel radius of the inner edge 60, outer edge 100 (200 = 1 unit).
            for edge in [60.0, 100.0] {
                let at_depth = |r: Ray| r.at((500.0 - (r.origin - cam.position).dot(cam.forward())) / r.dir.dot(cam.forward()));
                let pa = at_depth(lens_ray(&cam, screen, &resolved, 200.0 + edge - 0.01, 200.0).unwrap());
                let pb = at_depth(lens_ray(&cam, screen, &resolved, 200.0 + edge + 0.01, 200.0).unwrap());
                assert!((pa - pb).length() < 0.05, "{profile:?} jumps {} at {edge}", (pa - pb).length());
            }
        }
    }

    #[test]
    fn sampling_lens_magnifies_its_centre_by_the_centre_rate() {
        let screen = Screen::new(200, 200);
        let cam = camera(false);
        let lens = Lens { kind: LensKind::Sampling(Sampling::Cubic { center_rate: 3.0 }), ..Lens::magnifier(Vec2::ZERO, 0.5, 0.0, 2.0) };
        let resolved = [resolve(&lens, &cam, screen, (Vec3::ZERO, 100.0))];
        let m = local_magnification(&cam, screen, &resolved, 100.5, 100.5, 500.0).unwrap();
        assert!((m - 3.0).abs() < 0.1, "{m}");
        // Directions stay.
        let ray = lens_ray(&cam, screen, &resolved, 120.0, 110.0).unwrap();
        assert!((ray.dir - cam.forward()).length() < 1e-6);
        // The rim maps onto itself.
        let rim = lens_ray(&cam, screen, &resolved, 149.9, 100.0).unwrap();
        assert!((rim.origin - cam.ray(149.9, 100.0, 200, 200).origin).length() < 0.5);
    }

    #[test]
    fn whole_view_fisheye_leaves_the_corners_empty() {
        let screen = Screen::new(300, 200);
        let cam = camera(true);
        let lens =
            Lens { kind: LensKind::Angular { field_of_view: 180.0, whole_view: true }, ..Lens::magnifier(Vec2::ZERO, 0.3, 0.0, 1.0) };
        let resolved = [resolve(&lens, &cam, screen, (Vec3::ZERO, 100.0))];
        assert!(lens_ray(&cam, screen, &resolved, 1.0, 1.0).is_none());
        // The top edge of the centre column looks 90° up.
        // (Half a pixel below the rim: 0.995 of 90°.)
        let up = lens_ray(&cam, screen, &resolved, 150.0, 0.5).unwrap();
        assert!((up.dir - Vec3::Y).length() < 0.01, "{:?}", up.dir);
    }
}
