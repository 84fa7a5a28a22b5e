//! Distance rulers in the app: Shift+click two points, in a slice view or on the surface
//! the 3D view shows (picked with the CPU reference renderer under the view's transfer
//! functions, as a double-click picks its centre); the rulers are drawn in the 3D view
//! and in the slices they pass through, with their length in millimetres
//! ([`crate::slices::ruler`]).

use bevy::math::Affine3A;
use bevy::prelude::*;
use bevy::window::PrimaryWindow;
use bevy_egui::egui::{self, Color32, Rect, Stroke, pos2};

use super::orbit::{OrbitCamera, PointerInViewport};
use super::state::MainCamera;
use super::viewport::viewport_logical;
use crate::dataset::SceneRegions;
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

/// Shift+click in the 3D view: a ruler's end on the first visible point under the cursor.
// A Bevy system: its parameters are the resources and queries it uses.
#[allow(clippy::too_many_arguments)]
pub fn ruler_on_surface(
    buttons: Res<ButtonInput<MouseButton>>,
    keys: Res<ButtonInput<KeyCode>>,
    windows: Query<&Window, With<PrimaryWindow>>,
    pointer: Res<PointerInViewport>,
    regions: Res<SceneRegions>,
    cams: Query<(&OrbitCamera, &Camera), With<MainCamera>>,
    mut tool: ResMut<RulerTool>,
    mut pressed_at: Local<Option<Vec2>>,
) {
    let (Ok(window), Ok((orbit, camera))) = (windows.single(), cams.single()) else { return };
    let shift = keys.any_pressed([KeyCode::ShiftLeft, KeyCode::ShiftRight]);
    let cursor = window.cursor_position();
    if buttons.just_pressed(MouseButton::Left) {
        *pressed_at = cursor.filter(|_| shift && pointer.inside);
    }
    if !buttons.just_released(MouseButton::Left) {
        return;
    }
    let (Some(start), Some(cursor)) = (pressed_at.take(), cursor) else { return };
    if !shift || start.distance(cursor) > CLICK_SLOP {
        return;
    }
    let (origin, size) = viewport_logical(camera, window);
    let p = cursor - origin;
    let ray = orbit.camera().ray(p.x, p.y, size.x.max(1.0) as u32, size.y.max(1.0) as u32);
    if let Some((dataset, point)) = surface_point(&regions, ray) {
        tool.end(dataset, point);
    }
}

/// The dataset and the point (in the dataset's own frame, where its rulers live) of the
/// first visible point along `ray`. Through the region's own map, so a point on a
/// moved part or in a window is where the data is.
pub fn surface_point(regions: &SceneRegions, ray: crate::region::Ray) -> Option<(Entity, Vec3)> {
    let hit = crate::reference::pick(&regions.scene, ray).ok().flatten()?;
    let region = regions.scene.regions.get(hit.region)?;
    let volume = regions.scene.volumes.get(region.volume)?;
    let dataset = *regions.datasets.get(region.volume)?;
    let q = region.world_to_voxel.transform_point3(hit.position);
    Some((dataset, volume.grid.index_to_world().transform_point3(q)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::SceneFile;
    use crate::scene::load::{load_datasets, render_scene};

    #[test]
    fn a_surface_point_is_on_the_sphere_in_the_datasets_own_frame() {
        // The sphere phantom (radius 0.35·n voxels), moved 500 mm along x: a ray along −x
        // through its centre meets the surface one radius before the centre, and the point
        // comes back in the dataset's frame, not the world's.
        let scene =
            SceneFile::parse("(datasets: [(source: Phantom(kind: sphere, resolution: 40), translation: (500, 0, 0))])", "t").unwrap();
        let datasets = load_datasets(&scene, std::path::Path::new(".")).unwrap();
        let grid = &datasets[0].volume.grid;
        let centre = grid.index_to_world().transform_point3((grid.dims.as_vec3() - 1.0) * 0.5);
        let radius = 0.35 * 40.0 * grid.spacing.x;
        let regions = SceneRegions { scene: render_scene(&datasets, &scene), datasets: vec![Entity::from_raw_u32(7).unwrap()] };
        let world_centre = centre + Vec3::new(500.0, 0.0, 0.0);
        let ray = crate::region::Ray { origin: world_centre + Vec3::new(1000.0, 0.0, 0.0), dir: Vec3::NEG_X };
        let (dataset, point) = surface_point(&regions, ray).expect("the ray meets the sphere");
        assert_eq!(dataset, regions.datasets[0]);
        assert!((point.distance(centre) - radius).abs() < 2.0 * grid.spacing.x, "{point} from {centre}: {radius}");
        assert!(point.x > centre.x, "on the side facing the eye");
        // A ray that misses: nothing.
        let miss = crate::region::Ray { origin: world_centre + Vec3::new(1000.0, 0.0, 3.0 * radius), dir: Vec3::NEG_X };
        assert!(surface_point(&regions, miss).is_none());
    }
}
