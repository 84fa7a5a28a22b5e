//! Everything the per-pixel function needs about one region, computed once per render:
//! the sampler, the baked lookup, the brick occupancy and the constants of the mode.

use glam::{Affine3A, Mat3, Vec3};

use crate::context::ContextParams;
use crate::region::ObjectTable;
use crate::region::{Appearance, Lookup, Mode, Region, Shading};
use crate::transfer::Lut;
use crate::volume::encode::NO_DATA_GAP;
use crate::volume::pyramid::level_index;
use crate::volume::sample::VolumeSampler;
use crate::volume::{BrickGrid, Volume};

/// A baked lookup.
pub enum PreparedLookup {
    /// Transfer-function table and the map `u = a·t + b` from normalised sample to texcoord.
    Transfer { lut: Lut, a: f32, b: f32 },
    /// RGBA per label id.
    Labels(Vec<[f32; 4]>),
}

impl PreparedLookup {
    /// RGBA of a normalised sample (transfer functions) or of a label code.
    #[inline]
    pub fn classify(&self, t: f32, code: u16) -> [f32; 4] {
        match self {
            PreparedLookup::Transfer { lut, a, b } => lut.sample(a * t + b),
            PreparedLookup::Labels(table) => table.get(code as usize).copied().unwrap_or([0.0; 4]),
        }
    }

    /// (λt, λs) of a normalised sample (1 for label volumes).
    #[inline]
    pub fn lambda(&self, t: f32) -> [f32; 2] {
        match self {
            PreparedLookup::Transfer { lut, a, b } => lut.sample_lambda(a * t + b),
            PreparedLookup::Labels(_) => [1.0, 1.0],
        }
    }
}

/// A region ready to be sampled.
pub struct PreparedRegion<'a> {
    pub region: &'a Region,
    pub volume: &'a Volume,
    pub sampler: VolumeSampler<'a>,
    pub lookup: PreparedLookup,
    pub mode: Mode,
    pub shading: Shading,
    /// Step length in the volume's own millimetres.
    pub native_step: f32,
    /// Reference length of transfer-function opacities (`Volume::opacity_reference`).
    pub reference_length: f32,
    /// World→voxel linear part transposed: turns voxel-index gradients into world ones.
    pub normal_matrix: Mat3,
    /// World→native millimetres linear map (index→world of the volume after the region map).
    pub to_native: Mat3,
    /// Iso-value as a normalised sample.
    pub iso: f32,
    /// The normalised samples a projection takes (inclusive; `Appearance::projection_range`).
    pub projection: (f32, f32),
    /// The projection this region's samples belong to ([`projection_groups`]): the index
    /// of the first region showing the same volume with the same projecting look (the
    /// parts of an exploded view, the rest beside a same-look window), one value along the
    /// whole ray; the region's own index otherwise.
    pub projection_group: usize,
    /// Largest gradient magnitude (normalised units per voxel), for gradient modulation.
    pub gradient_max: f32,
    /// Per-brick visibility (DVR modes with a transfer function): invisible bricks add
    /// nothing and are not sampled.
    pub occupancy: Option<(&'a BrickGrid, Vec<bool>)>,
    /// Per-brick visibility of samples from mip levels up to 1, and from coarser ones
    /// (lenses' anti-aliasing, `Appearance::mip_brick_occupancy`); `None`: every brick
    /// may be visible there.
    pub mip_occupancy: Option<[Vec<bool>; 2]>,
    /// κt, κs of [`Mode::Context`].
    pub context: ContextParams,
    /// World-space bounding sphere (centre, radius) of the volume's box: the extent the
    /// context-preserving eye distance is normalised over.
    pub sphere: (Vec3, f32),
    /// Two-level rendering: the objects of a segmented volume.
    pub objects: Option<PreparedObjects<'a>>,
    /// Opacity weighted by a selection.
    pub weight: Option<PreparedWeight<'a>>,
}

/// A selection weight ready to be sampled.
pub struct PreparedWeight<'a> {
    pub weight: &'a crate::region::SelectionWeight,
    pub sampler: VolumeSampler<'a>,
    /// Data voxel index → selection voxel index.
    pub data_to_selection: Affine3A,
}

impl PreparedWeight<'_> {
    /// The weight at data voxel `q` (the degree of interest trilinearly sampled).
    #[inline]
    pub fn at(&self, q: Vec3) -> f32 {
        let t = self.sampler.trilinear(self.data_to_selection.transform_point3(q));
        self.weight.weight(self.weight.volume.normalized_to_real(t as f64) as f32)
    }
}

/// The objects of a segmented region ([`crate::twolevel`]), ready to be sampled.
pub struct PreparedObjects<'a> {
    pub table: ObjectTable,
    pub labels: VolumeSampler<'a>,
    pub label_volume: &'a Volume,
    /// Data voxel index → label voxel index.
    pub data_to_label: Affine3A,
    /// One prepared region per object, then the rest (the data volume's appearance).
    pub parts: Vec<PreparedRegion<'a>>,
    /// Per part: whether it draws.
    pub visible: Vec<bool>,
    /// `Segmentation::own_values` asked for, and the label volume lies on the data's
    /// grid (voxel for voxel): boundaries are sampled from each object's own voxels
    /// ([`Self::own_value`]).
    pub on_grid: bool,
    /// `Segmentation::own_values` (for bricked data the GPU checks level 0's grid).
    pub own_values: bool,
    /// Each label code's class (`twolevel::code_classes`): codes of the same objects
    /// (with `own_values` only).
    pub classes: Vec<u16>,
}

impl PreparedObjects<'_> {
    /// The part a sample at data voxel `q` with normalised value `v` belongs to.
    #[inline]
    pub fn part_at(&self, q: Vec3, v: f32) -> usize {
        let code = self.labels.nearest(self.data_to_label.transform_point3(q));
        self.table.object(code, v).unwrap_or(self.parts.len() - 1)
    }

    /// The value of a sample at data voxel `q` (plain trilinear value `v`, from `data`)
    /// taken from the voxels of its own label class alone (`twolevel::code_classes`:
    /// labels of the same objects): the trilinear weights of the cell's eight voxels
    /// renormalised over those whose class is the sample's, so near
    /// a boundary no other object's values bleed into this one's (a bone value into the
    /// soft tissue beside a skull drawn as another object: a rim). `v` where the cell
    /// holds one label, or the labels are not on the data's grid.
    pub fn own_value(&self, data: &VolumeSampler, q: Vec3, v: f32) -> f32 {
        if !self.on_grid {
            return v;
        }
        let class = |code: u16| self.classes.get(code as usize).copied().unwrap_or(u16::MAX);
        let code = class(self.labels.nearest(q));
        let last = self.label_volume.dims().as_vec3() - 1.0;
        let base = q.floor();
        let f = q - base;
        let (mut sum, mut weights, mut one_label) = (0.0f32, 0.0f32, true);
        for i in 0..8u32 {
            let o = Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32);
            let c = (base + o).clamp(Vec3::ZERO, last);
            let w = (Vec3::ONE - o - f + 2.0 * o * f).abs().element_product();
            if class(self.labels.nearest(c)) == code {
                sum += w * data.trilinear(c);
                weights += w;
            } else {
                one_label = false;
            }
        }
        if one_label || weights <= 0.0 { v } else { sum / weights }
    }
}

impl<'a> PreparedRegion<'a> {
    /// A region with its appearance; a segmented appearance also prepares its objects.
    pub fn new(region: &'a Region, volume: &'a Volume, appearance: &'a Appearance) -> Self {
        let mut p = Self::plain(region, volume, appearance);
        if let Some(seg) = &appearance.segmentation {
            let mut parts: Vec<PreparedRegion<'a>> = seg.objects.iter().map(|o| Self::plain(region, volume, &o.appearance)).collect();
            parts.push(Self::plain(region, volume, appearance));
            let mut visible: Vec<bool> = seg.objects.iter().map(|o| o.visible).collect();
            visible.push(seg.rest_visible);
            p.objects = Some(PreparedObjects {
                table: seg.table(volume),
                labels: seg.labels.sampler(),
                label_volume: &seg.labels,
                data_to_label: seg.data_to_label(&volume.grid),
                parts,
                visible,
                on_grid: seg.own_values
                    && seg.labels.dims() == volume.dims()
                    && seg.data_to_label(&volume.grid).abs_diff_eq(Affine3A::IDENTITY, 1e-4),
                own_values: seg.own_values,
                classes: if seg.own_values {
                    let table = seg.table(volume);
                    crate::twolevel::code_classes(&table, table.candidates.len())
                } else {
                    Vec::new()
                },
            });
        }
        p
    }

    /// A region with its appearance, objects left out.
    fn plain(region: &'a Region, volume: &'a Volume, appearance: &'a Appearance) -> Self {
        let labels = matches!(appearance.lookup, Lookup::Labels(_));
        let lookup = match &appearance.lookup {
            Lookup::Transfer(tf) => {
                let lut = Lut::for_volume(tf, volume);
                let (a, b) = lut.texcoord_map(volume);
                PreparedLookup::Transfer { lut, a, b }
            }
            Lookup::Labels(styles) => PreparedLookup::Labels(styles.bake(volume.stats.code_max as usize + 1)),
        };
        // Label volumes are composited like DVR whatever the mode says; context-preserving
        // DVR at κt = 0 is DVR.
        let mode = if labels { Mode::Dvr } else { appearance.effective_mode() };
        let occupancy = appearance.brick_occupancy(volume).map(|occ| (volume.bricks(), occ));
        let mip_occupancy = occupancy.as_ref().and_then(|_| appearance.mip_brick_occupancy(volume));
        let a = Mat3::from(region.world_to_voxel.matrix3);
        let index_to_native = volume.grid.direction * Mat3::from_diagonal(volume.grid.spacing);
        let reference_length = volume.opacity_reference();
        PreparedRegion {
            region,
            volume,
            sampler: volume.sampler(),
            lookup,
            mode,
            shading: appearance.shading,
            native_step: appearance.step.max(0.01) * volume.grid.min_spacing(),
            reference_length,
            normal_matrix: a.transpose(),
            to_native: index_to_native * a,
            iso: volume.real_to_normalized(appearance.iso_value) as f32,
            projection: projection_range(appearance, volume),
            projection_group: usize::MAX,
            gradient_max: volume.gradient_max().max(1e-6),
            occupancy,
            mip_occupancy,
            context: appearance.context,
            sphere: bounding_sphere(region, volume),
            objects: None,
            weight: appearance.selection.as_ref().map(|w| PreparedWeight {
                weight: w,
                sampler: w.volume.sampler(),
                data_to_selection: w.volume.grid.world_to_index() * volume.grid.index_to_world(),
            }),
        }
    }

    /// The region cut to the box of the bricks its appearance makes visible (its
    /// occupancy): outside that box every full-resolution sample is transparent. The
    /// region itself when there is no occupancy or nothing is visible.
    pub fn visible_part(&self) -> std::borrow::Cow<'_, Region> {
        let Some((bricks, occupied)) = &self.occupancy else { return std::borrow::Cow::Borrowed(self.region) };
        let Some((lo, hi)) = bricks.bounds_where(occupied) else { return std::borrow::Cow::Borrowed(self.region) };
        let dims = self.volume.dims().as_vec3();
        std::borrow::Cow::Owned(self.region.cut_to_index_box(lo.max(Vec3::splat(-0.5)), hi.min(dims - 0.5)))
    }

    /// World step that advances `native_step` in the volume along `dir`.
    pub fn world_step(&self, dir: Vec3) -> f32 {
        let scale = (self.to_native * dir).length().max(1e-9);
        self.native_step / scale
    }

    /// Whether the brick holding voxel position `q` can contribute (always true when
    /// there is no occupancy).
    #[inline]
    pub fn occupied(&self, q: Vec3) -> bool {
        match &self.occupancy {
            Some((bricks, occ)) => occ[bricks.index(bricks.brick_at(q))],
            None => true,
        }
    }

    /// Trilinear sample at voxel position `q` from mip level `level` of the volume
    /// (`crate::volume::pyramid`): level 0 is the volume itself, a fractional level
    /// blends the two nearest, levels beyond the chain clamp to its top.
    pub fn sample(&self, q: Vec3, level: f32) -> f32 {
        if level <= 0.0 {
            return self.sampler.trilinear(q);
        }
        let pyramid = self.volume.pyramid();
        let level = level.min(pyramid.len() as f32);
        let k = level.floor() as u32;
        let at = |k: u32| match k {
            0 => self.sampler.trilinear(q),
            _ => {
                let l = &pyramid[k as usize - 1];
                VolumeSampler::new(&l.voxels, l.dims).trilinear(level_index(q, k))
            }
        };
        let (a, f) = (at(k), level - k as f32);
        if f > 0.0 { a + (at(k + 1) - a) * f } else { a }
    }

    /// [`Self::index_gradient`] of mip level `level`.
    pub fn index_gradient_at(&self, q: Vec3, level: f32) -> Vec3 {
        if level <= 0.0 || matches!(self.lookup, PreparedLookup::Labels(_)) {
            return self.index_gradient(q);
        }
        let d = |e: Vec3| self.sample(q + e, level) - self.sample(q - e, level);
        Vec3::new(d(Vec3::X), d(Vec3::Y), d(Vec3::Z)) * 0.5
    }

    /// Gradient at voxel position `q` in normalised units per voxel (index axes). Label
    /// volumes use the gradient of the label opacity field.
    pub fn index_gradient(&self, q: Vec3) -> Vec3 {
        match &self.lookup {
            PreparedLookup::Labels(table) => {
                let alpha = |p: Vec3| table.get(self.sampler.nearest(p) as usize).map(|c| c[3]).unwrap_or(0.0);
                Vec3::new(
                    alpha(q + Vec3::X) - alpha(q - Vec3::X),
                    alpha(q + Vec3::Y) - alpha(q - Vec3::Y),
                    alpha(q + Vec3::Z) - alpha(q - Vec3::Z),
                ) * 0.5
            }
            PreparedLookup::Transfer { .. } => self.sampler.gradient(q),
        }
    }
}

/// World-space bounding sphere of the volume's box as the region places it (voxel
/// centres span `-0.5 … dims − 0.5` in index space).
pub fn bounding_sphere(region: &Region, volume: &Volume) -> (Vec3, f32) {
    let to_world = region.world_to_voxel.inverse();
    let dims = volume.dims().as_vec3();
    let centre = to_world.transform_point3(dims * 0.5 - 0.5);
    (centre, 0.5 * crate::region::longest_diagonal(Mat3::from(to_world.matrix3), dims))
}

/// The normalised samples a projection of `appearance` takes from `volume`: its
/// projection range as codes, or all (the ends as far as f32 holds, for the GPU).
///
/// A volume with no-data voxels (NaN in the file, `ValueMap::no_data`: code 0, its true
/// values from [`NO_DATA_GAP`] up) never projects the codes below its first true value:
/// a MinIP through a masked image would otherwise be the no-data code wherever a ray
/// crosses the mask, and an X-ray's mean would count it as values.
pub fn projection_range(appearance: &Appearance, volume: &Volume) -> (f32, f32) {
    let (lo, hi) = match appearance.projection_range {
        Some((lo, hi)) => {
            let (a, b) = (volume.real_to_normalized(lo) as f32, volume.real_to_normalized(hi) as f32);
            // (A negative rescale slope turns the range round.)
            (a.min(b), a.max(b))
        }
        None => (f32::MIN, f32::MAX),
    };
    match volume.values.no_data {
        Some(code) => {
            let first_value = (code as f32 + NO_DATA_GAP as f32) / volume.code_max() as f32;
            (lo.max(first_value), hi)
        }
        None => (lo, hi),
    }
}

/// Each region's projection group ([`PreparedRegion::projection_group`]): regions that
/// project (MIP, MinIP, X-ray, not segmented) the same volume with equal looks share the
/// first one's index; every other region has its own. Looks are the scene's
/// `appearances` compared by value (an exploded view gives each part its own copy).
pub fn projection_groups(prepared: &[PreparedRegion], appearances: &[Appearance]) -> Vec<usize> {
    let projects = |p: &PreparedRegion| p.objects.is_none() && p.mode.is_projection();
    (0..prepared.len())
        .map(|i| {
            let (p, look) = (&prepared[i], appearances.get(prepared[i].region.appearance));
            if !projects(p) {
                return i;
            }
            (0..i)
                .find(|&j| {
                    let q = &prepared[j];
                    projects(q) && q.region.volume == p.region.volume && appearances.get(q.region.appearance) == look
                })
                .unwrap_or(i)
        })
        .collect()
}
