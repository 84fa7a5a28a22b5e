//! The exploded view panel's selection section: smoothing the selection and painting it
//! with the volumetric brush ([`crate::explode::paint`]; the viewport tool
//! [`Tool::Paint`]: drag over the view, Shift paints the other way), undo stroke by
//! stroke; and the brush's outline at the cursor.

use bevy::prelude::*;
use bevy_egui::egui;

use super::explode_tools::{ExplodeUi, Tool};
use super::orbit::OrbitCamera;
use crate::explode::edit::{Edit, ExplodeEdits};
use crate::explode::spec::ExplodeSource;

/// Most binomial smoothing passes the panel offers.
const MAX_SMOOTHING: u32 = 6;

/// The section (for an exploded `dataset` made from `source`).
pub fn selection_section(ui: &mut egui::Ui, s: &mut ExplodeUi, edits: &mut ExplodeEdits, dataset: Entity, source: &ExplodeSource) {
    egui::CollapsingHeader::new("Selection (the focus)").default_open(true).show(ui, |ui| {
        let mut passes = source.0.smooth;
        if ui.add(egui::Slider::new(&mut passes, 0..=MAX_SMOOTHING).text("smoothing (binomial passes)")).changed() {
            edits.queue.push(Edit::Smooth { dataset, passes });
        }
        ui.horizontal(|ui| {
            ui.label("brush");
            let painting = s.tool == Tool::Paint;
            if ui.selectable_label(painting && !s.brush.erase, "add").clicked() {
                (s.tool, s.brush.erase) = (Tool::Paint, false);
            }
            if ui.selectable_label(painting && s.brush.erase, "erase").clicked() {
                (s.tool, s.brush.erase) = (Tool::Paint, true);
            }
            if ui.selectable_label(!painting, "off").clicked() && painting {
                s.tool = Tool::None;
            }
        });
        ui.add(egui::Slider::new(&mut s.brush.radius, 0.5..=60.0).logarithmic(true).suffix(" mm").text("radius"));
        ui.add(egui::Slider::new(&mut s.brush.hardness, 0.0..=1.0).text("hardness"));
        ui.horizontal(|ui| {
            let n = source.0.paint.len();
            if ui.add_enabled(n > 0, egui::Button::new(format!("Undo stroke ({n})"))).clicked() {
                edits.queue.push(Edit::UndoStroke { dataset });
            }
            ui.label("drag on the view; Shift: the other way");
        });
    });
}

/// The brush's outline at the cursor (window logical pixels), as large as the brush at
/// the orbit's centre in a viewport of `size`.
pub fn brush_overlay(ctx: &egui::Context, s: &ExplodeUi, orbit: &OrbitCamera, size: Vec2, cursor: Option<Vec2>) {
    let Some(cursor) = cursor.filter(|_| s.tool == Tool::Paint) else { return };
    let cam = orbit.camera();
    let (w, h) = (size.x.max(1.0), size.y.max(1.0));
    let (Some(a), Some(b)) = (cam.to_pixel(orbit.target, w, h), cam.to_pixel(orbit.target + cam.right() * s.brush.radius, w, h)) else {
        return;
    };
    let painter = ctx.layer_painter(egui::LayerId::new(egui::Order::Foreground, egui::Id::new("explode_brush")));
    let colour = if s.brush.erase { egui::Color32::from_rgb(120, 180, 255) } else { egui::Color32::from_rgb(255, 200, 60) };
    let r = a.distance(b).max(2.0);
    painter.circle_stroke(egui::pos2(cursor.x, cursor.y), r, egui::Stroke::new(1.5, colour));
    painter.circle_stroke(
        egui::pos2(cursor.x, cursor.y),
        r * s.brush.hardness.clamp(0.0, 1.0),
        egui::Stroke::new(1.0, colour.gamma_multiply(0.5)),
    );
}
