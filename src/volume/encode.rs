//! Turning a file's samples into compact voxel codes.
//!
//! Rules (each keeps the real values recoverable through the [`ValueMap`]):
//! - `uint8` and `uint16` are stored as they are (codes = samples).
//! - Other integer types are shifted so the smallest sample becomes code 0: `int8` into
//!   8-bit codes, wider types into 16-bit codes. This is lossless whenever the value
//!   range spans at most 65 536 steps (always for `int16`).
//! - Floating-point samples that are all whole numbers within such a range are stored the
//!   same lossless way (float label maps stay exact); other floats are quantised to
//!   16-bit codes over their true `[min, max]`, which the map keeps.
//! - NaN samples (masked or resampled float images) are no value: code 0
//!   ([`ValueMap::no_data`]), drawn as empty space and left out of the statistics; the
//!   true values then start [`NO_DATA_GAP`] codes higher, so that the lookup table can
//!   make the no-data texels transparent without touching a true value's. Infinite
//!   samples are an error (no place on the value axis can show them).

use super::voxels::{ValueMap, Voxels};

/// Codes between the no-data code 0 and the first true value: two texels of a 16-bit
/// volume's lookup table (`transfer::lut::LUT_SIZE_16` texels over 65 536 codes).
pub const NO_DATA_GAP: u16 = 32;

/// Sample types found in volume files.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleType {
    U8,
    I8,
    U16,
    I16,
    U32,
    I32,
    U64,
    I64,
    F32,
    F64,
}

/// Byte order of multi-byte samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ByteOrder {
    Little,
    Big,
}

impl SampleType {
    /// Size of one sample in bytes.
    pub fn size(self) -> usize {
        match self {
            SampleType::U8 | SampleType::I8 => 1,
            SampleType::U16 | SampleType::I16 => 2,
            SampleType::U32 | SampleType::I32 | SampleType::F32 => 4,
            SampleType::U64 | SampleType::I64 | SampleType::F64 => 8,
        }
    }

    /// The conventional name (`uint8`, `int16`, `float32`, …).
    pub fn name(self) -> &'static str {
        match self {
            SampleType::U8 => "uint8",
            SampleType::I8 => "int8",
            SampleType::U16 => "uint16",
            SampleType::I16 => "int16",
            SampleType::U32 => "uint32",
            SampleType::I32 => "int32",
            SampleType::U64 => "uint64",
            SampleType::I64 => "int64",
            SampleType::F32 => "float32",
            SampleType::F64 => "float64",
        }
    }

    pub fn is_float(self) -> bool {
        matches!(self, SampleType::F32 | SampleType::F64)
    }
}

/// Voxel codes plus the map back to the samples' values.
#[derive(Debug)]
pub struct Encoded {
    pub voxels: Voxels,
    pub map: ValueMap,
}

/// Encodes `bytes`, which must hold a whole number of samples of `ty` in `order`
/// (8-bit data is moved, not copied).
pub fn encode_samples(bytes: Vec<u8>, ty: SampleType, order: ByteOrder) -> Result<Encoded, String> {
    let size = ty.size();
    if !bytes.len().is_multiple_of(size) {
        return Err(format!("{} bytes is not a whole number of {} samples", bytes.len(), ty.name()));
    }
    match (ty, order) {
        (SampleType::U8, _) => Ok(Encoded { voxels: Voxels::U8(bytes), map: ValueMap::IDENTITY }),
        (SampleType::I16, _) if !bytes.is_empty() => {
            // The common CT case, in two vectorisable passes: the raw bits, then the shift.
            let mut codes: Vec<u16> = match order {
                ByteOrder::Little => bytes.chunks_exact(2).map(|b| u16::from_le_bytes([b[0], b[1]])).collect(),
                ByteOrder::Big => bytes.chunks_exact(2).map(|b| u16::from_be_bytes([b[0], b[1]])).collect(),
            };
            let lo = codes.iter().map(|&c| c as i16).min().unwrap_or(0);
            codes.iter_mut().for_each(|c| *c = c.wrapping_sub(lo as u16));
            Ok(Encoded { voxels: Voxels::U16(codes), map: ValueMap::new(1.0, lo as f64) })
        }
        (SampleType::U16, ByteOrder::Little) => Ok(Encoded {
            voxels: Voxels::U16(bytes.chunks_exact(2).map(|b| u16::from_le_bytes([b[0], b[1]])).collect()),
            map: ValueMap::IDENTITY,
        }),
        (SampleType::U16, ByteOrder::Big) => Ok(Encoded {
            voxels: Voxels::U16(bytes.chunks_exact(2).map(|b| u16::from_be_bytes([b[0], b[1]])).collect()),
            map: ValueMap::IDENTITY,
        }),
        _ => encode_general(&bytes, ty, order),
    }
}

/// Encodes values already decoded to `f64` (used by readers that get samples from a
/// library rather than as bytes).
pub fn encode_values(values: &[f64], ty: SampleType) -> Result<Encoded, String> {
    encode_with(values.len(), ty, |i| values[i])
}

fn encode_general(bytes: &[u8], ty: SampleType, order: ByteOrder) -> Result<Encoded, String> {
    let size = ty.size();
    let n = bytes.len() / size;
    let read = |i: usize| -> f64 {
        let b = &bytes[i * size..(i + 1) * size];
        let mut a = [0u8; 8];
        a[..size].copy_from_slice(b);
        if order == ByteOrder::Big {
            a[..size].reverse();
        }
        match ty {
            SampleType::U8 => a[0] as f64,
            SampleType::I8 => a[0] as i8 as f64,
            SampleType::U16 => u16::from_le_bytes([a[0], a[1]]) as f64,
            SampleType::I16 => i16::from_le_bytes([a[0], a[1]]) as f64,
            SampleType::U32 => u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            SampleType::I32 => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            SampleType::F32 => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            SampleType::U64 => u64::from_le_bytes(a) as f64,
            SampleType::I64 => i64::from_le_bytes(a) as f64,
            SampleType::F64 => f64::from_le_bytes(a),
        }
    };
    encode_with(n, ty, read)
}

fn encode_with(n: usize, ty: SampleType, read: impl Fn(usize) -> f64) -> Result<Encoded, String> {
    if n == 0 {
        return Err("no samples".into());
    }
    let (mut lo, mut hi, mut whole) = (f64::INFINITY, f64::NEG_INFINITY, true);
    let (mut nan, mut infinite) = (0usize, 0usize);
    for i in 0..n {
        let v = read(i);
        if v.is_nan() {
            nan += 1;
            continue;
        }
        if v.is_infinite() {
            infinite += 1;
            continue;
        }
        lo = lo.min(v);
        hi = hi.max(v);
        whole &= v.fract() == 0.0;
    }
    if infinite > 0 {
        return Err(format!("{infinite} of {n} {} samples are infinite", ty.name()));
    }
    if nan == n {
        return Err(format!("all {n} {} samples are NaN", ty.name()));
    }
    let range = hi - lo;
    // Codes 0 … gap − 1 stay free where NaN samples are (no data at code 0).
    let gap = if nan > 0 { NO_DATA_GAP } else { 0 };
    let no_data = (nan > 0).then_some(0u16);
    let top = (u16::MAX - gap) as f64;
    let exact = whole && range <= top;
    if exact && ty == SampleType::I8 {
        let codes = (0..n).map(|i| (read(i) - lo) as u8).collect();
        return Ok(Encoded { voxels: Voxels::U8(codes), map: ValueMap::new(1.0, lo) });
    }
    let code = |v: f64, to_code: &dyn Fn(f64) -> f64| if v.is_nan() { 0 } else { gap + to_code(v - lo).clamp(0.0, top) as u16 };
    if exact {
        let codes = (0..n).map(|i| code(read(i), &|d| d)).collect();
        let map = ValueMap { no_data, ..ValueMap::new(1.0, lo - gap as f64) };
        return Ok(Encoded { voxels: Voxels::U16(codes), map });
    }
    // Quantise to 16 bits over the true range.
    let slope = if range > 0.0 { range / top } else { 1.0 };
    let codes = (0..n).map(|i| code(read(i), &|d| (d / slope).round())).collect();
    let map = ValueMap { no_data, ..ValueMap::new(slope, lo - gap as f64 * slope) };
    Ok(Encoded { voxels: Voxels::U16(codes), map })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn real(e: &Encoded, i: usize) -> f64 {
        e.map.to_real(e.voxels.code(i) as f64)
    }

    #[test]
    fn unsigned_types_keep_their_codes() {
        let e = encode_samples(vec![1, 2, 255], SampleType::U8, ByteOrder::Little).unwrap();
        assert_eq!(e.voxels, Voxels::U8(vec![1, 2, 255]));
        let e = encode_samples(vec![0x01, 0x02], SampleType::U16, ByteOrder::Big).unwrap();
        assert_eq!(e.voxels, Voxels::U16(vec![0x0102]));
    }

    #[test]
    fn signed_types_are_shifted_losslessly() {
        let raw: Vec<u8> = [-1024i16, 0, 3071].iter().flat_map(|v| v.to_le_bytes()).collect();
        let e = encode_samples(raw, SampleType::I16, ByteOrder::Little).unwrap();
        assert_eq!(e.voxels, Voxels::U16(vec![0, 1024, 4095]));
        assert_eq!((real(&e, 0), real(&e, 1), real(&e, 2)), (-1024.0, 0.0, 3071.0));
        let e = encode_samples(vec![0x80, 0x7f], SampleType::I8, ByteOrder::Little).unwrap();
        assert_eq!(e.voxels, Voxels::U8(vec![0, 255]));
        assert_eq!(real(&e, 0), -128.0);
    }

    #[test]
    fn floats_are_quantised_over_their_true_range() {
        let raw: Vec<u8> = [-1.5f32, 0.25, 2.0].iter().flat_map(|v| v.to_be_bytes()).collect();
        let be16: Vec<u8> = [-5i16, 300].iter().flat_map(|v| v.to_be_bytes()).collect();
        let e16 = encode_samples(be16, SampleType::I16, ByteOrder::Big).unwrap();
        assert_eq!((real(&e16, 0), real(&e16, 1)), (-5.0, 300.0));
        let e = encode_samples(raw, SampleType::F32, ByteOrder::Big).unwrap();
        assert_eq!(e.voxels.code(0), 0);
        assert_eq!(e.voxels.code(2), 65535);
        assert!((real(&e, 1) - 0.25).abs() < 3.5 / 65535.0);
        assert_eq!(real(&e, 2), 2.0);
        // Whole-number floats (a label map saved as float) stay exact.
        let raw: Vec<u8> = [0.0f64, 17.0, 116.0].iter().flat_map(|v| v.to_le_bytes()).collect();
        let e = encode_samples(raw, SampleType::F64, ByteOrder::Little).unwrap();
        assert_eq!(e.voxels, Voxels::U16(vec![0, 17, 116]));
    }

    #[test]
    fn nan_is_no_data_below_every_value() {
        let raw: Vec<u8> = [-1.5f32, f32::NAN, 0.25, 2.0].iter().flat_map(|v| v.to_le_bytes()).collect();
        let e = encode_samples(raw, SampleType::F32, ByteOrder::Little).unwrap();
        assert_eq!(e.map.no_data, Some(0));
        assert_eq!([0, 1, 3].map(|i| e.voxels.code(i)), [NO_DATA_GAP, 0, 65535]);
        assert_eq!((real(&e, 0), real(&e, 3)), (-1.5, 2.0));
        assert!((real(&e, 2) - 0.25).abs() < 3.5 / 65503.0);
        assert!(real(&e, 1) < -1.5);
        assert_eq!((e.map.describe(0).as_str(), e.map.describe(65535).as_str()), ("no data (NaN)", "2"));
        // Whole numbers stay exact, shifted past the gap.
        let raw: Vec<u8> = [f64::NAN, 3.0, 7.0].iter().flat_map(|v| v.to_le_bytes()).collect();
        let e = encode_samples(raw, SampleType::F64, ByteOrder::Little).unwrap();
        assert_eq!(e.voxels, Voxels::U16(vec![0, NO_DATA_GAP, NO_DATA_GAP + 4]));
        assert_eq!((real(&e, 1), real(&e, 2)), (3.0, 7.0));
    }

    #[test]
    fn non_finite_and_ragged_input_are_errors() {
        let raw: Vec<u8> = [1.0f32, f32::INFINITY].iter().flat_map(|v| v.to_le_bytes()).collect();
        let err = encode_samples(raw, SampleType::F32, ByteOrder::Little).unwrap_err();
        assert!(err.contains("infinite"), "{err}");
        let raw: Vec<u8> = [f32::NAN, f32::NAN].iter().flat_map(|v| v.to_le_bytes()).collect();
        let err = encode_samples(raw, SampleType::F32, ByteOrder::Little).unwrap_err();
        assert!(err.contains("all 2") && err.contains("NaN"), "{err}");
        assert!(encode_samples(vec![1, 2, 3], SampleType::I16, ByteOrder::Little).is_err());
        assert!(encode_samples(vec![], SampleType::I32, ByteOrder::Little).is_err());
    }

    #[test]
    fn wide_ranges_are_quantised() {
        let raw: Vec<u8> = [0i32, 100_000, 1_000_000].iter().flat_map(|v| v.to_le_bytes()).collect();
        let e = encode_samples(raw, SampleType::I32, ByteOrder::Little).unwrap();
        assert_eq!(real(&e, 2), 1_000_000.0);
        assert!((real(&e, 1) - 100_000.0).abs() <= 1_000_000.0 / 65535.0);
    }
}
