//! Rendered images: colour over the background, projected values and depths, and PNG
//! output.

use std::path::Path;

use glam::Vec4;

use super::trace::Traced;
use crate::transfer::color::linear_to_srgb;

/// A rendered image with its per-pixel by-products.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderedImage {
    pub width: u32,
    pub height: u32,
    /// Final colour in linear light (composited over the background), row-major from the
    /// top.
    pub rgba: Vec<Vec4>,
    /// Accumulated opacity of the volume alone.
    pub alpha: Vec<f32>,
    /// Projected value (MIP, MinIP, X-ray) of each pixel, NaN where there is none.
    pub value: Vec<f32>,
    /// Depth (ray parameter) of each pixel, infinity where nothing was hit.
    pub depth: Vec<f32>,
    /// Sample positions visited over the whole image.
    pub samples: u64,
    /// Samples the regions took over the whole image ([`Traced::classified`]).
    pub classified: u64,
}

impl RenderedImage {
    pub fn from_traced(width: u32, height: u32, pixels: &[Traced], background: Vec4) -> Self {
        RenderedImage {
            width,
            height,
            rgba: pixels.iter().map(|p| p.color + background * (1.0 - p.color.w)).collect(),
            alpha: pixels.iter().map(|p| p.color.w).collect(),
            value: pixels.iter().map(|p| p.value).collect(),
            depth: pixels.iter().map(|p| p.depth).collect(),
            samples: pixels.iter().map(|p| p.samples as u64).sum(),
            classified: pixels.iter().map(|p| p.classified as u64).sum(),
        }
    }

    /// Pixel (x, y) colour.
    pub fn at(&self, x: u32, y: u32) -> Vec4 {
        self.rgba[(y * self.width + x) as usize]
    }

    /// 8-bit sRGB-encoded RGBA bytes (alpha linear), rounded.
    pub fn to_rgba8(&self) -> Vec<u8> {
        let q = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
        self.rgba.iter().flat_map(|c| [q(linear_to_srgb(c.x)), q(linear_to_srgb(c.y)), q(linear_to_srgb(c.z)), q(c.w)]).collect()
    }

    /// The image as sRGB RGBA8.
    pub fn to_image(&self) -> Result<image::RgbaImage, String> {
        image::RgbaImage::from_raw(self.width, self.height, self.to_rgba8()).ok_or_else(|| "image buffer has the wrong size".into())
    }

    /// Writes a PNG.
    pub fn save_png(&self, path: &Path) -> Result<(), String> {
        self.to_image()?.save(path).map_err(|e| format!("{}: {e}", path.display()))
    }
}
