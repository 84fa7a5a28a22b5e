//! The ray-cast pass: a system in the `Core3d` schedule, one full-screen triangle per view.

use bevy::prelude::*;
use bevy::render::camera::ExtractedCamera;
use bevy::render::diagnostic::RecordDiagnostics;
use bevy::render::extract_component::{ComponentUniforms, DynamicUniformIndex};
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderContext, ViewQuery};
use bevy::render::view::{ViewDepthTexture, ViewTarget, ViewUniformOffset, ViewUniforms};

use super::feature_pass::{FeatureBuffers, FeaturePipelines, encode_feature_passes};
use super::gpu_types::GpuSettings;
use super::pipeline::{RaycastPipeline, RaycastPipelineId};
use super::upload::GpuScene;

// A Bevy system: its parameters are the resources and queries it uses, and a query's
// type names the components it reads; splitting them up would only hide that.
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub fn raycast_pass(
    view: ViewQuery<(
        &ViewTarget,
        &ViewDepthTexture,
        &ViewUniformOffset,
        &DynamicUniformIndex<GpuSettings>,
        &RaycastPipelineId,
        Option<&ExtractedCamera>,
        Option<&FeatureBuffers>,
    )>,
    pipeline: Res<RaycastPipeline>,
    feature_pipelines: Res<FeaturePipelines>,
    cache: Res<PipelineCache>,
    view_uniforms: Res<ViewUniforms>,
    settings: Res<ComponentUniforms<GpuSettings>>,
    scene: Res<GpuScene>,
    bricks: Res<super::bricked::atlas::BrickAtlas>,
    progress: Res<super::progress::RenderProgress>,
    mut ctx: RenderContext,
) {
    let (target, depth, view_offset, settings_index, pipeline_id, camera, fields) = view.into_inner();
    if scene.region_count == 0 || !scene.ready() {
        return;
    }
    let (Some(render_pipeline), Some(view_binding), Some(settings_binding)) =
        (cache.get_render_pipeline(pipeline_id.0), view_uniforms.uniforms.binding(), settings.uniforms().binding())
    else {
        return;
    };
    let (Some(info), Some(regions), Some(planes), Some(occupancy), Some((_, lut)), Some(atlases)) =
        (&scene.info, &scene.regions, &scene.planes, &scene.occupancy, &scene.lut, &scene.atlases)
    else {
        return;
    };
    let (Some(brick_view), Some(pages)) = (&bricks.view, &bricks.pages) else { return };
    // The feature lenses' silhouettes, found first where the GPU finds them.
    let Some(fields) = fields else { return };
    if !encode_feature_passes(&mut ctx, fields, &feature_pipelines, &cache, &scene, (view_binding.clone(), view_offset.offset)) {
        return;
    }
    let bind_group = ctx.render_device().create_bind_group(
        "focal_raycast_bind_group",
        &cache.get_bind_group_layout(&pipeline.layout),
        &BindGroupEntries::sequential((
            view_binding,
            settings_binding,
            info.as_entire_binding(),
            regions.as_entire_binding(),
            planes.as_entire_binding(),
            occupancy.as_entire_binding(),
            lut,
            &atlases.volumes,
            &atlases.bricks,
            &pipeline.sampler,
            depth.view(),
            fields.fields.as_entire_binding(),
            brick_view,
            pages.as_entire_binding(),
        )),
    );
    let diagnostics = ctx.diagnostic_recorder();
    let diagnostics = diagnostics.as_deref();
    let mut pass = ctx.command_encoder().begin_render_pass(&RenderPassDescriptor {
        label: Some("focal_raycast_pass"),
        color_attachments: &[Some(RenderPassColorAttachment {
            view: target.main_texture_view(),
            depth_slice: None,
            resolve_target: None,
            ops: Operations { load: LoadOp::Load, store: StoreOp::Store },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    // A camera limited to part of its target (the app's viewport beside the panels):
    // the full-screen triangle then spans just that part.
    if let Some(v) = camera.and_then(|c| c.viewport.as_ref()) {
        let (p, s) = (v.physical_position.as_vec2(), v.physical_size.as_vec2());
        pass.set_viewport(p.x, p.y, s.x, s.y, v.depth.start, v.depth.end);
    }
    let span = diagnostics.pass_span(&mut pass, "focal_raycast");
    pass.set_pipeline(render_pipeline);
    pass.set_bind_group(0, &bind_group, &[view_offset.offset, settings_index.index()]);
    pass.draw(0..3, 0..1);
    span.end(&mut pass);
    progress.count_draw();
}
