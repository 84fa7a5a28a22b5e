//! GPU image tests of context-preserving rendering: the GPU against the CPU reference
//! (Schlick and exact power, data-dependent λ), and κt = 0 giving the plain DVR picture
//! on the GPU too.

use super::*;
use focal::context::{ContextParams, Power};

fn context(kappa_t: f32, kappa_s: f32, power: Power, tf: TransferFunction) -> Appearance {
    Appearance { context: ContextParams { kappa_t, kappa_s, power }, ..Appearance::new(Mode::Context, tf) }
}

pub fn context_matches_the_reference(gpu: &mut Gpu) {
    let h = head();
    let engine = Arc::new(Phantom::Engine.generate(64).unwrap());
    // The engine with its dense metal impenetrable (λt = 0 from the upper third on).
    let mut impenetrable = presets::builtin("industrial_ct").unwrap();
    impenetrable.lambda_t = vec![OpacityPoint(0.0, 1.0), OpacityPoint(150.0, 1.0), OpacityPoint(170.0, 0.0)];
    impenetrable.lambda_s = vec![OpacityPoint(0.0, 0.5)];
    let cases = [
        (
            "context_head_schlick",
            h.clone(),
            context(4.0, 0.5, Power::Schlick, presets::builtin("ct_skin_bone").unwrap()),
            framed(&h, View::Oblique, false),
        ),
        (
            "context_engine_exact_lambda",
            engine.clone(),
            context(6.0, 0.8, Power::Exact, impenetrable.validated().unwrap()),
            framed(&engine, View::Anterior, true),
        ),
    ];
    for (name, v, a, cam) in cases {
        let g = gpu.show(v.clone(), a.clone(), &cam);
        assert_matches(name, &g, &cpu(v, a, &cam));
    }
}

pub fn kappa_t_zero_is_dvr_on_the_gpu(gpu: &mut Gpu) {
    let h = head();
    let tf = presets::builtin("ct_skin_bone").unwrap();
    let cam = framed(&h, View::Oblique, false);
    let dvr = gpu.show(h.clone(), Appearance::new(Mode::Dvr, tf.clone()), &cam);
    let zero = gpu.show(h.clone(), context(0.0, 0.7, Power::Schlick, tf.clone()), &cam);
    let (_, _, max) = difference(&dvr, &zero);
    assert_eq!(max, 0, "κt = 0 differs from DVR by up to {max} levels");
    let open = gpu.show(h, context(6.0, 0.5, Power::Schlick, tf), &cam);
    let (mean, _, _) = difference(&dvr, &open);
    assert!(mean > 1.0, "κt = 6 leaves the DVR picture nearly unchanged (mean {mean})");
}
