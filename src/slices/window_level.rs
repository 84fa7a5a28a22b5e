//! Window and level: which data values a slice shows as greys.
//!
//! The linear VOI function of DICOM PS3.3 C.11.2.1.2.1, with window centre `c` (the
//! level) and width `w` (both in the data's units, Hounsfield units for CT):
//!
//! ```text
//! x ≤ c − ½ − (w − 1)/2  →  0
//! x > c − ½ + (w − 1)/2  →  255
//! otherwise              →  ((x − (c − ½)) / (w − 1) + ½) · 255
//! ```
//!
//! (for `w ≥ 1`; narrower windows are a threshold at `c`). Presets are the CT windows
//! radiology viewers offer; "auto" spans the 1st to 99th percentile of the dataset's
//! values (`ValueStats`), which shows any modality's tissue without saturating on a few
//! outliers.

use crate::volume::stats::ValueStats;

/// A window of data values (centre and width, the data's units).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WindowLevel {
    pub width: f64,
    pub level: f64,
}

/// The CT presets: (name, width, level) in Hounsfield units.
pub const CT_PRESETS: [(&str, f64, f64); 4] =
    [("soft tissue", 400.0, 40.0), ("lung", 1500.0, -600.0), ("bone", 1800.0, 400.0), ("brain", 80.0, 40.0)];

impl WindowLevel {
    pub fn new(width: f64, level: f64) -> WindowLevel {
        WindowLevel { width, level }
    }

    /// The 1st to 99th percentile of the values (all of them where those coincide).
    pub fn auto(stats: &ValueStats) -> WindowLevel {
        let (lo, hi) = if stats.p99 > stats.p01 { (stats.p01, stats.p99) } else { (stats.min, stats.max) };
        WindowLevel { width: (hi - lo).max(1.0), level: 0.5 * (lo + hi) }
    }

    /// A CT preset by name (`soft tissue`, `soft`, `lung`, `bone`, `brain`; any case).
    pub fn preset(name: &str) -> Result<WindowLevel, String> {
        let want = name.trim().to_ascii_lowercase();
        let want = if want == "soft" { "soft tissue".to_string() } else { want };
        CT_PRESETS.iter().find(|(n, ..)| *n == want).map(|(_, w, l)| WindowLevel::new(*w, *l)).ok_or_else(|| {
            let names: Vec<&str> = CT_PRESETS.iter().map(|(n, ..)| *n).collect();
            format!("'{name}' is not a window preset ({}, or auto)", names.join(", "))
        })
    }

    /// The grey (0–255) of data value `x` (module doc).
    pub fn grey(&self, x: f64) -> u8 {
        let (c, w) = (self.level, self.width);
        if !x.is_finite() {
            return 0;
        }
        if w < 1.0 {
            return if x > c - 0.5 { 255 } else { 0 };
        }
        if x <= c - 0.5 - (w - 1.0) / 2.0 {
            0
        } else if x > c - 0.5 + (w - 1.0) / 2.0 {
            255
        } else {
            (((x - (c - 0.5)) / (w - 1.0) + 0.5) * 255.0).round().clamp(0.0, 255.0) as u8
        }
    }

    /// The window after a drag of (dx, dy) pixels with the right mouse button, as
    /// radiology viewers do it: right widens, down raises the level, by `per_pixel` data
    /// units a pixel (a fraction of the value range).
    pub fn dragged(&self, dx: f32, dy: f32, per_pixel: f64) -> WindowLevel {
        WindowLevel { width: (self.width + dx as f64 * per_pixel).max(1.0), level: self.level + dy as f64 * per_pixel }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_dicom_linear_function_by_hand() {
        // Soft tissue, W 400 L 40: the window runs from −160.5 to 239.5 (w − 1 = 399).
        let wl = WindowLevel::new(400.0, 40.0);
        assert_eq!(wl.grey(-1000.0), 0);
        assert_eq!(wl.grey(-160.5), 0);
        assert_eq!(wl.grey(240.0), 255);
        // x = 39.5 = c − ½: exactly mid-grey, 0.5 · 255 = 127.5 → 128.
        assert_eq!(wl.grey(39.5), 128);
        // x = 139.25: (139.25 − 39.5)/399 + ½ = 0.75 → 191.25 → 191.
        assert_eq!(wl.grey(139.25), 191);
        // A window narrower than one unit thresholds at the level.
        let t = WindowLevel::new(0.5, 100.0);
        assert_eq!((t.grey(99.0), t.grey(100.0)), (0, 255));
        assert_eq!(wl.grey(f64::NAN), 0);
    }

    #[test]
    fn presets_and_auto() {
        assert_eq!(WindowLevel::preset("Lung"), Ok(WindowLevel::new(1500.0, -600.0)));
        assert_eq!(WindowLevel::preset("soft"), Ok(WindowLevel::new(400.0, 40.0)));
        assert!(WindowLevel::preset("liver").unwrap_err().contains("bone"));
        let v = crate::volume::phantom::sphere(16, 5.0).unwrap();
        let auto = WindowLevel::auto(&v.stats);
        assert!(auto.width >= 1.0 && auto.level >= v.stats.min && auto.level <= v.stats.max);
        // Right widens, down raises the level.
        let d = WindowLevel::new(400.0, 40.0).dragged(10.0, -5.0, 2.0);
        assert_eq!(d, WindowLevel::new(420.0, 30.0));
    }
}
