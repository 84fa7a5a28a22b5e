//! How a region looks: rendering mode, lookup (transfer function or label styles),
//! shading and sampling step. Shared by the CPU reference and the GPU renderer.

use serde::{Deserialize, Serialize};

use glam::Vec3;

use crate::context::ContextParams;
use crate::transfer::{LabelTransfer, Lut, TransferFunction};
use crate::twolevel::Segmentation;
use crate::volume::Volume;

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
    pub volume: std::sync::Arc<Volume>,
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
        }
    }

    /// Which bricks of `volume` can contribute under this appearance, for the modes that
    /// composite samples (DVR, gradient-modulated DVR, label volumes): a brick whose code
    /// range maps only to zero opacity adds nothing. `None` for modes that look at every
    /// sample (projections, iso-surfaces). Segmented volumes: see
    /// [`Segmentation::brick_occupancy`].
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

    /// [`Self::brick_occupancy`] of this appearance's own mode and lookup (for a
    /// segmented volume: of the rest).
    fn own_brick_occupancy(&self, volume: &Volume) -> Option<Vec<bool>> {
        let bricks = volume.bricks();
        match &self.lookup {
            Lookup::Transfer(tf) if matches!(self.mode, Mode::Dvr | Mode::GradientDvr | Mode::Context) => {
                let lut = Lut::for_volume(tf, volume);
                let map = &volume.values;
                Some(bricks.occupancy(|lo, hi| lut.max_opacity_between(map.to_real(lo as f64), map.to_real(hi as f64)) > 0.0))
            }
            Lookup::Transfer(_) => None,
            Lookup::Labels(styles) => {
                let table = styles.bake(volume.stats.code_max as usize + 1);
                Some(bricks.occupancy(|lo, hi| table.get(lo as usize..=hi as usize).is_some_and(|t| t.iter().any(|c| c[3] > 0.0))))
            }
        }
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
