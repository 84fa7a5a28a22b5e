//! GPU image tests of two-level rendering: the head phantom's CT split by its own
//! labels (arteries DVR, skull MIP, ventricles X-ray, calcifications iso, eyes
//! hidden, the rest context-preserving) against the CPU reference, alone (one-region loop) and
//! overlapping a second copy of itself (the sample-by-sample loop).

use super::*;
use focal::region::Region;
use focal::region::{Object, Segmentation};
use focal::volume::phantom::head::label;

fn segmented_head() -> (Arc<Volume>, Appearance) {
    segmented_head_at(64)
}

/// The segmented head phantom at `n`³ voxels, each sample's value from its own object's
/// voxels at boundaries (`Segmentation::own_values`).
pub fn segmented_head_at(n: u32) -> (Arc<Volume>, Appearance) {
    let h = phantom::head::generate(n).unwrap();
    let ct = Arc::new(h.ct);
    let tf = |name: &str| presets::builtin(name).unwrap();
    let mut eyes = Object::new("eyes", vec![label::EYES as u32], Appearance::new(Mode::Dvr, tf("ct_soft_tissue")));
    eyes.visible = false;
    let objects = vec![
        Object::new("arteries", vec![label::ARTERIES as u32], Appearance::new(Mode::Dvr, tf("ct_vessels"))),
        Object::new("skull", vec![label::SKULL as u32], Appearance::new(Mode::Mip, tf("grayscale_ramp"))),
        Object::new("ventricles", vec![label::VENTRICLES as u32], Appearance::new(Mode::XRay, tf("grayscale_ramp"))),
        eyes,
        Object::new(
            "calcifications",
            vec![label::CALCIFICATIONS as u32],
            Appearance { iso_value: 400.0, ..Appearance::new(Mode::Iso, tf("ct_bone")) },
        ),
    ];
    let rest = Appearance {
        segmentation: Some(Segmentation { table: None, labels: Arc::new(h.labels.volume), objects, rest_visible: true, own_values: true }),
        ..Appearance::new(Mode::Context, tf("ct_skin_bone"))
    };
    (ct, rest)
}

pub fn two_level_matches_the_reference(gpu: &mut Gpu) {
    let (ct, a) = segmented_head();
    let cam = framed(&ct, View::Oblique, false);
    let g = gpu.show(ct.clone(), a.clone(), &cam);
    assert_matches("two_level_head", &g, &cpu(ct.clone(), a.clone(), &cam));
    // The objects change the picture: the same CT without them differs.
    let plain = gpu.show(ct.clone(), Appearance { segmentation: None, ..a.clone() }, &cam);
    let (mean, _, _) = difference(&plain, &g);
    assert!(mean > 2.0, "the segmentation changed little (mean {mean})");
    // A range of values (the shader's VALUE_RANGES): the skull's samples below 600 HU,
    // its partial-volume shell, are the rest's.
    let mut ranged = a.clone();
    if let Some(seg) = ranged.segmentation.as_mut() {
        seg.objects[1].values = Some((600.0, 3000.0));
    }
    let r = gpu.show(ct.clone(), ranged.clone(), &cam);
    assert_matches("two_level_ranges", &r, &cpu(ct, ranged, &cam));
    let changed = r.pixels().zip(g.pixels()).filter(|(p, q)| (0..3).any(|k| p[k].abs_diff(q[k]) > 10)).count();
    println!("    the skull's range changed {changed} pixels");
    assert!(changed > 50, "the skull's range changed only {changed} pixels");
}

pub fn overlapping_two_level_regions_match_the_reference(gpu: &mut Gpu) {
    let (ct, a) = segmented_head();
    let shift = Vec3::new(30.0, 0.0, 0.0);
    gpu.clear();
    gpu.off.world_mut().spawn((Dataset::new(ct.clone(), a.clone()), Transform::default()));
    gpu.off.world_mut().spawn((Dataset::new(ct.clone(), a.clone()), Transform::from_translation(shift)));
    let (lo, hi) = ct.grid.world_bounds();
    let cam = View::Anterior.frame_box(lo, hi + shift, 1.0, true);
    gpu.off.set_camera(&cam);
    let img = gpu.off.capture().unwrap();
    let scene = RenderScene {
        volumes: vec![ct.clone()],
        appearances: vec![a],
        regions: vec![Region::volume_box(&ct.grid, 0, 0), Region::volume_box_at(&ct.grid, glam::Affine3A::from_translation(shift), 0, 0)],
        ..Default::default()
    };
    let reference = render(&scene, &cam, SIZE, SIZE).unwrap().to_image().unwrap();
    assert_matches("two_level_overlap", &img, &reference);
}

/// The rest beside a hidden object draws no rim of the object's values: a ball of 200
/// (label 1, hidden) in a field of 20 (the rest, drawn opaque above 100 only, a value no
/// voxel of the rest has) draws nothing, on the GPU as in the reference. (Plain trilinear
/// samples of the rest half a voxel from the ball read 110: a ring around it.)
pub fn the_rest_draws_no_rim_beside_a_hidden_object(gpu: &mut Gpu) {
    const N: u32 = 32;
    let c = (N as f32 - 1.0) * 0.5;
    let inside = |i: u32| (Vec3::new((i % N) as f32, (i / N % N) as f32, (i / (N * N)) as f32) - Vec3::splat(c)).length() < 8.0;
    let grid = focal::volume::Grid::centered(UVec3::splat(N), Vec3::ONE);
    let volume = |name: &str, codes: Vec<u8>| {
        Arc::new(Volume::new(name, grid.clone(), Voxels::U8(codes), ValueMap::IDENTITY, Source::default()).unwrap())
    };
    let data = volume("data", (0..N * N * N).map(|i| if inside(i) { 200 } else { 20 }).collect());
    let labels = volume("labels", (0..N * N * N).map(|i| u8::from(inside(i))).collect());
    let above_100 = focal::transfer::TransferFunction {
        opacity: vec![OpacityPoint(0.0, 0.0), OpacityPoint(100.0, 0.0), OpacityPoint(101.0, 1.0)],
        space: ValueSpace::Absolute,
        ..opaque_ramp()
    };
    let mut ball = Object::new("ball", vec![1], Appearance::new(Mode::Dvr, above_100.clone()));
    ball.visible = false;
    let plain = Appearance::new(Mode::Dvr, above_100);
    let seg = Segmentation { table: None, labels, objects: vec![ball], rest_visible: true, own_values: true };
    let segmented = Appearance { segmentation: Some(seg.clone()), ..plain.clone() };
    let cam = framed(&data, View::Oblique, false);
    let g = gpu.show(data.clone(), segmented.clone(), &cam);
    let (mean, p99, max) = difference(&g, &cpu(data.clone(), segmented, &cam));
    assert!(mean < 1.0 && p99 <= 6, "GPU against the reference: mean {mean:.3}, p99 {p99}, max {max}");
    let brightest = g.pixels().flat_map(|p| p.0[..3].to_vec()).max().unwrap_or(0);
    assert!(brightest <= 1, "the rest draws a rim beside the hidden ball (up to {brightest} levels)");
    // Plain trilinear values at boundaries (own_values off): the rim.
    let rim = gpu.show(data.clone(), Appearance { segmentation: Some(Segmentation { own_values: false, ..seg }), ..plain.clone() }, &cam);
    assert!(rim.pixels().any(|p| p[0] > 100), "no rim without own values: the test shows nothing");
    let ball_drawn = gpu.show(data.clone(), plain, &cam);
    assert!(ball_drawn.pixels().any(|p| p[0] > 100), "the look does not draw the ball: the test shows nothing");
}
