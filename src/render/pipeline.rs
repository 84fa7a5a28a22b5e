//! The ray-cast pipeline: bind group layout, specialisation per target format.

use bevy::core_pipeline::FullscreenShader;
use bevy::prelude::*;
use bevy::render::render_resource::binding_types::{
    sampler, storage_buffer_read_only_sized, texture_2d, texture_3d, texture_depth_2d, uniform_buffer, uniform_buffer_sized,
};
use bevy::render::render_resource::*;
use bevy::render::renderer::RenderDevice;
use bevy::render::view::{ExtractedView, ViewTarget, ViewUniform};
use bevy::shader::Shader;

use super::gpu_types::{GpuLens, GpuSceneInfo, GpuSettings, features, lens_codes};

/// Pipeline state shared by every view.
#[derive(Resource)]
pub struct RaycastPipeline {
    pub layout: BindGroupLayoutDescriptor,
    pub sampler: Sampler,
    fullscreen: FullscreenShader,
    shader: Handle<Shader>,
}

pub fn init_pipeline(mut commands: Commands, device: Res<RenderDevice>, fullscreen: Res<FullscreenShader>) {
    let float = |filterable| TextureSampleType::Float { filterable };
    let layout = BindGroupLayoutDescriptor::new(
        "focal_raycast_layout",
        &BindGroupLayoutEntries::sequential(
            ShaderStages::FRAGMENT,
            (
                uniform_buffer::<ViewUniform>(true),
                uniform_buffer::<GpuSettings>(true),
                uniform_buffer::<GpuSceneInfo>(false),
                storage_buffer_read_only_sized(false, None),
                storage_buffer_read_only_sized(false, None),
                storage_buffer_read_only_sized(false, None),
                // (The lookup tables' bits: f32 colours, or 16-bit normalised pairs
                // of two looks; render::pack::pair_table.)
                texture_2d(TextureSampleType::Uint),
                texture_3d(float(true)),
                texture_3d(TextureSampleType::Uint),
                sampler(SamplerBindingType::Filtering),
                texture_depth_2d(),
                storage_buffer_read_only_sized(false, None),
                texture_3d(float(true)),
                storage_buffer_read_only_sized(false, None),
                // (The region records, the planes and the occupancy bits again, where
                // they fit: render::upload::UniformCopies.)
                uniform_buffer_sized(false, None),
                uniform_buffer_sized(false, None),
                uniform_buffer_sized(false, None),
            ),
        ),
    );
    let sampler = device.create_sampler(&SamplerDescriptor {
        label: Some("focal volume sampler"),
        mag_filter: FilterMode::Linear,
        min_filter: FilterMode::Linear,
        address_mode_u: AddressMode::ClampToEdge,
        address_mode_v: AddressMode::ClampToEdge,
        address_mode_w: AddressMode::ClampToEdge,
        ..default()
    });
    commands.insert_resource(RaycastPipeline { layout, sampler, fullscreen: fullscreen.clone(), shader: super::shaders::RAYCAST });
}

/// Pipeline variant: the view's colour format and the scene's shader features.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct RaycastKey {
    format: TextureFormat,
    features: u32,
}

impl SpecializedRenderPipeline for RaycastPipeline {
    type Key = RaycastKey;

    fn specialize(&self, key: RaycastKey) -> RenderPipelineDescriptor {
        RenderPipelineDescriptor {
            label: Some("focal_raycast_pipeline".into()),
            layout: vec![self.layout.clone()],
            vertex: self.fullscreen.to_vertex_state(),
            fragment: Some(FragmentState {
                shader: self.shader.clone(),
                shader_defs: features::NAMES
                    .iter()
                    .chain(&features::LENS_NAMES)
                    .filter(|(bit, _)| key.features & bit != 0)
                    .map(|(_, name)| (*name).into())
                    .collect(),
                targets: vec![Some(ColorTargetState {
                    format: key.format,
                    // Premultiplied "over" onto the meshes already drawn.
                    blend: Some(BlendState::PREMULTIPLIED_ALPHA_BLENDING),
                    write_mask: ColorWrites::ALL,
                })],
                ..default()
            }),
            ..default()
        }
    }
}

/// The pipeline of a view.
#[derive(Component)]
pub struct RaycastPipelineId(pub CachedRenderPipelineId);

/// The per-view features of a view over a scene of `features`: lenses, and their
/// anti-aliasing where the view asks for it and some region samples scalar values in
/// memory (`features::MIP_READS`: anti-aliasing samples in-memory volumes' mip chains;
/// a scene of bricked regions alone reads none, its rays take their level from their
/// footprint instead, and the lens footprint per pixel cost the bench's 4× magnifier
/// ×2.9 → ×1.9 for nothing; label volumes are read whole, and the feature lens over
/// the labelled head paid ×1.4 for nothing).
/// With them, the kinds and shapes of `lenses` ([`lens_kinds`]).
pub fn lens_features(features: u32, lenses: &[GpuLens], antialias: bool) -> u32 {
    let kinds = lens_kinds(lenses);
    match (lenses.is_empty(), antialias) {
        (true, _) => 0,
        (false, true) if features & features::MIP_READS != 0 => features::LENSES | features::LENS_ANTIALIAS | kinds,
        (false, _) => features::LENSES | kinds,
    }
}

/// The lens kinds and shapes among `lenses` (features::LENS_NAMES; circles and squares
/// are two lines of code and always there).
pub fn lens_kinds(lenses: &[GpuLens]) -> u32 {
    lenses.iter().fold(0, |bits, lens| {
        let kind = match lens.codes.x {
            lens_codes::SAMPLING => features::LENS_SAMPLING,
            lens_codes::ANGULAR => features::LENS_ANGULAR,
            _ => features::LENS_MAGNIFIER,
        };
        let shape = match lens.codes.y {
            lens_codes::POLYGON => features::LENS_POLYGON,
            lens_codes::FEATURE => features::LENS_FEATURE,
            _ => 0,
        };
        bits | kind | shape
    })
}

pub fn prepare_pipelines(
    mut commands: Commands,
    cache: Res<PipelineCache>,
    mut pipelines: ResMut<SpecializedRenderPipelines<RaycastPipeline>>,
    pipeline: Res<RaycastPipeline>,
    scene: Res<super::upload::GpuScene>,
    atlas: Res<super::bricked::atlas::BrickAtlas>,
    views: Query<(Entity, &ViewTarget, &GpuSettings), With<ExtractedView>>,
) {
    let features = super::bricked::mark::pipeline_features(scene.features, atlas.coarse_in_atlas);
    for (entity, target, settings) in &views {
        let count = (settings.lens_count as usize).min(settings.lenses.len());
        let lenses = lens_features(features, &settings.lenses[..count], settings.flags & super::gpu_types::view_flags::LENS_ANTIALIAS != 0);
        // (MIP_READS is no shader def.)
        let key = RaycastKey { format: target.main_texture_format(), features: (features & !features::MIP_READS) | lenses };
        let id = pipelines.specialize(&cache, &pipeline, key);
        commands.entity(entity).insert(RaycastPipelineId(id));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lens_antialiasing_only_where_a_region_is_in_memory() {
        let (l, aa, m) = (features::LENSES, features::LENS_ANTIALIAS, features::LENS_MAGNIFIER);
        let one = [GpuLens::default()];
        let reads = features::DVR | features::MIP_READS;
        assert_eq!(lens_features(reads, &[], true), 0);
        assert_eq!(lens_features(reads, &one, false), l | m);
        assert_eq!(lens_features(reads | features::BRICKED, &one, true), l | aa | m);
        // Bricked volumes alone, label volumes alone: nothing reads a mip chain.
        assert_eq!(lens_features(features::DVR | features::BRICKED | features::BRICKED_ONLY, &one, true), l | m);
        assert_eq!(lens_features(features::DVR | features::LABELS, &one, true), l | m);
    }

    #[test]
    fn only_the_lenses_kinds_and_shapes_are_compiled() {
        let lens = |kind, shape| GpuLens { codes: UVec4::new(kind, shape, 0, 0), ..Default::default() };
        assert_eq!(lens_kinds(&[]), 0);
        assert_eq!(lens_kinds(&[lens(lens_codes::MAGNIFIER, lens_codes::SQUARE)]), features::LENS_MAGNIFIER);
        assert_eq!(
            lens_kinds(&[lens(lens_codes::SAMPLING, lens_codes::FEATURE), lens(lens_codes::ANGULAR, lens_codes::POLYGON)]),
            features::LENS_SAMPLING | features::LENS_ANGULAR | features::LENS_FEATURE | features::LENS_POLYGON
        );
    }
}
