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
use super::reduced::{AccumulatePipelineId, AccumulationTarget, ReducedTarget, UpscalePipeline, UpscalePipelineId};
use super::upload::GpuScene;
use crate::dataset::view::Accumulate;

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
        Option<(&ReducedTarget, &UpscalePipelineId)>,
        Option<(&AccumulationTarget, &AccumulatePipelineId, &Accumulate)>,
    )>,
    pipeline: Res<RaycastPipeline>,
    upscale: Res<UpscalePipeline>,
    feature_pipelines: Res<FeaturePipelines>,
    cache: Res<PipelineCache>,
    view_uniforms: Res<ViewUniforms>,
    settings: Res<ComponentUniforms<GpuSettings>>,
    scene: Res<GpuScene>,
    bricks: Res<super::bricked::atlas::BrickAtlas>,
    progress: Res<super::progress::RenderProgress>,
    mut ctx: RenderContext,
) {
    let (target, depth, view_offset, settings_index, pipeline_id, camera, fields, reduced, accumulation) = view.into_inner();
    if scene.region_count == 0 || !scene.ready() {
        return;
    }
    let (Some(render_pipeline), Some(view_binding), Some(settings_binding)) =
        (cache.get_render_pipeline(pipeline_id.0), view_uniforms.uniforms.binding(), settings.uniforms().binding())
    else {
        return;
    };
    let (Some(info), Some(regions), Some(planes), Some(occupancy), Some((_, lut)), Some(atlases), Some(uniform)) =
        (&scene.info, &scene.regions, &scene.planes, &scene.occupancy, &scene.lut, &scene.atlases, &scene.uniform)
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
            uniform.regions.as_entire_binding(),
            uniform.planes.as_entire_binding(),
            uniform.occupancy.as_entire_binding(),
        )),
    );
    // A view drawn at a reduced resolution: the rays into its smaller texture (cleared,
    // the whole of it), then that texture over the view (at full resolution until the
    // upscale pipeline is ready).
    let upscaled = reduced.and_then(|(reduced, id)| Some((reduced, cache.get_render_pipeline(id.0)?)));
    // An averaging view: this frame into the average with its weight (none once the
    // average is complete and held), then the average over the view.
    let averaged = upscaled.and(accumulation.and_then(|(a, id, frame)| Some((a, cache.get_render_pipeline(id.0)?, frame))));
    let hold = averaged.is_some_and(|(average, _, frame)| frame.holds(average.blended.get()));
    let diagnostics = ctx.diagnostic_recorder();
    let diagnostics = diagnostics.as_deref();
    if !hold {
        let (view, load) = match upscaled {
            Some((reduced, _)) => (&reduced.texture.default_view, LoadOp::Clear(Default::default())),
            None => (target.main_texture_view(), LoadOp::Load),
        };
        let mut pass = ctx.command_encoder().begin_render_pass(&RenderPassDescriptor {
            label: Some("focal_raycast_pass"),
            color_attachments: &[Some(RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: Operations { load, store: StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        if let (None, Some([x, y, w, h, near, far])) = (upscaled, camera_viewport(camera)) {
            pass.set_viewport(x, y, w, h, near, far);
        }
        let span = diagnostics.pass_span(&mut pass, "focal_raycast");
        pass.set_pipeline(render_pipeline);
        pass.set_bind_group(0, &bind_group, &[view_offset.offset, settings_index.index()]);
        pass.draw(0..3, 0..1);
        span.end(&mut pass);
    }
    if let Some((reduced, upscale_pipeline)) = upscaled {
        let mut source = &reduced.texture.default_view;
        if let Some((average, average_pipeline, _)) = averaged {
            if !hold {
                let weight = Some(Accumulate::weight(average.blended.get()));
                let into = Drawn { source, target: &average.view, pipeline: average_pipeline, viewport: None, weight };
                draw_texture(&mut ctx, &upscale, &cache, into, "focal_accumulate");
                average.blended.add_one();
            }
            source = &average.view;
        }
        let over = Drawn {
            source,
            target: target.main_texture_view(),
            pipeline: upscale_pipeline,
            viewport: camera_viewport(camera),
            weight: None,
        };
        draw_texture(&mut ctx, &upscale, &cache, over, "focal_upscale");
    }
    progress.count_draw();
}

/// A texture drawn onto another by the upscale pipeline.
struct Drawn<'a> {
    source: &'a TextureView,
    target: &'a TextureView,
    pipeline: &'a RenderPipeline,
    /// Where on the target (the whole of it when `None`).
    viewport: Option<[f32; 6]>,
    /// The blend constant of a weighted average.
    weight: Option<f32>,
}

/// Draws `drawn.source` over (or into) `drawn.target`, timed as `label`.
fn draw_texture(ctx: &mut RenderContext, upscale: &UpscalePipeline, cache: &PipelineCache, drawn: Drawn, label: &'static str) {
    let bind_group = ctx.render_device().create_bind_group(
        "focal_upscale_bind_group",
        &cache.get_bind_group_layout(&upscale.layout),
        &BindGroupEntries::sequential((drawn.source, &upscale.sampler)),
    );
    let diagnostics = ctx.diagnostic_recorder();
    let diagnostics = diagnostics.as_deref();
    let mut pass = ctx.command_encoder().begin_render_pass(&RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(RenderPassColorAttachment {
            view: drawn.target,
            depth_slice: None,
            resolve_target: None,
            ops: Operations { load: LoadOp::Load, store: StoreOp::Store },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    if let Some([x, y, w, h, near, far]) = drawn.viewport {
        pass.set_viewport(x, y, w, h, near, far);
    }
    if let Some(w) = drawn.weight {
        pass.set_blend_constant(LinearRgba::new(w, w, w, w).into());
    }
    let span = diagnostics.pass_span(&mut pass, label);
    pass.set_pipeline(drawn.pipeline);
    pass.set_bind_group(0, &bind_group, &[]);
    pass.draw(0..3, 0..1);
    span.end(&mut pass);
}

/// The viewport of a camera limited to part of its target (the app's viewport beside
/// the panels), as `set_viewport` takes it: the full-screen triangle then spans just
/// that part.
fn camera_viewport(camera: Option<&ExtractedCamera>) -> Option<[f32; 6]> {
    let v = camera?.viewport.as_ref()?;
    let (p, s) = (v.physical_position.as_vec2(), v.physical_size.as_vec2());
    Some([p.x, p.y, s.x, s.y, v.depth.start, v.depth.end])
}
