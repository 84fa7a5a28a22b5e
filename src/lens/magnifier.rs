//! The magnifier of "The Magic Volume Lens" (Wang, Zhao, Mueller, Kaufman 2005, §3.1,
//! equations 1–3): rays bend instead of pixels moving, so the magnified focus keeps
//! its depth and nothing of the context is cut away.
//!
//! Geometry. `c` is the unit direction of the camera ray through the lens centre and
//! `o` its origin. The lens lies in the plane `Π` perpendicular to `c` through
//! `P_O = o + e·c`. A pixel's own ray meets `Π` at `P`.
//!
//! - Focus region (eq. 1): the ray leaves `P` towards the virtual focal point `F` on the
//!   central ray, `F = P_O + c/κ`: its direction is `c + κ·(P_O − P)` (the component
//!   along `c` is 1, so `κ = 0` gives parallel rays and `κ < 0` puts `F` behind `Π`,
//!   rays diverging from it). At depth `z` beyond `Π` the ray is `(1 − κz)` times as far
//!   from the axis as at `P`.
//! - Transition region of width `lb` (eq. 2–3): the direction blends the focused one
//!   back to the pixel's normal one, `d = (1 − w)·d_focus + w·d_normal` (both scaled to
//!   unit component along `c`), with `w` from the border profile
//!   ([`super::profile::Profile::weight`]); rays outside the lens are the normal ones,
//!   so the image is continuous at both edges.
//! - Magnification. A normal ray's distance from the axis grows by `g(z) = (a + z)/a`
//!   (perspective, eye at distance `a = e` before `Π`) or stays (`g = 1`, orthographic),
//!   so structures at depth `z` appear `m(z) = g(z)/(1 − κz)` times larger. Asking for
//!   `m` at the focus depth `D` gives `κ = (1 − g(D)/m)/D`. When `F` lies beyond `Π`
//!   (converging rays, the paper's figure 2) moving `F` towards `Π` raises `m`.
//!
//! Where the lens plane sits decides how `m` varies with depth. By default it sits
//! close to the eye (`e = D/20`; orthographic: `20` scene radii before the focus), so
//! `m(z)` stays within a few percent of `m` over the whole volume and `F` lies just
//! behind the eye: a magnifying glass. A lens plane placed at the front of the volume
//! gives the paper's converging rays, magnification growing with depth up to `F`.

use glam::Vec3;

use super::profile::Profile;
use crate::region::Ray;

/// A magnifier resolved for one camera: everything the per-pixel ray bending needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Magnifier {
    /// Distance from the central ray's origin to the lens plane along `c`.
    pub plane: f32,
    /// Convergence `κ = 1/(distance from Π to F)` (signed; see the module docs).
    pub kappa: f32,
    /// Requested magnification at the focus depth.
    pub magnification: f32,
    pub profile: Profile,
}

/// Normal-ray spread factor `g(z)` at depth `z` beyond a plane at distance `plane` from
/// the eye (perspective) or for parallel rays (`None`).
pub fn spread(perspective: bool, plane: f32, z: f32) -> f32 {
    if perspective { (plane + z) / plane } else { 1.0 }
}

/// `κ` giving magnification `m` at depth `depth` beyond the plane (eq. 1 solved for F).
pub fn kappa_for(m: f32, perspective: bool, plane: f32, depth: f32) -> f32 {
    (1.0 - spread(perspective, plane, depth) / m) / depth
}

/// Magnification of the focus region at depth `z` beyond the plane.
pub fn magnification_at(kappa: f32, perspective: bool, plane: f32, z: f32) -> f32 {
    spread(perspective, plane, z) / (1.0 - kappa * z)
}

impl Magnifier {
    /// Resolves a magnifier: `focus` is the distance from the central ray's origin to
    /// where `m` must hold; `plane` the lens plane's distance (see the module docs for
    /// the default); `scene_radius` sizes the orthographic default.
    pub fn resolve(m: f32, profile: Profile, perspective: bool, focus: f32, plane: Option<f32>, scene_radius: f32) -> Magnifier {
        let focus = focus.max(1e-3);
        let plane = plane.unwrap_or(if perspective { focus / 20.0 } else { focus - 20.0 * scene_radius.max(1e-3) });
        let plane = if perspective { plane.clamp(focus * 1e-3, focus * 0.999) } else { plane.min(focus - 1e-3) };
        let depth = focus - plane;
        Magnifier { plane, kappa: kappa_for(m, perspective, plane, depth), magnification: m, profile }
    }

    /// The ray of a pixel at radial coordinate `r` (lens radius `lr`, border `lb`), given
    /// the central ray and the ray the pixel would have without this lens.
    pub fn bend(&self, central: Ray, below: Ray, r: f32, lr: f32, lb: f32) -> Ray {
        let c = central.dir;
        let p_o = central.origin + c * self.plane;
        let along = below.dir.dot(c);
        if along <= 1e-6 {
            return below;
        }
        let p = below.at((p_o - below.origin).dot(c) / along);
        let focused = c + (p_o - p) * self.kappa;
        let normal = below.dir / along;
        let w = self.profile.weight(r, lr, lb, self.magnification);
        let dir = (focused * (1.0 - w) + normal * w).normalize();
        // Rays start where they cross the plane of the central ray's origin, or at P
        // when that lies behind it (an orthographic lens plane before the camera).
        let back = (central.origin - p).dot(c) / dir.dot(c);
        Ray { origin: if back > 0.0 { p + dir * back } else { p }, dir }
    }

    /// The virtual focal point F for a central ray (`None` for parallel rays).
    pub fn focal_point(&self, central: Ray) -> Option<Vec3> {
        (self.kappa.abs() > 1e-12).then(|| central.origin + central.dir * (self.plane + 1.0 / self.kappa))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axis() -> Ray {
        Ray { origin: Vec3::ZERO, dir: Vec3::NEG_Z }
    }

    /// The perspective ray through image-plane offset `x` at unit distance.
    fn persp(x: f32) -> Ray {
        Ray { origin: Vec3::ZERO, dir: Vec3::new(x, 0.0, -1.0).normalize() }
    }

    fn offset_at_depth(ray: Ray, depth: f32) -> f32 {
        let t = (depth - (-ray.origin.z)) / (-ray.dir.z);
        ray.at(t).x
    }

    #[test]
    fn kappa_from_hand_computed_geometry() {
        // Orthographic, m = 2 at 10 beyond the plane: κ = (1 − 1/2)/10 = 0.05, F at 20.
        assert!((kappa_for(2.0, false, 5.0, 10.0) - 0.05).abs() < 1e-7);
        // Perspective, plane at 1, focus 9 beyond it: g = 10, m = 4 → κ = (1 − 2.5)/9.
        assert!((kappa_for(4.0, true, 1.0, 9.0) + 1.5 / 9.0).abs() < 1e-7);
        // m = 1 in perspective puts F at the eye: κ = −1/plane.
        assert!((kappa_for(1.0, true, 2.0, 7.0) + 0.5).abs() < 1e-7);
        for (k, p, e, z) in [(0.05, false, 5.0, 10.0), (-1.5 / 9.0, true, 1.0, 9.0)] {
            let want = if p { 4.0 } else { 2.0 };
            assert!((magnification_at(k, p, e, z) - want).abs() < 1e-5);
        }
    }

    #[test]
    fn moving_f_towards_the_plane_raises_magnification_when_rays_converge() {
        let m = |f: f32| magnification_at(1.0 / f, false, 0.0, 10.0);
        assert!(m(15.0) > m(20.0) && m(20.0) > m(40.0) && m(40.0) > 1.0);
    }

    #[test]
    fn rays_at_the_centre_in_the_border_and_outside() {
        let lens = Magnifier { plane: 1.0, kappa: -1.5 / 9.0, magnification: 4.0, profile: Profile::Linear };
        // Centre: along the axis.
        let r0 = lens.bend(axis(), persp(0.0), 0.0, 0.2, 0.1);
        assert!((r0.dir - Vec3::NEG_Z).length() < 1e-6);
        // Focus pixel at offset 0.1 on the plane (z = −1): direction (κ·(−0.1), 0, −1)
        // normalised, i.e. x-slope 0.1·1.5/9.
        let r1 = lens.bend(axis(), persp(0.1), 0.1, 0.2, 0.1);
        assert!((r1.dir.x / -r1.dir.z - 0.1 * 1.5 / 9.0).abs() < 1e-6);
        assert!((r1.origin - Vec3::new(0.1, 0.0, -1.0)).length() < 1e-6);
        // At the focus depth (10 from the eye) it is 1/4 as far from the axis as the
        // normal ray (0.1·10 = 1): 0.25.
        assert!((offset_at_depth(r1, 10.0) - 0.25).abs() < 1e-5);
        // Border midpoint (r = 0.25, linear): footprint ρ(0.25)·10 with
        // ρ = 0.05 + (0.3 − 0.05)·0.5 = 0.175.
        let r2 = lens.bend(axis(), persp(0.25), 0.25, 0.2, 0.1);
        assert!((offset_at_depth(r2, 10.0) - 1.75).abs() < 1e-4, "{}", offset_at_depth(r2, 10.0));
        // Outside: the normal ray.
        let r3 = lens.bend(axis(), persp(0.4), 0.4, 0.2, 0.1);
        assert!((r3.dir - persp(0.4).dir).length() < 1e-6);
    }

    #[test]
    fn default_planes_keep_the_magnification_nearly_constant() {
        for perspective in [true, false] {
            let focus = 400.0;
            let lens = Magnifier::resolve(2.0, Profile::Cubic, perspective, focus, None, 100.0);
            let at = |d: f32| magnification_at(lens.kappa, perspective, lens.plane, d - lens.plane);
            assert!((at(focus) - 2.0).abs() < 1e-4);
            for d in [focus - 100.0, focus + 100.0] {
                assert!((at(d) / 2.0 - 1.0).abs() < 0.06, "{perspective}: m({d}) = {}", at(d));
            }
        }
    }
}
