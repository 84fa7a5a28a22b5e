//! The mip chain of a volume, for the lenses' anti-aliasing (Wang et al. 2005, eq. 4:
//! where a lens compresses the image, samples come from a coarser level).
//!
//! Each level halves the one before: voxel `j` of level `k` is the rounded mean of the
//! 2×2×2 voxels `2j, 2j + 1` of level `k − 1` (an odd size rounds up, the last voxel
//! standing in for the missing one), so it covers level-0 voxels `2ᵏj … 2ᵏ(j + 1) − 1`
//! and the continuous level-0 index `q` lies at `q_k = (q + ½)/2ᵏ − ½` in level `k`.
//! Codes are averaged as stored, so the GPU atlas holds exactly these levels.

use glam::{UVec3, Vec3};

use super::Voxels;

/// Levels kept above level 0 (down to one eighth of the resolution).
pub const MIP_LEVELS: usize = 3;

/// One level of the chain.
#[derive(Clone, Debug, PartialEq)]
pub struct Level {
    pub dims: UVec3,
    pub voxels: Voxels,
}

/// Size of the level above one of `dims`.
pub fn half_dims(dims: UVec3) -> UVec3 {
    (dims + 1) / 2
}

/// The mean of a block's codes, leaving out `no_data` (NaN voxels: `ValueMap::no_data`);
/// a block of no data alone is no data. (Every true code lies above the no-data gap, so
/// the mean of true codes does too.)
pub fn block_mean(codes: &[u32], no_data: Option<u16>) -> u32 {
    let skip = no_data.map(u32::from);
    let (sum, n) = codes.iter().filter(|&&c| Some(c) != skip).fold((0u32, 0u32), |(s, n), &c| (s + c, n + 1));
    (sum + n / 2).checked_div(n).unwrap_or(skip.unwrap_or(0))
}

/// The level above `voxels` (`dims`).
pub fn halve(voxels: &Voxels, dims: UVec3) -> Level {
    halve_skipping(voxels, dims, None)
}

/// [`halve`] with `no_data` left out of each block's mean ([`block_mean`]).
pub fn halve_skipping(voxels: &Voxels, dims: UVec3, no_data: Option<u16>) -> Level {
    let out = half_dims(dims);
    let (nx, ny, nz) = (dims.x as usize, dims.y as usize, dims.z as usize);
    let mut codes = Vec::with_capacity((out.x * out.y * out.z) as usize);
    for z in 0..out.z as usize {
        let (z0, z1) = (2 * z, (2 * z + 1).min(nz - 1));
        for y in 0..out.y as usize {
            let (y0, y1) = (2 * y, (2 * y + 1).min(ny - 1));
            for x in 0..out.x as usize {
                let (x0, x1) = (2 * x, (2 * x + 1).min(nx - 1));
                let mut block = [0u32; 8];
                let mut k = 0;
                for zz in [z0, z1] {
                    for yy in [y0, y1] {
                        let row = (zz * ny + yy) * nx;
                        block[k] = voxels.code(row + x0) as u32;
                        block[k + 1] = voxels.code(row + x1) as u32;
                        k += 2;
                    }
                }
                codes.push(block_mean(&block, no_data) as u16);
            }
        }
    }
    let voxels = match voxels {
        Voxels::U8(_) => Voxels::U8(codes.into_iter().map(|c| c as u8).collect()),
        Voxels::U16(_) => Voxels::U16(codes),
    };
    Level { dims: out, voxels }
}

/// Levels 1 to [`MIP_LEVELS`] of a volume (fewer when it shrinks to one voxel).
pub fn build(voxels: &Voxels, dims: UVec3) -> Vec<Level> {
    build_skipping(voxels, dims, None)
}

/// [`build`] with `no_data` left out of every mean.
pub fn build_skipping(voxels: &Voxels, dims: UVec3, no_data: Option<u16>) -> Vec<Level> {
    let mut levels: Vec<Level> = Vec::with_capacity(MIP_LEVELS);
    for _ in 0..MIP_LEVELS {
        let (v, d) = levels.last().map_or((voxels, dims), |l| (&l.voxels, l.dims));
        if d == UVec3::ONE {
            break;
        }
        levels.push(halve_skipping(v, d, no_data));
    }
    levels
}

/// Continuous index in level `k` of continuous level-0 index `q`.
#[inline]
pub fn level_index(q: Vec3, k: u32) -> Vec3 {
    (q + 0.5) / (1u32 << k) as f32 - 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_data_is_left_out_of_block_means() {
        // NaN voxels (code 0) beside true codes 40 000 and 40 002: the mean of the true
        // ones, not a value between them and the no-data code.
        assert_eq!(block_mean(&[0, 40000, 0, 40002], Some(0)), 40001);
        assert_eq!(block_mean(&[0, 0], Some(0)), 0);
        assert_eq!(block_mean(&[0, 40000, 0, 40002], None), 20001);
        let v = Voxels::U16(vec![0, 40000, 0, 40002, 0, 0, 0, 0]);
        assert_eq!(halve_skipping(&v, UVec3::splat(2), Some(0)).voxels, Voxels::U16(vec![40001]));
    }

    #[test]
    fn levels_average_blocks_and_round_odd_sizes_up() {
        // 3×2×1: blocks {0,1} and {2} along x.
        let v = Voxels::U8(vec![10, 20, 40, 30, 50, 80]);
        let l = halve(&v, UVec3::new(3, 2, 1));
        assert_eq!(l.dims, UVec3::new(2, 1, 1));
        // (10+20+30+50)·2/8 = 27.5 → 28; the odd column repeats: (40+40+80+80)·2/8 = 60.
        assert_eq!(l.voxels, Voxels::U8(vec![28, 60]));
        let chain = build(&Voxels::U16(vec![7; 64]), UVec3::splat(4));
        assert_eq!(chain.iter().map(|l| l.dims).collect::<Vec<_>>(), vec![UVec3::splat(2), UVec3::ONE]);
        assert_eq!(chain[1].voxels, Voxels::U16(vec![7]));
    }

    #[test]
    fn level_indices_put_block_centres_on_voxel_centres() {
        // Level-1 voxel 0 covers level-0 voxels 0 and 1: its centre is at q = 0.5.
        assert_eq!(level_index(Vec3::splat(0.5), 1), Vec3::ZERO);
        assert_eq!(level_index(Vec3::splat(4.5), 1), Vec3::splat(2.0));
        assert_eq!(level_index(Vec3::splat(1.5), 2), Vec3::ZERO);
    }
}
