//! A renderable scene description: volumes, the regions showing them, their
//! appearances and the lighting. Both renderers take it (the CPU reference directly, the
//! GPU renderer after packing); the techniques produce it.

use std::sync::Arc;

use super::{Appearance, Light, Region};
use crate::volume::Volume;

/// Volumes, regions and appearances to render.
#[derive(Clone, Debug)]
pub struct RenderScene {
    pub volumes: Vec<Arc<Volume>>,
    pub regions: Vec<Region>,
    pub appearances: Vec<Appearance>,
    /// Background colour (display sRGB values).
    pub background: [f32; 3],
    pub light: Light,
    /// Jitter ray starts per pixel (against wood-grain artefacts).
    pub jitter: bool,
    /// Skip bricks the transfer function makes invisible (exact; off only to measure).
    pub skip_empty: bool,
    /// Under lenses, sample compressed areas from the mip chain (`lens::antialias`).
    pub lens_antialias: bool,
}

/// Equal when they show the same volumes (the same shared data, not equal copies) the
/// same way.
impl PartialEq for RenderScene {
    fn eq(&self, other: &Self) -> bool {
        self.regions == other.regions && self.equal_but_regions(other)
    }
}

impl RenderScene {
    /// [`PartialEq`] with the regions left out (the interactive views compare those
    /// within a tolerance).
    pub fn equal_but_regions(&self, other: &Self) -> bool {
        self.volumes.len() == other.volumes.len()
            && self.volumes.iter().zip(&other.volumes).all(|(a, b)| std::sync::Arc::ptr_eq(a, b))
            && self.appearances == other.appearances
            && self.background == other.background
            && self.light == other.light
            && self.jitter == other.jitter
            && self.skip_empty == other.skip_empty
            && self.lens_antialias == other.lens_antialias
    }
}

impl Default for RenderScene {
    fn default() -> Self {
        RenderScene {
            volumes: Vec::new(),
            regions: Vec::new(),
            appearances: Vec::new(),
            background: [0.0; 3],
            light: Light::Headlight,
            jitter: false,
            skip_empty: true,
            lens_antialias: true,
        }
    }
}

impl RenderScene {
    /// One volume shown in its own box with one appearance.
    pub fn single(volume: Arc<Volume>, appearance: Appearance) -> Self {
        let region = Region::volume_box(&volume.grid, 0, 0);
        RenderScene { volumes: vec![volume], regions: vec![region], appearances: vec![appearance], ..Default::default() }
    }
}

impl RenderScene {
    /// Every volume the scene samples: its volumes, then the label volumes of
    /// segmentations and the selections of selection weights that are not among them
    /// (the GPU atlas holds all of these).
    pub fn all_volumes(&self) -> Vec<Arc<Volume>> {
        let mut all = self.volumes.clone();
        let extra = self
            .appearances
            .iter()
            .flat_map(|a| a.segmentation.as_ref().map(|s| &s.labels).into_iter().chain(a.selection.as_ref().map(|w| &w.volume)));
        for v in extra {
            if !all.iter().any(|a| Arc::ptr_eq(a, v)) {
                all.push(v.clone());
            }
        }
        all
    }

    /// Bounding sphere (centre, radius) of the volumes the regions show; a unit sphere
    /// at the origin for an empty scene.
    pub fn bounding_sphere(&self) -> (glam::Vec3, f32) {
        let mut lo = glam::Vec3::splat(f32::INFINITY);
        let mut hi = glam::Vec3::splat(f32::NEG_INFINITY);
        for r in &self.regions {
            if let Some(v) = self.volumes.get(r.volume) {
                let (a, b) = v.grid.world_bounds();
                lo = lo.min(a);
                hi = hi.max(b);
            }
        }
        if !lo.is_finite() || !hi.is_finite() {
            return (glam::Vec3::ZERO, 1.0);
        }
        ((lo + hi) * 0.5, ((hi - lo).length() * 0.5).max(1e-3))
    }
}
