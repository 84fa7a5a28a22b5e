//! Converting a volume Focal reads into a multiscale pyramid (`focal convert`), so data
//! from NIfTI, DICOM and the other formats can take the bricked, out-of-core path.
//!
//! Levels: level `k + 1` halves level `k` along every axis (an odd size rounds up, the
//! last voxel standing in for the missing one), by the rounded mean of each 2×2×2 block
//! of codes ([`crate::volume::pyramid::halve`]) for intensities and by the block's first
//! voxel (nearest) for label maps, whose ids must not blend. Levels stop once a level
//! fits one chunk. Samples are written in the narrowest type that holds the real values
//! exactly ([`SampleKind::for_volume`]), float32 otherwise.

pub mod ome_zarr;

use glam::UVec3;

use super::pyramid::{self, half_dims};
use super::{Volume, Voxels};

/// How a level is made from the one below.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Downsample {
    /// Rounded mean of each 2×2×2 block (intensities).
    Mean,
    /// The block's first voxel (label ids).
    Nearest,
}

impl Downsample {
    /// The NGFF `type` of the multiscale.
    pub fn name(self) -> &'static str {
        match self {
            Downsample::Mean => "mean",
            Downsample::Nearest => "nearest",
        }
    }
}

/// The level above `voxels` (`dims`).
pub fn next_level(voxels: &Voxels, dims: UVec3, how: Downsample) -> pyramid::Level {
    match how {
        Downsample::Mean => pyramid::halve(voxels, dims),
        Downsample::Nearest => {
            let out = half_dims(dims);
            let (nx, ny) = (dims.x as usize, dims.y as usize);
            let pick = |x: u32, y: u32, z: u32| (2 * z as usize * ny + 2 * y as usize) * nx + 2 * x as usize;
            let idx: Vec<usize> = (0..out.z).flat_map(|z| (0..out.y).flat_map(move |y| (0..out.x).map(move |x| pick(x, y, z)))).collect();
            let voxels = match voxels {
                Voxels::U8(v) => Voxels::U8(idx.iter().map(|&i| v[i]).collect()),
                Voxels::U16(v) => Voxels::U16(idx.iter().map(|&i| v[i]).collect()),
            };
            pyramid::Level { dims: out, voxels }
        }
    }
}

/// The sample type written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleKind {
    U8,
    U16,
    I16,
    F32,
}

impl SampleKind {
    /// The source's `int16`, else the narrowest integer type, no narrower than the codes,
    /// that holds every real value of the volume exactly (codes map to whole numbers by a slope of 1), float32
    /// otherwise.
    pub fn for_volume(v: &Volume) -> SampleKind {
        let m = &v.values;
        // Means of the voxels stay within their range, so every level fits too.
        let whole = m.slope == 1.0 && m.intercept.fract() == 0.0;
        let fits = |a: f64, b: f64| whole && v.stats.min >= a && v.stats.max <= b;
        if v.source.sample_type == "int16" && fits(-32768.0, 32767.0) {
            // Kept as the file had it, even when no value is negative.
            SampleKind::I16
        } else if fits(0.0, 255.0) && v.voxels.bits() == 8 {
            SampleKind::U8
        } else if fits(0.0, 65535.0) {
            SampleKind::U16
        } else if fits(-32768.0, 32767.0) {
            SampleKind::I16
        } else {
            SampleKind::F32
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            SampleKind::U8 => "uint8",
            SampleKind::U16 => "uint16",
            SampleKind::I16 => "int16",
            SampleKind::F32 => "float32",
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::volume::source::level_count;
    use crate::volume::{Grid, Source, ValueMap};

    #[test]
    fn labels_take_the_first_voxel_of_each_block() {
        // 3×2×1: blocks {0,1} and {2} along x, rows 0 and 1 along y.
        let v = Voxels::U8(vec![1, 2, 3, 4, 5, 6]);
        let l = next_level(&v, UVec3::new(3, 2, 1), Downsample::Nearest);
        assert_eq!(l.dims, UVec3::new(2, 1, 1));
        assert_eq!(l.voxels, Voxels::U8(vec![1, 3]));
        let mean = next_level(&v, UVec3::new(3, 2, 1), Downsample::Mean);
        // (1+2+4+5)·2/8 = 3; (3+3+6+6)·2/8 = 4.5 → 5.
        assert_eq!(mean.voxels, Voxels::U8(vec![3, 5]));
    }

    #[test]
    fn the_narrowest_exact_type_is_chosen() {
        let vol = |voxels: Voxels, map: ValueMap| {
            Volume::new("v", Grid::new(UVec3::new(2, 1, 1), Vec3::ONE), voxels, map, Source::default()).expect("volume")
        };
        assert_eq!(SampleKind::for_volume(&vol(Voxels::U8(vec![0, 9]), ValueMap::IDENTITY)), SampleKind::U8);
        assert_eq!(SampleKind::for_volume(&vol(Voxels::U16(vec![0, 9]), ValueMap::IDENTITY)), SampleKind::U16);
        // A CT shifted from -1024: int16.
        assert_eq!(SampleKind::for_volume(&vol(Voxels::U16(vec![0, 3000]), ValueMap::new(1.0, -1024.0))), SampleKind::I16);
        // int8 shifted into 8-bit codes: negative values need int16 here (no int8 output).
        assert_eq!(SampleKind::for_volume(&vol(Voxels::U8(vec![0, 200]), ValueMap::new(1.0, -128.0))), SampleKind::I16);
        // Values past int16 are written as float.
        assert_eq!(SampleKind::for_volume(&vol(Voxels::U16(vec![0, 60000]), ValueMap::new(1.0, -1024.0))), SampleKind::F32);
        // Quantised floats stay float.
        assert_eq!(SampleKind::for_volume(&vol(Voxels::U16(vec![0, 9]), ValueMap::new(0.5, 0.0))), SampleKind::F32);
        assert_eq!(level_count(UVec3::new(181, 217, 181), 64), 3);
    }
}
