//! Lenses in the app: placed and tuned in the viewport and in the Lenses panel, drawn
//! over the view with their outlines, the lens-distorted lattice and the magnification
//! at the cursor.
//!
//! Viewport: drag inside a lens to move it, drag its rim for the radius and the outer
//! ring for the border width, turn the wheel over it for its strength (magnification,
//! sampling rate or field of view). "Draw" in the panel turns the next left drag into
//! a lens outline. A lens press is the lens's: the camera does not move with it. The
//! pure parts (handles, strokes, the lattice) live in `crate::lens`.

use bevy::ecs::system::SystemParam;
use bevy::input::mouse::AccumulatedMouseScroll;
use bevy::prelude::*;
use bevy::window::PrimaryWindow;
use bevy_egui::egui::{self, Color32, Pos2, Rect, RichText, Sense, Stroke, pos2, vec2};

use super::orbit::{PointerInViewport, wheel_lines};
use super::state::MainCamera;
use super::viewport::viewport_logical;
use crate::dataset::SceneRegions;
use crate::lens::handles::{self, Handle};
use crate::lens::lattice::{lattice, round_spacing};
use crate::lens::sampling::MAX_CUSTOM_SAMPLES;
use crate::lens::systems::LensOrder;
use crate::lens::{Lens, LensKind, MAX_LENSES, Profile, ResolvedLens, Sampling, Screen, Shape, ViewLenses, local_magnification};

/// Pixels within which a rim grabs.
const GRAB_PIXELS: f32 = 6.0;

/// What a lattice was computed for: the view's lenses and the scene's bounding sphere.
type LatticeKey = (ViewLenses, (Vec3, f32));

/// The app's lens tools.
#[derive(Resource)]
pub struct LensUi {
    pub selected: Option<Entity>,
    /// The handle being dragged and the last pointer position (lens units).
    pub dragging: Option<(Entity, Handle, Vec2)>,
    /// The handle under the pointer.
    pub hover: Option<(Entity, Handle)>,
    /// Drawing an outline: `Some` once armed, holding the stroke (lens units).
    pub drawing: Option<Vec<Vec2>>,
    pub show_outlines: bool,
    pub show_lattice: bool,
    pub show_readout: bool,
    /// The lattice last computed, with what it was computed for.
    lattice: Option<(LatticeKey, Vec<[Vec2; 2]>)>,
    /// The view lenses with their silhouettes found on the CPU, for the overlays (the
    /// render finds them on the GPU), and the view lenses they were found for.
    on_cpu: Option<(ViewLenses, Vec<ResolvedLens>)>,
}

impl LensUi {
    /// The lenses of `view` with every silhouette known (cached until the view changes).
    fn overlay_lenses(&mut self, view: &ViewLenses, regions: &SceneRegions) -> Vec<ResolvedLens> {
        if !view.has_gpu_silhouettes() {
            return view.lenses.clone();
        }
        if let Some((key, lenses)) = &self.on_cpu
            && key == view
        {
            return lenses.clone();
        }
        let lenses = view.on_cpu(&regions.scene);
        self.on_cpu = Some((view.clone(), lenses.clone()));
        lenses
    }
}

impl Default for LensUi {
    fn default() -> Self {
        Self {
            selected: None,
            dragging: None,
            hover: None,
            drawing: None,
            show_outlines: true,
            show_lattice: false,
            show_readout: true,
            lattice: None,
            on_cpu: None,
        }
    }
}

/// The lens entities, their view and the commands to add and remove them.
#[derive(SystemParam)]
pub struct LensParams<'w, 's> {
    pub ui: ResMut<'w, LensUi>,
    pub lenses: Query<'w, 's, (Entity, &'static mut Lens, Option<&'static LensOrder>)>,
    pub views: Query<'w, 's, &'static ViewLenses, With<MainCamera>>,
    pub commands: Commands<'w, 's>,
}

impl LensParams<'_, '_> {
    /// The lenses in stack order (bottom first).
    pub fn ordered(&self) -> Vec<(Entity, Lens, u32)> {
        let mut v: Vec<_> = self.lenses.iter().map(|(e, l, o)| (e, l.clone(), o.map_or(u32::MAX, |o| o.0))).collect();
        v.sort_by_key(|(e, _, o)| (*o, *e));
        v
    }

    /// Adds a lens on top of the others and selects it.
    pub fn add(&mut self, lens: Lens) {
        let top = self.lenses.iter().filter_map(|(_, _, o)| o.map(|o| o.0)).max().map_or(0, |o| o + 1);
        let name = Name::new(format!("lens {}", lens.kind_name()));
        let e = self.commands.spawn((lens, LensOrder(top), name)).id();
        self.ui.selected = Some(e);
    }
}

/// The pointer in lens units, if it is over the viewport.
fn pointer_lens(camera: &Camera, window: &Window) -> Option<Vec2> {
    let (origin, size) = viewport_logical(camera, window);
    let p = window.cursor_position()? - origin;
    (p.x >= 0.0 && p.y >= 0.0 && p.x < size.x && p.y < size.y).then(|| Screen { width: size.x, height: size.y }.to_lens(p.x, p.y))
}

/// The topmost lens handle at `s`.
fn topmost_hit(lenses: &[(Entity, Lens, u32)], s: Vec2, tolerance: f32) -> Option<(Entity, Handle)> {
    lenses.iter().rev().filter(|(_, l, _)| l.enabled).find_map(|(e, l, _)| handles::hit(l, s, tolerance).map(|h| (*e, h)))
}

/// Viewport input for lenses; runs before the camera's so a lens press is not an orbit.
pub fn lens_input(
    buttons: Res<ButtonInput<MouseButton>>,
    scroll: Res<AccumulatedMouseScroll>,
    windows: Query<&Window, With<PrimaryWindow>>,
    cams: Query<&Camera, With<MainCamera>>,
    mut pointer: ResMut<PointerInViewport>,
    mut params: LensParams,
) {
    pointer.press_taken = false;
    pointer.wheel_taken = false;
    let (Ok(window), Ok(camera)) = (windows.single(), cams.single()) else { return };
    let s = if pointer.inside || params.ui.dragging.is_some() || params.ui.drawing.as_ref().is_some_and(|d| !d.is_empty()) {
        pointer_lens(camera, window)
    } else {
        None
    };
    let (_, size) = viewport_logical(camera, window);
    let tolerance = GRAB_PIXELS * 2.0 / size.y.max(1.0);
    let ordered = params.ordered();

    // Drawing an outline.
    if let Some(stroke) = params.ui.drawing.as_mut() {
        if let Some(s) = s {
            if buttons.just_pressed(MouseButton::Left) {
                stroke.clear();
                stroke.push(s);
                pointer.press_taken = true;
            } else if buttons.pressed(MouseButton::Left) && !stroke.is_empty() && stroke.last().is_some_and(|l| l.distance(s) > 0.004) {
                stroke.push(s);
            }
        }
        if buttons.just_released(MouseButton::Left) && !params.ui.drawing.as_ref().is_some_and(|d| d.is_empty()) {
            let stroke = params.ui.drawing.take().unwrap_or_default();
            if let Some((center, shape)) = handles::stroke_to_shape(&stroke) {
                let radius = shape.focus_radius(0.3);
                params.add(Lens { shape, center, radius, ..Lens::magnifier(center, radius, 0.12, 2.0) });
            }
        }
        return;
    }

    // Dragging a handle.
    if let Some((e, handle, last)) = params.ui.dragging {
        if !buttons.pressed(MouseButton::Left) {
            params.ui.dragging = None;
        } else if let Some(s) = s
            && s != last
            && let Ok((_, mut lens, _)) = params.lenses.get_mut(e)
        {
            handles::drag(&mut lens, handle, last, s);
            params.ui.dragging = Some((e, handle, s));
        }
        return;
    }

    let hover = s.and_then(|s| topmost_hit(&ordered, s, tolerance));
    params.ui.hover = hover;
    if let (Some(s), Some((e, handle))) = (s, hover) {
        if buttons.just_pressed(MouseButton::Left) {
            params.ui.dragging = Some((e, handle, s));
            params.ui.selected = Some(e);
            pointer.press_taken = true;
        }
        if scroll.delta.y != 0.0
            && let Ok((_, mut lens, _)) = params.lenses.get_mut(e)
        {
            handles::wheel(&mut lens, wheel_lines(&scroll));
            pointer.wheel_taken = true;
        }
    }
}

/// The Lenses panel: the list, the overlays, and the selected lens's settings.
pub fn panel(ui: &mut egui::Ui, params: &mut LensParams) {
    let ordered = params.ordered();
    ui.horizontal_wrapped(|ui| {
        let room = ordered.len() < MAX_LENSES;
        if ui.add_enabled(room, egui::Button::new("+ magnifier")).clicked() {
            params.add(Lens::magnifier(Vec2::ZERO, 0.3, 0.15, 2.0));
        }
        if ui.add_enabled(room, egui::Button::new("+ sampling")).clicked() {
            params.add(Lens { kind: LensKind::Sampling(Sampling::default()), ..Lens::magnifier(Vec2::ZERO, 0.4, 0.0, 1.0) });
        }
        if ui.add_enabled(room, egui::Button::new("+ fisheye")).clicked() {
            let kind = LensKind::Angular { field_of_view: 180.0, whole_view: false };
            params.add(Lens { kind, ..Lens::magnifier(Vec2::ZERO, 0.4, 0.0, 1.0) });
        }
        let drawing = params.ui.drawing.is_some();
        if ui
            .add_enabled(room || drawing, egui::Button::new("✏ draw").selected(drawing))
            .on_hover_text("drag an outline in the view")
            .clicked()
        {
            params.ui.drawing = if drawing { None } else { Some(Vec::new()) };
        }
    });
    if params.ui.drawing.is_some() {
        ui.label(RichText::new("Drag an outline in the view (Esc: cancel).").color(Color32::YELLOW));
    }
    if ordered.is_empty() {
        ui.label(RichText::new("No lens. Add one, then drag it in the view.").weak());
    }
    let mut remove = None;
    for (i, (e, lens, _)) in ordered.iter().enumerate() {
        ui.horizontal(|ui| {
            let mut enabled = lens.enabled;
            if ui.checkbox(&mut enabled, "").changed()
                && let Ok((_, mut l, _)) = params.lenses.get_mut(*e)
            {
                l.enabled = enabled;
            }
            let label = format!("{} {}", i + 1, lens.kind_name());
            if ui.selectable_label(params.ui.selected == Some(*e), label).clicked() {
                params.ui.selected = Some(*e);
            }
            if ui.small_button("🗑").on_hover_text("remove").clicked() {
                remove = Some(*e);
            }
        });
    }
    if let Some(e) = remove {
        params.commands.entity(e).despawn();
        if params.ui.selected == Some(e) {
            params.ui.selected = None;
        }
    }
    ui.horizontal_wrapped(|ui| {
        ui.checkbox(&mut params.ui.show_outlines, "outlines");
        ui.checkbox(&mut params.ui.show_lattice, "lattice");
        ui.checkbox(&mut params.ui.show_readout, "magnification at cursor");
    });
    let Some(selected) = params.ui.selected.filter(|e| remove != Some(*e)) else { return };
    let Ok((_, lens, _)) = params.lenses.get(selected) else { return };
    let mut edited = lens.clone();
    ui.separator();
    lens_settings(ui, &mut edited);
    if edited != *lens
        && edited.validate().is_ok()
        && let Ok((_, mut lens, _)) = params.lenses.get_mut(selected)
    {
        *lens = edited;
    }
}

/// The settings of one lens.
fn lens_settings(ui: &mut egui::Ui, lens: &mut Lens) {
    let kinds: [(&str, LensKind); 3] = [
        ("magnifier", LensKind::Magnifier { magnification: 2.0, profile: Profile::Cubic, focus_depth: None, plane_depth: None }),
        ("sampling", LensKind::Sampling(Sampling::default())),
        ("angular", LensKind::Angular { field_of_view: 180.0, whole_view: false }),
    ];
    egui::ComboBox::from_label("kind").selected_text(lens.kind_name()).show_ui(ui, |ui| {
        for (name, kind) in kinds {
            if ui.selectable_label(lens.kind_name() == name, name).clicked() && lens.kind_name() != name {
                if !matches!(kind, LensKind::Magnifier { .. }) && matches!(lens.shape, Shape::Polygon(_) | Shape::Feature(_)) {
                    lens.shape = Shape::Circle;
                }
                if matches!(kind, LensKind::Angular { .. }) {
                    lens.shape = Shape::Circle;
                }
                lens.kind = kind;
            }
        }
    });
    let shape_name = match lens.shape {
        Shape::Circle => "circle",
        Shape::Square => "square",
        Shape::Polygon(_) => "drawn",
        Shape::Feature(_) => "feature",
    };
    let magnifier = matches!(lens.kind, LensKind::Magnifier { .. });
    let square_ok = !matches!(lens.kind, LensKind::Angular { .. });
    egui::ComboBox::from_label("shape").selected_text(shape_name).show_ui(ui, |ui| {
        if ui.selectable_label(shape_name == "circle", "circle").clicked() {
            lens.shape = Shape::Circle;
        }
        if square_ok && ui.selectable_label(shape_name == "square", "square").clicked() {
            lens.shape = Shape::Square;
        }
        if magnifier && ui.selectable_label(shape_name == "feature", "feature (a label)").clicked() {
            lens.shape = Shape::Feature(crate::lens::feature::FeatureRef { label: 1, region: None });
        }
    });
    if let Shape::Feature(feature) = &mut lens.shape {
        ui.horizontal(|ui| {
            ui.label("label");
            ui.add(egui::DragValue::new(&mut feature.label).range(1..=65535));
            ui.label(RichText::new("of the first label volume shown").weak());
        });
    }
    if !matches!(lens.shape, Shape::Polygon(_) | Shape::Feature(_)) {
        ui.add(egui::Slider::new(&mut lens.radius, 0.02..=1.5).text("radius"));
    }
    match &mut lens.kind {
        LensKind::Magnifier { magnification, profile, focus_depth, plane_depth } => {
            ui.add(egui::Slider::new(&mut lens.border, 0.0..=1.0).text("border"));
            ui.add(egui::Slider::new(magnification, 1.0..=16.0).logarithmic(true).text("magnification"));
            egui::ComboBox::from_label("border profile").selected_text(profile.name()).show_ui(ui, |ui| {
                for p in Profile::ALL {
                    ui.selectable_value(profile, p, p.name());
                }
            });
            optional_depth(ui, focus_depth, "focus depth", "centre of the scene", 1.0);
            optional_depth(ui, plane_depth, "lens plane", "near the eye", 0.0);
        }
        LensKind::Sampling(sampling) => {
            let drawn = matches!(sampling, Sampling::Custom(_));
            ui.horizontal(|ui| {
                if ui.radio(!drawn, "cubic").clicked() && drawn {
                    *sampling = Sampling::default();
                }
                if ui.radio(drawn, "drawn").clicked() && !drawn {
                    *sampling = Sampling::Custom((0..16).map(|i| sampling.rate(i as f32 / 15.0)).collect());
                }
            });
            match sampling {
                Sampling::Cubic { center_rate } => {
                    ui.add(egui::Slider::new(center_rate, 1.0..=4.9).text("rate at the centre"));
                }
                Sampling::Custom(samples) => {
                    sampling_editor(ui, samples);
                }
            }
        }
        LensKind::Angular { field_of_view, whole_view } => {
            ui.add(egui::Slider::new(field_of_view, 10.0..=360.0).text("field of view °"));
            ui.checkbox(whole_view, "whole view");
        }
    }
}

/// A depth that is automatic (`None`) or set.
fn optional_depth(ui: &mut egui::Ui, depth: &mut Option<f32>, label: &str, auto: &str, initial: f32) {
    ui.horizontal(|ui| {
        let mut set = depth.is_some();
        if ui.checkbox(&mut set, label).changed() {
            *depth = set.then_some(initial.max(1.0) * 100.0);
        }
        match depth {
            Some(d) => {
                ui.add(egui::DragValue::new(d).speed(1.0).range(0.0..=1.0e6).suffix(" mm"));
            }
            None => {
                ui.label(RichText::new(auto).weak());
            }
        }
    });
}

/// The drawn sampling function: drag across the plot to set the rates (centre on the
/// left, rim on the right); the function is normalised so the lens keeps its rays.
fn sampling_editor(ui: &mut egui::Ui, samples: &mut Vec<f32>) {
    const TOP: f32 = 5.0;
    let width = ui.available_width().max(120.0);
    let (resp, painter) = ui.allocate_painter(vec2(width, 90.0), Sense::drag());
    let r = resp.rect;
    painter.rect_filled(r, 2.0, Color32::from_gray(18));
    let n = samples.len().max(2);
    let x_of = |i: usize| r.left() + r.width() * i as f32 / (n - 1) as f32;
    let y_of = |v: f32| r.bottom() - r.height() * (v / TOP).clamp(0.0, 1.0);
    painter.line_segment([pos2(r.left(), y_of(1.0)), pos2(r.right(), y_of(1.0))], Stroke::new(1.0, Color32::from_gray(60)));
    if let Some(p) = resp.interact_pointer_pos()
        && (resp.dragged() || resp.drag_started())
    {
        let i = (((p.x - r.left()) / r.width()) * (n - 1) as f32).round().clamp(0.0, (n - 1) as f32) as usize;
        if let Some(v) = samples.get_mut(i) {
            *v = (((r.bottom() - p.y) / r.height()) * TOP).clamp(0.05, TOP);
        }
    }
    let points: Vec<Pos2> = samples.iter().enumerate().map(|(i, v)| pos2(x_of(i), y_of(*v))).collect();
    painter.add(egui::Shape::line(points.clone(), Stroke::new(1.5, Color32::LIGHT_BLUE)));
    for p in points {
        painter.circle_filled(p, 2.5, Color32::LIGHT_BLUE);
    }
    ui.horizontal(|ui| {
        ui.label(RichText::new("centre → rim; rate 1 = grey line").weak().small());
        if samples.len() < MAX_CUSTOM_SAMPLES && ui.small_button("finer").clicked() {
            let old = samples.clone();
            let m = (old.len() * 2 - 1).min(MAX_CUSTOM_SAMPLES);
            *samples = (0..m).map(|i| Sampling::Custom(old.clone()).rate(i as f32 / (m - 1) as f32)).collect();
        }
    });
}

/// Draws the overlays in the viewport rectangle `free` (egui points): outlines,
/// lattice, the outline being drawn, and the magnification at the cursor.
pub fn overlay(ctx: &egui::Context, free: Rect, params: &mut LensParams, regions: &SceneRegions) {
    let painter = ctx.layer_painter(egui::LayerId::new(egui::Order::Foreground, egui::Id::new("lens_overlay"))).with_clip_rect(free);
    let screen = Screen { width: free.width().max(1.0), height: free.height().max(1.0) };
    let to_pos = |s: Vec2| {
        let (x, y) = screen.to_pixel(s);
        pos2(free.left() + x, free.top() + y)
    };
    let view = params.views.single().ok().cloned();

    if params.ui.show_lattice
        && let Some(view) = &view
        && let (Some(cam), Some(vs)) = (view.camera, view.screen)
    {
        let bounds = regions.scene.bounding_sphere();
        let fresh = params.ui.lattice.as_ref().is_none_or(|((v, b), _)| v != view || *b != bounds);
        if fresh {
            let (centre, radius) = bounds;
            let depth = (centre - cam.position).dot(cam.forward()).max(radius * 0.05);
            let view_height = match cam.projection {
                crate::region::Projection::Perspective { fov_y } => 2.0 * depth * (fov_y * 0.5).tan(),
                crate::region::Projection::Orthographic { height } => height,
            };
            let lenses = params.ui.overlay_lenses(view, regions);
            let segments = lattice(&cam, vs, &lenses, depth, round_spacing(view_height, 16.0), 6.0);
            params.ui.lattice = Some(((view.clone(), bounds), segments));
        }
        if let Some((_, segments)) = &params.ui.lattice {
            let k = free.height() / vs.height;
            let stroke = Stroke::new(1.0, Color32::from_rgba_unmultiplied(90, 220, 255, 150));
            for [a, b] in segments {
                painter.line_segment([free.min + egui::vec2(a.x, a.y) * k, free.min + egui::vec2(b.x, b.y) * k], stroke);
            }
        }
    }

    if params.ui.show_outlines {
        for (e, lens, _) in params.ordered() {
            // A whole-view fisheye has no outline; a feature lens's is its feature.
            if matches!(lens.kind, LensKind::Angular { whole_view: true, .. }) || matches!(lens.shape, Shape::Feature(_)) {
                continue;
            }
            let selected = params.ui.selected == Some(e);
            let hover = params.ui.hover.filter(|(h, _)| *h == e).map(|(_, h)| h);
            let base = if !lens.enabled {
                Color32::from_gray(110)
            } else if selected {
                Color32::from_rgb(255, 210, 60)
            } else {
                Color32::from_gray(225)
            };
            let (rim, outer) = handles::outlines(&lens);
            let width = |h: Handle| if hover == Some(h) { 2.5 } else { 1.2 };
            // A dark halo under each line keeps it visible over bright and dark data.
            let halo = |w: f32| Stroke::new(w + 2.0, Color32::from_black_alpha(140));
            let rim: Vec<Pos2> = rim.into_iter().map(to_pos).collect();
            painter.add(egui::Shape::closed_line(rim.clone(), halo(width(Handle::Rim))));
            painter.add(egui::Shape::closed_line(rim, Stroke::new(width(Handle::Rim), base)));
            if lens.border > 0.0 && matches!(lens.kind, LensKind::Magnifier { .. }) {
                let points = closed(outer.into_iter().map(to_pos).collect());
                painter.extend(egui::Shape::dashed_line(&points, halo(width(Handle::Border)), 6.0, 4.0));
                painter.extend(egui::Shape::dashed_line(&points, Stroke::new(width(Handle::Border), base), 6.0, 4.0));
            }
            if hover == Some(Handle::Centre) {
                painter.circle_stroke(to_pos(lens.center), 4.0, Stroke::new(1.5, base));
            }
        }
    }

    if let Some(stroke) = &params.ui.drawing
        && stroke.len() > 1
    {
        let points: Vec<Pos2> = stroke.iter().map(|s| to_pos(*s)).collect();
        painter.add(egui::Shape::line(points, Stroke::new(2.0, Color32::from_rgb(255, 150, 40))));
    }

    if params.ui.show_readout
        && let Some(view) = &view
        && !view.lenses.is_empty()
        && let (Some(cam), Some(vs), Some(p)) = (view.camera, view.screen, ctx.pointer_hover_pos())
        && free.contains(p)
    {
        let k = vs.height / free.height();
        let (px, py) = ((p.x - free.left()) * k, (p.y - free.top()) * k);
        let (centre, radius) = regions.scene.bounding_sphere();
        let depth = (centre - cam.position).dot(cam.forward()).max(radius * 0.05);
        let lenses = params.ui.overlay_lenses(view, regions);
        if let Some(m) = local_magnification(&cam, vs, &lenses, px, py, depth) {
            painter.text(
                p + vec2(14.0, 14.0),
                egui::Align2::LEFT_TOP,
                format!("×{m:.2}"),
                egui::FontId::monospace(13.0),
                Color32::from_rgb(255, 230, 120),
            );
        }
    }
}

/// A closed polyline (the first point repeated at the end).
fn closed(mut points: Vec<Pos2>) -> Vec<Pos2> {
    if let Some(first) = points.first().copied() {
        points.push(first);
    }
    points
}

/// Esc cancels drawing; Delete removes the selected lens.
pub fn lens_keys(keys: Res<ButtonInput<KeyCode>>, mut contexts: bevy_egui::EguiContexts, mut params: LensParams) {
    if contexts.ctx_mut().is_ok_and(|c| c.egui_wants_keyboard_input()) {
        return;
    }
    if keys.just_pressed(KeyCode::Escape) {
        params.ui.drawing = None;
    }
    if keys.just_pressed(KeyCode::Delete)
        && let Some(e) = params.ui.selected.take()
        && params.lenses.get(e).is_ok()
    {
        params.commands.entity(e).despawn();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_topmost_lens_takes_the_pointer() {
        let a = Entity::from_raw_u32(1).unwrap_or(Entity::PLACEHOLDER);
        let b = Entity::from_raw_u32(2).unwrap_or(Entity::PLACEHOLDER);
        let lower = Lens::magnifier(Vec2::ZERO, 0.3, 0.1, 2.0);
        let upper = Lens::magnifier(Vec2::new(0.2, 0.0), 0.3, 0.1, 2.0);
        let lenses = vec![(a, lower.clone(), 0), (b, upper, 1)];
        assert_eq!(topmost_hit(&lenses, Vec2::new(0.1, 0.0), 0.01), Some((b, Handle::Centre)));
        assert_eq!(topmost_hit(&lenses, Vec2::new(-0.25, 0.0), 0.01), Some((a, Handle::Centre)));
        // The upper lens's border ring is grabbed before the lower lens's focus.
        assert_eq!(topmost_hit(&lenses, Vec2::new(-0.2, 0.0), 0.01), Some((b, Handle::Border)));
        // A disabled lens is not grabbed.
        let lenses = vec![(a, Lens { enabled: false, ..lower }, 0)];
        assert_eq!(topmost_hit(&lenses, Vec2::ZERO, 0.01), None);
    }
}
