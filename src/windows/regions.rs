//! Windows as regions (pure; the ECS system and the scene runner both call it).
//!
//! Each content of a window is one region: the window's box, cut to where the content's
//! data lies, with world → voxel map `V · M` (`V` the dataset's own map, `M` the
//! window → source map of [`super::mapping`], after the fit automation). A clip window
//! then cuts its box out of the datasets' own regions as a hole ([`Region::holes`]: a
//! ray meets a dataset in its interval less the box's, so a ray through a window is
//! three segments: the dataset before the box, the window, the dataset behind it).
//! Windows never cut each other's contents, so where windows overlap their contents
//! composite sample by sample, and where clip windows overlap the datasets are cut by
//! the union of the boxes (each box a hole). (The GPU packing draws a clip window that
//! shows its dataset in place as the dataset's region with the window's table inside
//! the box, the same picture without the segments: `render::pack::insets`.)

use std::sync::Arc;

use glam::{Affine3A, Vec3};

use super::boxes::OrientedBox;
use super::components::Fit;
use super::mapping::{fit, window_to_source};
use crate::region::{Appearance, Plane, Region, RenderScene, box_planes, has_volume};
use crate::volume::Volume;

/// A window placed in the world, its source box turned by any orientation coupling.
#[derive(Clone, Debug)]
pub struct PlacedWindow {
    pub window: OrientedBox,
    pub source: OrientedBox,
    pub fit: Option<Fit>,
    pub clip: bool,
    pub contents: Vec<PlacedContent>,
}

/// One content of a placed window.
#[derive(Clone, Debug)]
pub struct PlacedContent {
    pub volume: Arc<Volume>,
    /// Index of `volume` in the scene's volumes.
    pub volume_index: usize,
    /// The dataset's own frame → world (its transform).
    pub dataset_to_world: Affine3A,
    pub appearance: Appearance,
}

impl PlacedWindow {
    /// The window with the fit automation applied to its source (then `fit` is `None`).
    pub fn fitted(self) -> PlacedWindow {
        PlacedWindow { source: self.fitted_source(), fit: None, ..self }
    }

    /// The source box after the fit automation.
    pub fn fitted_source(&self) -> OrientedBox {
        match self.fit {
            Some(how) => {
                let corners: Vec<Vec3> =
                    self.contents.iter().flat_map(|c| c.volume.grid.corners().map(|p| c.dataset_to_world.transform_point3(p))).collect();
                fit(&self.window, self.source.rotation, &corners, how == Fit::Uniform)
            }
            None => self.source,
        }
    }
}

/// Adds the windows' regions to `scene`, whose first `dataset_regions` regions are the
/// datasets' own, and cuts the clip windows out of those.
pub fn add_windows(scene: &mut RenderScene, dataset_regions: usize, windows: &[PlacedWindow]) {
    for w in windows {
        let map = window_to_source(&w.window, &w.fitted_source());
        for c in &w.contents {
            scene.appearances.push(c.appearance.clone());
            let to_voxel = c.volume.grid.world_to_index() * c.dataset_to_world.inverse() * map;
            let mut planes = w.window.planes();
            planes.extend(box_planes(&to_voxel, Vec3::splat(-0.5), c.volume.dims().as_vec3() - 0.5));
            scene.regions.push(Region {
                planes,
                holes: Vec::new(),
                world_to_voxel: to_voxel,
                volume: c.volume_index,
                appearance: scene.appearances.len() - 1,
            });
        }
    }
    let n = dataset_regions.min(scene.regions.len());
    for b in windows.iter().filter(|w| w.clip).map(|w| &w.window) {
        for r in &mut scene.regions[..n] {
            if touches(&r.planes, b) {
                let planes = b.planes();
                r.holes.push(std::array::from_fn(|i| planes[i]));
            }
        }
    }
}

/// Whether the box meets the convex region `planes` with volume (a box that does not
/// leaves the region as it is).
fn touches(planes: &[Plane], b: &OrientedBox) -> bool {
    let mut both = planes.to_vec();
    both.extend(b.planes());
    has_volume(&both)
}
