//! Two-level rendering in scene files: a [`SegmentationSpec`] (objects by label codes or
//! names, value ranges, looks) resolved against its label volume into the
//! [`Segmentation`] the renderers draw, and back.
//!
//! The spec types themselves live beside [`crate::region::AppearanceSpec`], which holds
//! them and which an object's look is again.

use std::path::Path;
use std::sync::Arc;

use crate::region::{AppearanceSpec, Object, ObjectSpec, Segmentation, SegmentationSpec};
use crate::volume::{LabelTable, Volume};

/// The label volume a segmentation takes its objects from (a dataset of the scene).
pub struct LabelSource<'a> {
    /// Its name, for messages.
    pub name: &'a str,
    pub volume: &'a Arc<Volume>,
    pub table: Option<&'a LabelTable>,
}

/// The segmentation `spec` describes for data volume `data` with the labels of `labels`;
/// object looks' preset files are relative to `base`. Label names are matched in the
/// label table ([`matching_labels`]); a name no label has is an error naming it.
pub fn segmentation(spec: &SegmentationSpec, labels: LabelSource, data: &Volume, base: &Path) -> Result<Segmentation, String> {
    let objects = spec.objects.iter().map(|o| object(o, &labels, data, base)).collect::<Result<Vec<_>, String>>()?;
    let seg = Segmentation {
        table: labels.table.cloned().map(Arc::new),
        labels: labels.volume.clone(),
        objects,
        rest_visible: spec.rest_visible,
        own_values: spec.own_values,
    };
    seg.validate()?;
    Ok(seg)
}

fn object(o: &ObjectSpec, source: &LabelSource, data: &Volume, base: &Path) -> Result<Object, String> {
    let mut labels = o.labels.clone();
    for pattern in &o.names {
        let found = matching_labels(pattern, source.table);
        if found.is_empty() {
            return Err(format!("object '{}': no label of '{}' is named '{pattern}'", o.name, source.name));
        }
        labels.extend(found);
    }
    labels.sort_unstable();
    labels.dedup();
    if o.appearance.segmentation.is_some() {
        return Err(format!("object '{}': an object cannot be segmented again", o.name));
    }
    Ok(Object {
        name: o.name.clone(),
        labels,
        values: o.values,
        visible: o.visible,
        appearance: o.appearance.appearance(data, None, base).map_err(|e| format!("object '{}': {e}", o.name))?,
    })
}

/// Ids of the labels named `pattern` (a trailing `*` matches a prefix; case-insensitive).
pub fn matching_labels(pattern: &str, table: Option<&LabelTable>) -> Vec<u32> {
    let Some(table) = table else { return Vec::new() };
    let p = pattern.to_ascii_lowercase();
    let matches = |name: &str| {
        let name = name.to_ascii_lowercase();
        match p.strip_suffix('*') {
            Some(prefix) => name.starts_with(prefix),
            None => name == p,
        }
    };
    table.labels.iter().filter(|(_, l)| matches(&l.name)).map(|(id, _)| *id).collect()
}

/// A segmentation as a spec (objects by label code); `labels` is the label dataset's
/// index in the scene.
pub fn segmentation_spec(seg: &Segmentation, labels: usize) -> SegmentationSpec {
    let objects = seg
        .objects
        .iter()
        .map(|o| ObjectSpec {
            name: o.name.clone(),
            labels: o.labels.clone(),
            names: Vec::new(),
            values: o.values,
            visible: o.visible,
            appearance: AppearanceSpec::of(&o.appearance, None),
        })
        .collect();
    SegmentationSpec { labels, objects, rest_visible: seg.rest_visible, own_values: seg.own_values }
}
