//! The exploded view's tools in the app: which viewport tool is active and what the
//! panel has chosen (selection, grid, joint, brush), shared by the panel, its selection
//! section and the viewport overlay.

use std::collections::BTreeSet;

use bevy::prelude::*;

use crate::explode::JointKind;
use crate::explode::paint::Brush;
use crate::explode::splitters::ScreenAxis;

/// What a click (or drag) in the viewport does.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Tool {
    #[default]
    None,
    /// Axis splitter, the plane holding the screen's horizontal or vertical.
    Axis(ScreenAxis),
    Depth,
    /// Drag a segment.
    Line,
    /// Pick a joint's anchor (and its part).
    Anchor,
    /// Paint the selection with the brush (drag; Shift: the other way).
    Paint,
}

/// A joint's axis, chosen in the panel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AxisChoice {
    /// The view direction (a door that turns towards you about a vertical screen axis:
    /// use screen vertical).
    View,
    ScreenHorizontal,
    #[default]
    ScreenVertical,
    X,
    Y,
    Z,
}

/// The panel's state.
#[derive(Resource)]
pub struct ExplodeUi {
    pub tool: Tool,
    pub line_start: Option<Vec2>,
    /// The selection: labels of this dataset (index in entity order) or a value range.
    pub use_labels: bool,
    pub label_dataset: usize,
    pub label_ids: BTreeSet<u32>,
    pub range: (f64, f64),
    pub grid: (u32, u32, u32),
    pub joint_kind: JointKind,
    /// The joint's other end: `None` the world, else a part index.
    pub joint_to: Option<usize>,
    pub joint_axis: AxisChoice,
    pub joint_limits: Option<(f32, f32)>,
    /// The selection brush, and where its last dab was (viewport pixels).
    pub brush: Brush,
    pub last_dab: Option<Vec2>,
}

impl Default for ExplodeUi {
    fn default() -> Self {
        ExplodeUi {
            tool: Tool::None,
            line_start: None,
            use_labels: true,
            label_dataset: 1,
            label_ids: BTreeSet::new(),
            range: (300.0, 3000.0),
            grid: (2, 1, 2),
            joint_kind: JointKind::Hinge,
            joint_to: None,
            joint_axis: AxisChoice::ScreenVertical,
            joint_limits: None,
            brush: Brush::default(),
            last_dab: None,
        }
    }
}
