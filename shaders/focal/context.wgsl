#define_import_path focal::context

// Context-preserving opacity, equation 5 of Bruckner et al. 2005 (reference and the
// derivation: src/context/model.rs; keep the two in step):
// α = α_tf · ‖g‖^((κt·λt · s · (1 − ‖P − E‖) · (1 − α_prev))^(κs·λs)),
// the outer power by Schlick's approximation x/(n − n·x + x) (equation 7) unless the
// region asks for the exact power; 0⁰ = 1.

#import focal::types::{Region, CONTEXT_EXACT}

fn exact_pow(x: f32, n: f32) -> f32 {
    if n == 0.0 {
        return 1.0;
    }
    return pow(max(x, 0.0), n);
}

fn schlick_pow(x_in: f32, n: f32) -> f32 {
    if n == 0.0 {
        return 1.0;
    }
    let x = clamp(x_in, 0.0, 1.0);
    if n == 1.0 {
        return x;
    }
    if x == 0.0 {
        return 0.0;
    }
    return x / (n - n * x + x);
}

// Normalised eye distance of the sample at t on the ray: 0 where the ray enters the
// bounding sphere of the region's volume (r.sphere: centre, radius), 1 where it leaves.
fn eye_distance(r: Region, origin: vec3<f32>, dir: vec3<f32>, t: f32) -> f32 {
    let t_near = dot(r.sphere.xyz - origin, dir) - r.sphere.w;
    return clamp((t - t_near) / max(2.0 * r.sphere.w, 1e-12), 0.0, 1.0);
}

// alpha: the step-corrected transfer-function opacity; gradient: ‖g‖ over the largest,
// in [0, 1]; shading: s(P); eye: eye_distance; alpha_prev: accumulated opacity;
// lambda: (λt, λs) of the sample's value.
fn context_opacity(r: Region, alpha: f32, gradient: f32, shading: f32, eye: f32, alpha_prev: f32, lambda: vec2<f32>) -> f32 {
    let base = r.context.x * lambda.x * shading * (1.0 - eye) * (1.0 - alpha_prev);
    let e = exact_pow(max(base, 0.0), r.context.y * lambda.y);
    let g = clamp(gradient, 0.0, 1.0);
    if r.context.z == CONTEXT_EXACT {
        return alpha * exact_pow(g, e);
    }
    return alpha * schlick_pow(g, e);
}
