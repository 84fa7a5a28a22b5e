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

/// Window-logical origin and size of the main camera's viewport.
pub fn viewport_logical(camera: &Camera, window: &Window) -> (Vec2, Vec2) {
    let scale = window.scale_factor();
    match &camera.viewport {
        Some(v) => (v.physical_position.as_vec2() / scale, v.physical_size.as_vec2() / scale),
        None => (Vec2::ZERO, Vec2::new(window.width(), window.height())),
    }
}
