#define_import_path focal::types

// Mirrors src/render/gpu_types.rs (field order and types must match).

struct Region {
    world_to_voxel: mat4x4<f32>,
    normal_matrix: mat4x4<f32>,
    to_native: mat4x4<f32>,
    dims: vec4<f32>,
    shading: vec4<f32>,
    bricks: vec4<u32>,
    atlas_offset: vec4<f32>,
    brick_offset: vec4<u32>,
    plane_offset: u32,
    plane_count: u32,
    // Boxes cut out of the region (clip windows): six planes each from hole_offset.
    hole_offset: u32,
    hole_count: u32,
    mode: u32,
    flags: u32,
    lut_offset: u32,
    lut_width: u32,
    occupancy_offset: u32,
    lut_a: f32,
    lut_b: f32,
    native_step: f32,
    reference_length: f32,
    iso: f32,
    gradient_max: f32,
    mip_count: u32,
    // Objects of a segmentation: the inclusive range of normalised samples they take.
    value_lo: f32,
    value_hi: f32,
    // Atlas offsets of mip levels 1, 2, 3 (xyz).
    mips: array<vec4<f32>, 3>,
    // Context-preserving κt, κs, power (CONTEXT_SCHLICK or CONTEXT_EXACT).
    context: vec4<f32>,
    // World bounding sphere of the volume's box (centre, radius).
    sphere: vec4<f32>,
    // World bounding sphere of the region's polyhedron (centre, radius).
    bounds: vec4<f32>,
    // In the first region of each run of REGION_CLUSTER: a sphere around their bounds.
    cluster: vec4<f32>,
    // Segmented regions: first part record, part count, label record.
    objects: vec4<u32>,
    // A bricked volume: page directory index + 1 (0: in memory), brick size, apron,
    // coarse level C (render::bricked).
    bricked: vec4<u32>,
    // 2^C, the level-0 voxel size in the volume's own millimetres.
    bricked_scale: vec4<f32>,
    // Its level-0 voxel dims and page table directory level G.
    bricked_dims: vec4<u32>,
    // Projections: the normalised samples they take (inclusive range, xy) and the
    // region's projection group (z; raycast.wgsl leave_projection).
    projection: vec4<f32>,
}

struct Lens {
    // kind, shape, border profile, outline vertex count
    codes: vec4<u32>,
    // centre (xy, lens units), focus radius, border width
    geometry: vec4<f32>,
    // magnifier: plane distance, kappa, magnification; angular: half angle, whole view
    params: vec4<f32>,
}

const MAX_LENSES: u32 = 4u;
const LENS_DATA: u32 = 16u;

struct Settings {
    light: vec4<f32>,
    flags: u32,
    frame: u32,
    lens_count: u32,
    // Fraction of the view's pixels per axis the ray caster draws (render::reduced).
    resolution: f32,
    lenses: array<Lens, 4>,
    lens_data: array<vec4<f32>, 64>,
}

struct SceneInfo {
    inv_atlas_size: vec4<f32>,
    region_count: u32,
    pad_a: u32,
    // Bound on the iterations of every loop along a ray (render::pack::march_bound).
    max_steps: u32,
    // The clip windows drawn in their datasets' samples, insets[0 … inset_count)
    // (focal::insets).
    inset_count: u32,
    insets: array<Inset, MAX_INSETS>,
}

// The uniform copies' sizes (render::gpu_types::MAX_UNIFORM_REGIONS, MAX_UNIFORM_PLANES,
// MAX_UNIFORM_OCCUPANCY: words, read four to a vec4 as a uniform array's stride is 16
// bytes; focal::bindings).
const MAX_UNIFORM_REGIONS: u32 = 120u;
const MAX_UNIFORM_PLANES: u32 = 4096u;
const MAX_UNIFORM_OCCUPANCY: u32 = 16384u;

// (render::gpu_types::MAX_INSETS)
const MAX_INSETS: u32 = 4u;

// Texels per row of the lookup-table atlas (render::pack::LUT_ATLAS_WIDTH).
const LUT_ATLAS_WIDTH: u32 = 4096u;

// A clip window drawn in place: its box's planes (n·x − d, negative inside), the
// record of the region it is drawn in, its table's offset in the lookup atlas.
struct Inset {
    planes: array<vec4<f32>, 6>,
    host: u32,
    lut_offset: u32,
}

const MODE_DVR: u32 = 0u;
const MODE_MIP: u32 = 1u;
const MODE_MIN_IP: u32 = 2u;
const MODE_X_RAY: u32 = 3u;
const MODE_GRADIENT_DVR: u32 = 4u;
const MODE_ISO: u32 = 5u;
const MODE_CONTEXT: u32 = 6u;
const MODE_TWO_LEVEL: u32 = 7u;
const MODE_OFF: u32 = 8u;

const CONTEXT_SCHLICK: f32 = 0.0;
const CONTEXT_EXACT: f32 = 1.0;

const REGION_LABELS: u32 = 1u;
const REGION_SHADING: u32 = 2u;
const REGION_OCCUPANCY: u32 = 4u;
// The transfer function has λt, λs channels (after the colours in the LUT atlas).
const REGION_LAMBDA: u32 = 8u;
// Opacity weighted by a selection (record: objects.w); KEEP_UNSELECTED: by 1 − doi.
const REGION_SELECTION: u32 = 16u;
const REGION_KEEP_UNSELECTED: u32 = 32u;
// Another region is drawn in this one's samples (record: objects.z; the pair table of
// both looks: objects.y; render::pack::companions, render::pack::pair_table).
const REGION_COMPANION: u32 = 64u;
// A segmented region whose labels lie on its data's grid (two_level::own_value).
const REGION_ON_GRID: u32 = 128u;

const VIEW_JITTER: u32 = 1u;
const VIEW_SKIP_EMPTY: u32 = 2u;
const VIEW_EARLY_TERMINATION: u32 = 4u;
const VIEW_DEBUG_RAYS: u32 = 8u;
const VIEW_LENS_ANTIALIAS: u32 = 16u;
// Output the ray's sample and page look-up counts instead of its colour
// (render::counts decodes them).
const VIEW_DEBUG_COUNTS: u32 = 32u;
// Bricked regions under lenses step at the camera footprint's level.
const VIEW_LENS_CONTEXT_STEPS: u32 = 64u;

// Accumulated opacity at which a ray stops (reference: trace::EARLY_TERMINATION).
const EARLY_TERMINATION: f32 = 0.99;
// Bisection steps refining an iso-surface crossing (reference: trace::ISO_REFINEMENT).
const ISO_REFINEMENT: u32 = 8u;
// Most regions one ray can cross.
const MAX_RAY_REGIONS: u32 = 12u;
// Regions the interval loop tests together (render::gpu_types::CLUSTER).
const REGION_CLUSTER: u32 = 8u;
