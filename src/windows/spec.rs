//! Windows in scene files: the spec, its placement for the CPU reference, and the
//! entities it becomes in an app.
//!
//! A window's pose (`center`, `rotation_deg`) is given in the frame of its attachment:
//! the world (`Room`), the camera (`User`; the camera looks along its −z, so
//! `center: (0, 0, -300)` is 300 mm in front of the eye) or a dataset's own frame
//! (`Dataset(i)`).

use bevy::prelude::*;
use glam::{Affine3A, EulerRot};
use serde::{Deserialize, Serialize};

use super::boxes::OrientedBox;
use super::components::{Attachment, Automation, Content, Fit, Orientation, Pointer3d, Source, SourceBox, Viewer, VolumeWindow};
use super::mapping::{coupled_rotation, map_rotation};
use super::markers::Marker;
use super::regions::{PlacedContent, PlacedWindow};
use crate::region::{Appearance, AppearanceSpec};

/// A window of a scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WindowSpec {
    pub center: (f32, f32, f32),
    #[serde(default)]
    pub rotation_deg: (f32, f32, f32),
    pub size: (f32, f32, f32),
    #[serde(default)]
    pub contents: Vec<ContentSpec>,
    #[serde(default)]
    pub source: SourceSpec,
    #[serde(default)]
    pub attachment: AttachmentSpec,
    #[serde(default)]
    pub clip: bool,
    #[serde(default)]
    pub fit: Option<FitSpec>,
    #[serde(default)]
    pub orientation: OrientationSpec,
}

/// A dataset shown in a window (index in `datasets`), with the window's appearance.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContentSpec {
    pub dataset: usize,
    #[serde(default)]
    pub appearance: Option<AppearanceSpec>,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub enum SourceSpec {
    /// The window's own box.
    #[default]
    Own,
    /// A source box (world pose).
    Box {
        center: (f32, f32, f32),
        size: (f32, f32, f32),
        #[serde(default)]
        rotation_deg: (f32, f32, f32),
    },
    /// A box of this size on the scene's 3D pointer.
    Pointer { size: (f32, f32, f32) },
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub enum AttachmentSpec {
    #[default]
    Room,
    User,
    Dataset(usize),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FitSpec {
    Uniform,
    PerAxis,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub enum OrientationSpec {
    #[default]
    Free,
    MainView,
    /// Another window (index in `windows`).
    Window(usize),
}

fn vec3((x, y, z): (f32, f32, f32)) -> Vec3 {
    Vec3::new(x, y, z)
}

fn rotation((x, y, z): (f32, f32, f32)) -> Quat {
    Quat::from_euler(EulerRot::XYZ, x.to_radians(), y.to_radians(), z.to_radians())
}

impl WindowSpec {
    /// Checks indices against the scene; errors name the window.
    pub fn validate(&self, i: usize, datasets: usize, windows: usize) -> Result<(), String> {
        let bad = |what: &str, j: usize, n: usize| Err(format!("window {i}: {what} {j}, the scene has {n}"));
        for c in &self.contents {
            if c.dataset >= datasets {
                return bad("content refers to dataset", c.dataset, datasets);
            }
        }
        if let AttachmentSpec::Dataset(d) = self.attachment
            && d >= datasets
        {
            return bad("attached to dataset", d, datasets);
        }
        if let OrientationSpec::Window(w) = self.orientation
            && (w >= windows || w == i)
        {
            return Err(format!("window {i}: orientation coupled to window {w}, which is not another window of the {windows}"));
        }
        let sizes = [
            Some(self.size),
            if let SourceSpec::Box { size, .. } | SourceSpec::Pointer { size } = self.source { Some(size) } else { None },
        ];
        for (x, y, z) in sizes.into_iter().flatten() {
            if ![x, y, z].iter().all(|v| v.is_finite() && *v > 0.0) {
                return Err(format!("window {i}: size ({x}, {y}, {z}) must be positive"));
            }
        }
        Ok(())
    }

    /// The pose in the attachment's frame.
    pub fn pose(&self) -> Transform {
        Transform::from_translation(vec3(self.center)).with_rotation(rotation(self.rotation_deg))
    }

    fn automation(&self, windows: &[Entity]) -> Automation {
        Automation {
            fit: self.fit.map(|f| match f {
                FitSpec::Uniform => Fit::Uniform,
                FitSpec::PerAxis => Fit::PerAxis,
            }),
            orientation: match self.orientation {
                OrientationSpec::Free => Orientation::Free,
                OrientationSpec::MainView => Orientation::MainView,
                OrientationSpec::Window(w) => windows.get(w).map_or(Orientation::Free, |e| Orientation::Window(*e)),
            },
        }
    }
}

/// Every window's boxes for the CPU reference: `camera` and `datasets` (dataset frame →
/// world per dataset) place attached windows; `pointer` is the 3D pointer. Windows
/// whose source is the pointer are left out when there is no pointer.
pub fn placed_boxes(
    windows: &[WindowSpec],
    camera: Affine3A,
    datasets: &[Affine3A],
    pointer: Option<Vec3>,
) -> Vec<Option<(OrientedBox, OrientedBox)>> {
    let boxes: Vec<Option<(OrientedBox, OrientedBox)>> = windows
        .iter()
        .map(|w| {
            let frame = match w.attachment {
                AttachmentSpec::Room => Affine3A::IDENTITY,
                AttachmentSpec::User => camera,
                AttachmentSpec::Dataset(d) => *datasets.get(d)?,
            };
            let (_, r, t) = (frame * w.pose().compute_affine()).to_scale_rotation_translation();
            let window = OrientedBox { center: t, rotation: r, half: vec3(w.size) * 0.5 };
            let source = match w.source {
                SourceSpec::Own => window,
                SourceSpec::Box { center, size, rotation_deg } => {
                    OrientedBox { center: vec3(center), rotation: rotation(rotation_deg), half: vec3(size) * 0.5 }
                }
                SourceSpec::Pointer { size } => OrientedBox { center: pointer?, rotation: window.rotation, half: vec3(size) * 0.5 },
            };
            Some((window, source))
        })
        .collect();
    // Orientation coupling, against the other windows' uncoupled maps.
    windows
        .iter()
        .zip(&boxes)
        .map(|(w, b)| {
            let (window, mut source) = (*b)?;
            let coupled = match w.orientation {
                OrientationSpec::Free => None,
                OrientationSpec::MainView => Some(Quat::IDENTITY),
                OrientationSpec::Window(o) => boxes.get(o).copied().flatten().map(|(ow, os)| map_rotation(&ow, &os)),
            };
            if let Some(r) = coupled {
                source.rotation = coupled_rotation(window.rotation, r);
            }
            Some((window, source))
        })
        .collect()
}

/// A window placed for the CPU reference: `contents` are (volume index in the scene,
/// volume, dataset → world, appearance) per content.
pub fn placed(spec: &WindowSpec, boxes: (OrientedBox, OrientedBox), contents: Vec<PlacedContent>) -> PlacedWindow {
    let fit = spec.fit.map(|f| match f {
        FitSpec::Uniform => Fit::Uniform,
        FitSpec::PerAxis => Fit::PerAxis,
    });
    PlacedWindow { window: boxes.0, source: boxes.1, fit, clip: spec.clip, contents }
}

/// Replaces the windows, source boxes and pointer of `world` by those of a scene:
/// `datasets` are the dataset entities, `appearances` each content's appearance (in
/// order, `None`: the dataset's), `camera` the viewer (marked [`Viewer`]; `None`: the
/// viewer stays as it is).
pub fn replace_windows(
    world: &mut World,
    windows: &[WindowSpec],
    appearances: &[Vec<Option<Appearance>>],
    datasets: &[Entity],
    camera: Option<Entity>,
    pointer: Option<Vec3>,
) {
    let old: Vec<Entity> =
        world.query_filtered::<Entity, Or<(With<VolumeWindow>, With<SourceBox>, With<Pointer3d>)>>().iter(world).collect();
    for e in old {
        world.despawn(e);
    }
    if let Some(camera) = camera {
        world.entity_mut(camera).insert(Viewer);
    }
    if let Some(p) = pointer {
        world.spawn((Pointer3d, Transform::from_translation(p)));
    }
    let entities: Vec<Entity> = windows.iter().map(|_| world.spawn_empty().id()).collect();
    for ((w, e), looks) in windows.iter().zip(&entities).zip(appearances) {
        let source = match w.source {
            SourceSpec::Own => Source::Own,
            SourceSpec::Box { center, size, rotation_deg } => {
                let b = world.spawn((
                    SourceBox { size: vec3(size) },
                    Transform::from_translation(vec3(center)).with_rotation(rotation(rotation_deg)),
                ));
                Source::Box(b.id())
            }
            SourceSpec::Pointer { size } => Source::Pointer { size: vec3(size) },
        };
        let attachment = match w.attachment {
            AttachmentSpec::Room => Attachment::Room,
            AttachmentSpec::User => Attachment::User { offset: w.pose() },
            AttachmentSpec::Dataset(d) => match datasets.get(d) {
                Some(&dataset) => Attachment::Dataset { dataset, offset: w.pose() },
                None => Attachment::Room,
            },
        };
        let contents = w
            .contents
            .iter()
            .zip(looks)
            .filter_map(|(c, a)| datasets.get(c.dataset).map(|&dataset| Content { dataset, appearance: a.clone() }))
            .collect();
        let window = VolumeWindow { size: vec3(w.size), contents, source, attachment, clip: w.clip, automation: w.automation(&entities) };
        world.entity_mut(*e).insert((window, w.pose()));
    }
}

/// A window entity as a spec (for saving): `pose` is the window's world pose,
/// `dataset_index` the saved index of a dataset entity, `source` a source box entity's
/// world pose and size, `windows` the saved order of the window entities.
pub fn window_spec(
    w: &VolumeWindow,
    pose: Transform,
    dataset_index: impl Fn(Entity) -> Option<usize>,
    source: impl Fn(Entity) -> Option<(Transform, Vec3)>,
    windows: &[Entity],
) -> WindowSpec {
    let tuple = |v: Vec3| (v.x, v.y, v.z);
    let degrees = |q: Quat| {
        let (x, y, z) = q.to_euler(EulerRot::XYZ);
        (x.to_degrees(), y.to_degrees(), z.to_degrees())
    };
    let (attachment, local) = match w.attachment {
        Attachment::Room => (AttachmentSpec::Room, pose),
        Attachment::User { offset } => (AttachmentSpec::User, offset),
        Attachment::Dataset { dataset, offset } => match dataset_index(dataset) {
            Some(i) => (AttachmentSpec::Dataset(i), offset),
            None => (AttachmentSpec::Room, pose),
        },
    };
    let source = match w.source {
        Source::Own => SourceSpec::Own,
        Source::Box(b) => match source(b) {
            Some((t, size)) => SourceSpec::Box { center: tuple(t.translation), size: tuple(size), rotation_deg: degrees(t.rotation) },
            None => SourceSpec::Own,
        },
        Source::Pointer { size } => SourceSpec::Pointer { size: tuple(size) },
    };
    WindowSpec {
        center: tuple(local.translation),
        rotation_deg: degrees(local.rotation),
        size: tuple(w.size),
        contents: w
            .contents
            .iter()
            .filter_map(|c| {
                let dataset = dataset_index(c.dataset)?;
                Some(ContentSpec { dataset, appearance: c.appearance.as_ref().map(|a| AppearanceSpec::of(a, None)) })
            })
            .collect(),
        source,
        attachment,
        clip: w.clip,
        fit: w.automation.fit.map(|f| match f {
            Fit::Uniform => FitSpec::Uniform,
            Fit::PerAxis => FitSpec::PerAxis,
        }),
        orientation: match w.automation.orientation {
            Orientation::Free => OrientationSpec::Free,
            Orientation::MainView => OrientationSpec::MainView,
            Orientation::Window(e) => windows.iter().position(|x| *x == e).map_or(OrientationSpec::Free, OrientationSpec::Window),
        },
    }
}

/// An interpretive marker in a scene file: a point of a dataset, in the dataset's own
/// frame (millimetres), so it moves with the dataset.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MarkerSpec {
    pub dataset: usize,
    pub position: (f32, f32, f32),
}

impl MarkerSpec {
    /// Checks marker `i` against a scene of `datasets` datasets.
    pub fn validate(&self, i: usize, datasets: usize) -> Result<(), String> {
        if self.dataset >= datasets {
            return Err(format!("marker {i}: refers to dataset {}, the scene has {datasets}", self.dataset));
        }
        if !vec3(self.position).is_finite() {
            return Err(format!("marker {i}: position {:?} is not finite", self.position));
        }
        Ok(())
    }
}

/// The windows, the 3D pointer and the markers of a scene, as saved.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WindowScene {
    pub windows: Vec<WindowSpec>,
    pub pointer: Option<(f32, f32, f32)>,
    pub markers: Vec<MarkerSpec>,
}

/// Replaces the markers of `world` by a scene's (`datasets`: the dataset entities in the
/// scene's order; markers of a missing dataset are left out).
pub fn replace_markers(world: &mut World, markers: &[MarkerSpec], datasets: &[Entity]) {
    let old: Vec<Entity> = world.query_filtered::<Entity, With<Marker>>().iter(world).collect();
    for e in old {
        world.despawn(e);
    }
    for m in markers {
        if let Some(&dataset) = datasets.get(m.dataset) {
            world.spawn(Marker { dataset, position: vec3(m.position) });
        }
    }
}

/// `marker` as saved: `dataset_index` gives a dataset's index among the saved ones.
pub fn marker_spec(marker: &Marker, dataset_index: impl Fn(Entity) -> Option<usize>) -> Option<MarkerSpec> {
    Some(MarkerSpec { dataset: dataset_index(marker.dataset)?, position: marker.position.into() })
}
