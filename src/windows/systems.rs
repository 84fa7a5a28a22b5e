//! Window systems: attachments move windows; every frame the windows are placed (boxes,
//! sources, orientation coupling) and become regions ([`super::regions`]), in entity
//! order.

use std::collections::HashMap;

use bevy::prelude::*;

use super::boxes::OrientedBox;
use super::components::{Attachment, Orientation, Pointer3d, Source, SourceBox, Viewer, VolumeWindow};
use super::mapping::{coupled_rotation, map_rotation};
use super::regions::{PlacedContent, PlacedWindow, add_windows};
use crate::dataset::{Dataset, GpuVolume, SceneRegions};

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
    let mut placed = Vec::new();
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
        let contents = w
            .contents
            .iter()
            .filter_map(|c| {
                let (d, gpu, g) = datasets.get(c.dataset).ok()?;
                let volume = gpu.map_or_else(|| d.volume.clone(), |g| g.volume.clone());
                // Windows show their contents whether or not the main view does.
                let volume_index = index.iter().position(|x| *x == c.dataset).unwrap_or_else(|| {
                    scene.volumes.push(volume.clone());
                    index.push(c.dataset);
                    scene.volumes.len() - 1
                });
                let appearance = c.appearance.clone().unwrap_or_else(|| d.appearance.clone());
                Some(PlacedContent { volume, volume_index, dataset_to_world: g.affine(), appearance })
            })
            .collect();
        placed.push(PlacedWindow { window, source, fit: w.automation.fit, clip: w.clip, contents });
    }
    add_windows(&mut scene, dataset_regions, &placed);
    if out.scene != scene {
        out.scene = scene;
    }
    out.datasets = index;
}
