//! The geometry of working with windows in a 3D view (pure): which window has the
//! focus, dragging a window or the 3D pointer in the plane facing the camera, resizing
//! a window from a corner.
//!
//! Focus (Borst et al., section 3: "a window gains focus when the pointer hovers over it
//! or reaches into it"): the 3D pointer inside a window's box gives that window the
//! focus (the smallest such box, so a window inside another can be reached); otherwise
//! the window whose box the cursor's ray enters first; otherwise the main view. Without
//! a cursor in the view (it is over the panels) the focus stays, so the panels edit the
//! window that was last pointed at.

use glam::Vec3;

use super::boxes::OrientedBox;
use crate::region::Ray;

/// The smallest half extent a resized window keeps (millimetres).
pub const MIN_HALF: f32 = 1.0;

/// `[t0, t1]` of the ray inside the box (`t0` may be negative when the origin is inside).
pub fn ray_box(ray: &Ray, b: &OrientedBox) -> Option<(f32, f32)> {
    let local = b.to_local();
    let o = local.transform_point3(ray.origin);
    let d = local.transform_vector3(ray.dir);
    let (mut t0, mut t1) = (f32::NEG_INFINITY, f32::INFINITY);
    for a in 0..3 {
        if d[a].abs() < 1e-12 {
            if o[a].abs() > 1.0 {
                return None;
            }
            continue;
        }
        let (u, v) = ((-1.0 - o[a]) / d[a], (1.0 - o[a]) / d[a]);
        t0 = t0.max(u.min(v));
        t1 = t1.min(u.max(v));
    }
    (t0 <= t1 && t1 >= 0.0).then_some((t0, t1))
}

/// The window that has the focus after this input: `None` keeps the current focus (no
/// cursor in the view and the pointer in no window), `Some(None)` gives it to the main
/// view. `windows` in their order (entity order: the earlier wins ties).
pub fn focus<K: Copy>(windows: &[(K, OrientedBox)], cursor: Option<&Ray>, pointer: Option<Vec3>) -> Option<Option<K>> {
    let volume = |b: &OrientedBox| b.half.x * b.half.y * b.half.z;
    let reached = pointer.and_then(|p| {
        windows.iter().filter(|(_, b)| b.contains(p)).min_by(|(_, a), (_, b)| volume(a).total_cmp(&volume(b))).map(|(k, _)| *k)
    });
    if reached.is_some() {
        return Some(reached);
    }
    let ray = cursor?;
    let hovered = windows
        .iter()
        .filter_map(|(k, b)| ray_box(ray, b).map(|(t0, _)| (*k, t0.max(0.0))))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(k, _)| k);
    Some(hovered)
}

/// Where the cursor's ray meets the plane through `anchor` facing the camera (normal
/// `forward`): dragging there keeps the dragged point under the cursor at its depth.
pub fn on_view_plane(anchor: Vec3, forward: Vec3, ray: &Ray) -> Option<Vec3> {
    let denom = ray.dir.dot(forward);
    if denom.abs() < 1e-9 {
        return None;
    }
    let t = (anchor - ray.origin).dot(forward) / denom;
    (t.is_finite() && t >= 0.0).then(|| ray.at(t))
}

/// The window resized by dragging corner `corner` (numbered as
/// [`OrientedBox::corners`]) to `target`: the opposite corner stays, the box keeps its
/// rotation, and each half extent is at least [`MIN_HALF`].
pub fn resize_from_corner(b: &OrientedBox, corner: usize, target: Vec3) -> OrientedBox {
    let sign = |bit: usize| if corner & bit == 0 { -1.0 } else { 1.0 };
    let s = Vec3::new(sign(1), sign(2), sign(4));
    let fixed = b.corners()[7 - corner];
    // Extent from the fixed corner towards the dragged one, in the box's axes.
    let local = b.rotation.inverse() * (target - fixed);
    let half = (local * s * 0.5).max(Vec3::splat(MIN_HALF));
    OrientedBox { center: fixed + b.rotation * (s * half), rotation: b.rotation, half }
}

/// The corner of `b` nearest the cursor's ray, if the ray passes within `tolerance`
/// (world units at the corner) of it.
pub fn corner_under(b: &OrientedBox, ray: &Ray, tolerance: f32) -> Option<usize> {
    b.corners()
        .iter()
        .enumerate()
        .map(|(i, &c)| {
            let t = (c - ray.origin).dot(ray.dir).max(0.0);
            (i, ray.at(t).distance(c))
        })
        .filter(|(_, d)| *d <= tolerance)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

/// A tolerance in world units at `p` that spans `pixels` on a screen `height` pixels
/// tall showing `view_height` world units at unit distance (`2·tan(fov/2)` for a
/// perspective camera at `eye`; orthographic: the view's height, `eye` ignored).
pub fn pixels_to_world(pixels: f32, height: f32, view_height: f32, eye: Option<Vec3>, p: Vec3) -> f32 {
    let distance = eye.map_or(1.0, |e| e.distance(p));
    pixels / height.max(1.0) * view_height * distance
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    fn unit_at(center: Vec3, half: f32) -> OrientedBox {
        OrientedBox { center, rotation: Quat::IDENTITY, half: Vec3::splat(half) }
    }

    #[test]
    fn ray_box_by_hand() {
        let b = unit_at(Vec3::ZERO, 1.0);
        let ray = Ray { origin: Vec3::new(0.0, 0.0, -5.0), dir: Vec3::Z };
        assert_eq!(ray_box(&ray, &b), Some((4.0, 6.0)));
        let miss = Ray { origin: Vec3::new(2.0, 0.0, -5.0), dir: Vec3::Z };
        assert_eq!(ray_box(&miss, &b), None);
        // Behind the origin: no hit.
        let away = Ray { origin: Vec3::new(0.0, 0.0, 5.0), dir: Vec3::Z };
        assert_eq!(ray_box(&away, &b), None);
        // A turned box: 45° about z, half 1: the ray along x through the centre meets
        // the corner edges at ±√2.
        let turned = OrientedBox { rotation: Quat::from_rotation_z(std::f32::consts::FRAC_PI_4), ..b };
        let (t0, t1) = ray_box(&Ray { origin: Vec3::new(-5.0, 0.0, 0.0), dir: Vec3::X }, &turned).unwrap();
        assert!((t0 - (5.0 - 2f32.sqrt())).abs() < 1e-5 && (t1 - (5.0 + 2f32.sqrt())).abs() < 1e-5);
    }

    #[test]
    fn focus_rules() {
        let big = unit_at(Vec3::ZERO, 10.0);
        let small = unit_at(Vec3::new(5.0, 0.0, 0.0), 2.0);
        let far = unit_at(Vec3::new(0.0, 0.0, 40.0), 3.0);
        let windows = [(1, big), (2, small), (3, far)];
        let down_z = |x: f32| Ray { origin: Vec3::new(x, 0.0, -100.0), dir: Vec3::Z };
        // Hover: the box the ray enters first (big at z = -10, before far at 37).
        assert_eq!(focus(&windows, Some(&down_z(0.0)), None), Some(Some(1)));
        // Only far lies on this ray.
        let only_far = Ray { origin: Vec3::new(0.0, 2.5, -100.0), dir: Vec3::Z };
        assert_eq!(focus(&[(3, far)], Some(&only_far), None), Some(Some(3)));
        // Reaching in beats hovering: the pointer inside both big and small → the
        // smaller one, whatever the cursor points at.
        assert_eq!(focus(&windows, Some(&down_z(0.0)), Some(Vec3::new(5.5, 0.0, 0.0))), Some(Some(2)));
        assert_eq!(focus(&windows, None, Some(Vec3::new(0.0, 0.0, 41.0))), Some(Some(3)));
        // The cursor over empty space: the main view.
        assert_eq!(focus(&windows, Some(&down_z(50.0)), None), Some(None));
        // No cursor (over the panels) and the pointer outside: the focus stays.
        assert_eq!(focus(&windows, None, Some(Vec3::splat(100.0))), None);
        assert_eq!(focus::<i32>(&windows, None, None), None);
    }

    #[test]
    fn view_plane_drag_keeps_depth() {
        let ray = Ray { origin: Vec3::new(0.0, 0.0, 10.0), dir: Vec3::new(0.6, 0.0, -0.8) };
        let p = on_view_plane(Vec3::new(3.0, 7.0, 2.0), -Vec3::Z, &ray).unwrap();
        // Plane z = 2: t = 8 / 0.8 = 10 → (6, 0, 2).
        assert!(p.distance(Vec3::new(6.0, 0.0, 2.0)) < 1e-5);
        // A ray parallel to the plane never meets it.
        assert!(on_view_plane(Vec3::ZERO, Vec3::Z, &Ray { origin: Vec3::ONE, dir: Vec3::X }).is_none());
    }

    #[test]
    fn resizing_keeps_the_opposite_corner() {
        let b = OrientedBox { center: Vec3::new(1.0, 2.0, 3.0), rotation: Quat::from_rotation_y(0.3), half: Vec3::new(2.0, 3.0, 4.0) };
        for corner in 0..8 {
            let target = b.corners()[corner] + b.rotation * Vec3::new(1.0, -0.5, 2.0);
            let r = resize_from_corner(&b, corner, target);
            assert!(r.corners()[7 - corner].distance(b.corners()[7 - corner]) < 1e-4, "corner {corner}: the fixed corner moved");
            assert!(r.corners()[corner].distance(target) < 1e-4, "corner {corner}: the dragged corner is not at the target");
            assert_eq!(r.rotation, b.rotation);
        }
        // Corner 7 (+x +y +z) moved by (1, -0.5, 2) in box axes: half grows by half that.
        let r = resize_from_corner(&b, 7, b.corners()[7] + b.rotation * Vec3::new(1.0, -0.5, 2.0));
        assert!(r.half.distance(Vec3::new(2.5, 2.75, 5.0)) < 1e-5);
        // Dragged through the fixed corner: the box keeps the minimum size on the fixed
        // corner's side.
        let collapsed = resize_from_corner(&b, 7, b.corners()[0] - b.rotation * Vec3::ONE);
        assert_eq!(collapsed.half, Vec3::splat(MIN_HALF));
        assert!(collapsed.corners()[0].distance(b.corners()[0]) < 1e-4);
    }

    #[test]
    fn corners_under_the_cursor() {
        let b = unit_at(Vec3::ZERO, 1.0);
        // Aim at corner 7 (1, 1, 1) from far away along -z... the ray passes (1, 1, *):
        // corners 3 (1, 1, -1) and 7 (1, 1, 1) both lie on it; the nearer along the
        // ray does not matter, both are at distance 0: the first wins.
        let ray = Ray { origin: Vec3::new(1.02, 1.0, 10.0), dir: -Vec3::Z };
        assert!(matches!(corner_under(&b, &ray, 0.05), Some(3 | 7)));
        assert_eq!(corner_under(&b, &ray, 0.01), None);
        let oblique =
            Ray { origin: Vec3::new(10.0, -10.0, -10.0), dir: (Vec3::new(1.0, -1.0, -1.0) - Vec3::new(10.0, -10.0, -10.0)).normalize() };
        assert_eq!(corner_under(&b, &oblique, 0.01), Some(1));
        // 10 pixels of 500 at distance 20 with a view 0.8 tall at unit distance.
        assert!((pixels_to_world(10.0, 500.0, 0.8, Some(Vec3::ZERO), Vec3::new(0.0, 0.0, 20.0)) - 0.32).abs() < 1e-6);
    }
}
