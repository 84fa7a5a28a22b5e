#define_import_path focal::shading

// Two-sided Blinn-Phong (reference: reference::trace::shade):
// c·(ka + kd·max(N·L, 0)) + ks·max(N·H, 0)^shininess; no gradient, no shading.

// (ka + kd·max(N·L, 0), ks·max(N·H, 0)^shininess) for the gradient g; (1, 0) where g
// vanishes (reference: trace::blinn_phong).
fn blinn_phong(g: vec3<f32>, view_dir: vec3<f32>, light: vec4<f32>, k: vec4<f32>) -> vec2<f32> {
    let len = length(g);
    if len < 1e-6 {
        return vec2(1.0, 0.0);
    }
    let v = -view_dir;
    var n = g / len;
    if dot(n, v) < 0.0 {
        n = -n;
    }
    var l = v;
    if light.w > 0.5 && length(light.xyz) > 0.0 {
        l = normalize(light.xyz);
    }
    var h = l + v;
    if length(h) > 1e-6 {
        h = normalize(h);
    } else {
        h = v;
    }
    return vec2(k.x + k.y * max(dot(n, l), 0.0), k.z * pow(max(dot(n, h), 0.0), k.w));
}

fn shade(c: vec3<f32>, g: vec3<f32>, view_dir: vec3<f32>, light: vec4<f32>, k: vec4<f32>, enabled: bool) -> vec3<f32> {
    if !enabled {
        return c;
    }
    return shade_with(c, blinn_phong(g, view_dir, light, k));
}

// The colour c lit by Blinn-Phong terms (unchanged by the (1, 0) of a vanishing
// gradient). s(P) of context-preserving rendering is clamp(terms.x + terms.y, 0, 1)
// (reference: trace::shading_intensity).
fn shade_with(c: vec3<f32>, terms: vec2<f32>) -> vec3<f32> {
    return clamp(c * terms.x + vec3(terms.y), vec3(0.0), vec3(1.0));
}
