//! Compact voxel storage and the map from stored codes to real-world values.
//!
//! Voxels are kept as unsigned 8- or 16-bit *codes*, the formats a GPU samples as
//! normalised textures (`R8Unorm`, `R16Unorm`): 8-bit data stays 8-bit, 16-bit data
//! stays 16-bit. A [`ValueMap`] turns a code into the real value (Hounsfield units,
//! MR signal, density, …): `real = code · slope + intercept`. It folds together the
//! file's own rescale (DICOM Rescale Slope/Intercept, NIfTI `scl_slope`/`scl_inter`) and
//! the offset or quantisation used to fit the source type into the codes.
//!
//! Normalised texture value `t = code / code_max` (255 or 65535), so
//! `real = t · code_max · slope + intercept`.

use serde::{Deserialize, Serialize};

/// Voxel codes, x fastest, then y, then z.
#[derive(Clone, Debug, PartialEq)]
pub enum Voxels {
    U8(Vec<u8>),
    U16(Vec<u16>),
}

impl Voxels {
    pub fn len(&self) -> usize {
        match self {
            Voxels::U8(v) => v.len(),
            Voxels::U16(v) => v.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Bits per stored code.
    pub fn bits(&self) -> u32 {
        match self {
            Voxels::U8(_) => 8,
            Voxels::U16(_) => 16,
        }
    }

    /// The largest code of the storage type: the normalisation denominator.
    pub fn code_max(&self) -> u32 {
        match self {
            Voxels::U8(_) => u8::MAX as u32,
            Voxels::U16(_) => u16::MAX as u32,
        }
    }

    /// Code at a linear index.
    #[inline]
    pub fn code(&self, index: usize) -> u16 {
        match self {
            Voxels::U8(v) => v[index] as u16,
            Voxels::U16(v) => v[index],
        }
    }

    /// The codes as bytes (little-endian on every supported target), for GPU upload.
    pub fn as_bytes(&self) -> &[u8] {
        match self {
            Voxels::U8(v) => v,
            Voxels::U16(v) => bytemuck::cast_slice(v),
        }
    }

    /// Storage in bytes.
    pub fn byte_len(&self) -> usize {
        self.as_bytes().len()
    }
}

/// Affine map from stored code to real value, with the unit of the real value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ValueMap {
    pub slope: f64,
    pub intercept: f64,
    /// Unit of the real value, e.g. `"HU"`; `None` when the file does not say.
    pub units: Option<String>,
    /// The code that stands for no value (NaN samples of a float file, drawn as empty
    /// space and left out of the statistics: `encode`, `stats`, `Lut::for_volume`). Its
    /// real value lies below every true value.
    #[serde(default)]
    pub no_data: Option<u16>,
}

impl Default for ValueMap {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl ValueMap {
    pub const IDENTITY: ValueMap = ValueMap { slope: 1.0, intercept: 0.0, units: None, no_data: None };

    pub fn new(slope: f64, intercept: f64) -> Self {
        Self { slope, intercept, units: None, no_data: None }
    }

    /// A value as the probes write it: the real value and its unit, or no data.
    pub fn describe(&self, code: u32) -> String {
        if self.no_data.is_some_and(|c| c as u32 == code) {
            return "no data (NaN)".into();
        }
        let units = self.units.as_deref().map(|u| format!(" {u}")).unwrap_or_default();
        format!("{}{units}", self.to_real(code as f64))
    }

    #[inline]
    pub fn to_real(&self, code: f64) -> f64 {
        code * self.slope + self.intercept
    }

    /// The (fractional) code of a real value.
    #[inline]
    pub fn to_code(&self, real: f64) -> f64 {
        (real - self.intercept) / self.slope
    }

    /// Applies a further rescale `real' = real · slope + intercept` (e.g. a file's rescale
    /// on top of the storage offset).
    pub fn then(&self, slope: f64, intercept: f64) -> ValueMap {
        ValueMap {
            slope: self.slope * slope,
            intercept: self.intercept * slope + intercept,
            units: self.units.clone(),
            no_data: self.no_data,
        }
    }

    pub fn with_units(mut self, units: Option<String>) -> Self {
        self.units = units;
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_map_composes() {
        // Storage: code = raw + 1024 (raw int16 from -1024), then a file rescale 2x - 5.
        let m = ValueMap::new(1.0, -1024.0).then(2.0, -5.0);
        assert_eq!(m.to_real(1024.0), -5.0);
        assert_eq!(m.to_real(0.0), -2053.0);
        assert_eq!(m.to_code(m.to_real(77.0)), 77.0);
    }

    #[test]
    fn bytes_are_little_endian_codes() {
        let v = Voxels::U16(vec![0x0102, 0xffff]);
        assert_eq!(v.as_bytes(), &[0x02, 0x01, 0xff, 0xff]);
        assert_eq!(v.code_max(), 65535);
        assert_eq!(Voxels::U8(vec![7]).code(0), 7);
    }
}
