//! The clip-plane gizmo in the viewport: where each enabled clip plane of the selected
//! dataset cuts the dataset's box is drawn over the view, with a handle at its centre;
//! drag the handle to move the plane along its normal (the camera does not move with
//! it). The geometry is `crate::clip::gizmo`.

use bevy::prelude::*;
use bevy::window::PrimaryWindow;
use bevy_egui::egui::{self, Color32, Rect, Stroke, pos2};

use super::orbit::{OrbitCamera, PointerInViewport};
use super::state::{AppState, MainCamera};
use super::viewport::viewport_logical;
use crate::clip::gizmo::{box_section, drag_along_normal};
use crate::dataset::Dataset;

/// Pixels within which a handle grabs.
const GRAB_PIXELS: f32 = 9.0;

/// What the gizmo remembers between frames.
#[derive(Resource, Default)]
pub struct ClipGizmo {
    /// The plane being dragged (dataset, plane index) and the last pointer position.
    dragging: Option<(Entity, usize, Vec2)>,
    /// The handle under the pointer.
    hover: Option<(Entity, usize)>,
}

/// One plane on the screen (viewport pixels from the top left).
struct OnScreen {
    index: usize,
    outline: Vec<Vec2>,
    handle: Vec2,
    /// Pixels one millimetre along the plane's normal moves on the screen.
    per_mm: Vec2,
}

/// The enabled planes of `dataset` as seen by `camera` in a viewport of `size`.
fn on_screen(dataset: &Dataset, transform: &Transform, camera: &crate::region::Camera, size: Vec2) -> Vec<OnScreen> {
    let (lo, hi) = dataset.volume.grid.world_bounds();
    let to_world = transform.compute_affine();
    let pixel = |p: Vec3| camera.to_pixel(to_world.transform_point3(p), size.x, size.y);
    dataset
        .clip
        .planes
        .iter()
        .enumerate()
        .filter(|(_, p)| p.enabled)
        .filter_map(|(index, p)| {
            let section = box_section(&p.plane(), lo, hi);
            if section.is_empty() {
                return None;
            }
            let centre = section.iter().copied().sum::<Vec3>() / section.len() as f32;
            let outline = section.iter().map(|&q| pixel(q)).collect::<Option<Vec<Vec2>>>()?;
            let handle = pixel(centre)?;
            let per_mm = pixel(centre + p.normal.normalize_or(Vec3::Z))? - handle;
            Some(OnScreen { index, outline, handle, per_mm })
        })
        .collect()
}

/// The selected dataset (the panels' order: by entity).
fn selected<'a>(
    datasets: &'a mut Query<(Entity, &mut Dataset, &Transform)>,
    state: &AppState,
) -> Option<(Entity, Mut<'a, Dataset>, &'a Transform)> {
    let mut all: Vec<_> = datasets.iter_mut().collect();
    all.sort_by_key(|(e, ..)| *e);
    let i = state.selected.min(all.len().saturating_sub(1));
    all.into_iter().nth(i)
}

/// Viewport input for the gizmo; runs after the lenses' and before the camera's.
pub fn clip_input(
    buttons: Res<ButtonInput<MouseButton>>,
    windows: Query<&Window, With<PrimaryWindow>>,
    cams: Query<(&Camera, &OrbitCamera), With<MainCamera>>,
    state: Res<AppState>,
    mut pointer: ResMut<PointerInViewport>,
    mut gizmo: ResMut<ClipGizmo>,
    mut datasets: Query<(Entity, &mut Dataset, &Transform)>,
) {
    let (Ok(window), Ok((camera, orbit))) = (windows.single(), cams.single()) else { return };
    let (origin, size) = viewport_logical(camera, window);
    let cursor = window.cursor_position().map(|c| c - origin);
    let Some((entity, mut dataset, transform)) = selected(&mut datasets, &state) else {
        gizmo.dragging = None;
        gizmo.hover = None;
        return;
    };
    let planes = on_screen(&dataset, transform, &orbit.camera(), size);
    if let Some((e, index, last)) = gizmo.dragging {
        if !buttons.pressed(MouseButton::Left) || e != entity {
            gizmo.dragging = None;
        } else if let (Some(c), Some(p)) = (cursor, planes.iter().find(|p| p.index == index)) {
            let mm = drag_along_normal(p.per_mm, c - last);
            if mm != 0.0
                && let Some(plane) = dataset.clip.planes.get_mut(index)
            {
                plane.point += plane.normal.normalize_or(Vec3::Z) * mm;
            }
            gizmo.dragging = Some((e, index, c));
        }
        return;
    }
    let hover = cursor
        .filter(|_| pointer.inside)
        .and_then(|c| {
            planes
                .iter()
                .filter(|p| p.handle.distance(c) <= GRAB_PIXELS)
                .min_by(|a, b| a.handle.distance(c).total_cmp(&b.handle.distance(c)))
        })
        .map(|p| (entity, p.index));
    gizmo.hover = hover;
    if let (Some((e, index)), Some(c)) = (hover, cursor)
        && buttons.just_pressed(MouseButton::Left)
        && !pointer.press_taken
    {
        gizmo.dragging = Some((e, index, c));
        pointer.press_taken = true;
    }
}

/// Draws the planes of the selected dataset over the viewport `free`.
pub fn overlay(
    ctx: &egui::Context,
    free: Rect,
    gizmo: &ClipGizmo,
    dataset: Option<(Entity, &Dataset, &Transform)>,
    camera: Option<crate::region::Camera>,
) {
    let (Some((entity, dataset, transform)), Some(camera)) = (dataset, camera) else { return };
    let painter = ctx.layer_painter(egui::LayerId::new(egui::Order::Foreground, egui::Id::new("clip_overlay"))).with_clip_rect(free);
    let size = Vec2::new(free.width().max(1.0), free.height().max(1.0));
    let to_pos = |p: Vec2| pos2(free.left() + p.x, free.top() + p.y);
    for p in on_screen(dataset, transform, &camera, size) {
        let active = gizmo.dragging.is_some_and(|(e, i, _)| e == entity && i == p.index) || gizmo.hover == Some((entity, p.index));
        let colour = if active { Color32::YELLOW } else { Color32::from_rgb(90, 200, 255) };
        let mut outline: Vec<_> = p.outline.iter().map(|&q| to_pos(q)).collect();
        if let Some(&first) = outline.first() {
            outline.push(first);
        }
        painter.extend(egui::Shape::dashed_line(&outline, Stroke::new(1.5, colour), 8.0, 5.0));
        painter.circle_filled(to_pos(p.handle), if active { 6.0 } else { 4.5 }, colour);
        // The normal's direction on the screen: the way to drag.
        let tip = p.handle + p.per_mm.normalize_or_zero() * 22.0;
        painter.line_segment([to_pos(p.handle), to_pos(tip)], Stroke::new(2.0, colour));
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::clip::ClipPlane;
    use crate::region::{Appearance, Mode, View};
    use crate::transfer::presets;
    use crate::volume::phantom;

    #[test]
    fn a_plane_facing_sideways_shows_its_outline_and_drags_sideways() {
        // A 32 mm cube seen from the front (anterior view: the patient's right, +x in
        // RAS, is on the viewer's left), cut by the plane x = 4 with its normal along +x.
        let v = Arc::new(phantom::sphere(32, 10.0).unwrap());
        let mut d = Dataset::new(v.clone(), Appearance::new(Mode::Dvr, presets::builtin("grayscale_ramp").unwrap()));
        d.clip.planes.push(ClipPlane::new(Vec3::new(4.0, 0.0, 0.0), Vec3::X));
        d.clip.planes.push(ClipPlane { enabled: false, ..ClipPlane::new(Vec3::ZERO, Vec3::Y) });
        let (lo, hi) = v.grid.world_bounds();
        let cam = View::Anterior.frame_box(lo, hi, 1.0, true);
        let size = Vec2::new(400.0, 400.0);
        let shown = on_screen(&d, &Transform::default(), &cam, size);
        assert_eq!(shown.len(), 1, "the disabled plane is not drawn");
        let p = &shown[0];
        // Seen edge-on: the outline collapses onto one vertical line left of the centre.
        assert_eq!(p.outline.len(), 4);
        assert!(p.outline.iter().all(|q| (q.x - p.handle.x).abs() < 1e-2));
        assert!(p.handle.x < 200.0 && (p.handle.y - 200.0).abs() < 1.0, "{}", p.handle);
        // Dragging left moves it along +x: 1 mm is −per_mm.x pixels to the left.
        assert!(p.per_mm.x < -1.0 && p.per_mm.y.abs() < 1e-3, "{}", p.per_mm);
        assert!((drag_along_normal(p.per_mm, Vec2::new(p.per_mm.x * 3.0, 0.0)) - 3.0).abs() < 1e-4);
        // Moved with its dataset: the handle follows the translation on the screen.
        let moved = on_screen(&d, &Transform::from_xyz(5.0, 0.0, 0.0), &cam, size);
        assert!((moved[0].handle.x - p.handle.x - 5.0 * p.per_mm.x).abs() < 1e-2);
    }
}
