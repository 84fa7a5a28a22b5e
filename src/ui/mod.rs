//! The desktop app: egui panels, the orbit camera, loading, shortcuts.
//!
//! `focal [FILE]` opens a window on the built-in head phantom (or the file, DICOM folder
//! or scene given). Files open from the Open dialogs, by drag and drop, or on the
//! command line; loading runs in the background with a progress bar and a failed load
//! leaves the current data in place. See [`SHORTCUTS`] for the keys.
//!
//! [`app`] is the plugin and the app's own systems; [`state`] what the panels share;
//! each panel, gizmo and viewport tool has its file.

pub mod app;
pub mod camera_panel;
pub mod clip_gizmo;
pub mod clip_panel;
pub mod explode_overlay;
pub mod explode_panel;
pub mod explode_selection;
pub mod explode_tools;
pub mod gpu_status;
pub mod lenses;
pub mod loading;
pub mod movie;
pub mod objects_panel;
pub mod orbit;
pub mod panels;
pub mod recovery;
pub mod rulers;
pub mod settings;
pub mod slice_views;
pub mod state;
pub mod streamed_slices;
pub mod streaming_status;
pub mod tf_editor;
pub mod under_cursor;
pub mod viewport;
pub mod window_tools;
pub mod windows_panel;

pub use app::{FocalAppPlugin, RunOptions, run};
pub use state::{AppState, DialogPurpose, MainCamera, SHORTCUTS};
