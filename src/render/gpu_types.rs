//! The GPU layout of the per-pixel function's inputs (std430 / uniform rules via
//! `encase`). Field order and types match `shaders/focal/types.wgsl` exactly.

use bevy::prelude::Component;
use bevy::render::render_resource::ShaderType;
use glam::{Mat4, UVec4, Vec4};

use crate::volume::pyramid::MIP_LEVELS;

/// Mode numbers shared with the shader.
pub mod mode {
    pub const DVR: u32 = 0;
    pub const MIP: u32 = 1;
    pub const MIN_IP: u32 = 2;
    pub const X_RAY: u32 = 3;
    pub const GRADIENT_DVR: u32 = 4;
    pub const ISO: u32 = 5;
    pub const CONTEXT: u32 = 6;
    /// A segmented region: each sample's object has its own mode (`objects`).
    pub const TWO_LEVEL: u32 = 7;
    /// Draws nothing (hidden objects, the label record of a segmentation).
    pub const OFF: u32 = 8;
}

/// How a region evaluates the outer power of context-preserving opacity.
pub mod context_power {
    pub const SCHLICK: f32 = 0.0;
    pub const EXACT: f32 = 1.0;
}

/// Region flags.
pub mod region_flags {
    /// Codes are label ids: nearest sampling and a per-id table.
    pub const LABELS: u32 = 1;
    /// Blinn-Phong shading on.
    pub const SHADING: u32 = 2;
    /// The occupancy bits of this region may be used to skip bricks.
    pub const OCCUPANCY: u32 = 4;
    /// Context-preserving with λt, λs channels: their table follows the colours.
    pub const LAMBDA: u32 = 8;
    /// Opacity weighted by a selection (its record: `objects.w`).
    pub const SELECTION: u32 = 16;
    /// With [`SELECTION`]: weighted by 1 − the degree of interest.
    pub const KEEP_UNSELECTED: u32 = 32;
    /// Another region is drawn in this one's samples (its record: `objects.z`; both
    /// looks' pair table: `objects.y`; `render::pack::companions`).
    pub const COMPANION: u32 = 64;
    /// A segmented region whose label volume lies on its data's grid: each part's
    /// samples come from its own label's voxels (`two_level.wgsl` own_value).
    pub const ON_GRID: u32 = 128;
    /// A segmented region asks for [`ON_GRID`]'s boundaries (`Segmentation::own_values`;
    /// given where its labels lie on the grid: bricked data on level 0's).
    pub const OWN_VALUES: u32 = 256;
}

/// Scene features: which parts of the shader a scene needs (shader defs).
pub mod features {
    pub const DVR: u32 = 1;
    pub const GRADIENT_MODULATION: u32 = 2;
    pub const LABELS: u32 = 4;
    pub const PROJECTION: u32 = 8;
    pub const ISO: u32 = 16;
    pub const SHADING: u32 = 32;
    pub const MULTI_REGION: u32 = 64;
    /// The view has lenses (a per-view feature).
    pub const LENSES: u32 = 128;
    /// Context-preserving DVR.
    pub const CONTEXT: u32 = 256;
    /// Two-level rendering of segmented volumes.
    pub const TWO_LEVEL: u32 = 512;
    /// Two DVR-like regions overlap: the DVR loop takes both at each sample.
    pub const DVR_PAIRS: u32 = 1024;
    /// The view has lenses with anti-aliasing (a per-view feature, with [`LENSES`]).
    pub const LENS_ANTIALIAS: u32 = 2048;
    /// Some region's opacity is weighted by a selection (exploded views).
    pub const SELECTION: u32 = 4096;
    /// Some region has holes (clip windows): the intervals are cut (llvmpipe ran that
    /// code for every region of every ray, holes or not).
    pub const HOLES: u32 = 8192;
    /// Every selection weight's degree of interest lies in the second channel of its
    /// data's texels (`render::pack::doi_channels`): one fetch gives value and weight.
    pub const DOI_CHANNEL: u32 = 16384;
    /// Some region draws another in its samples (`render::pack::companions`).
    pub const COMPANION: u32 = 32768;
    /// Some region samples a bricked volume through its page table
    /// (`render::bricked`).
    pub const BRICKED: u32 = 65536;
    /// Every region samples a bricked volume whose coarse level is in the brick atlas
    /// (`render::bricked`): every sample reads the atlas, and the paths to the volume
    /// atlas, which llvmpipe ran beside the atlas's for every sample, are left out.
    pub const BRICKED_ONLY: u32 = 131072;
    /// A segmented region takes each sample's value from its own object's voxels at
    /// boundaries (`region_flags::ON_GRID`).
    pub const OWN_VALUES: u32 = 262144;

    /// The view's lenses, by kind and shape (per-view features, with [`LENSES`]): the
    /// code of the others is left out (llvmpipe ran every kind's and shape's code for
    /// every ray of a lens, five rays a pixel with anti-aliasing's footprint).
    pub const LENS_MAGNIFIER: u32 = 1 << 19;
    pub const LENS_SAMPLING: u32 = 1 << 20;
    pub const LENS_ANGULAR: u32 = 1 << 21;
    pub const LENS_POLYGON: u32 = 1 << 22;
    pub const LENS_FEATURE: u32 = 1 << 23;

    /// Some region samples scalar values of a volume in memory, which has a mip chain
    /// (not a shader def: lenses' anti-aliasing reads nothing else, so the view's
    /// pipeline has it only then, `render::pipeline::lens_features`).
    pub const MIP_READS: u32 = 1 << 24;

    /// Some region draws clip windows in place (`render::pack::insets`; the windows:
    /// [`super::GpuSceneInfo::insets`]).
    pub const INSETS: u32 = 1 << 25;
    /// More than one window drawn in place: each sample chooses among all
    /// [`super::MAX_INSETS`] (with one, it compares with that one alone: on llvmpipe
    /// the other three's comparisons cost a one-window view about 4 % of its frame).
    pub const SEVERAL_INSETS: u32 = 1 << 26;
    /// Some object of a segmented region takes only a range of values: a sample's part
    /// is the first of its label's candidates whose range holds its value (without, the
    /// first candidate: no object's range is read).
    pub const VALUE_RANGES: u32 = 1 << 27;
    /// Every plane fits the uniform copy of the planes ([`super::MAX_UNIFORM_PLANES`]):
    /// the shader reads them there (`render::upload::UniformCopies`).
    pub const UNIFORM_PLANES: u32 = 1 << 28;
    /// Every region record fits the uniform copy of the records
    /// ([`super::MAX_UNIFORM_REGIONS`]): the shader reads them there (on llvmpipe a load
    /// from a storage buffer runs lane by lane, with a branch per lane and word; a load
    /// from a uniform buffer by a per-lane index is one gather).
    pub const UNIFORM_REGIONS: u32 = 1 << 29;
    /// Every occupancy word fits the uniform copy of the occupancy bits
    /// ([`super::MAX_UNIFORM_OCCUPANCY`]): the empty-space tests read them there.
    pub const UNIFORM_OCCUPANCY: u32 = 1 << 30;

    /// Shader def names of the lens kinds and shapes, by bit.
    pub const LENS_NAMES: [(u32, &str); 5] = [
        (LENS_MAGNIFIER, "HAS_MAGNIFIER"),
        (LENS_SAMPLING, "HAS_SAMPLING_LENS"),
        (LENS_ANGULAR, "HAS_ANGULAR_LENS"),
        (LENS_POLYGON, "HAS_POLYGON_LENS"),
        (LENS_FEATURE, "HAS_FEATURE_LENS"),
    ];

    /// Shader def names, by bit.
    pub const NAMES: [(u32, &str); 25] = [
        (DVR, "HAS_DVR"),
        (GRADIENT_MODULATION, "HAS_GRADIENT_MODULATION"),
        (LABELS, "HAS_LABELS"),
        (PROJECTION, "HAS_PROJECTION"),
        (ISO, "HAS_ISO"),
        (SHADING, "HAS_SHADING"),
        (MULTI_REGION, "MULTI_REGION"),
        (LENSES, "HAS_LENSES"),
        (CONTEXT, "HAS_CONTEXT"),
        (TWO_LEVEL, "HAS_TWO_LEVEL"),
        (DVR_PAIRS, "DVR_PAIRS"),
        (LENS_ANTIALIAS, "LENS_ANTIALIAS"),
        (SELECTION, "HAS_SELECTION"),
        (HOLES, "HAS_HOLES"),
        (DOI_CHANNEL, "DOI_CHANNEL"),
        (COMPANION, "COMPANION"),
        (BRICKED, "HAS_BRICKED"),
        (BRICKED_ONLY, "BRICKED_ONLY"),
        (OWN_VALUES, "OWN_VALUES"),
        (INSETS, "INSETS"),
        (SEVERAL_INSETS, "SEVERAL_INSETS"),
        (VALUE_RANGES, "VALUE_RANGES"),
        (UNIFORM_PLANES, "UNIFORM_PLANES"),
        (UNIFORM_REGIONS, "UNIFORM_REGIONS"),
        (UNIFORM_OCCUPANCY, "UNIFORM_OCCUPANCY"),
    ];
}

/// View settings flags.
pub mod view_flags {
    pub const JITTER: u32 = 1;
    pub const SKIP_EMPTY: u32 = 2;
    pub const EARLY_TERMINATION: u32 = 4;
    /// Output each pixel's ray direction as colour, `dir·½ + ½` (tests of ray generation).
    pub const DEBUG_RAYS: u32 = 8;
    /// Sample compressed areas under lenses from the mip chain.
    pub const LENS_ANTIALIAS: u32 = 16;
    /// Output each pixel's sample and page look-up counts (`render::counts`).
    pub const DEBUG_COUNTS: u32 = 32;
    /// Bricked regions under lenses step at the camera footprint's level
    /// (`VolumeView::lens_context_steps`).
    pub const LENS_CONTEXT_STEPS: u32 = 64;
}

/// One region, with everything the shader needs about its volume and appearance.
#[derive(Clone, Copy, Debug, Default, PartialEq, ShaderType)]
pub struct GpuRegion {
    pub world_to_voxel: Mat4,
    /// Upper 3×3: world→voxel linear part transposed (voxel gradient → world normal).
    pub normal_matrix: Mat4,
    /// Upper 3×3: world direction → the volume's own millimetres (for step lengths).
    pub to_native: Mat4,
    /// Voxel dimensions (xyz) and the largest code of the storage type (w).
    pub dims: Vec4,
    /// ambient, diffuse, specular, shininess.
    pub shading: Vec4,
    /// Brick grid dimensions (xyz) and brick size (w).
    pub bricks: UVec4,
    /// Texel offset of the volume in the volume atlas (xyz).
    pub atlas_offset: Vec4,
    /// Offset of the brick grid in the brick atlas (xyz).
    pub brick_offset: UVec4,
    pub plane_offset: u32,
    pub plane_count: u32,
    /// Boxes cut out of the region: `hole_count` × six planes from `hole_offset`.
    pub hole_offset: u32,
    pub hole_count: u32,
    pub mode: u32,
    pub flags: u32,
    pub lut_offset: u32,
    pub lut_width: u32,
    pub occupancy_offset: u32,
    pub lut_a: f32,
    pub lut_b: f32,
    pub native_step: f32,
    pub reference_length: f32,
    pub iso: f32,
    pub gradient_max: f32,
    /// Mip levels above the volume in the atlas (0 when the atlas has no room for them).
    pub mip_count: u32,
    /// Objects of a segmentation: the inclusive range of normalised samples they take.
    pub value_lo: f32,
    pub value_hi: f32,
    /// Atlas texel offsets of mip levels 1… (xyz).
    pub mips: [Vec4; MIP_LEVELS],
    /// Context-preserving κt, κs, power ([`context_power`]).
    pub context: Vec4,
    /// World bounding sphere of the volume's box (centre, radius).
    pub sphere: Vec4,
    /// World bounding sphere of the region's polyhedron (centre, radius; an infinite
    /// radius when it has no vertices): rays that miss it skip the region's planes.
    pub bounds: Vec4,
    /// In the first region of each run of [`CLUSTER`] (the ray's interval loop tests
    /// them together): a sphere around the run's `bounds`; unused in the others.
    pub cluster: Vec4,
    /// Segmented regions ([`mode::TWO_LEVEL`]): index of the first part record (the
    /// objects, then the rest), the number of parts, and the index of the label
    /// record (the label volume with, per code, up to four candidate objects + 1);
    /// with [`region_flags::COMPANION`] (no objects), `y`: the offset of the pair table
    /// of both looks (`render::pack::pair_table`), `z`: the record of the region drawn
    /// in this one's samples; `w`: with [`region_flags::SELECTION`], the index of the selection record (the
    /// selection volume, its map from the data's voxel index, `lut_a·t + lut_b` the
    /// degree of interest of a normalised sample `t`).
    pub objects: UVec4,
    /// A bricked volume (`render::bricked`): its place in the page directory + 1 (`0`:
    /// in memory), brick size, apron, coarse level `C`.
    pub bricked: UVec4,
    /// `2^C` (coarse voxel index → level-0 index), the level-0 voxel size in the volume's
    /// own millimetres (the footprint's unit for a ray's level).
    pub bricked_scale: Vec4,
    /// A bricked volume's level-0 voxel dims (xyz) and its page table's directory level
    /// `G` (w; `render::bricked::page_table`).
    pub bricked_dims: UVec4,
    /// Projections: the normalised samples they take (inclusive; xy), from
    /// `Appearance::projection_range`, and the region's projection group (z, as a float:
    /// `reference::prepare::PreparedRegion::projection_group`).
    pub projection: Vec4,
}

/// Regions the interval loop tests together (`REGION_CLUSTER` in
/// `shaders/focal/types.wgsl`): a group of rays that misses the sphere around a run of
/// this many consecutive regions skips them all. On llvmpipe the loop's cost per region
/// (the sphere test and its bookkeeping), not the planes, was most of an exploded view's
/// interval time: 60 of 70 ms a frame with 64 parts.
pub const CLUSTER: usize = 8;

/// Lens kinds, shapes (codes shared with `shaders/focal/lens.wgsl`).
pub mod lens_codes {
    pub const MAGNIFIER: u32 = 0;
    pub const SAMPLING: u32 = 1;
    pub const ANGULAR: u32 = 2;
    pub const CIRCLE: u32 = 0;
    pub const SQUARE: u32 = 1;
    pub const POLYGON: u32 = 2;
    pub const FEATURE: u32 = 3;
    /// `vec4`s of table or outline data per lens.
    pub const DATA_PER_LENS: usize = 16;
}

/// One lens of a view.
#[derive(Clone, Copy, Debug, Default, PartialEq, ShaderType)]
pub struct GpuLens {
    /// kind, shape, border profile, outline vertex count.
    pub codes: UVec4,
    /// centre (xy, lens units), focus radius, border width.
    pub geometry: Vec4,
    /// Magnifier: lens plane distance, κ, magnification. Angular: half field of view,
    /// whole view (1/0).
    pub params: Vec4,
}

/// Per-view settings.
#[derive(Component, Clone, Copy, Debug, PartialEq, ShaderType)]
pub struct GpuSettings {
    /// Light direction towards the light (xyz), w = 1 for a fixed light, 0 for headlight.
    pub light: Vec4,
    pub flags: u32,
    pub frame: u32,
    pub lens_count: u32,
    /// Fraction of the view's pixels per axis the rays are drawn at
    /// ([`crate::dataset::VolumeView::resolution`], [`super::reduced`]).
    pub resolution: f32,
    pub lenses: [GpuLens; crate::lens::MAX_LENSES],
    /// Outline vertices (two per vec4) or sampling tables (four values per vec4),
    /// `DATA_PER_LENS` per lens.
    pub lens_data: [Vec4; crate::lens::MAX_LENSES * lens_codes::DATA_PER_LENS],
}

impl Default for GpuSettings {
    fn default() -> Self {
        GpuSettings {
            light: Vec4::ZERO,
            flags: 0,
            frame: 0,
            lens_count: 0,
            resolution: 1.0,
            lenses: [GpuLens::default(); crate::lens::MAX_LENSES],
            lens_data: [Vec4::ZERO; crate::lens::MAX_LENSES * lens_codes::DATA_PER_LENS],
        }
    }
}

/// Per-scene facts.
#[derive(Clone, Copy, Debug, Default, PartialEq, ShaderType)]
pub struct GpuSceneInfo {
    /// 1 / size of the volume atlas in texels (xyz).
    pub inv_atlas_size: Vec4,
    pub region_count: u32,
    /// (The LUT atlas's width is a shader constant, `LUT_ATLAS_WIDTH`.)
    pub pad_a: u32,
    /// Bound on the iterations of every loop along a ray ([`super::pack::march_bound`]).
    pub max_steps: u32,
    /// How many of `insets` are in use.
    pub inset_count: u32,
    /// The clip windows drawn in their datasets' samples ([`super::pack::insets`]): in
    /// the uniform buffer, where every SIMD lane reads them alike (on llvmpipe each read
    /// of a storage buffer at an address taken from another record loaded lane by lane,
    /// and six planes a window so read cost 5 % of a frame).
    pub insets: [GpuInset; MAX_INSETS],
}

/// Region records in the uniform copy of the records (`MAX_UNIFORM_REGIONS` in
/// `shaders/focal/types.wgsl`): 120 records of 544 bytes, within the 64 KiB a uniform
/// binding may hold. The copy is always bound, this size, zeros past the scene's.
pub const MAX_UNIFORM_REGIONS: usize = 120;

/// Planes in the uniform copy of the planes (`MAX_UNIFORM_PLANES` in
/// `shaders/focal/types.wgsl`): 16 bytes each, 64 KiB.
pub const MAX_UNIFORM_PLANES: usize = 4096;

/// Occupancy words in the uniform copy of the occupancy bits (`MAX_UNIFORM_OCCUPANCY` in
/// `shaders/focal/types.wgsl`, which counts them in fours: a uniform array's stride is
/// 16 bytes): 64 KiB.
pub const MAX_UNIFORM_OCCUPANCY: usize = 16384;

/// Most clip windows a scene draws in place (`render::pack::insets`; `MAX_INSETS` in
/// `shaders/focal/types.wgsl`).
pub const MAX_INSETS: usize = 4;

/// A clip window drawn in place: the six planes of its box (`n·x − d`, negative
/// inside), the record of the region it is drawn in, and its table in the lookup atlas.
#[derive(Clone, Copy, Debug, Default, PartialEq, ShaderType)]
pub struct GpuInset {
    pub planes: [Vec4; 6],
    pub host: u32,
    pub lut_offset: u32,
}
