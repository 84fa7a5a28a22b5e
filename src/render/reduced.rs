//! Rays at a reduced resolution: a view whose [`GpuSettings::resolution`] is below 1
//! has the ray caster draw into a texture of that fraction of its pixels per axis
//! ([`ReducedTarget`], from Bevy's texture cache), which [`UpscalePipeline`] then draws
//! over the view, bilinearly filtered and blended "over" the meshes as the rays
//! themselves would be (`shaders/upscale.wgsl`). The cost of a frame follows its rays,
//! so half the resolution is about a quarter of the time: what
//! [`crate::interactive`] trades while the view moves. The rays take their footprint
//! from the pixels drawn (`pixel_steps` in `shaders/focal/lens.wgsl`), so bricked
//! volumes step at the level those pixels need, and the scene depth from the view's
//! own pixel under each one's centre.

use bevy::core_pipeline::FullscreenShader;
use bevy::prelude::*;
use bevy::render::camera::ExtractedCamera;
use bevy::render::render_resource::binding_types::{sampler, texture_2d};
use bevy::render::render_resource::*;
use bevy::render::renderer::RenderDevice;
use bevy::render::texture::{CachedTexture, TextureCache};
use bevy::render::view::{ExtractedView, ViewTarget};

use super::gpu_types::GpuSettings;

/// The size in pixels a view of `viewport` pixels draws its rays at for `resolution`
/// (rounded up, at least one pixel; the view's own size at 1 or above).
pub fn reduced_size(viewport: UVec2, resolution: f32) -> UVec2 {
    if resolution.is_nan() || resolution >= 1.0 {
        return viewport;
    }
    (viewport.as_vec2() * resolution.max(0.0)).ceil().as_uvec2().max(UVec2::ONE).min(viewport.max(UVec2::ONE))
}

/// The texture a reduced-resolution view's rays are drawn into.
#[derive(Component)]
pub struct ReducedTarget {
    pub texture: CachedTexture,
    pub size: UVec2,
}

/// The pass that draws a [`ReducedTarget`] over its view.
#[derive(Resource)]
pub struct UpscalePipeline {
    pub layout: BindGroupLayoutDescriptor,
    pub sampler: Sampler,
    fullscreen: FullscreenShader,
}

pub fn init_upscale_pipeline(mut commands: Commands, device: Res<RenderDevice>, fullscreen: Res<FullscreenShader>) {
    let layout = BindGroupLayoutDescriptor::new(
        "focal_upscale_layout",
        &BindGroupLayoutEntries::sequential(
            ShaderStages::FRAGMENT,
            (texture_2d(TextureSampleType::Float { filterable: true }), sampler(SamplerBindingType::Filtering)),
        ),
    );
    let sampler = device.create_sampler(&SamplerDescriptor {
        label: Some("focal upscale sampler"),
        mag_filter: FilterMode::Linear,
        min_filter: FilterMode::Linear,
        address_mode_u: AddressMode::ClampToEdge,
        address_mode_v: AddressMode::ClampToEdge,
        ..default()
    });
    commands.insert_resource(UpscalePipeline { layout, sampler, fullscreen: fullscreen.clone() });
}

impl SpecializedRenderPipeline for UpscalePipeline {
    /// The view's colour format.
    type Key = TextureFormat;

    fn specialize(&self, format: TextureFormat) -> RenderPipelineDescriptor {
        RenderPipelineDescriptor {
            label: Some("focal_upscale_pipeline".into()),
            layout: vec![self.layout.clone()],
            vertex: self.fullscreen.to_vertex_state(),
            fragment: Some(FragmentState {
                shader: super::shaders::UPSCALE,
                targets: vec![Some(ColorTargetState {
                    format,
                    blend: Some(BlendState::PREMULTIPLIED_ALPHA_BLENDING),
                    write_mask: ColorWrites::ALL,
                })],
                ..default()
            }),
            ..default()
        }
    }
}

/// The upscale pipeline of a view drawn at a reduced resolution.
#[derive(Component)]
pub struct UpscalePipelineId(pub CachedRenderPipelineId);

/// Gives every view drawn at a reduced resolution its [`ReducedTarget`] (of the view's
/// colour format, so the ray caster's pipeline for the view draws into it) and its
/// upscale pipeline, and takes them from views drawn at full resolution.
pub fn prepare_reduced_targets(
    mut commands: Commands,
    mut textures: ResMut<TextureCache>,
    device: Res<RenderDevice>,
    cache: Res<PipelineCache>,
    mut pipelines: ResMut<SpecializedRenderPipelines<UpscalePipeline>>,
    pipeline: Res<UpscalePipeline>,
    views: Query<(Entity, &ExtractedCamera, &ViewTarget, &GpuSettings), With<ExtractedView>>,
) {
    for (entity, camera, target, settings) in &views {
        let viewport = camera.physical_viewport_size.unwrap_or(UVec2::ONE);
        let size = reduced_size(viewport, settings.resolution);
        if size == viewport {
            commands.entity(entity).remove::<(ReducedTarget, UpscalePipelineId)>();
            continue;
        }
        let format = target.main_texture_format();
        let texture = textures.get(
            &device,
            TextureDescriptor {
                label: Some("focal_reduced_rays"),
                size: Extent3d { width: size.x, height: size.y, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: TextureDimension::D2,
                format,
                usage: TextureUsages::RENDER_ATTACHMENT | TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
        );
        let id = pipelines.specialize(&cache, &pipeline, format);
        commands.entity(entity).insert((ReducedTarget { texture, size }, UpscalePipelineId(id)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reduced_sizes_round_up_and_stay_within_the_view() {
        assert_eq!(reduced_size(UVec2::new(800, 600), 1.0), UVec2::new(800, 600));
        assert_eq!(reduced_size(UVec2::new(800, 600), 1.5), UVec2::new(800, 600));
        assert_eq!(reduced_size(UVec2::new(800, 600), f32::NAN), UVec2::new(800, 600));
        assert_eq!(reduced_size(UVec2::new(800, 600), 0.5), UVec2::new(400, 300));
        // 801 · 0.25 = 200.25: 201 pixels, so the drawn pixels cover the view.
        assert_eq!(reduced_size(UVec2::new(801, 3), 0.25), UVec2::new(201, 1));
        assert_eq!(reduced_size(UVec2::new(10, 10), 0.0), UVec2::ONE);
    }
}
