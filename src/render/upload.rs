//! GPU resources of the scene: packed buffers, the lookup-table atlas, the volume atlas
//! and the brick min-max atlas. Buffers are rebuilt when the scene changes; the 3D
//! atlases only when the set of volumes changes (not when an appearance does).

use std::sync::Arc;

use bevy::prelude::*;
use bevy::render::render_resource::encase::{StorageBuffer, UniformBuffer};
use bevy::render::render_resource::{
    Buffer, BufferInitDescriptor, BufferUsages, Extent3d, Texture, TextureDataOrder, TextureDescriptor, TextureDimension, TextureFormat,
    TextureFormatFeatureFlags, TextureUsages, TextureView, TextureViewDescriptor,
};
use bevy::render::renderer::{RenderAdapter, RenderDevice, RenderQueue};

use rayon::prelude::*;

use super::extract::ExtractedScene;
use super::gpu_types::{GpuSceneInfo, MAX_UNIFORM_OCCUPANCY, MAX_UNIFORM_PLANES, MAX_UNIFORM_REGIONS};
use super::pack::{LUT_ATLAS_WIDTH, MAX_INSETS, PackedScene, pack};
use crate::region::RenderScene;
use crate::volume::{Volume, Voxels};

/// The 3D atlases of a set of volumes.
pub struct GpuAtlases {
    pub volumes: TextureView,
    pub bricks: TextureView,
    _textures: (Texture, Texture),
}

/// The scene on the GPU.
#[derive(Resource, Default)]
pub struct GpuScene {
    last: Option<RenderScene>,
    /// The volumes (by identity) the atlases hold, and the atlases.
    atlas_key: Vec<usize>,
    pub atlases: Option<GpuAtlases>,
    pub info: Option<Buffer>,
    pub regions: Option<Buffer>,
    /// The records, planes and occupancy bits again in uniform buffers where they fit.
    pub uniform: Option<UniformCopies>,
    pub planes: Option<Buffer>,
    pub occupancy: Option<Buffer>,
    pub lut: Option<(Texture, TextureView)>,
    pub region_count: u32,
    /// GPU region index of every scene region (`None`: dropped).
    pub region_slots: Vec<Option<u32>>,
    /// Shader features the scene needs.
    pub features: u32,
    /// Messages about regions that could not be drawn.
    pub dropped: Vec<String>,
    /// The scene volume of each page directory entry (`render::bricked::mark`).
    pub bricked_directory: Vec<usize>,
    /// The coarse level of each bricked scene volume the packing saw.
    bricked_key: Vec<Option<usize>>,
    /// The volumes (as `atlas_key`) of a scene the device refused to hold, and the
    /// limits it was packed under (lowered limits try it again, repacked).
    refused_key: Option<(Vec<usize>, crate::dataset::gpu_fit::GpuLimits)>,
}

impl GpuScene {
    /// Whether everything the pass binds exists.
    pub fn ready(&self) -> bool {
        self.info.is_some() && self.regions.is_some() && self.lut.is_some() && self.atlases.is_some()
    }
}

/// The region records, the planes and the occupancy bits again, each in a uniform buffer
/// of a fixed size ([`MAX_UNIFORM_REGIONS`] records, [`MAX_UNIFORM_PLANES`] planes,
/// [`MAX_UNIFORM_OCCUPANCY`] words: 64 KiB, what a uniform binding may hold on every
/// device), which the shader reads in place of the storage buffer where the whole
/// content fits (`features::UNIFORM_REGIONS`, `UNIFORM_PLANES`, `UNIFORM_OCCUPANCY`:
/// `render::pack::uniform_copies`); zeros where it does not, as every copy is bound.
/// (Each type's layout is the same in both address spaces: a record's scalars run in
/// groups that end at 16-byte boundaries, a pack test holds its size; planes are
/// vectors; the occupancy words are read four to a `vec4<u32>`.)
pub struct UniformCopies {
    pub regions: Buffer,
    pub planes: Buffer,
    pub occupancy: Buffer,
}

impl UniformCopies {
    fn of(device: &RenderDevice, packed: &PackedScene) -> Self {
        UniformCopies {
            regions: uniform_copy(device, "focal regions (uniform)", &packed.regions, MAX_UNIFORM_REGIONS),
            planes: uniform_copy(device, "focal planes (uniform)", &packed.planes, MAX_UNIFORM_PLANES),
            occupancy: uniform_copy(device, "focal occupancy (uniform)", &packed.occupancy, MAX_UNIFORM_OCCUPANCY),
        }
    }
}

/// A uniform buffer of `capacity` items: `items` first where they fit (the same test
/// as the feature's, `render::pack::uniform_copies`), zeros after.
fn uniform_copy<T>(device: &RenderDevice, label: &str, items: &[T], capacity: usize) -> Buffer
where
    T: Copy + Default,
    Vec<T>: bevy::render::render_resource::ShaderType + bevy::render::render_resource::encase::internal::WriteInto,
{
    let mut copy = vec![T::default(); capacity];
    if items.len() <= capacity {
        copy[..items.len()].copy_from_slice(items);
    }
    laid_out(device, label, &copy, BufferUsages::UNIFORM)
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
    health: Res<super::health::RenderHealth>,
    mut gpu: ResMut<GpuScene>,
) {
    let Some(extracted) = extracted else { return };
    let scene = &extracted.scene;
    let bricked_key: Vec<Option<usize>> = extracted.bricked.iter().map(|f| f.as_ref().map(|f| f.coarse)).collect();
    if gpu.last.as_ref().is_some_and(|last| same_scene(last, scene)) && gpu.ready() && gpu.bricked_key == bricked_key {
        return;
    }
    let mut packed = match pack(scene, extracted.limits.max_dimension) {
        Ok(p) => p,
        Err(e) => {
            error!("cannot draw the scene: {e}");
            return;
        }
    };
    for d in &packed.dropped {
        warn!("{d}");
    }
    gpu.bricked_directory = super::bricked::mark::mark_bricked(&mut packed, scene, &extracted.bricked);
    gpu.bricked_key = bricked_key;
    if !packed.mips && !packed.volumes.is_empty() {
        warn!(
            "no room for the volumes' mip chains in one texture atlas: lenses sample full resolution where they compress (the CPU reference does not)"
        );
    }
    let all = scene.all_volumes();
    let seconds = packed.doi_channels.iter().map(|c| c.map(|v| all[v].as_ref()));
    let key: Vec<usize> = packed
        .volumes
        .iter()
        .map(|&v| Arc::as_ptr(&all[v]) as usize)
        .chain(seconds.clone().map(|s| s.map_or(0, |s| s as *const Volume as usize)))
        .collect();
    // (A scene the device refused waits for its volumes to change: fitted smaller.)
    if gpu.refused_key.as_ref().is_some_and(|(k, l)| *k == key && *l == extracted.limits) {
        return;
    }
    let volumes: Vec<(&Volume, Option<&Volume>)> = packed.volumes.iter().map(|&v| all[v].as_ref()).zip(seconds).collect();
    let new_atlases = gpu.atlas_key != key || gpu.atlases.is_none();
    let uploaded = super::health::scoped(&device, || {
        let made = new_atlases.then(|| atlases(&device, &queue, &volumes, &packed, sixteen_bit_formats(&adapter)));
        write_buffers(&device, &queue, &packed, &mut gpu);
        made
    });
    match uploaded {
        Ok(Some(made)) => {
            gpu.atlases = Some(made);
            gpu.atlas_key = key;
        }
        Ok(None) => {}
        Err(reason) => {
            let size = packed.atlas.size.as_u64vec3();
            health.refuse(super::health::Refusal {
                what: super::health::Refused::Volumes,
                reason,
                largest_edge: packed.atlas.size.max_element(),
                bytes: size.x * size.y * size.z * texel_bytes(&volumes) as u64,
            });
            // Nothing of it is bound: the pass draws nothing until smaller volumes come.
            *gpu = GpuScene { refused_key: Some((key, extracted.limits)), ..Default::default() };
            return;
        }
    }
    gpu.refused_key = None;
    gpu.region_count = packed.region_count;
    gpu.features = packed.features;
    gpu.dropped = packed.dropped;
    gpu.region_slots = packed.region_slots;
    gpu.last = Some(scene.clone());
}

/// The 16-bit formats of one and two channels: normalised where the device filters
/// them, else half floats.
pub fn sixteen_bit_formats(adapter: &RenderAdapter) -> [TextureFormat; 2] {
    let filterable = |format: TextureFormat| {
        let f = adapter.get_texture_format_features(format);
        f.allowed_usages.contains(TextureUsages::TEXTURE_BINDING) && f.flags.contains(TextureFormatFeatureFlags::FILTERABLE)
    };
    [
        if filterable(TextureFormat::R16Unorm) { TextureFormat::R16Unorm } else { TextureFormat::R16Float },
        if filterable(TextureFormat::Rg16Unorm) { TextureFormat::Rg16Unorm } else { TextureFormat::Rg16Float },
    ]
}

/// A 3D texture the shader samples and uploads write to.
pub fn sampled_3d(label: &str, size: UVec3, format: TextureFormat) -> TextureDescriptor<'_> {
    TextureDescriptor {
        label: Some(label),
        size: Extent3d { width: size.x, height: size.y, depth_or_array_layers: size.z },
        mip_level_count: 1,
        sample_count: 1,
        dimension: TextureDimension::D3,
        format,
        usage: TextureUsages::TEXTURE_BINDING | TextureUsages::COPY_DST,
        view_formats: &[],
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
    let texture = device.create_texture_with_data(queue, &sampled_3d(label, size, format), TextureDataOrder::LayerMajor, data);
    let view = texture.create_view(&TextureViewDescriptor::default());
    (texture, view)
}

/// Copies `src` (x fastest, `dims`) into `dst` (`size`) at `offset`, `bpp` bytes a texel.
fn blit(dst: &mut [u8], size: UVec3, src: &[u8], dims: UVec3, offset: UVec3, bpp: usize) {
    let row = dims.x as usize * bpp;
    for z in 0..dims.z {
        for y in 0..dims.y {
            let s = ((z * dims.y + y) * dims.x) as usize * bpp;
            let d = ((((offset.z + z) * size.y + offset.y + y) * size.x + offset.x) as usize) * bpp;
            dst[d..d + row].copy_from_slice(&src[s..s + row]);
        }
    }
}

/// A volume's codes and those of its mip levels (built on first use; the atlas takes
/// as many as it has room for).
fn volume_levels(v: &Volume, mips: bool) -> impl Iterator<Item = (&Voxels, UVec3)> {
    let levels: &[crate::volume::pyramid::Level] = if mips { v.pyramid() } else { &[] };
    std::iter::once((&v.voxels, v.dims())).chain(levels.iter().map(|l| (&l.voxels, l.dims)))
}

/// The volume atlas (8-bit when every volume is, else 16-bit: 8-bit codes `c` become
/// `257·c`, the same normalised value; half floats of `code / 65535` where 16-bit
/// normalised textures are missing) and the brick min-max atlas (`Rg16Uint`, codes as
/// stored). Each volume may carry a second volume of its dimensions in a second channel
/// (the degree of interest of its selection, `pack::doi_channels`; its mip levels carry
/// 0 there): the atlas then has two channels.
fn atlases(
    device: &RenderDevice,
    queue: &RenderQueue,
    volumes: &[(&Volume, Option<&Volume>)],
    packed: &PackedScene,
    formats16: [TextureFormat; 2],
) -> GpuAtlases {
    let size = packed.atlas.size;
    let (format, data) = volume_texels(volumes, packed, formats16);
    let (vt, vv) = texture_3d(device, queue, "focal volume atlas", size, format, &data);
    let bsize = packed.brick_atlas.size;
    let mut bricks = vec![0u8; (bsize.x * bsize.y * bsize.z) as usize * 4];
    for ((v, _), &o) in volumes.iter().zip(&packed.brick_atlas.offsets) {
        let g = v.bricks();
        let pairs: Vec<u8> = g.min.iter().zip(&g.max).flat_map(|(&lo, &hi)| [lo.to_le_bytes(), hi.to_le_bytes()].concat()).collect();
        blit(&mut bricks, bsize, &pairs, g.dims, o, 4);
    }
    let (bt, bv) = texture_3d(device, queue, "focal brick atlas", bsize, TextureFormat::Rg16Uint, &bricks);
    GpuAtlases { volumes: vv, bricks: bv, _textures: (vt, bt) }
}

/// The volume atlas's channels (2 where a volume carries a second one) and whether its
/// texels are 16-bit (any volume is).
fn atlas_layout(volumes: &[(&Volume, Option<&Volume>)]) -> (usize, bool) {
    let channels = if volumes.iter().any(|(_, s)| s.is_some()) { 2 } else { 1 };
    let sixteen = volumes.iter().flat_map(|(v, s)| std::iter::once(*v).chain(*s)).any(|v| v.voxels.bits() == 16);
    (channels, sixteen)
}

/// Bytes of one texel of the volume atlas ([`volume_texels`]'s format).
fn texel_bytes(volumes: &[(&Volume, Option<&Volume>)]) -> usize {
    let (channels, sixteen) = atlas_layout(volumes);
    channels * if sixteen { 2 } else { 1 }
}

/// The volume atlas's format and texels ([`atlases`]).
fn volume_texels(volumes: &[(&Volume, Option<&Volume>)], packed: &PackedScene, formats16: [TextureFormat; 2]) -> (TextureFormat, Vec<u8>) {
    let size = packed.atlas.size;
    let texels = (size.x * size.y * size.z) as usize;
    let (channels, sixteen) = atlas_layout(volumes);
    let (format, bytes) = match (sixteen, channels) {
        (false, 1) => (TextureFormat::R8Unorm, 1),
        (false, _) => (TextureFormat::Rg8Unorm, 2),
        (true, c) => (formats16[c - 1], 2 * c),
    };
    // One channel of a texel.
    let write = |out: &mut [u8], c: u16, bits: u32| {
        if !sixteen {
            out[0] = c as u8;
            return;
        }
        out.copy_from_slice(&texel16(c, bits, format));
    };
    let mut data = vec![0u8; texels * bytes];
    for (slot, (v, second)) in volumes.iter().enumerate() {
        for (level, ((voxels, dims), &o)) in volume_levels(v, packed.mips).zip(&packed.levels[slot]).enumerate() {
            if bytes == 1 {
                blit(&mut data, size, voxels.as_bytes(), dims, o, 1);
                continue;
            }
            let second = second.filter(|s| level == 0 && s.voxels.len() == voxels.len());
            let mut texels = vec![0u8; voxels.len() * bytes];
            if !sixteen {
                // (8-bit codes as they are, interleaved: a paint stroke uploads the atlas
                // again, and this is most of that time.)
                let g = second.map(|s| s.voxels.as_bytes());
                texels.par_chunks_mut(2).zip(voxels.as_bytes().par_iter()).enumerate().for_each(|(i, (t, r))| {
                    t[0] = *r;
                    t[1] = g.map_or(0, |g| g[i]);
                });
                blit(&mut data, size, &texels, dims, o, bytes);
                continue;
            }
            texels.par_chunks_mut(bytes).enumerate().for_each(|(i, t)| {
                let (value, rest) = t.split_at_mut(bytes / channels);
                write(value, voxels.code(i), v.voxels.bits());
                if let Some(s) = second {
                    write(rest, s.voxels.code(i), s.voxels.bits());
                }
            });
            blit(&mut data, size, &texels, dims, o, bytes);
        }
    }
    (format, data)
}

/// One 16-bit channel of code `c` (of `bits`-bit codes: 8-bit codes become `257·c`, the
/// same normalised value) in `format`: normalised, or a half float of `c / 65535`.
pub fn texel16(c: u16, bits: u32, format: TextureFormat) -> [u8; 2] {
    let c = c as u32 * if bits == 8 { 257 } else { 1 };
    match format {
        TextureFormat::R16Unorm | TextureFormat::Rg16Unorm => (c as u16).to_le_bytes(),
        _ => half::f16::from_f32(c as f32 / 65535.0).to_le_bytes(),
    }
}

fn storage<T: bevy::render::render_resource::ShaderType + bevy::render::render_resource::encase::internal::WriteInto>(
    device: &RenderDevice,
    label: &str,
    value: &T,
) -> Buffer {
    laid_out(device, label, value, BufferUsages::STORAGE)
}

/// A buffer of `value` in the storage layout with `usage` (a uniform one where that
/// layout is the uniform one too: [`UniformCopies`]).
fn laid_out<T: bevy::render::render_resource::ShaderType + bevy::render::render_resource::encase::internal::WriteInto>(
    device: &RenderDevice,
    label: &str,
    value: &T,
    usage: BufferUsages,
) -> Buffer {
    let mut bytes = StorageBuffer::new(Vec::new());
    // Writing into a Vec cannot fail for these plain types.
    let _ = bytes.write(value);
    device.create_buffer_with_data(&BufferInitDescriptor {
        label: Some(label),
        contents: bytes.as_ref(),
        usage: usage | BufferUsages::COPY_DST,
    })
}

fn write_buffers(device: &RenderDevice, queue: &RenderQueue, packed: &PackedScene, gpu: &mut GpuScene) {
    let inv = 1.0 / packed.atlas.size.max(UVec3::ONE).as_vec3();
    let info = GpuSceneInfo {
        inv_atlas_size: inv.extend(0.0),
        region_count: packed.region_count,
        max_steps: packed.max_steps,
        inset_count: packed.insets.len().min(MAX_INSETS) as u32,
        insets: std::array::from_fn(|i| packed.insets.get(i).copied().unwrap_or_default()),
        ..Default::default()
    };
    let mut ub = UniformBuffer::new(Vec::new());
    let _ = ub.write(&info);
    gpu.info = Some(device.create_buffer_with_data(&BufferInitDescriptor {
        label: Some("focal scene info"),
        contents: ub.as_ref(),
        usage: BufferUsages::UNIFORM | BufferUsages::COPY_DST,
    }));
    let regions = if packed.regions.is_empty() { vec![Default::default()] } else { packed.regions.clone() };
    gpu.regions = Some(storage(device, "focal regions", &regions));
    gpu.uniform = Some(UniformCopies::of(device, packed));
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
            format: TextureFormat::Rgba32Uint,
            usage: TextureUsages::TEXTURE_BINDING | TextureUsages::COPY_DST,
            view_formats: &[],
        },
        TextureDataOrder::LayerMajor,
        &bytes,
    );
    let view = texture.create_view(&TextureViewDescriptor::default());
    gpu.lut = Some((texture, view));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::pack::Atlas;
    use crate::volume::{Grid, Source, ValueMap};

    fn volume(voxels: Voxels) -> Volume {
        Volume::new("v", Grid::new(UVec3::new(voxels.len() as u32, 1, 1), Vec3::ONE), voxels, ValueMap::IDENTITY, Source::default())
            .unwrap()
    }

    /// Two volumes side by side in an atlas of 5×1×1 texels, the first carrying a
    /// selection.
    fn packed() -> PackedScene {
        PackedScene {
            atlas: Atlas { size: UVec3::new(5, 1, 1), offsets: vec![UVec3::ZERO, UVec3::new(2, 0, 0)] },
            levels: vec![vec![UVec3::ZERO], vec![UVec3::new(2, 0, 0)]],
            ..Default::default()
        }
    }

    #[test]
    fn a_selection_rides_in_the_second_channel_of_its_datas_texels() {
        let (data, other) = (volume(Voxels::U8(vec![10, 20])), volume(Voxels::U8(vec![1, 2, 3])));
        let selection = volume(Voxels::U8(vec![0, 255]));
        let formats = [TextureFormat::R16Unorm, TextureFormat::Rg16Unorm];
        // 8-bit: (value, doi) pairs; the other volume's second channel is 0.
        let (format, bytes) = volume_texels(&[(&data, Some(&selection)), (&other, None)], &packed(), formats);
        assert_eq!((format, bytes), (TextureFormat::Rg8Unorm, vec![10, 0, 20, 255, 1, 0, 2, 0, 3, 0]));
        // Without a selection, one channel.
        let (format, bytes) = volume_texels(&[(&data, None), (&other, None)], &packed(), formats);
        assert_eq!((format, bytes), (TextureFormat::R8Unorm, vec![10, 20, 1, 2, 3]));
        // 16-bit data: 8-bit codes become 257·c; half floats of code / 65535 where
        // 16-bit normalised textures are missing.
        let wide = volume(Voxels::U16(vec![1000, 65535]));
        let (format, bytes) = volume_texels(&[(&wide, Some(&selection)), (&other, None)], &packed(), formats);
        let words: Vec<u16> = bytes.chunks(2).map(|b| u16::from_le_bytes([b[0], b[1]])).collect();
        assert_eq!((format, words), (TextureFormat::Rg16Unorm, vec![1000, 0, 65535, 65535, 257, 0, 514, 0, 771, 0]));
        let floats = [TextureFormat::R16Float, TextureFormat::Rg16Float];
        let (format, bytes) = volume_texels(&[(&wide, Some(&selection)), (&other, None)], &packed(), floats);
        let halves: Vec<f32> = bytes.chunks(2).map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32()).collect();
        assert_eq!(format, TextureFormat::Rg16Float);
        let expected = [1000.0 / 65535.0, 0.0, 1.0, 1.0, 1.0 / 255.0, 0.0, 2.0 / 255.0, 0.0, 3.0 / 255.0, 0.0];
        assert!(halves.iter().zip(expected).all(|(h, e)| (h - e).abs() <= 1e-3 * e.max(1e-3)), "{halves:?}");
    }
}
