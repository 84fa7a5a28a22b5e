//! What lies under the cursor in the 3D view: the first visible point along the
//! cursor's ray (through the lenses), picked on the CPU with the reference renderer again
//! only when the cursor, the camera, the lenses or the scene change. The value probe shows the
//! dataset, the voxel and its value (and label) there at the top left of the 3D view;
//! the streaming status line looks the level drawn there up in the frame's bricks.
//! (On a streamed dataset the pick sees the level in memory.)

use bevy::prelude::*;
use bevy::window::PrimaryWindow;
use bevy_egui::egui;

use super::orbit::PointerInViewport;
use super::state::MainCamera;
use super::viewport::viewport_logical;
use crate::dataset::{Dataset, SceneRegions};
use crate::lens::ViewLenses;
use crate::lens::stack::lens_ray;
use crate::reference::Hit;

/// What a pick was made for: the ray's pixel (viewport pixels), the view's camera and
/// screen, and its lenses.
type PickedFor = (Vec2, Option<crate::region::Camera>, Option<crate::lens::Screen>, Vec<crate::lens::stack::ResolvedLens>);

/// The first visible point under the cursor.
#[derive(Resource, Default)]
pub struct UnderCursor {
    picked_for: Option<PickedFor>,
    /// The scene volume and its voxel index (continuous) there.
    pub hit: Option<(usize, Vec3)>,
    /// The dataset and the point in its own frame (where its rulers live).
    pub point: Option<(Entity, Vec3)>,
    /// What the probe says of it.
    pub probe: Option<String>,
}

/// Picks the point under the cursor when the cursor, the camera, the lenses or the
/// scene changed.
pub fn pick_under_cursor(
    windows: Query<&Window, With<PrimaryWindow>>,
    pointer: Res<PointerInViewport>,
    cams: Query<(&Camera, &ViewLenses), With<MainCamera>>,
    regions: Res<SceneRegions>,
    datasets: Query<&Dataset>,
    mut under: ResMut<UnderCursor>,
) {
    let (Ok(window), Ok((camera, lenses))) = (windows.single(), cams.single()) else { return };
    let (origin, size) = viewport_logical(camera, window);
    let cursor = window.cursor_position().filter(|_| pointer.inside).map(|c| c - origin);
    let (Some(cursor), Some(view), Some(screen)) = (cursor, lenses.camera, lenses.screen) else {
        if under.picked_for.is_some() {
            *under = UnderCursor::default();
        }
        return;
    };
    let stale = regions.is_changed()
        || under.picked_for.as_ref().is_none_or(|(at, camera, shown, picked)| {
            at.distance(cursor) > 0.5 || *camera != lenses.camera || *shown != lenses.screen || *picked != lenses.lenses
        });
    if !stale {
        return;
    }
    let (px, py) = (cursor.x * screen.width / size.x.max(1.0), cursor.y * screen.height / size.y.max(1.0));
    let hit = lens_ray(&view, screen, &lenses.lenses, px, py).and_then(|ray| crate::reference::pick(&regions.scene, ray).ok().flatten());
    under.hit = hit.as_ref().and_then(|h| {
        let region = regions.scene.regions.get(h.region)?;
        Some((region.volume, region.world_to_voxel.transform_point3(h.position)))
    });
    under.point = hit.as_ref().and_then(|h| dataset_point(&regions, h));
    under.probe = hit.as_ref().and_then(|h| {
        let (entity, _) = dataset_point(&regions, h)?;
        describe(&regions, h, datasets.get(entity).ok()?)
    });
    under.picked_for = Some((cursor, lenses.camera, lenses.screen, lenses.lenses.clone()));
}

/// The dataset of a hit and the point in the dataset's own frame: through the region's
/// own map, so a point on a moved part or in a window is where the data is.
pub fn dataset_point(regions: &SceneRegions, hit: &Hit) -> Option<(Entity, Vec3)> {
    let region = regions.scene.regions.get(hit.region)?;
    let volume = regions.scene.volumes.get(region.volume)?;
    let dataset = *regions.datasets.get(region.volume)?;
    let q = region.world_to_voxel.transform_point3(hit.position);
    Some((dataset, volume.grid.index_to_world().transform_point3(q)))
}

/// "name · voxel (i, j, k): value units, label id name" of the dataset's own voxel
/// nearest a hit (the dataset's volume, not the one the GPU draws, which may be halved).
pub fn describe(regions: &SceneRegions, hit: &Hit, dataset: &Dataset) -> Option<String> {
    let (_, point) = dataset_point(regions, hit)?;
    let volume = &dataset.volume;
    let q = volume.grid.world_to_index().transform_point3(point);
    let voxel = q.round().max(Vec3::ZERO).min(volume.dims().as_vec3() - 1.0).as_uvec3();
    let code = volume.code(voxel.x, voxel.y, voxel.z);
    let value = volume.values.to_real(code as f64);
    let shown = volume.values.describe(code as u32);
    // A label volume's label is its value; a segmented one's, its segmentation's there.
    let label = match &dataset.labels {
        Some(table) => Some(format!(", label {} {}", value, table.name(value.round().max(0.0) as u32))),
        None => crate::reference::label_at(&regions.scene, hit).map(|id| format!(", label {id}")),
    };
    Some(format!("{} · voxel ({}, {}, {}): {shown}{}", volume.name, voxel.x, voxel.y, voxel.z, label.unwrap_or_default()))
}

/// The probe's text at the top left of the 3D view (`free`): a slice's voxel while the
/// cursor is over a slice view, else the 3D view's.
pub fn probe_overlay(ctx: &egui::Context, free: egui::Rect, text: Option<&str>) {
    let Some(text) = text else { return };
    ctx.layer_painter(egui::LayerId::new(egui::Order::Foreground, egui::Id::new("probe"))).text(
        free.left_top() + egui::vec2(8.0, 8.0),
        egui::Align2::LEFT_TOP,
        text,
        egui::FontId::monospace(13.0),
        egui::Color32::WHITE,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::SceneFile;
    use crate::scene::load::{load_datasets, render_scene};

    /// A one-dataset scene's regions and its dataset component.
    fn scene_of(text: &str) -> (SceneRegions, Dataset) {
        let scene = SceneFile::parse(text, "t").unwrap();
        let datasets = load_datasets(&scene, std::path::Path::new(".")).unwrap();
        let regions = SceneRegions { scene: render_scene(&datasets, &scene), datasets: vec![Entity::from_raw_u32(7).unwrap()] };
        (regions, datasets[0].component())
    }

    /// A ray along −x through the middle of the dataset, from far away, in the world.
    fn ray_through(d: &Dataset, shift: Vec3) -> crate::region::Ray {
        let grid = &d.volume.grid;
        let centre = grid.index_to_world().transform_point3((grid.dims.as_vec3() - 1.0) * 0.5) + shift;
        crate::region::Ray { origin: centre + Vec3::new(1000.0, 0.0, 0.0), dir: Vec3::NEG_X }
    }

    #[test]
    fn a_surface_point_is_on_the_sphere_in_the_datasets_own_frame() {
        // The sphere phantom (radius 0.35·n voxels), moved 500 mm along x: the ray meets
        // the surface one radius before the centre, and the point comes back in the
        // dataset's frame, not the world's.
        let (regions, d) = scene_of("(datasets: [(source: Phantom(kind: sphere, resolution: 40), translation: (500, 0, 0))])");
        let grid = &d.volume.grid;
        let centre = grid.index_to_world().transform_point3((grid.dims.as_vec3() - 1.0) * 0.5);
        let radius = 0.35 * 40.0 * grid.spacing.x;
        let hit = crate::reference::pick(&regions.scene, ray_through(&d, Vec3::new(500.0, 0.0, 0.0))).unwrap().expect("the sphere");
        let (dataset, point) = dataset_point(&regions, &hit).unwrap();
        assert_eq!(dataset, regions.datasets[0]);
        assert!((point.distance(centre) - radius).abs() < 2.0 * grid.spacing.x, "{point} from {centre}: {radius}");
        assert!(point.x > centre.x, "on the side facing the eye");
        let miss = ray_through(&d, Vec3::new(500.0, 0.0, 3.0 * radius));
        assert!(crate::reference::pick(&regions.scene, miss).unwrap().is_none());
    }

    #[test]
    fn the_probe_names_the_voxel_its_value_and_its_label() {
        // The head phantom's labels: the first visible voxel along the ray is labelled;
        // the probe gives its indices, its value (the label id) and its name.
        let (regions, d) = scene_of("(datasets: [(source: PhantomLabels(resolution: 32), appearance: (labels: Some(())))])");
        let hit = crate::reference::pick(&regions.scene, ray_through(&d, Vec3::ZERO)).unwrap().expect("the head is hit");
        let text = describe(&regions, &hit, &d).unwrap();
        let (_, point) = dataset_point(&regions, &hit).unwrap();
        let q = d.volume.grid.world_to_index().transform_point3(point).round().as_uvec3();
        let id = d.volume.code(q.x, q.y, q.z);
        let name = d.labels.as_ref().unwrap().name(id as u32).to_string();
        assert!(text.contains(&format!("voxel ({}, {}, {}): {id}", q.x, q.y, q.z)), "{text}");
        assert!(id > 0 && text.ends_with(&format!("label {id} {name}")), "{text}");
    }
}
