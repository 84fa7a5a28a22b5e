//! MetaImage (`.mha` with local data, `.mhd` with a separate data file), ITK's format.
//!
//! Fields are `Key = Value` lines ending with `ElementDataFile`, after which local data
//! follows. Supported: `NDims` 2 or 3, `DimSize`, `ElementSpacing`/`ElementSize`,
//! `Offset`/`Position`/`Origin`, `TransformMatrix`/`Rotation`/`Orientation` (ITK reads
//! each group of three numbers as the direction of one index axis), the `MET_*` scalar
//! types (with `ElementNumberOfChannels` > 1 the first channel is shown), byte order,
//! `CompressedData` (zlib), `HeaderSize` (`-1` = data at the end of the file),
//! `ElementDataFile` as `LOCAL`, a file name, `LIST` or a `%d` pattern. Positions are
//! in ITK's LPS space and are flipped into Focal's RAS world.

use std::io::{BufRead, Read};
use std::path::{Path, PathBuf};

use glam::{Mat3, Vec3};

use super::common::{
    Compression, Problem, ReadError, ReadOptions, decoder, encode, file_len, first_component, open_buffered, parse_numbers, pattern_files,
    read_exact_bounded, skip, volume_name,
};
use crate::volume::encode::{ByteOrder, SampleType, encode_values};
use crate::volume::grid::{lps_axes_to_ras, lps_to_ras};
use crate::volume::{Grid, Source, Volume};

const MAX_HEADER: u64 = 1 << 20;

struct Header {
    fields: Vec<(String, String)>,
}

impl Header {
    fn get(&self, key: &str) -> Option<&str> {
        self.fields.iter().find(|(k, _)| k.eq_ignore_ascii_case(key)).map(|(_, v)| v.as_str())
    }

    fn any(&self, keys: &[&str]) -> Option<&str> {
        keys.iter().find_map(|k| self.get(k))
    }

    fn flag(&self, keys: &[&str]) -> bool {
        self.any(keys).is_some_and(|v| v.eq_ignore_ascii_case("true") || v == "1")
    }
}

fn parse_header(reader: &mut impl BufRead) -> Result<Header, Problem> {
    let mut fields = Vec::new();
    let mut consumed = 0u64;
    let mut line = Vec::new();
    loop {
        line.clear();
        let n = reader.by_ref().take(MAX_HEADER).read_until(b'\n', &mut line)?;
        consumed += n as u64;
        if n == 0 || consumed > MAX_HEADER {
            return Err(Problem::Malformed("no ElementDataFile field ends the header".into()));
        }
        let text = String::from_utf8_lossy(&line);
        let text = text.trim();
        if text.is_empty() || text.starts_with('#') {
            continue;
        }
        let Some((k, v)) = text.split_once('=') else {
            if fields.is_empty() {
                return Err(Problem::NotFormat { format: "MetaImage", detail: "first line is not 'Key = Value'".into() });
            }
            return Err(Problem::Malformed(format!("line '{}' is not 'Key = Value'", text.chars().take(60).collect::<String>())));
        };
        let (k, v) = (k.trim().to_string(), v.trim().to_string());
        let last = k.eq_ignore_ascii_case("ElementDataFile");
        fields.push((k, v));
        if last {
            return Ok(Header { fields });
        }
    }
}

fn sample_type(name: &str) -> Result<SampleType, Problem> {
    let base = name.trim().to_ascii_uppercase();
    let base = base.trim_end_matches("_ARRAY");
    Ok(match base {
        "MET_CHAR" => SampleType::I8,
        "MET_UCHAR" => SampleType::U8,
        "MET_SHORT" => SampleType::I16,
        "MET_USHORT" => SampleType::U16,
        "MET_INT" | "MET_LONG" => SampleType::I32,
        "MET_UINT" | "MET_ULONG" => SampleType::U32,
        "MET_LONG_LONG" => SampleType::I64,
        "MET_ULONG_LONG" => SampleType::U64,
        "MET_FLOAT" => SampleType::F32,
        "MET_DOUBLE" => SampleType::F64,
        other => return Err(Problem::Unsupported(format!("ElementType {other}"))),
    })
}

/// Reads a MetaImage file.
pub fn read(path: &Path, options: &ReadOptions) -> Result<Volume, ReadError> {
    let fail = |p: Problem| ReadError::new(path, p);
    let mut reader = open_buffered(path, options)?;
    let h = parse_header(&mut reader).map_err(fail)?;
    if let Some(t) = h.get("ObjectType")
        && !t.eq_ignore_ascii_case("Image")
    {
        return Err(fail(Problem::Unsupported(format!("ObjectType {t} (only Image)"))));
    }
    let ndims: usize = h
        .get("NDims")
        .ok_or_else(|| fail(Problem::Malformed("NDims is missing".into())))?
        .parse()
        .map_err(|_| fail(Problem::Malformed("NDims is not a number".into())))?;
    if !(2..=3).contains(&ndims) {
        return Err(fail(Problem::Unsupported(format!("NDims = {ndims} (Focal reads 2-D and 3-D images)"))));
    }
    let size: Vec<u64> =
        parse_numbers("DimSize", h.get("DimSize").ok_or_else(|| fail(Problem::Malformed("DimSize is missing".into())))?).map_err(fail)?;
    if size.len() != ndims {
        return Err(fail(Problem::Malformed(format!("DimSize has {} values for NDims = {ndims}", size.len()))));
    }
    let ty = sample_type(h.get("ElementType").ok_or_else(|| fail(Problem::Malformed("ElementType is missing".into())))?).map_err(fail)?;
    let channels: u64 = h
        .get("ElementNumberOfChannels")
        .map(|c| c.parse().map_err(|_| fail(Problem::Malformed("ElementNumberOfChannels is not a number".into()))))
        .transpose()?
        .unwrap_or(1)
        .max(1);
    let dims3 = [size[0], size[1], size.get(2).copied().unwrap_or(1)];
    let (dims, _) = options.check_size(dims3, ty.size()).map_err(fail)?;
    let (_, len) = options.check_size([dims3[0] * channels, dims3[1], dims3[2]], ty.size()).map_err(fail)?;

    let vec3 = |keys: &[&str], default: Vec3| -> Result<Vec3, ReadError> {
        match h.any(keys) {
            None => Ok(default),
            Some(t) => {
                let v: Vec<f32> = parse_numbers(keys[0], t).map_err(fail)?;
                if v.len() < ndims || v.iter().any(|x| !x.is_finite()) {
                    return Err(fail(Problem::Malformed(format!("{} = '{t}' needs {ndims} finite numbers", keys[0]))));
                }
                Ok(Vec3::new(v[0], v[1], v.get(2).copied().unwrap_or(default.z)))
            }
        }
    };
    let spacing = vec3(&["ElementSpacing", "ElementSize"], Vec3::ONE)?;
    let offset = vec3(&["Offset", "Position", "Origin"], Vec3::ZERO)?;
    let direction = match h.any(&["TransformMatrix", "Rotation", "Orientation"]) {
        None => Mat3::IDENTITY,
        Some(t) => {
            let m: Vec<f32> = parse_numbers("TransformMatrix", t).map_err(fail)?;
            match (ndims, m.len()) {
                (3, 9) => Mat3::from_cols_slice(&m),
                (2, 4) => Mat3::from_cols(Vec3::new(m[0], m[1], 0.0), Vec3::new(m[2], m[3], 0.0), Vec3::Z),
                _ => return Err(fail(Problem::Malformed(format!("TransformMatrix has {} values for NDims = {ndims}", m.len())))),
            }
        }
    };
    let order = if h.flag(&["ElementByteOrderMSB", "BinaryDataByteOrderMSB"]) { ByteOrder::Big } else { ByteOrder::Little };
    let compressed = h.flag(&["CompressedData"]);
    let binary = h.get("BinaryData").is_none_or(|v| v.eq_ignore_ascii_case("true"));
    let header_size: i64 = h
        .get("HeaderSize")
        .map(|s| s.parse().map_err(|_| fail(Problem::Malformed("HeaderSize is not a number".into()))))
        .transpose()?
        .unwrap_or(0);

    let data_file = h.get("ElementDataFile").unwrap_or("LOCAL").to_string();
    let files = data_files(path, &data_file, &mut reader).map_err(fail)?;
    let mut bytes = Vec::new();
    let per_file = len / files.len().max(1);
    for (i, f) in files.iter().enumerate() {
        let want = if i + 1 == files.len() { len - per_file * i } else { per_file };
        let chunk = match f {
            None => read_stream(path, &mut reader, compressed, binary, header_size, want, ty)?,
            Some(p) => {
                let mut r = open_buffered(p, options)?;
                let skip_bytes =
                    if header_size == -1 && !compressed { file_len(p)?.saturating_sub(want as u64) as i64 } else { header_size };
                read_stream(p, &mut r, compressed, binary, skip_bytes, want, ty)?
            }
        };
        if bytes.is_empty() { bytes = chunk } else { bytes.extend_from_slice(&chunk) }
    }
    let encoded = if binary {
        encode(bytes, ty, order).map_err(fail)?
    } else {
        let values: Vec<f64> = parse_numbers("ASCII data", &String::from_utf8_lossy(&bytes)).map_err(fail)?;
        let n = len / ty.size();
        if values.len() < n {
            return Err(fail(Problem::Truncated(format!("{} of {n} values present", values.len()))));
        }
        encode_values(&values[..n], ty).map_err(|e| fail(Problem::Values(e)))?
    };
    let encoded = if channels > 1 { first_component(encoded, channels as usize) } else { encoded };

    let axes = lps_axes_to_ras(direction * Mat3::from_diagonal(spacing));
    let grid = Grid::from_axes(dims, axes, lps_to_ras(offset)).map_err(|e| fail(Problem::Malformed(format!("geometry: {e}"))))?;
    let mut details = vec![("space".to_string(), "LPS (ITK)".to_string())];
    if let Some(o) = h.get("AnatomicalOrientation") {
        details.push(("anatomical orientation".into(), o.to_string()));
    }
    if channels > 1 {
        details.push(("note".into(), format!("{channels} channels per voxel: showing the first")));
    }
    let source = Source { format: "MetaImage".into(), path: Some(path.to_path_buf()), sample_type: ty.name().into(), details };
    Volume::new(volume_name(path), grid, encoded.voxels, encoded.map, source).map_err(|e| fail(Problem::Malformed(e)))
}

/// Data files: `None` = local data after the header.
fn data_files(path: &Path, spec: &str, reader: &mut impl BufRead) -> Result<Vec<Option<PathBuf>>, Problem> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let resolve = |n: &str| Some(if Path::new(n).is_absolute() { PathBuf::from(n) } else { dir.join(n) });
    let parts: Vec<&str> = spec.split_whitespace().collect();
    match parts.as_slice() {
        [] => Err(Problem::Malformed("ElementDataFile is empty".into())),
        [l] if l.eq_ignore_ascii_case("LOCAL") => Ok(vec![None]),
        [l, ..] if l.eq_ignore_ascii_case("LIST") => {
            let mut names = String::new();
            reader.take(MAX_HEADER).read_to_string(&mut names)?;
            let files: Vec<_> = names.split_whitespace().map(resolve).collect();
            if files.is_empty() { Err(Problem::Malformed("ElementDataFile LIST names no files".into())) } else { Ok(files) }
        }
        [pattern, range @ ..] if pattern.contains('%') && range.len() >= 3 => {
            Ok(pattern_files(pattern, &range[..3])?.iter().map(|n| resolve(n)).collect())
        }
        _ => Ok(vec![resolve(spec.trim())]),
    }
}

fn read_stream(
    at: &Path,
    reader: &mut impl Read,
    compressed: bool,
    binary: bool,
    header_size: i64,
    len: usize,
    ty: SampleType,
) -> Result<Vec<u8>, ReadError> {
    let fail = |p: Problem| ReadError::new(at, p);
    if header_size < -1 {
        return Err(fail(Problem::Malformed(format!("HeaderSize {header_size} is negative"))));
    }
    if header_size > 0 {
        skip(reader, header_size as u64).map_err(fail)?;
    }
    if !binary {
        let mut text = Vec::new();
        reader.take(len as u64 / ty.size() as u64 * 64 + (1 << 20)).read_to_end(&mut text).map_err(|e| fail(Problem::Io(e)))?;
        return Ok(text);
    }
    let c = if compressed { Compression::Zlib } else { Compression::None };
    read_exact_bounded(decoder(reader, c), len).map_err(fail)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_stops_at_element_data_file() {
        let text = b"ObjectType = Image\nNDims = 3\nElementDataFile = LOCAL\n\x01\x02";
        let mut r = &text[..];
        let h = parse_header(&mut r).unwrap();
        assert_eq!(h.get("ndims"), Some("3"));
        assert_eq!(r, &[1, 2]);
        assert!(parse_header(&mut &b"NDims = 3\n"[..]).is_err());
        assert_eq!(sample_type("MET_SHORT").unwrap(), SampleType::I16);
        assert!(sample_type("MET_OTHER").is_err());
    }
}
