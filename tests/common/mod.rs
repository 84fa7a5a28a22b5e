//! Helpers shared by the integration tests.
// Each test crate uses some of these helpers, none uses all of them.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// A file of the shared real datasets (`../shared/data`, or `$FOCAL_DATA`).
pub fn data(rel: &str) -> PathBuf {
    let root =
        std::env::var_os("FOCAL_DATA").map(PathBuf::from).unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data"));
    let p = root.join(rel);
    assert!(p.exists(), "test data {} is missing (expected the shared datasets beside the project)", p.display());
    p
}

/// A fresh scratch directory for one test.
pub fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("focal-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("scratch directory");
    d
}

/// Writes fuel (`ct/fuel.nii.gz`) to `path` as a float32 NIfTI whose zero voxels are NaN,
/// as masking and resampling tools write them.
pub fn masked_fuel_nifti(path: &Path) {
    let mut nii = Vec::new();
    std::io::Read::read_to_end(&mut flate2::read::GzDecoder::new(std::fs::File::open(data("ct/fuel.nii.gz")).unwrap()), &mut nii).unwrap();
    let offset = f32::from_le_bytes(nii[108..112].try_into().unwrap()) as usize;
    let (slope, inter) = (f32::from_le_bytes(nii[112..116].try_into().unwrap()), f32::from_le_bytes(nii[116..120].try_into().unwrap()));
    let slope = if slope == 0.0 { 1.0 } else { slope };
    let mut out = nii[..offset].to_vec();
    out[70..72].copy_from_slice(&16i16.to_le_bytes()); // datatype float32
    out[72..74].copy_from_slice(&32i16.to_le_bytes()); // bitpix
    out[112..116].copy_from_slice(&1.0f32.to_le_bytes()); // scl_slope
    out[116..120].copy_from_slice(&0.0f32.to_le_bytes()); // scl_inter
    for &c in &nii[offset..] {
        let v = c as f32 * slope + inter;
        out.extend((if v == 0.0 { f32::NAN } else { v }).to_le_bytes());
    }
    std::fs::write(path, out).unwrap();
}
