//! The feature lenses' silhouettes on the GPU: per view, buffers sized for its feature
//! lenses and the compute passes of `shaders/feature.wgsl` (feature mask, jump
//! flooding, signed distances and centroid; algorithm and CPU reference in
//! [`crate::lens::feature`]) that fill them before the ray-cast pass reads them.

use std::num::NonZeroU64;

use bevy::prelude::*;
use bevy::render::render_resource::binding_types::{
    storage_buffer_read_only_sized, storage_buffer_sized, texture_3d, uniform_buffer, uniform_buffer_sized,
};
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderContext, RenderDevice, RenderQueue};
use bevy::render::view::ViewUniform;
use bytemuck::{Pod, Zeroable};

use super::lens_pack::GpuFeatureFields;
use super::upload::GpuScene;
use crate::lens::feature::{FeatureGrid, FeatureJob};

/// Bytes between two dispatches' parameters (the largest uniform offset alignment).
const PARAMS_STRIDE: u64 = 256;
/// Cells per workgroup side.
const GROUP: u32 = 8;

/// Mirrors `FeatureParams` in `shaders/feature.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
struct FeatureParams {
    cols: u32,
    rows: u32,
    offset: u32,
    region: u32,
    label: u32,
    jump: u32,
    source: u32,
    slot: u32,
    origin: [f32; 2],
    cell: [f32; 2],
    step: f32,
    // 1 where the volume holds the label (`within` then holds its box's planes).
    present: u32,
    pad: [f32; 2],
    within: [[f32; 4]; 6],
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    Mask,
    Flood,
    Finish,
}

/// One compute dispatch: stage, parameter offset, workgroups.
#[derive(Clone, Copy, Debug)]
struct Dispatch {
    stage: Stage,
    params: u32,
    groups: UVec2,
}

/// The jump lengths of one jump-flooding run over `grid`: n/2, n/4, …, 1, then 1 again
/// (JFA+1, which repairs most of plain JFA's errors).
pub fn flood_steps(grid: &FeatureGrid) -> Vec<u32> {
    let mut steps = Vec::new();
    let mut jump = grid.cols.max(grid.rows).next_power_of_two() / 2;
    while jump >= 1 {
        steps.push(jump);
        jump /= 2;
    }
    steps.push(1);
    steps
}

/// The dispatches of a view's jobs (those whose region is on the GPU) and their
/// parameters, `PARAMS_STRIDE` bytes apart.
fn plan(jobs: &[(u32, FeatureJob)], region_slots: &[Option<u32>]) -> (Vec<Dispatch>, Vec<u8>) {
    let (mut dispatches, mut bytes) = (Vec::new(), Vec::new());
    for (slot, (offset, job)) in jobs.iter().enumerate() {
        let Some(Some(region)) = region_slots.get(job.region as usize) else { continue };
        let g = job.grid;
        let base = FeatureParams {
            cols: g.cols,
            rows: g.rows,
            offset: *offset,
            region: *region,
            label: job.label,
            slot: slot as u32,
            origin: g.origin.to_array(),
            cell: g.step.to_array(),
            step: job.step,
            present: u32::from(job.within.is_some()),
            within: job.within.map_or([[0.0; 4]; 6], |planes| planes.map(|p| p.normal.extend(p.offset).to_array())),
            ..Default::default()
        };
        let groups = UVec2::new(g.cols.div_ceil(GROUP), g.rows.div_ceil(GROUP));
        let mut push = |stage, params: FeatureParams| {
            dispatches.push(Dispatch { stage, params: bytes.len() as u32, groups });
            bytes.extend_from_slice(bytemuck::bytes_of(&params));
            bytes.resize(bytes.len().next_multiple_of(PARAMS_STRIDE as usize), 0);
        };
        push(Stage::Mask, base);
        let steps = flood_steps(&g);
        for (i, jump) in steps.iter().enumerate() {
            push(Stage::Flood, FeatureParams { jump: *jump, source: (i % 2) as u32, ..base });
        }
        push(Stage::Finish, FeatureParams { source: (steps.len() % 2) as u32, ..base });
    }
    (dispatches, bytes)
}

/// Compute pipelines and layouts.
#[derive(Resource)]
pub struct FeaturePipelines {
    scene_layout: BindGroupLayoutDescriptor,
    job_layout: BindGroupLayoutDescriptor,
    mask: CachedComputePipelineId,
    flood: CachedComputePipelineId,
    finish: CachedComputePipelineId,
}

pub fn init_feature_pipelines(mut commands: Commands, cache: Res<PipelineCache>) {
    // Group 0 mirrors the bindings of `focal::bindings` the passes use.
    let scene_layout = BindGroupLayoutDescriptor::new(
        "focal_feature_scene_layout",
        &BindGroupLayoutEntries::with_indices(
            ShaderStages::COMPUTE,
            (
                (0, uniform_buffer::<ViewUniform>(true)),
                (3, storage_buffer_read_only_sized(false, None)),
                (4, storage_buffer_read_only_sized(false, None)),
                (7, texture_3d(TextureSampleType::Float { filterable: true })),
            ),
        ),
    );
    let job_layout = BindGroupLayoutDescriptor::new(
        "focal_feature_job_layout",
        &BindGroupLayoutEntries::sequential(
            ShaderStages::COMPUTE,
            (
                uniform_buffer_sized(true, NonZeroU64::new(size_of::<FeatureParams>() as u64)),
                storage_buffer_sized(false, None),
                storage_buffer_sized(false, None),
                storage_buffer_sized(false, None),
                storage_buffer_sized(false, None),
            ),
        ),
    );
    let queue = |entry: &'static str| {
        cache.queue_compute_pipeline(ComputePipelineDescriptor {
            label: Some(format!("focal_feature_{entry}").into()),
            layout: vec![scene_layout.clone(), job_layout.clone()],
            shader: super::shaders::FEATURE,
            entry_point: Some(entry.into()),
            ..default()
        })
    };
    let (mask, flood, finish) = (queue("mask"), queue("flood"), queue("finish"));
    commands.insert_resource(FeaturePipelines { scene_layout, job_layout, mask, flood, finish });
}

/// A view's silhouette buffers: the fields the ray-cast pass reads (CPU values written,
/// GPU jobs filled by the passes), the two seed maps, the counters and the parameters.
#[derive(Component)]
pub struct FeatureBuffers {
    pub fields: Buffer,
    seeds: [Buffer; 2],
    counts: Buffer,
    params: Buffer,
    dispatches: Vec<Dispatch>,
}

fn buffer(device: &RenderDevice, label: &str, size: u64, usage: BufferUsages) -> Buffer {
    device.create_buffer(&BufferDescriptor {
        label: Some(label),
        size: size.max(16),
        usage: usage | BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

fn fits(b: &Buffer, size: u64) -> bool {
    b.size() >= size.max(16)
}

/// Sizes every view's buffers for this frame's silhouettes (growing only) and writes
/// the CPU's fields and the passes' parameters.
pub fn prepare_feature_buffers(
    mut commands: Commands,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    scene: Res<GpuScene>,
    mut views: Query<(Entity, &GpuFeatureFields, Option<&mut FeatureBuffers>)>,
) {
    for (entity, fields, existing) in &mut views {
        let field_bytes = (fields.values.len() * 4) as u64;
        let cells = fields.jobs.iter().map(|(_, j)| j.grid.cells()).max().unwrap_or(0) as u64;
        let (dispatches, params) = plan(&fields.jobs, &scene.region_slots);
        let (seed_bytes, count_bytes) = (cells * 8, fields.jobs.len() as u64 * 16);
        let storage = BufferUsages::STORAGE;
        let mut fresh = None;
        let buffers = match existing {
            Some(b) => b.into_inner(),
            None => fresh.insert(FeatureBuffers {
                fields: buffer(&device, "focal feature fields", field_bytes, storage),
                seeds: [
                    buffer(&device, "focal feature seeds a", seed_bytes, storage),
                    buffer(&device, "focal feature seeds b", seed_bytes, storage),
                ],
                counts: buffer(&device, "focal feature counts", count_bytes, storage),
                params: buffer(&device, "focal feature params", params.len() as u64, BufferUsages::UNIFORM),
                dispatches: Vec::new(),
            }),
        };
        if !fits(&buffers.fields, field_bytes) {
            buffers.fields = buffer(&device, "focal feature fields", field_bytes, storage);
        }
        if !fits(&buffers.seeds[0], seed_bytes) {
            buffers.seeds = [
                buffer(&device, "focal feature seeds a", seed_bytes, storage),
                buffer(&device, "focal feature seeds b", seed_bytes, storage),
            ];
        }
        if !fits(&buffers.counts, count_bytes) {
            buffers.counts = buffer(&device, "focal feature counts", count_bytes, storage);
        }
        if !fits(&buffers.params, params.len() as u64) {
            buffers.params = buffer(&device, "focal feature params", params.len() as u64, BufferUsages::UNIFORM);
        }
        if !fields.values.is_empty() {
            queue.write_buffer(&buffers.fields, 0, bytemuck::cast_slice(&fields.values));
        }
        if !params.is_empty() {
            queue.write_buffer(&buffers.params, 0, &params);
        }
        buffers.dispatches = dispatches;
        if let Some(b) = fresh {
            commands.entity(entity).insert(b);
        }
    }
}

/// Records the view's silhouette passes; `false` while the pipelines are not built (the
/// view must not be drawn without its silhouettes then).
pub fn encode_feature_passes(
    ctx: &mut RenderContext,
    buffers: &FeatureBuffers,
    pipelines: &FeaturePipelines,
    cache: &PipelineCache,
    scene: &GpuScene,
    view: (BindingResource, u32),
) -> bool {
    if buffers.dispatches.is_empty() {
        return true;
    }
    let (Some(mask), Some(flood), Some(finish)) = (
        cache.get_compute_pipeline(pipelines.mask),
        cache.get_compute_pipeline(pipelines.flood),
        cache.get_compute_pipeline(pipelines.finish),
    ) else {
        return false;
    };
    let (Some(regions), Some(planes), Some(atlases)) = (&scene.regions, &scene.planes, &scene.atlases) else { return false };
    let device = ctx.render_device();
    let scene_group = device.create_bind_group(
        "focal_feature_scene",
        &cache.get_bind_group_layout(&pipelines.scene_layout),
        &BindGroupEntries::with_indices((
            (0, view.0),
            (3, regions.as_entire_binding()),
            (4, planes.as_entire_binding()),
            (7, &atlases.volumes),
        )),
    );
    let params = BufferBinding { buffer: &buffers.params, offset: 0, size: NonZeroU64::new(size_of::<FeatureParams>() as u64) };
    let job_group = device.create_bind_group(
        "focal_feature_job",
        &cache.get_bind_group_layout(&pipelines.job_layout),
        &BindGroupEntries::sequential((
            BindingResource::Buffer(params),
            buffers.seeds[0].as_entire_binding(),
            buffers.seeds[1].as_entire_binding(),
            buffers.counts.as_entire_binding(),
            buffers.fields.as_entire_binding(),
        )),
    );
    let encoder = ctx.command_encoder();
    encoder.clear_buffer(&buffers.counts, 0, None);
    let mut pass = encoder.begin_compute_pass(&ComputePassDescriptor { label: Some("focal_feature_pass"), timestamp_writes: None });
    pass.set_bind_group(0, &scene_group, &[view.1]);
    for d in &buffers.dispatches {
        pass.set_pipeline(match d.stage {
            Stage::Mask => mask,
            Stage::Flood => flood,
            Stage::Finish => finish,
        });
        pass.set_bind_group(1, &job_group, &[d.params]);
        pass.dispatch_workgroups(d.groups.x, d.groups.y, 1);
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lens::Screen;

    #[test]
    fn jump_flooding_halves_down_to_one_and_repeats_it() {
        let grid = FeatureGrid::of(Screen::new(400, 300));
        assert_eq!((grid.cols, grid.rows), (128, 96));
        assert_eq!(flood_steps(&grid), vec![64, 32, 16, 8, 4, 2, 1, 1]);
    }

    #[test]
    fn every_job_on_the_gpu_gets_mask_floods_and_finish() {
        let grid = FeatureGrid::of(Screen::new(100, 100));
        let unit = crate::region::box_planes(&bevy::math::Affine3A::IDENTITY, Vec3::ZERO, Vec3::ONE);
        let within: Option<[crate::region::Plane; 6]> = unit.try_into().ok();
        let job = |region| FeatureJob { region, label: 3, step: 0.5, grid, within };
        let (_, bytes) = plan(&[(0, job(0)), (9220, job(1)), (0, FeatureJob { within: None, ..job(1) })], &[None, Some(0)]);
        // A label the volume lacks marches nothing (its mask is empty).
        let last = *bytemuck::from_bytes::<FeatureParams>(&bytes[bytes.len() - PARAMS_STRIDE as usize..][..size_of::<FeatureParams>()]);
        assert_eq!(last.present, 0);
        let (dispatches, bytes) = plan(&[(0, job(0)), (9220, job(1))], &[None, Some(0)]);
        // The first job's region was dropped: only the second runs, counters in slot 1.
        let n = flood_steps(&grid).len();
        assert_eq!(dispatches.len(), n + 2);
        assert_eq!(bytes.len(), (n + 2) * PARAMS_STRIDE as usize);
        assert_eq!(dispatches[0].stage, Stage::Mask);
        assert_eq!(dispatches[n + 1].stage, Stage::Finish);
        let params = |d: &Dispatch| {
            *bytemuck::from_bytes::<FeatureParams>(&bytes[d.params as usize..d.params as usize + size_of::<FeatureParams>()])
        };
        let first = params(&dispatches[0]);
        assert_eq!((first.offset, first.region, first.slot, first.label), (9220, 0, 1, 3));
        // The label's box: the unit cube's planes (n, d), x ≤ 1 first.
        assert_eq!((first.present, first.within[0], first.within[1]), (1, [1.0, 0.0, 0.0, 1.0], [-1.0, 0.0, 0.0, 0.0]));
        // Flood passes alternate buffers; finish reads the one written last.
        assert_eq!(params(&dispatches[1]).source, 0);
        assert_eq!(params(&dispatches[2]).source, 1);
        assert_eq!(params(&dispatches[n + 1]).source, n as u32 % 2);
        assert_eq!(dispatches[0].groups, UVec2::new(grid.cols.div_ceil(8), 12));
    }
}
