//! Volume data: the grid model, readers, phantoms, label and selection volumes.
//!
//! A [`Volume`] is a regular grid ([`Grid`]: dimensions, spacing, origin, orientation)
//! of compact voxel codes ([`Voxels`], 8 or 16 bit) with a [`ValueMap`] back to real
//! values, its [`ValueStats`] (range, histogram) and the [`BrickGrid`] of per-brick code
//! ranges used for empty-space skipping. Label volumes ([`LabelVolume`]) and selection
//! volumes ([`SelectionVolume`], degree of interest 0..1) are volumes too.

pub mod bricks;
pub mod caught;
pub mod convert;
pub mod encode;
pub mod grid;
pub mod label_table;
pub mod labels;
pub mod phantom;
pub mod pyramid;
pub mod readers;
pub mod resample;
pub mod sample;
pub mod selection;
pub mod source;
pub mod stats;
pub mod voxels;

use std::path::PathBuf;
use std::sync::OnceLock;

use glam::UVec3;

pub use bricks::{BrickGrid, DEFAULT_BRICK_SIZE};
pub use encode::{ByteOrder, SampleType};
pub use grid::Grid;
pub use labels::{Label, LabelTable, LabelVolume};
pub use selection::SelectionVolume;
pub use stats::{Histogram, ValueStats};
pub use voxels::{ValueMap, Voxels};

/// Where a volume came from.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Source {
    /// Format name (`NIfTI-1`, `DICOM series`, `phantom`, …).
    pub format: String,
    /// File or folder it was read from.
    pub path: Option<PathBuf>,
    /// Sample type in the file (`uint8`, `int16`, `float32`, …).
    pub sample_type: String,
    /// Further facts worth showing (`key`, `value`), e.g. the DICOM modality.
    pub details: Vec<(String, String)>,
}

/// A scalar volume.
#[derive(Debug)]
pub struct Volume {
    pub name: String,
    pub grid: Grid,
    pub voxels: Voxels,
    pub values: ValueMap,
    pub stats: ValueStats,
    pub source: Source,
    /// The names and colours of label ids the file itself carries (a DICOM
    /// segmentation's segments): such a volume is shown as labels.
    pub label_table: Option<label_table::LabelTable>,
    /// Length (mm) that transfer-function opacities are given for; `None`: the
    /// smallest voxel spacing ([`Volume::opacity_reference`]).
    opacity_reference: Option<f32>,
    bricks: OnceLock<BrickGrid>,
    level_one_bricks: OnceLock<BrickGrid>,
    gradient_max: OnceLock<f32>,
    pyramid: OnceLock<Vec<pyramid::Level>>,
}

impl Clone for Volume {
    fn clone(&self) -> Self {
        Self {
            name: self.name.clone(),
            grid: self.grid.clone(),
            voxels: self.voxels.clone(),
            values: self.values.clone(),
            stats: self.stats.clone(),
            source: self.source.clone(),
            label_table: self.label_table.clone(),
            opacity_reference: self.opacity_reference,
            bricks: self.bricks.clone(),
            level_one_bricks: self.level_one_bricks.clone(),
            gradient_max: self.gradient_max.clone(),
            pyramid: self.pyramid.clone(),
        }
    }
}

impl Volume {
    /// Builds a volume, checking that the voxel count matches the grid.
    pub fn new(name: impl Into<String>, grid: Grid, voxels: Voxels, values: ValueMap, source: Source) -> Result<Volume, String> {
        grid.validate()?;
        if voxels.len() != grid.voxel_count() {
            return Err(format!(
                "{} voxels do not fill a {} grid ({} voxels)",
                voxels.len(),
                grid::fmt_dims(grid.dims),
                grid.voxel_count()
            ));
        }
        if !(values.slope.is_finite() && values.intercept.is_finite()) || values.slope == 0.0 {
            return Err(format!("value rescale {}·v + {} is not usable", values.slope, values.intercept));
        }
        let stats = stats::compute(&voxels, &values);
        let mut source = source;
        if stats.no_data > 0 {
            source.details.push((
                "note".into(),
                format!(
                    "{} of {} voxels are NaN: shown as empty space, left out of the statistics and the histogram",
                    stats.no_data,
                    voxels.len()
                ),
            ));
        }
        Ok(Volume {
            name: name.into(),
            grid,
            voxels,
            values,
            stats,
            source,
            label_table: None,
            opacity_reference: None,
            bricks: OnceLock::new(),
            level_one_bricks: OnceLock::new(),
            gradient_max: OnceLock::new(),
            pyramid: OnceLock::new(),
        })
    }

    /// The volume as labels with the table its file carries.
    pub fn with_label_table(self, table: label_table::LabelTable) -> Volume {
        Volume { label_table: Some(table), ..self }
    }

    pub fn dims(&self) -> UVec3 {
        self.grid.dims
    }

    /// The length (mm) that transfer-function opacities hold for: a sample one such
    /// length long keeps the table's opacity, others are corrected to their length
    /// (`1 − (1 − α)^(Δ/ℓ)`). The smallest voxel spacing, except for a level of a
    /// pyramid, which keeps its level 0's: every level, and a lens's native bricks
    /// inside a coarser context, are then as opaque per millimetre as the full data.
    pub fn opacity_reference(&self) -> f32 {
        self.opacity_reference.unwrap_or_else(|| self.grid.min_spacing())
    }

    /// This volume with opacities given for `mm` ([`Volume::opacity_reference`]).
    pub fn with_opacity_reference(mut self, mm: f32) -> Volume {
        if mm.is_finite() && mm > 0.0 {
            self.opacity_reference = Some(mm);
        }
        self
    }

    /// Code of voxel (i, j, k).
    #[inline]
    pub fn code(&self, i: u32, j: u32, k: u32) -> u16 {
        self.voxels.code(self.grid.linear_index(i, j, k))
    }

    /// Real value of voxel (i, j, k).
    pub fn real(&self, i: u32, j: u32, k: u32) -> f64 {
        self.values.to_real(self.code(i, j, k) as f64)
    }

    /// Largest code of the storage type (normalisation denominator).
    pub fn code_max(&self) -> u32 {
        self.voxels.code_max()
    }

    /// Real value of a normalised texture value `t = code / code_max`.
    pub fn normalized_to_real(&self, t: f64) -> f64 {
        self.values.to_real(t * self.code_max() as f64)
    }

    /// Normalised texture value of a real value.
    pub fn real_to_normalized(&self, real: f64) -> f64 {
        self.values.to_code(real) / self.code_max() as f64
    }

    /// The brick min-max grid (built on first use, [`DEFAULT_BRICK_SIZE`]).
    pub fn bricks(&self) -> &BrickGrid {
        self.bricks.get_or_init(|| BrickGrid::build(&self.voxels, self.grid.dims, DEFAULT_BRICK_SIZE))
    }

    /// [`Self::bricks`] with ranges that hold the samples of mip level 1 too
    /// ([`bricks::LEVEL_ONE_APRON`]; built on first use).
    pub fn level_one_bricks(&self) -> &BrickGrid {
        self.level_one_bricks
            .get_or_init(|| BrickGrid::build_with_apron(&self.voxels, self.grid.dims, DEFAULT_BRICK_SIZE, bricks::LEVEL_ONE_APRON))
    }

    /// Levels 1… of the mip chain (built on first use; see [`pyramid`]).
    pub fn pyramid(&self) -> &[pyramid::Level] {
        self.pyramid.get_or_init(|| pyramid::build_skipping(&self.voxels, self.grid.dims, self.values.no_data))
    }

    /// Largest central-difference gradient magnitude in normalised units per voxel,
    /// the denominator of normalised gradient magnitude (computed on first use).
    pub fn gradient_max(&self) -> f32 {
        *self.gradient_max.get_or_init(|| sample::max_gradient_magnitude(&self.voxels, self.grid.dims))
    }

    /// A sampler of its voxel codes (trilinear, nearest, gradients).
    pub fn sampler(&self) -> sample::VolumeSampler<'_> {
        sample::VolumeSampler::new(&self.voxels, self.grid.dims)
    }

    /// Approximate memory used by the voxels.
    pub fn byte_len(&self) -> usize {
        self.voxels.byte_len()
    }
}
