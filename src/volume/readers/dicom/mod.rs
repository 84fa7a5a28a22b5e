//! DICOM: a folder of single-frame slices, one slice (its series is gathered from the
//! folder), or an enhanced multi-frame file, with the dicom-rs crates.
//!
//! - Every file first passes [`guard::check`], so corrupted lengths cannot make the
//!   parser allocate beyond the file size; then `dicom-object` parses it.
//! - Slices are grouped by Series Instance UID, image size and orientation; the largest
//!   group is read. They are sorted by their position along the slice normal
//!   `n = row × column` (Image Orientation Patient), and the slice axis is
//!   `(p_last − p_first) / (N − 1)`, so gantry-tilted series keep their shear; irregular
//!   gaps are reported.
//! - Multi-frame files take position, orientation, pixel spacing and rescale per frame
//!   from the Per-frame (else Shared) Functional Groups.
//! - Pixel Spacing is (row spacing, column spacing): the i axis (columns) is the row
//!   direction times Pixel Spacing[1]. Stored values are masked to Bits Stored and sign
//!   extended when Pixel Representation is 1; Rescale Slope/Intercept give real values
//!   (Hounsfield units for CT). Positions are LPS and are flipped into Focal's RAS world.
//! - Compressed transfer syntaxes (JPEG baseline and 8-bit extended, JPEG lossless, JPEG
//!   2000 through the pure-Rust `openjp2`, JPEG-LS through CharLS, RLE) are decoded by
//!   `dicom-pixeldata` (32-bit RLE by [`rle`]); a decoder panic on bad
//!   data is caught and reported, and a transfer syntax without a decoder is named.
//!   Deflated data sets are inflated by the parser (and bounded by the guard first).
//! - Segmentations and other 1-bit images are label volumes ([`segmentation`]).

mod file;
pub mod guard;
mod rle;
pub mod segmentation;
mod series;

use std::path::{Path, PathBuf};

use dicom_dictionary_std::tags;

use super::common::{Problem, ReadError, ReadOptions};
use crate::volume::Volume;
use file::{int, open, string};

pub use series::FrameGeometry;

/// Most files scanned in one folder.
const MAX_FILES: usize = 20_000;

/// Reads a DICOM folder, slice file or multi-frame file.
pub fn read(path: &Path, options: &ReadOptions) -> Result<Volume, ReadError> {
    if path.is_dir() {
        let files = list_files(path).map_err(|e| ReadError::new(path, Problem::Io(e)))?;
        return series::read_series(path, &files, options);
    }
    let object = open(path, options)?;
    if segmentation::applies(&object) {
        return segmentation::read(path, object, options);
    }
    let frames = int(&object, tags::NUMBER_OF_FRAMES).unwrap_or(1);
    if frames > 1 {
        return series::read_multiframe(path, object, options);
    }
    // One slice: gather its series from the folder it lives in.
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let files = list_files(dir).map_err(|e| ReadError::new(dir, Problem::Io(e)))?;
    let uid = string(&object, tags::SERIES_INSTANCE_UID);
    series::read_series_of(path, &files, uid.as_deref(), options)
}

/// Regular files under `dir` (two levels deep), sorted by name.
fn list_files(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    let mut stack = vec![(dir.to_path_buf(), 0)];
    while let Some((d, depth)) = stack.pop() {
        for entry in std::fs::read_dir(&d)? {
            let p = entry?.path();
            if p.is_dir() && depth < 2 {
                stack.push((p, depth + 1));
            } else if p.is_file() && out.len() < MAX_FILES {
                out.push(p);
            }
        }
    }
    out.sort();
    Ok(out)
}
