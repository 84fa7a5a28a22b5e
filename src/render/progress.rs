//! How far the renderer has got, for automation that waits for a finished picture.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use bevy::prelude::*;

/// Render progress shared by the main and render worlds: how many times the ray-cast
/// pass has drawn volumes and whether every queued pipeline (ours, egui's, …) is built.
/// The app's automation waits for both before it takes a screenshot.
#[derive(Resource, Clone, Default)]
pub struct RenderProgress(std::sync::Arc<(AtomicU64, AtomicBool)>);

impl RenderProgress {
    pub fn volumes_drawn(&self) -> u64 {
        self.0.0.load(Ordering::Relaxed)
    }

    pub fn pipelines_settled(&self) -> bool {
        self.0.1.load(Ordering::Relaxed)
    }

    pub(crate) fn count_draw(&self) {
        self.0.0.fetch_add(1, Ordering::Relaxed);
    }
}

/// Records whether every queued pipeline is built (render world, each frame).
pub fn record_pipeline_state(progress: Res<RenderProgress>, cache: Res<bevy::render::render_resource::PipelineCache>) {
    progress.0.1.store(cache.waiting_pipelines().next().is_none(), Ordering::Relaxed);
}
