//! Window systems: attachments move windows; every frame the windows are placed (boxes,
//! sources, orientation coupling) and become regions ([`super::regions`]), in entity
//! order.

use std::collections::HashMap;

use bevy::prelude::*;

use super::boxes::OrientedBox;
use super::components::{Attachment, Orientation, Pointer3d, Source, SourceBox, Viewer, VolumeWindow};
use super::interaction::focus;
use super::mapping::{coupled_rotation, map_rotation};
use super::markers::{Marker, MarkerView, MarkerViews, PlacedWindows, WindowView, data_point, views};
use super::regions::{PlacedContent, PlacedWindow, add_windows};
use crate::dataset::{Dataset, GpuVolume, SceneRegions};
use crate::region::Ray;

/// Keeps user- and dataset-attached windows at their offset from the viewer or the
/// dataset (room windows stay where they are).
// A Bevy system: its parameters are the resources and queries it uses, and a query's
// type names the components it reads; splitting them up would only hide that.
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
// A Bevy system: its parameters are the resources and queries it uses, and a query's
// type names the components it reads; splitting them up would only hide that.
#[allow(clippy::type_complexity)]
pub fn window_regions(
    windows: Query<(Entity, &VolumeWindow, &GlobalTransform)>,
    sources: Query<(&SourceBox, &GlobalTransform)>,
    pointers: Query<&GlobalTransform, With<Pointer3d>>,
    datasets: Query<(&Dataset, Option<&GpuVolume>, &GlobalTransform)>,
    mut out: ResMut<SceneRegions>,
    mut views: ResMut<PlacedWindows>,
) {
    if windows.is_empty() {
        if !views.0.is_empty() {
            views.0.clear();
        }
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
    let mut placed_views = Vec::new();
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
        // The fit once: the placed window carries its fitted source.
        let fitted = PlacedWindow { window, source, fit: w.automation.fit, clip: w.clip, contents }.fitted();
        let shown = w.contents.iter().map(|c| c.dataset).filter(|d| datasets.contains(*d)).collect();
        placed_views.push((*e, WindowView { window, source: fitted.source, clip: w.clip, datasets: shown }));
        placed.push(fitted);
    }
    views.0 = placed_views;
    add_windows(&mut scene, dataset_regions, &placed);
    if out.scene != scene {
        out.scene = scene;
    }
    out.datasets = index;
}

/// The cursor's ray in the world when it is over the view (set by the app every frame;
/// `None` over the panels or outside the window).
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct CursorRay(pub Option<Ray>);

/// The window with the focus (`None`: the main view). Panel settings apply to it.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WindowFocus(pub Option<Entity>);

/// Gives the focus to the window the pointer reaches into or the cursor hovers
/// ([`super::interaction::focus`]); a removed window loses it.
pub fn update_focus(
    placed: Res<PlacedWindows>,
    cursor: Res<CursorRay>,
    pointers: Query<&GlobalTransform, With<Pointer3d>>,
    mut current: ResMut<WindowFocus>,
) {
    let boxes: Vec<(Entity, OrientedBox)> = placed.0.iter().map(|(e, v)| (*e, v.window)).collect();
    let pointer = pointers.iter().next().map(|g| g.translation());
    let mut next = focus(&boxes, cursor.0.as_ref(), pointer).unwrap_or(current.0);
    if next.is_some_and(|e| placed.get(e).is_none()) {
        next = None;
    }
    if current.0 != next {
        current.0 = next;
    }
}

/// Places every marker and the pointer in every view that shows their point
/// ([`super::markers::views`]).
// A Bevy system: its parameters are the resources and queries it uses, and a query's
// type names the components it reads; splitting them up would only hide that.
#[allow(clippy::type_complexity)]
pub fn propagate_markers(
    mut commands: Commands,
    placed: Res<PlacedWindows>,
    datasets: Query<&GlobalTransform, With<Dataset>>,
    mut markers: Query<(Entity, &Marker, Option<&mut MarkerViews>), Without<Pointer3d>>,
    mut pointers: Query<(Entity, &GlobalTransform, Option<&mut MarkerViews>), (With<Pointer3d>, Without<Marker>)>,
) {
    let mut set = |e: Entity, shown: Vec<MarkerView>, old: Option<Mut<MarkerViews>>| match old {
        Some(mut v) if v.0 != shown => v.0 = shown,
        Some(_) => {}
        None => {
            commands.entity(e).insert(MarkerViews(shown));
        }
    };
    for (e, m, old) in &mut markers {
        let shown =
            datasets.get(m.dataset).map_or_else(|_| Vec::new(), |g| views(g.transform_point(m.position), Some(m.dataset), &placed.0));
        set(e, shown, old);
    }
    for (e, g, old) in &mut pointers {
        let (p, _) = data_point(g.translation(), &placed.0);
        set(e, views(p, None, &placed.0), old);
    }
}

/// The dataset whose box holds world point `p` among `candidates` (the first; else the
/// first candidate when `fallback`).
fn dataset_at(world: &mut World, p: Vec3, candidates: Option<&[Entity]>, fallback: bool) -> Option<(Entity, Vec3)> {
    let mut q = world.query::<(Entity, &Dataset, &GlobalTransform)>();
    let mut all: Vec<(Entity, Vec3, bool)> = q
        .iter(world)
        .filter(|(e, ..)| candidates.is_none_or(|c| c.contains(e)))
        .map(|(e, d, g)| {
            let local = g.affine().inverse().transform_point3(p);
            let (lo, hi) = d.volume.grid.world_bounds();
            (e, local, local.cmpge(lo.min(hi)).all() && local.cmple(lo.max(hi)).all())
        })
        .collect();
    all.sort_by_key(|(e, ..)| *e);
    all.iter().find(|(.., inside)| *inside).or(all.first().filter(|_| fallback)).map(|(e, local, _)| (*e, *local))
}

/// The data point under the pointer, its dataset and position in the dataset's frame:
/// the dataset of the window the pointer reaches into, or the dataset holding it in
/// the main view.
fn pointed(world: &mut World) -> Option<(Vec3, Entity, Vec3)> {
    let mut pointers = world.query_filtered::<&GlobalTransform, With<Pointer3d>>();
    let pointer = pointers.iter(world).next()?.translation();
    let placed = world.get_resource::<PlacedWindows>().cloned().unwrap_or_default();
    let (p, window) = data_point(pointer, &placed.0);
    let candidates = window.and_then(|w| placed.get(w)).map(|v| v.datasets.clone());
    let (dataset, local) = dataset_at(world, p, candidates.as_deref(), candidates.is_some())?;
    Some((p, dataset, local))
}

/// Places a marker at the data point under the 3D pointer (reaching into a window marks
/// the data it shows); `None` when the pointer is in no dataset and no window.
pub fn place_marker(world: &mut World) -> Option<Entity> {
    let (_, dataset, position) = pointed(world)?;
    Some(world.spawn(Marker { dataset, position }).id())
}

/// The marker nearest the data point under the pointer, within `radius` millimetres.
fn marker_near(world: &mut World, radius: f32) -> Option<Entity> {
    let (p, ..) = pointed(world)?;
    let mut q = world.query::<(Entity, &Marker)>();
    let found: Vec<(Entity, Entity, Vec3)> = q.iter(world).map(|(e, m)| (e, m.dataset, m.position)).collect();
    found
        .into_iter()
        .filter_map(|(e, d, local)| world.get::<GlobalTransform>(d).map(|g| (e, g.transform_point(local).distance(p))))
        .filter(|(_, d)| *d <= radius)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(e, _)| e)
}

/// Deletes the marker nearest the pointer's data point (within `radius`).
pub fn delete_marker(world: &mut World, radius: f32) -> bool {
    marker_near(world, radius).is_some_and(|e| world.despawn(e))
}

/// Moves the marker nearest the pointer's data point (within `radius`) onto it.
pub fn move_marker(world: &mut World, radius: f32) -> bool {
    let Some(e) = marker_near(world, radius) else { return false };
    let Some((_, dataset, position)) = pointed(world) else { return false };
    world.entity_mut(e).insert(Marker { dataset, position });
    true
}
