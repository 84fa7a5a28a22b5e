//! Sampling a volume the way a GPU samples a 3D texture.
//!
//! Positions are continuous voxel indices (voxel centres at integers). Trilinear
//! interpolation clamps to the edge voxels, which is what a linearly filtered texture
//! with clamp-to-edge addressing returns at texture coordinate `(p + 0.5) / n`. Values
//! are normalised codes `code / code_max` in `[0, 1]`, as `R8Unorm`/`R16Unorm` give.
//!
//! Gradients are central differences of trilinear samples one voxel apart,
//! `g_i = (f(p + e_i) − f(p − e_i)) / 2`, in normalised units per voxel. The world-space
//! gradient is `(D·S)^{-T} g` for direction matrix D and spacing S.

use glam::{UVec3, Vec3};
use rayon::prelude::*;

use super::Voxels;

/// A voxel code type.
pub trait Code: Copy + Send + Sync + 'static {
    fn to_f32(self) -> f32;
    fn to_u16(self) -> u16;
}

impl Code for u8 {
    #[inline]
    fn to_f32(self) -> f32 {
        self as f32
    }
    #[inline]
    fn to_u16(self) -> u16 {
        self as u16
    }
}

impl Code for u16 {
    #[inline]
    fn to_f32(self) -> f32 {
        self as f32
    }
    #[inline]
    fn to_u16(self) -> u16 {
        self
    }
}

/// Samples one code array.
#[derive(Clone, Copy)]
pub struct Sampler<'a, T: Code> {
    data: &'a [T],
    nx: usize,
    nxy: usize,
    last: Vec3,
    dims: UVec3,
    inv_code_max: f32,
}

impl<'a, T: Code> Sampler<'a, T> {
    pub fn new(data: &'a [T], dims: UVec3, code_max: u32) -> Self {
        Self {
            data,
            nx: dims.x as usize,
            nxy: dims.x as usize * dims.y as usize,
            last: dims.as_vec3() - 1.0,
            dims,
            inv_code_max: 1.0 / code_max as f32,
        }
    }

    #[inline]
    fn at(&self, x: usize, y: usize, z: usize) -> f32 {
        self.data[z * self.nxy + y * self.nx + x].to_f32()
    }

    /// Trilinear sample at a continuous voxel index, normalised to `[0, 1]`.
    #[inline]
    pub fn trilinear(&self, p: Vec3) -> f32 {
        let p = p.clamp(Vec3::ZERO, self.last);
        let f = p.floor();
        let t = p - f;
        let (x0, y0, z0) = (f.x as usize, f.y as usize, f.z as usize);
        let x1 = (x0 + 1).min(self.dims.x as usize - 1);
        let y1 = (y0 + 1).min(self.dims.y as usize - 1);
        let z1 = (z0 + 1).min(self.dims.z as usize - 1);
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let c00 = lerp(self.at(x0, y0, z0), self.at(x1, y0, z0), t.x);
        let c10 = lerp(self.at(x0, y1, z0), self.at(x1, y1, z0), t.x);
        let c01 = lerp(self.at(x0, y0, z1), self.at(x1, y0, z1), t.x);
        let c11 = lerp(self.at(x0, y1, z1), self.at(x1, y1, z1), t.x);
        let c0 = lerp(c00, c10, t.y);
        let c1 = lerp(c01, c11, t.y);
        lerp(c0, c1, t.z) * self.inv_code_max
    }

    /// Code of the voxel nearest to a continuous index (label volumes).
    #[inline]
    pub fn nearest(&self, p: Vec3) -> u16 {
        let q = (p + 0.5).floor().clamp(Vec3::ZERO, self.last);
        self.data[q.z as usize * self.nxy + q.y as usize * self.nx + q.x as usize].to_u16()
    }

    /// Central-difference gradient at a continuous index (normalised units per voxel).
    #[inline]
    pub fn gradient(&self, p: Vec3) -> Vec3 {
        let d = |e: Vec3| self.trilinear(p + e) - self.trilinear(p - e);
        Vec3::new(d(Vec3::X), d(Vec3::Y), d(Vec3::Z)) * 0.5
    }
}

/// A sampler over either storage type.
#[derive(Clone, Copy)]
pub enum VolumeSampler<'a> {
    U8(Sampler<'a, u8>),
    U16(Sampler<'a, u16>),
}

impl<'a> VolumeSampler<'a> {
    pub fn new(voxels: &'a Voxels, dims: UVec3) -> Self {
        match voxels {
            Voxels::U8(v) => VolumeSampler::U8(Sampler::new(v, dims, 255)),
            Voxels::U16(v) => VolumeSampler::U16(Sampler::new(v, dims, 65535)),
        }
    }

    #[inline]
    pub fn trilinear(&self, p: Vec3) -> f32 {
        match self {
            VolumeSampler::U8(s) => s.trilinear(p),
            VolumeSampler::U16(s) => s.trilinear(p),
        }
    }

    #[inline]
    pub fn nearest(&self, p: Vec3) -> u16 {
        match self {
            VolumeSampler::U8(s) => s.nearest(p),
            VolumeSampler::U16(s) => s.nearest(p),
        }
    }

    #[inline]
    pub fn gradient(&self, p: Vec3) -> Vec3 {
        match self {
            VolumeSampler::U8(s) => s.gradient(p),
            VolumeSampler::U16(s) => s.gradient(p),
        }
    }
}

/// Largest gradient magnitude over all voxel centres of `voxels` on a `dims` grid
/// (normalised units per voxel).
pub fn max_gradient_magnitude(voxels: &Voxels, dims: UVec3) -> f32 {
    max_gradient_magnitude_in(voxels, dims, UVec3::ZERO, dims)
}

/// Largest gradient magnitude over the voxel centres `lo ≤ p < hi` of `voxels` on a
/// `dims` grid (central differences, edges clamped): a brick's owned voxels inside its
/// apron give the same gradients as the whole level would.
pub fn max_gradient_magnitude_in(voxels: &Voxels, dims: UVec3, lo: UVec3, hi: UVec3) -> f32 {
    let sampler = VolumeSampler::new(voxels, dims);
    let hi = hi.min(dims);
    (lo.z..hi.z)
        .into_par_iter()
        .map(|z| {
            let mut best = 0.0f32;
            for y in lo.y..hi.y {
                for x in lo.x..hi.x {
                    let g = sampler.gradient(UVec3::new(x, y, z).as_vec3());
                    best = best.max(g.length());
                }
            }
            best
        })
        .reduce(|| 0.0, f32::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trilinear_matches_hand_values() {
        // 2×2×2 cube with codes 0..7 (value = x + 2y + 4z).
        let data: Vec<u8> = (0..8).collect();
        let s = Sampler::new(&data, UVec3::splat(2), 1);
        assert_eq!(s.trilinear(Vec3::ZERO), 0.0);
        assert_eq!(s.trilinear(Vec3::ONE), 7.0);
        assert!((s.trilinear(Vec3::splat(0.5)) - 3.5).abs() < 1e-6);
        assert!((s.trilinear(Vec3::new(0.25, 0.5, 0.0)) - 1.25).abs() < 1e-6);
        // Clamped outside.
        assert_eq!(s.trilinear(Vec3::splat(-3.0)), 0.0);
        assert_eq!(s.nearest(Vec3::new(0.6, 0.4, 0.9)), 5);
        // A linear field has the exact gradient (1, 2, 4) inside.
        let big: Vec<u16> = (0..27u16).map(|i| (i % 3) + 2 * (i / 3 % 3) + 4 * (i / 9)).collect();
        let s = Sampler::new(&big, UVec3::splat(3), 1);
        assert!((s.gradient(Vec3::ONE) - Vec3::new(1.0, 2.0, 4.0)).length() < 1e-5);
    }
}
