//! The sampling-rate lens (Wang et al. 2005, §3.3, equations 5–7): ray directions stay,
//! ray start points are re-spaced.
//!
//! A sampling-rate function `S(x) > 0` over the lens radius gives the density of rays
//! per unit of source distance at source radius `x`. A pixel at radial coordinate `r`
//! starts its ray at the source radius `ρ` with `∫₀^ρ S(x) dx = r` (eq. 6), i.e. at the
//! camera ray through the image point `c + (s − c)·ρ/r`. The lens conserves its rays,
//! `∫₀^lr S(x) dx = lr` (eq. 5), so the rim maps onto itself and the image is
//! continuous there; where `S > 1` the data is magnified `S` times, where `S < 1`
//! compressed.
//!
//! Built-in cubic (eq. 7, in `t = x/lr`): `S(t) = a + (6 − 6a)t + (9a − 9)t² + (4 − 4a)t³`,
//! the cubic with rate `a` at the centre (the paper uses 3), rate 1 and slope 0 at the
//! rim (so the lens is C1 there) and `∫₀¹ S = 1`; its minimum `(5 − a)/4` at `t = ½` is
//! positive for `1 ≤ a < 5`. A user-drawn function (samples at equal steps, linear in
//! between) is scaled to satisfy eq. 5.
//!
//! Both are baked into [`TABLE_SIZE`] values of `ρ/lr` at equal steps of `r/lr`,
//! interpolated linearly by the CPU reference and the shader alike.

use serde::{Deserialize, Serialize};

/// Entries of the baked `ρ(r)/lr` table.
pub const TABLE_SIZE: usize = 64;
/// Most samples of a user-drawn sampling function.
pub const MAX_CUSTOM_SAMPLES: usize = 64;

/// A sampling-rate function over the lens radius.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sampling {
    /// The built-in cubic with this rate at the centre.
    Cubic { center_rate: f32 },
    /// A drawn function: rates at equal steps from the centre (first) to the rim (last).
    Custom(Vec<f32>),
}

impl Default for Sampling {
    fn default() -> Self {
        Sampling::Cubic { center_rate: 3.0 }
    }
}

impl Sampling {
    /// Checks the function.
    pub fn validate(&self) -> Result<(), String> {
        match self {
            Sampling::Cubic { center_rate } if !(1.0..5.0).contains(center_rate) => {
                Err(format!("the cubic sampling rate at the centre must lie in [1, 5), not {center_rate}"))
            }
            Sampling::Custom(s) if s.len() < 2 || s.len() > MAX_CUSTOM_SAMPLES => {
                Err(format!("a drawn sampling function needs 2 to {MAX_CUSTOM_SAMPLES} samples, not {}", s.len()))
            }
            Sampling::Custom(s) if s.iter().any(|v| !v.is_finite() || *v <= 0.0) => {
                Err("a drawn sampling function must be positive everywhere".into())
            }
            _ => Ok(()),
        }
    }

    /// The normalised rate `S(t)` at `t = x/lr ∈ [0, 1]` (eq. 5 holds: `∫₀¹ S = 1`).
    pub fn rate(&self, t: f32) -> f32 {
        let t = t.clamp(0.0, 1.0);
        match self {
            Sampling::Cubic { center_rate: a } => a + (6.0 - 6.0 * a) * t + (9.0 * a - 9.0) * t * t + (4.0 - 4.0 * a) * t * t * t,
            Sampling::Custom(s) => {
                let x = t * (s.len() - 1) as f32;
                let i = (x.floor() as usize).min(s.len() - 2);
                let f = x - i as f32;
                (s[i] * (1.0 - f) + s[i + 1] * f) / custom_integral(s)
            }
        }
    }

    /// `R(t) = ∫₀ᵗ S` (exact: polynomial or trapezoids).
    pub fn integral(&self, t: f32) -> f32 {
        let t = t.clamp(0.0, 1.0);
        match self {
            Sampling::Cubic { center_rate: a } => a * t + (3.0 - 3.0 * a) * t * t + (3.0 * a - 3.0) * t * t * t + (1.0 - a) * t * t * t * t,
            Sampling::Custom(s) => {
                let n = (s.len() - 1) as f32;
                let x = t * n;
                let full = (x.floor() as usize).min(s.len() - 1);
                let mut sum: f32 = s.windows(2).take(full).map(|w| 0.5 * (w[0] + w[1]) / n).sum();
                if full < s.len() - 1 {
                    let f = x - full as f32;
                    let end = s[full] * (1.0 - f) + s[full + 1] * f;
                    sum += 0.5 * (s[full] + end) * f / n;
                }
                sum / custom_integral(s)
            }
        }
    }

    /// The source radius `ρ/lr` of radial coordinate `r/lr` (eq. 6 inverted by bisection).
    pub fn source(&self, r: f32) -> f32 {
        let r = r.clamp(0.0, 1.0);
        let (mut lo, mut hi) = (0.0f32, 1.0f32);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if self.integral(mid) < r {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    /// The baked table of `ρ/lr` at `r/lr = i/(TABLE_SIZE − 1)`.
    pub fn table(&self) -> [f32; TABLE_SIZE] {
        std::array::from_fn(|i| self.source(i as f32 / (TABLE_SIZE - 1) as f32))
    }
}

fn custom_integral(s: &[f32]) -> f32 {
    let n = (s.len() - 1) as f32;
    s.windows(2).map(|w| 0.5 * (w[0] + w[1]) / n).sum::<f32>().max(1e-12)
}

/// Looks `r/lr` up in a baked table (linear interpolation).
pub fn lookup(table: &[f32; TABLE_SIZE], r: f32) -> f32 {
    let x = r.clamp(0.0, 1.0) * (TABLE_SIZE - 1) as f32;
    let i = (x.floor() as usize).min(TABLE_SIZE - 2);
    let f = x - i as f32;
    table[i] * (1.0 - f) + table[i + 1] * f
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Simpson's rule, independent of the closed forms.
    fn simpson(s: &Sampling, a: f32, b: f32) -> f32 {
        let n = 200;
        let h = (b - a) / n as f32;
        (0..=n)
            .map(|i| {
                let w = if i == 0 || i == n {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                w * s.rate(a + i as f32 * h)
            })
            .sum::<f32>()
            * h
            / 3.0
    }

    fn functions() -> Vec<Sampling> {
        vec![
            Sampling::Cubic { center_rate: 3.0 },
            Sampling::Cubic { center_rate: 1.5 },
            Sampling::Cubic { center_rate: 4.5 },
            Sampling::Custom(vec![4.0, 4.0, 1.0, 0.5, 1.0]),
            Sampling::Custom(vec![2.0, 1.0]),
        ]
    }

    #[test]
    fn every_function_integrates_to_the_lens_radius() {
        for s in functions() {
            assert!((simpson(&s, 0.0, 1.0) - 1.0).abs() < 1e-3, "{s:?}");
            assert!((s.integral(1.0) - 1.0).abs() < 1e-5, "{s:?}");
            for t in [0.1, 0.37, 0.5, 0.8] {
                assert!((s.integral(t) - simpson(&s, 0.0, t)).abs() < 2e-3, "{s:?} at {t}");
            }
        }
    }

    #[test]
    fn cubic_by_hand() {
        // a = 3: S = 3 − 12t + 18t² − 8t³: S(0) = 3, S(½) = 0.5, S(1) = 1, S'(1) = 0.
        let s = Sampling::Cubic { center_rate: 3.0 };
        assert!((s.rate(0.0) - 3.0).abs() < 1e-6);
        assert!((s.rate(0.5) - 0.5).abs() < 1e-6);
        assert!((s.rate(1.0) - 1.0).abs() < 1e-6);
        assert!((s.rate(1.0) - s.rate(0.999)).abs() < 1e-4);
        // R(½) = 1.5 − 1.5 + 0.75 − 0.125 = 0.625 (with a = 3: 3t − 6t² + 6t³ − 2t⁴).
        assert!((s.integral(0.5) - 0.625).abs() < 1e-6);
        assert!((s.source(0.625) - 0.5).abs() < 1e-5);
        // Near the centre the data is magnified 3×: ρ ≈ r/3.
        assert!((s.source(0.003) - 0.001).abs() < 1e-5);
    }

    #[test]
    fn tables_interpolate_the_inverse() {
        for s in functions() {
            let table = s.table();
            assert_eq!(table[0], 0.0f32.max(table[0]));
            assert!((table[TABLE_SIZE - 1] - 1.0).abs() < 1e-5);
            for i in 0..=50 {
                let r = i as f32 / 50.0;
                assert!((lookup(&table, r) - s.source(r)).abs() < 4e-3, "{s:?} at {r}");
            }
        }
        assert!(Sampling::Cubic { center_rate: 6.0 }.validate().is_err());
        assert!(Sampling::Custom(vec![1.0, 0.0]).validate().is_err());
    }
}
