//! Main world → render world: the scene regions and the per-view settings.

use bevy::prelude::*;
use bevy::render::Extract;
use bevy::render::extract_component::ExtractComponent;
use bevy::render::render_resource::TextureUsages;
use bevy::render::sync_component::SyncComponent;

use super::gpu_types::{GpuSettings, view_flags};
use crate::dataset::view::Accumulate;
use crate::dataset::{SceneRegions, VolumeView};
use crate::region::{Light, RenderScene};
use crate::streaming::bricked::{BrickFrame, BrickedScene, StreamBudget};

impl SyncComponent for VolumeView {
    type Target = GpuSettings;
}

impl SyncComponent for Accumulate {
    type Target = Accumulate;
}

impl ExtractComponent for Accumulate {
    type QueryData = &'static Accumulate;
    type QueryFilter = With<Camera3d>;
    type Out = Accumulate;

    fn extract_component(a: &Accumulate) -> Option<Accumulate> {
        Some(*a)
    }
}

impl ExtractComponent for VolumeView {
    type QueryData = (&'static VolumeView, Option<&'static crate::lens::ViewLenses>);
    type QueryFilter = With<Camera3d>;
    type Out = GpuSettings;

    fn extract_component((v, lenses): (&VolumeView, Option<&crate::lens::ViewLenses>)) -> Option<GpuSettings> {
        let mut flags = 0;
        if v.jitter {
            flags |= view_flags::JITTER;
        }
        if v.skip_empty {
            flags |= view_flags::SKIP_EMPTY;
        }
        if v.early_termination {
            flags |= view_flags::EARLY_TERMINATION;
        }
        if v.debug_rays {
            flags |= view_flags::DEBUG_RAYS;
        }
        if v.debug_counts {
            flags |= view_flags::DEBUG_COUNTS;
        }
        if v.lens_antialias {
            flags |= view_flags::LENS_ANTIALIAS;
        }
        if v.lens_context_steps {
            flags |= view_flags::LENS_CONTEXT_STEPS;
        }
        let light = match v.light {
            Light::Headlight => Vec4::ZERO,
            Light::Direction(d) => d.normalize_or_zero().extend(1.0),
        };
        // (Counts are written per pixel of the view: upscaled they would be blends.)
        let resolution = if v.debug_counts { 1.0 } else { v.drawn_resolution() };
        let mut settings = GpuSettings { light, flags, frame: v.frame, resolution, ..Default::default() };
        if let Some(lenses) = lenses {
            super::lens_pack::pack_lenses(&mut settings, &lenses.lenses);
        }
        Some(settings)
    }
}

/// The main depth texture must be bindable so the pass can read it.
pub fn request_depth_binding(mut cams: Query<(&mut Camera3d, &mut VolumeView)>, light: Res<crate::dataset::SceneLight>) {
    for (mut cam, mut view) in &mut cams {
        let usage = TextureUsages::RENDER_ATTACHMENT | TextureUsages::TEXTURE_BINDING;
        if cam.depth_texture_usages.0 != usage.bits() {
            cam.depth_texture_usages = usage.into();
        }
        if view.light != light.0 {
            view.light = light.0;
        }
    }
}

/// The scene as the render world sees it.
#[derive(Resource, Clone, Default)]
pub struct ExtractedScene {
    pub scene: RenderScene,
    /// The bricked frame of each of the scene's volumes (`None`: in memory).
    pub bricked: Vec<Option<BrickFrame>>,
    pub budget: StreamBudget,
    /// What the main world fits datasets to (the device's limits, lowered after a
    /// refusal): the packing keeps to it too.
    pub limits: crate::dataset::gpu_fit::GpuLimits,
}

/// Copies the scene regions into the render world (shared volumes, small vectors), and
/// what streaming drew.
pub fn extract_scene(
    mut commands: Commands,
    scene: Extract<Res<SceneRegions>>,
    bricked: Extract<Option<Res<BrickedScene>>>,
    budget: Extract<Option<Res<StreamBudget>>>,
    limits: Extract<Option<Res<crate::dataset::gpu_fit::GpuLimits>>>,
) {
    commands.insert_resource(ExtractedScene {
        scene: scene.scene.clone(),
        bricked: bricked.as_ref().map(|b| b.volumes.clone()).unwrap_or_default(),
        budget: budget.as_deref().copied().unwrap_or_default(),
        limits: limits.as_deref().copied().unwrap_or_default(),
    });
}
