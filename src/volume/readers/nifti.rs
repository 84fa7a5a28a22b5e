//! NIfTI-1 and NIfTI-2 (`.nii`, `.nii.gz`, and `.hdr`/`.img` pairs).
//!
//! NIfTI-1 headers are parsed by the `nifti` crate; NIfTI-2 (540-byte header, 64-bit
//! dimensions and doubles, which that crate does not read) by [`parse_nifti2`]. Both land
//! in one [`Header`] from which geometry and scaling are derived:
//!
//! - Placement follows the NIfTI-1 standard's methods: the sform (method 3) when
//!   `sform_code > 0`, else the qform (method 2) when `qform_code > 0`, else the plain
//!   pixdim scaling (method 1), as nibabel does. The qform rotation comes from the
//!   quaternion (b, c, d) with `a = √(1 − b² − c² − d²)`:
//!   `R = [[a²+b²−c²−d², 2(bc−ad), 2(bd+ac)], [2(bc+ad), a²+c²−b²−d², 2(cd−ab)],
//!   [2(bd−ac), 2(cd+ab), a²+d²−b²−c²]]`, columns scaled by `(dx, dy, qfac·dz)` with
//!   `qfac = pixdim[0] < 0 ? −1 : 1`.
//! - Spatial units (`xyzt_units`) convert metres and microns to millimetres.
//! - Real values are `scl_slope · v + scl_inter` when `scl_slope` is non-zero and finite.
//! - 4D (and higher) files show their first 3D volume; the details say so.

use std::io::Read;
use std::path::{Path, PathBuf};

use glam::{Mat3, Vec3};

use super::common::{
    Compression, Problem, ReadError, ReadOptions, decoder, encode, file_len, open_buffered, read_exact_bounded, skip, volume_name,
};
use crate::volume::encode::{ByteOrder, SampleType};
use crate::volume::{Grid, Source, Volume};

/// The fields of a NIfTI-1 or NIfTI-2 header that Focal uses.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    pub version: u8,
    pub big_endian: bool,
    pub dim: [i64; 8],
    pub datatype: i16,
    pub pixdim: [f64; 8],
    pub vox_offset: f64,
    pub scl_slope: f64,
    pub scl_inter: f64,
    pub xyzt_units: u8,
    pub qform_code: i32,
    pub sform_code: i32,
    /// quatern_b, c, d, qoffset_x, y, z.
    pub quatern: [f64; 6],
    pub srow: [[f64; 4]; 3],
    pub descrip: String,
    /// Whether the voxels live in a separate `.img` file (magic `ni1` / `n+2` vs `n+1`).
    pub pair: bool,
}

/// Reads a NIfTI file (or `.hdr`/`.img` pair).
pub fn read(path: &Path, options: &ReadOptions) -> Result<Volume, ReadError> {
    let fail = |p: Problem| ReadError::new(path, p);
    let gz = path.to_string_lossy().to_ascii_lowercase().ends_with(".gz");
    let header_path = header_path(path);
    let mut stream =
        decoder(open_buffered(&header_path, options)?, if is_gz(&header_path) { Compression::Gzip } else { Compression::None });
    // sizeof_hdr (348 or 540, either byte order) says how much header to read.
    let mut head = Vec::with_capacity(540);
    (&mut stream).take(4).read_to_end(&mut head).map_err(|e| fail(Problem::Io(e)))?;
    let size = match head.get(..4).map(|b| (i32::from_le_bytes([b[0], b[1], b[2], b[3]]), i32::from_be_bytes([b[0], b[1], b[2], b[3]]))) {
        Some((540, _) | (_, 540)) => 540,
        _ => 348,
    };
    (&mut stream).take(size - 4).read_to_end(&mut head).map_err(|e| fail(Problem::Io(e)))?;
    let header = parse_header(&head).map_err(fail)?;

    let (ty, size) = sample_type(header.datatype).map_err(fail)?;
    let ndim = header.dim[0];
    let dims = [header.dim[1], header.dim[2], if ndim >= 3 { header.dim[3] } else { 1 }];
    if dims.iter().any(|&d| d < 1) || !(1..=7).contains(&ndim) {
        return Err(fail(Problem::Malformed(format!("dim = {:?} is not a valid size", &header.dim[..=ndim.clamp(0, 7) as usize]))));
    }
    let extra: i64 = header.dim[4..=(ndim.max(3) as usize).min(7)].iter().map(|&d| d.max(1)).product();
    let (dims, len) = options.check_size(dims.map(|d| d as u64), size).map_err(fail)?;
    let order = if header.big_endian { ByteOrder::Big } else { ByteOrder::Little };

    let bytes = if header.pair {
        let img = image_path(path)
            .ok_or_else(|| fail(Problem::Malformed("header says the voxels are in a separate .img file, but none was found".into())))?;
        let c = if is_gz(&img) { Compression::Gzip } else { Compression::None };
        if c == Compression::None {
            check_file_len(&img, len as u64)?;
        }
        read_exact_bounded(decoder(open_buffered(&img, options)?, c), len).map_err(|p| ReadError::new(&img, p))?
    } else {
        let offset = header.vox_offset;
        if !offset.is_finite() || offset < head.len() as f64 || offset > 1e9 {
            return Err(fail(Problem::Malformed(format!("vox_offset {offset} is not a valid data offset"))));
        }
        let offset = offset as u64;
        if !gz {
            check_file_len(path, offset + len as u64)?;
        }
        skip(&mut stream, offset - head.len() as u64).map_err(fail)?;
        read_exact_bounded(stream, len).map_err(fail)?
    };

    let encoded = encode(bytes, ty, order).map_err(fail)?;
    let mut values = encoded.map;
    if header.scl_slope != 0.0 && header.scl_slope.is_finite() && header.scl_inter.is_finite() {
        values = values.then(header.scl_slope, header.scl_inter);
    }
    let (axes, origin, method) = placement(&header);
    let unit_scale = match header.xyzt_units & 7 {
        1 => 1000.0,
        3 => 0.001,
        _ => 1.0,
    };
    let grid =
        Grid::from_axes(dims, axes * unit_scale, origin * unit_scale).map_err(|e| fail(Problem::Malformed(format!("{method}: {e}"))))?;

    let mut details = vec![("placement".to_string(), method.to_string())];
    if !header.descrip.is_empty() {
        details.push(("description".into(), header.descrip.clone()));
    }
    if extra > 1 {
        details.push(("note".into(), format!("{}-D data: showing the first of {extra} volumes", ndim)));
    }
    let source =
        Source { format: format!("NIfTI-{}", header.version), path: Some(path.to_path_buf()), sample_type: ty.name().into(), details };
    Volume::new(volume_name(path), grid, encoded.voxels, values, source).map_err(|e| fail(Problem::Malformed(e)))
}

fn check_file_len(path: &Path, needed: u64) -> Result<(), ReadError> {
    let have = file_len(path)?;
    if have < needed {
        return Err(ReadError::new(path, Problem::Truncated(format!("file has {have} bytes, the header needs {needed}"))));
    }
    Ok(())
}

fn is_gz(p: &Path) -> bool {
    p.extension().is_some_and(|e| e.eq_ignore_ascii_case("gz"))
}

/// `.img` → `.hdr` (the header of a pair); any other path is its own header.
fn header_path(path: &Path) -> PathBuf {
    let s = path.to_string_lossy();
    let lower = s.to_ascii_lowercase();
    for (img, hdr) in [(".img.gz", ".hdr.gz"), (".img", ".hdr")] {
        if lower.ends_with(img) {
            for h in [hdr, ".hdr"] {
                let p = PathBuf::from(format!("{}{h}", &s[..s.len() - img.len()]));
                if p.exists() {
                    return p;
                }
            }
        }
    }
    path.to_path_buf()
}

/// The `.img` (or `.img.gz`) beside a `.hdr`.
fn image_path(path: &Path) -> Option<PathBuf> {
    let s = path.to_string_lossy();
    let lower = s.to_ascii_lowercase();
    let stem = [".hdr.gz", ".hdr", ".img.gz", ".img"].iter().find(|e| lower.ends_with(*e)).map(|e| &s[..s.len() - e.len()])?;
    [".img", ".img.gz"].iter().map(|e| PathBuf::from(format!("{stem}{e}"))).find(|p| p.exists())
}

/// Parses a NIfTI-1 or NIfTI-2 header from its first bytes.
pub fn parse_header(head: &[u8]) -> Result<Header, Problem> {
    let not = |detail: &str| Problem::NotFormat { format: "NIfTI", detail: detail.into() };
    if head.len() < 4 {
        return Err(Problem::Truncated(format!("{} bytes, too short for a NIfTI header", head.len())));
    }
    let le = i32::from_le_bytes([head[0], head[1], head[2], head[3]]);
    let be = i32::from_be_bytes([head[0], head[1], head[2], head[3]]);
    match (le, be) {
        (348, _) | (_, 348) => parse_nifti1(head),
        (540, _) => parse_nifti2(head, false),
        (_, 540) => parse_nifti2(head, true),
        _ => Err(not("sizeof_hdr is neither 348 (NIfTI-1) nor 540 (NIfTI-2)")),
    }
}

fn parse_nifti1(head: &[u8]) -> Result<Header, Problem> {
    if head.len() < 348 {
        return Err(Problem::Truncated(format!("{} bytes, a NIfTI-1 header has 348", head.len())));
    }
    let h = nifti::NiftiHeader::from_reader(&head[..348]).map_err(|e| match e {
        nifti::NiftiError::InvalidFormat => {
            Problem::NotFormat { format: "NIfTI", detail: "magic is not 'n+1' or 'ni1' (ANALYZE 7.5 is not supported)".into() }
        }
        other => Problem::Malformed(other.to_string()),
    })?;
    let mut dim = [0i64; 8];
    for (d, s) in dim.iter_mut().zip(h.dim) {
        *d = s as i16 as i64;
    }
    let f = |v: f32| v as f64;
    Ok(Header {
        version: 1,
        big_endian: h.endianness == nifti::Endianness::Big,
        dim,
        datatype: h.datatype,
        pixdim: h.pixdim.map(f),
        vox_offset: f(h.vox_offset),
        scl_slope: f(h.scl_slope),
        scl_inter: f(h.scl_inter),
        xyzt_units: h.xyzt_units,
        qform_code: h.qform_code as i32,
        sform_code: h.sform_code as i32,
        quatern: [h.quatern_b, h.quatern_c, h.quatern_d, h.quatern_x, h.quatern_y, h.quatern_z].map(f),
        srow: [h.srow_x.map(f), h.srow_y.map(f), h.srow_z.map(f)],
        descrip: c_string(&h.descrip),
        pair: &h.magic == b"ni1\0",
    })
}

/// Parses a 540-byte NIfTI-2 header.
pub fn parse_nifti2(head: &[u8], big_endian: bool) -> Result<Header, Problem> {
    if head.len() < 540 {
        return Err(Problem::Truncated(format!("{} bytes, a NIfTI-2 header has 540", head.len())));
    }
    let magic = &head[4..8];
    if magic != b"n+2\0" && magic != b"ni2\0" {
        return Err(Problem::NotFormat { format: "NIfTI", detail: "NIfTI-2 magic is not 'n+2' or 'ni2'".into() });
    }
    let b8 = |o: usize| -> [u8; 8] {
        let mut a = [0u8; 8];
        a.copy_from_slice(&head[o..o + 8]);
        if big_endian {
            a.reverse();
        }
        a
    };
    let i64_at = |o: usize| i64::from_le_bytes(b8(o));
    let f64_at = |o: usize| f64::from_le_bytes(b8(o));
    let i32_at = |o: usize| {
        let mut a = [head[o], head[o + 1], head[o + 2], head[o + 3]];
        if big_endian {
            a.reverse();
        }
        i32::from_le_bytes(a)
    };
    let i16_at =
        |o: usize| if big_endian { i16::from_be_bytes([head[o], head[o + 1]]) } else { i16::from_le_bytes([head[o], head[o + 1]]) };
    Ok(Header {
        version: 2,
        big_endian,
        dim: std::array::from_fn(|i| i64_at(16 + 8 * i)),
        datatype: i16_at(12),
        pixdim: std::array::from_fn(|i| f64_at(104 + 8 * i)),
        vox_offset: i64_at(168) as f64,
        scl_slope: f64_at(176),
        scl_inter: f64_at(184),
        xyzt_units: i32_at(500) as u8,
        qform_code: i32_at(344),
        sform_code: i32_at(348),
        quatern: std::array::from_fn(|i| f64_at(352 + 8 * i)),
        srow: std::array::from_fn(|r| std::array::from_fn(|c| f64_at(400 + 32 * r + 8 * c))),
        descrip: c_string(&head[240..320]),
        pair: magic == b"ni2\0",
    })
}

fn c_string(b: &[u8]) -> String {
    let end = b.iter().position(|&c| c == 0).unwrap_or(b.len());
    String::from_utf8_lossy(&b[..end]).trim().to_string()
}

fn sample_type(datatype: i16) -> Result<(SampleType, usize), Problem> {
    let t = match datatype {
        2 => SampleType::U8,
        4 => SampleType::I16,
        8 => SampleType::I32,
        16 => SampleType::F32,
        64 => SampleType::F64,
        256 => SampleType::I8,
        512 => SampleType::U16,
        768 => SampleType::U32,
        1024 => SampleType::I64,
        1280 => SampleType::U64,
        32 | 1792 | 2048 => return Err(Problem::Unsupported("complex-valued NIfTI data".into())),
        128 | 2304 => return Err(Problem::Unsupported("RGB NIfTI data (Focal shows scalar volumes)".into())),
        other => return Err(Problem::Malformed(format!("unknown datatype code {other}"))),
    };
    Ok((t, t.size()))
}

/// The index→world axes (columns), the origin and the method used, in RAS mm before unit
/// conversion.
pub fn placement(h: &Header) -> (Mat3, Vec3, &'static str) {
    let v = |a: [f64; 3]| Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32);
    let pix = |i: usize| if h.pixdim[i].is_finite() && h.pixdim[i] > 0.0 { h.pixdim[i] } else { 1.0 };
    if h.sform_code > 0 {
        let r = &h.srow;
        let axes = Mat3::from_cols(v([r[0][0], r[1][0], r[2][0]]), v([r[0][1], r[1][1], r[2][1]]), v([r[0][2], r[1][2], r[2][2]]));
        return (axes, v([r[0][3], r[1][3], r[2][3]]), "sform");
    }
    if h.qform_code > 0 {
        let rot = quaternion_matrix(h.quatern[0], h.quatern[1], h.quatern[2]);
        let qfac = if h.pixdim[0] < 0.0 { -1.0 } else { 1.0 };
        let scale = Vec3::new(pix(1) as f32, pix(2) as f32, (qfac * pix(3)) as f32);
        return (rot * Mat3::from_diagonal(scale), v([h.quatern[3], h.quatern[4], h.quatern[5]]), "qform");
    }
    (Mat3::from_diagonal(Vec3::new(pix(1) as f32, pix(2) as f32, pix(3) as f32)), Vec3::ZERO, "pixdim (no qform or sform)")
}

/// The rotation of a NIfTI quaternion (b, c, d).
pub fn quaternion_matrix(b: f64, c: f64, d: f64) -> Mat3 {
    let a = (1.0 - (b * b + c * c + d * d)).max(0.0).sqrt();
    let m = [
        [a * a + b * b - c * c - d * d, 2.0 * (b * c - a * d), 2.0 * (b * d + a * c)],
        [2.0 * (b * c + a * d), a * a + c * c - b * b - d * d, 2.0 * (c * d - a * b)],
        [2.0 * (b * d - a * c), 2.0 * (c * d + a * b), a * a + d * d - c * c - b * b],
    ];
    Mat3::from_cols(
        Vec3::new(m[0][0] as f32, m[1][0] as f32, m[2][0] as f32),
        Vec3::new(m[0][1] as f32, m[1][1] as f32, m[2][1] as f32),
        Vec3::new(m[0][2] as f32, m[1][2] as f32, m[2][2] as f32),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quaternion_matches_hand_computed_rotations() {
        // b = 0, c = 0, d = sin(45°): a rotation of 90° about z: x → y, y → −x.
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let m = quaternion_matrix(0.0, 0.0, s);
        assert!((m.x_axis - Vec3::Y).length() < 1e-6, "{m}");
        assert!((m.y_axis + Vec3::X).length() < 1e-6);
        // b = 1 (a = 0): 180° about x: y → −y, z → −z (the common radiological flip).
        let m = quaternion_matrix(1.0, 0.0, 0.0);
        assert!((m.x_axis - Vec3::X).length() < 1e-6);
        assert!((m.y_axis + Vec3::Y).length() < 1e-6);
        assert!((m.z_axis + Vec3::Z).length() < 1e-6);
    }

    #[test]
    fn placement_prefers_sform_then_qform() {
        let mut h = Header {
            version: 1,
            big_endian: false,
            dim: [3, 2, 2, 2, 1, 1, 1, 1],
            datatype: 2,
            pixdim: [-1.0, 2.0, 3.0, 4.0, 0.0, 0.0, 0.0, 0.0],
            vox_offset: 352.0,
            scl_slope: 0.0,
            scl_inter: 0.0,
            xyzt_units: 2,
            qform_code: 1,
            sform_code: 0,
            quatern: [0.0, 0.0, 0.0, 10.0, 20.0, 30.0],
            srow: [[-1.0, 0.0, 0.0, 90.0], [0.0, 1.0, 0.0, -126.0], [0.0, 0.0, 1.0, -72.0]],
            descrip: String::new(),
            pair: false,
        };
        // qform with qfac = −1: identity rotation, z axis flipped.
        let (axes, origin, method) = placement(&h);
        assert_eq!(method, "qform");
        assert_eq!(axes, Mat3::from_diagonal(Vec3::new(2.0, 3.0, -4.0)));
        assert_eq!(origin, Vec3::new(10.0, 20.0, 30.0));
        h.sform_code = 4;
        let (axes, origin, method) = placement(&h);
        assert_eq!(method, "sform");
        assert_eq!(axes.x_axis, Vec3::new(-1.0, 0.0, 0.0));
        assert_eq!(origin, Vec3::new(90.0, -126.0, -72.0));
        h.sform_code = 0;
        h.qform_code = 0;
        assert_eq!(placement(&h).0, Mat3::from_diagonal(Vec3::new(2.0, 3.0, 4.0)));
    }

    #[test]
    fn rejects_non_nifti_headers() {
        assert!(matches!(parse_header(&[0u8; 348]), Err(Problem::NotFormat { .. })));
        assert!(matches!(parse_header(&[1, 2]), Err(Problem::Truncated(_))));
        let mut h = vec![0u8; 348];
        h[..4].copy_from_slice(&348i32.to_le_bytes());
        assert!(matches!(parse_header(&h), Err(Problem::NotFormat { .. })));
    }
}
