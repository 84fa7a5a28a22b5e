//! The image plane of a view in lens coordinates: `y` from −1 (bottom) to 1 (top), `x`
//! scaled by the aspect ratio, the origin at the image centre.

use glam::Vec2;

use crate::region::{Camera, Ray};

/// An image of `width × height` pixels and its lens coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Screen {
    pub width: f32,
    pub height: f32,
}

impl Screen {
    pub fn new(width: u32, height: u32) -> Screen {
        Screen { width: width.max(1) as f32, height: height.max(1) as f32 }
    }

    pub fn aspect(&self) -> f32 {
        self.width / self.height
    }

    /// Lens coordinates of pixel position `(px, py)` (top-left origin).
    pub fn to_lens(&self, px: f32, py: f32) -> Vec2 {
        Vec2::new((2.0 * px / self.width - 1.0) * self.aspect(), 1.0 - 2.0 * py / self.height)
    }

    /// Pixel position of lens coordinates `s`.
    pub fn to_pixel(&self, s: Vec2) -> (f32, f32) {
        ((s.x / self.aspect() + 1.0) * 0.5 * self.width, (1.0 - s.y) * 0.5 * self.height)
    }

    /// The camera's own ray through lens coordinates `s`.
    pub fn camera_ray(&self, camera: &Camera, s: Vec2) -> Ray {
        let (px, py) = self.to_pixel(s);
        camera.ray(px, py, self.width as u32, self.height as u32)
    }
}
