//! Opacity correction for the sampling distance.
//!
//! Transfer-function opacities are defined for a reference segment length `Δ₀` (Focal
//! uses the smallest voxel spacing of the volume). A segment of length `Δ` through a
//! homogeneous medium of that opacity transmits `(1 − α)^(Δ/Δ₀)`, so the corrected
//! opacity is `α' = 1 − (1 − α)^(Δ/Δ₀)` (Engel et al., *Real-Time Volume Graphics*,
//! eq. 9.1). This keeps images the same when the step size changes.

/// Opacity of a segment `ratio = Δ/Δ₀` reference lengths long.
#[inline]
pub fn correct(alpha: f32, ratio: f32) -> f32 {
    if alpha >= 1.0 {
        return 1.0;
    }
    1.0 - (1.0 - alpha.max(0.0)).powf(ratio)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_hand_values_and_composes() {
        assert_eq!(correct(0.5, 1.0), 0.5);
        // Two half steps of α = 0.5: each 1 − √0.5 ≈ 0.29289.
        let half = correct(0.5, 0.5);
        assert!((half - (1.0 - 0.5f32.sqrt())).abs() < 1e-6);
        // Compositing the two half steps gives back the full-step opacity.
        let two = half + (1.0 - half) * half;
        assert!((two - 0.5).abs() < 1e-6);
        assert_eq!(correct(0.0, 3.0), 0.0);
        assert_eq!(correct(1.0, 0.1), 1.0);
    }
}
