//! Lens systems: each frame, the lenses of the world resolved for every volume camera.

use bevy::camera::CameraUpdateSystems;
use bevy::prelude::*;

use super::screen::Screen;
use super::spec::Lens;
use super::stack::{MAX_LENSES, ResolvedLens, Silhouettes, resolve_with};
use crate::dataset::{SceneRegions, VolumeView};
use crate::region::{Camera as FocalCamera, Projection as FocalProjection};

/// The lenses of one view, resolved for its camera this frame (in lens order).
#[derive(Component, Clone, Debug, Default, PartialEq)]
pub struct ViewLenses {
    pub lenses: Vec<ResolvedLens>,
    pub camera: Option<FocalCamera>,
    pub screen: Option<Screen>,
    /// Feature lenses were left to the GPU ([`VolumeView::gpu_silhouettes`]).
    pub gpu_silhouettes: bool,
}

impl ViewLenses {
    /// The lenses with every feature's silhouette found on the CPU (for overlays and
    /// read-outs; a feature out of view drops out).
    pub fn on_cpu(&self, scene: &crate::region::RenderScene) -> Vec<ResolvedLens> {
        let (Some(camera), Some(screen)) = (self.camera, self.screen) else { return Vec::new() };
        self.lenses.iter().filter_map(|l| l.clone().with_silhouette(&camera, screen, scene)).collect()
    }

    /// Whether a lens waits for the GPU's silhouette.
    pub fn has_gpu_silhouettes(&self) -> bool {
        self.lenses.iter().any(|l| l.job.is_some() && l.field.is_none())
    }
}

/// The Focal camera of a Bevy camera (`None` for custom projections).
pub fn focal_camera(transform: &GlobalTransform, projection: &Projection) -> Option<FocalCamera> {
    let projection = match projection {
        Projection::Perspective(p) => FocalProjection::Perspective { fov_y: p.fov },
        Projection::Orthographic(o) => {
            let height = match o.scaling_mode {
                _ if o.area.height() > 0.0 => o.area.height(),
                bevy::camera::ScalingMode::FixedVertical { viewport_height } => viewport_height * o.scale,
                _ => return None,
            };
            FocalProjection::Orthographic { height }
        }
        _ => return None,
    };
    let (_, rotation, position) = transform.to_scale_rotation_translation();
    Some(FocalCamera { position, rotation, projection })
}

/// Place of a lens in the stack (lower first, the last on top); lenses without it
/// follow in entity order.
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct LensOrder(pub u32);

/// Resolves the lenses for every volume camera whose camera, image size, lenses or
/// scene changed (a feature lens computes its silhouette then).
pub fn resolve_view_lenses(
    lenses: Query<(Entity, &Lens, Option<&LensOrder>)>,
    mut views: Query<(&Camera, &GlobalTransform, &Projection, &VolumeView, &mut ViewLenses)>,
    scene: Res<SceneRegions>,
    mut last: Local<Vec<Lens>>,
) {
    let mut ordered: Vec<(Entity, &Lens, Option<&LensOrder>)> =
        lenses.iter().filter(|(_, l, _)| l.enabled && l.validate().is_ok()).collect();
    ordered.sort_by_key(|(e, _, o)| (o.map_or(u32::MAX, |o| o.0), *e));
    ordered.truncate(MAX_LENSES);
    let current: Vec<Lens> = ordered.iter().map(|(_, l, _)| (*l).clone()).collect();
    let lenses_changed = *last != current;
    let mut all_resolved = true;
    for (camera, transform, projection, volume_view, mut view) in &mut views {
        let (Some(cam), Some(size)) = (focal_camera(transform, projection), camera.physical_viewport_size()) else {
            all_resolved = false;
            continue;
        };
        let screen = Screen::new(size.x, size.y);
        let gpu = volume_view.gpu_silhouettes;
        if !lenses_changed && !scene.is_changed() && view.camera == Some(cam) && view.screen == Some(screen) && view.gpu_silhouettes == gpu
        {
            continue;
        }
        let silhouettes = if gpu { Silhouettes::Gpu } else { Silhouettes::Cpu };
        let resolved: Vec<ResolvedLens> = current.iter().filter_map(|l| resolve_with(l, &cam, screen, &scene.scene, silhouettes)).collect();
        let next = ViewLenses { lenses: resolved, camera: Some(cam), screen: Some(screen), gpu_silhouettes: gpu };
        if *view != next {
            *view = next;
        }
    }
    // A view skipped this frame must see the change later.
    if all_resolved {
        *last = current;
    }
}

/// Replaces every lens entity of `world` with `lenses`, in stack order.
pub fn replace_lenses(world: &mut World, lenses: &[Lens]) {
    let old: Vec<Entity> = world.query_filtered::<Entity, With<Lens>>().iter(world).collect();
    for e in old {
        world.despawn(e);
    }
    for (i, lens) in lenses.iter().enumerate() {
        world.spawn((lens.clone(), LensOrder(i as u32), Name::new(format!("lens {}", lens.kind_name()))));
    }
}

/// Adds [`ViewLenses`] to every volume camera.
fn add_view_lenses(mut commands: Commands, views: Query<Entity, (With<VolumeView>, Without<ViewLenses>)>) {
    for e in &views {
        commands.entity(e).insert(ViewLenses::default());
    }
}

/// Lens resolution (no GPU needed).
pub struct LensPlugin;

impl Plugin for LensPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(
            PostUpdate,
            (add_view_lenses, resolve_view_lenses)
                .chain()
                .after(TransformSystems::Propagate)
                .after(CameraUpdateSystems)
                .after(crate::dataset::RegionSystems::Modify),
        );
    }
}
