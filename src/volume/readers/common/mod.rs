//! What every reader shares: errors, limits, bounded decompression, sample decoding,
//! raw data of a known layout ([`raw_layout`], [`read_raw`]), names and sidecar files.

pub mod raw_layout;

use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use flate2::read::{GzDecoder, ZlibDecoder};
use glam::UVec3;

pub use raw_layout::{RawSpec, parse_sample_type};

use crate::volume::encode::{ByteOrder, Encoded, SampleType, encode_samples};
use crate::volume::grid::fmt_dims;
use crate::volume::{Grid, Source, Volume, Voxels};

/// A file could not be read: which file, and why.
#[derive(Debug, thiserror::Error)]
#[error("{}: {problem}", path.display())]
pub struct ReadError {
    pub path: PathBuf,
    pub problem: Problem,
}

impl ReadError {
    pub fn new(path: &Path, problem: Problem) -> Self {
        Self { path: path.to_path_buf(), problem }
    }
}

/// What is wrong with a file.
#[derive(Debug, thiserror::Error)]
pub enum Problem {
    #[error("cannot read the file: {0}")]
    Io(#[from] std::io::Error),
    #[error("not a {format} file: {detail}")]
    NotFormat { format: &'static str, detail: String },
    #[error("truncated: {0}")]
    Truncated(String),
    #[error("invalid header: {0}")]
    Malformed(String),
    #[error("unsupported: {0}")]
    Unsupported(String),
    #[error("too large: {0}")]
    TooLarge(String),
    #[error("corrupt compressed data: {0}")]
    Corrupt(String),
    #[error("bad voxel values: {0}")]
    Values(String),
}

/// Bytes read so far out of the bytes to read, shared with whoever shows a progress bar.
#[derive(Clone, Debug, Default)]
pub struct Progress {
    done: Arc<AtomicU64>,
    total: Arc<AtomicU64>,
}

impl Progress {
    /// Fraction done, once anything is known about the total.
    pub fn fraction(&self) -> Option<f32> {
        let total = self.total.load(Ordering::Relaxed);
        (total > 0).then(|| (self.done.load(Ordering::Relaxed) as f64 / total as f64).min(1.0) as f32)
    }

    pub fn add_total(&self, bytes: u64) {
        self.total.fetch_add(bytes, Ordering::Relaxed);
    }

    pub fn add_done(&self, bytes: u64) {
        self.done.fetch_add(bytes, Ordering::Relaxed);
    }
}

/// A reader that counts what passes through it.
pub struct Counting<R> {
    inner: R,
    progress: Option<Progress>,
}

impl<R: Read> Read for Counting<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        if let Some(p) = &self.progress {
            p.add_done(n as u64);
        }
        Ok(n)
    }
}

/// How to read, and what to refuse.
#[derive(Clone, Debug)]
pub struct ReadOptions {
    /// Largest number of voxels accepted (checked before allocating).
    pub max_voxels: u64,
    /// Largest size of the decoded sample data in bytes.
    pub max_bytes: u64,
    /// Dimensions and type for headerless raw files.
    pub raw: Option<RawSpec>,
    /// Where to report progress.
    pub progress: Option<Progress>,
}

impl Default for ReadOptions {
    fn default() -> Self {
        Self { max_voxels: 1 << 31, max_bytes: 8 << 30, raw: None, progress: None }
    }
}

impl ReadOptions {
    /// Reports a whole file read at once (`size` bytes).
    pub fn count_whole(&self, size: u64) {
        if let Some(p) = &self.progress {
            p.add_total(size);
            p.add_done(size);
        }
    }
}

/// Largest extent along one axis that any reader accepts.
pub const MAX_AXIS: u64 = 1 << 16;

impl ReadOptions {
    /// Checks dimensions and the decoded byte size against the limits; returns the
    /// dimensions and the byte count. Call before allocating anything of that size.
    pub fn check_size(&self, dims: [u64; 3], sample_size: usize) -> Result<(UVec3, usize), Problem> {
        if dims.contains(&0) {
            return Err(Problem::Malformed(format!("dimensions {}×{}×{} contain a zero", dims[0], dims[1], dims[2])));
        }
        if dims.iter().any(|&d| d > MAX_AXIS) {
            return Err(Problem::TooLarge(format!(
                "dimensions {}×{}×{} exceed {MAX_AXIS} voxels along an axis",
                dims[0], dims[1], dims[2]
            )));
        }
        let voxels = dims[0] * dims[1] * dims[2];
        let d = UVec3::new(dims[0] as u32, dims[1] as u32, dims[2] as u32);
        if voxels > self.max_voxels {
            return Err(Problem::TooLarge(format!("{} is {voxels} voxels, more than the limit of {}", fmt_dims(d), self.max_voxels)));
        }
        let bytes = voxels * sample_size as u64;
        if bytes > self.max_bytes {
            return Err(Problem::TooLarge(format!(
                "{} samples take {bytes} bytes, more than the limit of {}",
                fmt_dims(d),
                self.max_bytes
            )));
        }
        Ok((d, bytes as usize))
    }
}

/// Compression of a data stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compression {
    None,
    Gzip,
    Zlib,
}

/// Wraps `reader` in the decoder for `compression`.
pub fn decoder<'a>(reader: impl Read + 'a, compression: Compression) -> Box<dyn Read + 'a> {
    match compression {
        Compression::None => Box::new(reader),
        Compression::Gzip => Box::new(GzDecoder::new(reader)),
        Compression::Zlib => Box::new(ZlibDecoder::new(reader)),
    }
}

/// Reads exactly `len` bytes from `reader` (typically a [`decoder`]), never allocating
/// more than the data actually present; fewer bytes is a truncation error, a decoder
/// failure is reported as corrupt data.
pub fn read_exact_bounded(reader: impl Read, len: usize) -> Result<Vec<u8>, Problem> {
    // Reserve up front only what no corrupt header can turn into a large waste.
    let mut out = Vec::with_capacity(len.min(64 << 20));
    match reader.take(len as u64).read_to_end(&mut out) {
        Ok(_) if out.len() == len => Ok(out),
        Ok(_) => Err(Problem::Truncated(format!("expected {len} bytes of voxel data, found {}", out.len()))),
        Err(e) => Err(stream_problem(e, out.len(), len)),
    }
}

/// Classifies an I/O error met while decoding a stream.
pub fn stream_problem(e: std::io::Error, got: usize, len: usize) -> Problem {
    use std::io::ErrorKind::*;
    match e.kind() {
        UnexpectedEof => Problem::Truncated(format!("data ends after {got} of {len} bytes")),
        InvalidData | InvalidInput | Other => Problem::Corrupt(format!("{e} (after {got} of {len} bytes)")),
        _ => Problem::Io(e),
    }
}

/// Skips `n` bytes of a stream (a header's padding before the voxels).
pub fn skip(reader: &mut impl Read, n: u64) -> Result<(), Problem> {
    let skipped = std::io::copy(&mut reader.take(n), &mut std::io::sink()).map_err(|e| stream_problem(e, 0, n as usize))?;
    if skipped < n {
        return Err(Problem::Truncated(format!("file ends {} bytes before the voxel data starts", n - skipped)));
    }
    Ok(())
}

/// Inflates one whole zlib block whose decoded size is known.
pub fn inflate_zlib(block: &[u8], len: usize) -> Result<Vec<u8>, Problem> {
    read_exact_bounded(decoder(block, Compression::Zlib), len)
}

/// Buffer size of file readers: large reads keep system calls few.
pub const READ_BUFFER: usize = 1 << 20;

/// Opens a file for buffered reading, counting its bytes into the options' progress.
pub fn open_buffered(path: &Path, options: &ReadOptions) -> Result<std::io::BufReader<Counting<File>>, ReadError> {
    let file = open(path)?;
    if let Some(p) = &options.progress {
        p.add_total(file.metadata().map(|m| m.len()).unwrap_or(0));
    }
    Ok(std::io::BufReader::with_capacity(READ_BUFFER, Counting { inner: file, progress: options.progress.clone() }))
}

/// Opens a file, mapping failure to a [`ReadError`].
pub fn open(path: &Path) -> Result<File, ReadError> {
    File::open(path).map_err(|e| ReadError::new(path, Problem::Io(e)))
}

/// Size of a file in bytes.
pub fn file_len(path: &Path) -> Result<u64, ReadError> {
    std::fs::metadata(path).map(|m| m.len()).map_err(|e| ReadError::new(path, Problem::Io(e)))
}

/// Reads a whole text header file, refusing files over `max` bytes.
pub fn read_text(path: &Path, max: u64) -> Result<String, ReadError> {
    let len = file_len(path)?;
    if len > max {
        return Err(ReadError::new(path, Problem::TooLarge(format!("a {len}-byte header file (at most {max} expected)"))));
    }
    let bytes = std::fs::read(path).map_err(|e| ReadError::new(path, Problem::Io(e)))?;
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}

/// Turns decoded sample bytes into voxel codes.
pub fn encode(bytes: Vec<u8>, ty: SampleType, order: ByteOrder) -> Result<Encoded, Problem> {
    encode_samples(bytes, ty, order).map_err(Problem::Values)
}

/// Parses whitespace- or comma-separated numbers, naming the field on failure.
pub fn parse_numbers<T: std::str::FromStr>(field: &str, text: &str) -> Result<Vec<T>, Problem> {
    text.split(|c: char| c.is_whitespace() || c == ',')
        .filter(|s| !s.is_empty())
        .map(|s| s.parse::<T>().map_err(|_| Problem::Malformed(format!("{field}: '{s}' is not a number"))))
        .collect()
}

/// Parses exactly `n` numbers.
pub fn parse_n<T: std::str::FromStr>(field: &str, text: &str, n: usize) -> Result<Vec<T>, Problem> {
    let v = parse_numbers(field, text)?;
    if v.len() != n {
        return Err(Problem::Malformed(format!("{field} has {} values, expected {n}", v.len())));
    }
    Ok(v)
}

/// Requires a finite float.
pub fn finite(field: &str, v: f64) -> Result<f64, Problem> {
    if v.is_finite() { Ok(v) } else { Err(Problem::Malformed(format!("{field} is {v}"))) }
}

/// Expands a printf-style `%d` / `%03d` pattern.
fn format_pattern(pattern: &str, i: i64) -> Result<String, Problem> {
    let start = pattern.find('%').ok_or_else(|| Problem::Malformed("data file pattern has no %".into()))?;
    let rest = &pattern[start + 1..];
    let end = rest.find('d').ok_or_else(|| Problem::Malformed(format!("data file pattern '{pattern}' is not %d-style")))?;
    let spec = &rest[..end];
    let width: usize = spec.trim_start_matches('0').parse().unwrap_or(0);
    let num = if spec.starts_with('0') { format!("{i:0width$}") } else { format!("{i:width$}") };
    Ok(format!("{}{}{}", &pattern[..start], num, &rest[end + 1..]))
}

/// The file names of a `pattern min max step` data-file list (NRRD, MetaImage).
pub fn pattern_files(pattern: &str, range: &[&str]) -> Result<Vec<String>, Problem> {
    let n = |s: &str| s.parse::<i64>().map_err(|_| Problem::Malformed(format!("data file pattern: '{s}' is not a number")));
    let (min, max, step) = (n(range[0])?, n(range[1])?, n(range[2])?);
    if step == 0 || (max - min) / step < 0 || (max - min) / step > 100_000 {
        return Err(Problem::Malformed(format!("data file pattern range {min} {max} {step} is not usable")));
    }
    let mut out = Vec::new();
    let mut i = min;
    while (step > 0 && i <= max) || (step < 0 && i >= max) {
        out.push(format_pattern(pattern, i)?);
        i += step;
    }
    Ok(out)
}

/// Keeps every `n`-th sample: the first component of interleaved vectors or channels.
pub fn first_component(e: Encoded, n: usize) -> Encoded {
    let voxels = match e.voxels {
        Voxels::U8(v) => Voxels::U8(v.into_iter().step_by(n).collect()),
        Voxels::U16(v) => Voxels::U16(v.into_iter().step_by(n).collect()),
    };
    Encoded { voxels, map: e.map }
}

/// Reads raw data laid out as `spec` says; `format` and `details` describe where the
/// spec came from.
pub fn read_raw(
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

/// Name shown for a volume: the file name without its extensions.
pub fn volume_name(path: &Path) -> String {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "volume".into());
    name.split('.').next().filter(|s| !s.is_empty()).unwrap_or(&name).to_string()
}

/// Sidecar candidates of a volume path: the name with its volume extension stripped
/// and each of `exts` appended, plus the full name with `exts` appended (`aal.nii.txt`).
pub fn sidecars(path: &Path, exts: &[&str]) -> Vec<PathBuf> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let mut stems = vec![name.clone()];
    for ext in [".nii.gz", ".gz", ".nii", ".nrrd", ".nhdr", ".mha", ".mhd", ".vti"] {
        if let Some(s) = name.strip_suffix(ext) {
            stems.push(s.to_string());
            if let Some(s2) = s.strip_suffix(".nii") {
                stems.push(format!("{s2}.nii"));
            }
        }
    }
    let mut out = Vec::new();
    for stem in stems {
        for ext in exts {
            let p = path.with_file_name(format!("{stem}.{ext}"));
            if !out.contains(&p) {
                out.push(p);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    #[test]
    fn bounded_reads_report_truncation_and_corruption() {
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        gz.write_all(&[7u8; 1000]).unwrap();
        let gz = gz.finish().unwrap();
        let read = |bytes: &[u8], c, len| read_exact_bounded(decoder(bytes, c), len);
        assert_eq!(read(&gz, Compression::Gzip, 1000).unwrap().len(), 1000);
        // Asking for more than is there: truncated, not a huge allocation.
        assert!(matches!(read(&gz, Compression::Gzip, 1 << 30), Err(Problem::Truncated(_))));
        // Cut stream.
        assert!(matches!(read(&gz[..gz.len() / 2], Compression::Gzip, 1000), Err(Problem::Truncated(_))));
        // Garbage.
        assert!(matches!(read(&[1u8, 2, 3, 4, 5, 6], Compression::Zlib, 10), Err(Problem::Corrupt(_))));
    }

    #[test]
    fn size_limits_apply_before_allocation() {
        let o = ReadOptions::default();
        assert!(o.check_size([256, 256, 128], 1).is_ok());
        assert!(matches!(o.check_size([100_000, 2, 2], 1), Err(Problem::TooLarge(_))));
        assert!(matches!(o.check_size([60_000, 60_000, 60_000], 1), Err(Problem::TooLarge(_))));
        assert!(matches!(o.check_size([2, 0, 2], 1), Err(Problem::Malformed(_))));
        let small = ReadOptions { max_bytes: 1000, ..Default::default() };
        assert!(matches!(small.check_size([10, 10, 10], 2), Err(Problem::TooLarge(_))));
    }

    #[test]
    fn data_file_patterns_expand() {
        assert_eq!(format_pattern("slice%03d.raw", 7).unwrap(), "slice007.raw");
        assert_eq!(format_pattern("s%d", 12).unwrap(), "s12");
        assert_eq!(pattern_files("s%d", &["3", "1", "-1"]).unwrap(), vec!["s3", "s2", "s1"]);
        assert!(pattern_files("s%d", &["1", "3", "0"]).is_err());
    }
}
