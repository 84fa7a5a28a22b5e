//! Streaming: datasets larger than memory and the GPU, drawn from a resolution pyramid
//! brick by brick (issue 23).
//!
//! - [`bricked`]: a bricked dataset (its coarse level whole, finer levels as bricks
//!   through a cache), budgets, what the renderer is told each frame, the status;
//! - [`select`]: the bricks each view wants, from pixel footprints through every region
//!   that shows the volume and the magnification of lenses over it;
//! - [`systems`]: each frame, asking the cache and publishing the bricks to draw;
//! - [`unchanged`]: a volume's last frame kept while nothing it depends on changed.
//!
//! The renderer (`render::bricked`) places the drawn bricks in its atlas within a
//! per-frame upload budget and builds the page table the ray caster samples through.

pub mod bricked;
pub mod select;
pub mod systems;
pub mod unchanged;

use bevy::prelude::*;

/// Streaming of bricked datasets.
pub struct StreamingPlugin;

impl Plugin for StreamingPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<bricked::StreamBudget>()
            .init_resource::<bricked::StreamStatus>()
            .init_resource::<bricked::BrickedScene>()
            .add_systems(PostUpdate, systems::data_boxes.before(crate::dataset::RegionSystems::Collect))
            .add_systems(
                PostUpdate,
                systems::stream_bricks.after(crate::dataset::RegionSystems::Modify).after(crate::lens::systems::resolve_view_lenses),
            );
    }
}
