//! The GPU ray caster: a render pass in Bevy 0.19's `Core3d` schedule.
//!
//! Main world: [`crate::dataset`] builds the [`SceneRegions`] every frame; cameras that
//! should show volumes carry a [`VolumeView`]. Render world:
//! - [`extract`] copies the scene (shared `Arc`s, small vectors) and each view's settings;
//! - [`upload`] packs the scene ([`pack`], reusing the CPU reference's preparation) into
//!   storage buffers and a lookup-table atlas, and uploads the volumes as 3D textures
//!   (`R8Unorm`; `R16Unorm`, or `R16Float` where 16-bit normalised formats are missing;
//!   `Rg8Unorm`, `Rg16Unorm` or `Rg16Float` when a selection rides in a second channel,
//!   [`pack::doi_channels`]) with their brick min-max grids (`Rg16Uint`), only when
//!   something changed;
//! - [`pass`] draws one full-screen triangle per view running `shaders/raycast.wgsl`,
//!   after the opaque and transparent main passes so it reads their depth, blending the
//!   premultiplied result over the meshes; a view drawn at a reduced resolution
//!   ([`reduced`]) has its rays drawn into a smaller texture, then upscaled over it.
//!
//! - [`health`] keeps what the device refused (uploads run inside error scopes; the
//!   limits are lowered and the datasets fitted again) and whether rendering stopped
//!   (a lost device), for the app and the headless renderer to act on.
//!
//! The renderer packs; it does not decide: what is drawn where is the techniques'
//! business (datasets, windows, exploded parts), expressed as regions.

pub mod bricked;
pub mod counts;
pub mod extract;
pub mod feature_pass;
pub mod gpu_types;
pub mod headless;
pub mod health;
pub mod lens_pack;
pub mod pack;
pub mod pass;
pub mod pipeline;
pub mod progress;
pub mod reduced;
pub mod shaders;
pub mod upload;

use bevy::core_pipeline::schedule::{Core3d, Core3dSystems};
use bevy::prelude::*;
use bevy::render::extract_component::{ExtractComponentPlugin, UniformComponentPlugin};
use bevy::render::renderer::RenderDevice;
use bevy::render::{Render, RenderApp, RenderStartup, RenderSystems};

pub use gpu_types::GpuSettings;
pub use progress::RenderProgress;

use crate::dataset::gpu_fit::{GpuLimits, fit_datasets};
use crate::dataset::{SceneRegions, VolumeView};
use progress::record_pipeline_state;

/// The volume ray caster.
pub struct VolumeRenderPlugin;

impl Plugin for VolumeRenderPlugin {
    fn build(&self, app: &mut App) {
        shaders::register(app);

        let progress = RenderProgress::default();
        let health = health::RenderHealth::default();
        app.init_resource::<GpuLimits>()
            .insert_resource(progress.clone())
            .insert_resource(health.clone())
            .insert_resource(health::error_handler())
            .init_resource::<health::GpuMessages>()
            .add_plugins((
                ExtractComponentPlugin::<VolumeView>::default(),
                ExtractComponentPlugin::<crate::lens::ViewLenses>::default(),
                ExtractComponentPlugin::<crate::dataset::view::Accumulate>::default(),
                UniformComponentPlugin::<GpuSettings>::default(),
            ))
            .add_systems(
                PostUpdate,
                (
                    extract::request_depth_binding,
                    (health::lower_limits_after_refusals, fit_datasets).chain().before(crate::dataset::RegionSystems::Collect),
                ),
            );

        let status = app.world().get_resource::<crate::streaming::bricked::StreamStatus>().cloned().unwrap_or_default();
        let Some(render_app) = app.get_sub_app_mut(RenderApp) else {
            return;
        };
        render_app
            .insert_resource(progress)
            .insert_resource(health)
            .insert_resource(status)
            .init_resource::<upload::GpuScene>()
            .init_resource::<bricked::atlas::BrickAtlas>()
            .init_resource::<bevy::render::render_resource::SpecializedRenderPipelines<pipeline::RaycastPipeline>>()
            .init_resource::<bevy::render::render_resource::SpecializedRenderPipelines<reduced::UpscalePipeline>>()
            .add_systems(bevy::render::ExtractSchedule, extract::extract_scene)
            .add_systems(RenderStartup, (pipeline::init_pipeline, feature_pass::init_feature_pipelines, reduced::init_upscale_pipeline))
            .add_systems(
                Render,
                (
                    upload::upload_scene.in_set(RenderSystems::PrepareResources),
                    bricked::atlas::upload_bricks.in_set(RenderSystems::PrepareResources).after(upload::upload_scene),
                    feature_pass::prepare_feature_buffers.in_set(RenderSystems::PrepareResources).after(upload::upload_scene),
                    pipeline::prepare_pipelines.in_set(RenderSystems::Prepare).after(bricked::atlas::upload_bricks),
                    reduced::prepare_reduced_targets.in_set(RenderSystems::PrepareResources),
                    record_pipeline_state.in_set(RenderSystems::Cleanup),
                ),
            )
            .add_systems(Core3d, pass::raycast_pass.after(Core3dSystems::MainPass).before(Core3dSystems::EarlyPostProcess));
    }

    fn finish(&self, app: &mut App) {
        // The device exists now: record its limits for fitting datasets.
        if let Some(device) = app.world().get_resource::<RenderDevice>() {
            let limits = device.limits();
            let max_bytes = GpuLimits::default().max_bytes.min(limits.max_buffer_size);
            app.insert_resource(GpuLimits { max_dimension: limits.max_texture_dimension_3d, max_bytes });
        }
        let _ = app.world().get_resource::<SceneRegions>();
    }
}
