//! What lies under the cursor in the 3D view: the first visible point along the
//! cursor's ray (through the lenses), picked on the CPU with the reference renderer again
//! only when the cursor, the lenses or the scene change. The value probe shows the
//! dataset, the voxel and its value (and label) there at the top left of the 3D view;
//! the streaming status line looks the level drawn there up in the frame's bricks.
//! (On a streamed dataset the pick sees the level in memory.)

use bevy::prelude::*;
use bevy::window::PrimaryWindow;
use bevy_egui::{EguiContexts, egui};

use super::orbit::PointerInViewport;
use super::slice_views::SliceViews;
use super::state::MainCamera;
use super::viewport::viewport_logical;
use crate::dataset::SceneRegions;
use crate::lens::ViewLenses;
use crate::lens::stack::lens_ray;
use crate::reference::Hit;

/// The first visible point under the cursor.
#[derive(Resource, Default)]
pub struct UnderCursor {
    /// The ray's pixel (viewport pixels) and the lenses the hit was picked under.
    picked_for: Option<(Vec2, Vec<crate::lens::stack::ResolvedLens>)>,
    /// The scene volume and its voxel index (continuous) there.
    pub hit: Option<(usize, Vec3)>,
    /// What the probe says of it.
    pub probe: Option<String>,
}

/// Picks the point under the cursor when the cursor, the lenses or the scene changed.
pub fn pick_under_cursor(
    windows: Query<&Window, With<PrimaryWindow>>,
    pointer: Res<PointerInViewport>,
    cams: Query<(&Camera, &ViewLenses), With<MainCamera>>,
    regions: Res<SceneRegions>,
    datasets: Query<&crate::dataset::Dataset>,
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
    let stale =
        regions.is_changed() || under.picked_for.as_ref().is_none_or(|(at, picked)| at.distance(cursor) > 0.5 || *picked != lenses.lenses);
    if !stale {
        return;
    }
    let (px, py) = (cursor.x * screen.width / size.x.max(1.0), cursor.y * screen.height / size.y.max(1.0));
    let hit = lens_ray(&view, screen, &lenses.lenses, px, py).and_then(|ray| crate::reference::pick(&regions.scene, ray).ok().flatten());
    under.hit = hit.as_ref().and_then(|h| {
        let region = regions.scene.regions.get(h.region)?;
        Some((region.volume, region.world_to_voxel.transform_point3(h.position)))
    });
    // (Label names from the dataset's own table: a label volume's.)
    let name = |volume: usize, id: u32| {
        let dataset = datasets.get(*regions.datasets.get(volume)?).ok()?;
        Some(dataset.labels.as_ref()?.name(id).to_string())
    };
    under.probe = hit.as_ref().and_then(|h| describe(&regions, h, name));
    under.picked_for = Some((cursor, lenses.lenses.clone()));
}

/// "name · voxel (i, j, k): value units, label id name" of the voxel nearest a hit
/// (`name(volume, id)`: a label's name).
pub fn describe(regions: &SceneRegions, hit: &Hit, name: impl Fn(usize, u32) -> Option<String>) -> Option<String> {
    let scene = &regions.scene;
    let region = scene.regions.get(hit.region)?;
    let volume = scene.volumes.get(region.volume)?;
    let q = region.world_to_voxel.transform_point3(hit.position);
    let voxel = q.round().max(Vec3::ZERO).min(volume.dims().as_vec3() - 1.0).as_uvec3();
    let value = volume.values.to_real(volume.code(voxel.x, voxel.y, voxel.z) as f64);
    let units = volume.values.units.as_deref().map(|u| format!(" {u}")).unwrap_or_default();
    let label = crate::reference::label_at(scene, hit)
        .map(|id| match name(region.volume, id) {
            Some(n) => format!(", label {id} {n}"),
            None => format!(", label {id}"),
        })
        .unwrap_or_default();
    Some(format!("{} · voxel ({}, {}, {}): {value}{units}{label}", volume.name, voxel.x, voxel.y, voxel.z))
}

/// The probe at the top left of the 3D view (the slice views' own probe, when the cursor
/// is over a slice, takes its place).
pub fn probe_text(
    mut contexts: EguiContexts,
    under: Res<UnderCursor>,
    views: Res<SliceViews>,
    windows: Query<&Window, With<PrimaryWindow>>,
    cams: Query<&Camera, With<MainCamera>>,
) -> Result {
    let Some(text) = under.probe.as_ref().filter(|_| !(views.show && views.probe.is_some())) else { return Ok(()) };
    let (Ok(window), Ok(camera)) = (windows.single(), cams.single()) else { return Ok(()) };
    let ctx = contexts.ctx_mut()?.clone();
    let (origin, _) = viewport_logical(camera, window);
    ctx.layer_painter(egui::LayerId::new(egui::Order::Foreground, egui::Id::new("probe"))).text(
        egui::pos2(origin.x + 8.0, origin.y + 8.0),
        egui::Align2::LEFT_TOP,
        text,
        egui::FontId::monospace(13.0),
        egui::Color32::WHITE,
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::SceneFile;
    use crate::scene::load::{load_datasets, render_scene};

    #[test]
    fn the_probe_names_the_voxel_its_value_and_its_label() {
        // The head phantom's labels, seen along −x through the middle: the first visible
        // voxel is a labelled one; the probe gives its indices, its value (the label id)
        // and the name the closure gives.
        let scene = SceneFile::parse("(datasets: [(source: PhantomLabels(resolution: 32), appearance: (labels: Some(())))])", "t").unwrap();
        let datasets = load_datasets(&scene, std::path::Path::new(".")).unwrap();
        let regions = SceneRegions { scene: render_scene(&datasets, &scene), datasets: vec![Entity::from_raw_u32(1).unwrap()] };
        let grid = &datasets[0].volume.grid;
        let centre = grid.index_to_world().transform_point3((grid.dims.as_vec3() - 1.0) * 0.5);
        let ray = crate::region::Ray { origin: centre + Vec3::new(1000.0, 0.0, 0.0), dir: Vec3::NEG_X };
        let hit = crate::reference::pick(&regions.scene, ray).unwrap().expect("the head is hit");
        let text = describe(&regions, &hit, |volume, id| (volume == 0).then(|| format!("tissue{id}"))).unwrap();
        let q = regions.scene.regions[hit.region].world_to_voxel.transform_point3(hit.position).round().as_uvec3();
        let id = datasets[0].volume.code(q.x, q.y, q.z);
        assert!(text.contains(&format!("voxel ({}, {}, {}): {id}", q.x, q.y, q.z)), "{text}");
        assert!(id > 0 && text.ends_with(&format!("label {id} tissue{id}")), "{text}");
    }
}
