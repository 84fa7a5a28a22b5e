//! The Volumetric windows panel: add a lens window, a clip box, a magnifier (a source
//! box with its window beside it) or a world-in-miniature fixed to the view; per
//! window: clip, fit, orientation coupling, attachment (room, user, dataset), size,
//! which datasets it shows, remove.

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bevy_egui::egui::{self, RichText, Ui};

use super::orbit::OrbitCamera;
use super::state::MainCamera;
use crate::dataset::Dataset;
use crate::region::Appearance;
use crate::windows::markers::Marker;
use crate::windows::spec::{WindowScene, marker_spec, window_spec};
use crate::windows::systems::WindowFocus;
use crate::windows::{Attachment, Automation, Content, Fit, Orientation, Pointer3d, Source, SourceBox, VolumeWindow};

/// The window entities and the commands to add and remove them.
#[derive(SystemParam)]
pub struct WindowParams<'w, 's> {
    // A query's type names the components it reads and the ones it excludes; an alias
    // would only hide that.
    #[allow(clippy::type_complexity)]
    pub windows: Query<'w, 's, (Entity, &'static mut VolumeWindow, &'static GlobalTransform), (Without<Dataset>, Without<MainCamera>)>,
    pub sources: Query<'w, 's, (&'static SourceBox, &'static GlobalTransform)>,
    pub commands: Commands<'w, 's>,
    pub markers: Query<'w, 's, &'static Marker>,
    pub pointer: Query<'w, 's, &'static GlobalTransform, With<Pointer3d>>,
    pub focus: ResMut<'w, WindowFocus>,
    pub tools: ResMut<'w, super::window_tools::WindowTools>,
}

impl WindowParams<'_, '_> {
    /// The windows, the 3D pointer and the markers as saved; `datasets` are the saved
    /// datasets' entities in order.
    pub fn specs(&self, datasets: &[Entity]) -> WindowScene {
        let mut list: Vec<_> = self.windows.iter().collect();
        list.sort_by_key(|(e, ..)| *e);
        let order: Vec<Entity> = list.iter().map(|(e, ..)| *e).collect();
        let index = |e: Entity| datasets.iter().position(|d| *d == e);
        let windows = list
            .iter()
            .map(|(_, w, g)| {
                window_spec(
                    w,
                    g.compute_transform(),
                    index,
                    |b| self.sources.get(b).ok().map(|(s, g)| (g.compute_transform(), s.size)),
                    &order,
                )
            })
            .collect();
        let pointer = self.pointer.iter().next().map(|g| g.translation().into());
        let markers = self.markers.iter().filter_map(|m| marker_spec(m, index)).collect();
        WindowScene { windows, pointer, markers }
    }
}

/// A loaded dataset as the panel needs it.
pub struct DatasetRow {
    pub entity: Entity,
    pub name: String,
    pub appearance: Appearance,
    pub transform: Transform,
}

/// The panel. `selected` is the dataset new windows show; `extent` the scene's size.
pub fn panel(ui: &mut Ui, p: &mut WindowParams, datasets: &[DatasetRow], selected: usize, orbit: &OrbitCamera, extent: f32) {
    let content =
        datasets.get(selected).map(|d| vec![Content { dataset: d.entity, appearance: Some(d.appearance.clone()) }]).unwrap_or_default();
    let cam = orbit.camera();
    let at = orbit.target;
    ui.horizontal_wrapped(|ui| {
        if ui.button("lens").on_hover_text("a window showing the data in place, with its own look").clicked() {
            p.commands.spawn((VolumeWindow::new(Vec3::splat(extent / 3.0), content.clone()), Transform::from_translation(at)));
        }
        if ui.button("clip box").on_hover_text("cuts the view away inside itself").clicked() {
            p.commands.spawn((
                VolumeWindow { clip: true, ..VolumeWindow::new(Vec3::splat(extent / 3.0), vec![]) },
                Transform::from_translation(at),
            ));
        }
        if ui.button("magnifier").on_hover_text("a source box at the centre, its window (×2) beside the data").clicked() {
            let source = p.commands.spawn((SourceBox { size: Vec3::splat(extent / 8.0) }, Transform::from_translation(at))).id();
            let w = VolumeWindow { source: Source::Box(source), ..VolumeWindow::new(Vec3::splat(extent / 4.0), content.clone()) };
            p.commands.spawn((w, Transform::from_translation(at + cam.right() * extent * 0.7)));
        }
        if ui.button("world-in-miniature").on_hover_text("the whole data, small, fixed in the view's corner").clicked() {
            let d = orbit.distance;
            let offset = Transform::from_xyz(0.12 * d, 0.09 * d, -0.45 * d);
            let all = datasets.iter().map(|d| Content { dataset: d.entity, appearance: None }).collect();
            let w = VolumeWindow {
                attachment: Attachment::User { offset },
                automation: Automation { fit: Some(Fit::Uniform), orientation: Orientation::MainView },
                ..VolumeWindow::new(Vec3::splat(0.08 * d), all)
            };
            p.commands.spawn((w, Transform::default()));
        }
    });
    ui.checkbox(&mut p.tools.pointer_tool, "3D pointer (T)").on_hover_text(
        "the pointer follows the cursor at its depth; wheel: depth, G: onto the surface under the cursor, Space: marker, Shift+Space: move the nearest marker here, Backspace: delete it",
    );
    let viewer = orbit.bevy().0;
    let focus = &mut p.focus;
    let mut list: Vec<_> = p.windows.iter_mut().collect();
    list.sort_by_key(|(e, ..)| *e);
    ui.separator();
    // The focus: hover a window (or reach into it with the 3D pointer) or pick it here.
    ui.horizontal_wrapped(|ui| {
        ui.label("focus");
        if ui.selectable_label(focus.0.is_none(), "main view").clicked() {
            focus.0 = None;
        }
        for (k, (entity, ..)) in list.iter().enumerate() {
            if ui.selectable_label(focus.0 == Some(*entity), format!("window {}", k + 1)).clicked() {
                focus.0 = Some(*entity);
            }
        }
    });
    let mut remove = None;
    for (k, (entity, w, global)) in list.iter_mut().enumerate() {
        if focus.0 != Some(*entity) {
            continue;
        }
        ui.label(RichText::new(format!("window {}: the panels edit its look", k + 1)).strong());
        if window_settings(ui, w, global, viewer, datasets, extent) {
            remove = Some((*entity, w.source));
        }
    }
    if focus.0.is_none() && !list.is_empty() {
        ui.label(RichText::new("hover a window to edit it (right-click it: its menu)").small());
    }
    if let Some((e, source)) = remove {
        despawn_window(&mut p.commands, e, source);
        focus.0 = None;
    }
}

/// The focused window's number (1-based, entity order) and its look of `dataset`, when
/// it shows that dataset (the dataset's own look until the window has its own).
pub fn focused_look(p: &WindowParams, dataset: Entity, own_look: &Appearance) -> Option<(usize, Appearance)> {
    let focused = p.focus.0?;
    let (_, w, _) = p.windows.get(focused).ok()?;
    let content = w.contents.iter().find(|c| c.dataset == dataset)?;
    let mut order: Vec<Entity> = p.windows.iter().map(|(e, ..)| e).collect();
    order.sort();
    let number = order.iter().position(|e| *e == focused)? + 1;
    Some((number, content.appearance.clone().unwrap_or_else(|| own_look.clone())))
}

/// Gives the focused window its own look of `dataset`.
pub fn set_focused_look(p: &mut WindowParams, dataset: Entity, look: Appearance) {
    let Some(focused) = p.focus.0 else { return };
    if let Ok((_, mut w, _)) = p.windows.get_mut(focused)
        && let Some(c) = w.contents.iter_mut().find(|c| c.dataset == dataset)
    {
        c.appearance = Some(look);
    }
}

/// Removes a window and its source box.
pub fn despawn_window(commands: &mut Commands, e: Entity, source: Source) {
    commands.entity(e).despawn();
    if let Source::Box(b) = source {
        commands.entity(b).despawn();
    }
}

/// The parameters of one window (the panel shows the focused window's, its menu in the
/// viewport the same); true when "remove" was clicked. `viewer`: the camera's pose.
pub fn window_settings(
    ui: &mut Ui,
    w: &mut Mut<VolumeWindow>,
    global: &GlobalTransform,
    viewer: Transform,
    datasets: &[DatasetRow],
    extent: f32,
) -> bool {
    let mut remove = false;
    ui.horizontal(|ui| {
        ui.checkbox(&mut w.clip, "clip");
        let mut fit = w.automation.fit.is_some();
        if ui.checkbox(&mut fit, "fit").changed() {
            w.automation.fit = fit.then_some(Fit::Uniform);
        }
        let mut coupled = w.automation.orientation == Orientation::MainView;
        if ui.checkbox(&mut coupled, "keep view orientation").changed() {
            w.automation.orientation = if coupled { Orientation::MainView } else { Orientation::Free };
        }
        remove = ui.small_button("✖ remove").clicked();
    });
    // Attachment: the window stays where it is, its offset taken in the new frame.
    let here = global.compute_transform();
    let current = match w.attachment {
        Attachment::Room => 0,
        Attachment::User { .. } => 1,
        Attachment::Dataset { .. } => 2,
    };
    let mut chosen = current;
    ui.horizontal(|ui| {
        ui.label("fixed to");
        ui.radio_value(&mut chosen, 0, "room");
        ui.radio_value(&mut chosen, 1, "view");
        ui.radio_value(&mut chosen, 2, "data");
    });
    if chosen != current {
        let first = w.contents.first().map(|c| c.dataset).or(datasets.first().map(|d| d.entity));
        let frame_of = |e: Entity| datasets.iter().find(|d| d.entity == e).map(|d| d.transform);
        w.attachment = match (chosen, first.and_then(|e| frame_of(e).map(|t| (e, t)))) {
            (1, _) => Attachment::User { offset: relative(viewer, here) },
            (2, Some((dataset, t))) => Attachment::Dataset { dataset, offset: relative(t, here) },
            _ => Attachment::Room,
        };
    }
    let mut scale = w.size.max_element();
    if ui.add(egui::Slider::new(&mut scale, 1.0..=extent.max(2.0)).logarithmic(true).text("size (mm)")).changed() {
        let old = w.size.max_element().max(1e-3);
        w.size *= scale / old;
    }
    ui.horizontal_wrapped(|ui| {
        ui.label("shows");
        for d in datasets {
            let mut on = w.contents.iter().any(|c| c.dataset == d.entity);
            if ui.checkbox(&mut on, &d.name).changed() {
                if on {
                    w.contents.push(Content { dataset: d.entity, appearance: None });
                } else {
                    w.contents.retain(|c| c.dataset != d.entity);
                }
            }
        }
    });
    remove
}

/// `child`'s pose in the frame of `parent`.
fn relative(parent: Transform, child: Transform) -> Transform {
    Transform::from_matrix(Mat4::from(parent.compute_affine().inverse() * child.compute_affine()))
}
