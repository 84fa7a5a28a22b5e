//! Rays drawn at a reduced resolution and upscaled (`render::reduced`, issue 24): the
//! picture is the CPU reference's at that many rays, bilinearly upscaled.

use super::*;

/// The reference's picture at `n × n` rays, bilinearly upscaled in linear light to the
/// test's size as a texture sampler with clamp-to-edge filters it (texel centres at
/// `(i + ½)/n` of the view), sRGB-encoded: what the GPU's reduced path should draw.
fn reference_upscaled(volume: Arc<Volume>, look: Appearance, camera: &FocalCamera, n: u32) -> image::RgbaImage {
    let low = render(&RenderScene::single(volume, look), camera, n, n).unwrap();
    let texel = |x: i64, y: i64| low.at(x.clamp(0, n as i64 - 1) as u32, y.clamp(0, n as i64 - 1) as u32);
    let encode = |v: f32| (focal::transfer::color::linear_to_srgb(v).clamp(0.0, 1.0) * 255.0).round() as u8;
    image::RgbaImage::from_fn(SIZE, SIZE, |x, y| {
        let u = (x as f32 + 0.5) / SIZE as f32 * n as f32 - 0.5;
        let v = (y as f32 + 0.5) / SIZE as f32 * n as f32 - 0.5;
        let (x0, y0) = (u.floor(), v.floor());
        let (fx, fy) = (u - x0, v - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = texel(x0, y0).lerp(texel(x0 + 1, y0), fx);
        let bottom = texel(x0, y0 + 1).lerp(texel(x0 + 1, y0 + 1), fx);
        let c = top.lerp(bottom, fy);
        image::Rgba([encode(c.x), encode(c.y), encode(c.z), 255])
    })
}

/// The brightness-weighted centre of the picture, in pixels.
fn centroid(img: &image::RgbaImage) -> (f64, f64) {
    let (mut w, mut x, mut y) = (0.0, 0.0, 0.0);
    for (px, py, p) in img.enumerate_pixels() {
        let b = (p[0] as f64 + p[1] as f64 + p[2] as f64) / 3.0;
        w += b;
        x += b * (px as f64 + 0.5);
        y += b * (py as f64 + 0.5);
    }
    (x / w.max(1e-9), y / w.max(1e-9))
}

pub fn a_reduced_resolution_is_the_picture_of_fewer_rays_upscaled(gpu: &mut Gpu) {
    let h = head();
    let look = Appearance::new(Mode::Dvr, presets::builtin("ct_bone").unwrap());
    // Off-centre and oblique, so a shift or a flip of the upscaled picture shows.
    let cam = framed(&h, View::Oblique, false);
    let full = gpu.show(h.clone(), look.clone(), &cam);
    let mut pictures = Vec::new();
    for resolution in [0.5f32, 0.25] {
        gpu.off.set_view(VolumeView { jitter: false, resolution, ..Default::default() });
        pictures.push(gpu.off.capture().unwrap_or_else(|e| panic!("{e}")));
    }
    gpu.off.set_view(VolumeView { jitter: false, ..Default::default() });
    let again = gpu.off.capture().unwrap_or_else(|e| panic!("{e}"));
    let dir = std::env::temp_dir().join("focal-gpu-tests");
    let _ = std::fs::create_dir_all(&dir);
    for (name, img) in [("reduced-1", &full), ("reduced-0.5", &pictures[0]), ("reduced-0.25", &pictures[1])] {
        let _ = img.save(dir.join(format!("{name}.png")));
    }
    // Back at full resolution, the same picture as before.
    assert_eq!(difference(&full, &again).2, 0, "full resolution after a reduced one differs");
    // Each is the reference's picture at that many rays, upscaled.
    for (img, n) in [(&pictures[0], SIZE / 2), (&pictures[1], SIZE / 4)] {
        let expected = reference_upscaled(h.clone(), look.clone(), &cam, n);
        let _ = expected.save(dir.join(format!("reduced-{n}-reference.png")));
        assert_matches(&format!("reduced-{n}-rays"), img, &expected);
    }
    // Not the full picture: the fewer rays, the further from it; about the same place
    // (within half a pixel of the view: 16 rays across shift the centre a little).
    let (m_half, _, _) = difference(&full, &pictures[0]);
    let (m_quarter, _, _) = difference(&full, &pictures[1]);
    let (c_full, c_half, c_quarter) = (centroid(&full), centroid(&pictures[0]), centroid(&pictures[1]));
    println!(
        "    centre {c_full:.2?} / {c_half:.2?} / {c_quarter:.2?}; mean difference from every ray {m_half:.2} / {m_quarter:.2} levels"
    );
    assert!(m_half > 1.0 && m_quarter > m_half, "mean differences {m_half} / {m_quarter}");
    for c in [c_half, c_quarter] {
        assert!((c.0 - c_full.0).abs() < 0.5 && (c.1 - c_full.1).abs() < 0.5, "centre {c:?} against {c_full:?}");
    }
}

/// At rest at every pixel, the app's view averages frames of different ray jitter
/// (`dataset::view::Accumulate`, put there by `interactive`): after its 8 frames the
/// picture is the mean of the CPU reference's pictures with the jitter of frames 0 … 7,
/// and it is held (no new rays change it).
pub fn a_view_at_rest_shows_the_mean_of_its_jittered_frames(gpu: &mut Gpu) {
    use focal::dataset::view::Accumulate;
    use focal::interactive::InteractiveResolution;
    let h = head();
    // Samples 3 voxels apart: each jittered frame is noisy, their mean much less so.
    let look = Appearance { step: 3.0, ..Appearance::new(Mode::Dvr, presets::builtin("ct_bone").unwrap()) };
    let cam = framed(&h, View::Oblique, false);
    gpu.show(h.clone(), look.clone(), &cam);
    let jittered = VolumeView { jitter: true, ..Default::default() };
    gpu.off.set_view(jittered);
    let single = gpu.off.capture().unwrap_or_else(|e| panic!("{e}"));
    let camera = gpu.off.camera();
    const FRAMES: u32 = 8;
    gpu.off.world_mut().entity_mut(camera).insert(InteractiveResolution { accumulate: FRAMES, ..Default::default() });
    for _ in 0..FRAMES + 2 {
        gpu.off.update();
    }
    let index = gpu.off.world_mut().get::<Accumulate>(camera).map(|a| a.index);
    let averaged = gpu.off.capture().unwrap_or_else(|e| panic!("{e}"));
    let held = gpu.off.capture().unwrap_or_else(|e| panic!("{e}"));
    gpu.off.world_mut().entity_mut(camera).remove::<(InteractiveResolution, Accumulate)>();
    gpu.off.set_view(VolumeView { jitter: false, ..Default::default() });
    assert!(index.is_some_and(|i| i >= FRAMES), "the view does not average at rest: {index:?}");
    // The mean of the reference's jittered pictures, in linear light.
    let scene = RenderScene { jitter: true, ..RenderScene::single(h, look) };
    let frames: Vec<_> = (0..FRAMES).map(|f| focal::reference::render_frame(&scene, &cam, &[], SIZE, SIZE, f).unwrap()).collect();
    let encode = |v: f32| (focal::transfer::color::linear_to_srgb(v).clamp(0.0, 1.0) * 255.0).round() as u8;
    let mean = image::RgbaImage::from_fn(SIZE, SIZE, |x, y| {
        let c = frames.iter().map(|f| f.at(x, y)).sum::<glam::Vec4>() / FRAMES as f32;
        image::Rgba([encode(c.x), encode(c.y), encode(c.z), 255])
    });
    assert_matches("accumulated-8", &averaged, &mean);
    assert_eq!(difference(&averaged, &held).2, 0, "the held average changed");
    // One jittered frame is further from the mean: the average did something.
    let (one, _, _) = difference(&single, &mean);
    let (all, _, _) = difference(&averaged, &mean);
    println!("    against the mean of 8 jittered frames: one frame {one:.3}, the average {all:.3} levels");
    assert!(one > 2.0 * all + 0.1, "one frame {one} against the average {all}");
}
