//! Headerless raw volumes, described by a [`RawSpec`] (from the command line or a
//! `.dat` file).
//!
//! Spec syntax (command line `--raw`): `DIMS:TYPE[:le|be][:s=SPACING][:skip=BYTES]`, for
//! example `256x256x128:uint8` or `512x512x300:int16:be:s=0.5x0.5x1:skip=1024`. A skip
//! of `-1` reads the data from the end of the file (a header of unknown size before it).

use std::path::Path;

use glam::{UVec3, Vec3};

use super::common::{Compression, Problem, ReadError, ReadOptions, decoder, encode, file_len, open_buffered, read_exact_bounded, skip};
use super::nifti::volume_name;
use crate::volume::encode::{ByteOrder, SampleType};
use crate::volume::{Grid, Source, Volume};

/// Layout of a raw file.
#[derive(Clone, Debug, PartialEq)]
pub struct RawSpec {
    pub dims: UVec3,
    pub sample: SampleType,
    pub order: ByteOrder,
    pub spacing: Vec3,
    /// Bytes before the data; `-1` = the data ends the file.
    pub skip: i64,
}

/// Parses a sample type name (`uint8`, `uchar`, `int16`, `short`, `float32`, …).
pub fn parse_sample_type(name: &str) -> Option<SampleType> {
    Some(match name.to_ascii_lowercase().as_str() {
        "uint8" | "u8" | "uchar" | "byte" => SampleType::U8,
        "int8" | "i8" | "char" => SampleType::I8,
        "uint16" | "u16" | "ushort" => SampleType::U16,
        "int16" | "i16" | "short" => SampleType::I16,
        "uint32" | "u32" | "uint" => SampleType::U32,
        "int32" | "i32" | "int" => SampleType::I32,
        "uint64" | "u64" => SampleType::U64,
        "int64" | "i64" => SampleType::I64,
        "float32" | "f32" | "float" => SampleType::F32,
        "float64" | "f64" | "double" => SampleType::F64,
        _ => return None,
    })
}

fn parse_triple<T: std::str::FromStr + Copy>(s: &str) -> Option<[T; 3]> {
    let v: Vec<T> = s.split(['x', 'X', ',']).map(|p| p.trim().parse().ok()).collect::<Option<_>>()?;
    (v.len() == 3).then(|| [v[0], v[1], v[2]])
}

impl std::str::FromStr for RawSpec {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let mut parts = s.split(':');
        let dims = parts.next().and_then(parse_triple::<u32>).ok_or_else(|| format!("'{s}': expected DIMS like 256x256x128 first"))?;
        let sample = parts
            .next()
            .and_then(parse_sample_type)
            .ok_or_else(|| format!("'{s}': expected a sample type (uint8, int16, float32, …) after the dimensions"))?;
        let mut spec = RawSpec { dims: UVec3::from_array(dims), sample, order: ByteOrder::Little, spacing: Vec3::ONE, skip: 0 };
        for p in parts {
            match p {
                "le" | "little" => spec.order = ByteOrder::Little,
                "be" | "big" => spec.order = ByteOrder::Big,
                _ if p.starts_with("s=") => {
                    spec.spacing =
                        Vec3::from_array(parse_triple::<f32>(&p[2..]).ok_or_else(|| format!("'{p}': spacing must look like s=0.5x0.5x1"))?);
                }
                _ if p.starts_with("skip=") => spec.skip = p[5..].parse().map_err(|_| format!("'{p}': skip must be a byte count"))?,
                _ => return Err(format!("'{p}' is not le, be, s=SPACING or skip=BYTES")),
            }
        }
        Ok(spec)
    }
}

/// Reads a raw file (optionally gzip-compressed when it ends in `.gz`).
pub fn read(path: &Path, spec: &RawSpec, options: &ReadOptions) -> Result<Volume, ReadError> {
    read_as(path, spec, options, "raw", Vec::new())
}

/// Reads raw data; `format` and `details` describe where the spec came from.
pub fn read_as(
    path: &Path,
    spec: &RawSpec,
    options: &ReadOptions,
    format: &str,
    details: Vec<(String, String)>,
) -> Result<Volume, ReadError> {
    let fail = |p: Problem| ReadError::new(path, p);
    let (dims, len) = options.check_size(spec.dims.to_array().map(u64::from), spec.sample.size()).map_err(fail)?;
    let gz = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("gz"));
    let mut skip_bytes = spec.skip;
    if !gz {
        let have = file_len(path)?;
        if skip_bytes == -1 {
            skip_bytes = have as i64 - len as i64;
        }
        if skip_bytes < 0 || have < skip_bytes as u64 + len as u64 {
            return Err(fail(Problem::Truncated(format!(
                "file has {have} bytes, {} needed for {} {} samples",
                len as i64 + spec.skip.max(0),
                spec.dims.x as u64 * spec.dims.y as u64 * spec.dims.z as u64,
                spec.sample.name()
            ))));
        }
    } else if skip_bytes < 0 {
        return Err(fail(Problem::Malformed("skip -1 needs an uncompressed file".into())));
    }
    let mut stream = decoder(open_buffered(path, options)?, if gz { Compression::Gzip } else { Compression::None });
    skip(&mut stream, skip_bytes as u64).map_err(fail)?;
    let bytes = read_exact_bounded(stream, len).map_err(fail)?;
    let encoded = encode(bytes, spec.sample, spec.order).map_err(fail)?;
    let spacing = spec.spacing;
    if !spacing.is_finite() || spacing.min_element() <= 0.0 {
        return Err(fail(Problem::Malformed(format!("spacing {spacing} is not positive"))));
    }
    let grid = Grid::centered(dims, spacing);
    let source = Source { format: format.into(), path: Some(path.to_path_buf()), sample_type: spec.sample.name().into(), details };
    Volume::new(volume_name(path), grid, encoded.voxels, encoded.map, source).map_err(|e| fail(Problem::Malformed(e)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spec_syntax() {
        let s: RawSpec = "512x512x300:int16:be:s=0.5x0.5x1:skip=1024".parse().unwrap();
        assert_eq!(s.dims, UVec3::new(512, 512, 300));
        assert_eq!(s.sample, SampleType::I16);
        assert_eq!(s.order, ByteOrder::Big);
        assert_eq!(s.spacing, Vec3::new(0.5, 0.5, 1.0));
        assert_eq!(s.skip, 1024);
        assert!("256x256:uint8".parse::<RawSpec>().is_err());
        assert!("256x256x2:complex".parse::<RawSpec>().is_err());
        assert!("2x2x2:uint8:zz".parse::<RawSpec>().is_err());
    }
}
