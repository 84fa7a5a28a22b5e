//! How a look is written in scene files: [`AppearanceSpec`] and the specs it holds
//! (label styles, the objects of a segmentation), and the conversions between a spec and
//! the [`Appearance`] it describes.
//!
//! Every technique that shows data with a look of its own (a window's contents, an
//! exploded view's selection, a segmentation's objects) writes it as an
//! [`AppearanceSpec`], so the spec lives here, beside the appearance, where they can all
//! use it; the scene file only composes them.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::appearance::{Appearance, Lookup, Mode, Shading};
use crate::context::ContextParams;
use crate::transfer::{LabelStyle, LabelTransfer, TransferFunction, presets};
use crate::volume::{LabelTable, Volume};

fn default_step() -> f32 {
    0.5
}

fn default_label_opacity() -> f32 {
    0.6
}

fn yes() -> bool {
    true
}

/// How a dataset looks.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AppearanceSpec {
    #[serde(default)]
    pub mode: Mode,
    /// A built-in preset name or a `.ron` file (default: chosen for the data).
    #[serde(default)]
    pub preset: Option<String>,
    /// An inline transfer function (wins over `preset`).
    #[serde(default)]
    pub transfer: Option<TransferFunction>,
    /// Show the dataset as a label volume.
    #[serde(default)]
    pub labels: Option<LabelsSpec>,
    #[serde(default)]
    pub shading: Option<Shading>,
    /// Sample distance in units of the smallest voxel spacing.
    #[serde(default = "default_step")]
    pub step: f32,
    /// Iso-value in the data's units (default: middle of the value range).
    #[serde(default)]
    pub iso: Option<f64>,
    /// κt, κs of the context-preserving mode.
    #[serde(default)]
    pub context: ContextParams,
    /// Projections take only samples within (low, high), the data's units
    /// ([`Appearance::projection_range`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub projection_range: Option<(f64, f64)>,
    /// Two-level rendering: objects from a label dataset, each with its own appearance;
    /// this appearance draws the rest.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub segmentation: Option<SegmentationSpec>,
}

/// The objects of a segmented dataset (two-level rendering, [`crate::twolevel`]); in
/// this file because an object's look is an [`AppearanceSpec`] again.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SegmentationSpec {
    /// Index in `datasets` of the label volume (it may be hidden; its grid places it).
    pub labels: usize,
    /// In order: a sample belongs to the first object that takes it.
    pub objects: Vec<ObjectSpec>,
    /// Whether samples in no object are drawn.
    #[serde(default = "yes")]
    pub rest_visible: bool,
    /// Each sample's value from its own object's voxels at boundaries (no rims;
    /// `Segmentation::own_values`).
    #[serde(default)]
    pub own_values: bool,
}

/// One object of a segmentation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectSpec {
    pub name: String,
    /// Label codes it takes.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub labels: Vec<u32>,
    /// Label names from the label dataset's table (a trailing `*` matches every name
    /// with that prefix). With neither codes nor names the object takes every label.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub names: Vec<String>,
    /// Range of data values (real units, inclusive) it takes.
    #[serde(default)]
    pub values: Option<(f64, f64)>,
    #[serde(default = "yes")]
    pub visible: bool,
    /// Mode, transfer function, shading, iso-value, context parameters.
    #[serde(default)]
    pub appearance: AppearanceSpec,
}

impl Default for AppearanceSpec {
    fn default() -> Self {
        Self {
            mode: Mode::Dvr,
            preset: None,
            transfer: None,
            labels: None,
            shading: None,
            step: 0.5,
            iso: None,
            context: ContextParams::default(),
            projection_range: None,
            segmentation: None,
        }
    }
}

/// Label-volume display: the table and per-label overrides.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LabelsSpec {
    /// Label table file (default: the sidecar files beside the volume).
    #[serde(default)]
    pub table: Option<PathBuf>,
    /// Opacity of every label but the background.
    #[serde(default = "default_label_opacity")]
    pub opacity: f32,
    /// Overrides by label id.
    #[serde(default)]
    pub styles: BTreeMap<u32, LabelOverride>,
}

impl Default for LabelsSpec {
    fn default() -> Self {
        Self { table: None, opacity: 0.6, styles: BTreeMap::new() }
    }
}

/// A change to one label's style.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LabelOverride {
    #[serde(default)]
    pub color: Option<(f32, f32, f32)>,
    #[serde(default)]
    pub opacity: Option<f32>,
    #[serde(default)]
    pub visible: Option<bool>,
}

impl AppearanceSpec {
    /// The appearance this spec describes for `volume` (`table`: its label table when it
    /// is shown as a label volume; `base`: the folder a preset file is relative to). A
    /// segmentation refers to another dataset and is resolved by the caller
    /// ([`crate::twolevel::spec::segmentation`]); the result has none.
    pub fn appearance(&self, volume: &Volume, table: Option<&LabelTable>, base: &Path) -> Result<Appearance, String> {
        let lookup = match (&self.labels, table) {
            (Some(labels), Some(table)) => Lookup::Labels(labels.styles_for(volume, table)),
            _ => Lookup::Transfer(match (&self.transfer, &self.preset) {
                (Some(tf), _) => tf.clone().validated()?,
                (None, Some(p)) => presets::load_relative(p, base)?,
                (None, None) if self.mode.is_projection() => presets::builtin("grayscale_ramp")?,
                (None, None) => presets::default_for(volume)?,
            }),
        };
        if !(0.01..=16.0).contains(&self.step) {
            return Err(format!("step {} is outside 0.01..16 voxels", self.step));
        }
        if let Some(range) = self.projection_range {
            check_projection_range(range)?;
        }
        Ok(Appearance {
            mode: self.mode,
            lookup,
            shading: self.shading.unwrap_or_default(),
            step: self.step,
            iso_value: self.iso.unwrap_or((volume.stats.min + volume.stats.max) * 0.5),
            context: self.context.validated()?,
            segmentation: None,
            selection: None,
            projection_range: self.projection_range,
        })
    }

    /// An appearance as a spec: its transfer function inline, label styles as
    /// overrides of `labels_table` (the spec it was loaded with, if any); no
    /// segmentation.
    pub fn of(a: &Appearance, labels_table: Option<&LabelsSpec>) -> AppearanceSpec {
        let (transfer, labels) = match &a.lookup {
            Lookup::Transfer(tf) => (Some(tf.clone()), None),
            Lookup::Labels(styles) => {
                let base = labels_table.cloned().unwrap_or_default();
                let styles = styles
                    .styles
                    .iter()
                    .map(|(id, s)| {
                        let o = LabelOverride {
                            color: Some((s.color[0], s.color[1], s.color[2])),
                            opacity: Some(s.opacity),
                            visible: Some(s.visible),
                        };
                        (*id, o)
                    })
                    .collect();
                (None, Some(LabelsSpec { styles, ..base }))
            }
        };
        AppearanceSpec {
            mode: a.mode,
            preset: None,
            transfer,
            labels,
            shading: Some(a.shading),
            step: a.step,
            iso: Some(a.iso_value),
            context: a.context,
            projection_range: a.projection_range,
            segmentation: None,
        }
    }
}

/// A projection range is finite and not empty; the message names the problem.
pub fn check_projection_range((lo, hi): (f64, f64)) -> Result<(), String> {
    if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
        return Err(format!("projection_range ({lo}, {hi}) must be two finite values, low ≤ high"));
    }
    Ok(())
}

impl LabelsSpec {
    /// Label styles from `table` for the labels `volume` holds, with this spec's opacity
    /// and overrides.
    pub fn styles_for(&self, volume: &Volume, table: &LabelTable) -> LabelTransfer {
        let ids =
            crate::volume::stats::code_counts(&volume.voxels).into_iter().enumerate().filter(|(_, c)| *c > 0).map(|(id, _)| id as u32);
        let mut styles = LabelTransfer::from_table(table, ids, self.opacity);
        for (id, o) in &self.styles {
            let s = styles.styles.entry(*id).or_insert(LabelStyle { color: [1.0; 3], opacity: self.opacity, visible: true });
            if let Some((r, g, b)) = o.color {
                s.color = [r, g, b];
            }
            if let Some(a) = o.opacity {
                s.opacity = a;
            }
            if let Some(v) = o.visible {
                s.visible = v;
            }
        }
        styles
    }
}
