//! Colour spaces. Transfer-function and label colours are authored as display (sRGB)
//! values, as in every colour picker; rendering composites in linear light; images are
//! encoded back to sRGB. A grey ramp therefore shows value `v` as display grey `v`.
//! The transfer functions are the IEC 61966-2-1 sRGB curves.

/// sRGB-encoded component to linear light.
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// Linear light to the sRGB-encoded component.
#[inline]
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 { c * 12.92 } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

/// Converts an sRGB colour to linear light.
pub fn srgb3_to_linear(c: [f32; 3]) -> [f32; 3] {
    c.map(srgb_to_linear)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_curve_matches_reference_values() {
        // sRGB 0.5 is 0.21404 linear; 188/255 is about 0.5 linear.
        assert!((srgb_to_linear(0.5) - 0.214_041).abs() < 1e-5);
        assert!((linear_to_srgb(0.5) * 255.0 - 187.5).abs() < 0.6);
        for i in 0..=255 {
            let v = i as f32 / 255.0;
            assert!((linear_to_srgb(srgb_to_linear(v)) - v).abs() < 1e-5);
        }
    }
}
