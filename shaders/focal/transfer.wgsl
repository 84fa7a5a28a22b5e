#define_import_path focal::transfer

// Classification through the lookup-table atlas with the same manual linear filtering
// as the reference (transfer::Lut::sample) and opacity correction
// α' = 1 − (1 − α)^(Δ/Δ₀) (transfer::opacity::correct).

#import focal::types::Region
#import focal::sampling::lut_texel

// The table of `width` texels at `base`, linearly filtered at the sample t, which
// a·t + b maps onto it.
fn filtered_table(base: u32, width: u32, a: f32, b: f32, t: f32, atlas_width: u32) -> vec4<f32> {
    let n = f32(width);
    let x = clamp((a * t + b) * n - 0.5, 0.0, n - 1.0);
    let i = min(u32(x), width - 2u);
    let f = x - f32(i);
    return mix(lut_texel(base + i, atlas_width), lut_texel(base + i + 1u, atlas_width), f);
}

// Region r's table of lut_width texels at `base`, filtered at t.
fn filtered(r: Region, base: u32, t: f32, atlas_width: u32) -> vec4<f32> {
    return filtered_table(base, r.lut_width, r.lut_a, r.lut_b, t, atlas_width);
}

fn classify(r: Region, t: f32, atlas_width: u32) -> vec4<f32> {
    return filtered(r, r.lut_offset, t, atlas_width);
}

// (λt, λs) of context-preserving regions: the lut_width texels after the colours
// (reference: Lut::sample_lambda).
fn classify_lambda(r: Region, t: f32, atlas_width: u32) -> vec2<f32> {
    return filtered(r, r.lut_offset + r.lut_width, t, atlas_width).xy;
}

fn classify_label(r: Region, code: u32, atlas_width: u32) -> vec4<f32> {
    if code >= r.lut_width {
        return vec4(0.0);
    }
    return lut_texel(r.lut_offset + code, atlas_width);
}

fn correct_opacity(alpha: f32, ratio: f32) -> f32 {
    if alpha >= 1.0 {
        return 1.0;
    }
    return 1.0 - pow(1.0 - max(alpha, 0.0), ratio);
}
