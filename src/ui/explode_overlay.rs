//! What the exploded view shows over the viewport: the cut the axis or depth splitter
//! would make at the cursor (the face where its plane cuts the part under it, drawn
//! before the click), and every joint of the selected dataset's parts where the parts
//! are now (its anchor, its axis or axes, its kind).

use bevy::math::Affine3A;
use bevy::prelude::*;
use bevy::window::PrimaryWindow;
use bevy_egui::{EguiContexts, egui};

use super::explode_tools::{ExplodeUi, Tool};
use super::orbit::{OrbitCamera, PointerInViewport};
use super::state::{AppState, MainCamera};
use super::viewport::viewport_logical;
use crate::dataset::{Dataset, SceneRegions};
use crate::explode::edit::{background_hit, nearest_part};
use crate::explode::splitters::{axis_plane, depth_plane, in_part_frame};
use crate::explode::{JointKind, Part, PartJoint};

/// The splitter's cut at the cursor, kept while the cursor, the tool and the view stay.
#[derive(Resource, Default)]
pub struct CutPreview {
    key: Option<(Vec2, Tool, Vec3, Quat)>,
    /// The cut face (world), empty when nothing is under the cursor.
    face: Vec<Vec3>,
}

const CUT: egui::Color32 = egui::Color32::from_rgb(255, 200, 60);
const JOINT: egui::Color32 = egui::Color32::from_rgb(120, 230, 160);

/// Draws the cut preview and the joints of the selected dataset.
// A Bevy system: its parameters are the resources and queries it uses, and a query's
// type names the components it reads; splitting them up would only hide that.
#[allow(clippy::too_many_arguments)]
pub fn explode_overlay(
    mut contexts: EguiContexts,
    state: Res<AppState>,
    ui: Res<ExplodeUi>,
    mut preview: ResMut<CutPreview>,
    pointer: Res<PointerInViewport>,
    primary: Query<&Window, With<PrimaryWindow>>,
    cams: Query<(&Camera, &OrbitCamera), With<MainCamera>>,
    scene: Res<SceneRegions>,
    datasets: Query<(Entity, &Dataset, &GlobalTransform)>,
    parts: Query<(Entity, &Part, &Transform)>,
    joints: Query<&PartJoint>,
) -> Result {
    if !state.show_explode {
        return Ok(());
    }
    let (Ok(window), Ok((camera, orbit))) = (primary.single(), cams.single()) else { return Ok(()) };
    let mut sorted: Vec<(Entity, &Dataset, &GlobalTransform)> = datasets.iter().collect();
    sorted.sort_by_key(|d| d.0);
    let Some(&(dataset, data, global)) = sorted.get(state.selected) else { return Ok(()) };
    let (origin, size) = viewport_logical(camera, window);
    let cam = orbit.camera();
    let to_world = |motion: &Transform| global.affine() * motion.compute_affine();
    let mine: Vec<(Entity, &Part, Affine3A)> =
        parts.iter().filter(|(_, p, _)| p.dataset == dataset).map(|(e, p, t)| (e, p, to_world(t))).collect();
    // The cut at the cursor, found again when the cursor, the tool or the view moved.
    let cursor = window.cursor_position().filter(|_| pointer.inside).map(|c| c - origin);
    let splitting = matches!(ui.tool, Tool::Axis(_) | Tool::Depth);
    match cursor.filter(|_| splitting) {
        Some(c) => {
            let key = Some((c, ui.tool, cam.position, cam.rotation));
            if preview.key != key {
                let ray = cam.ray(c.x, c.y, size.x.max(1.0) as u32, size.y.max(1.0) as u32);
                let hit = background_hit(&scene.scene, ray).ok().flatten();
                preview.face = hit.and_then(|hit| cut_face(&mine, &cam, ui.tool, hit)).unwrap_or_default();
                preview.key = key;
            }
        }
        None => *preview = CutPreview::default(),
    }
    let ctx = contexts.ctx_mut()?.clone();
    // Under the panels' windows, inside the viewport.
    let viewport = egui::Rect::from_min_size(egui::pos2(origin.x, origin.y), egui::vec2(size.x, size.y));
    let painter = ctx.layer_painter(egui::LayerId::new(egui::Order::Background, egui::Id::new("explode_overlay"))).with_clip_rect(viewport);
    let pixel = |p: Vec3| cam.to_pixel(p, size.x, size.y).map(|q| egui::pos2(q.x + origin.x, q.y + origin.y));
    if let Some(points) = preview.face.iter().map(|p| pixel(*p)).collect::<Option<Vec<_>>>()
        && points.len() >= 3
    {
        painter.add(egui::Shape::closed_line(points, egui::Stroke::new(2.0, CUT)));
    }
    // The joints: anchor, axes (a tenth of the dataset's diagonal each way), kind.
    let (lo, hi) = data.volume.grid.world_bounds();
    let reach = 0.1 * (hi - lo).length();
    for j in joints.iter().filter(|j| j.kind != JointKind::Fixed) {
        let Some((_, _, m)) = mine.iter().find(|(e, ..)| *e == j.part) else { continue };
        let Some(anchor) = pixel(m.transform_point3(j.anchor)) else { continue };
        let axes: &[Vec3] = match j.kind {
            JointKind::Hinge | JointKind::Slider => &[j.axis],
            JointKind::Universal => &[j.axis, j.axis2],
            _ => &[],
        };
        for axis in axes {
            let d = m.transform_vector3(axis.normalize_or_zero()) * reach;
            let centre = m.transform_point3(j.anchor);
            if let (Some(a), Some(b)) = (pixel(centre - d), pixel(centre + d)) {
                painter.line_segment([a, b], egui::Stroke::new(2.0, JOINT));
            }
        }
        painter.circle_stroke(anchor, 5.0, egui::Stroke::new(2.0, JOINT));
        painter.text(anchor + egui::vec2(8.0, -8.0), egui::Align2::LEFT_BOTTOM, j.kind.name(), egui::FontId::proportional(12.0), JOINT);
    }
    Ok(())
}

/// The face the axis or depth splitter would cut through the part at `hit` (world).
fn cut_face(parts: &[(Entity, &Part, Affine3A)], cam: &crate::region::Camera, tool: Tool, hit: Vec3) -> Option<Vec<Vec3>> {
    let plane = match tool {
        Tool::Axis(axis) => axis_plane(cam, hit, axis),
        Tool::Depth => depth_plane(cam, hit),
        _ => return None,
    };
    let part = nearest_part(parts.iter().map(|(e, p, m)| (*e, *p, *m)), hit)?;
    let (_, p, m) = parts.iter().find(|(e, ..)| *e == part)?;
    let face = p.rest.section(in_part_frame(plane, *m));
    Some(face.into_iter().map(|v| m.transform_point3(v)).collect())
}
