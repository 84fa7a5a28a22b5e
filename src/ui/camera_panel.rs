//! The Camera panel: standard views, projection, fly-through, the orbit's angles, and
//! the interactive resolution a moving view draws at.

use bevy::prelude::*;
use bevy_egui::egui::{self, Ui};

use super::orbit::OrbitCamera;
use crate::interactive::InteractiveResolution;
use crate::region::View;

/// The view's interactive resolution: on or off, the frame time it holds while moving.
pub fn interaction_panel(ui: &mut Ui, adapt: &mut InteractiveResolution) {
    ui.separator();
    ui.checkbox(&mut adapt.enabled, "fewer pixels while moving").on_hover_text(
        "While the camera, a lens, a window or a slider moves, the rays are drawn at a lower \
         resolution that holds the frame time below, then refined to every pixel when it rests",
    );
    ui.add_enabled(
        adapt.enabled,
        egui::Slider::new(&mut adapt.target_ms, 16.0..=500.0).logarithmic(true).suffix(" ms").text("frame time while moving"),
    );
}

/// Standard views, reset, projection, fly-through, field of view and the orbit's angles.
pub fn camera_panel(ui: &mut Ui, orbit: &mut OrbitCamera, bounds: (Vec3, Vec3)) {
    ui.horizontal_wrapped(|ui| {
        for (label, view) in [
            ("front", View::Anterior),
            ("back", View::Posterior),
            ("left", View::Left),
            ("right", View::Right),
            ("top", View::Superior),
            ("bottom", View::Inferior),
            ("oblique", View::Oblique),
        ] {
            if ui.button(label).clicked() {
                orbit.frame(view, bounds.0, bounds.1, 1.0);
            }
        }
    });
    ui.horizontal(|ui| {
        if ui.button("reset").clicked() {
            orbit.frame(View::Oblique, bounds.0, bounds.1, 1.0);
        }
        ui.checkbox(&mut orbit.orthographic, "orthographic");
        let mut fly = orbit.fly;
        if ui.checkbox(&mut fly, "fly-through (V)").changed() {
            super::orbit::toggle_fly(orbit, bounds);
        }
    });
    ui.add(egui::Slider::new(&mut orbit.fov_deg, 10.0..=90.0).text("field of view °"));
    ui.add(egui::Slider::new(&mut orbit.azimuth_deg, 0.0..=360.0).text("azimuth °"));
    ui.add(egui::Slider::new(&mut orbit.elevation_deg, -89.0..=89.0).text("elevation °"));
}
