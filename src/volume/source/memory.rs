//! A volume in memory as a [`VoxelSource`]: level 0 is the volume itself, the levels
//! above are its mip chain ([`crate::volume::pyramid::halve`], 2×2×2 means of the codes),
//! built when the source is made, down to the size given.

use std::sync::Arc;

use glam::UVec3;

use super::{Block, SourceError, SourceInfo, SourceLevel, VoxelSource, check_box, level_count, level_grid};
use crate::volume::{Volume, Voxels, pyramid};

/// A volume and its mip chain.
pub struct MemorySource {
    volume: Arc<Volume>,
    /// Levels 1…, each with its dimensions.
    above: Vec<pyramid::Level>,
    info: SourceInfo,
}

impl MemorySource {
    /// The volume with levels halving it until no axis exceeds `smallest` voxels.
    pub fn new(volume: Arc<Volume>, smallest: u32) -> Self {
        let n = level_count(volume.dims(), smallest);
        let mut above: Vec<pyramid::Level> = Vec::with_capacity(n - 1);
        for _ in 1..n {
            let (v, d) = above.last().map_or((&volume.voxels, volume.dims()), |l| (&l.voxels, l.dims));
            let next = pyramid::halve_skipping(v, d, volume.values.no_data);
            above.push(next);
        }
        let levels = (0..n as u32).map(|k| SourceLevel { grid: level_grid(&volume.grid, k), chunk: UVec3::splat(64) }).collect();
        let info = SourceInfo {
            name: volume.name.clone(),
            source: volume.source.clone(),
            values: volume.values.clone(),
            bits: volume.voxels.bits(),
            levels,
            warnings: Vec::new(),
            range: Some((volume.stats.min, volume.stats.max)),
        };
        Self { volume, above, info }
    }

    /// The codes of a whole level.
    pub fn level_voxels(&self, level: usize) -> Option<&Voxels> {
        if level == 0 { Some(&self.volume.voxels) } else { self.above.get(level - 1).map(|l| &l.voxels) }
    }
}

impl VoxelSource for MemorySource {
    fn info(&self) -> &SourceInfo {
        &self.info
    }

    fn read_box(&self, level: usize, lo: UVec3, size: UVec3) -> Result<Block, SourceError> {
        check_box(&self.info, level, lo, size)?;
        let dims = self.info.levels[level].grid.dims;
        let Some(voxels) = self.level_voxels(level) else {
            return Err(SourceError::new(self.info.location(), format!("level {level} is missing")));
        };
        Ok(Block { voxels: copy_box(voxels, dims, lo, size), faults: Vec::new() })
    }
}

/// The box `lo .. lo + size` of voxels `src` (`dims`), which must hold it.
pub fn copy_box(src: &Voxels, dims: UVec3, lo: UVec3, size: UVec3) -> Voxels {
    fn copy<T: Copy + Default>(v: &[T], dims: UVec3, lo: UVec3, size: UVec3) -> Vec<T> {
        let mut out = vec![T::default(); size.x as usize * size.y as usize * size.z as usize];
        copy_overlap((v, UVec3::ZERO, dims), (&mut out, lo, size));
        out
    }
    match src {
        Voxels::U8(v) => Voxels::U8(copy(v, dims, lo, size)),
        Voxels::U16(v) => Voxels::U16(copy(v, dims, lo, size)),
    }
}

/// Copies the voxels two boxes of one level share from the first into the second: each
/// given as its values (x fastest), its first voxel and its size.
pub fn copy_overlap<T: Copy>((src, src_lo, src_size): (&[T], UVec3, UVec3), (dst, lo, size): (&mut [T], UVec3, UVec3)) {
    let a = src_lo.max(lo);
    let b = (src_lo + src_size).min(lo + size);
    if a.cmpge(b).any() {
        return;
    }
    let run = (b.x - a.x) as usize;
    let index = |p: UVec3, origin: UVec3, dims: UVec3| {
        let d = p - origin;
        (d.z as usize * dims.y as usize + d.y as usize) * dims.x as usize + d.x as usize
    };
    for z in a.z..b.z {
        for y in a.y..b.y {
            let row = UVec3::new(a.x, y, z);
            let (from, to) = (index(row, src_lo, src_size), index(row, lo, size));
            dst[to..to + run].copy_from_slice(&src[from..from + run]);
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::volume::{Grid, Source, ValueMap};

    #[test]
    fn levels_are_the_mip_chain_of_the_volume() {
        let dims = UVec3::new(9, 6, 4);
        let codes: Vec<u16> = (0..dims.x * dims.y * dims.z).map(|i| (i * 37 % 1000) as u16).collect();
        let v =
            Volume::new("v", Grid::new(dims, Vec3::ONE), Voxels::U16(codes), ValueMap::new(2.0, -5.0), Source::default()).expect("volume");
        let s = MemorySource::new(Arc::new(v), 2);
        // 9×6×4 → 5×3×2 → 3×2×1 → 2×1×1.
        assert_eq!(
            s.info().levels.iter().map(|l| l.grid.dims).collect::<Vec<_>>(),
            vec![dims, UVec3::new(5, 3, 2), UVec3::new(3, 2, 1), UVec3::new(2, 1, 1)]
        );
        assert_eq!(s.info().values, ValueMap::new(2.0, -5.0));
        // Level-1 voxel (1, 1, 0) is the rounded mean of level-0 voxels x 2..3, y 2..3, z 0..1.
        let l0 = |x: u32, y: u32, z: u32| (z * 54 + y * 9 + x) * 37 % 1000;
        let sum: u32 = [(2, 2, 0), (3, 2, 0), (2, 3, 0), (3, 3, 0), (2, 2, 1), (3, 2, 1), (2, 3, 1), (3, 3, 1)]
            .iter()
            .map(|&(x, y, z)| l0(x, y, z))
            .sum();
        let b = s.read_box(1, UVec3::new(1, 1, 0), UVec3::ONE).expect("box");
        assert_eq!(b.voxels, Voxels::U16(vec![((sum + 4) / 8) as u16]));
        // A box of level 0 is the volume's voxels.
        let b = s.read_box(0, UVec3::new(7, 5, 3), UVec3::new(2, 1, 1)).expect("box");
        assert_eq!(b.voxels, Voxels::U16(vec![l0(7, 5, 3) as u16, l0(8, 5, 3) as u16]));
        assert!(s.read_box(0, UVec3::new(8, 0, 0), UVec3::new(2, 1, 1)).is_err());
        assert!(s.read_box(4, UVec3::ZERO, UVec3::ONE).is_err());
    }
}
