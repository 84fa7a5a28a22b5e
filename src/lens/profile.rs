//! Border profiles of a magnifying lens (LaMar, Hamann, Joy 2001, §4).
//!
//! A lens that magnifies its focus region by `m` shows, at radial coordinate `r` (see
//! [`super::shape`]), the context found at *source radius* `ρ(r)`. Inside the focus
//! region `ρ = r/m`; outside the lens `ρ = r`; the border `lr < r < lr + lb` joins them:
//!
//! - **simple**: no border, a single jump at `r = lr` (the ring `lr/m < ρ < lr` of the
//!   context is hidden under the lens);
//! - **linear**: `ρ` linear from `lr/m` to `lr + lb` (continuous, with kinks: the
//!   magnification jumps at both edges);
//! - **cubic**: the cubic Bézier with control points `lr/m`, `lr/m + lb/(3m)`,
//!   `lr + lb − lb/3`, `lr + lb` in the border parameter `u = (r − lr)/lb`, which matches
//!   value and slope (`1/m` inside, `1` outside) at both edges: C1.
//!
//! The magnifier of Wang et al. bends rays rather than moving pixels; it turns the
//! profile into the weight `w` with which a border ray blends the focused direction with
//! the normal one (see [`super::magnifier`]): `w = (ρ/r − 1/m)/(1 − 1/m)`, so a lens ray's
//! footprint at the focus depth is exactly `ρ(r)`.

use serde::{Deserialize, Serialize};

/// How the border joins the focus region to the context.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Profile {
    Simple,
    Linear,
    #[default]
    Cubic,
}

impl Profile {
    pub const ALL: [Profile; 3] = [Profile::Simple, Profile::Linear, Profile::Cubic];

    pub fn name(self) -> &'static str {
        match self {
            Profile::Simple => "simple",
            Profile::Linear => "linear",
            Profile::Cubic => "cubic",
        }
    }

    pub fn code(self) -> u32 {
        self as u32
    }

    /// Source radius `ρ(r)` for a lens of focus radius `lr`, border `lb` and
    /// magnification `m`.
    pub fn source_radius(self, r: f32, lr: f32, lb: f32, m: f32) -> f32 {
        if r <= lr {
            return r / m;
        }
        if self == Profile::Simple || lb <= 0.0 || r >= lr + lb {
            return r;
        }
        let (p0, p3) = (lr / m, lr + lb);
        let u = (r - lr) / lb;
        match self {
            Profile::Linear => p0 + (p3 - p0) * u,
            _ => {
                let (p1, p2) = (p0 + lb / (3.0 * m), p3 - lb / 3.0);
                let v = 1.0 - u;
                v * v * v * p0 + 3.0 * v * v * u * p1 + 3.0 * v * u * u * p2 + u * u * u * p3
            }
        }
    }

    /// Blend weight of a magnifier ray at radial coordinate `r`: 0 = focused, 1 = normal.
    pub fn weight(self, r: f32, lr: f32, lb: f32, m: f32) -> f32 {
        if r <= lr {
            return 0.0;
        }
        if (m - 1.0).abs() < 1e-6 {
            return 1.0;
        }
        let inv = 1.0 / m;
        ((self.source_radius(r, lr, lb, m) / r - inv) / (1.0 - inv)).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LR: f32 = 0.3;
    const LB: f32 = 0.2;
    const M: f32 = 2.5;

    fn slope(p: Profile, r: f32) -> f32 {
        let h = 1e-5;
        (p.source_radius(r + h, LR, LB, M) - p.source_radius(r - h, LR, LB, M)) / (2.0 * h)
    }

    #[test]
    fn hand_computed_values() {
        // Focus: 0.2/2.5 = 0.08. Linear midpoint: (0.12 + 0.5)/2 = 0.31.
        for p in Profile::ALL {
            assert!((p.source_radius(0.2, LR, LB, M) - 0.08).abs() < 1e-6);
            assert!((p.source_radius(0.7, LR, LB, M) - 0.7).abs() < 1e-6);
        }
        assert!((Profile::Linear.source_radius(0.4, LR, LB, M) - 0.31).abs() < 1e-6);
        // Cubic midpoint: (p0 + 3p1 + 3p2 + p3)/8 with p0 = 0.12, p1 = 0.12 + 0.2/7.5,
        // p2 = 0.5 − 0.2/3, p3 = 0.5.
        let mid = (0.12 + 3.0 * (0.12 + 0.2 / 7.5) + 3.0 * (0.5 - 0.2 / 3.0) + 0.5) / 8.0;
        assert!((Profile::Cubic.source_radius(0.4, LR, LB, M) - mid).abs() < 1e-6);
        // Simple: the jump at the rim.
        assert!((Profile::Simple.source_radius(0.3001, LR, LB, M) - 0.3001).abs() < 1e-6);
    }

    #[test]
    fn continuity_at_both_edges_and_c1_for_cubic() {
        let e = 1e-4;
        for p in [Profile::Linear, Profile::Cubic] {
            for edge in [LR, LR + LB] {
                let jump = p.source_radius(edge + e, LR, LB, M) - p.source_radius(edge - e, LR, LB, M);
                assert!(jump.abs() < 1e-3, "{p:?} jumps by {jump} at {edge}");
            }
        }
        // Cubic: slope 1/m on both sides of the inner edge, 1 on both sides of the outer.
        for (edge, want) in [(LR, 1.0 / M), (LR + LB, 1.0)] {
            assert!((slope(Profile::Cubic, edge - 2e-5) - want).abs() < 0.01);
            assert!((slope(Profile::Cubic, edge + 2e-5) - want).abs() < 0.01, "{}", slope(Profile::Cubic, edge + 2e-5));
        }
        // Linear has a kink: slope 0.38/0.2 = 1.9 in the border, 1/m inside.
        assert!((slope(Profile::Linear, LR + 2e-5) - 1.9).abs() < 1e-2);
        assert!((slope(Profile::Linear, LR + 0.1) - 1.9).abs() < 1e-2);
        // Simple jumps.
        assert!(Profile::Simple.source_radius(LR + e, LR, LB, M) - Profile::Simple.source_radius(LR - e, LR, LB, M) > 0.1);
    }

    #[test]
    fn weights_reproduce_the_source_radius() {
        for p in Profile::ALL {
            for i in 1..100 {
                let r = i as f32 * 0.01;
                let w = p.weight(r, LR, LB, M);
                let rho = r * ((1.0 - w) / M + w);
                assert!((rho - p.source_radius(r, LR, LB, M)).abs() < 1e-5, "{p:?} r {r}");
            }
        }
    }
}
