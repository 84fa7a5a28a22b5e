//! NRRD (`.nrrd` with attached data, `.nhdr` with detached data).
//!
//! Follows the teem format definition (NRRD0001–0005): `type`, `dimension`, `sizes`,
//! `encoding` (raw, gzip, ascii/text, hex), `endian`, `space` / `space dimension`,
//! `space directions`, `space origin`, `spacings`, `data file` (one file, `LIST`, or a
//! `%d` pattern with min, max, step), `line skip` and `byte skip` (`-1` = data at the end
//! of a raw file). Line skip applies to the file, byte skip to the decoded stream, as in
//! teem. Spaces in LPS or LAS are flipped into Focal's RAS world; `scanner-xyz` and the
//! generic 3D spaces are taken as they are. A 4-D file whose first axis is not spatial
//! (a vector or list) shows its first component.

use std::io::{BufRead, Read};
use std::path::{Path, PathBuf};

use glam::{Mat3, Vec3};

use super::common::{
    Compression, Problem, ReadError, ReadOptions, decoder, encode, file_len, finite, first_component, open, open_buffered, parse_n,
    parse_numbers, pattern_files, read_exact_bounded, skip, volume_name,
};
use crate::volume::encode::{ByteOrder, SampleType, encode_values};
use crate::volume::{Grid, Source, Volume};

const MAX_HEADER: usize = 1 << 20;

/// Parsed NRRD header fields.
#[derive(Debug, Default)]
struct Header {
    fields: Vec<(String, String)>,
    /// Lines after `data file: LIST`.
    list: Vec<String>,
    /// Byte offset of attached data.
    data_start: u64,
}

impl Header {
    fn get(&self, key: &str) -> Option<&str> {
        self.fields.iter().rev().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
    }

    fn require(&self, key: &str) -> Result<&str, Problem> {
        self.get(key).ok_or_else(|| Problem::Malformed(format!("required field '{key}' is missing")))
    }
}

fn parse_header(reader: &mut impl BufRead) -> Result<Header, Problem> {
    let mut line = Vec::new();
    let mut consumed = 0u64;
    let mut header = Header::default();
    let mut first = true;
    let mut in_list = false;
    loop {
        line.clear();
        let n = reader.by_ref().take(MAX_HEADER as u64).read_until(b'\n', &mut line)?;
        consumed += n as u64;
        if consumed > MAX_HEADER as u64 {
            return Err(Problem::Malformed("header is longer than 1 MiB (missing blank line before the data?)".into()));
        }
        if n == 0 {
            break;
        }
        let text = String::from_utf8_lossy(&line);
        let text = text.trim_end_matches(['\n', '\r']);
        if first {
            if !text.starts_with("NRRD") {
                return Err(Problem::NotFormat { format: "NRRD", detail: "first line is not the NRRD magic".into() });
            }
            first = false;
            continue;
        }
        if text.is_empty() {
            break;
        }
        if in_list {
            header.list.push(text.trim().to_string());
            continue;
        }
        if text.starts_with('#') || text.contains(":=") {
            continue;
        }
        let Some((key, value)) = text.split_once(": ") else {
            return Err(Problem::Malformed(format!("line '{}' is not 'field: value'", text.chars().take(60).collect::<String>())));
        };
        let key = key.trim().to_ascii_lowercase();
        let key = if key == "datafile" { "data file".to_string() } else { key };
        let value = value.trim().to_string();
        if key == "data file" && value.starts_with("LIST") {
            in_list = true;
        }
        header.fields.push((key, value));
    }
    header.data_start = consumed;
    Ok(header)
}

fn sample_type(name: &str) -> Result<SampleType, Problem> {
    let t = match name.trim().to_ascii_lowercase().as_str() {
        "signed char" | "int8" | "int8_t" => SampleType::I8,
        "uchar" | "unsigned char" | "uint8" | "uint8_t" => SampleType::U8,
        "short" | "short int" | "signed short" | "signed short int" | "int16" | "int16_t" => SampleType::I16,
        "ushort" | "unsigned short" | "unsigned short int" | "uint16" | "uint16_t" => SampleType::U16,
        "int" | "signed int" | "int32" | "int32_t" => SampleType::I32,
        "uint" | "unsigned int" | "uint32" | "uint32_t" => SampleType::U32,
        "longlong" | "long long" | "long long int" | "signed long long" | "signed long long int" | "int64" | "int64_t" => SampleType::I64,
        "ulonglong" | "unsigned long long" | "unsigned long long int" | "uint64" | "uint64_t" => SampleType::U64,
        "float" => SampleType::F32,
        "double" => SampleType::F64,
        other => return Err(Problem::Unsupported(format!("NRRD type '{other}'"))),
    };
    Ok(t)
}

/// Parses `(x,y,z)` vectors, or `none` for a non-spatial axis.
fn parse_vectors(field: &str, text: &str) -> Result<Vec<Option<Vec3>>, Problem> {
    let mut out = Vec::new();
    let mut rest = text.trim();
    while !rest.is_empty() {
        if let Some(r) = rest.strip_prefix("none") {
            out.push(None);
            rest = r.trim_start();
            continue;
        }
        let open = rest.strip_prefix('(').ok_or_else(|| Problem::Malformed(format!("{field}: expected '(' in '{text}'")))?;
        let end = open.find(')').ok_or_else(|| Problem::Malformed(format!("{field}: missing ')' in '{text}'")))?;
        let v: Vec<f64> = parse_n(field, &open[..end], 3)?;
        let v = Vec3::new(finite(field, v[0])? as f32, finite(field, v[1])? as f32, finite(field, v[2])? as f32);
        out.push(Some(v));
        rest = open[end + 1..].trim_start();
    }
    Ok(out)
}

/// Reads a NRRD file.
pub fn read(path: &Path, options: &ReadOptions) -> Result<Volume, ReadError> {
    let fail = |p: Problem| ReadError::new(path, p);
    let mut reader = open_buffered(path, options)?;
    let header = parse_header(&mut reader).map_err(fail)?;

    let ty = sample_type(header.require("type").map_err(fail)?).map_err(fail)?;
    let dimension: usize = header
        .require("dimension")
        .map_err(fail)?
        .trim()
        .parse()
        .map_err(|_| fail(Problem::Malformed("dimension is not a number".into())))?;
    let sizes: Vec<u64> = parse_numbers("sizes", header.require("sizes").map_err(fail)?).map_err(fail)?;
    if sizes.len() != dimension || !(2..=4).contains(&dimension) {
        return Err(fail(Problem::Unsupported(format!("dimension {dimension} with sizes {sizes:?} (Focal reads 2-D to 4-D arrays)"))));
    }
    let directions = header.get("space directions").map(|t| parse_vectors("space directions", t)).transpose().map_err(fail)?;
    // Which axes are spatial: those with a direction, else the last three.
    let components = if dimension == 4 {
        let first_spatial = directions.as_ref().map(|d| d.first().is_some_and(|v| v.is_some())).unwrap_or(false);
        if first_spatial {
            return Err(fail(Problem::Unsupported("4-D data with four spatial axes (time series)".into())));
        }
        sizes[0]
    } else {
        1
    };
    let spatial: Vec<u64> = sizes[sizes.len() - dimension.min(3)..].to_vec();
    let dims = [spatial[0], spatial.get(1).copied().unwrap_or(1), spatial.get(2).copied().unwrap_or(1)];
    let (dims, _) = options.check_size(dims, ty.size()).map_err(fail)?;
    let (_, len) = options.check_size([dims.x as u64 * components, dims.y as u64, dims.z as u64], ty.size()).map_err(fail)?;

    let encoding = header.require("encoding").map_err(fail)?.to_ascii_lowercase();
    let order = match header.get("endian").map(|e| e.to_ascii_lowercase()) {
        Some(e) if e == "big" => ByteOrder::Big,
        Some(e) if e == "little" => ByteOrder::Little,
        Some(e) => return Err(fail(Problem::Malformed(format!("endian '{e}' is neither little nor big")))),
        None if ty.size() > 1 && matches!(encoding.as_str(), "raw" | "gzip" | "gz" | "hex") => {
            return Err(fail(Problem::Malformed("multi-byte samples but no 'endian' field".into())));
        }
        None => ByteOrder::Little,
    };
    let line_skip: u64 = header
        .get("line skip")
        .or(header.get("lineskip"))
        .map(|s| s.trim().parse())
        .transpose()
        .map_err(|_| fail(Problem::Malformed("line skip is not a number".into())))?
        .unwrap_or(0);
    let byte_skip: i64 = header
        .get("byte skip")
        .or(header.get("byteskip"))
        .map(|s| s.trim().parse())
        .transpose()
        .map_err(|_| fail(Problem::Malformed("byte skip is not a number".into())))?
        .unwrap_or(0);

    let files = data_files(path, &header).map_err(fail)?;
    let samples = match encoding.as_str() {
        "raw" | "gzip" | "gz" => {
            let compression = if encoding == "raw" { Compression::None } else { Compression::Gzip };
            let per_file = len / files.len().max(1);
            let mut data = Vec::new();
            for (i, file) in files.iter().enumerate() {
                let want = if i + 1 == files.len() { len - per_file * i } else { per_file };
                let layout = ChunkLayout { compression, line_skip, byte_skip, len: want };
                let chunk = read_chunk(path, file.as_deref(), &mut reader, &layout, options)?;
                if data.is_empty() { data = chunk } else { data.extend_from_slice(&chunk) }
            }
            encode(data, ty, order).map_err(fail)?
        }
        "ascii" | "text" | "txt" | "hex" => {
            let mut text = String::new();
            for file in &files {
                let mut bytes = Vec::new();
                let r: Box<dyn Read> = match file {
                    Some(f) => Box::new(open(f)?),
                    None => Box::new(&mut reader),
                };
                r.take(len as u64 * 64 + (1 << 20)).read_to_end(&mut bytes).map_err(|e| fail(Problem::Io(e)))?;
                text.push_str(&String::from_utf8_lossy(&bytes));
                text.push('\n');
            }
            let values: Vec<f64> = if encoding == "hex" {
                hex_values(&text, ty, order).map_err(fail)?
            } else {
                parse_numbers("ascii data", &text).map_err(fail)?
            };
            let n = len / ty.size();
            if values.len() < n {
                return Err(fail(Problem::Truncated(format!("{} of {n} values present", values.len()))));
            }
            encode_values(&values[..n], ty).map_err(|e| fail(Problem::Values(e)))?
        }
        "bzip2" | "bz2" => return Err(fail(Problem::Unsupported("bzip2 encoding (re-save with gzip or raw)".into()))),
        other => return Err(fail(Problem::Unsupported(format!("encoding '{other}'")))),
    };
    let encoded = if components > 1 { first_component(samples, components as usize) } else { samples };

    let space = header.get("space").map(|s| s.to_ascii_lowercase()).unwrap_or_default();
    let (flip, space_name) = match space.as_str() {
        "left-posterior-superior" | "lps" | "left-posterior-superior-time" | "lpst" => (Vec3::new(-1.0, -1.0, 1.0), "LPS"),
        "left-anterior-superior" | "las" | "left-anterior-superior-time" | "last" => (Vec3::new(-1.0, 1.0, 1.0), "LAS"),
        "right-anterior-superior" | "ras" | "right-anterior-superior-time" | "rast" => (Vec3::ONE, "RAS"),
        "" => (Vec3::ONE, "none given"),
        _ => (Vec3::ONE, "taken as RAS"),
    };
    let spatial_dirs: Vec<Vec3> = directions.as_ref().map(|d| d.iter().flatten().copied().collect()).unwrap_or_default();
    let axes = if spatial_dirs.len() >= dimension.min(3) && !spatial_dirs.is_empty() {
        let get = |i: usize| spatial_dirs.get(i).copied().unwrap_or(Vec3::ZERO);
        let mut a = Mat3::from_cols(get(0), get(1), get(2));
        if dimension == 2 {
            a.z_axis = a.x_axis.cross(a.y_axis).normalize_or(Vec3::Z);
        }
        a
    } else {
        let sp: Vec<f64> = header.get("spacings").map(|s| parse_numbers("spacings", s)).transpose().map_err(fail)?.unwrap_or_default();
        let sp: Vec<f32> = sp[sp.len().saturating_sub(dimension.min(3))..]
            .iter()
            .map(|&s| if s.is_finite() && s > 0.0 { s as f32 } else { 1.0 })
            .collect();
        let at = |i: usize| sp.get(i).copied().unwrap_or(1.0);
        Mat3::from_diagonal(Vec3::new(at(0), at(1), at(2)))
    };
    let origin = header.get("space origin").map(|t| parse_vectors("space origin", t)).transpose().map_err(fail)?;
    let origin = origin.and_then(|o| o.first().copied().flatten()).unwrap_or(Vec3::ZERO);
    let to_ras = |v: Vec3| v * flip;
    let axes = Mat3::from_cols(to_ras(axes.x_axis), to_ras(axes.y_axis), to_ras(axes.z_axis));
    let grid = Grid::from_axes(dims, axes, to_ras(origin)).map_err(|e| fail(Problem::Malformed(format!("space directions: {e}"))))?;

    let mut details = vec![("space".to_string(), space_name.to_string()), ("encoding".to_string(), encoding.clone())];
    if components > 1 {
        details.push(("note".into(), format!("{components} components per voxel: showing the first")));
    }
    let name = header.get("content").map(str::to_string).unwrap_or_else(|| volume_name(path));
    let source = Source { format: "NRRD".into(), path: Some(path.to_path_buf()), sample_type: ty.name().into(), details };
    Volume::new(name, grid, encoded.voxels, encoded.map, source).map_err(|e| fail(Problem::Malformed(e)))
}

/// The data files: `None` = attached data in the header file itself.
fn data_files(path: &Path, header: &Header) -> Result<Vec<Option<PathBuf>>, Problem> {
    let Some(spec) = header.get("data file") else {
        return Ok(vec![None]);
    };
    let dir = path.parent().unwrap_or(Path::new("."));
    let resolve = |name: &str| {
        let p = Path::new(name.trim());
        Some(if p.is_absolute() { p.to_path_buf() } else { dir.join(p) })
    };
    if spec.starts_with("LIST") {
        if header.list.is_empty() {
            return Err(Problem::Malformed("data file LIST names no files".into()));
        }
        return Ok(header.list.iter().map(|l| resolve(l)).collect());
    }
    let parts: Vec<&str> = spec.split_whitespace().collect();
    if parts.len() >= 4 && parts[0].contains('%') {
        return Ok(pattern_files(parts[0], &parts[1..4])?.iter().map(|n| resolve(n)).collect());
    }
    Ok(vec![resolve(spec)])
}

/// How one file's samples are stored: compressed or not, after how many lines and bytes
/// (`byte_skip` −1: the data ends the file), and how many bytes they take.
struct ChunkLayout {
    compression: Compression,
    line_skip: u64,
    byte_skip: i64,
    len: usize,
}

/// Reads one data file's samples (`file`, or the bytes after the header in `attached`).
fn read_chunk(
    header_path: &Path,
    file: Option<&Path>,
    attached: &mut impl Read,
    layout: &ChunkLayout,
    options: &ReadOptions,
) -> Result<Vec<u8>, ReadError> {
    let &ChunkLayout { compression, line_skip, byte_skip, len } = layout;
    let at = file.unwrap_or(header_path);
    let fail = |p: Problem| ReadError::new(at, p);
    let mut own;
    let stream: &mut dyn Read = match file {
        Some(f) => {
            own = open_buffered(f, options)?;
            &mut own
        }
        None => attached,
    };
    for _ in 0..line_skip {
        let mut b = [0u8; 1];
        loop {
            match stream.read(&mut b) {
                Ok(0) => return Err(fail(Problem::Truncated("file ends inside the skipped lines".into()))),
                Ok(_) if b[0] == b'\n' => break,
                Ok(_) => {}
                Err(e) => return Err(fail(Problem::Io(e))),
            }
        }
    }
    if byte_skip == -1 {
        if compression != Compression::None {
            return Err(fail(Problem::Malformed("byte skip -1 is only allowed with raw encoding".into())));
        }
        let Some(f) = file else {
            return Err(fail(Problem::Malformed("byte skip -1 needs a detached data file".into())));
        };
        let total = file_len(f)?;
        if total < len as u64 {
            return Err(fail(Problem::Truncated(format!("file has {total} bytes, {len} needed"))));
        }
        let mut data = open_buffered(f, options)?;
        skip(&mut data, total - len as u64).map_err(fail)?;
        return read_exact_bounded(data, len).map_err(fail);
    }
    if byte_skip < -1 {
        return Err(fail(Problem::Malformed(format!("byte skip {byte_skip} is negative"))));
    }
    let mut dec = decoder(stream, compression);
    skip(&mut dec, byte_skip as u64).map_err(fail)?;
    read_exact_bounded(dec, len).map_err(fail)
}

fn hex_values(text: &str, ty: SampleType, order: ByteOrder) -> Result<Vec<f64>, Problem> {
    let digits: Vec<u8> = text.bytes().filter(|b| b.is_ascii_hexdigit()).collect();
    let bytes: Vec<u8> = digits
        .chunks_exact(2)
        .map(|p| {
            let h = |c: u8| (c as char).to_digit(16).unwrap_or(0) as u8;
            h(p[0]) << 4 | h(p[1])
        })
        .collect();
    let size = ty.size();
    let enc = crate::volume::encode::encode_samples(bytes[..bytes.len() / size * size].to_vec(), ty, order).map_err(Problem::Values)?;
    Ok((0..enc.voxels.len()).map(|i| enc.map.to_real(enc.voxels.code(i) as f64)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_vectors_and_patterns() {
        let v = parse_vectors("d", "none (1,0,0) (0,-2.5,0)  (0,0,3)").unwrap();
        assert_eq!(v, vec![None, Some(Vec3::X), Some(Vec3::new(0.0, -2.5, 0.0)), Some(Vec3::new(0.0, 0.0, 3.0))]);
        assert!(parse_vectors("d", "(1,0)").is_err());
        assert!(parse_vectors("d", "(1,0,nan)").is_err());
    }

    #[test]
    fn header_ends_at_blank_line() {
        let text = b"NRRD0004\n# c\ntype: short\ndimension: 3\nkey:=value\nsizes: 2 2 2\n\nDATA";
        let mut r = &text[..];
        let h = parse_header(&mut r).unwrap();
        assert_eq!(h.get("type"), Some("short"));
        assert_eq!(h.data_start as usize, text.len() - 4);
        assert!(parse_header(&mut &b"P5\n"[..]).is_err());
    }
}
