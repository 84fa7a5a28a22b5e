//! Lens shapes on the image plane and their radial coordinate.
//!
//! Lens coordinates: a point of the image is `s = (x·aspect, y)` with `x, y` its
//! normalised device coordinates (y up), so one unit is half the image height and
//! circles stay round on any aspect ratio. A lens is centred at `c`; its shape gives
//! every point a *radial coordinate* `r(s)` that equals the lens radius `lr` on the
//! rim of the focus region:
//!
//! - circle: `r = ‖s − c‖`;
//! - square (half side `lr`): `r = max(|sx − cx|, |sy − cy|)` (Chebyshev distance), so
//!   the rings of the border are squares (LaMar et al.'s square lens);
//! - drawn polygon (vertices relative to `c`): `r = lr + d(s)` with `d` the signed
//!   distance to the polygon (negative inside) and `lr = √(area/π)`, the radius of the
//!   circle of the same area: the focus region is the polygon and the border is the band
//!   of width `lb` around it, defined by the distance field as in the paper (§3.1).

use glam::Vec2;
use serde::{Deserialize, Serialize};

/// Most vertices of a drawn lens shape (the GPU keeps them in the view uniform).
pub const MAX_POLYGON_VERTICES: usize = 32;

/// The shape of a lens's focus region.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    Circle,
    Square,
    /// A user-drawn closed outline, vertices relative to the lens centre in lens units.
    Polygon(Vec<Vec2>),
    /// The silhouette of a segmented feature in the view (the feature lens, see
    /// [`super::feature`]); resolved per view, a circle where no view is at hand.
    Feature(super::feature::FeatureRef),
}

impl Shape {
    /// Radial coordinate of offset `v = s − c` (a drawn outline uses its equivalent
    /// radius).
    pub fn radial(&self, v: Vec2) -> f32 {
        match self {
            Shape::Circle | Shape::Feature(_) => v.length(),
            Shape::Square => v.x.abs().max(v.y.abs()),
            Shape::Polygon(points) => polygon_radius(points) + signed_distance(points, v),
        }
    }

    /// The radius of the focus region (for a polygon, its equivalent radius).
    pub fn focus_radius(&self, radius: f32) -> f32 {
        match self {
            Shape::Polygon(points) => polygon_radius(points),
            _ => radius,
        }
    }

    /// Checks a shape (enough vertices, not too many, a non-zero area).
    pub fn validate(&self) -> Result<(), String> {
        if let Shape::Polygon(points) = self {
            if points.len() < 3 || points.len() > MAX_POLYGON_VERTICES {
                return Err(format!("a drawn lens needs 3 to {MAX_POLYGON_VERTICES} vertices, not {}", points.len()));
            }
            if points.iter().any(|p| !p.is_finite()) {
                return Err("a drawn lens has a vertex that is not a number".into());
            }
            if polygon_area(points).abs() < 1e-6 {
                return Err("a drawn lens encloses no area".into());
            }
        }
        Ok(())
    }
}

/// Area of a closed polygon (positive when counter-clockwise).
pub fn polygon_area(points: &[Vec2]) -> f32 {
    let n = points.len();
    (0..n).map(|i| points[i].perp_dot(points[(i + 1) % n])).sum::<f32>() * 0.5
}

/// Radius of the circle with the polygon's area.
pub fn polygon_radius(points: &[Vec2]) -> f32 {
    (polygon_area(points).abs() / std::f32::consts::PI).sqrt()
}

/// Signed distance from `p` to a closed polygon: negative inside (even-odd rule).
pub fn signed_distance(points: &[Vec2], p: Vec2) -> f32 {
    let n = points.len();
    let mut d2 = f32::INFINITY;
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (points[i], points[(i + 1) % n]);
        let e = b - a;
        let t = ((p - a).dot(e) / e.length_squared().max(1e-12)).clamp(0.0, 1.0);
        d2 = d2.min((p - a - e * t).length_squared());
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
    }
    if inside { -d2.sqrt() } else { d2.sqrt() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radial_coordinates_of_the_shapes() {
        assert!((Shape::Circle.radial(Vec2::new(3.0, 4.0)) - 5.0).abs() < 1e-6);
        assert!((Shape::Square.radial(Vec2::new(-3.0, 2.0)) - 3.0).abs() < 1e-6);
        // A 2×2 square drawn as a polygon: area 4, equivalent radius 2/√π.
        let sq = Shape::Polygon(vec![Vec2::new(-1.0, -1.0), Vec2::new(1.0, -1.0), Vec2::new(1.0, 1.0), Vec2::new(-1.0, 1.0)]);
        let req = 2.0 / std::f32::consts::PI.sqrt();
        assert!((sq.focus_radius(9.0) - req).abs() < 1e-6);
        // Centre: 1 inside the outline; (3, 0): 2 outside; (2, 2): √2 outside the corner.
        assert!((sq.radial(Vec2::ZERO) - (req - 1.0)).abs() < 1e-6);
        assert!((sq.radial(Vec2::new(3.0, 0.0)) - (req + 2.0)).abs() < 1e-6);
        assert!((sq.radial(Vec2::new(2.0, 2.0)) - (req + 2f32.sqrt())).abs() < 1e-6);
    }

    #[test]
    fn polygons_are_validated() {
        assert!(Shape::Polygon(vec![Vec2::ZERO, Vec2::X]).validate().is_err());
        assert!(Shape::Polygon(vec![Vec2::ZERO, Vec2::X, Vec2::X * 2.0]).validate().is_err());
        assert!(Shape::Polygon(vec![Vec2::ZERO, Vec2::X, Vec2::Y]).validate().is_ok());
    }
}
