//! Focal: a focus+context volume explorer.
//!
//! The crate is organised by technique (see `../shared/DESIGN.md`, the README and
//! `docs/architecture.md`, which gives the order in which the folders may know each
//! other): [`volume`] holds the data model, readers and phantoms; [`transfer`] the
//! transfer functions; [`context`] context-preserving rendering's equations;
//! [`region`] what every renderer sees (geometry, cameras, looks and their scene form);
//! [`clip`] clip planes and boxes; [`twolevel`] two-level rendering of segmented data;
//! [`dataset`] the dataset entities that become regions and the volume views; [`lens`]
//! the magic volume lenses; [`reference`] the CPU reference renderer; [`windows`]
//! volumetric windows; [`explode`] exploded views; [`render`] the GPU ray caster that
//! packs and draws them; [`scene`] scene files; [`ui`] the desktop app.

pub mod clip;
pub mod context;
pub mod dataset;
pub mod explode;
pub mod interactive;
pub mod lens;
pub mod reference;
pub mod region;
pub mod render;
pub mod scene;
pub mod slices;
pub mod streaming;
pub mod transfer;
pub mod twolevel;
pub mod ui;
pub mod volume;
pub mod windows;

use bevy::app::{PluginGroup, PluginGroupBuilder};

/// Everything that needs no GPU: datasets, regions, scenes (for headless ECS tests
/// with `MinimalPlugins`).
pub struct FocalCorePlugins;

impl PluginGroup for FocalCorePlugins {
    fn build(self) -> PluginGroupBuilder {
        PluginGroupBuilder::start::<Self>()
            .add(dataset::DatasetPlugin)
            .add(lens::LensPlugin)
            .add(windows::VolumeWindowPlugin)
            .add(explode::ExplodePlugin)
            .add(streaming::StreamingPlugin)
            .add(interactive::InteractivePlugin)
    }
}

/// Everything: the core plus the GPU ray caster. Add after Bevy's `DefaultPlugins`.
pub struct FocalPlugins;

impl PluginGroup for FocalPlugins {
    fn build(self) -> PluginGroupBuilder {
        FocalCorePlugins.build().add(render::VolumeRenderPlugin)
    }
}
