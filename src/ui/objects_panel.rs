//! The Objects panel: two-level rendering of the selected dataset ([`crate::twolevel`]).
//!
//! Segment a dataset with any loaded label volume, then make objects from labels
//! (double-click the view to pick one, or add the picked label to the object being
//! edited), give each its mode, show or hide it, restrict it to a value range, and pick
//! which object the transfer-function editor edits. The rest (samples in no object) is
//! drawn with the dataset's own mode and transfer function.

use std::sync::Arc;

use bevy_egui::egui::{self, Color32, RichText, Ui};

use crate::region::{Appearance, Mode};
use crate::region::{Object, Segmentation};
use crate::transfer::presets;
use crate::volume::{LabelTable, Volume};

/// A loaded label volume that can segment others.
pub struct LabelSource {
    pub name: String,
    pub volume: Arc<Volume>,
    pub table: Option<Arc<LabelTable>>,
}

/// What the panel edits besides the segmentation.
pub struct Selection<'a> {
    /// The label last picked on this dataset.
    pub picked: Option<u32>,
    /// The object the transfer-function editor edits (`None`: the rest).
    pub editing: &'a mut Option<usize>,
}

/// The panel for a dataset whose data volume is `data`.
pub fn panel(ui: &mut Ui, data: &Volume, segmentation: &mut Option<Segmentation>, sources: &[LabelSource], sel: Selection) {
    let Some(seg) = segmentation else {
        ui.label(RichText::new("Two-level rendering: each label its own mode and transfer function.").small());
        if sources.is_empty() {
            ui.label(RichText::new("Load a label volume (an atlas or segmentation) to segment this dataset.").small().weak());
        }
        for s in sources {
            if ui.button(format!("Segment with {}", s.name)).clicked() {
                *segmentation = Some(Segmentation {
                    labels: s.volume.clone(),
                    table: s.table.clone(),
                    objects: Vec::new(),
                    rest_visible: true,
                    own_values: false,
                });
                *sel.editing = None;
            }
        }
        return;
    };
    let mut stop = false;
    ui.horizontal(|ui| {
        ui.label(format!("labels: {}", seg.labels.name));
        stop = ui.small_button("stop segmenting").clicked();
    });
    if let Some(code) = sel.picked {
        picked_label(ui, data, seg, code, sel.editing);
    } else {
        ui.label(RichText::new("double-click the view to pick a label, or choose one below").small().weak());
    }
    ui.checkbox(&mut seg.own_values, "no rims at object boundaries").on_hover_text(
        "Each sample's value from its own object's voxels where objects meet (labels on the data's grid); \
         slower in software rendering",
    );
    egui::CollapsingHeader::new("labels").default_open(false).show(ui, |ui| label_list(ui, data, seg, sel.editing));
    let mut remove = None;
    for (k, o) in seg.objects.iter_mut().enumerate() {
        ui.horizontal(|ui| {
            ui.checkbox(&mut o.visible, "");
            let edited = *sel.editing == Some(k);
            if ui.selectable_label(edited, &o.name).on_hover_text("edit its transfer function").clicked() {
                *sel.editing = if edited { None } else { Some(k) };
            }
            mode_combo(ui, k, &mut o.appearance.mode);
            if ui.small_button("✖").on_hover_text("remove the object").clicked() {
                remove = Some(k);
            }
        });
        if *sel.editing == Some(k) {
            object_details(ui, data, seg.table.as_deref(), o);
        }
    }
    ui.horizontal(|ui| {
        ui.checkbox(&mut seg.rest_visible, "");
        let edited = sel.editing.is_none();
        if ui.selectable_label(edited, "the rest").on_hover_text("drawn with this dataset's mode and transfer function").clicked() {
            *sel.editing = None;
        }
    });
    if let Some(k) = remove {
        seg.objects.remove(k);
        *sel.editing = None;
    }
    if stop {
        *segmentation = None;
        *sel.editing = None;
    }
}

/// The picked label: which object holds it, and buttons to make or extend one.
fn picked_label(ui: &mut Ui, data: &Volume, seg: &mut Segmentation, code: u32, editing: &mut Option<usize>) {
    let name = seg.label_name(code);
    let holder = seg.object_of_label(code);
    let text = match holder {
        Some(k) => format!("picked: {name} ({code}) — in '{}'", seg.objects[k].name),
        None => format!("picked: {name} ({code}) — in the rest"),
    };
    ui.label(RichText::new(text).strong().color(Color32::YELLOW));
    ui.horizontal(|ui| {
        if ui.button("new object").on_hover_text("an object of this label, in DVR").clicked()
            && let Ok(tf) = presets::default_for(data)
            && try_edit(ui, seg, |s| s.objects.push(Object::new(name.clone(), vec![code], Appearance::new(Mode::Dvr, tf))))
        {
            *editing = Some(seg.objects.len() - 1);
        }
        if let Some(k) = *editing
            && holder != Some(k)
            && ui.button(format!("add to '{}'", seg.objects[k].name)).clicked()
        {
            try_edit(ui, seg, |s| s.objects[k].labels.push(code));
        }
    });
}

/// Every label of the table with the object holding it; a button makes an object of a
/// label in no object.
fn label_list(ui: &mut Ui, data: &Volume, seg: &mut Segmentation, editing: &mut Option<usize>) {
    let Some(table) = seg.table.clone() else {
        ui.label(RichText::new("the label volume has no table of names").small().weak());
        return;
    };
    egui::ScrollArea::vertical().max_height(200.0).id_salt("object labels").show(ui, |ui| {
        for (&code, label) in &table.labels {
            ui.horizontal(|ui| {
                let [r, g, b] = label.color;
                ui.label(RichText::new("■").color(Color32::from_rgb(r, g, b)));
                ui.label(format!("{} ({code})", label.name));
                match seg.object_of_label(code) {
                    Some(k) => {
                        ui.label(RichText::new(format!("in '{}'", seg.objects[k].name)).small().weak());
                    }
                    None => {
                        if ui.small_button("+ object").clicked()
                            && let Ok(tf) = presets::default_for(data)
                            && try_edit(ui, seg, |s| {
                                s.objects.push(Object::new(label.name.clone(), vec![code], Appearance::new(Mode::Dvr, tf)))
                            })
                        {
                            *editing = Some(seg.objects.len() - 1);
                        }
                    }
                }
            });
        }
    });
}

/// Applies `edit` if the segmentation stays valid; says why not otherwise.
fn try_edit(ui: &mut Ui, seg: &mut Segmentation, edit: impl FnOnce(&mut Segmentation)) -> bool {
    let mut candidate = seg.clone();
    edit(&mut candidate);
    match candidate.validate() {
        Ok(()) => {
            *seg = candidate;
            true
        }
        Err(e) => {
            ui.label(RichText::new(e).color(Color32::LIGHT_RED));
            false
        }
    }
}

fn mode_combo(ui: &mut Ui, k: usize, mode: &mut Mode) {
    egui::ComboBox::from_id_salt(("object mode", k)).width(110.0).selected_text(mode.name()).show_ui(ui, |ui| {
        for m in Mode::ALL {
            ui.selectable_value(mode, m, m.name());
        }
    });
}

/// Labels, value range and iso-value of the object being edited.
fn object_details(ui: &mut Ui, data: &Volume, table: Option<&LabelTable>, o: &mut Object) {
    let names: Vec<String> = o.labels.iter().map(|&c| table.map_or_else(|| format!("{c}"), |t| format!("{} ({c})", t.name(c)))).collect();
    let labels = if names.is_empty() { "every label".to_string() } else { names.join(", ") };
    ui.label(RichText::new(format!("labels: {labels}")).small());
    let (lo, hi) = (data.stats.min, data.stats.max);
    let mut ranged = o.values.is_some();
    if ui.checkbox(&mut ranged, "only values in a range").changed() {
        o.values = ranged.then_some((lo, hi));
    }
    if let Some((a, b)) = &mut o.values {
        ui.add(egui::Slider::new(a, lo..=hi).text("from"));
        ui.add(egui::Slider::new(b, lo..=hi).text("to"));
        *b = b.max(*a);
    }
    if o.appearance.mode == Mode::Iso {
        ui.add(egui::Slider::new(&mut o.appearance.iso_value, lo..=hi).text("iso-value"));
    }
}
