//! Slice views: the dataset's voxels in the three planes radiologists read (axial,
//! coronal, sagittal; X, Y, Z for data without a patient frame), at the voxels' own
//! resolution, through a window of values (window/level), with label volumes in their
//! colours or laid over.
//!
//! - [`plane`]: which index plane a view shows and how it lies on the screen
//!   (radiological convention);
//! - [`window_level`]: the DICOM linear VOI function, CT presets, auto from the
//!   histogram;
//! - [`image`]: a slice's voxels (from memory or a streamed source) and its picture;
//! - [`crosshair`]: the point the views share, the slice and pixel that show it;
//! - [`outline`]: where a box (a volumetric window) cuts a slice;
//! - [`lens_outline`]: where a lens (the camera's rays through its outlines) cuts one;
//! - [`ruler`]: distance rulers between two points of a dataset, saved with the scene.
//!
//! `focal render INPUT --slice axial[:INDEX]` writes one slice view as a PNG.

pub mod crosshair;
pub mod image;
pub mod lens_outline;
pub mod outline;
pub mod plane;
pub mod ruler;
pub mod window_level;

pub use image::{Slice, overlay_labels, to_image};
pub use plane::{Orientation, SliceAxes};
pub use window_level::{CT_PRESETS, WindowLevel};
