//! The geometry of the clip-plane gizmo: where a plane cuts the dataset's box (the
//! outline drawn over the view), how a drag on the screen moves the plane along its
//! normal, and how a drag of the rotate handle at its tip turns the normal.

use glam::{Quat, Vec2, Vec3};

use crate::region::Plane;

/// The polygon where `plane` cuts the box `lo..hi`, in order around its centre; empty
/// when the plane misses the box.
///
/// Each of the box's 12 edges that has its ends on opposite sides of the plane (or one
/// end on it) gives a vertex at the crossing; the vertices, coplanar and convex, are
/// sorted by angle about their mean in a basis of the plane.
pub fn box_section(plane: &Plane, lo: Vec3, hi: Vec3) -> Vec<Vec3> {
    let corner = |i: usize| {
        Vec3::new(if i & 1 == 0 { lo.x } else { hi.x }, if i & 2 == 0 { lo.y } else { hi.y }, if i & 4 == 0 { lo.z } else { hi.z })
    };
    let mut points: Vec<Vec3> = Vec::new();
    for a in 0..8usize {
        for bit in [1, 2, 4] {
            if a & bit != 0 {
                continue;
            }
            let (p, q) = (corner(a), corner(a | bit));
            let (dp, dq) = (plane.distance(p), plane.distance(q));
            if (dp <= 0.0) == (dq <= 0.0) && dp != 0.0 && dq != 0.0 {
                continue;
            }
            let t = if dp == dq { 0.0 } else { dp / (dp - dq) };
            let x = p + (q - p) * t.clamp(0.0, 1.0);
            if !points.iter().any(|y| y.distance_squared(x) < 1e-10) {
                points.push(x);
            }
        }
    }
    if points.len() < 3 {
        return Vec::new();
    }
    let centre = points.iter().copied().sum::<Vec3>() / points.len() as f32;
    let (u, v) = plane.normal.any_orthonormal_pair();
    points.sort_by(|a, b| {
        let (da, db) = (*a - centre, *b - centre);
        da.dot(v).atan2(da.dot(u)).total_cmp(&db.dot(v).atan2(db.dot(u)))
    });
    points
}

/// Millimetres to move a plane along its normal for a drag of `drag` pixels, when one
/// millimetre along the normal shows as `per_mm` pixels on the screen: the drag's
/// component along that direction, in millimetres. Zero when the normal points at the
/// viewer (it has no screen direction to drag along).
pub fn drag_along_normal(per_mm: Vec2, drag: Vec2) -> f32 {
    let len2 = per_mm.length_squared();
    if len2 < 1e-6 { 0.0 } else { drag.dot(per_mm) / len2 }
}

/// The normal after a drag of `drag` pixels (x right, y down) of the rotate handle at
/// its tip, the camera's right and up axes given in the normal's frame: the tip follows
/// the pointer. With `d` the drag's direction in the world, the normal turns by
/// |drag| / `radius` radians about `n × d`, which moves it towards `d` (`(n × d) × n`
/// is `d` less its part along `n`); a normal facing the viewer turns like a trackball,
/// a drag along the normal's own direction on the screen turns nothing. Unit length.
pub fn rotate_normal(normal: Vec3, right: Vec3, up: Vec3, drag: Vec2, radius: f32) -> Vec3 {
    let n = normal.normalize_or(Vec3::Z);
    let d = (right * drag.x - up * drag.y).normalize_or_zero();
    let axis = n.cross(d);
    if axis.length_squared() < 1e-10 || radius <= 0.0 {
        return n;
    }
    (Quat::from_axis_angle(axis.normalize(), drag.length() / radius) * n).normalize_or(Vec3::Z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rotate_handle_turns_the_normal_towards_the_drag() {
        // Camera looking down −z (right +x, up +y, towards the viewer +z); radius 100 px.
        let (right, up) = (Vec3::X, Vec3::Y);
        let quarter = 100.0 * std::f32::consts::FRAC_PI_2;
        // A normal facing the viewer, dragged a quarter turn to the right, points right.
        let n = rotate_normal(Vec3::Z, right, up, Vec2::new(quarter, 0.0), 100.0);
        assert!(n.distance(Vec3::X) < 1e-5, "{n}");
        // Dragged down (screen y grows downwards) a quarter turn: it points down, −y.
        let n = rotate_normal(Vec3::Z, right, up, Vec2::new(0.0, quarter), 100.0);
        assert!(n.distance(-Vec3::Y) < 1e-5, "{n}");
        // A normal along +x (its tip to the right) dragged 50 px up turns 0.5 rad about
        // +z: (cos 0.5, sin 0.5, 0).
        let n = rotate_normal(Vec3::X, right, up, Vec2::new(0.0, -50.0), 100.0);
        assert!(n.distance(Vec3::new(0.5f32.cos(), 0.5f32.sin(), 0.0)) < 1e-5, "{n}");
        // Pulled along itself, or not dragged: unchanged (and made unit).
        assert_eq!(rotate_normal(Vec3::X, right, up, Vec2::new(-40.0, 0.0), 100.0), Vec3::X);
        assert_eq!(rotate_normal(Vec3::new(0.0, 0.0, 2.0), right, up, Vec2::ZERO, 100.0), Vec3::Z);
    }

    #[test]
    fn an_axis_plane_cuts_a_rectangle() {
        let s = box_section(&Plane::through(Vec3::new(0.0, 0.0, 1.0), Vec3::Z), Vec3::ZERO, Vec3::new(4.0, 2.0, 3.0));
        assert_eq!(s.len(), 4);
        assert!(s.iter().all(|p| (p.z - 1.0).abs() < 1e-6));
        // In order around the rectangle: consecutive corners share an x or a y.
        for i in 0..4 {
            let (a, b) = (s[i], s[(i + 1) % 4]);
            assert!((a.x - b.x).abs() < 1e-6 || (a.y - b.y).abs() < 1e-6, "{s:?}");
        }
    }

    #[test]
    fn the_diagonal_plane_of_a_cube_cuts_a_regular_hexagon() {
        // x + y + z = 1.5 through the unit cube: six vertices, all 0.7071 from the centre.
        let s = box_section(&Plane::through(Vec3::splat(0.5), Vec3::ONE), Vec3::ZERO, Vec3::ONE);
        assert_eq!(s.len(), 6);
        for p in &s {
            assert!((p.distance(Vec3::splat(0.5)) - 0.5f32.sqrt()).abs() < 1e-5);
        }
        // Sides of equal length 0.7071 (in order).
        for i in 0..6 {
            assert!((s[i].distance(s[(i + 1) % 6]) - 0.5f32.sqrt()).abs() < 1e-5, "{s:?}");
        }
    }

    #[test]
    fn a_plane_beside_the_box_cuts_nothing() {
        assert!(box_section(&Plane::through(Vec3::new(0.0, 0.0, 5.0), Vec3::Z), Vec3::ZERO, Vec3::ONE).is_empty());
    }

    #[test]
    fn drags_move_along_the_normal_on_screen() {
        // 1 mm shows as 2 px to the right: a 10 px drag right is 5 mm, up is nothing.
        assert_eq!(drag_along_normal(Vec2::new(2.0, 0.0), Vec2::new(10.0, 0.0)), 5.0);
        assert_eq!(drag_along_normal(Vec2::new(2.0, 0.0), Vec2::new(0.0, 7.0)), 0.0);
        assert_eq!(drag_along_normal(Vec2::new(-1.0, 1.0), Vec2::new(-3.0, 3.0)), 3.0);
        assert_eq!(drag_along_normal(Vec2::ZERO, Vec2::new(5.0, 5.0)), 0.0);
    }
}
