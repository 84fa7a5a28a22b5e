//! The exploded view's panel and viewport tools (Bruckner and Gröller 2006).
//!
//! The panel (View → Exploded view, or E) edits the selected dataset: explode it around
//! a selection (labels of a label dataset, or a value range) in a grid of parts; the
//! degree of explosion (the main control), the viewing force, the δ of equation 5; the
//! splitters (axis, depth, line) as viewport tools; undo; each part's visibility, fixed
//! state, density and group; joints (pick an anchor on a part in the viewport, choose the
//! kind, the other end and the axis, add); the selection's smoothing and brush
//! ([`super::explode_selection`]). Edits go through
//! [`crate::explode::edit::ExplodeEdits`].

use bevy::prelude::*;
use bevy::window::PrimaryWindow;
use bevy_egui::EguiContexts;
use bevy_egui::egui;

use super::explode_selection::{brush_overlay, selection_section};
use super::explode_tools::{AxisChoice, ExplodeUi, Tool};
use super::orbit::{OrbitCamera, PointerInViewport};
use super::state::{AppState, MainCamera};
use super::viewport::viewport_logical;
use crate::dataset::Dataset;
use crate::explode::edit::{Edit, ExplodeEdits, SplitHistory, Splitter};
use crate::explode::paint::Brush;
use crate::explode::spec::ExplodeSource;
use crate::explode::spec::{ExplodeSpec, PartsSpec, SelectionSpec};
use crate::explode::splitters::ScreenAxis;
use crate::explode::{Exploded, JointKind, Part, PartJoint};

/// Viewport input of the explode tools (after the lenses', before the camera's).
// A Bevy system: its parameters are the resources and queries it uses, and a query's
// type names the components it reads; splitting them up would only hide that.
#[allow(clippy::too_many_arguments)]
pub fn explode_input(
    buttons: Res<ButtonInput<MouseButton>>,
    keys: Res<ButtonInput<KeyCode>>,
    primary: Query<&Window, With<PrimaryWindow>>,
    cams: Query<(&Camera, &OrbitCamera), With<MainCamera>>,
    mut pointer: ResMut<PointerInViewport>,
    mut ui: ResMut<ExplodeUi>,
    mut edits: ResMut<ExplodeEdits>,
    state: Res<AppState>,
    datasets: Query<Entity, With<Dataset>>,
) {
    if ui.tool == Tool::None || !state.show_explode {
        ui.line_start = None;
        return;
    }
    if keys.just_pressed(KeyCode::Escape) {
        ui.tool = Tool::None;
        return;
    }
    let (Ok(window), Ok((camera, orbit))) = (primary.single(), cams.single()) else { return };
    let Some(cursor) = window.cursor_position() else { return };
    let mut sorted: Vec<Entity> = datasets.iter().collect();
    sorted.sort();
    let Some(&dataset) = sorted.get(state.selected) else { return };
    let (origin, size) = viewport_logical(camera, window);
    let p = cursor - origin;
    let (w, h) = (size.x.max(1.0) as u32, size.y.max(1.0) as u32);
    let cam = orbit.camera();
    let ray = cam.ray(p.x, p.y, w, h);
    if pointer.inside && !pointer.press_taken && buttons.just_pressed(MouseButton::Left) {
        pointer.press_taken = true;
        let splitter = match ui.tool {
            Tool::Axis(axis) => Some(Splitter::Axis { camera: cam, ray, axis }),
            Tool::Depth => Some(Splitter::Depth { camera: cam, ray }),
            Tool::Line => {
                ui.line_start = Some(p);
                None
            }
            Tool::Anchor => {
                edits.queue.push(Edit::Pick { dataset, ray });
                None
            }
            Tool::Paint => {
                edits.queue.push(Edit::Paint { dataset, ray, brush: brush(&ui, &keys), new_stroke: true });
                ui.last_dab = Some(p);
                None
            }
            Tool::None => None,
        };
        if let Some(splitter) = splitter {
            edits.queue.push(Edit::Split { dataset, splitter });
        }
    }
    if ui.tool == Tool::Paint && buttons.pressed(MouseButton::Left) && !buttons.just_pressed(MouseButton::Left) {
        // A dab every few pixels of the drag, in the same stroke.
        pointer.press_taken = true;
        if ui.last_dab.is_some_and(|last| last.distance(p) >= DAB_SPACING) {
            edits.queue.push(Edit::Paint { dataset, ray, brush: brush(&ui, &keys), new_stroke: false });
            ui.last_dab = Some(p);
        }
    }
    if buttons.just_released(MouseButton::Left) {
        ui.last_dab = None;
    }
    if ui.tool == Tool::Line && buttons.pressed(MouseButton::Left) && ui.line_start.is_some() {
        // The segment is the tool's, not the camera's.
        pointer.press_taken = true;
    }
    if ui.tool == Tool::Line
        && buttons.just_released(MouseButton::Left)
        && let Some(a) = ui.line_start.take()
    {
        edits.queue.push(Edit::Split { dataset, splitter: Splitter::Line { camera: cam, a, b: p, size: UVec2::new(w, h) } });
    }
}

/// Viewport pixels between two dabs of a drag.
const DAB_SPACING: f32 = 4.0;

/// The brush as set in the panel, erasing instead of adding while Shift is held.
fn brush(ui: &ExplodeUi, keys: &ButtonInput<KeyCode>) -> Brush {
    let shift = keys.any_pressed([KeyCode::ShiftLeft, KeyCode::ShiftRight]);
    Brush { erase: ui.brush.erase != shift, ..ui.brush }
}

/// Draws the segment being drawn with the line splitter.
fn line_overlay(ctx: &egui::Context, ui: &ExplodeUi, origin: Vec2, cursor: Option<Vec2>) {
    let (Some(a), Some(b)) = (ui.line_start, cursor) else { return };
    let painter = ctx.layer_painter(egui::LayerId::new(egui::Order::Foreground, egui::Id::new("explode_line")));
    let at = |v: Vec2| egui::pos2(v.x + origin.x, v.y + origin.y);
    painter.line_segment([at(a), at(b - origin)], egui::Stroke::new(2.0, egui::Color32::from_rgb(255, 200, 60)));
}

/// The part entities of `dataset`, in entity order (the order scene files list them).
fn parts_of(parts: &Query<(Entity, &mut Part)>, dataset: Entity) -> Vec<Entity> {
    let mut v: Vec<Entity> = parts.iter().filter(|(_, p)| p.dataset == dataset).map(|(e, _)| e).collect();
    v.sort();
    v
}

/// The panel.
// A Bevy system: its parameters are the resources and queries it uses, and a query's
// type names the components it reads; splitting them up would only hide that.
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub fn explode_panel(
    mut contexts: EguiContexts,
    mut state: ResMut<AppState>,
    mut ui_state: ResMut<ExplodeUi>,
    mut edits: ResMut<ExplodeEdits>,
    datasets: Query<(Entity, &Dataset, Option<&SplitHistory>)>,
    mut exploded: Query<&mut Exploded>,
    mut parts: Query<(Entity, &mut Part)>,
    joints: Query<(Entity, &PartJoint)>,
    cams: Query<(&OrbitCamera, &Camera), With<MainCamera>>,
    primary: Query<&Window, With<PrimaryWindow>>,
    sources: Query<&ExplodeSource>,
    mut commands: Commands,
) -> Result {
    if !state.show_explode {
        return Ok(());
    }
    let ctx = contexts.ctx_mut()?.clone();
    if let (Ok(window), Ok((orbit, camera))) = (primary.single(), cams.single()) {
        let (origin, size) = viewport_logical(camera, window);
        line_overlay(&ctx, &ui_state, origin, window.cursor_position());
        brush_overlay(&ctx, &ui_state, orbit, size, window.cursor_position());
    }
    let mut sorted: Vec<(Entity, &Dataset, Option<&SplitHistory>)> = datasets.iter().collect();
    sorted.sort_by_key(|d| d.0);
    let Some(&(dataset, data, history)) = sorted.get(state.selected) else { return Ok(()) };
    let view = cams.single().map(|(o, _)| o.camera()).ok();
    let mut open = true;
    let right = ctx.viewport_rect().right();
    egui::Window::new("Exploded view").open(&mut open).default_width(300.0).default_pos(egui::pos2(right - 330.0, 40.0)).show(&ctx, |ui| {
        ui.label(egui::RichText::new(&data.volume.name).strong());
        if let Some(e) = &edits.error {
            ui.colored_label(egui::Color32::from_rgb(255, 120, 100), e);
        }
        match exploded.get_mut(dataset) {
            Err(_) => explode_form(ui, &mut ui_state, &mut edits, dataset, &sorted),
            Ok(mut x) => {
                ui.add(egui::Slider::new(&mut x.coefficients.degree, 0.0..=16.0).text("degree of explosion"));
                ui.checkbox(&mut x.viewing, "viewing force (parts leave the lines of sight)");
                ui.add_enabled(x.viewing, egui::Checkbox::new(&mut x.fade, "parts in the way fade (figure 9)"));
                egui::CollapsingHeader::new("Advanced (δ of equation 5)").show(ui, |ui| {
                    ui.add(egui::Slider::new(&mut x.coefficients.delta_explosion, 0.0..=2.0).text("δ explosion"));
                    ui.add(egui::Slider::new(&mut x.coefficients.delta_viewing, 0.0..=2.0).text("δ viewing"));
                    ui.add(egui::Slider::new(&mut x.coefficients.delta_spacing, 0.0..=2.0).text("δ spacing"));
                });
                if let Ok(source) = sources.get(dataset) {
                    selection_section(ui, &mut ui_state, &mut edits, dataset, source);
                }
                ui.separator();
                ui.label("Split (click a part; line: drag across parts; Esc: stop)");
                ui.horizontal_wrapped(|ui| {
                    let t = &mut ui_state.tool;
                    ui.selectable_value(t, Tool::None, "off");
                    ui.selectable_value(t, Tool::Axis(ScreenAxis::Vertical), "axis |");
                    ui.selectable_value(t, Tool::Axis(ScreenAxis::Horizontal), "axis —");
                    ui.selectable_value(t, Tool::Depth, "depth");
                    ui.selectable_value(t, Tool::Line, "line");
                });
                ui.horizontal(|ui| {
                    let n = history.map_or(0, |h| h.len());
                    if ui.add_enabled(n > 0, egui::Button::new(format!("Undo split ({n})"))).clicked() {
                        edits.queue.push(Edit::Undo { dataset });
                    }
                    if ui.button("Un-explode").clicked() {
                        edits.queue.push(Edit::Unexplode { dataset });
                    }
                });
                let list = parts_of(&parts, dataset);
                parts_list(ui, &mut parts, &list);
                joints_form(ui, &mut ui_state, &mut edits, &joints, &list, view.as_ref(), &mut commands);
            }
        }
    });
    if !open {
        state.show_explode = false;
    }
    Ok(())
}

/// The form that explodes a dataset.
fn explode_form(
    ui: &mut egui::Ui,
    s: &mut ExplodeUi,
    edits: &mut ExplodeEdits,
    dataset: Entity,
    datasets: &[(Entity, &Dataset, Option<&SplitHistory>)],
) {
    ui.label("Selection (the focus):");
    ui.horizontal(|ui| {
        ui.radio_value(&mut s.use_labels, true, "labels");
        ui.radio_value(&mut s.use_labels, false, "value range");
    });
    if s.use_labels {
        let label_sets: Vec<(usize, &Dataset)> =
            datasets.iter().enumerate().filter(|(_, d)| d.1.labels.is_some()).map(|(i, d)| (i, d.1)).collect();
        if label_sets.is_empty() {
            ui.label("(no label dataset loaded: use a value range)");
        }
        if !label_sets.iter().any(|(i, _)| *i == s.label_dataset)
            && let Some((i, _)) = label_sets.first()
        {
            s.label_dataset = *i;
        }
        egui::ComboBox::from_label("label dataset")
            .selected_text(label_sets.iter().find(|(i, _)| *i == s.label_dataset).map_or("—".to_string(), |(_, d)| d.volume.name.clone()))
            .show_ui(ui, |ui| {
                for (i, d) in &label_sets {
                    ui.selectable_value(&mut s.label_dataset, *i, &d.volume.name);
                }
            });
        if let Some((_, d)) = label_sets.iter().find(|(i, _)| *i == s.label_dataset)
            && let Some(table) = &d.labels
        {
            egui::ScrollArea::vertical().max_height(160.0).show(ui, |ui| {
                for (id, label) in &table.labels {
                    let mut on = s.label_ids.contains(id);
                    if ui.checkbox(&mut on, format!("{id} {}", label.name)).changed() {
                        if on {
                            s.label_ids.insert(*id);
                        } else {
                            s.label_ids.remove(id);
                        }
                    }
                }
            });
        }
    } else {
        ui.horizontal(|ui| {
            ui.add(egui::DragValue::new(&mut s.range.0).prefix("from "));
            ui.add(egui::DragValue::new(&mut s.range.1).prefix("to "));
        });
    }
    ui.horizontal(|ui| {
        ui.label("parts");
        for n in [&mut s.grid.0, &mut s.grid.1, &mut s.grid.2] {
            ui.add(egui::DragValue::new(n).range(1..=8));
        }
    });
    if ui.button("Explode").clicked() {
        let selection = if s.use_labels {
            SelectionSpec::Labels { dataset: s.label_dataset, ids: s.label_ids.iter().copied().collect() }
        } else {
            SelectionSpec::Range { lo: s.range.0, hi: s.range.1 }
        };
        let spec = ExplodeSpec { parts: PartsSpec::Grid(s.grid), degree: 1.0, ..ExplodeSpec::around(selection) };
        edits.queue.push(Edit::Explode { dataset, spec: Box::new(spec) });
    }
}

/// Each part's visibility, fixed state, density and group.
fn parts_list(ui: &mut egui::Ui, parts: &mut Query<(Entity, &mut Part)>, list: &[Entity]) {
    egui::CollapsingHeader::new(format!("Parts ({})", list.len())).default_open(true).show(ui, |ui| {
        egui::Grid::new("explode_parts").striped(true).show(ui, |ui| {
            ui.label("part");
            ui.label("shown");
            ui.label("fixed");
            ui.label("density");
            ui.label("group");
            ui.end_row();
            for (i, e) in list.iter().enumerate() {
                let Ok((_, mut p)) = parts.get_mut(*e) else { continue };
                ui.label(i.to_string());
                let mut shown = !p.hidden;
                if ui.checkbox(&mut shown, "").changed() {
                    p.hidden = !shown;
                }
                let mut fixed = p.fixed;
                if ui.checkbox(&mut fixed, "").changed() {
                    p.fixed = fixed;
                }
                let mut density = p.density;
                if ui.add(egui::DragValue::new(&mut density).range(0.05..=100.0).speed(0.05)).changed() {
                    p.density = density;
                }
                let mut group = p.group.map_or(0, |g| g + 1);
                if ui.add(egui::DragValue::new(&mut group).range(0..=16)).on_hover_text("0: on its own").changed() {
                    p.group = group.checked_sub(1);
                }
                ui.end_row();
            }
        });
    });
}

/// The joints of the parts in `list`, and a form that adds one at the picked anchor.
fn joints_form(
    ui: &mut egui::Ui,
    s: &mut ExplodeUi,
    edits: &mut ExplodeEdits,
    joints: &Query<(Entity, &PartJoint)>,
    list: &[Entity],
    view: Option<&crate::region::Camera>,
    commands: &mut Commands,
) {
    let index = |e: Entity| list.iter().position(|p| *p == e);
    egui::CollapsingHeader::new("Joints").default_open(true).show(ui, |ui| {
        for (e, j) in joints.iter() {
            let (Some(part), to) = (index(j.part), j.to.map(index)) else { continue };
            if j.kind == JointKind::Fixed {
                continue;
            }
            ui.horizontal(|ui| {
                let other = match to {
                    None => "world".to_string(),
                    Some(Some(t)) => format!("part {t}"),
                    Some(None) => "?".to_string(),
                };
                ui.label(format!("{} part {part} – {other}", j.kind.name()));
                if ui.small_button("remove").clicked() {
                    commands.entity(e).despawn();
                }
            });
        }
        ui.separator();
        ui.horizontal(|ui| {
            ui.selectable_value(&mut s.tool, Tool::Anchor, "pick anchor");
            match edits.picked.filter(|p| list.contains(&p.part)) {
                Some(p) => ui.label(format!("part {} at ({:.0}, {:.0}, {:.0})", index(p.part).unwrap_or(0), p.rest.x, p.rest.y, p.rest.z)),
                None => ui.label("click a part in the view"),
            };
        });
        egui::ComboBox::from_label("kind").selected_text(s.joint_kind.name()).show_ui(ui, |ui| {
            for k in JointKind::ALL {
                ui.selectable_value(&mut s.joint_kind, k, k.name());
            }
        });
        egui::ComboBox::from_label("to").selected_text(s.joint_to.map_or("the world".to_string(), |t| format!("part {t}"))).show_ui(
            ui,
            |ui| {
                ui.selectable_value(&mut s.joint_to, None, "the world");
                for i in 0..list.len() {
                    ui.selectable_value(&mut s.joint_to, Some(i), format!("part {i}"));
                }
            },
        );
        egui::ComboBox::from_label("axis").selected_text(format!("{:?}", s.joint_axis)).show_ui(ui, |ui| {
            for a in
                [AxisChoice::ScreenVertical, AxisChoice::ScreenHorizontal, AxisChoice::View, AxisChoice::X, AxisChoice::Y, AxisChoice::Z]
            {
                ui.selectable_value(&mut s.joint_axis, a, format!("{a:?}"));
            }
        });
        let mut limited = s.joint_limits.is_some();
        ui.horizontal(|ui| {
            ui.checkbox(&mut limited, if s.joint_kind.angular() { "limits (°)" } else { "limits (mm)" });
            if limited {
                let l = s.joint_limits.get_or_insert((-90.0, 90.0));
                ui.add(egui::DragValue::new(&mut l.0));
                ui.add(egui::DragValue::new(&mut l.1));
            } else {
                s.joint_limits = None;
            }
        });
        let picked = edits.picked.filter(|p| list.contains(&p.part));
        if ui.add_enabled(picked.is_some(), egui::Button::new("Add joint")).clicked()
            && let Some(p) = picked
        {
            // Screen axes are carried from the world into the part's rest frame; the
            // dataset's axes are the rest frame's.
            let on_screen = |v: Vec3| p.to_world.inverse().transform_vector3(v);
            let axis = match (s.joint_axis, view) {
                (AxisChoice::View, Some(c)) => on_screen(c.forward()),
                (AxisChoice::ScreenHorizontal, Some(c)) => on_screen(c.right()),
                (AxisChoice::ScreenVertical, Some(c)) => on_screen(c.up()),
                (AxisChoice::X, _) => Vec3::X,
                (AxisChoice::Y, _) => Vec3::Y,
                _ => Vec3::Z,
            }
            .normalize_or(Vec3::Z);
            let to = s.joint_to.and_then(|i| list.get(i).copied()).filter(|t| *t != p.part);
            let mut joint = PartJoint::new(s.joint_kind, p.part, to, p.rest, axis);
            joint.limits = s.joint_limits;
            commands.spawn(joint);
            s.tool = Tool::None;
        }
    });
}
