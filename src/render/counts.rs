//! Where a frame's time goes, per ray: with [`crate::dataset::VolumeView::debug_counts`]
//! the ray caster writes each pixel's count of samples (sample positions marched, in
//! every mode) and of page look-ups into bricked volumes' page tables instead of its
//! colour (`shaders/raycast.wgsl` `debug_counts`): samples in red (low byte) and green
//! (high byte), look-ups per sample ×32 in blue, each byte `n` written as the linear
//! value whose sRGB code is `n` on the sRGB target
//! (`render::headless::Offscreen::capture_counts`). [`decode`] sums them over an image:
//! at equal cost per sample, a frame's cost follows its sample count, so two views'
//! sample ratio bounds what an optimisation of the per-sample cost alone can reach.

/// Totals of one image of counts.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RayCounts {
    /// Samples over all pixels.
    pub samples: u64,
    /// Page look-ups over all pixels (from each pixel's rounded per-sample rate).
    pub lookups: f64,
    /// Pixels whose ray took samples.
    pub rays: u64,
    /// Most samples one ray took.
    pub most: u32,
}

impl RayCounts {
    /// Mean samples per ray that took any.
    pub fn per_ray(&self) -> f64 {
        self.samples as f64 / self.rays.max(1) as f64
    }

    /// Page look-ups per sample.
    pub fn lookups_per_sample(&self) -> f64 {
        self.lookups / self.samples.max(1) as f64
    }
}

/// The counts of pixel `p` (RGBA8 as read back): samples and look-ups per sample.
pub fn pixel(p: [u8; 4]) -> (u32, f64) {
    (p[0] as u32 | (p[1] as u32) << 8, p[2] as f64 / 32.0)
}

/// The totals of an image the ray caster wrote with `debug_counts`.
pub fn decode(image: &image::RgbaImage) -> RayCounts {
    decode_where(image, |_, _| true)
}

/// The totals over the pixels `(x, y)` of `image` that `keep` keeps.
pub fn decode_where(image: &image::RgbaImage, keep: impl Fn(u32, u32) -> bool) -> RayCounts {
    let mut c = RayCounts::default();
    for (x, y, p) in image.enumerate_pixels() {
        let (n, per) = pixel(p.0);
        if n > 0 && keep(x, y) {
            c.samples += n as u64;
            c.lookups += n as f64 * per;
            c.rays += 1;
            c.most = c.most.max(n);
        }
    }
    c
}

/// A heat map of an image of counts: each pixel's samples over `most` on a ramp from
/// black (none) through blue, red and yellow to white (`most` or more), so the
/// pictures of one group, scaled alike, show where their samples go.
pub fn heat_map(image: &image::RgbaImage, most: u32) -> image::RgbaImage {
    const RAMP: [[f32; 3]; 5] = [[0.0, 0.0, 0.0], [0.1, 0.2, 0.9], [0.9, 0.1, 0.2], [1.0, 0.85, 0.1], [1.0, 1.0, 1.0]];
    let mut out = image::RgbaImage::new(image.width(), image.height());
    for (x, y, p) in image.enumerate_pixels() {
        let (n, _) = pixel(p.0);
        let f = (n as f32 / most.max(1) as f32).clamp(0.0, 1.0) * (RAMP.len() - 1) as f32;
        let i = (f.floor() as usize).min(RAMP.len() - 2);
        let t = f - i as f32;
        let c = |a: usize| ((RAMP[i][a] + (RAMP[i + 1][a] - RAMP[i][a]) * t) * 255.0).round() as u8;
        out.put_pixel(x, y, image::Rgba([c(0), c(1), c(2), 255]));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_decode_from_the_bytes() {
        assert_eq!(pixel([0x34, 0x12, 64, 255]), (0x1234, 2.0));
        let mut img = image::RgbaImage::new(2, 1);
        img.put_pixel(0, 0, image::Rgba([20, 0, 32, 255]));
        img.put_pixel(1, 0, image::Rgba([0, 1, 16, 255]));
        let c = decode(&img);
        assert_eq!((c.samples, c.rays, c.most), (276, 2, 256));
        assert!((c.lookups - (20.0 + 128.0)).abs() < 1e-9);
        assert!((c.per_ray() - 138.0).abs() < 1e-9);
        assert_eq!(decode(&image::RgbaImage::new(3, 3)), RayCounts::default());
        assert_eq!(decode_where(&img, |x, _| x == 1).samples, 256);
    }

    #[test]
    fn heat_maps_ramp_from_black_to_white() {
        let mut img = image::RgbaImage::new(3, 1);
        img.put_pixel(1, 0, image::Rgba([100, 0, 0, 255]));
        img.put_pixel(2, 0, image::Rgba([144, 1, 0, 255]));
        let h = heat_map(&img, 400);
        assert_eq!(h.get_pixel(0, 0).0, [0, 0, 0, 255]);
        // 100 of 400: the ramp's second stop (blue).
        let blue = h.get_pixel(1, 0).0;
        for (got, want) in blue.iter().zip([25.5, 51.0, 229.5, 255.0]) {
            assert!((*got as f32 - want).abs() <= 0.5, "{blue:?}");
        }
        // 400 (0x190) or more: white.
        assert_eq!(h.get_pixel(2, 0).0, [255, 255, 255, 255]);
    }
}
