//! The map from a window onto its source, and the automations that set the source box
//! (Borst, Baiyya, Best, Kinsland, "Volumetric Windows").
//!
//! A window shows, at each of its points, the data at the point of its source box with
//! the same local coordinates: `M = S · W⁻¹` (`W`, `S`: the boxes' local → world maps,
//! [`OrientedBox::to_world`]). A source smaller than the window magnifies by
//! `w_i / s_i` along axis `i`; a larger one minifies (a world-in-miniature). A region
//! of the window then maps world points to the data's voxels by `V · M`, `V` being the
//! dataset's own world → voxel map.
//!
//! Automations: *fit* sets the source box to the content's bounding box seen along the
//! window's axes (uniformly scaled so all of it shows, or per axis to fill the box), and
//! *orientation coupling* turns the source box so that `M` has the rotation of another
//! map — the identity for the main view (the content keeps the orientation it has in
//! the main view however the window turns), or another window's `M`.

use glam::{Affine3A, Mat3, Quat, Vec3};

use super::boxes::OrientedBox;

/// World point in the window → world point in the source (same local coordinates).
pub fn window_to_source(window: &OrientedBox, source: &OrientedBox) -> Affine3A {
    source.to_world() * window.to_local()
}

/// Magnification along each of the window's axes: window extent over source extent.
pub fn magnification(window: &OrientedBox, source: &OrientedBox) -> Vec3 {
    window.half / source.half.max(Vec3::splat(1e-12))
}

/// The source box that fits `points` (the content's corners, world) into `window`:
/// turned like `rotation`, centred on the points' box along those axes, and scaled so
/// that every point shows (`uniform`: one factor for all axes, the content undistorted)
/// or so that the content fills each axis.
pub fn fit(window: &OrientedBox, rotation: Quat, points: &[Vec3], uniform: bool) -> OrientedBox {
    let to_axes = Mat3::from_quat(rotation.inverse());
    let (lo, hi) = points
        .iter()
        .map(|p| to_axes * *p)
        .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(a, b), p| (a.min(p), b.max(p)));
    if !lo.is_finite() || !hi.is_finite() {
        return OrientedBox { rotation, ..*window };
    }
    let center = Mat3::from_quat(rotation) * ((lo + hi) * 0.5);
    let content = ((hi - lo) * 0.5).max(Vec3::splat(1e-6));
    let half = if uniform {
        // The largest content-to-window ratio: every axis fits.
        let s = (content / window.half.max(Vec3::splat(1e-12))).max_element();
        window.half * s
    } else {
        content
    };
    OrientedBox { center, rotation, half }
}

/// The rotation a source box needs so that the window's map has rotation `coupled`
/// (the identity to keep the main view's orientation): `R_S · R_W⁻¹ = coupled`.
pub fn coupled_rotation(window: Quat, coupled: Quat) -> Quat {
    (coupled * window).normalize()
}

/// The rotation part of a window's map `M` (its linear part with the scale removed).
pub fn map_rotation(window: &OrientedBox, source: &OrientedBox) -> Quat {
    (source.rotation * window.rotation.inverse()).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_half_size_source_magnifies_by_two() {
        let window = OrientedBox { center: Vec3::new(50.0, 0.0, 0.0), rotation: Quat::IDENTITY, half: Vec3::splat(20.0) };
        let source = OrientedBox { center: Vec3::new(0.0, 5.0, 0.0), rotation: Quat::IDENTITY, half: Vec3::splat(10.0) };
        assert_eq!(magnification(&window, &source), Vec3::splat(2.0));
        let m = window_to_source(&window, &source);
        // The window's centre shows the source's centre, its corner the source's corner,
        // and 20 mm across the window are 10 mm of data.
        assert!((m.transform_point3(window.center) - source.center).length() < 1e-5);
        assert!((m.transform_point3(Vec3::new(70.0, 20.0, 20.0)) - Vec3::new(10.0, 15.0, 10.0)).length() < 1e-4);
        assert!((m.transform_vector3(Vec3::X * 20.0) - Vec3::X * 10.0).length() < 1e-5);
        // A source twice the window: a world-in-miniature, ×0.5.
        let big = OrientedBox { half: Vec3::splat(40.0), ..source };
        assert_eq!(magnification(&window, &big), Vec3::splat(0.5));
    }

    #[test]
    fn a_window_turned_against_its_source_turns_the_content() {
        // Window turned 90° about z, source not: the window's local x (world y) shows the
        // source's local x (world x).
        let window =
            OrientedBox { center: Vec3::ZERO, rotation: Quat::from_rotation_z(std::f32::consts::FRAC_PI_2), half: Vec3::splat(1.0) };
        let source = OrientedBox { center: Vec3::ZERO, rotation: Quat::IDENTITY, half: Vec3::splat(1.0) };
        let m = window_to_source(&window, &source);
        assert!((m.transform_point3(Vec3::Y) - Vec3::X).length() < 1e-5);
        // Coupled to the main view the source turns with the window: no rotation left.
        let coupled = OrientedBox { rotation: coupled_rotation(window.rotation, Quat::IDENTITY), ..source };
        assert!((window_to_source(&window, &coupled).transform_point3(Vec3::Y) - Vec3::Y).length() < 1e-5);
        // Coupled to another map: this map takes its rotation.
        let other = Quat::from_rotation_x(0.4);
        let coupled = OrientedBox { rotation: coupled_rotation(window.rotation, other), ..source };
        assert!(map_rotation(&window, &coupled).angle_between(other) < 1e-4);
    }

    #[test]
    fn fit_shows_all_of_the_content() {
        let window = OrientedBox { center: Vec3::new(100.0, 0.0, 0.0), rotation: Quat::IDENTITY, half: Vec3::new(10.0, 10.0, 5.0) };
        // Content 200 × 100 × 40 mm around (0, 0, 0).
        let corners: Vec<Vec3> = OrientedBox::aligned(Vec3::new(-100.0, -50.0, -20.0), Vec3::new(100.0, 50.0, 20.0)).corners().to_vec();
        let uniform = fit(&window, Quat::IDENTITY, &corners, true);
        // Ratios 10, 5, 4: the source is the window ×10, so x fills and y, z have room.
        assert!((uniform.half - Vec3::new(100.0, 100.0, 50.0)).length() < 1e-3, "{}", uniform.half);
        assert!(uniform.center.length() < 1e-4);
        let m = window_to_source(&window, &uniform);
        assert!(corners.iter().all(|c| window.contains(m.inverse().transform_point3(*c))));
        assert_eq!(magnification(&window, &uniform), Vec3::splat(0.1));
        // Per axis: the content fills every axis.
        let filled = fit(&window, Quat::IDENTITY, &corners, false);
        assert!((filled.half - Vec3::new(100.0, 50.0, 20.0)).length() < 1e-3);
    }
}
