//! Brick min-max grid for empty-space skipping and explosion points.
//!
//! The volume is cut into bricks of `size³` voxels; each brick stores the smallest and
//! largest code of the voxels a trilinear sample inside it can touch. Brick `b` covers
//! the sample positions `[b·size − 0.5, (b+1)·size − 0.5)` (in voxel index units), and a
//! trilinear sample there reads voxels `b·size − 1 … (b+1)·size`, so each brick's range
//! includes a one-voxel apron on every side. A ray segment inside a brick whose code
//! range the transfer function maps to zero opacity can then be skipped without changing
//! the image.

use glam::{UVec3, Vec3};
use rayon::prelude::*;

use super::voxels::Voxels;

/// Default brick edge length in voxels.
pub const DEFAULT_BRICK_SIZE: u32 = 8;

/// Per-brick code ranges.
#[derive(Clone, Debug, PartialEq)]
pub struct BrickGrid {
    /// Brick edge length in voxels.
    pub size: u32,
    /// Number of bricks along each axis.
    pub dims: UVec3,
    /// Smallest code per brick, x fastest.
    pub min: Vec<u16>,
    /// Largest code per brick.
    pub max: Vec<u16>,
}

impl BrickGrid {
    /// Builds the grid for voxels of dimensions `dims`.
    pub fn build(voxels: &Voxels, dims: UVec3, size: u32) -> BrickGrid {
        Self::build_with_apron(voxels, dims, size, 1)
    }

    /// [`Self::build`] with ranges over `apron` voxels beyond each brick on every side
    /// (one holds its trilinear samples; two the samples of mip level 1 and of the
    /// blends between levels 0 and 1, [`LEVEL_ONE_APRON`]).
    pub fn build_with_apron(voxels: &Voxels, dims: UVec3, size: u32, apron: u32) -> BrickGrid {
        let size = size.max(1);
        let bdims = (dims + size - 1) / size;
        let count = bdims.x as usize * bdims.y as usize * bdims.z as usize;
        let ranges: Vec<(u16, u16)> = (0..count)
            .into_par_iter()
            .map(|b| {
                let bx = (b % bdims.x as usize) as u32;
                let by = (b / bdims.x as usize % bdims.y as usize) as u32;
                let bz = (b / (bdims.x as usize * bdims.y as usize)) as u32;
                let lo = (UVec3::new(bx, by, bz) * size).saturating_sub(UVec3::splat(apron));
                let hi = ((UVec3::new(bx, by, bz) + 1) * size + apron - 1).min(dims - 1);
                match voxels {
                    Voxels::U8(v) => range_of(v, dims, lo, hi),
                    Voxels::U16(v) => range_of(v, dims, lo, hi),
                }
            })
            .collect();
        let (min, max) = ranges.into_iter().unzip();
        BrickGrid { size, dims: bdims, min, max }
    }

    pub fn len(&self) -> usize {
        self.min.len()
    }

    pub fn is_empty(&self) -> bool {
        self.min.is_empty()
    }

    /// Linear index of brick (x, y, z).
    #[inline]
    pub fn index(&self, b: UVec3) -> usize {
        (b.z as usize * self.dims.y as usize + b.y as usize) * self.dims.x as usize + b.x as usize
    }

    /// The brick holding a continuous voxel position (clamped to the grid).
    #[inline]
    pub fn brick_at(&self, voxel: Vec3) -> UVec3 {
        let b = ((voxel + 0.5) / self.size as f32).floor().max(Vec3::ZERO).as_uvec3();
        b.min(self.dims - 1)
    }

    /// The continuous voxel-index box of brick `b`: `[lo, hi)`.
    pub fn brick_bounds(&self, b: UVec3) -> (Vec3, Vec3) {
        let s = self.size as f32;
        (b.as_vec3() * s - 0.5, (b.as_vec3() + 1.0) * s - 0.5)
    }

    /// The continuous voxel-index box around every brick whose code range holds `code`
    /// (the union of their [`Self::brick_bounds`]): every sample position whose nearest
    /// voxel has that code lies inside it. `None` when no brick's range holds it.
    pub fn code_box(&self, code: u32) -> Option<(Vec3, Vec3)> {
        let (mut lo, mut hi) = (UVec3::MAX, UVec3::ZERO);
        for (i, (&mn, &mx)) in self.min.iter().zip(&self.max).enumerate() {
            if u32::from(mn) <= code && code <= u32::from(mx) {
                let i = i as u32;
                let b = UVec3::new(i % self.dims.x, i / self.dims.x % self.dims.y, i / (self.dims.x * self.dims.y));
                lo = lo.min(b);
                hi = hi.max(b);
            }
        }
        (lo.x <= hi.x).then(|| (self.brick_bounds(lo).0, self.brick_bounds(hi).1))
    }

    /// Code range of brick `b`.
    #[inline]
    pub fn range(&self, b: UVec3) -> (u16, u16) {
        let i = self.index(b);
        (self.min[i], self.max[i])
    }

    /// Which bricks are worth visiting: `visible(min, max)` says whether any code in the
    /// range has opacity under the current transfer function.
    pub fn occupancy(&self, visible: impl Fn(u16, u16) -> bool) -> Vec<bool> {
        self.min.iter().zip(&self.max).map(|(&lo, &hi)| visible(lo, hi)).collect()
    }

    /// The code range of brick `b` and its (up to 26) neighbours: it holds every
    /// trilinear sample of mip levels 1 to [`NEIGHBOURHOOD_LEVELS`] at a position inside
    /// `b` (`volume::pyramid`: a level-k voxel averages 2^k voxels per axis, its taps at
    /// a position in `b` reach at most one brick of 8 voxels beyond it), `None` for
    /// bricks smaller than that.
    pub fn neighbourhood_range(&self, b: UVec3) -> Option<(u16, u16)> {
        if self.size < 1 << NEIGHBOURHOOD_LEVELS {
            return None;
        }
        let lo = b.saturating_sub(UVec3::ONE);
        let hi = (b + 1).min(self.dims - 1);
        let (mut mn, mut mx) = (u16::MAX, 0u16);
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for x in lo.x..=hi.x {
                    let (a, c) = self.range(UVec3::new(x, y, z));
                    mn = mn.min(a);
                    mx = mx.max(c);
                }
            }
        }
        Some((mn, mx))
    }

    /// [`Self::occupancy`] of samples from mip levels 1 to [`NEIGHBOURHOOD_LEVELS`]
    /// (lenses' anti-aliasing): a brick is worth visiting where its
    /// [`Self::neighbourhood_range`] can be visible; `None` for bricks too small.
    pub fn neighbourhood_occupancy(&self, visible: impl Fn(u16, u16) -> bool) -> Option<Vec<bool>> {
        (0..self.len())
            .map(|i| {
                let (x, y) = (i as u32 % self.dims.x, i as u32 / self.dims.x % self.dims.y);
                let z = i as u32 / (self.dims.x * self.dims.y);
                self.neighbourhood_range(UVec3::new(x, y, z)).map(|(lo, hi)| visible(lo, hi))
            })
            .collect()
    }
}

/// Mip levels whose samples [`BrickGrid::neighbourhood_range`] bounds (those the
/// lenses' anti-aliasing reads, `volume::pyramid::MIP_LEVELS`).
pub const NEIGHBOURHOOD_LEVELS: u32 = 3;

/// The apron whose ranges hold the samples of mip level 1 at positions inside a brick
/// (its trilinear taps at a position in brick b read level-1 voxels 4b − 1 … 4b + 4 of
/// bricks of 8, level-0 voxels 8b − 2 … 8b + 9), and of the blends of levels 0 and 1.
pub const LEVEL_ONE_APRON: u32 = 2;

impl BrickGrid {
    /// Continuous voxel-index box `(lo, hi)` enclosing the bricks where `keep` is true.
    pub fn bounds_where(&self, keep: &[bool]) -> Option<(Vec3, Vec3)> {
        let mut lo = UVec3::MAX;
        let mut hi = UVec3::ZERO;
        for z in 0..self.dims.z {
            for y in 0..self.dims.y {
                for x in 0..self.dims.x {
                    let b = UVec3::new(x, y, z);
                    if keep.get(self.index(b)).copied().unwrap_or(false) {
                        lo = lo.min(b);
                        hi = hi.max(b);
                    }
                }
            }
        }
        (lo.x <= hi.x).then(|| (self.brick_bounds(lo).0, self.brick_bounds(hi).1))
    }
}

fn range_of<T: Copy + Into<u16> + Ord>(v: &[T], dims: UVec3, lo: UVec3, hi: UVec3) -> (u16, u16) {
    let (nx, ny) = (dims.x as usize, dims.y as usize);
    let (mut mn, mut mx) = (u16::MAX, 0u16);
    for z in lo.z..=hi.z {
        for y in lo.y..=hi.y {
            let row = (z as usize * ny + y as usize) * nx;
            let slice = &v[row + lo.x as usize..=row + hi.x as usize];
            // min/max over a contiguous row vectorises well.
            let (a, b) = slice.iter().fold((slice[0], slice[0]), |(a, b), &x| (a.min(x), b.max(x)));
            mn = mn.min(a.into());
            mx = mx.max(b.into());
        }
    }
    (mn, mx)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_code_box_holds_every_voxel_of_the_code() {
        // 24 × 16 × 8 voxels in bricks of 4: code 7 at voxels (5, 9, 2) and (13, 10, 6).
        let dims = UVec3::new(24, 16, 8);
        let mut v = vec![1u8; 24 * 16 * 8];
        let at = |x: usize, y: usize, z: usize| (z * 16 + y) * 24 + x;
        v[at(5, 9, 2)] = 7;
        v[at(13, 10, 6)] = 7;
        let g = BrickGrid::build(&Voxels::U8(v), dims, 4);
        // Bricks (1, 2, 0) … (3, 2, 1): x from brick 1 (voxels 4…7) to 3 (12…15), y
        // brick 2 (8…11), z bricks 0 … 1 (the one-voxel aprons reach no other brick).
        let (lo, hi) = g.code_box(7).expect("code 7 is there");
        assert_eq!(lo, Vec3::new(3.5, 7.5, -0.5));
        assert_eq!(hi, Vec3::new(15.5, 11.5, 7.5));
        for q in [Vec3::new(5.0, 9.0, 2.0), Vec3::new(13.4, 10.0, 6.4)] {
            assert!(q.cmpge(lo).all() && q.cmplt(hi).all(), "{q}");
        }
        assert_eq!(g.code_box(1), Some((Vec3::splat(-0.5), dims.as_vec3() - 0.5)));
        assert_eq!(g.code_box(8), None);
        assert_eq!(g.code_box(70_000), None);
    }

    #[test]
    fn ranges_include_the_trilinear_apron() {
        // 16 voxels along x, a single bright voxel at x = 8 (first voxel of brick 1).
        let dims = UVec3::new(16, 2, 2);
        let mut v = vec![0u8; 64];
        v[8] = 200;
        let g = BrickGrid::build(&Voxels::U8(v), dims, 8);
        assert_eq!(g.dims, UVec3::new(2, 1, 1));
        // Brick 0 samples up to x = 7.5, which interpolates voxel 8: it must see 200.
        assert_eq!(g.range(UVec3::new(0, 0, 0)), (0, 200));
        assert_eq!(g.range(UVec3::new(1, 0, 0)), (0, 200));
    }

    #[test]
    fn mip_samples_lie_in_their_bricks_neighbourhood_range() {
        // Every trilinear sample of levels 1–3 (and the blends between them) at a
        // position inside a brick lies in that brick's neighbourhood range: checked on
        // the pyramid's own samples at random positions of volumes whose sides are no
        // multiple of the brick.
        use crate::volume::pyramid::{self, level_index};
        use crate::volume::sample::VolumeSampler;
        assert_eq!(pyramid::MIP_LEVELS as u32, NEIGHBOURHOOD_LEVELS);
        let dims = UVec3::new(29, 21, 19);
        let mut seed = 12345u64;
        let mut next = move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 33) as u32
        };
        let at = |i: u32| (i % dims.x, i / dims.x % dims.y, i / (dims.x * dims.y));
        // Random constant cells of 3³ voxels; and a bright slab at x ≥ 17, which brick
        // 1's own range (voxels 7…16) does not see but its level-3 samples do.
        let cells: Vec<u16> = (0..10 * 7 * 7).map(|_| (next() % 60000) as u16).collect();
        let cell = |i: u32| {
            let (x, y, z) = at(i);
            cells[(((z / 3) * 7 + y / 3) * 10 + x / 3) as usize]
        };
        let slab = |i: u32| if at(i).0 >= 17 { 60000 } else { 0 };
        let mut outside_own = 0;
        for field in [&cell as &dyn Fn(u32) -> u16, &slab] {
            let voxels = Voxels::U16((0..dims.x * dims.y * dims.z).map(field).collect());
            let g = BrickGrid::build(&voxels, dims, 8);
            let near = BrickGrid::build_with_apron(&voxels, dims, 8, LEVEL_ONE_APRON);
            let levels = pyramid::build(&voxels, dims);
            let level_zero = VolumeSampler::new(&voxels, dims);
            for _ in 0..20000 {
                let q = Vec3::new(next() as f32, next() as f32, next() as f32) / (1u64 << 31) as f32;
                let q = q * dims.as_vec3() - 0.5;
                let b = g.brick_at(q);
                let Some((lo, hi)) = g.neighbourhood_range(b) else { panic!("bricks of 8 have a neighbourhood range") };
                // Level 1 and every blend of levels 0 and 1 within the apron-2 range.
                let one = VolumeSampler::new(&levels[0].voxels, levels[0].dims).trilinear(level_index(q, 1)) * 65535.0;
                let zero = level_zero.trilinear(q) * 65535.0;
                let (a2, c2) = near.range(b);
                for f in [0.0, 0.3, 1.0] {
                    let v = zero + (one - zero) * f;
                    assert!(v >= a2 as f32 - 0.01 && v <= c2 as f32 + 0.01, "level {f} at {q}: {v} outside {a2}…{c2}");
                }
                for (k, level) in levels.iter().enumerate() {
                    let v = VolumeSampler::new(&level.voxels, level.dims).trilinear(level_index(q, k as u32 + 1)) * 65535.0;
                    assert!(v >= lo as f32 - 0.01 && v <= hi as f32 + 0.01, "level {} at {q}: {v} outside {lo}…{hi}", k + 1);
                    let (a, c) = g.range(b);
                    outside_own += usize::from(v < a as f32 - 0.01 || v > c as f32 + 0.01);
                }
            }
            assert_eq!(BrickGrid::build(&voxels, dims, 4).neighbourhood_range(UVec3::ZERO), None);
            let occupied = g.neighbourhood_occupancy(|lo, hi| lo < 100 && hi > 59000);
            assert_eq!(occupied.map(|o| o.len()), Some(g.len()));
        }
        // (The brick's own range would not do: coarser samples reach its neighbours.)
        assert!(outside_own > 0);
    }

    #[test]
    fn ranges_match_brute_force() {
        let dims = UVec3::new(13, 9, 11);
        let v: Vec<u16> = (0..dims.x * dims.y * dims.z).map(|i| ((i * 7919) % 1000) as u16).collect();
        let g = BrickGrid::build(&Voxels::U16(v.clone()), dims, 4);
        for bz in 0..g.dims.z {
            for by in 0..g.dims.y {
                for bx in 0..g.dims.x {
                    let b = UVec3::new(bx, by, bz);
                    let (mut mn, mut mx) = (u16::MAX, 0);
                    for z in 0..dims.z {
                        for y in 0..dims.y {
                            for x in 0..dims.x {
                                let p = UVec3::new(x, y, z).as_vec3();
                                let (lo, hi) = g.brick_bounds(b);
                                // Voxels within one of the brick's sample box.
                                if (p.cmpge(lo - 1.0) & p.cmple(hi + 1.0)).all() {
                                    let c = v[((z * dims.y + y) * dims.x + x) as usize];
                                    mn = mn.min(c);
                                    mx = mx.max(c);
                                }
                            }
                        }
                    }
                    assert_eq!(g.range(b), (mn, mx), "brick {b}");
                }
            }
        }
        assert_eq!(g.brick_at(Vec3::new(-0.5, 3.4, 12.0)), UVec3::new(0, 0, 2));
        assert_eq!(g.occupancy(|_, hi| hi > 990).len(), g.len());
        let mut keep = vec![false; g.len()];
        keep[g.index(UVec3::new(1, 2, 0))] = true;
        keep[g.index(UVec3::new(2, 0, 1))] = true;
        assert_eq!(g.bounds_where(&keep), Some((Vec3::new(3.5, -0.5, -0.5), Vec3::new(11.5, 11.5, 7.5))));
        assert_eq!(g.bounds_where(&vec![false; g.len()]), None);
    }
}
