//! What streaming is doing, in a line at the bottom left of the viewport while a bricked
//! dataset is shown: bricks wanted and in memory, loading, on the GPU, not yet uploaded,
//! failed, and the finest level the views ask for (yellow while the picture is still
//! converging, grey once it has).

use bevy::prelude::*;
use bevy_egui::{EguiContexts, egui};

use crate::streaming::bricked::StreamStatus;

pub fn streaming_status(mut contexts: EguiContexts, status: Option<Res<StreamStatus>>) -> Result {
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
    let color = if converged { egui::Color32::GRAY } else { egui::Color32::YELLOW };
    let rect = ctx.viewport_rect();
    egui::Area::new("streaming status".into())
        .anchor(egui::Align2::LEFT_BOTTOM, egui::vec2(8.0, -8.0))
        .interactable(false)
        .constrain_to(rect)
        .show(&ctx, |ui| {
            ui.label(egui::RichText::new(text).color(color).small().monospace());
        });
    Ok(())
}
