//! Writing the current state as a scene file: every dataset with its source and its
//! appearance spelled out (transfer functions inline, label styles as overrides), the
//! camera as an explicit pose, the lenses in stack order.

use crate::clip::Clipping;
use std::path::Path;

use glam::{EulerRot, Quat, Vec3};

use super::file::{CameraSpec, DatasetSpec, SceneFile, SourceSpec};
use super::load::resolve;
use crate::region::{Appearance, AppearanceSpec, Camera, Light, Projection};
use crate::twolevel::spec::segmentation_spec;

/// One dataset as the app holds it.
pub struct DatasetState<'a> {
    pub spec: &'a DatasetSpec,
    pub appearance: &'a Appearance,
    pub translation: Vec3,
    pub rotation: Quat,
    pub visible: bool,
    pub clip: &'a Clipping,
    /// Its exploded view as it is now.
    pub explode: Option<crate::explode::spec::ExplodeSpec>,
}

impl<'a> DatasetState<'a> {
    /// A dataset as a scene file loaded it.
    pub fn of(d: &'a super::load::LoadedDataset) -> Self {
        let (_, rotation, translation) = d.transform.to_scale_rotation_translation();
        DatasetState {
            spec: &d.spec,
            appearance: &d.appearance,
            translation,
            rotation,
            visible: d.visible,
            clip: &d.clip,
            explode: d.spec.explode.clone(),
        }
    }
}

/// Source paths made absolute (the saved file may live elsewhere).
fn absolute(source: &SourceSpec, base: &Path) -> SourceSpec {
    let abs = |p: &Path| std::fs::canonicalize(resolve(base, p)).unwrap_or_else(|_| resolve(base, p));
    match source {
        SourceSpec::File(p) => SourceSpec::File(abs(p)),
        SourceSpec::Raw { path, layout } => SourceSpec::Raw { path: abs(path), layout: layout.clone() },
        other => other.clone(),
    }
}

/// The scene file of a state.
pub fn scene_file(
    datasets: &[DatasetState],
    camera: &Camera,
    background: [f32; 3],
    light: Light,
    size: (u32, u32),
    lenses: &[crate::lens::Lens],
    base: &Path,
) -> SceneFile {
    let datasets = datasets
        .iter()
        .map(|d| {
            let (x, y, z) = d.rotation.to_euler(EulerRot::XYZ);
            DatasetSpec {
                name: d.spec.name.clone(),
                source: absolute(&d.spec.source, base),
                appearance: AppearanceSpec {
                    segmentation: d
                        .appearance
                        .segmentation
                        .as_ref()
                        .zip(d.spec.appearance.segmentation.as_ref())
                        .map(|(seg, spec)| segmentation_spec(seg, spec.labels)),
                    // (A label table's path made absolute too, as the source's.)
                    labels: AppearanceSpec::of(d.appearance, d.spec.appearance.labels.as_ref()).labels.map(|mut l| {
                        l.table = l.table.map(|t| std::fs::canonicalize(resolve(base, &t)).unwrap_or_else(|_| resolve(base, &t)));
                        l
                    }),
                    ..AppearanceSpec::of(d.appearance, d.spec.appearance.labels.as_ref())
                },
                translation: d.translation.into(),
                rotation_deg: (x.to_degrees(), y.to_degrees(), z.to_degrees()),
                visible: d.visible,
                clip: d.clip.clone(),
                explode: d.explode.clone(),
            }
        })
        .collect();
    let target = camera.position + camera.forward() * 100.0;
    let camera = CameraSpec::LookAt {
        eye: camera.position.into(),
        target: target.into(),
        up: camera.up().into(),
        orthographic_height: match camera.projection {
            Projection::Orthographic { height } => Some(height),
            Projection::Perspective { .. } => None,
        },
        fov_deg: match camera.projection {
            Projection::Perspective { fov_y } => fov_y.to_degrees(),
            Projection::Orthographic { .. } => 30.0,
        },
    };
    SceneFile {
        size,
        background: (background[0], background[1], background[2]),
        light,
        rendering: Default::default(),
        datasets,
        camera,
        lenses: lenses.to_vec(),
        windows: Vec::new(),
        pointer: None,
        markers: Vec::new(),
        rulers: Vec::new(),
        frames: Vec::new(),
        animation: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::region::View;
    use crate::scene::load::{camera as camera_of, load_datasets};

    #[test]
    fn saved_scenes_load_back_the_same() {
        let original = SceneFile::parse(
            "(datasets: [(source: Phantom(kind: sphere, resolution: 16), appearance: (mode: mip)), (source: PhantomLabels(resolution: 16), appearance: (labels: Some((opacity: 0.4))))])",
            "t",
        )
        .unwrap();
        let loaded = load_datasets(&original, Path::new(".")).unwrap();
        let states: Vec<DatasetState> =
            loaded.iter().map(|d| DatasetState { translation: Vec3::new(1.0, 2.0, 3.0), ..DatasetState::of(d) }).collect();
        let cam = View::Left.frame(Vec3::ZERO, 20.0, true);
        let lenses = vec![
            crate::lens::Lens::magnifier(glam::Vec2::new(0.1, -0.2), 0.3, 0.1, 2.5),
            crate::lens::Lens {
                kind: crate::lens::LensKind::Sampling(crate::lens::Sampling::Custom(vec![2.0, 1.5, 0.5, 1.0])),
                shape: crate::lens::Shape::Square,
                ..crate::lens::Lens::magnifier(glam::Vec2::ZERO, 0.4, 0.0, 1.0)
            },
        ];
        let saved = scene_file(&states, &cam, [0.1, 0.2, 0.3], Light::Headlight, (64, 64), &lenses, Path::new("."));
        let text = saved.to_ron().unwrap();
        let again = SceneFile::parse(&text, "saved").unwrap();
        let reloaded = load_datasets(&again, Path::new(".")).unwrap();
        for (a, b) in loaded.iter().zip(&reloaded) {
            assert_eq!(a.appearance, b.appearance, "{}", a.name);
        }
        assert_eq!(reloaded[0].transform.translation, glam::Vec3A::new(1.0, 2.0, 3.0));
        let back = camera_of(&again.camera, (Vec3::splat(-1.0), Vec3::ONE), 1.0);
        assert!((back.position - cam.position).length() < 1e-3);
        assert_eq!(back.projection, cam.projection);
        assert_eq!(again.lenses, lenses);
    }
}
