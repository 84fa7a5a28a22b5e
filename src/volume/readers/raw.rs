//! Headerless raw volumes, described by a [`RawSpec`] (its syntax:
//! [`super::common::raw_layout`]).

use std::path::Path;

use super::common::{RawSpec, ReadError, ReadOptions, read_raw};
use crate::volume::Volume;

/// Reads a raw file (optionally gzip-compressed when it ends in `.gz`).
pub fn read(path: &Path, spec: &RawSpec, options: &ReadOptions) -> Result<Volume, ReadError> {
    read_raw(path, spec, options, "raw", Vec::new())
}
