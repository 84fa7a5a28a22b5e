//! The clip-plane gizmo in the viewport: where each enabled clip plane of the selected
//! dataset cuts the dataset's box is drawn over the view, with a handle at its centre
//! and an arrow along its normal ending in a ring; drag the handle to move the plane
//! along its normal, drag the ring to turn the plane about the handle (the normal's tip
//! follows the pointer; the camera does not move with either). The geometry is `crate::clip::gizmo`.

use bevy::prelude::*;
use bevy::window::PrimaryWindow;
use bevy_egui::egui::{self, Color32, Rect, Stroke, pos2};

use super::orbit::{OrbitCamera, PointerInViewport};
use super::state::{AppState, MainCamera};
use super::viewport::viewport_logical;
use crate::clip::gizmo::{box_section, drag_along_normal, rotate_normal};
use crate::dataset::Dataset;

/// Pixels within which a handle grabs.
const GRAB_PIXELS: f32 = 9.0;
/// Pixels from the move handle to the rotate ring, along the normal on the screen.
const ARROW_PIXELS: f32 = 28.0;
/// Pixels of drag that turn a plane by one radian.
const TRACKBALL_PIXELS: f32 = 90.0;

/// Which handle of a plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Handle {
    /// At the section's centre: moves the plane along its normal.
    Move,
    /// The ring at the normal's tip: turns the plane about the centre.
    Rotate,
}

/// What the gizmo remembers between frames.
#[derive(Resource, Default)]
pub struct ClipGizmo {
    /// The handle being dragged (dataset, plane index, which) and the last pointer
    /// position.
    dragging: Option<(Entity, usize, Handle, Vec2)>,
    /// The handle under the pointer.
    hover: Option<(Entity, usize, Handle)>,
}

/// One plane on the screen (viewport pixels from the top left).
struct OnScreen {
    index: usize,
    outline: Vec<Vec2>,
    handle: Vec2,
    /// The rotate ring: `ARROW_PIXELS` from the handle along the normal's screen
    /// direction (to the right where the normal faces the viewer).
    ring: Vec2,
    /// The section's centre in the dataset's frame (what the plane turns about).
    centre: Vec3,
    /// Pixels one millimetre along the plane's normal moves on the screen.
    per_mm: Vec2,
}

impl OnScreen {
    /// The position of `which` handle.
    fn at(&self, which: Handle) -> Vec2 {
        match which {
            Handle::Move => self.handle,
            Handle::Rotate => self.ring,
        }
    }
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
            let ring = handle + per_mm.try_normalize().unwrap_or(Vec2::X) * ARROW_PIXELS;
            Some(OnScreen { index, outline, handle, ring, centre, per_mm })
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
    let camera = orbit.camera();
    let planes = on_screen(&dataset, transform, &camera, size);
    if let Some((e, index, which, last)) = gizmo.dragging {
        if !buttons.pressed(MouseButton::Left) || e != entity {
            gizmo.dragging = None;
        } else if let (Some(c), Some(p)) = (cursor, planes.iter().find(|p| p.index == index)) {
            if let Some(plane) = dataset.clip.planes.get_mut(index) {
                match which {
                    Handle::Move => {
                        let mm = drag_along_normal(p.per_mm, c - last);
                        if mm != 0.0 {
                            plane.point += plane.normal.normalize_or(Vec3::Z) * mm;
                        }
                    }
                    Handle::Rotate if c != last => {
                        // The camera's axes in the dataset's frame, where the normal is.
                        let to_dataset = transform.rotation.inverse() * camera.rotation;
                        plane.normal = rotate_normal(plane.normal, to_dataset * Vec3::X, to_dataset * Vec3::Y, c - last, TRACKBALL_PIXELS);
                    }
                    Handle::Rotate => {}
                }
            }
            gizmo.dragging = Some((e, index, which, c));
        }
        return;
    }
    let hover = cursor.filter(|_| pointer.inside).and_then(|c| {
        planes
            .iter()
            .flat_map(|p| [Handle::Move, Handle::Rotate].map(|h| (p.index, h, p.at(h).distance(c))))
            .filter(|(.., d)| *d <= GRAB_PIXELS)
            .min_by(|a, b| a.2.total_cmp(&b.2))
            .map(|(index, h, _)| (entity, index, h))
    });
    gizmo.hover = hover;
    if let (Some((e, index, which)), Some(c)) = (hover, cursor)
        && buttons.just_pressed(MouseButton::Left)
        && !pointer.press_taken
    {
        // A turn pivots about the section's centre where it was grabbed.
        if let (Handle::Rotate, Some(p), Some(plane)) =
            (which, planes.iter().find(|p| p.index == index), dataset.clip.planes.get_mut(index))
        {
            plane.point = p.centre;
        }
        gizmo.dragging = Some((e, index, which, c));
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
        let active = |h: Handle| {
            gizmo.dragging.is_some_and(|(e, i, which, _)| e == entity && i == p.index && which == h)
                || gizmo.hover == Some((entity, p.index, h))
        };
        let colour = |h: Handle| if active(h) { Color32::YELLOW } else { Color32::from_rgb(90, 200, 255) };
        let plane_colour = if active(Handle::Move) || active(Handle::Rotate) { Color32::YELLOW } else { colour(Handle::Move) };
        let mut outline: Vec<_> = p.outline.iter().map(|&q| to_pos(q)).collect();
        if let Some(&first) = outline.first() {
            outline.push(first);
        }
        painter.extend(egui::Shape::dashed_line(&outline, Stroke::new(1.5, plane_colour), 8.0, 5.0));
        painter.circle_filled(to_pos(p.handle), if active(Handle::Move) { 6.0 } else { 4.5 }, colour(Handle::Move));
        // The normal's direction on the screen (the way to drag the handle), ending in
        // the rotate ring.
        painter.line_segment([to_pos(p.handle), to_pos(p.ring)], Stroke::new(2.0, plane_colour));
        let ring = if active(Handle::Rotate) { 7.0 } else { 5.5 };
        painter.circle_stroke(to_pos(p.ring), ring, Stroke::new(2.0, colour(Handle::Rotate)));
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

    /// A world with what [`clip_input`] reads: a 400×400 window, the main camera
    /// orbiting from the front, and the 32 mm sphere cut by the plane x = 4 (normal +x).
    fn gizmo_world() -> (World, Entity) {
        let mut world = World::new();
        world.insert_resource(ButtonInput::<MouseButton>::default());
        world.insert_resource(AppState::default());
        world.insert_resource(PointerInViewport { inside: true, ..Default::default() });
        world.insert_resource(ClipGizmo::default());
        let mut window = Window::default();
        window.resolution.set(400.0, 400.0);
        world.spawn((window, PrimaryWindow));
        let v = Arc::new(phantom::sphere(32, 10.0).unwrap());
        let mut orbit = OrbitCamera::default();
        let (lo, hi) = v.grid.world_bounds();
        orbit.frame(View::Anterior, lo, hi, 1.0);
        world.spawn((Camera::default(), orbit, MainCamera));
        let mut d = Dataset::new(v, Appearance::new(Mode::Dvr, presets::builtin("grayscale_ramp").unwrap()));
        d.clip.planes.push(ClipPlane::new(Vec3::new(4.0, 0.0, 0.0), Vec3::X));
        let e = world.spawn((d, Transform::default())).id();
        (world, e)
    }

    /// Presses the left button at `from`, drags to `to` over a few frames, releases.
    fn drag(world: &mut World, from: Vec2, to: Vec2) {
        use bevy::ecs::system::RunSystemOnce;
        let set_cursor = |world: &mut World, at: Vec2| {
            let mut q = world.query_filtered::<&mut Window, With<PrimaryWindow>>();
            for mut w in q.iter_mut(world) {
                w.set_cursor_position(Some(at));
            }
        };
        set_cursor(world, from);
        // (The UI frees the press every frame, ui::lenses.)
        world.resource_mut::<PointerInViewport>().press_taken = false;
        world.resource_mut::<ButtonInput<MouseButton>>().press(MouseButton::Left);
        world.run_system_once(clip_input).unwrap();
        for k in 1..=4 {
            world.resource_mut::<ButtonInput<MouseButton>>().clear();
            set_cursor(world, from + (to - from) * (k as f32 / 4.0));
            world.run_system_once(clip_input).unwrap();
        }
        world.resource_mut::<ButtonInput<MouseButton>>().release(MouseButton::Left);
        world.run_system_once(clip_input).unwrap();
    }

    fn shown(world: &mut World, e: Entity) -> OnScreen {
        let cam = world.query::<&OrbitCamera>().single(world).unwrap().camera();
        let (d, t) = world.query::<(&Dataset, &Transform)>().get(world, e).unwrap();
        on_screen(d, t, &cam, Vec2::new(400.0, 400.0)).remove(0)
    }

    #[test]
    fn dragging_the_handle_moves_the_plane_and_dragging_the_ring_turns_it() {
        let (mut world, e) = gizmo_world();
        let before = shown(&mut world, e);
        // The handle, dragged 3 mm along the normal's screen direction: x = 7.
        drag(&mut world, before.handle, before.handle + before.per_mm * 3.0);
        let plane = world.get::<Dataset>(e).unwrap().clip.planes[0];
        assert!((plane.point.x - 7.0).abs() < 0.05 && plane.normal == Vec3::X, "{plane:?}");
        assert!(world.resource::<ClipGizmo>().dragging.is_none(), "the release ends the drag");
        // The ring (the normal's tip, on the viewer's left), dragged up by
        // TRACKBALL_PIXELS·π/4: the plane turns 45° about its centre, its normal tilting
        // up (towards +z, the patient's superior, seen from the front), still through
        // the section's centre.
        let moved = shown(&mut world, e);
        let up = Vec2::new(0.0, -TRACKBALL_PIXELS * std::f32::consts::FRAC_PI_4);
        drag(&mut world, moved.ring, moved.ring + up);
        let plane = world.get::<Dataset>(e).unwrap().clip.planes[0];
        let want = Vec3::new(1.0, 0.0, 1.0).normalize();
        assert!(plane.normal.distance(want) < 1e-3, "normal {}", plane.normal);
        assert!(plane.plane().distance(moved.centre).abs() < 1e-3, "the plane left its centre: {plane:?}");
        // A press away from both handles takes nothing.
        drag(&mut world, Vec2::new(5.0, 5.0), Vec2::new(60.0, 60.0));
        assert_eq!(world.get::<Dataset>(e).unwrap().clip.planes[0], plane);
    }
}
