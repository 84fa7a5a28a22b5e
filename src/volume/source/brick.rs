//! Bricks: the fixed-size boxes a brick cache holds.
//!
//! Brick `b` of a level owns voxels `b·B … (b + 1)·B − 1` (B the brick size) and is
//! stored with an apron of `A` voxels on every side, `(B + 2A)³` codes in all, so that
//! trilinear filtering anywhere in the owned box reads only the brick itself. Where the
//! apron (or a last, partial brick) reaches past the level, the edge voxel repeats, which
//! is what a whole-volume texture sampled with clamp-to-edge reads there: a brick atlas
//! and the volume in one texture give the same samples.

use glam::UVec3;

use super::{Block, SourceError, VoxelSource};
use crate::volume::Voxels;

/// Brick size and apron.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BrickLayout {
    /// Owned voxels per axis.
    pub size: u32,
    /// Extra voxels stored on each side.
    pub apron: u32,
}

impl BrickLayout {
    pub const fn new(size: u32, apron: u32) -> Self {
        Self { size, apron }
    }

    /// Voxels stored per axis: `B + 2A`.
    pub fn stored(&self) -> u32 {
        self.size + 2 * self.apron
    }

    /// Bricks per axis over a level of `dims`.
    pub fn bricks(&self, dims: UVec3) -> UVec3 {
        (dims + self.size - 1) / self.size
    }

    /// Reads brick `b` of `level` with its apron, edges repeated past the level.
    pub fn read(&self, source: &dyn VoxelSource, level: usize, b: UVec3) -> Result<Block, SourceError> {
        let info = source.info();
        let Some(l) = info.levels.get(level) else {
            return Err(SourceError::new(info.location(), format!("level {level} asked for, the pyramid has {}", info.levels.len())));
        };
        let dims = l.grid.dims;
        let want_lo = (b * self.size).as_ivec3() - self.apron as i32;
        let lo = want_lo.max(glam::IVec3::ZERO).as_uvec3();
        let hi = ((b + 1) * self.size + self.apron).min(dims);
        if lo.cmpge(hi).any() {
            return Err(SourceError::new(info.location(), format!("brick {b} lies outside level {level}")));
        }
        let inner = source.read_box(level, lo, hi - lo)?;
        let n = self.stored();
        let voxels = pad(
            &inner.voxels,
            hi - lo,
            |i, axis| (want_lo[axis] + i as i32).clamp(lo[axis] as i32, hi[axis] as i32 - 1) as u32 - lo[axis],
            n,
        );
        Ok(Block { voxels, faults: inner.faults })
    }
}

/// A `n³` box whose voxel `(x, y, z)` is `src`'s voxel `(at(x, 0), at(y, 1), at(z, 2))`.
fn pad(src: &Voxels, dims: UVec3, at: impl Fn(u32, usize) -> u32, n: u32) -> Voxels {
    let map = |axis: usize| (0..n).map(|i| at(i, axis) as usize).collect::<Vec<_>>();
    let (xs, ys, zs) = (map(0), map(1), map(2));
    let (nx, ny) = (dims.x as usize, dims.y as usize);
    fn gather<T: Copy>(v: &[T], xs: &[usize], ys: &[usize], zs: &[usize], nx: usize, ny: usize) -> Vec<T> {
        let mut out = Vec::with_capacity(xs.len() * ys.len() * zs.len());
        for &z in zs {
            for &y in ys {
                let row = &v[(z * ny + y) * nx..][..nx];
                out.extend(xs.iter().map(|&x| row[x]));
            }
        }
        out
    }
    match src {
        Voxels::U8(v) => Voxels::U8(gather(v, &xs, &ys, &zs, nx, ny)),
        Voxels::U16(v) => Voxels::U16(gather(v, &xs, &ys, &zs, nx, ny)),
    }
}

/// Smallest and largest code of a block.
pub fn code_range(voxels: &Voxels) -> (u16, u16) {
    fn range<T: Copy + Ord + Into<u16>>(v: &[T]) -> (u16, u16) {
        match (v.iter().min(), v.iter().max()) {
            (Some(&a), Some(&b)) => (a.into(), b.into()),
            _ => (0, 0),
        }
    }
    match voxels {
        Voxels::U8(v) => range(v),
        Voxels::U16(v) => range(v),
    }
}

/// Edge of the sub-blocks whose ranges a brick keeps for finer empty-space skipping.
pub const SUB_BLOCK: u32 = 8;

impl BrickLayout {
    /// Sub-blocks per axis of a brick's owned box (`B / 8`, at most 4: 64 in all).
    pub fn sub_blocks(&self) -> u32 {
        (self.size / SUB_BLOCK).clamp(1, 4)
    }

    /// The code range of each sub-block of a stored brick (x fastest), with the voxel
    /// around it that trilinear samples inside it touch (when the apron holds it).
    pub fn sub_ranges(&self, voxels: &Voxels) -> Vec<(u16, u16)> {
        let (n, m, a) = (self.stored() as usize, self.sub_blocks() as usize, self.apron as usize);
        let edge = self.size as usize / m;
        let code = |x: usize, y: usize, z: usize| voxels.code((z * n + y) * n + x);
        let span = |s: usize| {
            let lo = (a + s * edge).saturating_sub(1);
            lo..(a + (s + 1) * edge + 1).min(n)
        };
        let mut out = Vec::with_capacity(m * m * m);
        for sz in 0..m {
            for sy in 0..m {
                for sx in 0..m {
                    let (mut lo, mut hi) = (u16::MAX, 0u16);
                    for z in span(sz) {
                        for y in span(sy) {
                            for x in span(sx) {
                                let c = code(x, y, z);
                                lo = lo.min(c);
                                hi = hi.max(c);
                            }
                        }
                    }
                    out.push((lo, hi));
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::volume::source::memory::MemorySource;
    use crate::volume::{Grid, Source, ValueMap, Volume};

    fn ramp(dims: UVec3) -> Volume {
        let codes = (0..dims.x * dims.y * dims.z).map(|i| (i % 251) as u8).collect();
        Volume::new("ramp", Grid::new(dims, glam::Vec3::ONE), Voxels::U8(codes), ValueMap::IDENTITY, Source::default()).expect("volume")
    }

    #[test]
    fn bricks_carry_their_apron_and_repeat_the_edges() {
        let dims = UVec3::new(10, 7, 5);
        let v = Arc::new(ramp(dims));
        let source = MemorySource::new(v.clone(), 1);
        let layout = BrickLayout::new(4, 1);
        assert_eq!(layout.bricks(dims), UVec3::new(3, 2, 2));
        for b in [UVec3::ZERO, UVec3::new(2, 1, 1), UVec3::new(1, 0, 1)] {
            let block = layout.read(&source, 0, b).expect("brick");
            assert!(block.faults.is_empty());
            let n = layout.stored();
            for z in 0..n {
                for y in 0..n {
                    for x in 0..n {
                        // Stored voxel (x, y, z) is level voxel b·4 − 1 + (x, y, z), clamped.
                        let p = (b * 4).as_ivec3() - 1 + glam::UVec3::new(x, y, z).as_ivec3();
                        let q = p.clamp(glam::IVec3::ZERO, dims.as_ivec3() - 1).as_uvec3();
                        let got = block.voxels.code(((z * n + y) * n + x) as usize);
                        assert_eq!(got, v.code(q.x, q.y, q.z), "brick {b} voxel {x} {y} {z}");
                    }
                }
            }
        }
        assert!(layout.read(&source, 0, UVec3::new(3, 0, 0)).is_err());
        assert!(layout.read(&source, 5, UVec3::ZERO).is_err());
        assert_eq!(code_range(&Voxels::U16(vec![9, 3, 70])), (3, 70));
    }

    #[test]
    fn sub_ranges_cover_each_sub_block_and_its_neighbouring_voxels() {
        // 32³ owned + apron 1: a single hot voxel at stored (9, 1, 1) is in sub-block x 1
        // (stored 9..17) and, as the voxel around sub-block 0 (stored 1..9), in its range too.
        let layout = BrickLayout::new(32, 1);
        let n = layout.stored() as usize;
        let mut codes = vec![0u8; n * n * n];
        codes[(n + 1) * n + 9] = 200;
        let ranges = layout.sub_ranges(&Voxels::U8(codes));
        assert_eq!(ranges.len(), 64);
        assert_eq!(ranges[0], (0, 200));
        assert_eq!(ranges[1], (0, 200));
        assert_eq!(ranges[2], (0, 0));
        assert_eq!(ranges[4], (0, 0), "sub-block (0, 1, 0) starts at stored y 9");
    }
}
