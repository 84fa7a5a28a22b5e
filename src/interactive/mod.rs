//! Interactive resolution (issue 24): a view that moves draws its rays at a reduced
//! resolution chosen to hold a target frame time, and refines to every pixel once it
//! rests.
//!
//! A camera with [`InteractiveResolution`] has its [`crate::dataset::VolumeView::resolution`] set every
//! frame by [`systems::adapt_resolution`]: while what it shows changes (its camera, its
//! lenses, the scene's regions and looks: a drag, a slider, an explosion settling) the
//! scale follows [`controller::while_moving`] from the frames measured; once nothing
//! changed for [`InteractiveResolution::rest_ms`] it doubles every frame up to 1
//! ([`controller::at_rest`]). The renderer draws what the view asks for
//! (`render::reduced`); headless renders and scenes draw every pixel unless they ask.

pub mod controller;
pub mod systems;
pub mod view;

use bevy::prelude::*;

pub use view::InteractiveResolution;

/// Ordering: after the regions, lenses and cameras of the frame are final.
#[derive(SystemSet, Debug, Clone, PartialEq, Eq, Hash)]
pub struct InteractiveSystems;

/// Adapts the resolution of the views that carry [`InteractiveResolution`].
pub struct InteractivePlugin;

impl Plugin for InteractivePlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(
            PostUpdate,
            systems::adapt_resolution
                .in_set(InteractiveSystems)
                .after(crate::dataset::RegionSystems::Modify)
                .after(crate::lens::systems::resolve_view_lenses),
        );
    }
}
