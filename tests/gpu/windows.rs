//! GPU image tests of volumetric windows: a clip window through the whole head shows
//! nothing of the main view inside it (only its own content), clip windows showing the
//! head in place with other looks (drawn in the head's samples, `render::pack::insets`)
//! beside one that cannot be, a window magnifying a source box shows the feature there
//! enlarged by the magnification (its area by the square), and all match the CPU
//! reference of the same regions.

use super::*;
use focal::dataset::SceneRegions;
use focal::windows::{Content, Source, SourceBox, VolumeWindow};

/// The regions the app built this frame, rendered by the CPU reference.
fn reference_of_app(gpu: &mut Gpu, cam: &FocalCamera) -> image::RgbaImage {
    let scene = gpu.off.world_mut().resource::<SceneRegions>().scene.clone();
    render(&scene, cam, SIZE, SIZE).unwrap().to_image().unwrap()
}

pub fn a_clip_window_shows_nothing_of_the_main_view_inside(gpu: &mut Gpu) {
    let ct = head();
    let skin = Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone").unwrap());
    gpu.clear();
    let data = gpu.off.world_mut().spawn((Dataset::new(ct.clone(), skin), Transform::default())).id();
    // A box 60 mm wide through the whole head along the view (y), empty: a pure clip box.
    let cut = VolumeWindow { clip: true, ..VolumeWindow::new(Vec3::new(60.0, 400.0, 60.0), vec![]) };
    let window = gpu.off.world_mut().spawn((cut, Transform::default())).id();
    let cam = framed(&ct, View::Anterior, true);
    gpu.off.set_camera(&cam);
    let g = gpu.off.capture().unwrap();
    assert_matches("clip_window", &g, &reference_of_app(gpu, &cam));
    // The box covers the middle 60 mm of the 240 mm view: pixels 24..40 of 64 wide.
    let inside = (26..38).flat_map(|y| (26..38).map(move |x| (x, y)));
    let lit = inside.filter(|&(x, y)| g.get_pixel(x, y).0[..3].iter().any(|c| *c > 2)).count();
    assert_eq!(lit, 0, "{lit} pixels inside the clip window show the main view");
    // Outside it the head is still there.
    assert!(g.get_pixel(16, 32).0[..3].iter().any(|c| *c > 30));
    // With content (bone), the window shows its own appearance inside.
    let bone = Appearance::new(Mode::Dvr, presets::builtin("ct_bone").unwrap());
    gpu.off.world_mut().get_mut::<VolumeWindow>(window).unwrap().contents = vec![Content { dataset: data, appearance: Some(bone) }];
    let g = gpu.off.capture().unwrap();
    assert_matches("clip_window_bone", &g, &reference_of_app(gpu, &cam));
    let lit =
        (26..38).flat_map(|y| (26..38).map(move |x| (x, y))).filter(|&(x, y)| g.get_pixel(x, y).0[..3].iter().any(|c| *c > 30)).count();
    assert!(lit > 20, "the window's bone content shows: {lit} pixels");
}

pub fn clip_windows_drawn_in_place_match_the_reference(gpu: &mut Gpu) {
    use focal::render::gpu_types::features;
    let ct = head();
    let look = |mode: Mode, tf: &str| Appearance::new(mode, presets::builtin(tf).unwrap());
    gpu.clear();
    let data = gpu.off.world_mut().spawn((Dataset::new(ct.clone(), look(Mode::Dvr, "ct_skin_bone")), Transform::default())).id();
    let cam = framed(&ct, View::Superior, false);
    gpu.off.set_camera(&cam);
    // Four deep boxes into the top of the head, one a quadrant, each showing the head
    // in place with another look, and a small one between them in MIP (another mode: a
    // region of its own and a hole).
    let (lo, hi) = ct.grid.world_bounds();
    let at = |f: Vec3| lo + (hi - lo) * f;
    let quadrant = (hi - lo) * Vec3::new(0.2, 0.2, 0.5);
    let windows = [
        (Vec3::new(0.35, 0.35, 0.75), quadrant, look(Mode::Dvr, "ct_soft_tissue")),
        (Vec3::new(0.65, 0.35, 0.75), quadrant, look(Mode::Dvr, "ct_bone")),
        (Vec3::new(0.35, 0.65, 0.75), quadrant, look(Mode::Dvr, "grayscale_ramp")),
        (Vec3::new(0.65, 0.65, 0.75), quadrant, look(Mode::Dvr, "ct_vessels")),
        (Vec3::new(0.5, 0.5, 0.75), (hi - lo) * Vec3::new(0.08, 0.08, 0.5), look(Mode::Mip, "grayscale_ramp")),
    ];
    for (f, size, a) in windows {
        let w = VolumeWindow { clip: true, ..VolumeWindow::new(size, vec![Content { dataset: data, appearance: Some(a) }]) };
        gpu.off.world_mut().spawn((w, Transform::from_translation(at(f))));
    }
    let g = gpu.off.capture().unwrap();
    let scene = gpu.off.world_mut().resource::<SceneRegions>().scene.clone();
    let packed = focal::render::pack::pack(&scene, 2048).unwrap();
    let wanted = features::INSETS | features::SEVERAL_INSETS | features::HOLES;
    assert_eq!(packed.features & wanted, wanted, "four windows in place, the MIP one a hole");
    assert_eq!(packed.insets.len(), 4);
    assert_eq!(packed.region_count, 2, "the head and the MIP window");
    assert_matches("clip_windows_in_place", &g, &reference_of_app(gpu, &cam));
    // The windows show something of their own: the picture differs from the head's.
    gpu.clear();
    gpu.off.world_mut().spawn((Dataset::new(ct.clone(), look(Mode::Dvr, "ct_skin_bone")), Transform::default()));
    gpu.off.set_camera(&cam);
    let plain = gpu.off.capture().unwrap();
    let (mean, _, _) = difference(&g, &plain);
    assert!(mean > 2.0, "the windows changed little (mean {mean:.2} levels)");
}

pub fn a_magnifying_window_enlarges_its_source(gpu: &mut Gpu) {
    // A sphere of radius 4 mm in a 64³ volume (1 mm voxels) at the origin; a source box
    // of 16 mm around it and a window of 40 mm beside it: ×2.5.
    let ball = Arc::new(phantom::sphere(64, 4.0).unwrap());
    let mut tf = opaque_ramp();
    tf.opacity = vec![OpacityPoint(0.0, 0.0), OpacityPoint(0.45, 0.0), OpacityPoint(0.55, 1.0)];
    let a = Appearance::new(Mode::Dvr, tf);
    gpu.clear();
    let data = gpu.off.world_mut().spawn((Dataset::new(ball.clone(), a), Transform::default())).id();
    let source = gpu.off.world_mut().spawn((SourceBox { size: Vec3::splat(16.0) }, Transform::default())).id();
    let w = VolumeWindow {
        source: Source::Box(source),
        ..VolumeWindow::new(Vec3::splat(40.0), vec![Content { dataset: data, appearance: None }])
    };
    gpu.off.world_mut().spawn((w, Transform::from_xyz(80.0, 0.0, 0.0)));
    let cam = View::Anterior.frame_box(Vec3::new(-32.0, -32.0, -32.0), Vec3::new(100.0, 32.0, 32.0), 1.0, true);
    gpu.off.set_camera(&cam);
    let g = gpu.off.capture().unwrap();
    assert_matches("magnifying_window", &g, &reference_of_app(gpu, &cam));
    // Sphere pixels left of the middle (the ball in place) and right (in the window).
    let (w_px, h_px) = g.dimensions();
    let count = |from: u32, to: u32| {
        (0..h_px).flat_map(|y| (from..to).map(move |x| (x, y))).filter(|&(x, y)| g.get_pixel(x, y).0[0] > 60).count() as f32
    };
    // Split the image half-way between the ball (x = 0) and the window (x = 80).
    let at = |x: f32| cam.to_pixel(Vec3::new(x, 0.0, 0.0), w_px as f32, h_px as f32).unwrap().x;
    let (ball_x, split) = (at(0.0), at(40.0) as u32);
    let (left, right) = (count(0, split), count(split, w_px));
    let (plain, magnified) = if ball_x < split as f32 { (left, right) } else { (right, left) };
    println!("    sphere pixels: in place {plain}, in the window {magnified} (×{:.2} area)", magnified / plain);
    assert!(plain > 3.0, "the ball is too small to measure: {plain}");
    assert!((magnified / plain - 6.25).abs() < 1.6, "area ratio {} (expected 2.5² = 6.25)", magnified / plain);
}
