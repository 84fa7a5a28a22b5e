//! Volumetric windows (Borst, Baiyya, Best, Kinsland, "Volumetric Windows: Application
//! to Interpretation of Scientific Data, Shader-Based Rendering Method, and
//! Performance Evaluation"): 3D boxes holding 3D content, a 3D analogue of 2D windows.
//!
//! A window ([`components::VolumeWindow`]) is an entity with the paper's parameters:
//! *contents* (datasets, each with the window's own appearance), *source* (its own box,
//! another box, or a box following the 3D pointer), *attachment* (room, user or a
//! dataset), *clip* (whether it cuts the main view away inside itself) and
//! *automation* (fit, orientation coupling). In the region model (DESIGN.md) a window
//! is one region per content: its box, with the map that sends the window onto its
//! source ([`mapping`]), so it magnifies a smaller source and minifies a larger one
//! (a world-in-miniature). A clip window cuts its box out of the datasets' regions as a
//! hole (`region::Region::holes`).
//!
//! [`boxes`], [`mapping`], [`regions`], [`interaction`] (focus, dragging, resizing) and
//! [`markers`] (where markers and the 3D pointer show) are pure; [`systems`] moves
//! attached windows, places them every frame, keeps the focus and the markers' views,
//! and places, moves and deletes markers with the pointer.

pub mod boxes;
pub mod components;
pub mod frames;
pub mod interaction;
pub mod mapping;
pub mod markers;
pub mod regions;
pub mod spec;
pub mod systems;

use bevy::prelude::*;

pub use components::{Attachment, Automation, Content, Fit, Orientation, Pointer3d, Source, SourceBox, Viewer, VolumeWindow};

use crate::dataset::RegionSystems;

/// Window systems (no GPU needed).
pub struct VolumeWindowPlugin;

impl Plugin for VolumeWindowPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(
            PostUpdate,
            (
                systems::attach_windows.after(TransformSystems::Propagate).before(RegionSystems::Modify),
                systems::window_regions.in_set(RegionSystems::Modify),
                (systems::update_focus, systems::propagate_markers).after(RegionSystems::Modify),
            ),
        )
        .init_resource::<markers::PlacedWindows>()
        .init_resource::<systems::CursorRay>()
        .init_resource::<systems::WindowFocus>();
    }
}
