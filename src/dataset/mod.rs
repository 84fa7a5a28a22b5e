//! Datasets: volumes shown in the scene, each an entity.
//!
//! A [`Dataset`] holds its volume (shared, immutable), its appearance and a display
//! name; its `Transform` places it in the world (identity = the volume's own RAS
//! millimetres). Every frame [`collect_regions`] turns the datasets into the
//! [`SceneRegions`] both renderers draw: one region per visible dataset, its box mapped
//! through the inverse of the dataset's transform. Later techniques (windows, exploded
//! parts) add or replace regions after it, in [`RegionSystems::Modify`]. Cameras that
//! show the volumes carry a [`VolumeView`] ([`view`]).

pub mod gpu_fit;
pub mod view;

use std::sync::Arc;

use bevy::prelude::*;

use crate::clip::Clipping;
use crate::region::{Appearance, Light, RenderScene};
use crate::volume::{LabelTable, Volume};

pub use view::VolumeView;

/// A volume in the scene.
#[derive(Component, Clone)]
pub struct Dataset {
    pub volume: Arc<Volume>,
    pub appearance: Appearance,
    /// Whether this dataset is drawn.
    pub visible: bool,
    /// Names and colours of the labels, for label volumes.
    pub labels: Option<Arc<LabelTable>>,
    /// Clip planes and box (in the dataset's frame).
    pub clip: Clipping,
}

impl Dataset {
    pub fn new(volume: Arc<Volume>, appearance: Appearance) -> Self {
        Self { volume, appearance, visible: true, labels: None, clip: Clipping::default() }
    }
}

/// The volume the GPU draws for a dataset, when it had to be reduced to fit the device
/// (set by [`gpu_fit`]); the warning says so.
#[derive(Component, Clone)]
pub struct GpuVolume {
    pub volume: Arc<Volume>,
    pub warning: Option<String>,
}

/// The scene the renderers draw, rebuilt every frame from the datasets.
#[derive(Resource, Clone, Default)]
pub struct SceneRegions {
    pub scene: RenderScene,
    /// The dataset entity of each of `scene.volumes`.
    pub datasets: Vec<Entity>,
}

/// Lighting of the scene.
#[derive(Resource, Clone, Copy, Default, PartialEq)]
pub struct SceneLight(pub Light);

/// Ordering of the systems that build [`SceneRegions`].
#[derive(SystemSet, Debug, Clone, PartialEq, Eq, Hash)]
pub enum RegionSystems {
    /// Datasets become regions.
    Collect,
    /// Techniques add or change regions.
    Modify,
}

/// The part of a dataset volume's continuous voxel-index box that holds data, where it is
/// less than the whole (a bricked dataset's volume is its pyramid's coarse level, whose
/// box reaches past level 0's: `streaming::bricked::BrickedDataset::index_box`).
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct DataBox {
    pub lo: Vec3,
    pub hi: Vec3,
}

/// What [`collect_regions`] reads of each dataset.
type DatasetItems = (Entity, &'static Dataset, Option<&'static GpuVolume>, &'static GlobalTransform, Option<&'static DataBox>);

/// Collects one region per visible dataset (cut to its [`DataBox`]).
pub fn collect_regions(datasets: Query<DatasetItems>, light: Res<SceneLight>, mut out: ResMut<SceneRegions>) {
    let mut scene = RenderScene { light: light.0, ..Default::default() };
    let mut entities = Vec::new();
    for (entity, d, gpu, transform, data_box) in &datasets {
        if !d.visible {
            continue;
        }
        let volume = gpu.map(|g| g.volume.clone()).unwrap_or_else(|| d.volume.clone());
        let index = scene.volumes.len();
        let mut region = d.clip.region(&volume.grid, transform.affine(), index);
        if let Some(b) = data_box {
            region = region.cut_to_index_box(b.lo, b.hi);
        }
        scene.regions.push(region);
        scene.volumes.push(volume);
        scene.appearances.push(d.appearance.clone());
        entities.push(entity);
    }
    if out.scene != scene {
        out.scene = scene;
    }
    if out.datasets != entities {
        out.datasets = entities;
    }
}

/// Datasets and the scene regions, without any GPU.
pub struct DatasetPlugin;

impl Plugin for DatasetPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<SceneRegions>()
            .init_resource::<SceneLight>()
            .configure_sets(PostUpdate, (RegionSystems::Collect, RegionSystems::Modify).chain().after(TransformSystems::Propagate))
            .add_systems(PostUpdate, collect_regions.in_set(RegionSystems::Collect));
    }
}
