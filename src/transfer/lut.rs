//! Baking a transfer function into a lookup table, and reading it back as a linearly
//! filtered 1D texture does.
//!
//! The table has `N` RGBA entries over the real-value domain `[lo, hi]` (the volume's
//! value range); entry `i` holds the function at the texel centre
//! `lo + (i + 0.5)/N · (hi − lo)`. A lookup at texture coordinate `u` interpolates
//! between the texels around `u·N − 0.5`, clamped at the ends, exactly like a GPU's
//! linear filtering with clamp-to-edge. The shader gets the texture coordinate of a
//! normalised volume sample `t` from one affine map `u = a·t + b` ([`Lut::texcoord_map`]).

use super::color::srgb3_to_linear;
use super::function::TransferFunction;
use super::visible::VisibleEntries;
use crate::volume::Volume;

/// Number of entries used for 8-bit volumes (one per code) and for 16-bit volumes.
pub const LUT_SIZE_8: usize = 256;
pub const LUT_SIZE_16: usize = 4096;

/// A baked RGBA table (linear colour, not premultiplied; alpha per reference length).
#[derive(Clone, Debug, PartialEq)]
pub struct Lut {
    pub rgba: Vec<[f32; 4]>,
    /// (λt, λs) of context-preserving rendering at the same texels.
    pub lambda: Vec<[f32; 2]>,
    /// Real values at the start of the first texel and the end of the last.
    pub lo: f64,
    pub hi: f64,
}

impl Lut {
    /// Bakes `tf` (already resolved to absolute values) over `[lo, hi]` with `n` entries.
    pub fn bake(tf: &TransferFunction, lo: f64, hi: f64, n: usize) -> Lut {
        let n = n.max(2);
        let hi = if hi > lo { hi } else { lo + 1.0 };
        let centre = |i: usize| lo + (i as f64 + 0.5) / n as f64 * (hi - lo);
        let rgba = (0..n)
            .map(|i| {
                let c = srgb3_to_linear(tf.color_at(centre(i)));
                [c[0], c[1], c[2], tf.opacity_at(centre(i))]
            })
            .collect();
        let lambda = (0..n).map(|i| tf.lambda_at(centre(i))).collect();
        Lut { rgba, lambda, lo, hi }
    }

    /// Bakes `tf` for a volume: relative points resolved to its range, one texel per code
    /// for 8-bit data, [`LUT_SIZE_16`] texels over the value range otherwise.
    pub fn for_volume(tf: &TransferFunction, volume: &Volume) -> Lut {
        let (lo, hi) = (volume.stats.min, volume.stats.max);
        let tf = tf.resolved(lo, hi);
        if volume.voxels.bits() == 8 {
            // Texel centres on the codes 0..255: domain spans code −0.5 … 255.5.
            let a = volume.values.to_real(-0.5);
            let b = volume.values.to_real(255.5);
            Lut::bake(&tf, a.min(b), a.max(b), LUT_SIZE_8)
        } else {
            // With no data (volume::encode::NO_DATA_GAP codes below the first true
            // value) the table starts at it, and its texels below the first true value
            // are transparent.
            let bottom = volume.values.no_data.map_or(lo, |code| volume.values.to_real(code as f64));
            let pad = (hi - bottom).abs().max(1e-9) * 0.5 / LUT_SIZE_16 as f64;
            let mut lut = Lut::bake(&tf, bottom - pad, hi + pad, LUT_SIZE_16);
            if volume.values.no_data.is_some() {
                let (a, w) = (lut.lo, (lut.hi - lut.lo) / LUT_SIZE_16 as f64);
                for (_, t) in lut.rgba.iter_mut().enumerate().filter(|(i, _)| a + (*i as f64 + 0.5) * w < lo) {
                    t[3] = 0.0;
                }
            }
            lut
        }
    }

    pub fn len(&self) -> usize {
        self.rgba.len()
    }

    pub fn is_empty(&self) -> bool {
        self.rgba.is_empty()
    }

    /// Texture coordinate of a real value.
    #[inline]
    pub fn texcoord(&self, real: f64) -> f32 {
        ((real - self.lo) / (self.hi - self.lo)) as f32
    }

    /// `(a, b)` with `u = a·t + b` mapping a normalised sample `t` of `volume` to the
    /// texture coordinate of this table.
    pub fn texcoord_map(&self, volume: &Volume) -> (f32, f32) {
        let code_max = volume.code_max() as f64;
        let span = self.hi - self.lo;
        let a = code_max * volume.values.slope / span;
        let b = (volume.values.intercept - self.lo) / span;
        (a as f32, b as f32)
    }

    /// Linearly filtered lookup at texture coordinate `u` (clamp to edge).
    #[inline]
    pub fn sample(&self, u: f32) -> [f32; 4] {
        filtered(&self.rgba, u)
    }

    /// (λt, λs) at texture coordinate `u`, filtered like [`Self::sample`].
    #[inline]
    pub fn sample_lambda(&self, u: f32) -> [f32; 2] {
        filtered(&self.lambda, u)
    }

    /// Largest opacity of any texel that a sample between the real values `lo..=hi` can
    /// touch (for empty-space skipping: zero means the range is invisible).
    pub fn max_opacity_between(&self, lo: f64, hi: f64) -> f32 {
        let (i0, i1) = self.texels_between(lo, hi);
        self.rgba[i0..=i1].iter().map(|c| c[3]).fold(0.0, f32::max)
    }

    /// The texels `i0..=i1` a sample between the real values `lo..=hi` can touch.
    pub fn texels_between(&self, lo: f64, hi: f64) -> (usize, usize) {
        let n = self.rgba.len();
        let texel = |v: f64| (self.texcoord(v) * n as f32 - 0.5).clamp(0.0, (n - 1) as f32);
        let (a, b) = (texel(lo.min(hi)), texel(lo.max(hi)));
        (a.floor() as usize, (b.ceil() as usize).min(n - 1))
    }

    /// Which texels have any opacity, for [`Self::max_opacity_between`]` > 0` in
    /// constant time (with [`Self::texels_between`]).
    pub fn visible_texels(&self) -> VisibleEntries {
        VisibleEntries::new(self.rgba.iter().map(|c| c[3] > 0.0))
    }
}

/// Linear filtering of a table at texture coordinate `u`, clamped to the edge texels.
#[inline]
fn filtered<const N: usize>(table: &[[f32; N]], u: f32) -> [f32; N] {
    let n = table.len();
    let x = (u * n as f32 - 0.5).clamp(0.0, (n - 1) as f32);
    let i = (x as usize).min(n - 2);
    let t = x - i as f32;
    let (a, b) = (table[i], table[i + 1]);
    std::array::from_fn(|k| a[k] + (b[k] - a[k]) * t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transfer::function::{ColorPoint, OpacityPoint, ValueSpace};

    fn ramp() -> TransferFunction {
        TransferFunction {
            name: "ramp".into(),
            space: ValueSpace::Absolute,
            units: None,
            color: vec![ColorPoint(0.0, [0.0; 3]), ColorPoint(100.0, [1.0; 3])],
            opacity: vec![OpacityPoint(0.0, 0.0), OpacityPoint(100.0, 1.0)],
            lambda_t: vec![],
            lambda_s: vec![],
        }
    }

    #[test]
    fn texel_centres_hold_the_function() {
        let lut = Lut::bake(&ramp(), 0.0, 100.0, 4);
        // Texel centres at 12.5, 37.5, 62.5, 87.5.
        assert_eq!(lut.rgba[1][3], 0.375);
        // A linear function is reproduced exactly between texel centres …
        assert!((lut.sample(lut.texcoord(50.0))[3] - 0.5).abs() < 1e-6);
        // … and clamps outside them.
        assert_eq!(lut.sample(0.0)[3], 0.125);
        assert_eq!(lut.sample(1.0)[3], 0.875);
    }

    #[test]
    fn no_data_is_transparent_and_true_values_keep_their_colour() {
        use crate::volume::encode::{ByteOrder, SampleType, encode_samples};
        use crate::volume::{Grid, Source, Volume};
        // Values 0 … 100 with NaN between them, under an opaque table.
        let values: Vec<f32> = (0..64).map(|i| if i % 5 == 0 { f32::NAN } else { i as f32 * 100.0 / 63.0 }).collect();
        let bytes = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let e = encode_samples(bytes, SampleType::F32, ByteOrder::Little).unwrap();
        let grid = Grid::new(glam::UVec3::new(4, 4, 4), glam::Vec3::ONE);
        let v = Volume::new("nan", grid, e.voxels, e.map, Source::default()).unwrap();
        assert_eq!((v.stats.no_data, v.stats.min as f32, v.stats.max), (13, 100.0 / 63.0, 100.0));
        let mut opaque = ramp();
        opaque.opacity = vec![OpacityPoint(0.0, 1.0), OpacityPoint(100.0, 1.0)];
        let lut = Lut::for_volume(&opaque, &v);
        let at = |code: f64| lut.sample(lut.texcoord(v.values.to_real(code)));
        assert_eq!(at(0.0)[3], 0.0, "no data");
        // The lowest true value: half a texel from the transparent ones; above it, opaque.
        assert!(at(v.stats.code_min as f64)[3] >= 0.5);
        assert!(at(v.stats.code_min as f64 + 16.0)[3] > 0.99);
        assert!((at(v.stats.code_max as f64)[0] - 1.0).abs() < 1e-3);
    }

    #[test]
    fn opacity_bound_over_a_range() {
        let mut tf = ramp();
        tf.opacity = vec![OpacityPoint(0.0, 0.0), OpacityPoint(60.0, 0.0), OpacityPoint(61.0, 0.8)];
        let lut = Lut::bake(&tf, 0.0, 100.0, 100);
        assert_eq!(lut.max_opacity_between(0.0, 50.0), 0.0);
        assert!(lut.max_opacity_between(50.0, 70.0) > 0.7);
        // Reversed bounds work too.
        assert!(lut.max_opacity_between(70.0, 50.0) > 0.7);
        // The constant-time answer agrees with the bound everywhere.
        let visible = lut.visible_texels();
        for a in (-10..110).step_by(3) {
            for b in (-10..110).step_by(7) {
                let (i0, i1) = lut.texels_between(a as f64, b as f64);
                assert_eq!(visible.any(i0, i1), lut.max_opacity_between(a as f64, b as f64) > 0.0, "{a}..{b}");
            }
        }
    }
}
