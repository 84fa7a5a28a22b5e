//! GPU resources of the scene: packed buffers, the lookup-table atlas and one 3D texture
//! (plus brick min-max texture) per volume slot. Rebuilt only when the scene changes;
//! volume textures are cached per volume and reused across scene changes.

use std::collections::HashMap;
use std::sync::{Arc, Weak};

use bevy::prelude::*;
use bevy::render::render_resource::encase::{StorageBuffer, UniformBuffer};
use bevy::render::render_resource::{
    Buffer, BufferInitDescriptor, BufferUsages, Extent3d, Texture, TextureDataOrder, TextureDescriptor, TextureDimension, TextureFormat,
    TextureFormatFeatureFlags, TextureUsages, TextureView, TextureViewDescriptor,
};
use bevy::render::renderer::{RenderAdapter, RenderDevice, RenderQueue};

use super::extract::ExtractedScene;
use super::gpu_types::GpuSceneInfo;
use super::pack::{LUT_ATLAS_WIDTH, PackedScene, VOLUME_SLOTS, pack};
use crate::region::RenderScene;
use crate::volume::{Volume, Voxels};

/// A volume and its brick grid on the GPU.
pub struct GpuVolumeTextures {
    pub volume: TextureView,
    pub minmax: TextureView,
    _textures: (Texture, Texture),
}

/// The scene on the GPU.
#[derive(Resource, Default)]
pub struct GpuScene {
    last: Option<RenderScene>,
    cache: HashMap<usize, (Weak<Volume>, Arc<GpuVolumeTextures>)>,
    dummy: Option<Arc<GpuVolumeTextures>>,
    pub info: Option<Buffer>,
    pub regions: Option<Buffer>,
    pub planes: Option<Buffer>,
    pub occupancy: Option<Buffer>,
    pub lut: Option<(Texture, TextureView)>,
    /// One entry per slot (dummies for unused slots).
    pub slots: Vec<Arc<GpuVolumeTextures>>,
    pub region_count: u32,
    /// Messages about regions that could not be drawn.
    pub dropped: Vec<String>,
}

impl GpuScene {
    /// Whether everything the pass binds exists.
    pub fn ready(&self) -> bool {
        self.info.is_some() && self.regions.is_some() && self.lut.is_some() && self.slots.len() == VOLUME_SLOTS
    }
}

/// Whether two scenes draw the same thing (volumes compared by identity).
fn same_scene(a: &RenderScene, b: &RenderScene) -> bool {
    a.volumes.len() == b.volumes.len()
        && a.volumes.iter().zip(&b.volumes).all(|(x, y)| Arc::ptr_eq(x, y))
        && a.regions == b.regions
        && a.appearances == b.appearances
}

/// Packs and uploads the scene when it changed.
pub fn upload_scene(
    extracted: Option<Res<ExtractedScene>>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    adapter: Res<RenderAdapter>,
    mut gpu: ResMut<GpuScene>,
) {
    let Some(extracted) = extracted else { return };
    let scene = &extracted.scene;
    if gpu.last.as_ref().is_some_and(|last| same_scene(last, scene)) && gpu.ready() {
        return;
    }
    let packed = match pack(scene) {
        Ok(p) => p,
        Err(e) => {
            error!("cannot draw the scene: {e}");
            return;
        }
    };
    for d in &packed.dropped {
        warn!("{d}");
    }
    let format16 = sixteen_bit_format(&adapter);
    gpu.cache.retain(|_, (weak, _)| weak.strong_count() > 0);
    let mut slots = Vec::with_capacity(VOLUME_SLOTS);
    for &v in &packed.slots {
        let volume = &scene.volumes[v];
        let key = Arc::as_ptr(volume) as usize;
        let textures = match gpu.cache.get(&key) {
            Some((_, t)) => t.clone(),
            None => {
                let t = Arc::new(volume_textures(&device, &queue, volume, format16));
                gpu.cache.insert(key, (Arc::downgrade(volume), t.clone()));
                t
            }
        };
        slots.push(textures);
    }
    let dummy = gpu.dummy.get_or_insert_with(|| Arc::new(dummy_textures(&device, &queue))).clone();
    slots.resize(VOLUME_SLOTS, dummy);
    write_buffers(&device, &queue, &packed, &mut gpu);
    gpu.slots = slots;
    gpu.region_count = packed.regions.len() as u32;
    gpu.dropped = packed.dropped;
    gpu.last = Some(scene.clone());
}

/// `R16Unorm` where the device has filterable 16-bit normalised textures, else `R16Float`.
fn sixteen_bit_format(adapter: &RenderAdapter) -> TextureFormat {
    let f = adapter.get_texture_format_features(TextureFormat::R16Unorm);
    if f.allowed_usages.contains(TextureUsages::TEXTURE_BINDING) && f.flags.contains(TextureFormatFeatureFlags::FILTERABLE) {
        TextureFormat::R16Unorm
    } else {
        TextureFormat::R16Float
    }
}

fn texture_3d(
    device: &RenderDevice,
    queue: &RenderQueue,
    label: &str,
    size: UVec3,
    format: TextureFormat,
    data: &[u8],
) -> (Texture, TextureView) {
    let texture = device.create_texture_with_data(
        queue,
        &TextureDescriptor {
            label: Some(label),
            size: Extent3d { width: size.x, height: size.y, depth_or_array_layers: size.z },
            mip_level_count: 1,
            sample_count: 1,
            dimension: TextureDimension::D3,
            format,
            usage: TextureUsages::TEXTURE_BINDING | TextureUsages::COPY_DST,
            view_formats: &[],
        },
        TextureDataOrder::LayerMajor,
        data,
    );
    let view = texture.create_view(&TextureViewDescriptor::default());
    (texture, view)
}

/// The volume's codes as a texture (16-bit codes as normalised halves where `R16Unorm`
/// is missing: `code / 65535` rounded to f16) and its brick min-max grid.
fn volume_textures(device: &RenderDevice, queue: &RenderQueue, v: &Volume, format16: TextureFormat) -> GpuVolumeTextures {
    let (format, data): (TextureFormat, std::borrow::Cow<[u8]>) = match (&v.voxels, format16) {
        (Voxels::U8(d), _) => (TextureFormat::R8Unorm, d.as_slice().into()),
        (Voxels::U16(_), TextureFormat::R16Unorm) => (TextureFormat::R16Unorm, v.voxels.as_bytes().into()),
        (Voxels::U16(d), _) => {
            let halves: Vec<u8> = d.iter().flat_map(|&c| half::f16::from_f32(c as f32 / 65535.0).to_le_bytes()).collect();
            (TextureFormat::R16Float, halves.into())
        }
    };
    let (vt, vv) = texture_3d(device, queue, &format!("focal volume {}", v.name), v.dims(), format, &data);
    let bricks = v.bricks();
    let minmax: Vec<u8> = bricks.min.iter().zip(&bricks.max).flat_map(|(&lo, &hi)| [lo.to_le_bytes(), hi.to_le_bytes()].concat()).collect();
    let (mt, mv) = texture_3d(device, queue, "focal brick min-max", bricks.dims, TextureFormat::Rg16Uint, &minmax);
    GpuVolumeTextures { volume: vv, minmax: mv, _textures: (vt, mt) }
}

fn dummy_textures(device: &RenderDevice, queue: &RenderQueue) -> GpuVolumeTextures {
    let (vt, vv) = texture_3d(device, queue, "focal empty volume", UVec3::ONE, TextureFormat::R8Unorm, &[0]);
    let (mt, mv) = texture_3d(device, queue, "focal empty bricks", UVec3::ONE, TextureFormat::Rg16Uint, &[0; 4]);
    GpuVolumeTextures { volume: vv, minmax: mv, _textures: (vt, mt) }
}

fn storage<T: bevy::render::render_resource::ShaderType + bevy::render::render_resource::encase::internal::WriteInto>(
    device: &RenderDevice,
    label: &str,
    value: &T,
) -> Buffer {
    let mut bytes = StorageBuffer::new(Vec::new());
    // Writing into a Vec cannot fail for these plain types.
    let _ = bytes.write(value);
    device.create_buffer_with_data(&BufferInitDescriptor {
        label: Some(label),
        contents: bytes.as_ref(),
        usage: BufferUsages::STORAGE | BufferUsages::COPY_DST,
    })
}

fn write_buffers(device: &RenderDevice, queue: &RenderQueue, packed: &PackedScene, gpu: &mut GpuScene) {
    let info = GpuSceneInfo { region_count: packed.regions.len() as u32, lut_atlas_width: LUT_ATLAS_WIDTH, pad_a: 0, pad_b: 0 };
    let mut ub = UniformBuffer::new(Vec::new());
    let _ = ub.write(&info);
    gpu.info = Some(device.create_buffer_with_data(&BufferInitDescriptor {
        label: Some("focal scene info"),
        contents: ub.as_ref(),
        usage: BufferUsages::UNIFORM | BufferUsages::COPY_DST,
    }));
    let regions = if packed.regions.is_empty() { vec![Default::default()] } else { packed.regions.clone() };
    gpu.regions = Some(storage(device, "focal regions", &regions));
    gpu.planes = Some(storage(device, "focal planes", &packed.planes));
    gpu.occupancy = Some(storage(device, "focal occupancy", &packed.occupancy));
    let rows = packed.lut_rows();
    let bytes: Vec<u8> = packed.lut.iter().flat_map(|c| c.iter().flat_map(|v| v.to_le_bytes())).collect();
    let texture = device.create_texture_with_data(
        queue,
        &TextureDescriptor {
            label: Some("focal lookup atlas"),
            size: Extent3d { width: LUT_ATLAS_WIDTH, height: rows, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: TextureDimension::D2,
            format: TextureFormat::Rgba32Float,
            usage: TextureUsages::TEXTURE_BINDING | TextureUsages::COPY_DST,
            view_formats: &[],
        },
        TextureDataOrder::LayerMajor,
        &bytes,
    );
    let view = texture.create_view(&TextureViewDescriptor::default());
    gpu.lut = Some((texture, view));
}
