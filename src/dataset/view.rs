//! The cameras that show the volumes: [`VolumeView`] marks one and holds its rendering
//! switches; the renderer extracts it per view, the lenses are resolved per view.

use bevy::prelude::*;

use crate::region::Light;

/// The lowest [`VolumeView::resolution`]: an eighth of the pixels per axis.
pub const MIN_RESOLUTION: f32 = 0.125;

/// Marks a camera that shows the volumes, with its rendering switches.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct VolumeView {
    /// Jitter ray starts per pixel (against wood-grain artefacts).
    pub jitter: bool,
    /// Skip bricks the transfer functions make invisible.
    pub skip_empty: bool,
    /// Stop rays once they are opaque.
    pub early_termination: bool,
    /// Show ray directions instead of the volumes (tests of ray generation).
    pub debug_rays: bool,
    /// Show each ray's sample and page look-up counts instead of the volumes
    /// (`render::counts`: where the time of a frame goes).
    pub debug_counts: bool,
    /// Under lenses, sample compressed areas from the mip chain (`lens::antialias`).
    pub lens_antialias: bool,
    /// Under lenses, bricked regions step along the ray at the camera's rate (the
    /// context's) while sampling the finer bricks the lens asked for: a magnifier then
    /// costs about what the view without it costs, native laterally, but a structure
    /// thinner than the context's step along the ray may be missed (default off).
    pub lens_context_steps: bool,
    /// Feature lenses find their silhouettes in compute passes (else on the CPU).
    pub gpu_silhouettes: bool,
    /// Seed of the jitter pattern.
    pub frame: u32,
    /// Fraction of the view's pixels per axis the rays are drawn at, upscaled to the
    /// view (1: every pixel; at least [`MIN_RESOLUTION`]): what
    /// [`super::resolution::InteractiveResolution`] lowers while the view moves.
    pub resolution: f32,
    /// Light of the view (copied from the scene each frame).
    pub light: Light,
}

/// On a view whose picture at rest is averaged over frames of different ray jitter
/// (`interactive` puts it there): this frame is the `index`-th at rest (0 starts the
/// average anew). The renderer counts the frames it actually blended into the average
/// (a frame it could not draw, its pipeline still compiling, is not one of them): the
/// next weighs `1 / (blended + 1)` against them, so after `frames` of them the picture
/// is their mean; from then on it is held (no rays are cast, the average is drawn).
/// The view's [`VolumeView::frame`] seeds each frame's jitter.
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq)]
pub struct Accumulate {
    pub index: u32,
    pub frames: u32,
}

impl Accumulate {
    /// The weight of a frame against the `blended` frames already in the average.
    pub fn weight(blended: u32) -> f32 {
        1.0 / (blended as f64 + 1.0) as f32
    }

    /// Whether the average of `blended` frames is complete: the frame casts no rays and
    /// shows it.
    pub fn holds(&self, blended: u32) -> bool {
        blended >= self.frames
    }
}

impl VolumeView {
    /// [`Self::resolution`] as the renderer takes it: within [`MIN_RESOLUTION`] … 1, and
    /// 1 where it is not a number.
    pub fn drawn_resolution(&self) -> f32 {
        if self.resolution.is_finite() { self.resolution.clamp(MIN_RESOLUTION, 1.0) } else { 1.0 }
    }
}

impl Default for VolumeView {
    fn default() -> Self {
        Self {
            jitter: true,
            skip_empty: true,
            early_termination: true,
            debug_rays: false,
            debug_counts: false,
            lens_antialias: true,
            lens_context_steps: false,
            gpu_silhouettes: true,
            frame: 0,
            resolution: 1.0,
            light: Light::Headlight,
        }
    }
}
