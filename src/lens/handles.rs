//! Placing and tuning lenses by hand: which part of a lens a point of the image grabs,
//! what a drag or a wheel turn does to it, the outlines the viewport draws, and drawn
//! outlines turned into lens shapes. Pure functions in lens units (see
//! [`super::shape`]); the app's viewport systems call them.
//!
//! A lens has three handles: its focus region (drag: move the lens), its rim (radial
//! coordinate `r = lr`; drag: radius) and the outer edge of its border (`r = lr + lb`;
//! drag: border width). The rims grab within a tolerance; the rim wins over the
//! border edge when both are close (a narrow border). A drawn shape scales about its
//! centre when its rim is dragged.

use glam::Vec2;

use super::sampling::Sampling;
use super::shape::{MAX_POLYGON_VERTICES, Shape, polygon_area};
use super::spec::{Lens, LensKind};

/// The part of a lens under the pointer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Handle {
    /// Inside the focus region: moves the lens.
    Centre,
    /// The rim of the focus region: its radius.
    Rim,
    /// The outer edge of the border: the border width.
    Border,
}

/// Radial coordinate of `s` for `lens` (its focus radius for a drawn shape).
fn radial(lens: &Lens, s: Vec2) -> f32 {
    lens.shape.radial(s - lens.center)
}

/// The handle of `lens` at `s`, if any (`tolerance` in lens units). A whole-view
/// fisheye and a feature lens (it follows its feature) have no handles.
pub fn hit(lens: &Lens, s: Vec2, tolerance: f32) -> Option<Handle> {
    if matches!(lens.kind, LensKind::Angular { whole_view: true, .. }) || matches!(lens.shape, Shape::Feature(_)) {
        return None;
    }
    let r = radial(lens, s);
    let lr = lens.shape.focus_radius(lens.radius);
    let outer = lr + lens.border;
    let has_border = lens.border > 0.0 && !matches!(lens.kind, LensKind::Sampling(_) | LensKind::Angular { .. });
    if (r - lr).abs() <= tolerance {
        Some(Handle::Rim)
    } else if has_border && (r - outer).abs() <= tolerance {
        Some(Handle::Border)
    } else if r < lr {
        Some(Handle::Centre)
    } else {
        None
    }
}

/// Applies a drag of a handle from `from` to `to` (lens units).
pub fn drag(lens: &mut Lens, handle: Handle, from: Vec2, to: Vec2) {
    match handle {
        Handle::Centre => lens.center += to - from,
        Handle::Rim => match &mut lens.shape {
            Shape::Polygon(points) => {
                // The signed distance of a drawn shape scales with it: find the scale
                // that puts `to` on the rim by bisection.
                let target = to - lens.center;
                let original = points.clone();
                let outside = |k: f32| {
                    let scaled: Vec<Vec2> = original.iter().map(|p| *p * k).collect();
                    super::shape::signed_distance(&scaled, target) > 0.0
                };
                let (mut lo, mut hi) = (0.05f32, 20.0f32);
                if outside(lo) && !outside(hi) {
                    for _ in 0..40 {
                        let mid = (lo * hi).sqrt();
                        if outside(mid) { lo = mid } else { hi = mid }
                    }
                    let k = (lo * hi).sqrt();
                    points.iter_mut().for_each(|p| *p *= k);
                }
                lens.radius = lens.shape.focus_radius(lens.radius);
            }
            _ => lens.radius = lens.shape.radial(to - lens.center).max(0.02),
        },
        Handle::Border => {
            let lr = lens.shape.focus_radius(lens.radius);
            lens.border = (radial(lens, to) - lr).max(0.0);
        }
    }
}

/// Applies `lines` turns of the wheel over a lens: its main strength (magnification,
/// sampling rate at the centre, or field of view), kept in the valid range.
pub fn wheel(lens: &mut Lens, lines: f32) {
    let factor = 1.1f32.powf(lines);
    match &mut lens.kind {
        LensKind::Magnifier { magnification, .. } => *magnification = (*magnification * factor).clamp(1.0, 64.0),
        LensKind::Sampling(Sampling::Cubic { center_rate }) => *center_rate = (*center_rate * factor).clamp(1.0, 4.9),
        LensKind::Sampling(Sampling::Custom(samples)) => {
            if let Some(first) = samples.first_mut() {
                *first = (*first * factor).clamp(0.05, 20.0);
            }
        }
        LensKind::Angular { field_of_view, .. } => *field_of_view = (*field_of_view + 10.0 * lines).clamp(10.0, 360.0),
    }
}

/// Points of the curve `r = radius` of `shape` around the origin (lens units), for
/// drawing: found along `n` directions by bisection (exact for circles, squares and
/// shapes star-shaped about their centre).
pub fn contour(shape: &Shape, radius: f32, n: usize) -> Vec<Vec2> {
    (0..n)
        .map(|i| {
            let a = i as f32 / n as f32 * std::f32::consts::TAU;
            let dir = Vec2::new(a.cos(), a.sin());
            let (mut lo, mut hi) = (0.0f32, radius.max(1e-3) * 2.0 + 4.0);
            for _ in 0..40 {
                let mid = 0.5 * (lo + hi);
                if shape.radial(dir * mid) < radius { lo = mid } else { hi = mid }
            }
            dir * 0.5 * (lo + hi)
        })
        .collect()
}

/// The two outlines of a lens for drawing: the rim of the focus region and the outer
/// edge of the border (lens units, absolute).
pub fn outlines(lens: &Lens) -> (Vec<Vec2>, Vec<Vec2>) {
    let lr = lens.shape.focus_radius(lens.radius);
    let n = if matches!(lens.shape, Shape::Polygon(_)) { 128 } else { 64 };
    let at = |r: f32| contour(&lens.shape, r, n).into_iter().map(|p| p + lens.center).collect();
    (at(lr), at(lr + lens.border))
}

/// A drawn stroke (lens units) as a lens outline: its centroid and at most
/// [`MAX_POLYGON_VERTICES`] vertices relative to it, at equal steps of arc length.
/// `None` when the stroke encloses (almost) no area.
pub fn stroke_to_shape(stroke: &[Vec2]) -> Option<(Vec2, Shape)> {
    if stroke.len() < 3 {
        return None;
    }
    let n = stroke.len();
    let lengths: Vec<f32> = (0..n).map(|i| stroke[i].distance(stroke[(i + 1) % n])).collect();
    let total: f32 = lengths.iter().sum();
    if total <= 1e-6 {
        return None;
    }
    let count = MAX_POLYGON_VERTICES.min(n);
    let mut points = Vec::with_capacity(count);
    let (mut seg, mut walked) = (0usize, 0.0f32);
    for k in 0..count {
        let want = total * k as f32 / count as f32;
        while seg < n - 1 && walked + lengths[seg] < want {
            walked += lengths[seg];
            seg += 1;
        }
        let f = ((want - walked) / lengths[seg].max(1e-12)).clamp(0.0, 1.0);
        points.push(stroke[seg].lerp(stroke[(seg + 1) % n], f));
    }
    let area = polygon_area(&points);
    if area.abs() < 1e-4 {
        return None;
    }
    let centroid = points.iter().copied().sum::<Vec2>() / points.len() as f32;
    let shape = Shape::Polygon(points.into_iter().map(|p| p - centroid).collect());
    shape.validate().ok()?;
    Some((centroid, shape))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn handles_are_found_where_they_are() {
        let lens = Lens::magnifier(Vec2::new(0.5, 0.0), 0.3, 0.2, 2.0);
        assert_eq!(hit(&lens, Vec2::new(0.5, 0.1), 0.02), Some(Handle::Centre));
        assert_eq!(hit(&lens, Vec2::new(0.8, 0.0), 0.02), Some(Handle::Rim));
        assert_eq!(hit(&lens, Vec2::new(0.5, -0.49), 0.02), Some(Handle::Border));
        assert_eq!(hit(&lens, Vec2::new(0.5, 0.4), 0.02), None);
        assert_eq!(hit(&lens, Vec2::new(-0.5, 0.0), 0.02), None);
        // Square lens: the rim is the square's edge.
        let square = Lens { shape: Shape::Square, ..lens.clone() };
        assert_eq!(hit(&square, Vec2::new(0.79, 0.29), 0.02), Some(Handle::Rim));
    }

    #[test]
    fn dragging_moves_resizes_and_widens() {
        let mut lens = Lens::magnifier(Vec2::ZERO, 0.3, 0.2, 2.0);
        drag(&mut lens, Handle::Centre, Vec2::new(0.1, 0.1), Vec2::new(0.2, -0.1));
        assert!((lens.center - Vec2::new(0.1, -0.2)).length() < 1e-6);
        drag(&mut lens, Handle::Rim, Vec2::ZERO, Vec2::new(0.1, 0.2));
        assert!((lens.radius - 0.4).abs() < 1e-6, "{}", lens.radius);
        drag(&mut lens, Handle::Border, Vec2::ZERO, Vec2::new(0.1, -0.2 - 0.5));
        assert!((lens.border - 0.1).abs() < 1e-6, "{}", lens.border);
        // A drawn square (half side 0.2) dragged by its rim to x = 0.4 doubles in size.
        let sq = vec![Vec2::new(-0.2, -0.2), Vec2::new(0.2, -0.2), Vec2::new(0.2, 0.2), Vec2::new(-0.2, 0.2)];
        let mut drawn = Lens { shape: Shape::Polygon(sq), ..Lens::magnifier(Vec2::ZERO, 0.3, 0.1, 2.0) };
        drag(&mut drawn, Handle::Rim, Vec2::new(0.2, 0.0), Vec2::new(0.4, 0.0));
        let Shape::Polygon(p) = &drawn.shape else { unreachable!() };
        assert!((p[1] - Vec2::new(0.4, -0.4)).length() < 1e-3, "{p:?}");
        assert!((drawn.radius - drawn.shape.focus_radius(0.0)).abs() < 1e-6);
    }

    #[test]
    fn the_wheel_tunes_the_strength_within_range() {
        let mut lens = Lens::magnifier(Vec2::ZERO, 0.3, 0.2, 2.0);
        wheel(&mut lens, 1.0);
        assert!(matches!(lens.kind, LensKind::Magnifier { magnification, .. } if (magnification - 2.2).abs() < 1e-5));
        wheel(&mut lens, -100.0);
        assert!(matches!(lens.kind, LensKind::Magnifier { magnification, .. } if magnification == 1.0));
        let mut fish = Lens { kind: LensKind::Angular { field_of_view: 180.0, whole_view: false }, ..lens };
        wheel(&mut fish, 30.0);
        assert!(matches!(fish.kind, LensKind::Angular { field_of_view, .. } if field_of_view == 360.0));
        assert!(fish.validate().is_ok());
    }

    #[test]
    fn contours_follow_the_shapes() {
        for p in contour(&Shape::Circle, 0.5, 16) {
            assert!((p.length() - 0.5).abs() < 1e-5);
        }
        for p in contour(&Shape::Square, 0.5, 16) {
            assert!((p.x.abs().max(p.y.abs()) - 0.5).abs() < 1e-5, "{p}");
        }
    }

    #[test]
    fn strokes_become_outlines() {
        // A circle of radius 0.3 around (0.2, 0.1), drawn with 200 points.
        let stroke: Vec<Vec2> = (0..200)
            .map(|i| {
                let a = i as f32 / 200.0 * std::f32::consts::TAU;
                Vec2::new(0.2, 0.1) + 0.3 * Vec2::new(a.cos(), a.sin())
            })
            .collect();
        let (centre, shape) = stroke_to_shape(&stroke).unwrap();
        assert!((centre - Vec2::new(0.2, 0.1)).length() < 1e-3);
        let Shape::Polygon(p) = &shape else { unreachable!() };
        assert_eq!(p.len(), MAX_POLYGON_VERTICES);
        assert!((shape.focus_radius(0.0) - 0.3).abs() < 0.01);
        // A straight scribble encloses nothing.
        assert!(stroke_to_shape(&[Vec2::ZERO, Vec2::X, Vec2::X * 2.0, Vec2::X * 3.0]).is_none());
    }
}
