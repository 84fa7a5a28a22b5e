//! The app's state shared by its panels and tools: settings and panel flags
//! ([`AppState`]), the main camera's marker, the shortcut list, what the scene shows.

use std::path::PathBuf;

use bevy::prelude::*;

use super::tf_editor;
use crate::dataset::{SceneRegions, VolumeView};

/// Keyboard shortcuts, as listed in the help panel.
pub const SHORTCUTS: &[(&str, &str)] = &[
    ("Left drag", "orbit"),
    ("Right / middle drag", "pan"),
    ("Wheel", "zoom"),
    ("Drag a lens", "move it (its rim: radius; its dashed ring: border)"),
    ("Wheel over a lens", "magnification (rate, field of view)"),
    ("Delete / Esc", "remove the selected lens / stop drawing"),
    ("Drag a clip handle", "move the clip plane along its normal (Clipping panel adds planes)"),
    ("Hover a window", "focus it: the panels edit its look and parameters"),
    ("Ctrl+drag a window / source box / dataset", "move it in the plane facing you"),
    ("Drag a window corner", "resize the focused window (the opposite corner stays)"),
    ("Right-click a window", "its parameter menu"),
    ("T", "3D pointer on / off (follows the cursor; wheel: depth; G: onto the surface)"),
    ("Space / Shift+Space / Backspace", "pointer: place a marker / move the nearest / delete it"),
    ("E", "exploded view panel (splitters: click a part; line: drag; Esc: stop)"),
    ("V", "fly-through on / off (drag: look; arrows, Page Up / Down, wheel: move)"),
    ("Double-click", "centre on the point under the cursor"),
    ("R", "reset the camera"),
    ("1 … 6", "view from front, back, left, right, top, bottom"),
    ("7", "oblique view"),
    ("P", "perspective / orthographic"),
    ("M", "next rendering mode"),
    ("[ / ]", "context-preserving κt down / up (mode: context-preserving)"),
    ("Ctrl+O", "open a file"),
    ("Ctrl+S", "save the scene"),
    ("F12 or S", "save a screenshot (out/)"),
    ("F", "show the frame rate"),
    ("L", "slice views on / off (click: crosshair; wheel: slice; right drag: window/level)"),
    ("Shift+click twice", "a distance ruler, on the surface in the 3D view or in a slice (Esc: cancel)"),
    ("H or F1", "this help"),
];

/// The app's own settings and panel state.
#[derive(Resource)]
pub struct AppState {
    pub show_help: bool,
    pub show_fps: bool,
    /// The exploded view's panel.
    pub show_explode: bool,
    pub background: [f32; 3],
    pub view: VolumeView,
    /// The dataset the panels edit (index among the datasets).
    pub selected: usize,
    pub editor: tf_editor::EditorState,
    pub dialog: egui_file_dialog::FileDialog,
    pub dialog_purpose: DialogPurpose,
    /// Last screenshot written, to report it.
    pub last_screenshot: Option<PathBuf>,
    /// Automation: write a screenshot after this many frames, then quit.
    pub screenshot_and_exit: Option<(u32, PathBuf)>,
    pub frames: u32,
}

/// What the open file dialog is for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DialogPurpose {
    #[default]
    Open,
    SaveScene,
}

impl Default for AppState {
    fn default() -> Self {
        Self {
            show_help: false,
            show_fps: false,
            show_explode: false,
            background: [0.0; 3],
            view: VolumeView::default(),
            selected: 0,
            editor: Default::default(),
            dialog: egui_file_dialog::FileDialog::new(),
            dialog_purpose: DialogPurpose::Open,
            last_screenshot: None,
            screenshot_and_exit: None,
            frames: 0,
        }
    }
}

/// Marks the 3D camera of the app.
#[derive(Component)]
pub struct MainCamera;

/// The default scene (the head phantom), embedded.
pub fn default_scene() -> crate::scene::SceneFile {
    const TEXT: &str = include_str!("../../assets/scenes/default.ron");
    crate::scene::SceneFile::parse(TEXT, "assets/scenes/default.ron")
        .unwrap_or_else(|e| unreachable!("the embedded default scene parses: {e}"))
}

/// World bounds of what the scene shows (its regions' volumes, as placed).
pub fn scene_bounds(regions: &SceneRegions) -> (Vec3, Vec3) {
    let s = &regions.scene;
    let mut out: Option<(Vec3, Vec3)> = None;
    for r in &s.regions {
        let (Some(v), Some(a)) = (s.volumes.get(r.volume), s.appearances.get(r.appearance)) else { continue };
        let (lo, hi) = a.visible_bounds(v).unwrap_or_else(|| v.grid.world_bounds());
        // The region map takes world to voxel; with the grid's own map it gives the
        // dataset's placement.
        let own_to_world = r.world_to_voxel.inverse() * v.grid.world_to_index();
        for c in 0..8 {
            let p = own_to_world.transform_point3(Vec3::new(
                if c & 1 == 0 { lo.x } else { hi.x },
                if c & 2 == 0 { lo.y } else { hi.y },
                if c & 4 == 0 { lo.z } else { hi.z },
            ));
            out = Some(out.map_or((p, p), |(a, b)| (a.min(p), b.max(p))));
        }
    }
    out.unwrap_or((Vec3::splat(-100.0), Vec3::splat(100.0)))
}
