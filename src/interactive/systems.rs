//! The system that sets each interactive view's resolution.

use bevy::prelude::*;

use super::view::{InteractiveResolution, Shown};
use crate::dataset::view::Accumulate;
use crate::dataset::{SceneRegions, VolumeView};
use crate::lens::systems::ViewLenses;
use crate::streaming::bricked::StreamStatus;

/// What the system reads and sets of a view.
type AdaptedView = (
    Entity,
    &'static mut InteractiveResolution,
    &'static mut VolumeView,
    &'static GlobalTransform,
    &'static Camera,
    Option<&'static ViewLenses>,
    Option<&'static Accumulate>,
);

/// Sets [`VolumeView::resolution`] of every view with an enabled
/// [`InteractiveResolution`] from the frame just measured (`Time<Real>`'s delta) and
/// whether what it shows changed; at rest at every pixel, averages jittered frames
/// ([`Accumulate`], each frame's jitter seeded by its index).
pub fn adapt_resolution(
    mut commands: Commands,
    time: Res<Time<Real>>,
    regions: Res<SceneRegions>,
    streaming: Option<Res<StreamStatus>>,
    mut views: Query<AdaptedView>,
) {
    let frame_ms = time.delta_secs() * 1000.0;
    for (entity, mut adapt, mut view, transform, camera, lenses, accumulating) in &mut views {
        let shown = Shown {
            camera: transform.to_matrix(),
            projection: camera.clip_from_view(),
            pixels: camera.physical_viewport_size(),
            switches: VolumeView { resolution: 1.0, frame: 0, ..*view },
            lenses: lenses.cloned(),
            scene: regions.scene.clone(),
        };
        let state = adapt.bypass_change_detection();
        // (The first frame a view shows is no movement. What is compared is what the
        // view showed when it last moved, so a slow drift adds up to a movement.)
        let moved = state.last.as_ref().and_then(|last| shown.what_moved(last));
        let changed = moved.is_some();
        if changed || state.last.is_none() {
            state.last = Some(shown);
        }
        // (Nothing watches this component's changes: the system's own bookkeeping
        // bypasses them.)
        let next = state.step(changed, frame_ms);
        if state.moving != next.1 {
            let what = if next.1 { format!("moving ({})", moved.unwrap_or("")) } else { "at rest".into() };
            debug!("view {entity}: {what}, rays at {:.0} % of the pixels per axis", next.0 * 100.0);
        }
        (state.scale, state.moving) = next;
        if view.resolution != state.scale {
            view.resolution = state.scale;
        }
        // (Bricks arriving change the picture of a view at rest: its average starts anew.)
        let counts = streaming.as_ref().map(|s| s.counts());
        if state.last_stream != counts {
            state.last_stream = counts;
            state.still_frames = 0;
        }
        match state.accumulation(view.jitter) {
            Some(a) => {
                if view.frame != a.index {
                    view.frame = a.index;
                }
                commands.entity(entity).insert(a);
            }
            None => {
                if accumulating.is_some() {
                    commands.entity(entity).remove::<Accumulate>();
                    view.frame = 0;
                }
            }
        }
    }
}
