//! Distance rulers in the app: Shift+click two points, in a slice view or on the surface
//! the 3D view shows (the point under the cursor, picked with the CPU reference renderer
//! through the lenses under the view's transfer functions); the rulers are drawn in the 3D view
//! and in the slices they pass through, with their length in millimetres
//! ([`crate::slices::ruler`]).

use bevy::math::Affine3A;
use bevy::prelude::*;
use bevy::window::PrimaryWindow;
use bevy_egui::egui::{self, Color32, Rect, Stroke, pos2};

use super::orbit::PointerInViewport;
use super::under_cursor::UnderCursor;
use crate::slices::ruler::Ruler;

/// The rulers' colour.
pub const RULER: Color32 = Color32::from_rgb(255, 80, 220);

/// Pixels a Shift+click may move between press and release and still place a point.
const CLICK_SLOP: f32 = 4.0;

/// A ruler from `a` to `b` on the screen (each with whether it is the ruler's end, which
/// gets a dot), labelled with its length.
pub fn draw_ruler(painter: &egui::Painter, (a, a_end): (egui::Pos2, bool), (b, b_end): (egui::Pos2, bool), length_mm: f32, font: f32) {
    painter.line_segment([a, b], Stroke::new(2.0, RULER));
    for (p, end) in [(a, a_end), (b, b_end)] {
        if end {
            painter.circle_filled(p, 3.0, RULER);
        }
    }
    let label = format!("{length_mm:.1} mm");
    painter.text(a.lerp(b, 0.5) + egui::vec2(4.0, -4.0), egui::Align2::LEFT_BOTTOM, label, egui::FontId::proportional(font), RULER);
}

/// Rulers being made: the first end placed, rulers finished this frame, a dataset whose
/// rulers go ([`apply_rulers`] spawns and despawns them).
#[derive(Resource, Default)]
pub struct RulerTool {
    /// A ruler's first end (dataset, point in its frame).
    pub start: Option<(Entity, Vec3)>,
    pub pending: Vec<Ruler>,
    pub clear: Option<Entity>,
}

impl RulerTool {
    /// A ruler's end at `point` of `dataset` (its frame): the first begins a ruler, the
    /// second on the same dataset finishes it.
    pub fn end(&mut self, dataset: Entity, point: Vec3) {
        match self.start.take() {
            Some((e, from)) if e == dataset => self.pending.push(Ruler { dataset, from, to: point }),
            _ => self.start = Some((dataset, point)),
        }
    }
}

/// Spawns the rulers made and removes those cleared; Esc cancels a ruler begun.
pub fn apply_rulers(mut tool: ResMut<RulerTool>, mut commands: Commands, rulers: Query<(Entity, &Ruler)>, keys: Res<ButtonInput<KeyCode>>) {
    for r in std::mem::take(&mut tool.pending) {
        commands.spawn(r);
    }
    if let Some(dataset) = tool.clear.take() {
        for (e, r) in &rulers {
            if r.dataset == dataset {
                commands.entity(e).despawn();
            }
        }
    }
    if keys.just_pressed(KeyCode::Escape) {
        tool.start = None;
    }
}

/// Every ruler in the 3D view (`free`), each with its dataset's placement, and a ruler
/// begun from its first point to the cursor.
pub fn overlay(ctx: &egui::Context, free: Rect, camera: Option<crate::region::Camera>, rulers: &[(Ruler, Affine3A)], begun: Option<Vec3>) {
    let Some(camera) = camera else { return };
    if rulers.is_empty() && begun.is_none() {
        return;
    }
    let painter = ctx.layer_painter(egui::LayerId::new(egui::Order::Background, egui::Id::new("rulers"))).with_clip_rect(free);
    let on_screen = |p: Vec3| camera.to_pixel(p, free.width(), free.height()).map(|q| pos2(free.left() + q.x, free.top() + q.y));
    for (r, to_world) in rulers {
        if let (Some(a), Some(b)) = (on_screen(to_world.transform_point3(r.from)), on_screen(to_world.transform_point3(r.to))) {
            draw_ruler(&painter, (a, true), (b, true), r.length_mm(), 13.0);
        }
    }
    if let Some(a) = begun.and_then(on_screen) {
        painter.circle_filled(a, 3.0, RULER);
        if let Some(p) = ctx.pointer_hover_pos().filter(|p| free.contains(*p)) {
            painter.line_segment([a, p], Stroke::new(1.0, RULER));
        }
    }
}

/// Shift+click in the 3D view: a ruler's end on the first visible point under the cursor
/// (picked through the lenses, [`super::under_cursor`]).
pub fn ruler_on_surface(
    buttons: Res<ButtonInput<MouseButton>>,
    keys: Res<ButtonInput<KeyCode>>,
    windows: Query<&Window, With<PrimaryWindow>>,
    pointer: Res<PointerInViewport>,
    under: Res<UnderCursor>,
    mut tool: ResMut<RulerTool>,
    mut pressed_at: Local<Option<Vec2>>,
) {
    let Ok(window) = windows.single() else { return };
    let shift = keys.any_pressed([KeyCode::ShiftLeft, KeyCode::ShiftRight]);
    let cursor = window.cursor_position();
    if buttons.just_pressed(MouseButton::Left) {
        *pressed_at = cursor.filter(|_| shift && pointer.inside);
    }
    if !buttons.just_released(MouseButton::Left) {
        return;
    }
    let (Some(start), Some(cursor)) = (pressed_at.take(), cursor) else { return };
    if shift
        && start.distance(cursor) <= CLICK_SLOP
        && let Some((dataset, point)) = under.point
    {
        tool.end(dataset, point);
    }
}
