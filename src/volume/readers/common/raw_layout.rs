//! The layout of headerless raw data, [`RawSpec`] (from the command line or a `.dat`
//! file), and sample type names.
//!
//! Spec syntax (command line `--raw`): `DIMS:TYPE[:le|be][:s=SPACING][:skip=BYTES]`, for
//! example `256x256x128:uint8` or `512x512x300:int16:be:s=0.5x0.5x1:skip=1024`. A skip
//! of `-1` reads the data from the end of the file (a header of unknown size before it).

use glam::{UVec3, Vec3};

use crate::volume::encode::{ByteOrder, SampleType};

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
