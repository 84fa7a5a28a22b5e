//! Volumetric windows in the viewport: the cursor's ray gives the focus
//! (`crate::windows::systems::update_focus`); Ctrl+drag a window or a source box to move
//! it in the plane facing the camera (Ctrl+drag a dataset to move the data: the world
//! moves past room-fixed windows); drag a corner handle of the focused window
//! (drawn when the cursor is near) to resize it, the opposite corner staying; right-click
//! the focused window for its parameter menu beside it. The 3D pointer tool (T) moves the
//! pointer with the cursor in the plane facing the camera at the pointer's depth; the
//! wheel changes that depth, G puts it on the first visible surface under the cursor;
//! Space places a marker there, Shift+Space moves the nearest marker to it, Backspace
//! deletes the nearest. The geometry is `crate::windows::interaction`.

use bevy::input::mouse::AccumulatedMouseScroll;
use bevy::prelude::*;
use bevy::window::PrimaryWindow;
use bevy_egui::EguiContexts;
use bevy_egui::egui::{self, Color32, Stroke};

use super::orbit::{OrbitCamera, PointerInViewport, wheel_lines};
use super::state::MainCamera;
use super::viewport::viewport_logical;
use crate::dataset::{Dataset, SceneRegions};
use crate::region::Ray;
use crate::windows::boxes::OrientedBox;
use crate::windows::interaction::{corner_under, on_view_plane, pixels_to_world, ray_box, resize_from_corner};
use crate::windows::markers::PlacedWindows;
use crate::windows::systems::{CursorRay, WindowFocus, delete_marker, move_marker, place_marker, window_box};
use crate::windows::{Attachment, Pointer3d, SourceBox, VolumeWindow};

/// Pixels within which a corner handle grabs.
const GRAB_PIXELS: f32 = 10.0;
/// Pointer depth per wheel line, as a share of the camera's distance.
const DEPTH_STEP: f32 = 0.02;
/// Markers within this many pixels (at the pointer) are "near" for moving and deleting.
const MARKER_PIXELS: f32 = 12.0;

/// What the window tools remember between frames.
#[derive(Resource, Default)]
pub struct WindowTools {
    /// The 3D pointer follows the cursor.
    pub pointer_tool: bool,
    drag: Option<Drag>,
    /// The focused window's corner under the cursor (its handle is drawn).
    pub hover_corner: Option<(Entity, usize)>,
    /// The window whose parameter menu is open and where (viewport pixels).
    pub menu: Option<(Entity, Vec2)>,
}

#[derive(Clone, Copy, Debug)]
enum Drag {
    /// A window or source box grabbed at `anchor` (its centre is `anchor + offset`).
    Move { target: Entity, anchor: Vec3, offset: Vec3 },
    /// A window's corner, from the box it had when grabbed.
    Resize { window: Entity, start: OrientedBox, corner: usize },
}

/// Moves a window to world pose `(centre, size)`: a room window's transform, a user or
/// dataset window's offset in its parent's frame.
fn place_window(w: &mut VolumeWindow, t: &mut Transform, centre: Vec3, size: Option<Vec3>, parent: Option<GlobalTransform>) {
    if let Some(s) = size {
        w.size = s / t.scale.abs().max(Vec3::splat(1e-6));
    }
    match (&mut w.attachment, parent) {
        (Attachment::User { offset } | Attachment::Dataset { offset, .. }, Some(p)) => {
            offset.translation = p.affine().inverse().transform_point3(centre);
        }
        _ => t.translation = centre,
    }
}

/// Viewport input for windows and the 3D pointer; runs before the camera's.
// A Bevy system: its parameters are the resources and queries it uses, and a query's
// type names the components it reads; splitting them up would only hide that.
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub fn window_input(
    (buttons, keys, scroll): (Res<ButtonInput<MouseButton>>, Res<ButtonInput<KeyCode>>, Res<AccumulatedMouseScroll>),
    mut contexts: EguiContexts,
    primary: Query<&Window, With<PrimaryWindow>>,
    cams: Query<(&Camera, &OrbitCamera, &GlobalTransform), With<MainCamera>>,
    mut pointer_in: ResMut<PointerInViewport>,
    mut tools: ResMut<WindowTools>,
    mut cursor_ray: ResMut<CursorRay>,
    focus: Res<WindowFocus>,
    placed: Res<PlacedWindows>,
    regions: Res<SceneRegions>,
    mut windows: Query<(&mut VolumeWindow, &mut Transform, &GlobalTransform), (Without<SourceBox>, Without<Pointer3d>)>,
    mut sources: Query<(Entity, &SourceBox, &mut Transform, &GlobalTransform), (Without<VolumeWindow>, Without<Pointer3d>)>,
    mut pointers: Query<&mut Transform, (With<Pointer3d>, Without<VolumeWindow>, Without<SourceBox>)>,
    mut datasets: Query<
        (Entity, &Dataset, &mut Transform, &GlobalTransform),
        (Without<VolumeWindow>, Without<SourceBox>, Without<Pointer3d>),
    >,
    mut commands: Commands,
) {
    let (Ok(window), Ok((camera, orbit, camera_global))) = (primary.single(), cams.single()) else { return };
    let (origin, size) = viewport_logical(camera, window);
    let cam = orbit.camera();
    // The cursor over the viewport (`pointer_in` is last frame's: the cursor may have
    // left since, and a ray through a point beside the viewport would take the focus).
    let cursor = window.cursor_position().map(|c| c - origin).filter(|c| c.cmpge(Vec2::ZERO).all() && c.cmplt(size).all());
    let ray = cursor.filter(|_| pointer_in.inside).map(|c| ray_at(orbit, c, size)).filter(|r| r.dir.is_finite());
    if cursor_ray.0 != ray {
        cursor_ray.0 = ray;
    }
    let forward = cam.forward();
    let parent_of = |w: &VolumeWindow| match w.attachment {
        Attachment::Room => None,
        Attachment::User { .. } => Some(*camera_global),
        Attachment::Dataset { dataset, .. } => datasets.get(dataset).ok().map(|(.., g)| *g),
    };

    // A drag under way.
    if let Some(drag) = tools.drag {
        if !buttons.pressed(MouseButton::Left) {
            tools.drag = None;
        } else if let Some(ray) = ray {
            match drag {
                Drag::Move { target, anchor, offset } => {
                    if let Some(p) = on_view_plane(anchor, forward, &ray) {
                        if let Ok((mut w, mut t, _)) = windows.get_mut(target) {
                            let parent = parent_of(&w);
                            place_window(&mut w, &mut t, p + offset, None, parent);
                        } else if let Ok((_, _, mut t, _)) = sources.get_mut(target) {
                            t.translation = p + offset;
                        } else if let Ok((_, _, mut t, _)) = datasets.get_mut(target) {
                            // The world moves: dataset-attached windows and markers follow.
                            t.translation = p + offset;
                        }
                    }
                }
                Drag::Resize { window: e, start, corner } => {
                    if let (Some(p), Ok((mut w, mut t, _))) = (on_view_plane(start.corners()[corner], forward, &ray), windows.get_mut(e)) {
                        let b = resize_from_corner(&start, corner, p);
                        let parent = parent_of(&w);
                        place_window(&mut w, &mut t, b.center, Some(b.half * 2.0), parent);
                    }
                }
            }
        }
        pointer_in.press_taken |= buttons.pressed(MouseButton::Left);
        return;
    }

    // Corner handles of the focused window.
    let focused = focus.0.and_then(|e| placed.get(e).map(|v| (e, v.window)));
    let (eye, unit_height) = match cam.projection {
        crate::region::Projection::Perspective { fov_y } => (Some(cam.position), 2.0 * (fov_y * 0.5).tan()),
        crate::region::Projection::Orthographic { height } => (None, height),
    };
    tools.hover_corner = match (focused, ray) {
        (Some((e, b)), Some(r)) => {
            let tolerance = pixels_to_world(GRAB_PIXELS, size.y, unit_height, eye, b.center);
            corner_under(&b, &r, tolerance).map(|c| (e, c))
        }
        _ => None,
    };
    let ctrl = keys.any_pressed([KeyCode::ControlLeft, KeyCode::ControlRight]);
    if let Some(r) = ray
        && buttons.just_pressed(MouseButton::Left)
        && !pointer_in.press_taken
    {
        if let (Some((e, c)), Some((_, b))) = (tools.hover_corner, focused) {
            tools.drag = Some(Drag::Resize { window: e, start: b, corner: c });
        } else if ctrl {
            // The nearest window or source box under the cursor, else the nearest
            // dataset (its box, met in its own frame; its origin is what moves). A hit is
            // (entity, the point that moves, where the ray enters).
            let enters = |ray: &Ray, b: &OrientedBox| ray_box(ray, b).map(|(t0, _)| r.at(t0.max(0.0)));
            let nearest = |hits: Vec<(Entity, Vec3, Vec3)>| {
                hits.into_iter().min_by(|a, b| a.2.distance_squared(r.origin).total_cmp(&b.2.distance_squared(r.origin)))
            };
            let tool_hits = placed
                .0
                .iter()
                .map(|(e, v)| (*e, v.window))
                .chain(sources.iter().map(|(e, s, _, g)| (e, window_box(&VolumeWindow::new(s.size, vec![]), g))))
                .filter_map(|(e, b)| enters(&r, &b).map(|at| (e, b.center, at)))
                .collect();
            let data_hits = || {
                datasets
                    .iter()
                    .filter_map(|(e, d, _, g)| {
                        let (lo, hi) = d.volume.grid.world_bounds();
                        let to_local = g.affine().inverse();
                        // (The same ray parameter in both frames: the direction is mapped, not normalised.)
                        let local = Ray { origin: to_local.transform_point3(r.origin), dir: to_local.transform_vector3(r.dir) };
                        enters(&local, &OrientedBox::aligned(lo, hi)).map(|at| (e, g.translation(), at))
                    })
                    .collect()
            };
            let hit = nearest(tool_hits).or_else(|| nearest(data_hits()));
            if let Some((target, centre, anchor)) = hit {
                tools.drag = Some(Drag::Move { target, anchor, offset: centre - anchor });
            }
        }
        if tools.drag.is_some() {
            pointer_in.press_taken = true;
        }
    }
    // The parameter menu of the focused window.
    if let (Some((e, b)), Some(r), Some(c)) = (focused, ray, cursor)
        && buttons.just_pressed(MouseButton::Right)
        && !pointer_in.press_taken
        && ray_box(&r, &b).is_some()
    {
        tools.menu = Some((e, c));
        pointer_in.press_taken = true;
    }

    // The 3D pointer tool (its keys are ignored while egui has the keyboard).
    let typing = contexts.ctx_mut().is_ok_and(|c| c.egui_wants_keyboard_input());
    if keys.just_pressed(KeyCode::KeyT) && !typing {
        tools.pointer_tool = !tools.pointer_tool;
    }
    if !tools.pointer_tool {
        return;
    }
    let Ok(mut p) = pointers.single_mut() else {
        commands.spawn((Pointer3d, Transform::from_translation(orbit.target)));
        return;
    };
    if let Some(r) = ray {
        if keys.just_pressed(KeyCode::KeyG) && !typing {
            match crate::reference::pick(&regions.scene, r) {
                Ok(Some(hit)) => p.translation = hit.position,
                Ok(None) => {}
                Err(e) => warn!("cannot pick under the cursor: {e}"),
            }
        } else if !buttons.any_pressed([MouseButton::Left, MouseButton::Right, MouseButton::Middle])
            && let Some(q) = on_view_plane(p.translation, forward, &r)
        {
            p.translation = q;
        }
        if scroll.delta.y != 0.0 && !pointer_in.wheel_taken {
            p.translation += forward * wheel_lines(&scroll) * DEPTH_STEP * orbit.distance;
            pointer_in.wheel_taken = true;
        }
    }
    let radius = pixels_to_world(MARKER_PIXELS, size.y, unit_height, eye, p.translation);
    let shift = keys.any_pressed([KeyCode::ShiftLeft, KeyCode::ShiftRight]);
    if typing {
        return;
    }
    if keys.just_pressed(KeyCode::Space) {
        commands.queue(move |world: &mut World| {
            if shift {
                move_marker(world, radius);
            } else if place_marker(world).is_none() {
                warn!("the pointer is in no dataset: no marker placed");
            }
        });
    }
    if keys.just_pressed(KeyCode::Backspace) {
        commands.queue(move |world: &mut World| {
            delete_marker(world, radius);
        });
    }
}

/// Draws the focused window's corner handles (the hovered one larger) over the viewport
/// `free` (viewport pixels from its top left corner at `free.min`).
pub fn overlay(ctx: &egui::Context, free: egui::Rect, tools: &WindowTools, focused: Option<OrientedBox>, orbit: &OrbitCamera) {
    let Some(b) = focused else { return };
    let cam = orbit.camera();
    let handles: Vec<(egui::Pos2, bool)> = b
        .corners()
        .iter()
        .enumerate()
        .filter_map(|(i, c)| {
            let px = cam.to_pixel(*c, free.width(), free.height())?;
            Some((free.min + egui::vec2(px.x, px.y), tools.hover_corner.is_some_and(|(_, k)| k == i)))
        })
        .collect();
    egui::Area::new(egui::Id::new("window_handles")).order(egui::Order::Foreground).fixed_pos(free.min).interactable(false).show(
        ctx,
        |ui| {
            let painter = ui.painter().with_clip_rect(free);
            for (at, hovered) in handles {
                let r = if hovered { 6.0 } else { 3.5 };
                painter.circle(at, r, Color32::from_rgba_unmultiplied(240, 200, 80, 160), Stroke::new(1.0, Color32::BLACK));
            }
        },
    );
}

/// The world ray through viewport point `px` (pixels from the top left) of a viewport of
/// `size`.
pub fn ray_at(orbit: &OrbitCamera, px: Vec2, size: Vec2) -> Ray {
    orbit.camera().ray(px.x, px.y, size.x.max(1.0) as u32, size.y.max(1.0) as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_moved_window_stays_where_it_was_put_under_each_attachment() {
        let parent = GlobalTransform::from(Transform::from_xyz(0.0, -300.0, 0.0).with_rotation(Quat::from_rotation_z(0.5)));
        let target = Vec3::new(10.0, 20.0, 30.0);
        // Room: the transform moves.
        let mut w = VolumeWindow::new(Vec3::splat(40.0), vec![]);
        let mut t = Transform::default();
        place_window(&mut w, &mut t, target, Some(Vec3::new(20.0, 30.0, 40.0)), None);
        assert_eq!(t.translation, target);
        assert_eq!(w.size, Vec3::new(20.0, 30.0, 40.0));
        // Fixed to the view (or a dataset): the offset in the parent's frame is what
        // moves, so that attaching puts the window at the target again.
        let mut w =
            VolumeWindow { attachment: Attachment::User { offset: Transform::IDENTITY }, ..VolumeWindow::new(Vec3::splat(40.0), vec![]) };
        let mut t = Transform::from_scale(Vec3::splat(2.0));
        place_window(&mut w, &mut t, target, Some(Vec3::splat(40.0)), Some(parent));
        let Attachment::User { offset } = w.attachment else { panic!("the attachment changed") };
        let miss = parent.transform_point(offset.translation).distance(target);
        assert!(miss < 1e-3, "{miss}: {parent:?} {offset:?}");
        // The size is the world size over the transform's scale.
        assert_eq!(w.size, Vec3::splat(20.0));
    }
}
