//! `.dat` volumes, in the two conventions found with the classic volvis data sets.
//!
//! - **Text header** (volvis.org): a small text file of `Key: value` lines naming the raw
//!   file and its layout, e.g.
//!   ```text
//!   ObjectFileName: engine.raw
//!   Resolution:     256 256 128
//!   SliceThickness: 1 1 1
//!   Format:         UCHAR
//!   ```
//!   `Format` is `UCHAR`, `USHORT`, `SHORT`, `FLOAT` (and the other type names of
//!   [`super::common::parse_sample_type`]); data is little-endian.
//! - **Binary** (TU Wien): three little-endian `u16` dimensions followed by `u16` voxels
//!   (12-bit CT values), recognised when the file size is exactly `6 + 2·x·y·z`.

use std::io::Read;
use std::path::Path;

use glam::{UVec3, Vec3};

use super::common::{Problem, RawSpec, ReadError, ReadOptions, file_len, open, parse_n, parse_sample_type, read_raw, read_text};
use crate::volume::Volume;
use crate::volume::encode::{ByteOrder, SampleType};

/// Reads a `.dat` volume of either convention.
pub fn read(path: &Path, options: &ReadOptions) -> Result<Volume, ReadError> {
    let fail = |p: Problem| ReadError::new(path, p);
    let len = file_len(path)?;
    let mut head = [0u8; 6];
    open(path)?.read_exact(&mut head).map_err(|_| fail(Problem::Truncated(format!("{len} bytes is too short for a .dat file"))))?;
    let d = [0, 2, 4].map(|i| u16::from_le_bytes([head[i], head[i + 1]]) as u64);
    if d.iter().all(|&x| x > 0) && len == 6 + 2 * d[0] * d[1] * d[2] {
        let spec = RawSpec {
            dims: UVec3::new(d[0] as u32, d[1] as u32, d[2] as u32),
            sample: SampleType::U16,
            order: ByteOrder::Little,
            spacing: Vec3::ONE,
            skip: 6,
        };
        return read_raw(path, &spec, options, "TU Wien .dat", vec![("layout".into(), "binary header: 3 × u16 dimensions".into())]);
    }
    // The text convention first; where that fails on a file whose first bytes are not
    // text, a binary header that does not match the file's length (its claim checked
    // first: a trillion voxels is too large, not merely truncated).
    let parsed = read_text(path, 1 << 16).and_then(|text| parse_text(&text).map_err(fail));
    let (file, spec) = match parsed {
        Ok(parsed) => parsed,
        Err(_) if d.iter().all(|&x| x > 0) && head.iter().any(|&b| b == 0 || b > 127) => {
            options.check_size(d, 2).map_err(fail)?;
            let needed = 6 + 2 * d[0] * d[1] * d[2];
            let text = format!(
                "the binary header gives {}×{}×{} 16-bit voxels ({needed} bytes in all), the file has {len} bytes",
                d[0], d[1], d[2]
            );
            return Err(fail(if len < needed { Problem::Truncated(text) } else { Problem::Malformed(text) }));
        }
        Err(e) => return Err(e),
    };
    // The header's claim is checked against the limits here, so the error names it.
    options.check_size([spec.dims.x as u64, spec.dims.y as u64, spec.dims.z as u64], spec.sample.size()).map_err(fail)?;
    let raw = path.parent().unwrap_or(Path::new(".")).join(file.trim());
    if !raw.is_file() {
        return Err(fail(Problem::Malformed(format!("ObjectFileName '{}' not found beside the .dat file", file.trim()))));
    }
    read_raw(&raw, &spec, options, "volvis .dat + raw", vec![("header".into(), path.display().to_string())])
}

/// Parses the text convention into the raw file name and its layout.
fn parse_text(text: &str) -> Result<(String, RawSpec), Problem> {
    let mut file = None;
    let mut dims = None;
    let mut spacing = Vec3::ONE;
    let mut sample = None;
    // (A byte-order mark, as some Windows editors save, is no part of the first key.)
    for line in text.trim_start_matches('\u{feff}').lines() {
        let Some((k, v)) = line.split_once(':') else { continue };
        match k.trim().to_ascii_lowercase().as_str() {
            "objectfilename" => file = Some(v.trim().to_string()),
            "resolution" => {
                let r: Vec<u32> = parse_n("Resolution", v, 3)?;
                dims = Some(UVec3::new(r[0], r[1], r[2]));
            }
            "slicethickness" => {
                let s: Vec<f32> = parse_n("SliceThickness", v, 3)?;
                spacing = Vec3::new(s[0], s[1], s[2]);
            }
            "format" => sample = Some(parse_sample_type(v.trim()).ok_or_else(|| Problem::Unsupported(format!("Format {}", v.trim())))?),
            _ => {}
        }
    }
    let missing = |f: &str| Problem::NotFormat { format: "volvis .dat", detail: format!("no {f} line") };
    let file = file.ok_or_else(|| missing("ObjectFileName"))?;
    let dims = dims.ok_or_else(|| missing("Resolution"))?;
    let sample = sample.ok_or_else(|| missing("Format"))?;
    Ok((file, RawSpec { dims, sample, order: ByteOrder::Little, spacing, skip: 0 }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_header_fields() {
        let (f, s) = parse_text(
            "ObjectFileName: engine.raw\nTaggedFileName: ---\nResolution: 256 256 128\nSliceThickness: 1 1 1.5\nFormat: USHORT\n",
        )
        .unwrap();
        assert_eq!(f, "engine.raw");
        assert_eq!(s.dims, UVec3::new(256, 256, 128));
        assert_eq!(s.spacing.z, 1.5);
        assert_eq!(s.sample, SampleType::U16);
        assert!(parse_text("Resolution: 1 2 3\n").is_err());
        assert!(parse_text("ObjectFileName: a\nResolution: 1 2\nFormat: UCHAR").is_err());
    }
}
