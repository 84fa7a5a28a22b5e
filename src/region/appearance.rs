//! How a region looks: rendering mode, lookup (transfer function or label styles),
//! shading and sampling step, the parameters of the context-preserving mode, the weight
//! of a selection, and the objects of a segmented volume (two-level rendering,
//! [`crate::twolevel`]), each with a look of its own. Shared by the CPU reference and
//! the GPU renderer.
//!
//! ## Objects of a segmented volume and the per-sample object lookup
//!
//! A sample belongs to the first object (in list order) that lists its label code — an
//! object with no codes takes every code — and whose value range, if it has one,
//! contains the sample's data value; a sample in no object belongs to the rest. So one
//! label can be split by value (the AAL atlas's background 0 holds scalp, skull and
//! white matter alike; "label 0 with a bright T1 value" picks the scalp and marrow), and
//! a value range alone makes objects of data without labels.
//!
//! Both renderers look objects up in an [`ObjectTable`]: per label code, the first
//! [`MAX_CANDIDATES`] objects that list it, tried in order against their value ranges.
//! [`Segmentation`] and [`Appearance`] hold each other (an object's look is an
//! appearance), so they live in one file.

use std::sync::Arc;

use glam::{Affine3A, Vec3};
use serde::{Deserialize, Serialize};

use crate::context::ContextParams;
use crate::transfer::{LabelTransfer, Lut, TransferFunction};
use crate::volume::{Grid, LabelTable, Volume};

/// Rendering modes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// Direct volume rendering, front-to-back compositing with Blinn-Phong shading.
    #[default]
    Dvr,
    /// Maximum intensity projection.
    Mip,
    /// Minimum intensity projection.
    #[serde(rename = "minip")]
    MinIp,
    /// Average along the ray (a simulated radiograph).
    #[serde(rename = "xray")]
    XRay,
    /// DVR with opacity scaled by the normalised gradient magnitude.
    GradientDvr,
    /// First hit of an iso-value, shaded.
    Iso,
    /// Context-preserving DVR (Bruckner et al. 2005, [`crate::context`]): opacity
    /// modulated by gradient magnitude, shading, eye distance and accumulated opacity.
    Context,
}

impl Mode {
    pub const ALL: [Mode; 7] = [Mode::Dvr, Mode::Mip, Mode::MinIp, Mode::XRay, Mode::GradientDvr, Mode::Iso, Mode::Context];

    pub fn name(self) -> &'static str {
        match self {
            Mode::Dvr => "dvr",
            Mode::Mip => "mip",
            Mode::MinIp => "minip",
            Mode::XRay => "xray",
            Mode::GradientDvr => "gradient_dvr",
            Mode::Iso => "iso",
            Mode::Context => "context",
        }
    }

    /// Whether the mode projects one value per region instead of compositing samples.
    pub fn is_projection(self) -> bool {
        matches!(self, Mode::Mip | Mode::MinIp | Mode::XRay)
    }
}

impl std::str::FromStr for Mode {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let s = s.trim().to_ascii_lowercase().replace('-', "_");
        Mode::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| format!("unknown mode '{s}' (dvr, mip, minip, xray, gradient_dvr, iso, context)"))
    }
}

/// Blinn-Phong coefficients: `c·(ka + kd·max(N·L, 0)) + ks·max(N·H, 0)^shininess`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Shading {
    pub enabled: bool,
    pub ambient: f32,
    pub diffuse: f32,
    pub specular: f32,
    pub shininess: f32,
}

impl Default for Shading {
    fn default() -> Self {
        Self { enabled: true, ambient: 0.3, diffuse: 0.7, specular: 0.25, shininess: 24.0 }
    }
}

/// Where the light comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub enum Light {
    /// From the eye, along each ray.
    #[default]
    Headlight,
    /// A fixed world-space direction *towards* the light.
    Direction(glam::Vec3),
}

/// What a sample's value is looked up in.
#[derive(Clone, Debug, PartialEq)]
pub enum Lookup {
    /// A transfer function (baked for the region's volume when rendering).
    Transfer(TransferFunction),
    /// Per-label styles of a label volume (nearest sampling).
    Labels(LabelTransfer),
}

/// Which samples a selection weight keeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Keep {
    /// Opacity × the degree of interest: the selection (an exploded view's focus).
    Selected,
    /// Opacity × (1 − the degree of interest): the rest (an exploded view's parts).
    Unselected,
}

/// Opacity weighted by a selection volume's degree of interest (Bruckner and Gröller
/// 2006, section 4: the parts draw the data less the selection, the selection's own
/// region the data in it). The selection is placed by its grid in the data volume's
/// frame, like a segmentation's labels, so it follows the data through any region map.
/// The transfer function's opacity is weighted before the step correction; modes that
/// do not composite samples (projections, iso-surfaces) ignore the weight.
#[derive(Clone, Debug)]
pub struct SelectionWeight {
    /// Degree of interest in `[0, 1]` (a [`crate::volume::SelectionVolume`]'s volume).
    pub volume: Arc<Volume>,
    pub keep: Keep,
}

/// Equal when they use the same selection (the same shared data) alike.
impl PartialEq for SelectionWeight {
    fn eq(&self, other: &Self) -> bool {
        std::sync::Arc::ptr_eq(&self.volume, &other.volume) && self.keep == other.keep
    }
}

impl SelectionWeight {
    /// Refines the occupancy of `volume`'s bricks: a brick whose selection range gives
    /// weight 0 throughout (none selected for [`Keep::Selected`], all for
    /// [`Keep::Unselected`]) adds nothing. Only when the selection lies on the volume's
    /// own grid (its bricks are then the same); otherwise the occupancy stays.
    pub fn brick_occupancy(&self, volume: &Volume, mut occupancy: Vec<bool>) -> Vec<bool> {
        let (data, sel) = (volume.bricks(), self.volume.bricks());
        if self.volume.grid != volume.grid || data.dims != sel.dims || data.size != sel.size || occupancy.len() != sel.len() {
            return occupancy;
        }
        let doi = |code: u16| self.volume.values.to_real(code as f64) as f32;
        for (i, o) in occupancy.iter_mut().enumerate() {
            *o &= match self.keep {
                Keep::Selected => doi(sel.max[i]) > 0.0,
                Keep::Unselected => doi(sel.min[i]) < 1.0,
            };
        }
        occupancy
    }

    /// The weight of a degree of interest.
    pub fn weight(&self, doi: f32) -> f32 {
        match self.keep {
            Keep::Selected => doi.clamp(0.0, 1.0),
            Keep::Unselected => 1.0 - doi.clamp(0.0, 1.0),
        }
    }
}

/// Whether codes `lo ..= hi` can show anything ([`Appearance::code_visibility`]).
pub type CodeVisibility = Box<dyn Fn(u16, u16) -> bool + Send + Sync>;

/// The appearance of a region.
#[derive(Clone, Debug, PartialEq)]
pub struct Appearance {
    pub mode: Mode,
    pub lookup: Lookup,
    pub shading: Shading,
    /// Distance between samples in units of the volume's smallest voxel spacing.
    pub step: f32,
    /// Iso-value in real units (for [`Mode::Iso`]).
    pub iso_value: f64,
    /// κt, κs of [`Mode::Context`].
    pub context: ContextParams,
    /// Two-level rendering ([`crate::twolevel`]): a label volume splits the data into
    /// objects with their own modes; this appearance then draws the rest.
    pub segmentation: Option<Segmentation>,
    /// Opacity weighted by a selection ([`SelectionWeight`]).
    pub selection: Option<SelectionWeight>,
    /// Projections (MIP, MinIP, X-ray) take only the samples within this range of
    /// values (the data's units, inclusive), as radiology viewers' thresholds do: a
    /// MinIP above the air around an object, a MIP below metal. `None`: every sample.
    pub projection_range: Option<(f64, f64)>,
}

impl Appearance {
    pub fn new(mode: Mode, tf: TransferFunction) -> Self {
        Self {
            mode,
            lookup: Lookup::Transfer(tf),
            shading: Shading::default(),
            step: 0.5,
            iso_value: 0.0,
            context: ContextParams::default(),
            segmentation: None,
            selection: None,
            projection_range: None,
        }
    }

    /// The mode the ray caster composites this look with: context-preserving DVR whose
    /// equation 5 is plain DVR (κt = 0, `ContextParams::is_plain_dvr`) is DVR.
    pub fn effective_mode(&self) -> Mode {
        let lambda_s_positive = match &self.lookup {
            Lookup::Transfer(tf) => tf.lambda_s.iter().all(|p| p.1 > 0.0),
            Lookup::Labels(_) => true,
        };
        if self.mode == Mode::Context && self.context.is_plain_dvr(lambda_s_positive) { Mode::Dvr } else { self.mode }
    }

    /// Whether the look (or an object of its segmentation) weighs samples by the
    /// normalised gradient magnitude (gradient-modulated and context-preserving DVR),
    /// which needs the volume's largest gradient.
    pub fn uses_gradient_magnitude(&self) -> bool {
        matches!(self.mode, Mode::GradientDvr | Mode::Context)
            || self.segmentation.as_ref().is_some_and(|s| s.objects.iter().any(|o| o.appearance.uses_gradient_magnitude()))
    }

    /// The same look with every opacity times `scale` (in 0..1; an exploded part fading
    /// by the viewing force). Segmentations' objects keep theirs.
    pub fn with_opacity_scaled(mut self, scale: f32) -> Appearance {
        if scale >= 1.0 {
            return self;
        }
        let s = scale.clamp(0.0, 1.0);
        match &mut self.lookup {
            Lookup::Transfer(tf) => tf.opacity.iter_mut().for_each(|p| p.1 *= s),
            Lookup::Labels(l) => {
                l.default_opacity *= s;
                l.styles.values_mut().for_each(|st| st.opacity *= s);
            }
        }
        self
    }

    /// Which bricks of `volume` can contribute under this appearance, for the modes that
    /// composite samples (DVR, gradient-modulated DVR, label volumes): a brick whose code
    /// range maps only to zero opacity adds nothing. `None` for modes that look at every
    /// sample (projections, iso-surfaces). Segmented volumes: see
    /// [`Segmentation::brick_occupancy`].
    pub fn brick_occupancy(&self, volume: &Volume) -> Option<Vec<bool>> {
        let occupancy = match &self.segmentation {
            Some(seg) => Some(seg.brick_occupancy(volume, self.own_brick_occupancy(volume))),
            None => self.own_brick_occupancy(volume),
        };
        match (&self.selection, occupancy) {
            (Some(w), Some(occupancy)) => Some(w.brick_occupancy(volume, occupancy)),
            (_, occupancy) => occupancy,
        }
    }

    /// [`Self::brick_occupancy`] for samples of the volume's mip levels (lenses'
    /// anti-aliasing, which blends neighbouring voxels in): for levels up to 1 (and
    /// blends of 0 and 1) a brick's range over a wider apron must be invisible
    /// (`Volume::level_one_bricks`), for coarser ones its whole neighbourhood's
    /// (`BrickGrid::neighbourhood_occupancy`); label volumes are never blended (their
    /// occupancy holds for both). A selection only takes opacity away, so the look's own
    /// answer bounds it; `None` where that does not hold (segmented volumes: each object
    /// has its own look) and where [`Self::brick_occupancy`] is `None`: every brick is
    /// then sampled at those levels.
    pub fn mip_brick_occupancy(&self, volume: &Volume) -> Option<[Vec<bool>; 2]> {
        if self.segmentation.is_some() {
            return None;
        }
        let visible = self.own_code_visibility(volume)?;
        match self.lookup {
            Lookup::Labels(_) => {
                let fine = volume.bricks().occupancy(visible);
                Some([fine.clone(), fine])
            }
            Lookup::Transfer(_) => {
                let coarse = volume.bricks().neighbourhood_occupancy(&visible)?;
                Some([volume.level_one_bricks().occupancy(visible), coarse])
            }
        }
    }

    /// [`Self::brick_occupancy`] of this appearance's own mode and lookup (for a
    /// segmented volume: of the rest).
    fn own_brick_occupancy(&self, volume: &Volume) -> Option<Vec<bool>> {
        let visible = self.own_code_visibility(volume)?;
        Some(volume.bricks().occupancy(visible))
    }

    /// Whether codes between `lo` and `hi` (inclusive) can show anything under this
    /// appearance's own mode and lookup, for `volume`'s codes; `None` where every code
    /// may (projections, iso-surfaces).
    fn own_code_visibility(&self, volume: &Volume) -> Option<CodeVisibility> {
        match &self.lookup {
            Lookup::Transfer(tf) if matches!(self.mode, Mode::Dvr | Mode::GradientDvr | Mode::Context) => {
                let lut = Lut::for_volume(tf, volume);
                let (visible, map) = (lut.visible_texels(), volume.values.clone());
                Some(Box::new(move |lo, hi| {
                    let (i0, i1) = lut.texels_between(map.to_real(lo as f64), map.to_real(hi as f64));
                    visible.any(i0, i1)
                }))
            }
            Lookup::Transfer(_) => None,
            Lookup::Labels(styles) => {
                let table = styles.bake(volume.stats.code_max as usize + 1);
                let visible = crate::transfer::visible::VisibleEntries::new(table.iter().map(|c| c[3] > 0.0));
                Some(Box::new(move |lo, hi| visible.any(lo as usize, hi as usize)))
            }
        }
    }

    /// [`Self::own_code_visibility`] for a whole appearance: `None` also where a
    /// segmentation or selection decides (bricks streamed with such a look are never
    /// skipped as empty). `volume` gives the codes' meaning (any level of a pyramid).
    pub fn code_visibility(&self, volume: &Volume) -> Option<CodeVisibility> {
        if self.segmentation.is_some() || self.selection.is_some() {
            return None;
        }
        self.own_code_visibility(volume)
    }

    /// World-space bounds of what this appearance shows of `volume` (the bricks with any
    /// opacity; the whole box for projections and iso-surfaces).
    pub fn visible_bounds(&self, volume: &Volume) -> Option<(Vec3, Vec3)> {
        let Some(keep) = self.brick_occupancy(volume) else { return Some(volume.grid.world_bounds()) };
        volume
            .bricks()
            .bounds_where(&keep)
            .map(|(lo, hi)| volume.grid.index_box_world_bounds(lo.max(Vec3::splat(-0.5)), hi.min(volume.dims().as_vec3() - 0.5)))
    }
}

/// Most objects of one segmentation (the shader keeps one region record per object).
pub const MAX_OBJECTS: usize = 64;
/// Most objects that may list one label code (one RGBA texel of candidates per code).
pub const MAX_CANDIDATES: usize = 4;

/// A data volume's split into objects by a label volume.
#[derive(Clone, Debug)]
pub struct Segmentation {
    /// The label volume. It is placed by its grid in the data volume's frame (both
    /// grids' world coordinates are the same scanner space), so it follows the data
    /// volume wherever a region shows it.
    pub labels: Arc<Volume>,
    /// Names and colours of the labels, when the label volume has a table.
    pub table: Option<Arc<LabelTable>>,
    pub objects: Vec<Object>,
    /// Whether samples in no object are drawn (with the data volume's own appearance).
    pub rest_visible: bool,
    /// Each sample's value from its own object's voxels where a cell straddles objects
    /// (no rim of one object's values around another: `twolevel`, "Object boundaries");
    /// labels on the data's grid only. Costs the cell's labels at every boundary sample.
    pub own_values: bool,
}

/// Equal when they use the same label volume (the same shared data) the same way.
impl PartialEq for Segmentation {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.labels, &other.labels)
            && self.objects == other.objects
            && self.rest_visible == other.rest_visible
            && self.own_values == other.own_values
    }
}

/// One object: which samples it takes and how its segments are rendered.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    pub name: String,
    /// Label codes it takes (empty: every code).
    pub labels: Vec<u32>,
    /// Range of data values (real units, inclusive) it takes; `None`: any value.
    pub values: Option<(f64, f64)>,
    /// Hidden objects keep their samples (they do not fall to the rest) but draw nothing.
    pub visible: bool,
    /// Mode, transfer function, shading, iso-value and context parameters of its
    /// segments (the sample step is the data volume's).
    pub appearance: Appearance,
}

impl Object {
    /// An object of `labels` rendered with `appearance`.
    pub fn new(name: impl Into<String>, labels: Vec<u32>, appearance: Appearance) -> Object {
        Object { name: name.into(), labels, values: None, visible: true, appearance }
    }

    /// Whether the object lists `code`.
    pub fn takes_code(&self, code: u32) -> bool {
        self.labels.is_empty() || self.labels.contains(&code)
    }
}

impl Segmentation {
    /// Checks what the renderers rely on; errors name the object.
    pub fn validate(&self) -> Result<(), String> {
        if self.objects.len() > MAX_OBJECTS {
            return Err(format!("{} objects: at most {MAX_OBJECTS} per segmentation", self.objects.len()));
        }
        for o in &self.objects {
            if !matches!(o.appearance.lookup, Lookup::Transfer(_)) {
                return Err(format!("object '{}': needs a transfer function (label colours are for label volumes)", o.name));
            }
            if o.appearance.segmentation.is_some() {
                return Err(format!("object '{}': an object cannot be segmented again", o.name));
            }
            if let Some((lo, hi)) = o.values
                && !(lo.is_finite() && hi.is_finite() && lo <= hi)
            {
                return Err(format!("object '{}': value range ({lo}, {hi}) is not a finite range with low ≤ high", o.name));
            }
        }
        let codes = self.labels.stats.code_max as u32;
        for code in 0..=codes {
            let n = self.objects.iter().filter(|o| o.takes_code(code)).count();
            if n > MAX_CANDIDATES {
                return Err(format!("label {code} is listed by {n} objects: at most {MAX_CANDIDATES} objects may share a label"));
            }
        }
        Ok(())
    }

    /// The label code at data voxel index `q` (nearest label voxel; `None` outside).
    pub fn label_at(&self, data: &Grid, q: glam::Vec3) -> Option<u32> {
        let l = (self.data_to_label(data).transform_point3(q) + 0.5).floor();
        let dims = self.labels.dims().as_vec3();
        if l.cmplt(glam::Vec3::ZERO).any() || l.cmpge(dims).any() {
            return None;
        }
        let u = l.as_uvec3();
        Some(self.labels.code(u.x, u.y, u.z) as u32)
    }

    /// The name of label `code` (from the table, else its number).
    pub fn label_name(&self, code: u32) -> String {
        self.table.as_ref().map_or_else(|| format!("label {code}"), |t| t.name(code))
    }

    /// The first object listing `code` (whatever its value range).
    pub fn object_of_label(&self, code: u32) -> Option<usize> {
        self.objects.iter().position(|o| o.takes_code(code))
    }

    /// Map from the data volume's voxel index to the label volume's.
    pub fn data_to_label(&self, data: &Grid) -> Affine3A {
        self.labels.grid.world_to_index() * data.index_to_world()
    }

    /// The lookup table both renderers use, for data volume `data`.
    pub fn table(&self, data: &Volume) -> ObjectTable {
        let codes = self.labels.stats.code_max as usize + 1;
        let candidates = (0..codes)
            .map(|code| {
                let mut c = [0u16; MAX_CANDIDATES];
                let listed = self.objects.iter().enumerate().filter(|(_, o)| o.takes_code(code as u32));
                for (slot, (i, _)) in c.iter_mut().zip(listed) {
                    *slot = i as u16 + 1;
                }
                c
            })
            .collect();
        let ranges = self
            .objects
            .iter()
            .map(|o| match o.values {
                Some((lo, hi)) => (data.real_to_normalized(lo) as f32, data.real_to_normalized(hi) as f32),
                None => ObjectTable::UNBOUNDED,
            })
            .collect();
        ObjectTable { candidates, ranges }
    }

    /// Which bricks of `data` can contribute, given `rest` (the occupancy of the rest's
    /// own appearance, `None`: every brick). A brick is empty when every part its
    /// samples can fall into draws nothing there: hidden, or DVR-like with zero
    /// opacity over the brick's values. The parts come from the label voxels nearest
    /// to any point of the brick (all candidate objects of their codes, and the rest
    /// where a code has no object or an object with a value range). Projection and
    /// iso-surface parts look at every sample, so a brick where one can occur is kept;
    /// skipping a brick therefore never cuts a segment that would have emitted
    /// something (the renderers end the open segment where they skip).
    pub fn brick_occupancy(&self, data: &Volume, rest: Option<Vec<bool>>) -> Vec<bool> {
        let bricks = data.bricks();
        let table = self.table(data);
        let rest_bit = 1u128 << MAX_OBJECTS;
        let masks: Vec<u128> = table
            .candidates
            .iter()
            .map(|c| {
                let listed = c.iter().take_while(|&&k| k > 0).map(|&k| k as usize - 1);
                let mut m = listed.clone().fold(0u128, |m, k| m | 1 << k);
                if m == 0 || listed.into_iter().any(|k| self.objects[k].values.is_some()) {
                    m |= rest_bit;
                }
                m
            })
            .collect();
        // Per part: drawn at all, and its own occupancy.
        let parts: Vec<(bool, Option<Vec<bool>>)> = self
            .objects
            .iter()
            .map(|o| (o.visible, o.visible.then(|| o.appearance.brick_occupancy(data)).flatten()))
            .chain(std::iter::once((self.rest_visible, rest)))
            .collect();
        let to_label = self.data_to_label(&data.grid);
        let ldims = self.labels.dims();
        let mut out = vec![false; bricks.len()];
        for z in 0..bricks.dims.z {
            for y in 0..bricks.dims.y {
                for x in 0..bricks.dims.x {
                    let b = glam::UVec3::new(x, y, z);
                    let (lo, hi) = bricks.brick_bounds(b);
                    // Nearest label voxels of the brick's box (clamped as the samplers clamp).
                    let corners = (0..8).map(|c| {
                        let p = glam::Vec3::new(
                            if c & 1 == 0 { lo.x } else { hi.x },
                            if c & 2 == 0 { lo.y } else { hi.y },
                            if c & 4 == 0 { lo.z } else { hi.z },
                        );
                        to_label.transform_point3(p)
                    });
                    let (mut a, mut z1) = (glam::Vec3::splat(f32::INFINITY), glam::Vec3::splat(f32::NEG_INFINITY));
                    for c in corners {
                        a = a.min(c);
                        z1 = z1.max(c);
                    }
                    let first = (a + 0.5).floor().max(glam::Vec3::ZERO).as_uvec3().min(ldims - 1);
                    let last = (z1 + 0.5).floor().max(glam::Vec3::ZERO).as_uvec3().min(ldims - 1);
                    let mut mask = 0u128;
                    for k in first.z..=last.z {
                        for j in first.y..=last.y {
                            for i in first.x..=last.x {
                                mask |= masks.get(self.labels.code(i, j, k) as usize).copied().unwrap_or(rest_bit);
                            }
                        }
                    }
                    let index = bricks.index(b);
                    out[index] = parts.iter().enumerate().any(|(p, (shown, occ))| {
                        let bit = if p == self.objects.len() { rest_bit } else { 1 << p };
                        mask & bit != 0 && *shown && occ.as_ref().is_none_or(|o| o[index])
                    });
                }
            }
        }
        out
    }

    /// The modes the objects draw with (for the shader's feature list).
    pub fn modes(&self) -> impl Iterator<Item = Mode> + '_ {
        self.objects.iter().filter(|o| o.visible).map(|o| o.appearance.mode)
    }
}

/// Per label code, the objects that list it; per object, its normalised value range.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectTable {
    /// Object index + 1 of up to [`MAX_CANDIDATES`] objects per code, in list order
    /// (0: no more).
    pub candidates: Vec<[u16; MAX_CANDIDATES]>,
    /// Inclusive range of normalised samples per object (infinite without a range).
    pub ranges: Vec<(f32, f32)>,
}

impl ObjectTable {
    /// The range of an object without one: every value.
    pub const UNBOUNDED: (f32, f32) = (f32::NEG_INFINITY, f32::INFINITY);

    /// Whether some object takes only a range of values.
    pub fn has_ranges(&self) -> bool {
        self.ranges.iter().any(|&r| r != Self::UNBOUNDED)
    }

    /// The object of a sample with label `code` and normalised data value `v`
    /// (`None`: the rest).
    pub fn object(&self, code: u16, v: f32) -> Option<usize> {
        let c = self.candidates.get(code as usize)?;
        c.iter().take_while(|&&k| k > 0).map(|&k| k as usize - 1).find(|&k| {
            let (lo, hi) = self.ranges[k];
            lo <= v && v <= hi
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transfer::presets;
    use crate::volume::{Source, ValueMap, Voxels};
    use glam::{UVec3, Vec3};

    fn labels(codes: Vec<u8>) -> Arc<Volume> {
        let n = codes.len() as u32;
        let grid = Grid::new(UVec3::new(n, 1, 1), Vec3::ONE);
        Arc::new(Volume::new("labels", grid, Voxels::U8(codes), ValueMap::IDENTITY, Source::default()).unwrap())
    }

    fn object(name: &str, codes: Vec<u32>, values: Option<(f64, f64)>) -> Object {
        let tf = presets::builtin("grayscale_ramp").unwrap();
        Object { values, ..Object::new(name, codes, Appearance::new(Mode::Mip, tf)) }
    }

    #[test]
    fn first_listed_object_whose_range_holds_the_value_wins() {
        let seg = Segmentation {
            table: None,
            labels: labels(vec![0, 1, 2, 3]),
            objects: vec![
                object("bright background", vec![0], Some((128.0, 255.0))),
                object("one and two", vec![1, 2], None),
                object("anything dark", vec![], Some((0.0, 50.0))),
            ],
            rest_visible: true,
            own_values: false,
        };
        seg.validate().unwrap();
        // The data volume maps codes 0…255 to themselves, normalised by 255.
        let data = labels(vec![0, 255]);
        let t = seg.table(&data);
        let n = |x: f64| (x / 255.0) as f32;
        assert_eq!(t.candidates[0], [1, 3, 0, 0]);
        assert_eq!(t.candidates[1], [2, 3, 0, 0]);
        assert_eq!(t.candidates[3], [3, 0, 0, 0]);
        assert_eq!(t.object(0, n(200.0)), Some(0));
        assert_eq!(t.object(0, n(128.0)), Some(0), "inclusive range");
        assert_eq!(t.object(0, n(20.0)), Some(2), "falls through to the next object listing 0");
        assert_eq!(t.object(0, n(90.0)), None, "in no object: the rest");
        assert_eq!(t.object(2, n(90.0)), Some(1));
        assert_eq!(t.object(3, n(60.0)), None);
        assert_eq!(t.object(3, n(10.0)), Some(2));
        assert_eq!(t.object(9, 0.5), None, "codes beyond the table: the rest");
    }

    #[test]
    fn validation_names_the_problem() {
        let mut seg = Segmentation {
            table: None,
            labels: labels(vec![0, 1]),
            objects: vec![object("a", vec![1], Some((5.0, 1.0)))],
            rest_visible: true,
            own_values: false,
        };
        assert!(seg.validate().unwrap_err().contains("object 'a'"));
        seg.objects = (0..5).map(|i| object(&format!("o{i}"), vec![1], None)).collect();
        assert!(seg.validate().unwrap_err().contains("label 1 is listed by 5 objects"));
        seg.objects = vec![Object {
            appearance: Appearance {
                lookup: Lookup::Labels(crate::transfer::LabelTransfer { styles: Default::default(), default_opacity: 0.0 }),
                ..object("x", vec![], None).appearance
            },
            ..object("x", vec![], None)
        }];
        assert!(seg.validate().unwrap_err().contains("transfer function"));
    }

    #[test]
    fn label_voxels_follow_the_data_grid() {
        // Labels at half the resolution of the data, same world box origin.
        let data = Grid::new(UVec3::new(8, 8, 8), Vec3::ONE);
        let seg = Segmentation { table: None, labels: Arc::new(phantom_labels()), objects: vec![], rest_visible: true, own_values: false };
        let m = seg.data_to_label(&data);
        assert!((m.transform_point3(Vec3::new(6.0, 2.0, 4.0)) - Vec3::new(3.0, 1.0, 2.0)).length() < 1e-6);
    }

    fn phantom_labels() -> Volume {
        let grid = Grid::new(UVec3::new(4, 4, 4), Vec3::splat(2.0));
        Volume::new("half", grid, Voxels::U8(vec![0; 64]), ValueMap::IDENTITY, Source::default()).unwrap()
    }
}
