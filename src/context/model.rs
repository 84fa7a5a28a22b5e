//! The context-preserving opacity of Bruckner, Grimm, Kanitsar and Gröller,
//! "Illustrative Context-Preserving Volume Rendering" (EuroVis 2005), as pure functions.
//!
//! Equation 5: the opacity of a sample P is the transfer function's opacity scaled by
//! the normalised gradient magnitude raised to a power that grows where the sample is
//! lit, near the eye and not yet hidden:
//!
//! ```text
//! α(P) = α_tf(f_P) · ‖g_P‖ ^ ((κt · s(P) · (1 − ‖P − E‖) · (1 − α_prev)) ^ κs)
//! ```
//!
//! - `‖g_P‖` ∈ [0, 1]: gradient magnitude over the volume's largest one;
//! - `s(P)` ∈ [0, 1]: Blinn-Phong intensity of equation 3, `ka + kd·(N·L)⁺ + ks·(N·H)⁺ⁿ`
//!   (1 without shading: nothing is singled out by light then);
//! - `‖P − E‖` ∈ [0, 1]: distance from the eye, normalised over the volume's extent along
//!   the ray (`0` where the ray enters the volume's bounding sphere, `1` where it leaves);
//! - `α_prev`: the opacity accumulated in front of P;
//! - `κt` (how far in the view reaches) and `κs` (how sharp the transition is) are the
//!   user's two parameters; the data-dependent `λt`, `λs` of section 5 multiply them per
//!   value: `λt = 0` makes a value range impenetrable (exponent 0, plain DVR), `λs = 0`
//!   reduces it to gradient-magnitude modulation (exponent 1).
//!
//! Limits the tests check: κt = 0 gives plain DVR (0^κs = 0, ‖g‖⁰ = 1); κs = 0 gives
//! gradient-magnitude modulation (x⁰ = 1, ‖g‖¹); `0⁰` is taken as 1.
//!
//! The outer power is evaluated by Schlick's approximation (equation 7),
//! `xⁿ ≈ x / (n − n·x + x)` for x ∈ [0, 1], n ≥ 0, by default, as in the paper; it is
//! exact at n = 0 and n = 1, so both limits above hold with it too. [`Power::Exact`]
//! uses `powf`. The inner power's base can exceed 1 (κt > 1), where Schlick's formula
//! does not hold, so it is always exact.

use serde::{Deserialize, Serialize};

/// How the outer power of equation 5 is evaluated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Power {
    /// Schlick's rational approximation (equation 7).
    #[default]
    Schlick,
    /// `powf`.
    Exact,
}

/// The two user parameters and the evaluation.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ContextParams {
    /// κt ≥ 0: how deep the view reaches into the volume.
    pub kappa_t: f32,
    /// κs ≥ 0: how sharp the boundary between clear and opaque is.
    pub kappa_s: f32,
    pub power: Power,
}

impl Default for ContextParams {
    fn default() -> Self {
        Self { kappa_t: 3.0, kappa_s: 0.5, power: Power::Schlick }
    }
}

impl ContextParams {
    /// Whether equation 5 is plain DVR with these parameters, for λs positive at every
    /// value (`lambda_s_positive`): with κt = 0 the exponent's base is 0, so the exponent
    /// is `0^(κs·λs)` = 0 and ‖g‖⁰ = 1 (Schlick's and the exact power alike), leaving
    /// α = α_TF; only where κs·λs = 0 is the exponent 0⁰ = 1 (gradient-modulated).
    /// The ray caster then takes DVR's cost path.
    pub fn is_plain_dvr(&self, lambda_s_positive: bool) -> bool {
        self.kappa_t == 0.0 && self.kappa_s > 0.0 && lambda_s_positive
    }

    /// Most useful ranges of the sliders.
    pub const KAPPA_T_MAX: f32 = 12.0;
    pub const KAPPA_S_MAX: f32 = 2.0;
    /// Step of κt per key press in the app.
    pub const KAPPA_T_STEP: f32 = 0.5;

    /// κt moved by `delta`, kept within the slider's range.
    pub fn with_kappa_t_step(self, delta: f32) -> Self {
        Self { kappa_t: (self.kappa_t + delta).clamp(0.0, Self::KAPPA_T_MAX), ..self }
    }

    /// Checks the parameters (finite, not negative).
    pub fn validated(self) -> Result<Self, String> {
        for (name, v) in [("kappa_t", self.kappa_t), ("kappa_s", self.kappa_s)] {
            if !v.is_finite() || v < 0.0 {
                return Err(format!("context-preserving {name} is {v}; it must be a number ≥ 0"));
            }
        }
        Ok(self)
    }
}

/// `x^n` with `0⁰ = 1` (x ≥ 0).
pub fn exact_pow(x: f32, n: f32) -> f32 {
    if n == 0.0 { 1.0 } else { x.max(0.0).powf(n) }
}

/// Schlick's approximation of `x^n` for x ∈ [0, 1], n ≥ 0 (equation 7), with `0⁰ = 1`.
pub fn schlick_pow(x: f32, n: f32) -> f32 {
    if n == 0.0 {
        return 1.0;
    }
    let x = x.clamp(0.0, 1.0);
    // Exact at n = 1 in exact arithmetic; in floats (1 − x) + x can miss 1 by an ulp.
    if n == 1.0 {
        return x;
    }
    if x == 0.0 {
        return 0.0;
    }
    x / (n - n * x + x)
}

/// The per-sample inputs of equation 5 besides the parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Opacity from the transfer function (already corrected for the step).
    pub alpha: f32,
    /// Gradient magnitude over the volume's largest, clamped to [0, 1].
    pub gradient: f32,
    /// Shading intensity s(P) ∈ [0, 1].
    pub shading: f32,
    /// Normalised eye distance ∈ [0, 1].
    pub eye_distance: f32,
    /// Opacity accumulated in front.
    pub alpha_prev: f32,
    /// λt, λs of the sample's value (section 5).
    pub lambda: [f32; 2],
}

/// The exponent of ‖g‖ in equation 5: `(κt·λt · s · (1 − ‖P − E‖) · (1 − α_prev))^(κs·λs)`.
pub fn exponent(p: &ContextParams, s: &Sample) -> f32 {
    let base = p.kappa_t * s.lambda[0] * s.shading * (1.0 - s.eye_distance) * (1.0 - s.alpha_prev);
    exact_pow(base.max(0.0), p.kappa_s * s.lambda[1])
}

/// Equation 5: the context-preserving opacity of a sample.
pub fn opacity(p: &ContextParams, s: &Sample) -> f32 {
    let e = exponent(p, s);
    let g = s.gradient.clamp(0.0, 1.0);
    let m = match p.power {
        Power::Schlick => schlick_pow(g, e),
        Power::Exact => exact_pow(g, e),
    };
    s.alpha * m
}

/// Normalised eye distance of the sample at ray parameter `t` for a volume whose
/// bounding sphere (centre `c`, radius `r`) the ray `origin + t·dir` (unit `dir`) meets:
/// 0 at the sphere's near side along the ray, 1 at its far side, clamped.
pub fn eye_distance(t: f32, origin: glam::Vec3, dir: glam::Vec3, centre: glam::Vec3, radius: f32) -> f32 {
    let t_near = (centre - origin).dot(dir) - radius;
    ((t - t_near) / (2.0 * radius).max(1e-12)).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn is_plain_dvr_holds_where_equation_5_leaves_the_opacity() {
        // κt = 0 with κs·λs > 0: α = α_TF for every sample (the test below checks eq. 5).
        let p = ContextParams { kappa_t: 0.0, kappa_s: 0.5, power: Power::Schlick };
        assert!(p.is_plain_dvr(true));
        for prev in [0.0, 0.5, 0.9] {
            let s = Sample { gradient: 0.3, alpha_prev: prev, ..sample() };
            assert_eq!(opacity(&p, &s), s.alpha);
        }
        // κs = 0, or λs = 0 somewhere: the exponent is 0⁰ = 1, α·‖g‖: not DVR.
        let flat = ContextParams { kappa_s: 0.0, ..p };
        assert!(!flat.is_plain_dvr(true) && !p.is_plain_dvr(false));
        assert_eq!(opacity(&flat, &Sample { gradient: 0.5, ..sample() }), 0.8 * 0.5);
        assert!(!ContextParams { kappa_t: 0.5, ..p }.is_plain_dvr(true));
    }

    fn sample() -> Sample {
        Sample { alpha: 0.8, gradient: 0.5, shading: 0.8, eye_distance: 0.25, alpha_prev: 0.2, lambda: [1.0, 1.0] }
    }

    #[test]
    fn equation_5_by_hand() {
        // base = 2·0.8·(1 − 0.25)·(1 − 0.2) = 0.96, exponent = 0.96^0.5 = 0.97980,
        // 0.5^0.97980 = 0.50705, α = 0.8·0.50705 = 0.40564.
        let exact = ContextParams { kappa_t: 2.0, kappa_s: 0.5, power: Power::Exact };
        assert!((exponent(&exact, &sample()) - 0.979_80).abs() < 1e-5);
        assert!((opacity(&exact, &sample()) - 0.405_64).abs() < 1e-5);
        // Schlick: 0.5 / (0.97980 − 0.97980·0.5 + 0.5) = 0.50510, α = 0.40408.
        let schlick = ContextParams { power: Power::Schlick, ..exact };
        assert!((opacity(&schlick, &sample()) - 0.404_08).abs() < 1e-5);
    }

    #[test]
    fn schlick_by_hand() {
        // 0.5/(2 − 1 + 0.5) = 1/3; 0.25/(0.5 − 0.125 + 0.25) = 0.4; exact at n = 0, 1.
        assert!((schlick_pow(0.5, 2.0) - 1.0 / 3.0).abs() < 1e-7);
        assert!((schlick_pow(0.25, 0.5) - 0.4).abs() < 1e-7);
        for x in [0.0, 0.1, 0.5, 1.0] {
            assert_eq!(schlick_pow(x, 0.0), 1.0);
            assert_eq!(schlick_pow(x, 1.0), x);
        }
    }

    #[test]
    fn kappa_t_zero_is_plain_dvr_and_kappa_s_zero_is_gradient_modulation() {
        for power in [Power::Schlick, Power::Exact] {
            for g in [0.0, 0.3, 1.0] {
                let s = Sample { gradient: g, ..sample() };
                let plain = ContextParams { kappa_t: 0.0, kappa_s: 0.7, power };
                assert_eq!(opacity(&plain, &s), s.alpha);
                let gradient = ContextParams { kappa_t: 4.0, kappa_s: 0.0, power };
                assert_eq!(opacity(&gradient, &s), s.alpha * g);
                // λt = 0: impenetrable; λs = 0: gradient modulation.
                let p = ContextParams { kappa_t: 4.0, kappa_s: 0.7, power };
                assert_eq!(opacity(&p, &Sample { lambda: [0.0, 1.0], ..s }), s.alpha);
                assert_eq!(opacity(&p, &Sample { lambda: [1.0, 0.0], ..s }), s.alpha * g);
            }
        }
    }

    #[test]
    fn opacity_falls_where_lit_near_and_unoccluded() {
        let p = ContextParams { kappa_t: 4.0, kappa_s: 0.5, power: Power::Exact };
        let s = sample();
        let near = opacity(&p, &Sample { eye_distance: 0.1, ..s });
        let far = opacity(&p, &Sample { eye_distance: 0.9, ..s });
        assert!(near < far, "{near} {far}");
        let hidden = opacity(&p, &Sample { alpha_prev: 0.95, ..s });
        assert!(hidden > opacity(&p, &s));
        let dark = opacity(&p, &Sample { shading: 0.05, ..s });
        assert!(dark > opacity(&p, &s));
        let stronger = ContextParams { kappa_t: 8.0, ..p };
        assert!(opacity(&stronger, &s) < opacity(&p, &s));
    }

    /// Largest difference between Schlick's approximation and the exact power over a
    /// grid of inputs, reported overall and where the exponent is at least 1 (Schlick's
    /// formula is meant for large exponents; below 1 it falls off far too fast near
    /// x = 0: 0.05^0.094 = 0.755 exactly, 0.36 by the formula).
    #[test]
    fn schlick_against_exact_on_a_grid() {
        let mut worst = [0.0f32; 2];
        let steps = |n: usize| (0..=n).map(move |i| i as f32 / n as f32);
        for kt in [0.5, 1.0, 2.0, 4.0, 8.0, 12.0] {
            for ks in [0.1, 0.25, 0.5, 1.0, 2.0] {
                for g in steps(20) {
                    for sh in steps(4) {
                        for d in steps(4) {
                            for a in steps(4) {
                                let s = Sample { alpha: 1.0, gradient: g, shading: sh, eye_distance: d, alpha_prev: a, lambda: [1.0, 1.0] };
                                let e = ContextParams { kappa_t: kt, kappa_s: ks, power: Power::Exact };
                                let diff = (opacity(&e, &s) - opacity(&ContextParams { power: Power::Schlick, ..e }, &s)).abs();
                                let k = usize::from(exponent(&e, &s) >= 1.0);
                                worst[0] = worst[0].max(diff);
                                worst[k] = worst[k].max(diff);
                            }
                        }
                    }
                }
            }
        }
        println!("Schlick vs exact, largest opacity difference: {:.3} overall, {:.3} where the exponent ≥ 1", worst[0], worst[1]);
        // Measured: 0.396 overall (exponent ≈ 0.1, ‖g‖ = 0.05), 0.198 for exponents ≥ 1.
        assert!(worst[0] < 0.4 && worst[1] < 0.2, "{worst:?}");
        assert!(worst[1] > 0.01, "the grid never exercised the approximation");
    }

    #[test]
    fn eye_distance_spans_the_bounding_sphere() {
        let (o, d, c) = (glam::Vec3::ZERO, glam::Vec3::Z, glam::Vec3::new(0.0, 0.0, 10.0));
        assert_eq!(eye_distance(8.0, o, d, c, 2.0), 0.0);
        assert_eq!(eye_distance(10.0, o, d, c, 2.0), 0.5);
        assert_eq!(eye_distance(12.0, o, d, c, 2.0), 1.0);
        assert_eq!(eye_distance(1.0, o, d, c, 2.0), 0.0);
    }

    #[test]
    fn kappa_t_steps_stay_in_range() {
        let p = ContextParams { kappa_t: 0.2, ..Default::default() };
        assert_eq!(p.with_kappa_t_step(-0.5).kappa_t, 0.0);
        assert_eq!(p.with_kappa_t_step(0.5).kappa_t, 0.7);
        assert_eq!(ContextParams { kappa_t: 11.8, ..p }.with_kappa_t_step(0.5).kappa_t, ContextParams::KAPPA_T_MAX);
    }

    #[test]
    fn bad_parameters_are_refused() {
        assert!(ContextParams { kappa_t: f32::NAN, ..Default::default() }.validated().is_err());
        assert!(ContextParams { kappa_s: -1.0, ..Default::default() }.validated().is_err());
        assert!(ContextParams::default().validated().is_ok());
    }
}
