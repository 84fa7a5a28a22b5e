//! Context-preserving volume rendering on the CPU reference, against the limits the
//! paper states and against measurements of the image: κt = 0 is plain DVR, κs = 0 is
//! gradient-magnitude modulation, raising κt uncovers an object inside a soft shell,
//! λt = 0 keeps a value range opaque, and the light direction matters.

use std::sync::Arc;

use focal::context::{ContextParams, Power};
use focal::reference::{RenderScene, RenderedImage, render};
use focal::region::{Appearance, Camera, Light, Mode, Projection, View};
use focal::transfer::{ColorPoint, OpacityPoint, TransferFunction, ValueSpace, presets};
use focal::volume::phantom::Phantom;
use focal::volume::{Grid, Source, ValueMap, Volume, Voxels};
use glam::{Quat, UVec3, Vec3};

const N: u32 = 48;

/// A soft ball (value 80, its edge a 6-voxel ramp) around a sharp cube (value 200).
fn shell_and_core() -> Arc<Volume> {
    let c = (N as f32 - 1.0) * 0.5;
    let codes = (0..N * N * N)
        .map(|i| {
            let p = Vec3::new((i % N) as f32, (i / N % N) as f32, (i / (N * N)) as f32) - Vec3::splat(c);
            if p.abs().max_element() < 6.0 {
                return 200u8;
            }
            let shell = ((20.0 - p.length()) / 6.0).clamp(0.0, 1.0);
            (80.0 * shell).round() as u8
        })
        .collect();
    Arc::new(
        Volume::new("shell and core", Grid::centered(UVec3::splat(N), Vec3::ONE), Voxels::U8(codes), ValueMap::IDENTITY, Source::default())
            .unwrap(),
    )
}

/// Shell red and fairly opaque, core blue and opaque.
fn shell_core_tf() -> TransferFunction {
    TransferFunction {
        name: "shell and core".into(),
        space: ValueSpace::Absolute,
        units: None,
        color: vec![ColorPoint(0.0, [1.0, 0.2, 0.1]), ColorPoint(120.0, [1.0, 0.2, 0.1]), ColorPoint(160.0, [0.1, 0.3, 1.0])],
        opacity: vec![
            OpacityPoint(0.0, 0.0),
            OpacityPoint(20.0, 0.0),
            OpacityPoint(60.0, 0.2),
            OpacityPoint(120.0, 0.2),
            OpacityPoint(160.0, 0.9),
        ],
        lambda_t: vec![],
        lambda_s: vec![],
    }
}

fn front_camera() -> Camera {
    Camera { position: Vec3::new(0.0, 0.0, 80.0), rotation: Quat::IDENTITY, projection: Projection::Orthographic { height: 50.0 } }
}

fn context(kappa_t: f32, kappa_s: f32) -> ContextParams {
    ContextParams { kappa_t, kappa_s, power: Power::Schlick }
}

fn show(v: &Arc<Volume>, a: Appearance, light: Light) -> RenderedImage {
    let mut scene = RenderScene::single(v.clone(), a);
    scene.light = light;
    render(&scene, &front_camera(), 32, 32).unwrap()
}

/// Mean blue minus red over the central pixels (where the core lies behind the shell).
fn core_visibility(img: &RenderedImage) -> f32 {
    let mut sum = 0.0;
    let mut n = 0;
    for y in 13..19 {
        for x in 13..19 {
            let c = img.rgba[(y * img.width + x) as usize];
            sum += c.z - c.x;
            n += 1;
        }
    }
    sum / n as f32
}

#[test]
fn kappa_t_zero_is_plain_dvr_and_kappa_s_zero_is_gradient_modulation() {
    let head = Arc::new(Phantom::Head.generate(48).unwrap());
    let tf = presets::builtin("ct_skin_bone").unwrap();
    let (lo, hi) = head.grid.world_bounds();
    let cam = View::Oblique.frame_box(lo, hi, 1.0, false);
    let image = |a: Appearance| render(&RenderScene::single(head.clone(), a), &cam, 40, 40).unwrap();
    let with = |mode, c| Appearance { context: c, ..Appearance::new(mode, tf.clone()) };
    for power in [Power::Schlick, Power::Exact] {
        let dvr = image(Appearance::new(Mode::Dvr, tf.clone()));
        assert_eq!(image(with(Mode::Context, ContextParams { kappa_t: 0.0, kappa_s: 0.7, power })).rgba, dvr.rgba);
        let gradient = image(Appearance::new(Mode::GradientDvr, tf.clone()));
        assert_eq!(image(with(Mode::Context, ContextParams { kappa_t: 5.0, kappa_s: 0.0, power })).rgba, gradient.rgba);
        // And it is a different picture in between.
        assert_ne!(image(with(Mode::Context, ContextParams { kappa_t: 5.0, kappa_s: 0.5, power })).rgba, dvr.rgba);
    }
}

#[test]
fn raising_kappa_t_uncovers_the_core() {
    let v = shell_and_core();
    let seen: Vec<f32> = [0.0, 0.5, 1.0, 4.0]
        .iter()
        .map(|&kt| {
            let a = Appearance { context: context(kt, 0.6), ..Appearance::new(Mode::Context, shell_core_tf()) };
            core_visibility(&show(&v, a, Light::Headlight))
        })
        .collect();
    println!("core visibility (blue − red) for κt 0, 0.5, 1, 4: {seen:?}");
    // Plain DVR: the shell hides the core (red wins). (Far higher κt fades the core's
    // own faces too: 0.32 at κt = 16 — the model clears whatever is lit and near.)
    assert!(seen[0] < 0.0, "{seen:?}");
    for w in seen.windows(2) {
        assert!(w[1] > w[0] + 0.01, "not increasing: {seen:?}");
    }
    assert!(seen[3] > 0.3, "the core stays hidden: {seen:?}");
}

#[test]
fn lambda_t_zero_keeps_a_value_range_opaque() {
    let v = shell_and_core();
    let dvr = show(&v, Appearance::new(Mode::Dvr, shell_core_tf()), Light::Headlight);
    let open = show(&v, Appearance { context: context(8.0, 0.6), ..Appearance::new(Mode::Context, shell_core_tf()) }, Light::Headlight);
    // λt = 0 over the shell's values: the shell is impenetrable again.
    let mut tf = shell_core_tf();
    tf.lambda_t = vec![OpacityPoint(0.0, 0.0), OpacityPoint(120.0, 0.0), OpacityPoint(160.0, 1.0)];
    let tf = tf.validated().unwrap();
    let closed = show(&v, Appearance { context: context(8.0, 0.6), ..Appearance::new(Mode::Context, tf.clone()) }, Light::Headlight);
    let (d, o, c) = (core_visibility(&dvr), core_visibility(&open), core_visibility(&closed));
    println!("core visibility: DVR {d}, κt 8 {o}, κt 8 with λt = 0 on the shell {c}");
    assert!(o > d + 0.3, "{o} {d}");
    assert!((c - d).abs() < 0.02, "λt = 0 should give the DVR picture: {c} vs {d}");
    // λs = 0 over the shell: gradient-magnitude modulation there, whatever κt.
    let mut grad_tf = shell_core_tf();
    grad_tf.lambda_s = vec![OpacityPoint(0.0, 0.0)];
    let by_lambda = show(&v, Appearance { context: context(8.0, 0.6), ..Appearance::new(Mode::Context, grad_tf) }, Light::Headlight);
    let gradient = show(&v, Appearance::new(Mode::GradientDvr, shell_core_tf()), Light::Headlight);
    assert_eq!(by_lambda.rgba, gradient.rgba);
}

#[test]
fn the_light_direction_changes_what_is_cleared() {
    // s(P) is the shading intensity: lit from the front the shell clears, lit from
    // behind (its front faces dark, s small) it stays.
    let v = shell_and_core();
    let a = Appearance { context: context(6.0, 0.6), ..Appearance::new(Mode::Context, shell_core_tf()) };
    let front = core_visibility(&show(&v, a.clone(), Light::Direction(Vec3::Z)));
    let back = core_visibility(&show(&v, a, Light::Direction(-Vec3::Z)));
    println!("core visibility lit from the front {front}, from behind {back}");
    assert!(front > back + 0.05, "{front} {back}");
}
