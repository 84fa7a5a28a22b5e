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

/// The segmented head phantom at `n`³ voxels.
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
        segmentation: Some(Segmentation { table: None, labels: Arc::new(h.labels.volume), objects, rest_visible: true }),
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
    let plain = gpu.show(ct, Appearance { segmentation: None, ..a }, &cam);
    let (mean, _, _) = difference(&plain, &g);
    assert!(mean > 2.0, "the segmentation changed little (mean {mean})");
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
