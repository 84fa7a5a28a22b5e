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
//!
//! A view that averages jittered frames at rest ([`Accumulate`]) also draws its rays
//! into such a texture (at every pixel), which is blended into its
//! [`AccumulationTarget`] (half floats, kept from frame to frame) with the frame's
//! weight as the blend constant, `a ← w·c + (1 − w)·a`; the average is then drawn over
//! the view.

use bevy::core_pipeline::FullscreenShader;
use bevy::prelude::*;
use bevy::render::camera::ExtractedCamera;
use bevy::render::render_resource::binding_types::{sampler, texture_2d};
use bevy::render::render_resource::*;
use bevy::render::renderer::RenderDevice;
use bevy::render::texture::{CachedTexture, TextureCache};
use bevy::render::view::{ExtractedView, ViewTarget};

use super::gpu_types::GpuSettings;
use crate::dataset::view::Accumulate;

/// The format of the averages of jittered frames.
pub const ACCUMULATION_FORMAT: TextureFormat = TextureFormat::Rgba16Float;

/// The size in pixels a view of `viewport` pixels draws its rays at for `resolution`
/// (rounded up, at least one pixel; the view's own size at 1 or above).
pub fn reduced_size(viewport: UVec2, resolution: f32) -> UVec2 {
    if resolution.is_nan() || resolution >= 1.0 {
        return viewport;
    }
    (viewport.as_vec2() * resolution.max(0.0)).ceil().as_uvec2().max(UVec2::ONE).min(viewport.max(UVec2::ONE))
}

/// The texture a reduced-resolution (or accumulating) view's rays are drawn into.
#[derive(Component)]
pub struct ReducedTarget {
    pub texture: CachedTexture,
    pub size: UVec2,
}

/// The average of an accumulating view's jittered frames, kept between frames, and how
/// many frames were blended into it: only frames the pass drew count, so an average is
/// never held before it has its frames (the main world's frame index runs on while a
/// pipeline compiles).
#[derive(Component)]
pub struct AccumulationTarget {
    pub texture: Texture,
    pub view: TextureView,
    pub size: UVec2,
    pub blended: BlendedFrames,
}

/// The count of frames blended into an average (set from the render pass, which reads
/// its view's components only).
#[derive(Default, Debug)]
pub struct BlendedFrames(std::sync::atomic::AtomicU32);

impl BlendedFrames {
    pub fn get(&self) -> u32 {
        self.0.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// One more frame in the average.
    pub fn add_one(&self) {
        self.0.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    }

    /// The average starts anew.
    pub fn restart(&self) {
        self.0.store(0, std::sync::atomic::Ordering::Relaxed);
    }
}

/// The pipeline that blends a view's rays into its [`AccumulationTarget`].
#[derive(Component)]
pub struct AccumulatePipelineId(pub CachedRenderPipelineId);

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

/// How the upscale pass blends: "over" the view, or into an average with the frame's
/// weight as the blend constant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Blend {
    Over,
    Average,
}

impl SpecializedRenderPipeline for UpscalePipeline {
    /// The target's colour format and the blending.
    type Key = (TextureFormat, Blend);

    fn specialize(&self, (format, blend): (TextureFormat, Blend)) -> RenderPipelineDescriptor {
        let weighted =
            BlendComponent { src_factor: BlendFactor::Constant, dst_factor: BlendFactor::OneMinusConstant, operation: BlendOperation::Add };
        let blend = match blend {
            Blend::Over => BlendState::PREMULTIPLIED_ALPHA_BLENDING,
            Blend::Average => BlendState { color: weighted, alpha: weighted },
        };
        RenderPipelineDescriptor {
            label: Some("focal_upscale_pipeline".into()),
            layout: vec![self.layout.clone()],
            vertex: self.fullscreen.to_vertex_state(),
            fragment: Some(FragmentState {
                shader: super::shaders::UPSCALE,
                targets: vec![Some(ColorTargetState { format, blend: Some(blend), write_mask: ColorWrites::ALL })],
                ..default()
            }),
            ..default()
        }
    }
}

/// The upscale pipeline of a view drawn at a reduced resolution.
#[derive(Component)]
pub struct UpscalePipelineId(pub CachedRenderPipelineId);

/// Gives every view drawn at a reduced resolution, or averaging jittered frames, its
/// [`ReducedTarget`] (of the view's colour format, so the ray caster's pipeline for the
/// view draws into it) and its upscale pipeline, and an averaging view its
/// [`AccumulationTarget`] and the pipeline into it; takes them from the others.
// A Bevy system: its parameters are the resources and queries it uses.
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub fn prepare_reduced_targets(
    mut commands: Commands,
    mut textures: ResMut<TextureCache>,
    device: Res<RenderDevice>,
    cache: Res<PipelineCache>,
    mut pipelines: ResMut<SpecializedRenderPipelines<UpscalePipeline>>,
    pipeline: Res<UpscalePipeline>,
    views: Query<
        (Entity, &ExtractedCamera, &ViewTarget, &GpuSettings, Option<&Accumulate>, Option<&AccumulationTarget>),
        With<ExtractedView>,
    >,
) {
    for (entity, camera, target, settings, accumulate, kept) in &views {
        // (Both pipelines are asked for from the view's first frame, so the app's
        // asynchronous compilation has them ready when the view first moves or rests: a
        // frame of an average drawn without its pipeline would be missing from it.)
        let format = target.main_texture_format();
        let over = pipelines.specialize(&cache, &pipeline, (format, Blend::Over));
        let average = pipelines.specialize(&cache, &pipeline, (ACCUMULATION_FORMAT, Blend::Average));
        let viewport = camera.physical_viewport_size.unwrap_or(UVec2::ONE);
        let size = reduced_size(viewport, settings.resolution);
        if accumulate.is_none() {
            commands.entity(entity).remove::<(AccumulationTarget, AccumulatePipelineId)>();
            if size == viewport {
                commands.entity(entity).remove::<(ReducedTarget, UpscalePipelineId)>();
                continue;
            }
        }
        let texture = textures.get(&device, target_descriptor("focal_reduced_rays", size, format));
        commands.entity(entity).insert((ReducedTarget { texture, size }, UpscalePipelineId(over)));
        if accumulate.is_some() {
            match kept {
                Some(k) if k.size == size => {
                    if accumulate.is_some_and(|a| a.index == 0) {
                        k.blended.restart();
                    }
                }
                _ => {
                    let texture = device.create_texture(&target_descriptor("focal_accumulated_rays", size, ACCUMULATION_FORMAT));
                    let view = texture.create_view(&TextureViewDescriptor::default());
                    commands.entity(entity).insert(AccumulationTarget { texture, view, size, blended: BlendedFrames::default() });
                }
            }
            commands.entity(entity).insert(AccumulatePipelineId(average));
        }
    }
}

/// A 2D texture the rays are drawn into and then sampled.
fn target_descriptor(label: &'static str, size: UVec2, format: TextureFormat) -> TextureDescriptor<'static> {
    TextureDescriptor {
        label: Some(label),
        size: Extent3d { width: size.x, height: size.y, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: TextureDimension::D2,
        format,
        usage: TextureUsages::RENDER_ATTACHMENT | TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
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

    /// The main world's frame index runs on while the pass cannot draw (a lens's
    /// pipeline compiling): the average holds only once its frames were blended, and
    /// is then their mean.
    #[test]
    fn an_average_holds_only_after_its_frames_were_blended() {
        let frame = Accumulate { index: 40, frames: 16 };
        let blended = BlendedFrames::default();
        assert!(!frame.holds(blended.get()), "an average of no frames is not held");
        let mut average = 0.0f32;
        for value in 0..16 {
            let w = Accumulate::weight(blended.get());
            average = w * value as f32 + (1.0 - w) * average;
            blended.add_one();
        }
        assert!((average - 7.5).abs() < 1e-5, "the mean of 0 … 15 is 7.5, not {average}");
        assert!(frame.holds(blended.get()));
        blended.restart();
        assert!(!frame.holds(blended.get()));
    }
}
