//! What streaming is doing, in a line at the bottom left of the viewport while a bricked
//! dataset is shown: bricks wanted and in memory, loading, on the GPU, not yet uploaded,
//! failed, the finest level the views ask for and the level drawn under the cursor
//! (yellow while the picture is still converging, grey once it has).
//!
//! The level under the cursor is that of the first visible point along the cursor's
//! ray (through the lenses, picked on the CPU from the coarse level, again only when
//! the cursor, the lenses or the scene change), looked up each frame in the bricks
//! drawn there ([`crate::streaming::bricked::BrickFrame::level_at`]): under a magnifier
//! it shows the native level once its bricks arrive.

use bevy::prelude::*;
use bevy::window::PrimaryWindow;
use bevy_egui::{EguiContexts, egui};

use super::orbit::PointerInViewport;
use super::state::MainCamera;
use super::viewport::viewport_logical;
use crate::dataset::SceneRegions;
use crate::lens::ViewLenses;
use crate::lens::stack::lens_ray;
use crate::streaming::bricked::{BrickedScene, StreamStatus};

/// The level drawn at the first visible point under the cursor.
#[derive(Resource, Default)]
pub struct LevelUnderCursor {
    /// The ray's pixel (viewport pixels) and the lenses the hit was picked under.
    picked_for: Option<(Vec2, Vec<crate::lens::stack::ResolvedLens>)>,
    /// The hit: the scene volume and its coarse voxel index there.
    hit: Option<(usize, Vec3)>,
    pub level: Option<usize>,
}

/// Picks the point under the cursor when the cursor, the lenses or the scene changed and
/// looks its level up in this frame's bricks.
pub fn level_under_cursor(
    windows: Query<&Window, With<PrimaryWindow>>,
    pointer: Res<PointerInViewport>,
    cams: Query<(&Camera, &ViewLenses), With<MainCamera>>,
    regions: Res<SceneRegions>,
    bricked: Res<BrickedScene>,
    mut under: ResMut<LevelUnderCursor>,
) {
    let any_bricked = bricked.volumes.iter().any(Option::is_some);
    let (Ok(window), Ok((camera, lenses))) = (windows.single(), cams.single()) else { return };
    let (origin, size) = viewport_logical(camera, window);
    let cursor = window.cursor_position().filter(|_| pointer.inside && any_bricked).map(|c| c - origin);
    let (Some(cursor), Some(view), Some(screen)) = (cursor, lenses.camera, lenses.screen) else {
        *under = LevelUnderCursor::default();
        return;
    };
    let stale =
        regions.is_changed() || under.picked_for.as_ref().is_none_or(|(at, picked)| at.distance(cursor) > 0.5 || *picked != lenses.lenses);
    if stale {
        let (px, py) = (cursor.x * screen.width / size.x.max(1.0), cursor.y * screen.height / size.y.max(1.0));
        let hit = lens_ray(&view, screen, &lenses.lenses, px, py)
            .and_then(|ray| crate::reference::pick(&regions.scene, ray).ok().flatten())
            .and_then(|hit| {
                let region = regions.scene.regions.get(hit.region)?;
                Some((region.volume, region.world_to_voxel.transform_point3(hit.position)))
            });
        under.hit = hit;
        under.picked_for = Some((cursor, lenses.lenses.clone()));
    }
    let level = under.hit.and_then(|(v, q)| bricked.volumes.get(v)?.as_ref()?.level_at(q));
    if under.level != level {
        under.level = level;
    }
}

pub fn streaming_status(
    mut contexts: EguiContexts,
    status: Option<Res<StreamStatus>>,
    under: Option<Res<LevelUnderCursor>>,
    windows: Query<&Window, With<PrimaryWindow>>,
    cams: Query<&Camera, With<MainCamera>>,
) -> Result {
    let Some(status) = status else { return Ok(()) };
    let c = status.counts();
    if c.bricked == 0 {
        return Ok(());
    }
    let ctx = contexts.ctx_mut()?.clone();
    let converged = status.converged();
    let mut text = format!("streaming: {}/{} bricks in memory, {} on the GPU", c.resident.min(c.wanted), c.wanted, c.on_gpu);
    if c.pending > 0 {
        text += &format!(", {} loading", c.pending);
    }
    if c.not_uploaded > 0 {
        text += &format!(", {} to upload", c.not_uploaded);
    }
    if c.failed > 0 {
        text += &format!(", {} failed (drawn coarser)", c.failed);
    }
    if let Some(l) = c.finest_wanted {
        text += &format!("; finest level {l}");
    }
    if let Some(l) = under.and_then(|u| u.level) {
        text += &format!(", level {l} under the cursor");
    }
    let color = if converged { egui::Color32::GRAY } else { egui::Color32::YELLOW };
    // The 3D viewport (beside the panels), in egui points.
    let rect = match (windows.single(), cams.single()) {
        (Ok(window), Ok(camera)) => {
            let (origin, size) = viewport_logical(camera, window);
            egui::Rect::from_min_size(egui::pos2(origin.x, origin.y), egui::vec2(size.x, size.y))
        }
        _ => ctx.viewport_rect(),
    };
    let margin = 8.0;
    egui::Area::new("streaming status".into())
        .pivot(egui::Align2::LEFT_BOTTOM)
        .fixed_pos(rect.left_bottom() + egui::vec2(margin, -margin))
        .interactable(false)
        .constrain_to(rect)
        .show(&ctx, |ui| {
            ui.set_max_width((rect.width() - 2.0 * margin).max(1.0));
            ui.label(egui::RichText::new(text).color(color).small().monospace());
        });
    Ok(())
}
