//! Frames of windows and source boxes: line meshes (children of their entities) drawn
//! by Bevy with the scene depth, so the ray caster ends rays at them and they sit
//! correctly in the volume. Windows get solid edges, source boxes dotted ones (the
//! paper draws source boxes dotted); the focused window's frame is lighter. Markers and
//! the 3D pointer are line crosses at each of their views.

use bevy::asset::RenderAssetUsages;
use bevy::mesh::PrimitiveTopology;
use bevy::prelude::*;

use super::components::{Pointer3d, SourceBox, VolumeWindow};
use super::markers::MarkerViews;
use super::systems::WindowFocus;

/// The frame entity of a window or source box.
#[derive(Component, Clone, Copy, Debug)]
pub struct Framed(pub Entity);

/// Marks a frame mesh.
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct Frame;

/// Meshes and materials shared by every frame.
#[derive(Resource)]
pub struct FrameAssets {
    solid: Handle<Mesh>,
    dotted: Handle<Mesh>,
    window: Handle<StandardMaterial>,
    focused: Handle<StandardMaterial>,
    source: Handle<StandardMaterial>,
    cross: Handle<Mesh>,
    marker: Handle<StandardMaterial>,
    pointer: Handle<StandardMaterial>,
}

/// Marks a cross drawn at one view of a marker or of the 3D pointer.
#[derive(Component, Clone, Copy, Debug, Default)]
pub struct ViewCross;

/// Arm length of a marker's cross (millimetres); the pointer's is twice that.
pub const CROSS_MM: f32 = 3.0;

/// Three segments of length 2 along the axes through the origin.
pub fn cross() -> Vec<[f32; 3]> {
    (0..3)
        .flat_map(|a| {
            let mut p = [0.0; 3];
            p[a] = 1.0;
            [p, p.map(|c| -c)]
        })
        .collect()
}

/// Line segments (pairs of points) along the 12 edges of the cube `[-½, ½]³`, each edge
/// cut into `dashes` dashes with gaps of the same length between them (1: solid).
pub fn box_edges(dashes: u32) -> Vec<[f32; 3]> {
    let dashes = dashes.max(1);
    let mut out = Vec::new();
    for axis in 0..3 {
        for corner in 0..4 {
            let mut a = Vec3::ZERO;
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            a[u] = if corner & 1 == 0 { -0.5 } else { 0.5 };
            a[v] = if corner & 2 == 0 { -0.5 } else { 0.5 };
            // 2·dashes − 1 equal parts: dash, gap, dash, …, dash.
            let parts = (2 * dashes - 1) as f32;
            for d in 0..dashes {
                let (mut p, mut q) = (a, a);
                p[axis] = -0.5 + 2.0 * d as f32 / parts;
                q[axis] = -0.5 + (2.0 * d as f32 + 1.0) / parts;
                out.push(p.to_array());
                out.push(q.to_array());
            }
        }
    }
    out
}

fn lines(points: Vec<[f32; 3]>) -> Mesh {
    Mesh::new(PrimitiveTopology::LineList, RenderAssetUsages::default()).with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, points)
}

pub fn setup_frames(mut commands: Commands, mut meshes: ResMut<Assets<Mesh>>, mut materials: ResMut<Assets<StandardMaterial>>) {
    let unlit = |r: f32, g: f32, b: f32| StandardMaterial { base_color: Color::srgb(r, g, b), unlit: true, ..default() };
    commands.insert_resource(FrameAssets {
        solid: meshes.add(lines(box_edges(1))),
        dotted: meshes.add(lines(box_edges(8))),
        window: materials.add(unlit(0.95, 0.8, 0.3)),
        focused: materials.add(unlit(1.0, 1.0, 0.75)),
        source: materials.add(unlit(0.6, 0.85, 1.0)),
        cross: meshes.add(lines(cross())),
        marker: materials.add(unlit(1.0, 0.35, 0.2)),
        pointer: materials.add(unlit(0.3, 1.0, 0.6)),
    });
}

/// Gives every window and source box a frame, and keeps its size; the focused window's
/// frame is lighter.
// A Bevy system: its parameters are the resources and queries it uses, and a query's
// type names the components it reads; splitting them up would only hide that.
#[allow(clippy::type_complexity)]
pub fn update_frames(
    mut commands: Commands,
    assets: Option<Res<FrameAssets>>,
    focus: Option<Res<WindowFocus>>,
    windows: Query<(Entity, &VolumeWindow, Option<&Framed>)>,
    sources: Query<(Entity, &SourceBox, Option<&Framed>)>,
    mut frames: Query<(&mut Transform, &mut MeshMaterial3d<StandardMaterial>), With<Frame>>,
) {
    let Some(assets) = assets else { return };
    let focused = focus.and_then(|f| f.0);
    let boxes = windows
        .iter()
        .map(|(e, w, f)| (e, w.size, f, &assets.solid, if focused == Some(e) { &assets.focused } else { &assets.window }))
        .chain(sources.iter().map(|(e, s, f)| (e, s.size, f, &assets.dotted, &assets.source)));
    for (entity, size, framed, mesh, material) in boxes {
        let scale = size.abs().max(Vec3::splat(1e-3));
        match framed.and_then(|f| frames.get_mut(f.0).ok()) {
            Some((mut t, mut m)) => {
                if t.scale != scale {
                    t.scale = scale;
                }
                if m.0 != *material {
                    m.0 = material.clone();
                }
            }
            None => {
                let frame = commands
                    .spawn((Frame, Mesh3d(mesh.clone()), MeshMaterial3d(material.clone()), Transform::from_scale(scale), ChildOf(entity)))
                    .id();
                // (Visibility on the parent too, so the frame inherits it.)
                commands.entity(entity).insert(Framed(frame)).insert_if_new(Visibility::default());
            }
        }
    }
}

/// Draws a cross at every view of every marker and of the 3D pointer
/// ([`super::markers::MarkerViews`]), redrawn when they change.
// A Bevy system: its parameters are the resources and queries it uses, and a query's
// type names the components it reads; splitting them up would only hide that.
#[allow(clippy::type_complexity)]
pub fn update_crosses(
    mut commands: Commands,
    assets: Option<Res<FrameAssets>>,
    views: Query<(&MarkerViews, Has<Pointer3d>)>,
    crosses: Query<Entity, With<ViewCross>>,
    mut drawn: Local<Vec<(Vec3, f32, bool)>>,
) {
    let Some(assets) = assets else { return };
    let mut now: Vec<(Vec3, f32, bool)> = views.iter().flat_map(|(v, pointer)| v.0.iter().map(move |m| (m.at, m.scale, pointer))).collect();
    now.sort_by(|a, b| a.0.to_array().partial_cmp(&b.0.to_array()).unwrap_or(std::cmp::Ordering::Equal).then(a.2.cmp(&b.2)));
    if *drawn == now {
        return;
    }
    for e in &crosses {
        commands.entity(e).despawn();
    }
    for &(p, scale, pointer) in &now {
        // As large as the view magnifies (small in a world-in-miniature).
        let (material, arm) = if pointer { (&assets.pointer, 2.0 * CROSS_MM) } else { (&assets.marker, CROSS_MM) };
        let size = Vec3::splat(arm * scale.clamp(0.05, 20.0));
        commands.spawn((
            ViewCross,
            Mesh3d(assets.cross.clone()),
            MeshMaterial3d(material.clone()),
            Transform::from_translation(p).with_scale(size),
        ));
    }
    *drawn = now;
}

/// Frames need Bevy's mesh and material assets: the app and the scene runner add this
/// next to `FocalPlugins` (the GPU image tests leave it out, as the CPU reference draws
/// no meshes).
pub struct WindowFramePlugin;

impl Plugin for WindowFramePlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(Startup, setup_frames).add_systems(
            PostUpdate,
            (update_frames.before(TransformSystems::Propagate), update_crosses.after(super::systems::propagate_markers)),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dotted_edges_cover_half_of_each_edge() {
        let solid = box_edges(1);
        assert_eq!(solid.len(), 24);
        let dotted = box_edges(4);
        assert_eq!(dotted.len(), 12 * 4 * 2);
        let length: f32 = dotted.chunks(2).map(|s| (Vec3::from(s[0]) - Vec3::from(s[1])).length()).sum();
        // 4 dashes of 1/7 per unit edge: 12 · 4/7.
        assert!((length - 12.0 * 4.0 / 7.0).abs() < 1e-4, "{length}");
        assert!(dotted.iter().all(|p| p.iter().all(|c| c.abs() <= 0.5 + 1e-6)));
    }
}
