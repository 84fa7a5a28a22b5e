//! Anti-aliasing under lenses (Wang et al. 2005, §3.1, equation 4): where a lens
//! compresses the image (local magnification `mf < 1`), neighbouring rays lie further
//! apart than the data's detail, and samples alias. They are taken from the volume's
//! mip chain ([`crate::volume::pyramid`]) at level
//!
//! `L = max(0, log₂(1/mf))`,
//!
//! blending the two nearest levels; where the lens magnifies, `L = 0`.
//!
//! `mf` is measured per sample with ray differentials. Each ray is written by its view
//! depth `z` (distance along the camera's forward axis): `x(z) = p + q·z` with
//! `q = d/(d·f)` and `p = o − q·z(o)` — the same line gives the same `p, q` wherever its
//! origin lies (a bent ray starts on the lens plane, a straight one at the eye). The rays
//! of a pixel and of its right and lower neighbours are `Δ_x = Δp_x + Δq_x·z` and
//! `Δ_y = Δp_y + Δq_y·z` apart at depth `z`. A lens border compresses
//! in one direction (radially) while it stretches in the other, so `mf` is the
//! magnification in the most compressed direction: the pixel footprint's longest
//! extent, the largest singular value `σ` of `[Δ_x Δ_y]`,
//! `σ² = (a + c)/2 + √(((a − c)/2)² + b²)` with `a = Δ_x·Δ_x`, `b = Δ_x·Δ_y`,
//! `c = Δ_y·Δ_y`, compared with the camera's own rays at the same view depth:
//! `mf = σ_plain/σ_lensed`. (The geometric mean of the two directions, as in
//! [`super::local_magnification`], would leave the radial moiré in place.) The shader
//! computes the same differentials once per pixel and the level at every sample.
//!
//! The lensed extent is convex in `z` (the largest singular value of a matrix affine in
//! `z`) and the plain one affine in `z` (rays from one eye, or parallel), so their ratio
//! is quasi-convex: over a ray's interval its maximum lies at an end. Where the level is
//! 0 at both ends of the interval it is 0 throughout, and the shader skips the
//! per-sample work for that pixel (an exact shortcut; [`Footprint::level_free`]).
//!
//! Where the lens map jumps (the rim of a simple-profile magnifier, of an angular lens)
//! the difference across the jump is no footprint: it would blur a seam along the rim.
//! So each axis takes the one-sided difference, forward (right, lower neighbour) or
//! backward (left, upper), that is smaller over the ray's interval `[t0, t1]`
//! ([`Footprint::over`]; `|Δ(z)|` is convex in `z`, so its maximum is at an end). The
//! chosen spread is again affine in `z`, so the shortcut above stays exact.

use glam::Vec3;

use super::screen::Screen;
use super::stack::{ResolvedLens, lens_ray};
use crate::region::{Camera, Ray};

/// Differentials of a pixel's rays and the map from ray parameter to view depth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spread {
    /// `Δp_x, Δq_x, Δp_y, Δq_y` (see the module docs).
    pub deltas: [Vec3; 4],
    /// View depth of the ray origin and its change per unit `t`.
    pub depth0: f32,
    pub depth_per_t: f32,
}

/// Largest singular value of the 3×2 matrix `[x y]`.
pub fn largest_singular_value(x: Vec3, y: Vec3) -> f32 {
    let (a, b, c) = (x.dot(x), x.dot(y), y.dot(y));
    ((a + c) * 0.5 + (((a - c) * 0.5).powi(2) + b * b).sqrt()).max(0.0).sqrt()
}

impl Spread {
    /// The spread of the rays `r` (the pixel), `rx` and `ry` (its neighbours).
    pub fn of(camera: &Camera, r: Ray, rx: Ray, ry: Ray) -> Spread {
        let fwd = camera.forward();
        // The line of a ray by view depth: x(z) = p + q·z.
        let line = |ray: Ray| {
            let q = ray.dir / ray.dir.dot(fwd).max(1e-6);
            (ray.origin - q * (ray.origin - camera.position).dot(fwd), q)
        };
        let ((p, q), (px, qx), (py, qy)) = (line(r), line(rx), line(ry));
        let d = r.dir.normalize_or_zero();
        Spread { deltas: [px - p, qx - q, py - p, qy - q], depth0: (r.origin - camera.position).dot(fwd), depth_per_t: d.dot(fwd) }
    }

    /// Longest extent of the pixel footprint at view depth `z`.
    pub fn extent(&self, z: f32) -> f32 {
        let [px, qx, py, qy] = self.deltas;
        largest_singular_value(px + qx * z, py + qy * z)
    }

    /// Ray parameter at view depth `z`.
    pub fn t_at_depth(&self, z: f32) -> f32 {
        (z - self.depth0) / self.depth_per_t.max(1e-6)
    }
}

/// A pixel's lensed and plain ray spreads.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    pub lensed: Spread,
    pub plain: Spread,
    /// The lensed backward differences `Δp_x, Δq_x, Δp_y, Δq_y` (pixel minus its left
    /// and upper neighbours).
    pub backward: [Vec3; 4],
}

impl Footprint {
    /// The footprint of pixel position `(px, py)`; `None` where the pixel or a neighbour
    /// has no ray (outside a whole-view fisheye).
    pub fn new(camera: &Camera, screen: Screen, lenses: &[ResolvedLens], px: f32, py: f32) -> Option<Footprint> {
        let lensed = |x: f32, y: f32| lens_ray(camera, screen, lenses, x, y);
        let plain = |x: f32, y: f32| camera.ray(x, y, screen.width as u32, screen.height as u32);
        let r = lensed(px, py)?;
        let forward = Spread::of(camera, r, lensed(px + 1.0, py)?, lensed(px, py + 1.0)?);
        // Without a left or upper neighbour's ray, the forward differences.
        let backward = match (lensed(px - 1.0, py), lensed(px, py - 1.0)) {
            (Some(bx), Some(by)) => Spread::of(camera, r, bx, by).deltas.map(|d| -d),
            _ => forward.deltas,
        };
        Some(Footprint { lensed: forward, plain: Spread::of(camera, plain(px, py), plain(px + 1.0, py), plain(px, py + 1.0)), backward })
    }

    /// The footprint for the interval `[t0, t1]` of the lensed ray: per axis the
    /// one-sided difference that is smaller over it (see the module docs).
    pub fn over(&self, t0: f32, t1: f32) -> Footprint {
        let s = &self.lensed;
        let (z0, z1) = (s.depth0 + s.depth_per_t * t0, s.depth0 + s.depth_per_t * t1);
        let reach = |p: Vec3, q: Vec3| (p + q * z0).length().max((p + q * z1).length());
        let mut deltas = s.deltas;
        for axis in [0, 2] {
            let (f, b) = ((s.deltas[axis], s.deltas[axis + 1]), (self.backward[axis], self.backward[axis + 1]));
            if reach(b.0, b.1) < reach(f.0, f.1) {
                deltas[axis] = b.0;
                deltas[axis + 1] = b.1;
            }
        }
        Footprint { lensed: Spread { deltas, ..*s }, ..*self }
    }

    /// Magnification `mf` in the most compressed direction at parameter `t` of the
    /// lensed ray.
    pub fn magnification(&self, t: f32) -> f32 {
        let depth = self.lensed.depth0 + self.lensed.depth_per_t * t;
        let plain = self.plain.extent(depth);
        let lensed = self.lensed.extent(depth);
        if lensed <= 0.0 { f32::INFINITY } else { plain / lensed }
    }

    /// Whether the level is 0 all over `[t0, t1]` (both ends suffice, see the module docs).
    pub fn level_free(&self, t0: f32, t1: f32) -> bool {
        self.level(t0, 1.0) == 0.0 && self.level(t1, 1.0) == 0.0
    }

    /// Mip level at parameter `t` (eq. 4), at most `max_level`.
    pub fn level(&self, t: f32, max_level: f32) -> f32 {
        level_for(self.magnification(t), max_level)
    }
}

/// Levels below this are level 0 ([`level_for`]): rounding leaves a lens that compresses
/// nothing (a ×1 magnifier, the flat middle of a border) with `mf` a hair under 1, and
/// a level of 10⁻⁴ blends in the mip chain invisibly but made every sample a mip sample
/// and switched empty-space skipping off: 41 % more samples in the bench's ×1 lens with
/// anti-aliasing. A 1/256 level moves a sample by under 0.4 % of the levels' difference.
pub const LEVEL_DEAD_ZONE: f32 = 1.0 / 256.0;

/// Equation 4: `L = max(0, log₂(1/mf))`, at most `max_level`; 0 below
/// [`LEVEL_DEAD_ZONE`].
pub fn level_for(mf: f32, max_level: f32) -> f32 {
    if mf.is_nan() || mf <= 0.0 {
        return max_level;
    }
    let l = -mf.log2();
    if l < LEVEL_DEAD_ZONE { 0.0 } else { l.min(max_level) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lens::stack::resolve;
    use crate::lens::{Lens, LensKind, Sampling, local_magnification};
    use crate::region::Projection;
    use glam::Vec2;

    #[test]
    fn equation_4_by_hand() {
        assert_eq!(level_for(1.0, 3.0), 0.0);
        assert_eq!(level_for(3.0, 3.0), 0.0);
        assert!((level_for(0.25, 3.0) - 2.0).abs() < 1e-6);
        assert!((level_for(0.5f32.powf(1.5), 3.0) - 1.5).abs() < 1e-5);
        assert_eq!(level_for(0.01, 3.0), 3.0);
        // Within the dead zone: log₂(1/0.999) = 0.0014 of a level is none; 0.99 is 0.0145.
        assert_eq!(level_for(0.999, 3.0), 0.0);
        assert!((level_for(0.99, 3.0) - 0.0145).abs() < 1e-4);
    }

    #[test]
    fn without_lenses_nothing_is_compressed() {
        for projection in [Projection::Perspective { fov_y: 0.7 }, Projection::Orthographic { height: 200.0 }] {
            let cam = Camera::look_at(Vec3::new(30.0, 400.0, 50.0), Vec3::ZERO, Vec3::Z, projection);
            let f = Footprint::new(&cam, Screen::new(160, 120), &[], 20.0, 90.0).unwrap();
            for t in [10.0, 300.0, 900.0] {
                assert!((f.magnification(t) - 1.0).abs() < 1e-3, "{projection:?} {t}: {}", f.magnification(t));
            }
        }
    }

    #[test]
    fn singular_values_by_hand() {
        assert!((largest_singular_value(Vec3::new(3.0, 0.0, 0.0), Vec3::Y) - 3.0).abs() < 1e-6);
        assert!((largest_singular_value(Vec3::new(1.0, 1.0, 0.0), Vec3::new(1.0, -1.0, 0.0)) - 2f32.sqrt()).abs() < 1e-6);
        // A sheared square [1 1; 0 1]: σ = golden ratio.
        assert!((largest_singular_value(Vec3::X, Vec3::new(1.0, 1.0, 0.0)) - 1.618_034).abs() < 1e-5);
    }

    #[test]
    fn ray_differentials_agree_with_the_area_ratio_where_lenses_are_isotropic() {
        // Two independent measures of mf: ray differentials along the ray, and the
        // corner-square areas on the focus plane (`local_magnification`). They agree at
        // lens centres (isotropic); in borders the most compressed direction is at
        // most the geometric mean.
        let screen = Screen::new(200, 200);
        for projection in [Projection::Perspective { fov_y: 0.6 }, Projection::Orthographic { height: 200.0 }] {
            let cam = Camera::look_at(Vec3::new(0.0, 0.0, 500.0), Vec3::ZERO, Vec3::Y, projection);
            let lenses = [
                Lens::magnifier(Vec2::ZERO, 0.3, 0.3, 3.0),
                Lens { kind: LensKind::Sampling(Sampling::Custom(vec![2.0, 2.0, 0.4, 1.0])), ..Lens::magnifier(Vec2::ZERO, 0.5, 0.0, 1.0) },
            ];
            for lens in lenses {
                let resolved = [resolve(&lens, &cam, screen, (Vec3::ZERO, 100.0))];
                for (px, py, centre) in [(100.0, 100.0, true), (130.0, 100.0, false), (150.0, 110.0, false), (170.0, 100.0, false)] {
                    let f = Footprint::new(&cam, screen, &resolved, px, py).unwrap();
                    let mf = f.magnification(f.lensed.t_at_depth(500.0));
                    let mean = local_magnification(&cam, screen, &resolved, px + 0.5, py + 0.5, 500.0).unwrap();
                    let name = lens.kind_name();
                    if centre {
                        assert!((mf / mean - 1.0).abs() < 0.05, "{projection:?} {name} centre: {mf} vs {mean}");
                    } else {
                        assert!(mf <= mean * 1.02, "{projection:?} {name} at ({px}, {py}): {mf} > {mean}");
                    }
                }
            }
        }
        // The border of the magnifier compresses radially: there mf < 1 and L > 0.
        let cam = Camera::look_at(Vec3::new(0.0, 0.0, 500.0), Vec3::ZERO, Vec3::Y, Projection::Orthographic { height: 200.0 });
        let resolved = [resolve(&Lens::magnifier(Vec2::ZERO, 0.4, 0.3, 3.0), &cam, screen, (Vec3::ZERO, 100.0))];
        let f = Footprint::new(&cam, screen, &resolved, 155.0, 100.0).unwrap();
        let t = f.lensed.t_at_depth(500.0);
        assert!(f.magnification(t) < 0.6 && f.level(t, 3.0) > 0.7, "{} {}", f.magnification(t), f.level(t, 3.0));
    }

    #[test]
    fn compression_peaks_at_the_ends_of_an_interval() {
        // Quasi-convexity of 1/mf along a ray: mf(t) ≥ min(mf(t0), mf(t1)) in between,
        // for every lens kind, both projections, pixels all over the image.
        let screen = Screen::new(120, 120);
        for projection in [Projection::Perspective { fov_y: 0.8 }, Projection::Orthographic { height: 200.0 }] {
            let cam = Camera::look_at(Vec3::new(40.0, -300.0, 120.0), Vec3::ZERO, Vec3::Z, projection);
            let lenses = [
                Lens::magnifier(Vec2::new(0.1, 0.0), 0.3, 0.4, 4.0),
                Lens {
                    kind: crate::lens::LensKind::Magnifier {
                        magnification: 3.0,
                        profile: crate::lens::Profile::Linear,
                        focus_depth: None,
                        plane_depth: Some(150.0),
                    },
                    ..Lens::magnifier(Vec2::new(-0.2, 0.1), 0.25, 0.3, 3.0)
                },
                Lens { kind: LensKind::Sampling(Sampling::Custom(vec![3.0, 0.3, 1.0])), ..Lens::magnifier(Vec2::ZERO, 0.6, 0.0, 1.0) },
                Lens { kind: LensKind::Angular { field_of_view: 200.0, whole_view: false }, ..Lens::magnifier(Vec2::ZERO, 0.5, 0.0, 1.0) },
            ];
            for lens in lenses {
                let resolved = [resolve(&lens, &cam, screen, (Vec3::ZERO, 100.0))];
                for py in (3..120).step_by(9) {
                    for px in (3..120).step_by(9) {
                        let (t0, t1) = (200.0, 500.0);
                        // The sides chosen for the interval, as the renderers do.
                        let Some(f) = Footprint::new(&cam, screen, &resolved, px as f32, py as f32).map(|f| f.over(t0, t1)) else {
                            continue;
                        };
                        let ends = f.magnification(t0).min(f.magnification(t1));
                        for k in 1..30 {
                            let t = t0 + (t1 - t0) * k as f32 / 30.0;
                            let mf = f.magnification(t);
                            assert!(mf >= ends * (1.0 - 1e-3), "{} ({px}, {py}) t = {t}: {mf} < {ends}", lens.kind_name());
                            if f.level_free(t0, t1) {
                                assert!(f.level(t, 3.0) < 1e-3, "{}", f.level(t, 3.0));
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn rays_starting_elsewhere_on_the_same_line_do_not_count_as_spread() {
        // At the outer edge of a magnifier's border the bent rays start on the lens
        // plane, their straight neighbours at the eye: same lines, no compression.
        let screen = Screen::new(200, 200);
        for projection in [Projection::Perspective { fov_y: 0.6 }, Projection::Orthographic { height: 200.0 }] {
            let cam = Camera::look_at(Vec3::new(0.0, 0.0, 500.0), Vec3::ZERO, Vec3::Y, projection);
            let resolved = [resolve(&Lens::magnifier(Vec2::ZERO, 0.4, 0.3, 3.0), &cam, screen, (Vec3::ZERO, 100.0))];
            // The outer edge at 70 pixels from the centre: pixel 169.5 bends, 170.5 does not.
            let f = Footprint::new(&cam, screen, &resolved, 169.5, 100.0).unwrap();
            let t = f.lensed.t_at_depth(500.0);
            assert!(f.level(t, 3.0) < 0.1, "{projection:?}: level {}", f.level(t, 3.0));
        }
    }

    #[test]
    fn a_jump_of_the_lens_map_is_no_footprint() {
        // A simple-profile magnifier jumps from ×2 to ×1 at its rim, 40 pixels from the
        // centre: pixel 139.5 is inside, its right neighbour outside. The forward
        // difference spans the jump; the backward one (inside) is the footprint.
        let screen = Screen::new(200, 200);
        let lens = Lens {
            kind: LensKind::Magnifier { magnification: 2.0, profile: crate::lens::Profile::Simple, focus_depth: None, plane_depth: None },
            ..Lens::magnifier(Vec2::ZERO, 0.4, 0.2, 2.0)
        };
        for projection in [Projection::Perspective { fov_y: 0.6 }, Projection::Orthographic { height: 200.0 }] {
            let cam = Camera::look_at(Vec3::new(0.0, 0.0, 500.0), Vec3::ZERO, Vec3::Y, projection);
            let resolved = [resolve(&lens, &cam, screen, (Vec3::ZERO, 100.0))];
            for (px, py) in [(139.5, 100.0), (100.0, 139.5), (60.5, 100.0)] {
                let f = Footprint::new(&cam, screen, &resolved, px, py).unwrap();
                let (t0, t1) = (f.lensed.t_at_depth(400.0), f.lensed.t_at_depth(600.0));
                let t = f.lensed.t_at_depth(500.0);
                let chosen = f.over(t0, t1);
                assert!(chosen.level(t, 3.0) < 1e-3, "{projection:?} ({px}, {py}): level {}", chosen.level(t, 3.0));
                assert!(chosen.magnification(t) > 1.5, "{projection:?}: inside, mf {}", chosen.magnification(t));
                if px > 100.0 {
                    // Forward differences alone blur the rim.
                    assert!(f.level(t, 3.0) > 1.0, "{projection:?} ({px}, {py}): forward level {}", f.level(t, 3.0));
                }
            }
            // Where the map is smooth both sides agree.
            let f = Footprint::new(&cam, screen, &resolved, 100.0, 100.0).unwrap();
            let t = f.lensed.t_at_depth(500.0);
            assert!((f.over(f.lensed.t_at_depth(400.0), f.lensed.t_at_depth(600.0)).magnification(t) - f.magnification(t)).abs() < 0.05);
        }
    }
}
