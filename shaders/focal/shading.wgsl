#define_import_path focal::shading

// Two-sided Blinn-Phong (reference: reference::trace::shade):
// c·(ka + kd·max(N·L, 0)) + ks·max(N·H, 0)^shininess; no gradient, no shading.

fn shade(c: vec3<f32>, g: vec3<f32>, view_dir: vec3<f32>, light: vec4<f32>, k: vec4<f32>, enabled: bool) -> vec3<f32> {
    let len = length(g);
    if !enabled || len < 1e-6 {
        return c;
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
    let lit = c * (k.x + k.y * max(dot(n, l), 0.0)) + vec3(k.z * pow(max(dot(n, h), 0.0), k.w));
    return clamp(lit, vec3(0.0), vec3(1.0));
}
