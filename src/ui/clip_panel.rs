//! The Clipping panel: clip planes (add, axis or view-facing normal, position along the
//! normal, flip side, enable, remove, reset) and a clip box (per-axis extent) of the
//! selected dataset, in the dataset's frame. In the viewport, each plane's handle drags
//! it along its normal and the ring at its normal's tip turns it (`super::clip_gizmo`).

use bevy::math::Vec3;
use bevy_egui::egui::{self, Ui};

use crate::clip::{ClipBox, ClipPlane, Clipping};

/// Shows the panel for a dataset whose box spans `lo..hi`; `view_dir` (the camera's
/// forward in the dataset's frame) orients new view-facing planes.
pub fn panel(ui: &mut Ui, clip: &mut Clipping, (lo, hi): (Vec3, Vec3), view_dir: Vec3) {
    let centre = (lo + hi) * 0.5;
    let mut remove = None;
    for (i, p) in clip.planes.iter_mut().enumerate() {
        ui.horizontal(|ui| {
            ui.checkbox(&mut p.enabled, format!("plane {}", i + 1));
            for (label, n) in [("x", Vec3::X), ("y", Vec3::Y), ("z", Vec3::Z)] {
                if ui.small_button(label).on_hover_text(format!("normal along {label}")).clicked() {
                    p.normal = n;
                }
            }
            if ui.small_button("view").on_hover_text("face the camera").clicked() {
                p.normal = -view_dir;
            }
            ui.checkbox(&mut p.flip, "flip");
            if ui.small_button("✖").on_hover_text("remove").clicked() {
                remove = Some(i);
            }
        });
        // Position of the plane along its normal, over the box's extent along it.
        let n = p.normal.normalize_or(Vec3::Z);
        let half = ((hi - lo) * 0.5 * n.abs()).element_sum();
        let mut d = n.dot(p.point - centre);
        if ui.add(egui::Slider::new(&mut d, -half..=half).text("position (mm)")).changed() {
            p.point = centre + n * d;
        }
    }
    if let Some(i) = remove {
        clip.planes.remove(i);
    }
    ui.horizontal(|ui| {
        if ui.button("add plane").clicked() {
            clip.planes.push(ClipPlane::new(centre, -view_dir.normalize_or(Vec3::Z)));
        }
        if ui.button("reset").on_hover_text("remove every plane and the box").clicked() {
            *clip = Clipping::default();
        }
    });
    let mut boxed = clip.clip_box.is_some_and(|b| b.enabled);
    if ui.checkbox(&mut boxed, "clip box").changed() {
        clip.clip_box = Some(ClipBox { enabled: boxed, ..clip.clip_box.unwrap_or(ClipBox { min: lo, max: hi, enabled: true }) });
    }
    if let Some(b) = clip.clip_box.as_mut().filter(|b| b.enabled) {
        for (k, axis) in ["x", "y", "z"].into_iter().enumerate() {
            ui.horizontal(|ui| {
                ui.label(axis);
                let step = ((hi[k] - lo[k]) / 256.0).max(1e-3);
                let mut a = b.min[k];
                let mut z = b.max[k];
                ui.add(egui::DragValue::new(&mut a).range(lo[k]..=z - step).speed(step));
                ui.add(egui::DragValue::new(&mut z).range(a + step..=hi[k]).speed(step));
                b.min[k] = a;
                b.max[k] = z;
            });
        }
    }
}
