//! Per-label colour and opacity for label volumes.
//!
//! Each label id has a colour, an opacity and a visibility; the table is baked into an
//! RGBA lookup indexed by id (sampled nearest, never interpolated: ids are categories).

use std::collections::BTreeMap;

use super::color::srgb3_to_linear;
use crate::volume::LabelTable;

/// How one label is drawn.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LabelStyle {
    pub color: [f32; 3],
    pub opacity: f32,
    pub visible: bool,
}

/// Styles of all labels of a label volume.
#[derive(Clone, Debug, PartialEq)]
pub struct LabelTransfer {
    pub styles: BTreeMap<u32, LabelStyle>,
    /// Opacity of ids without a style (0 hides unknown ids).
    pub default_opacity: f32,
}

impl LabelTransfer {
    /// Colours from the table, every label but the background (0) at `opacity`.
    pub fn from_table(table: &LabelTable, ids: impl IntoIterator<Item = u32>, opacity: f32) -> Self {
        let styles = ids
            .into_iter()
            .map(|id| {
                let c = table.color(id);
                let color = [c[0] as f32 / 255.0, c[1] as f32 / 255.0, c[2] as f32 / 255.0];
                (id, LabelStyle { color, opacity: if id == 0 { 0.0 } else { opacity }, visible: id != 0 })
            })
            .collect();
        Self { styles, default_opacity: 0.0 }
    }

    /// RGBA per id `0..len`, colour in linear light (hidden labels get opacity 0).
    pub fn bake(&self, len: usize) -> Vec<[f32; 4]> {
        (0..len as u32)
            .map(|id| match self.styles.get(&id) {
                Some(s) => {
                    let c = srgb3_to_linear(s.color);
                    [c[0], c[1], c[2], if s.visible { s.opacity } else { 0.0 }]
                }
                None => [1.0, 1.0, 1.0, self.default_opacity],
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::Label;

    #[test]
    fn bakes_colours_and_hides() {
        let mut table = LabelTable::default();
        table.labels.insert(2, Label { name: "b".into(), color: [255, 0, 0] });
        let mut t = LabelTransfer::from_table(&table, [0, 2, 3], 0.5);
        assert_eq!(t.bake(4)[2], [1.0, 0.0, 0.0, 0.5]); // pure red is red in both spaces
        assert_eq!(t.bake(4)[0][3], 0.0);
        assert_eq!(t.bake(4)[1], [1.0, 1.0, 1.0, 0.0]);
        t.styles.get_mut(&2).unwrap().visible = false;
        assert_eq!(t.bake(4)[2][3], 0.0);
    }
}
