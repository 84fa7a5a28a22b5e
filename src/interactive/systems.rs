//! The system that sets each interactive view's resolution.

use bevy::prelude::*;

use super::view::{InteractiveResolution, Shown};
use crate::dataset::{SceneRegions, VolumeView};
use crate::lens::systems::ViewLenses;

/// Sets [`VolumeView::resolution`] of every view with an enabled
/// [`InteractiveResolution`] from the frame just measured (`Time<Real>`'s delta) and
/// whether what it shows changed.
pub fn adapt_resolution(
    time: Res<Time<Real>>,
    regions: Res<SceneRegions>,
    mut views: Query<(&mut InteractiveResolution, &mut VolumeView, &GlobalTransform, &Camera, Option<&ViewLenses>)>,
) {
    let frame_ms = time.delta_secs() * 1000.0;
    for (mut adapt, mut view, transform, camera, lenses) in &mut views {
        let shown = Shown {
            camera: transform.to_matrix(),
            projection: camera.clip_from_view(),
            lenses: lenses.cloned(),
            scene: regions.scene.clone(),
        };
        let state = adapt.bypass_change_detection();
        // (The first frame a view shows is no movement.)
        let changed = state.last.as_ref().is_some_and(|last| *last != shown);
        if state.last.as_ref() != Some(&shown) {
            state.last = Some(shown);
        }
        let next = state.step(changed, frame_ms);
        let differs = (state.scale, state.moving) != next;
        (state.scale, state.moving) = next;
        let scale = state.scale;
        if differs {
            adapt.set_changed();
        }
        if view.resolution != scale {
            view.resolution = scale;
        }
    }
}
