//! 1D piecewise-linear transfer functions over the real value range.
//!
//! Colour and opacity have separate control-point lists (as in VTK and ParaView), each
//! sorted by value and interpolated linearly, constant beyond the ends. Points are in
//! real units (`Absolute`, e.g. Hounsfield units, for CT presets) or as fractions of the
//! volume's value range (`Relative`, for MR and other arbitrary-unit data).

use serde::{Deserialize, Serialize};

/// How control-point values are to be read.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub enum ValueSpace {
    /// Real values in the volume's units.
    #[default]
    Absolute,
    /// Fractions of the volume's `[min, max]`.
    Relative,
}

/// A colour control point.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ColorPoint(pub f64, pub [f32; 3]);

/// An opacity control point (opacity per reference length, see [`super::opacity`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct OpacityPoint(pub f64, pub f32);

/// A transfer function.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TransferFunction {
    pub name: String,
    #[serde(default)]
    pub space: ValueSpace,
    /// Units the absolute values are meant for (`"HU"`), if any: a CT preset on MR data
    /// is flagged rather than silently applied.
    #[serde(default)]
    pub units: Option<String>,
    pub color: Vec<ColorPoint>,
    pub opacity: Vec<OpacityPoint>,
    /// λt of context-preserving rendering (section 5 of Bruckner et al. 2005), in 0..1
    /// per value: multiplies κt; 0 makes the value range impenetrable. None: 1 everywhere.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub lambda_t: Vec<OpacityPoint>,
    /// λs: multiplies κs; 0 reduces the value range to gradient-magnitude modulation.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub lambda_s: Vec<OpacityPoint>,
}

impl TransferFunction {
    /// Checks and sorts the control points.
    pub fn validated(mut self) -> Result<Self, String> {
        if self.color.is_empty() || self.opacity.is_empty() {
            return Err(format!("transfer function '{}' needs at least one colour and one opacity point", self.name));
        }
        for ColorPoint(v, c) in &self.color {
            if !v.is_finite() || c.iter().any(|x| !x.is_finite() || !(0.0..=1.0).contains(x)) {
                return Err(format!("'{}': colour point at {v} has a component outside 0..1", self.name));
            }
        }
        for (channel, points) in [("opacity", &self.opacity), ("lambda_t", &self.lambda_t), ("lambda_s", &self.lambda_s)] {
            for OpacityPoint(v, a) in points {
                if !v.is_finite() || !a.is_finite() || !(0.0..=1.0).contains(a) {
                    return Err(format!("'{}': {channel} point at {v} is {a}, outside 0..1", self.name));
                }
            }
        }
        self.color.sort_by(|a, b| a.0.total_cmp(&b.0));
        for points in [&mut self.opacity, &mut self.lambda_t, &mut self.lambda_s] {
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
        Ok(self)
    }

    /// Converts relative points to absolute values for a volume with value range
    /// `[min, max]`.
    pub fn resolved(&self, min: f64, max: f64) -> TransferFunction {
        match self.space {
            ValueSpace::Absolute => self.clone(),
            ValueSpace::Relative => {
                let to = |f: f64| min + f * (max - min);
                TransferFunction {
                    name: self.name.clone(),
                    space: ValueSpace::Absolute,
                    units: None,
                    color: self.color.iter().map(|&ColorPoint(v, c)| ColorPoint(to(v), c)).collect(),
                    opacity: self.opacity.iter().map(|&OpacityPoint(v, a)| OpacityPoint(to(v), a)).collect(),
                    lambda_t: self.lambda_t.iter().map(|&OpacityPoint(v, a)| OpacityPoint(to(v), a)).collect(),
                    lambda_s: self.lambda_s.iter().map(|&OpacityPoint(v, a)| OpacityPoint(to(v), a)).collect(),
                }
            }
        }
    }

    /// Colour at a value (points must be absolute and sorted).
    pub fn color_at(&self, value: f64) -> [f32; 3] {
        let pts: Vec<(f64, [f32; 3])> = self.color.iter().map(|p| (p.0, p.1)).collect();
        piecewise(&pts, value, |a, b, t| std::array::from_fn(|i| a[i] + (b[i] - a[i]) * t))
    }

    /// Opacity at a value (points must be absolute and sorted).
    pub fn opacity_at(&self, value: f64) -> f32 {
        scalar_at(&self.opacity, value, 0.0)
    }

    /// (λt, λs) at a value, 1 where a channel has no points.
    pub fn lambda_at(&self, value: f64) -> [f32; 2] {
        [scalar_at(&self.lambda_t, value, 1.0), scalar_at(&self.lambda_s, value, 1.0)]
    }

    /// Smallest and largest value with non-zero opacity, if any.
    pub fn visible_range(&self) -> Option<(f64, f64)> {
        let n = self.opacity.len();
        let mut lo = None;
        let mut hi = None;
        for i in 0..n {
            if self.opacity[i].1 > 0.0 {
                let left = if i > 0 { self.opacity[i - 1].0 } else { f64::NEG_INFINITY };
                let right = if i + 1 < n { self.opacity[i + 1].0 } else { f64::INFINITY };
                lo = Some(lo.map_or(left, |l: f64| l.min(left)));
                hi = Some(hi.map_or(right, |h: f64| h.max(right)));
            }
        }
        lo.zip(hi)
    }
}

/// A scalar channel at a value; `empty` when it has no points.
fn scalar_at(points: &[OpacityPoint], value: f64, empty: f32) -> f32 {
    if points.is_empty() {
        return empty;
    }
    let pts: Vec<(f64, f32)> = points.iter().map(|p| (p.0, p.1)).collect();
    piecewise(&pts, value, |a, b, t| a + (b - a) * t)
}

/// Piecewise-linear interpolation over sorted `(x, y)` points, constant outside.
pub fn piecewise<T: Copy>(pts: &[(f64, T)], x: f64, lerp: impl Fn(T, T, f32) -> T) -> T {
    let first = pts[0];
    if x <= first.0 || pts.len() == 1 {
        return first.1;
    }
    for w in pts.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        if x <= x1 {
            let t = if x1 > x0 { ((x - x0) / (x1 - x0)) as f32 } else { 1.0 };
            return lerp(y0, y1, t);
        }
    }
    pts[pts.len() - 1].1
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tf() -> TransferFunction {
        TransferFunction {
            name: "t".into(),
            space: ValueSpace::Absolute,
            units: None,
            color: vec![ColorPoint(100.0, [1.0, 0.0, 0.0]), ColorPoint(0.0, [0.0, 0.0, 1.0])],
            lambda_t: vec![],
            lambda_s: vec![],
            opacity: vec![OpacityPoint(0.0, 0.0), OpacityPoint(100.0, 0.5), OpacityPoint(200.0, 0.0)],
        }
        .validated()
        .unwrap()
    }

    #[test]
    fn interpolates_linearly_and_clamps() {
        let t = tf();
        assert_eq!(t.color_at(50.0), [0.5, 0.0, 0.5]);
        assert_eq!(t.color_at(-10.0), [0.0, 0.0, 1.0]);
        assert_eq!(t.color_at(1e9), [1.0, 0.0, 0.0]);
        assert_eq!(t.opacity_at(150.0), 0.25);
        assert_eq!(t.opacity_at(250.0), 0.0);
        assert_eq!(t.visible_range(), Some((0.0, 200.0)));
    }

    #[test]
    fn relative_points_follow_the_data_range() {
        let mut t = tf();
        t.space = ValueSpace::Relative;
        t.opacity = vec![OpacityPoint(0.0, 0.0), OpacityPoint(1.0, 1.0)];
        let r = t.resolved(-1000.0, 3000.0);
        assert_eq!(r.opacity_at(1000.0), 0.5);
    }

    #[test]
    fn rejects_out_of_range_points() {
        let mut t = tf();
        t.opacity.push(OpacityPoint(5.0, 1.5));
        assert!(t.validated().is_err());
        let mut t = tf();
        t.color.clear();
        assert!(t.validated().is_err());
    }
}
