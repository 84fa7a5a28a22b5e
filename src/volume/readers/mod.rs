//! Readers, one module per file format, and the dispatch that picks one.
//!
//! Every reader returns a [`Volume`] in Focal's world frame (RAS millimetres, see
//! [`crate::volume::grid`]) or a [`ReadError`] naming the file and the problem. Readers
//! never trust a header: dimensions are checked against [`ReadOptions`] limits *before*
//! anything is allocated, uncompressed data sizes are checked against the file size, and
//! compressed streams are inflated into buffers that grow with the data actually found
//! (never pre-sized from the header), capped at the size the header promises.

pub mod common;
pub mod dat;
pub mod dicom;
pub mod label_table;
pub mod metaimage;
pub mod nifti;
pub mod nrrd;
pub mod ome_zarr;
pub mod raw;
pub mod vti;

use std::fs::File;
use std::io::Read;
use std::path::Path;

pub use common::{Problem, Progress, RawSpec, ReadError, ReadOptions, sidecars};

use super::{LabelVolume, Volume};

/// File formats Focal reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Nifti,
    Dicom,
    Nrrd,
    MetaImage,
    Vti,
    VolvisDat,
    OmeZarr,
    Raw,
}

impl Format {
    pub fn name(self) -> &'static str {
        match self {
            Format::Nifti => "NIfTI",
            Format::Dicom => "DICOM",
            Format::Nrrd => "NRRD",
            Format::MetaImage => "MetaImage",
            Format::Vti => "VTK ImageData",
            Format::VolvisDat => "volvis .dat",
            Format::OmeZarr => "OME-Zarr",
            Format::Raw => "raw",
        }
    }
}

/// File name extensions Focal opens (for file dialogs).
pub const EXTENSIONS: &[&str] = &["nii", "gz", "hdr", "img", "dcm", "nrrd", "nhdr", "mha", "mhd", "vti", "dat", "raw"];

/// Works out the format of `path` from its name, then from its first bytes.
pub fn detect(path: &Path, options: &ReadOptions) -> Result<Format, ReadError> {
    if ome_zarr::is_zarr(path) {
        return Ok(Format::OmeZarr);
    }
    if path.is_dir() {
        return Ok(Format::Dicom);
    }
    let name = path.file_name().map(|n| n.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
    let by_name = [
        (".nii", Format::Nifti),
        (".nii.gz", Format::Nifti),
        (".hdr", Format::Nifti),
        (".img", Format::Nifti),
        (".img.gz", Format::Nifti),
        (".nrrd", Format::Nrrd),
        (".nhdr", Format::Nrrd),
        (".mha", Format::MetaImage),
        (".mhd", Format::MetaImage),
        (".vti", Format::Vti),
        (".dat", Format::VolvisDat),
        (".dcm", Format::Dicom),
    ];
    if let Some((_, f)) = by_name.iter().find(|(ext, _)| name.ends_with(ext)) {
        return Ok(*f);
    }
    if options.raw.is_some() {
        return Ok(Format::Raw);
    }
    let mut head = [0u8; 132];
    let n = File::open(path).and_then(|mut f| read_up_to(&mut f, &mut head)).map_err(|e| ReadError::new(path, Problem::Io(e)))?;
    let head = &head[..n];
    let text = String::from_utf8_lossy(head);
    let sizeof_hdr = |b: &[u8]| b.len() >= 4 && matches!(i32::from_le_bytes([b[0], b[1], b[2], b[3]]), 348 | 540);
    let sizeof_hdr_be = |b: &[u8]| b.len() >= 4 && matches!(i32::from_be_bytes([b[0], b[1], b[2], b[3]]), 348 | 540);
    if text.starts_with("NRRD") {
        Ok(Format::Nrrd)
    } else if text.trim_start().starts_with("ObjectType") || text.trim_start().starts_with("NDims") {
        Ok(Format::MetaImage)
    } else if text.contains("<VTKFile") || text.trim_start().starts_with("<?xml") {
        Ok(Format::Vti)
    } else if head.len() >= 132 && &head[128..132] == b"DICM" {
        Ok(Format::Dicom)
    } else if sizeof_hdr(head) || sizeof_hdr_be(head) {
        Ok(Format::Nifti)
    } else {
        Err(ReadError::new(
            path,
            Problem::Unsupported(
                "unknown file format (expected NIfTI, DICOM, NRRD, MetaImage, VTK .vti, volvis .dat, \
                 an OME-Zarr folder, or raw data with dimensions given by --raw)"
                    .into(),
            ),
        ))
    }
}

fn read_up_to(f: &mut File, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match f.read(&mut buf[n..])? {
            0 => break,
            k => n += k,
        }
    }
    Ok(n)
}

/// Reads a volume from a file or DICOM folder, whatever its format.
pub fn read_volume(path: &Path, options: &ReadOptions) -> Result<Volume, ReadError> {
    match detect(path, options)? {
        Format::Nifti => nifti::read(path, options),
        Format::Dicom => dicom::read(path, options),
        Format::Nrrd => nrrd::read(path, options),
        Format::MetaImage => metaimage::read(path, options),
        Format::Vti => vti::read(path, options),
        Format::VolvisDat => dat::read(path, options),
        Format::OmeZarr => ome_zarr::read(path, options),
        Format::Raw => match &options.raw {
            Some(spec) => raw::read(path, spec, options),
            None => Err(ReadError::new(path, Problem::Malformed("raw data needs dimensions and a sample type".into()))),
        },
    }
}

/// Reads a label volume and its table: `table` if given, else the sidecar files found
/// beside the volume (`NAME.txt`, `NAME.lut`, `NAME.csv` for `NAME.nii.gz` and the
/// like), else the one the file carries (a DICOM segmentation's); ids without an entry
/// get generated colours.
pub fn read_label_volume(path: &Path, table: Option<&Path>, options: &ReadOptions) -> Result<LabelVolume, ReadError> {
    let mut volume = read_volume(path, options)?;
    let carried = volume.label_table.take();
    let table = match table {
        Some(t) => label_table::read(t)?,
        None => Some(label_table::read_sidecars(path)?).filter(|t| !t.is_empty()).or(carried).unwrap_or_default(),
    };
    LabelVolume::from_volume(volume, table).map_err(|e| ReadError::new(path, Problem::Values(e)))
}
