//! The CPU reference renderer: the same per-pixel function as the GPU shaders.
//!
//! It is the oracle for GPU image tests, serves picking (first hit under the transfer
//! function, for splitters, pointers and selection painting) and renders small images
//! headless (`focal render --cpu`). Rows are traced in parallel. See [`trace`] for the
//! per-pixel algorithm.

pub mod image;
pub mod prepare;
pub mod trace;

use glam::Vec4;
use rayon::prelude::*;

pub use image::RenderedImage;
pub use trace::Traced;

use crate::lens::antialias::Footprint;
use crate::lens::{Lens, ResolvedLens, Screen, lens_ray};
pub use crate::region::RenderScene;
use crate::region::{Camera, Ray};
use prepare::PreparedRegion;

/// Accumulated opacity that defines the depth of a pixel and a pick hit.
pub const DEPTH_THRESHOLD: f32 = 0.5;

/// Prepares every region of `scene` (baked lookups, samplers, occupancy).
pub fn prepare(scene: &RenderScene) -> Result<Vec<PreparedRegion<'_>>, String> {
    scene
        .regions
        .iter()
        .map(|r| {
            let v =
                scene.volumes.get(r.volume).ok_or_else(|| format!("region refers to volume {} of {}", r.volume, scene.volumes.len()))?;
            let a = scene
                .appearances
                .get(r.appearance)
                .ok_or_else(|| format!("region refers to appearance {} of {}", r.appearance, scene.appearances.len()))?;
            let mut p = PreparedRegion::new(r, v, a);
            if !scene.skip_empty {
                p.occupancy = None;
                for part in p.objects.iter_mut().flat_map(|o| o.parts.iter_mut()) {
                    part.occupancy = None;
                }
            }
            Ok(p)
        })
        .collect::<Result<Vec<_>, String>>()
        .map(|mut prepared| {
            let groups = prepare::projection_groups(&prepared, &scene.appearances);
            for (p, g) in prepared.iter_mut().zip(groups) {
                p.projection_group = g;
            }
            prepared
        })
}

/// Renders `scene` seen by `camera` into a `width × height` image.
pub fn render(scene: &RenderScene, camera: &Camera, width: u32, height: u32) -> Result<RenderedImage, String> {
    render_lensed(scene, camera, &[], width, height)
}

/// Renders `scene` seen by `camera` through `lenses` (in order, the last on top).
pub fn render_lensed(scene: &RenderScene, camera: &Camera, lenses: &[Lens], width: u32, height: u32) -> Result<RenderedImage, String> {
    render_frame(scene, camera, lenses, width, height, 0)
}

/// [`render_lensed`] with the ray jitter of frame `frame` (the seed of
/// [`trace::jitter`], as the GPU's `VolumeView::frame`), where the scene jitters.
pub fn render_frame(
    scene: &RenderScene,
    camera: &Camera,
    lenses: &[Lens],
    width: u32,
    height: u32,
    frame: u32,
) -> Result<RenderedImage, String> {
    if width == 0 || height == 0 {
        return Err(format!("image size {width}×{height} is empty"));
    }
    for lens in lenses {
        lens.validate().map_err(|e| format!("{} lens: {e}", lens.kind_name()))?;
    }
    let screen = Screen::new(width, height);
    let resolved: Vec<ResolvedLens> = lenses.iter().filter_map(|l| crate::lens::stack::resolve_in(l, camera, screen, scene)).collect();
    let regions = prepare(scene)?;
    let [r, g, b] = crate::transfer::color::srgb3_to_linear(scene.background);
    let bg = Vec4::new(r, g, b, 1.0);
    let pixels: Vec<Traced> = (0..height)
        .into_par_iter()
        .flat_map_iter(|y| {
            let (regions, resolved) = (&regions, &resolved);
            (0..width).map(move |x| {
                let Some(ray) = lens_ray(camera, screen, resolved, x as f32 + 0.5, y as f32 + 0.5) else {
                    return Traced::EMPTY;
                };
                let j = if scene.jitter { trace::jitter(x, y, frame) } else { 0.5 };
                let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
                let footprint = if scene.lens_antialias { Footprint::new(camera, screen, resolved, px, py) } else { None };
                trace::trace_antialiased(regions, scene.light, ray, j, DEPTH_THRESHOLD, false, footprint.as_ref())
            })
        })
        .collect();
    Ok(RenderedImage::from_traced(width, height, &pixels, bg))
}

/// A pick hit: the first point along a ray where the accumulated opacity reaches
/// [`DEPTH_THRESHOLD`] (for iso-surfaces, the surface).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub position: glam::Vec3,
    pub region: usize,
}

/// The label id at a hit on a label volume (its nearest voxel: the label whose sample
/// made the ray opaque there), or on a segmented volume (the label of its segmentation
/// there); `None` on other regions.
pub fn label_at(scene: &RenderScene, hit: &Hit) -> Option<u32> {
    let region = scene.regions.get(hit.region)?;
    let appearance = scene.appearances.get(region.appearance)?;
    let volume = scene.volumes.get(region.volume)?;
    let q = region.world_to_voxel.transform_point3(hit.position);
    match (&appearance.lookup, &appearance.segmentation) {
        (_, Some(seg)) => seg.label_at(&volume.grid, q),
        (crate::region::Lookup::Labels(_), None) => Some(volume.sampler().nearest(q) as u32),
        _ => None,
    }
}

/// First visible point along `ray` under the scene's transfer functions.
pub fn pick(scene: &RenderScene, ray: Ray) -> Result<Option<Hit>, String> {
    let regions = prepare(scene)?;
    let t = trace::trace(&regions, scene.light, ray, 0.5, DEPTH_THRESHOLD, true);
    Ok(t.region.map(|region| Hit { t: t.depth, position: ray.at(t.depth), region }))
}
