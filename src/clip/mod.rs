//! Clipping: planes and a box that cut a dataset, the baseline the papers compare
//! against and what every viewer offers.
//!
//! A dataset's [`Clipping`] is given in the dataset's own frame (millimetres of the
//! volume's world placement before the entity's transform), so it moves with the
//! dataset. Each enabled plane keeps the half-space `n · p ≤ n · point` (the side its
//! normal points away from; `flip` swaps the sides); the box keeps what lies inside it.
//! The region model cuts the dataset's region by these as extra planes
//! ([`Clipping::world_planes`], [`Clipping::region`]), so the CPU reference and the ray caster clip alike with
//! no code of their own.

pub mod gizmo;

use glam::{Affine3A, Vec3};
use serde::{Deserialize, Serialize};

use crate::region::{Plane, Region};
use crate::volume::Grid;

/// One clip plane.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClipPlane {
    /// A point on the plane (dataset frame, mm).
    pub point: Vec3,
    /// The normal; the kept side is the one it points away from.
    pub normal: Vec3,
    /// Keep the other side.
    #[serde(default)]
    pub flip: bool,
    #[serde(default = "yes")]
    pub enabled: bool,
}

fn yes() -> bool {
    true
}

impl ClipPlane {
    /// A plane through `point` keeping the side away from `normal`.
    pub fn new(point: Vec3, normal: Vec3) -> Self {
        Self { point, normal, flip: false, enabled: true }
    }

    /// The kept half-space in the dataset frame.
    pub fn plane(&self) -> Plane {
        let n = if self.flip { -self.normal } else { self.normal };
        Plane::through(self.point, n.normalize_or(Vec3::Z))
    }
}

/// An axis-aligned clip box in the dataset frame: what lies inside is kept.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClipBox {
    pub min: Vec3,
    pub max: Vec3,
    #[serde(default = "yes")]
    pub enabled: bool,
}

impl ClipBox {
    /// Its six faces as kept half-spaces.
    pub fn planes(&self) -> [Plane; 6] {
        let (lo, hi) = (self.min.min(self.max), self.min.max(self.max));
        [
            Plane::through(hi, Vec3::X),
            Plane::through(hi, Vec3::Y),
            Plane::through(hi, Vec3::Z),
            Plane::through(lo, -Vec3::X),
            Plane::through(lo, -Vec3::Y),
            Plane::through(lo, -Vec3::Z),
        ]
    }
}

/// The clipping of one dataset.
#[derive(bevy::prelude::Component, Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Clipping {
    pub planes: Vec<ClipPlane>,
    #[serde(rename = "box")]
    pub clip_box: Option<ClipBox>,
}

impl Clipping {
    /// Checks for what cannot cut anything sensibly: non-finite values, a zero normal,
    /// an empty box.
    pub fn validated(self) -> Result<Self, String> {
        for (i, p) in self.planes.iter().enumerate() {
            if !p.point.is_finite() || !p.normal.is_finite() || p.normal.length_squared() < 1e-12 {
                return Err(format!("clip plane {i}: point {} and normal {} do not define a plane", p.point, p.normal));
            }
        }
        if let Some(b) = &self.clip_box
            && (!b.min.is_finite() || !b.max.is_finite() || b.min.cmpge(b.max).any())
        {
            return Err(format!("clip box from {} to {} is empty or not finite", b.min, b.max));
        }
        Ok(self)
    }

    /// Whether anything cuts.
    pub fn is_active(&self) -> bool {
        self.planes.iter().any(|p| p.enabled) || self.clip_box.is_some_and(|b| b.enabled)
    }

    /// The kept half-spaces in world space, for a dataset placed by `transform`.
    pub fn world_planes(&self, transform: &Affine3A) -> Vec<Plane> {
        let local = self.planes.iter().filter(|p| p.enabled).map(ClipPlane::plane);
        let boxed = self.clip_box.filter(|b| b.enabled).map(|b| b.planes()).into_iter().flatten();
        local.chain(boxed).map(|p| transform_plane(&p, transform)).collect()
    }

    /// A dataset's region: the box of its volume on `grid` placed by `transform`, cut by
    /// this clipping (one region per dataset; the volume and appearance share `index`).
    pub fn region(&self, grid: &Grid, transform: Affine3A, index: usize) -> Region {
        let mut region = Region::volume_box_at(grid, transform, index, index);
        region.planes.extend(self.world_planes(&transform));
        region
    }
}

/// A plane moved by an affine map: the point moves, the normal by the inverse transpose.
pub fn transform_plane(p: &Plane, m: &Affine3A) -> Plane {
    let point = m.transform_point3(p.normal * p.offset);
    let normal = m.matrix3.inverse().transpose() * p.normal;
    Plane::through(point, normal.normalize_or(Vec3::Z))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    #[test]
    fn a_plane_keeps_the_side_away_from_its_normal() {
        let p = ClipPlane::new(Vec3::new(0.0, 0.0, 5.0), Vec3::Z).plane();
        assert!(p.distance(Vec3::new(3.0, -2.0, 4.0)) < 0.0);
        assert!(p.distance(Vec3::new(3.0, -2.0, 6.0)) > 0.0);
        let flipped = ClipPlane { flip: true, ..ClipPlane::new(Vec3::new(0.0, 0.0, 5.0), Vec3::Z) }.plane();
        assert!(flipped.distance(Vec3::new(3.0, -2.0, 6.0)) < 0.0);
    }

    #[test]
    fn the_box_keeps_its_inside() {
        let b = ClipBox { min: Vec3::new(-1.0, -2.0, -3.0), max: Vec3::new(1.0, 2.0, 3.0), enabled: true };
        let inside = |p: Vec3| b.planes().iter().all(|pl| pl.distance(p) <= 0.0);
        assert!(inside(Vec3::new(0.9, -1.9, 2.9)));
        assert!(!inside(Vec3::new(1.1, 0.0, 0.0)));
        assert!(!inside(Vec3::new(0.0, 0.0, -3.1)));
    }

    #[test]
    fn planes_follow_the_dataset() {
        // Rotated 90° about z, scaled by 2 in x before, moved by (10, 0, 0): the plane
        // x = 1 (keep x ≤ 1) of the dataset frame becomes y = 2 … checked on points.
        let m = Affine3A::from_scale_rotation_translation(
            Vec3::new(2.0, 1.0, 1.0),
            Quat::from_rotation_z(std::f32::consts::FRAC_PI_2),
            Vec3::new(10.0, 0.0, 0.0),
        );
        let local = ClipPlane::new(Vec3::X, Vec3::X).plane();
        let world = transform_plane(&local, &m);
        for p in [Vec3::new(0.5, 3.0, 1.0), Vec3::new(1.5, -2.0, 0.0), Vec3::new(-4.0, 0.0, 7.0)] {
            let (a, b) = (local.distance(p), world.distance(m.transform_point3(p)));
            assert_eq!(a < 0.0, b < 0.0, "{p}: {a} vs {b}");
        }
        // By hand: local x = 1 maps to world y = 2 (scale 2, then x → y), kept y ≤ 2.
        assert!((world.normal - Vec3::Y).length() < 1e-6 && (world.offset - 2.0).abs() < 1e-5, "{world:?}");
    }

    #[test]
    fn disabled_parts_do_not_cut_and_bad_input_is_refused() {
        let c = Clipping {
            planes: vec![ClipPlane { enabled: false, ..ClipPlane::new(Vec3::ZERO, Vec3::X) }],
            clip_box: Some(ClipBox { min: Vec3::ZERO, max: Vec3::ONE, enabled: false }),
        };
        assert!(!c.is_active());
        assert!(c.world_planes(&Affine3A::IDENTITY).is_empty());
        assert!(Clipping { planes: vec![ClipPlane::new(Vec3::ZERO, Vec3::ZERO)], clip_box: None }.validated().is_err());
        assert!(
            Clipping { planes: vec![], clip_box: Some(ClipBox { min: Vec3::ONE, max: Vec3::ZERO, enabled: true }) }.validated().is_err()
        );
        assert!(Clipping { planes: vec![ClipPlane::new(Vec3::NAN, Vec3::X)], clip_box: None }.validated().is_err());
    }
}
