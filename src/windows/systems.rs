//! Window systems: attachments move windows; every frame each window becomes regions
//! (one per content, its box mapped onto its source) and clip windows cut their box out
//! of the datasets' regions.
//!
//! Overlapping windows: each window's regions cover its own box, so where two windows
//! overlap both contents show, composited sample by sample (region order: windows in
//! entity order). A clip window cuts the main view's datasets only, never another
//! window's contents; where clip windows overlap, the datasets are cut by the union of
//! the boxes.

use std::collections::HashMap;

use bevy::prelude::*;
use glam::Affine3A;

use super::boxes::{OrientedBox, subtract};
use super::components::{Attachment, Fit, Orientation, Pointer3d, Source, SourceBox, Viewer, VolumeWindow};
use super::mapping::{coupled_rotation, fit, map_rotation, window_to_source};
use crate::dataset::{Dataset, GpuVolume, SceneRegions};
use crate::region::{Region, box_planes};

/// Keeps user- and dataset-attached windows at their offset from the viewer or the
/// dataset (room windows stay where they are).
#[allow(clippy::type_complexity)]
pub fn attach_windows(
    mut windows: Query<(&VolumeWindow, &mut Transform, &mut GlobalTransform), (Without<Viewer>, Without<Dataset>)>,
    viewers: Query<&GlobalTransform, (With<Viewer>, Without<VolumeWindow>)>,
    datasets: Query<&GlobalTransform, (With<Dataset>, Without<VolumeWindow>)>,
) {
    for (w, mut transform, mut global) in &mut windows {
        let parent = match w.attachment {
            Attachment::Room => continue,
            Attachment::User { offset } => viewers.iter().next().map(|g| (*g, offset)),
            Attachment::Dataset { dataset, offset } => datasets.get(dataset).ok().map(|g| (*g, offset)),
        };
        let Some((parent, offset)) = parent else { continue };
        let placed = parent.mul_transform(offset);
        let (_, rotation, translation) = placed.to_scale_rotation_translation();
        let new = Transform { translation, rotation, scale: transform.scale };
        if *transform != new {
            *transform = new;
        }
        *global = GlobalTransform::from(new);
    }
}

/// The world box of a window (its transform's scale multiplies the size).
pub fn window_box(w: &VolumeWindow, global: &GlobalTransform) -> OrientedBox {
    let (scale, rotation, center) = global.to_scale_rotation_translation();
    OrientedBox { center, rotation, half: (w.size * scale).abs() * 0.5 }
}

/// Turns every window into regions and cuts clip windows out of the datasets.
#[allow(clippy::type_complexity)]
pub fn window_regions(
    windows: Query<(Entity, &VolumeWindow, &GlobalTransform)>,
    sources: Query<(&SourceBox, &GlobalTransform)>,
    pointers: Query<&GlobalTransform, With<Pointer3d>>,
    datasets: Query<(&Dataset, Option<&GpuVolume>, &GlobalTransform)>,
    mut out: ResMut<SceneRegions>,
) {
    if windows.is_empty() {
        return;
    }
    let mut list: Vec<_> = windows.iter().collect();
    list.sort_by_key(|(e, ..)| *e);
    let pointer = pointers.iter().next().map(|g| g.translation());
    // Window and source boxes, then coupling (one level: to the main view or to another
    // window's own map).
    let mut boxes: HashMap<Entity, (OrientedBox, OrientedBox)> = HashMap::new();
    for (e, w, g) in &list {
        let window = window_box(w, g);
        let source = match w.source {
            Source::Own => window,
            Source::Box(b) => match sources.get(b) {
                Ok((s, sg)) => window_box(&VolumeWindow { size: s.size, ..(*w).clone() }, sg),
                Err(_) => continue,
            },
            Source::Pointer { size } => match pointer {
                Some(p) => OrientedBox { center: p, rotation: window.rotation, half: size.abs() * 0.5 },
                None => continue,
            },
        };
        boxes.insert(*e, (window, source));
    }
    let mut scene = out.scene.clone();
    let mut index = out.datasets.clone();
    let dataset_regions = scene.regions.len();
    let mut clips = Vec::new();
    for (e, w, _) in &list {
        let Some(&(window, mut source)) = boxes.get(e) else { continue };
        let coupled = match w.automation.orientation {
            Orientation::Free => None,
            Orientation::MainView => Some(Quat::IDENTITY),
            Orientation::Window(other) => boxes.get(&other).map(|(ow, os)| map_rotation(ow, os)),
        };
        if let Some(r) = coupled {
            source.rotation = coupled_rotation(window.rotation, r);
        }
        // Every content's world→voxel map and the corners of its box.
        let contents: Vec<_> = w
            .contents
            .iter()
            .filter_map(|c| {
                let (d, gpu, g) = datasets.get(c.dataset).ok()?;
                let volume = gpu.map_or_else(|| d.volume.clone(), |g| g.volume.clone());
                let world_to_voxel = volume.grid.world_to_index() * g.affine().inverse();
                Some((c, d, volume, world_to_voxel, g.affine()))
            })
            .collect();
        if let Some(how) = w.automation.fit {
            let corners: Vec<Vec3> =
                contents.iter().flat_map(|(_, _, v, _, to_world)| v.grid.corners().map(|p| to_world.transform_point3(p))).collect();
            source = fit(&window, source.rotation, &corners, how == Fit::Uniform);
        }
        let map = window_to_source(&window, &source);
        for (c, d, volume, world_to_voxel, _) in contents {
            let volume_index = match index.iter().position(|x| *x == c.dataset) {
                Some(i) => i,
                None => {
                    scene.volumes.push(volume.clone());
                    index.push(c.dataset);
                    scene.volumes.len() - 1
                }
            };
            scene.appearances.push(c.appearance.clone().unwrap_or_else(|| d.appearance.clone()));
            let to_voxel: Affine3A = world_to_voxel * map;
            let mut planes = window.planes();
            planes.extend(box_planes(&to_voxel, Vec3::splat(-0.5), volume.dims().as_vec3() - 0.5));
            scene.regions.push(Region { planes, world_to_voxel: to_voxel, volume: volume_index, appearance: scene.appearances.len() - 1 });
        }
        if w.clip {
            clips.push(window);
        }
    }
    // Clip windows cut the datasets' own regions.
    let mut cut = Vec::with_capacity(dataset_regions);
    for r in scene.regions.drain(..dataset_regions) {
        let mut pieces = vec![r.planes.clone()];
        for b in &clips {
            pieces = pieces.iter().flat_map(|p| subtract(p, b)).collect();
        }
        cut.extend(pieces.into_iter().map(|planes| Region { planes, ..r.clone() }));
    }
    scene.regions.splice(0..0, cut);
    if out.scene != scene {
        out.scene = scene;
    }
    out.datasets = index;
}
