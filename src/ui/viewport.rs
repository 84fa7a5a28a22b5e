//! The 3D view's part of the window: what the panels leave free.

use bevy::camera::Viewport;
use bevy::prelude::*;

/// Limits the 3D camera to the part of the window the panels leave free.
pub fn set_viewport(camera: &mut Camera, window: &Window, free: bevy_egui::egui::Rect, zoom: f32) {
    let scale = window.scale_factor() * zoom;
    let pos = UVec2::new((free.min.x * scale).max(0.0) as u32, (free.min.y * scale).max(0.0) as u32);
    let size = UVec2::new((free.width() * scale) as u32, (free.height() * scale) as u32)
        .min(UVec2::new(window.physical_width(), window.physical_height()).saturating_sub(pos));
    if size.x < 8 || size.y < 8 {
        return;
    }
    let viewport = Viewport { physical_position: pos, physical_size: size, ..default() };
    if camera.viewport.as_ref().is_none_or(|v| v.physical_position != pos || v.physical_size != size) {
        camera.viewport = Some(viewport);
    }
}

/// The main camera's viewport as an egui rectangle (window-logical points), or the
/// whole of `ctx` without a window or camera: where overlays go.
pub fn viewport_rect(
    ctx: &bevy_egui::egui::Context,
    windows: &Query<&Window, With<bevy::window::PrimaryWindow>>,
    cams: &Query<&Camera, With<super::state::MainCamera>>,
) -> bevy_egui::egui::Rect {
    match (windows.single(), cams.single()) {
        (Ok(window), Ok(camera)) => {
            let (origin, size) = viewport_logical(camera, window);
            bevy_egui::egui::Rect::from_min_size(bevy_egui::egui::pos2(origin.x, origin.y), bevy_egui::egui::vec2(size.x, size.y))
        }
        _ => ctx.viewport_rect(),
    }
}

/// Window-logical origin and size of the main camera's viewport.
pub fn viewport_logical(camera: &Camera, window: &Window) -> (Vec2, Vec2) {
    let scale = window.scale_factor();
    match &camera.viewport {
        Some(v) => (v.physical_position.as_vec2() / scale, v.physical_size.as_vec2() / scale),
        None => (Vec2::ZERO, Vec2::new(window.width(), window.height())),
    }
}
