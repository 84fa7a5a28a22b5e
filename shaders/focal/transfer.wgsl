#define_import_path focal::transfer

// Classification through the lookup-table atlas with the same manual linear filtering
// as the reference (transfer::Lut::sample) and opacity correction
// α' = 1 − (1 − α)^(Δ/Δ₀) (transfer::opacity::correct).

#import focal::types::Region
#import focal::sampling::{lut_bits, lut_texel}

// The table of `width` texels at `base`, linearly filtered at the sample t, which
// a·t + b maps onto it.
fn filtered_table(base: u32, width: u32, a: f32, b: f32, t: f32) -> vec4<f32> {
    return filtered_looks(base, width, a, b, t, false).first;
}

// Where a sample falls in a table: between texels i and i + 1, at weight f of the second.
struct TablePosition {
    i: u32,
    f: f32,
}

// Where the sample t falls in a table of `width` texels that a·t + b maps onto.
fn table_position(width: u32, a: f32, b: f32, t: f32) -> TablePosition {
    let n = f32(width);
    let x = clamp((a * t + b) * n - 0.5, 0.0, n - 1.0);
    let i = min(u32(x), width - 2u);
    return TablePosition(i, x - f32(i));
}

// Two looks of one volume classified by one lookup (render::pack::pair_table: an
// exploded view at rest, its parts' look and its selection's in the same samples). On
// llvmpipe every texel load is a gather, and the second look's own two made an
// exploded head at rest cost ×1.30 of the plain head's frame against ×1.16 without.
struct Looks {
    first: vec4<f32>,
    second: vec4<f32>,
}

// The colour of two 16-bit normalised numbers per channel pair (pack2x16unorm's
// layout; unpack2x16float would need a capability llvmpipe lacks without f16).
fn pair_look(bits: vec2<u32>) -> vec4<f32> {
    return vec4(unpack2x16unorm(bits.x), unpack2x16unorm(bits.y));
}

// The table at `base` filtered at t as filtered_table does. `paired`: it is a pair
// table, each texel the first look's colour (xy) and the second's (zw) as 16-bit
// normalised numbers; otherwise its f32 colour is the first look and the second is
// transparent.
fn filtered_looks(base: u32, width: u32, a: f32, b: f32, t: f32, paired: bool) -> Looks {
    let x = table_position(width, a, b, t);
    let lo = lut_bits(base + x.i);
    let hi = lut_bits(base + x.i + 1u);
    var looks = Looks(mix(bitcast<vec4<f32>>(lo), bitcast<vec4<f32>>(hi), x.f), vec4(0.0));
    if paired {
        looks.first = mix(pair_look(lo.xy), pair_look(hi.xy), x.f);
        looks.second = mix(pair_look(lo.zw), pair_look(hi.zw), x.f);
    }
    return looks;
}

// Region r's table of lut_width texels at `base`, filtered at t.
fn filtered(r: Region, base: u32, t: f32) -> vec4<f32> {
    return filtered_table(base, r.lut_width, r.lut_a, r.lut_b, t);
}

fn classify(r: Region, t: f32) -> vec4<f32> {
    return filtered(r, r.lut_offset, t);
}

// (λt, λs) of context-preserving regions: the lut_width texels after the colours
// (reference: Lut::sample_lambda).
fn classify_lambda(r: Region, t: f32) -> vec2<f32> {
    return filtered(r, r.lut_offset + r.lut_width, t).xy;
}

fn classify_label(r: Region, code: u32) -> vec4<f32> {
    if code >= r.lut_width {
        return vec4(0.0);
    }
    return lut_texel(r.lut_offset + code);
}

fn correct_opacity(alpha: f32, ratio: f32) -> f32 {
    if alpha >= 1.0 {
        return 1.0;
    }
    return 1.0 - pow(1.0 - max(alpha, 0.0), ratio);
}
