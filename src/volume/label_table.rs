//! Label tables: the names and colours of label ids ([`super::labels`] holds the
//! volumes of ids). Ids missing from a table get a distinct generated colour so nothing
//! is invisible by accident.

use std::collections::BTreeMap;

/// One entry of a label table.
#[derive(Clone, Debug, PartialEq)]
pub struct Label {
    pub name: String,
    pub color: [u8; 3],
}

/// Names and colours of label ids.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LabelTable {
    pub labels: BTreeMap<u32, Label>,
}

impl LabelTable {
    pub fn len(&self) -> usize {
        self.labels.len()
    }

    pub fn is_empty(&self) -> bool {
        self.labels.is_empty()
    }

    pub fn get(&self, id: u32) -> Option<&Label> {
        self.labels.get(&id)
    }

    /// Name of an id (`"label 17"` when unnamed, `"background"` for 0 when unnamed).
    pub fn name(&self, id: u32) -> String {
        match self.labels.get(&id) {
            Some(l) => l.name.clone(),
            None if id == 0 => "background".into(),
            None => format!("label {id}"),
        }
    }

    /// Colour of an id: the table's, else a generated one.
    pub fn color(&self, id: u32) -> [u8; 3] {
        self.labels.get(&id).map(|l| l.color).unwrap_or_else(|| generated_color(id))
    }

    /// Merges `other` into `self`: its names replace generated ones, its colours apply
    /// where given. Used to combine a names file with a colour file.
    pub fn merge(&mut self, other: LabelTable) {
        for (id, l) in other.labels {
            self.labels.insert(id, l);
        }
    }
}

/// A distinct colour for an id (golden-angle hue walk, fixed saturation and value).
pub fn generated_color(id: u32) -> [u8; 3] {
    if id == 0 {
        return [0, 0, 0];
    }
    let h = (id as f32 * 137.507_77).rem_euclid(360.0) / 60.0;
    let (s, v) = (0.65f32, 0.95f32);
    let c = v * s;
    let x = c * (1.0 - (h.rem_euclid(2.0) - 1.0).abs());
    let (r, g, b) = match h as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = v - c;
    [((r + m) * 255.0) as u8, ((g + m) * 255.0) as u8, ((b + m) * 255.0) as u8]
}
