//! What streaming is doing, in a line at the bottom left of the viewport while a bricked
//! dataset is shown: bricks wanted and in memory, loading, on the GPU, not yet uploaded,
//! failed, the finest level the views ask for and the level drawn under the cursor
//! (yellow while the picture is still converging, grey once it has).
//!
//! The level under the cursor is that of the first visible point along the cursor's
//! ray ([`super::under_cursor`]), looked up each frame in the bricks drawn there
//! ([`crate::streaming::bricked::BrickFrame::level_at`]): under a magnifier it shows the
//! native level once its bricks arrive.

use bevy::prelude::*;
use bevy::window::PrimaryWindow;
use bevy_egui::{EguiContexts, egui};

use super::state::MainCamera;
use super::under_cursor::UnderCursor;
use super::viewport::viewport_rect;
use crate::streaming::bricked::{BrickedScene, StreamStatus};

pub fn streaming_status(
    mut contexts: EguiContexts,
    status: Option<Res<StreamStatus>>,
    under: Option<Res<UnderCursor>>,
    bricked: Option<Res<BrickedScene>>,
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
    let level = under.and_then(|u| u.hit).zip(bricked).and_then(|((v, q), b)| b.volumes.get(v)?.as_ref()?.level_at(q));
    if let Some(l) = level {
        text += &format!(", level {l} under the cursor");
    }
    let color = if converged { egui::Color32::GRAY } else { egui::Color32::YELLOW };
    // The 3D viewport (beside the panels), in egui points.
    let rect = viewport_rect(&ctx, &windows, &cams);
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
