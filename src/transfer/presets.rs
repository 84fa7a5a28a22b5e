//! Transfer-function presets: the files in `assets/transfer/`, embedded in the binary,
//! and user files in the same RON format.

use std::path::Path;

use super::function::TransferFunction;
use crate::volume::Volume;

/// The built-in presets: (file stem, RON text).
const BUILTIN: &[(&str, &str)] = &[
    ("ct_skin_bone", include_str!("../../assets/transfer/ct_skin_bone.ron")),
    ("ct_bone", include_str!("../../assets/transfer/ct_bone.ron")),
    ("ct_vessels", include_str!("../../assets/transfer/ct_vessels.ron")),
    ("ct_soft_tissue", include_str!("../../assets/transfer/ct_soft_tissue.ron")),
    ("mr_default", include_str!("../../assets/transfer/mr_default.ron")),
    ("grayscale_ramp", include_str!("../../assets/transfer/grayscale_ramp.ron")),
    ("industrial_ct", include_str!("../../assets/transfer/industrial_ct.ron")),
];

/// Parses a transfer function from RON text; `origin` names it in errors.
pub fn parse(text: &str, origin: &str) -> Result<TransferFunction, String> {
    let tf: TransferFunction = ron::from_str(text).map_err(|e| format!("{origin}: {e}"))?;
    tf.validated().map_err(|e| format!("{origin}: {e}"))
}

/// Keys of the built-in presets (`ct_bone`, `mr_default`, …).
pub fn names() -> impl Iterator<Item = &'static str> {
    BUILTIN.iter().map(|(k, _)| *k)
}

/// A built-in preset by key or display name (case-insensitive).
pub fn builtin(key: &str) -> Result<TransferFunction, String> {
    let want = key.trim().to_ascii_lowercase();
    for (k, text) in BUILTIN {
        let tf = parse(text, &format!("assets/transfer/{k}.ron"))?;
        if *k == want || tf.name.to_ascii_lowercase() == want {
            return Ok(tf);
        }
    }
    Err(format!("unknown transfer-function preset '{key}' (built in: {})", names().collect::<Vec<_>>().join(", ")))
}

/// A preset by key, or a `.ron` file path.
pub fn load(key_or_path: &str) -> Result<TransferFunction, String> {
    let p = Path::new(key_or_path);
    if key_or_path.ends_with(".ron") || p.is_file() {
        let text = std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?;
        return parse(&text, &p.display().to_string());
    }
    builtin(key_or_path)
}

/// Like [`load`], with a `.ron` path taken relative to `base` (a scene file's folder).
pub fn load_relative(key_or_path: &str, base: &Path) -> Result<TransferFunction, String> {
    if key_or_path.ends_with(".ron") { load(&base.join(key_or_path).display().to_string()) } else { load(key_or_path) }
}

/// The preset a medical viewer would open a volume with: skin and bone for CT (values
/// in Hounsfield units), the MR default otherwise.
pub fn default_for(volume: &Volume) -> Result<TransferFunction, String> {
    match volume.values.units.as_deref() {
        Some("HU") => builtin("ct_skin_bone"),
        _ => builtin("mr_default"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_parses() {
        for k in names() {
            let tf = builtin(k).unwrap();
            assert!(!tf.color.is_empty() && !tf.opacity.is_empty(), "{k}");
        }
        assert_eq!(builtin("CT bone").unwrap().name, "CT bone");
        assert!(builtin("nope").unwrap_err().contains("ct_bone"));
    }

    #[test]
    fn errors_name_the_origin() {
        let e = parse("(name: \"x\", colour: [])", "my.ron").unwrap_err();
        assert!(e.starts_with("my.ron"), "{e}");
        let e = parse("(name: \"x\", color: [(0.0, (2.0, 0.0, 0.0))], opacity: [(0.0, 0.5)])", "bad.ron").unwrap_err();
        assert!(e.contains("outside 0..1"), "{e}");
    }
}
