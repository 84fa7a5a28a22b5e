//! The components of a volumetric window: the parameters of Borst et al.'s windows.

use bevy::prelude::*;

use crate::region::Appearance;

/// A volumetric window. Its entity's `Transform` places the box (centre and rotation;
/// [`Attachment`] keeps it there); `size` is its extent in millimetres.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct VolumeWindow {
    pub size: Vec3,
    /// What it shows.
    pub contents: Vec<Content>,
    /// What region of the data it shows.
    pub source: Source,
    pub attachment: Attachment,
    /// Whether the box cuts the datasets of the main view away inside itself (its own
    /// contents are always cut to the box).
    pub clip: bool,
    pub automation: Automation,
}

impl VolumeWindow {
    /// A window of `size` showing `contents` in place (source: itself), fixed in the room.
    pub fn new(size: Vec3, contents: Vec<Content>) -> Self {
        VolumeWindow { size, contents, source: Source::Own, attachment: Attachment::Room, clip: false, automation: Automation::default() }
    }
}

/// One dataset shown in a window, with the window's own appearance of it (`None`: the
/// dataset's).
#[derive(Clone, Debug, PartialEq)]
pub struct Content {
    pub dataset: Entity,
    pub appearance: Option<Appearance>,
}

/// Where a window's data comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Source {
    /// The window's own box selects the data (a lens, a clip box).
    Own,
    /// Another entity, a [`SourceBox`], selects it (moving either updates the map).
    Box(Entity),
    /// A source box of this size centred on the 3D pointer ([`Pointer3d`]), turned like
    /// the window.
    Pointer { size: Vec3 },
}

/// A box that selects the data of a window; it has no contents of its own. Its entity's
/// `Transform` places it.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct SourceBox {
    pub size: Vec3,
}

/// The 3D pointer tool (its entity's `Transform` is the pointer's position).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct Pointer3d;

/// What a window stays fixed to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Attachment {
    /// Fixed in the world: datasets move past it.
    Room,
    /// Fixed relative to the [`Viewer`] (like a heads-up view): `offset` is its pose in
    /// the viewer's frame.
    User { offset: Transform },
    /// Moves with a dataset: `offset` is its pose in the dataset's frame.
    Dataset { dataset: Entity, offset: Transform },
}

/// The viewpoint that user-attached windows follow (the app's camera).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct Viewer;

/// Automatic settings of the source.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Automation {
    /// Fit the contents into the box (the source box becomes their bounding box).
    pub fit: Option<Fit>,
    /// Keep the content's orientation coupled to another view.
    pub orientation: Orientation,
}

/// How [`Automation::fit`] scales.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fit {
    /// One factor for all axes: all of the content shows, undistorted.
    Uniform,
    /// Each axis filled.
    PerAxis,
}

/// Orientation coupling of a window's content.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Orientation {
    /// The source box keeps its own orientation (the content turns with the window).
    #[default]
    Free,
    /// The content keeps the orientation it has in the main view.
    MainView,
    /// The content keeps the orientation of another window's content.
    Window(Entity),
}
