//! Label volumes: integer ids per voxel with a table of names and colours.
//!
//! A label volume is a [`Volume`] whose codes *are* the label ids (identity value map,
//! nearest-neighbour sampling). The [`LabelTable`] names the ids and gives each a colour;
//! ids missing from the table get a distinct generated colour so nothing is invisible by
//! accident. Tables are read by [`crate::volume::readers::label_table`].

pub use super::label_table::{Label, LabelTable, generated_color};
use super::{Source, ValueMap, Volume, Voxels};

/// A volume of label ids with their table.
#[derive(Clone, Debug)]
pub struct LabelVolume {
    pub volume: Volume,
    pub table: LabelTable,
}

impl LabelVolume {
    /// Reinterprets a read volume as labels: every real value must be a whole number in
    /// `0..=65535`; codes become the ids themselves (8-bit when ids fit).
    pub fn from_volume(volume: Volume, table: LabelTable) -> Result<LabelVolume, String> {
        let counts = super::stats::code_counts(&volume.voxels);
        let mut max_id = 0u32;
        // (No data, NaN in a float label map, is the background.)
        let no_data = volume.values.no_data.map(usize::from);
        for (code, _) in counts.iter().enumerate().filter(|(c, n)| **n > 0 && Some(*c) != no_data) {
            let real = volume.values.to_real(code as f64);
            if real.fract() != 0.0 || !(0.0..=65535.0).contains(&real) {
                return Err(format!("value {real} is not a label id (whole number 0..65535)"));
            }
            max_id = max_id.max(real as u32);
        }
        let id_of = |c: u16| if Some(c as usize) == no_data { 0 } else { volume.values.to_real(c as f64) as u32 };
        let voxels = match (&volume.voxels, max_id <= 255) {
            (Voxels::U8(v), true) if volume.values == ValueMap::IDENTITY => Voxels::U8(v.clone()),
            (v, true) => Voxels::U8((0..v.len()).map(|i| id_of(v.code(i)) as u8).collect()),
            (v, false) => Voxels::U16((0..v.len()).map(|i| id_of(v.code(i)) as u16).collect()),
        };
        let source = Source { format: volume.source.format.clone(), ..volume.source.clone() };
        let volume = Volume::new(volume.name.clone(), volume.grid.clone(), voxels, ValueMap::IDENTITY, source)?;
        Ok(LabelVolume { volume, table })
    }

    /// Ids present in the volume (with voxel counts), background 0 included.
    pub fn present_ids(&self) -> Vec<(u32, u64)> {
        super::stats::code_counts(&self.volume.voxels)
            .into_iter()
            .enumerate()
            .filter(|(_, c)| *c > 0)
            .map(|(id, c)| (id as u32, c))
            .collect()
    }

    /// Label id of voxel (i, j, k).
    pub fn id(&self, i: u32, j: u32, k: u32) -> u32 {
        self.volume.code(i, j, k) as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nan_in_a_float_label_map_is_background() {
        use crate::volume::encode::{ByteOrder, SampleType, encode_samples};
        let ids: Vec<f32> = vec![f32::NAN, 3.0, 17.0, f32::NAN, 0.0, 3.0, 17.0, 17.0];
        let e = encode_samples(ids.iter().flat_map(|v| v.to_le_bytes()).collect(), SampleType::F32, ByteOrder::Little).unwrap();
        let v =
            Volume::new("labels", crate::volume::Grid::new(glam::UVec3::splat(2), glam::Vec3::ONE), e.voxels, e.map, Default::default())
                .unwrap();
        let l = LabelVolume::from_volume(v, LabelTable::default()).unwrap();
        assert_eq!((0..8).map(|i| l.volume.voxels.code(i)).collect::<Vec<_>>(), vec![0, 3, 17, 0, 0, 3, 17, 17]);
    }
    use crate::volume::Grid;
    use glam::{UVec3, Vec3};

    #[test]
    fn generated_colours_differ_and_background_is_black() {
        assert_eq!(generated_color(0), [0, 0, 0]);
        let a = generated_color(1);
        let b = generated_color(2);
        assert_ne!(a, b);
    }

    #[test]
    fn from_volume_requires_whole_ids() {
        let grid = Grid::new(UVec3::new(3, 1, 1), Vec3::ONE);
        let v = Volume::new("l", grid.clone(), Voxels::U16(vec![0, 5, 300]), ValueMap::IDENTITY, Source::default()).unwrap();
        let l = LabelVolume::from_volume(v, LabelTable::default()).unwrap();
        assert_eq!(l.present_ids(), vec![(0, 1), (5, 1), (300, 1)]);
        let shifted = Volume::new("l", grid.clone(), Voxels::U16(vec![0, 1, 2]), ValueMap::new(1.0, 10.0), Source::default()).unwrap();
        let l = LabelVolume::from_volume(shifted, LabelTable::default()).unwrap();
        assert!(matches!(l.volume.voxels, Voxels::U8(_)));
        assert_eq!(l.id(2, 0, 0), 12);
        let frac = Volume::new("l", grid, Voxels::U16(vec![0, 1, 2]), ValueMap::new(0.5, 0.0), Source::default()).unwrap();
        assert!(LabelVolume::from_volume(frac, LabelTable::default()).is_err());
    }
}
