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
