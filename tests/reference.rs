//! The CPU reference renderer against independent computations: axis-aligned
//! orthographic projections against the voxel array, the sphere phantom's iso-surface
//! against its analytic radius, picking, clipping, gradient modulation and the
//! invariance of the image to empty-space skipping and (nearly) to the step size.

use std::sync::Arc;

use focal::reference::{RenderScene, pick, render};
use focal::region::{Appearance, Camera, Lookup, Mode, Plane, Projection, Region, View};
use focal::transfer::color::linear_to_srgb;
use focal::transfer::{ColorPoint, OpacityPoint, TransferFunction, ValueSpace, presets};
use focal::volume::phantom::{self, Phantom};
use focal::volume::{Grid, Source, ValueMap, Volume, Voxels};
use glam::{Quat, UVec3, Vec3};

/// A deterministic pseudo-random volume, centred, unit spacing.
fn noise_volume(dims: UVec3, sixteen: bool) -> Volume {
    let n = (dims.x * dims.y * dims.z) as usize;
    let h = |i: usize| ((i as u64).wrapping_mul(2_654_435_761) ^ 0x5bd1e995).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 40;
    let voxels = if sixteen {
        Voxels::U16((0..n).map(|i| (h(i) % 4000) as u16 + 100).collect())
    } else {
        Voxels::U8((0..n).map(|i| (h(i) % 250) as u8 + 3).collect())
    };
    Volume::new("noise", Grid::centered(dims, Vec3::ONE), voxels, ValueMap::IDENTITY, Source::default()).unwrap()
}

/// Orthographic camera looking down −z with one pixel per voxel column.
fn top_camera(dims: UVec3) -> Camera {
    Camera {
        position: Vec3::new(0.0, 0.0, 100.0),
        rotation: Quat::IDENTITY,
        projection: Projection::Orthographic { height: dims.y as f32 },
    }
}

/// Grey ramp over the data range, fully opaque: colour = (v − min) / (max − min).
fn opaque_ramp() -> TransferFunction {
    TransferFunction {
        name: "opaque ramp".into(),
        space: ValueSpace::Relative,
        units: None,
        color: vec![ColorPoint(0.0, [0.0; 3]), ColorPoint(1.0, [1.0; 3])],
        opacity: vec![OpacityPoint(0.0, 1.0)],
        lambda_t: vec![],
        lambda_s: vec![],
    }
}

fn projection_matches(mode: Mode, sixteen: bool, reduce: impl Fn(&[f32]) -> f32) {
    let dims = UVec3::new(24, 20, 16);
    let v = noise_volume(dims, sixteen);
    let mut a = Appearance::new(mode, opaque_ramp());
    a.step = 1.0;
    let scene = RenderScene::single(Arc::new(v.clone()), a);
    let img = render(&scene, &top_camera(dims), dims.x, dims.y).unwrap();
    let code_max = v.code_max() as f32;
    let (lo, hi) = (v.stats.min as f32, v.stats.max as f32);
    // The LUT has one texel per code for 8-bit data, 4096 over the range for 16-bit.
    let lut_tol = if sixteen { 1.0 / 4096.0 } else { 1e-5 };
    for py in 0..dims.y {
        for px in 0..dims.x {
            let (i, j) = (px, dims.y - 1 - py);
            let column: Vec<f32> = (0..dims.z).map(|k| v.code(i, j, k) as f32 / code_max).collect();
            let want = reduce(&column);
            let got = img.value[(py * dims.x + px) as usize];
            assert!((got - want).abs() < 2e-6, "{mode:?} pixel ({px},{py}): {got} vs {want}");
            // Display grey = (v − min)/(max − min); the image holds it in linear light.
            let grey = (want * code_max - lo) / (hi - lo);
            let c = linear_to_srgb(img.at(px, py).x);
            assert!((c - grey).abs() < 2.0 * lut_tol + 1e-5, "{mode:?} colour {c} vs {grey}");
        }
    }
}

#[test]
fn orthographic_mip_equals_the_voxel_maximum() {
    projection_matches(Mode::Mip, false, |c| c.iter().cloned().fold(f32::MIN, f32::max));
    projection_matches(Mode::Mip, true, |c| c.iter().cloned().fold(f32::MIN, f32::max));
}

#[test]
fn orthographic_minip_equals_the_voxel_minimum() {
    projection_matches(Mode::MinIp, false, |c| c.iter().cloned().fold(f32::MAX, f32::min));
}

/// A projection with a value range takes only the column's samples within it; a column
/// with none draws nothing.
fn projection_within_matches(mode: Mode, reduce: impl Fn(&[f32]) -> f32) {
    let dims = UVec3::new(24, 20, 16);
    let v = noise_volume(dims, false);
    let (min, max) = (v.stats.min, v.stats.max);
    // Narrow: about half the columns of 16 uniform samples have none within it.
    let range = (min + 0.50 * (max - min), min + 0.55 * (max - min));
    let mut a = Appearance::new(mode, opaque_ramp());
    a.step = 1.0;
    a.projection_range = Some(range);
    let scene = RenderScene::single(Arc::new(v.clone()), a);
    let img = render(&scene, &top_camera(dims), dims.x, dims.y).unwrap();
    let code_max = v.code_max() as f32;
    let (lo, hi) = (v.real_to_normalized(range.0) as f32, v.real_to_normalized(range.1) as f32);
    let (mut empty, mut taken) = (0, 0);
    for py in 0..dims.y {
        for px in 0..dims.x {
            let (i, j) = (px, dims.y - 1 - py);
            let column: Vec<f32> = (0..dims.z).map(|k| v.code(i, j, k) as f32 / code_max).filter(|c| (lo..=hi).contains(c)).collect();
            let got = img.value[(py * dims.x + px) as usize];
            if column.is_empty() {
                empty += 1;
                assert!(
                    got.is_nan() && img.at(px, py).truncate() == glam::Vec3::ZERO,
                    "{mode:?} pixel ({px},{py}) drew {got} ({}) from no sample",
                    img.at(px, py)
                );
            } else {
                taken += 1;
                let want = reduce(&column);
                assert!((got - want).abs() < 2e-6, "{mode:?} pixel ({px},{py}): {got} vs {want}");
            }
        }
    }
    assert!(taken > 0 && empty > 0, "{mode:?}: {taken} columns with samples within the range, {empty} without");
}

#[test]
fn a_projections_value_range_leaves_out_the_samples_outside_it() {
    projection_within_matches(Mode::Mip, |c| c.iter().cloned().fold(f32::MIN, f32::max));
    projection_within_matches(Mode::MinIp, |c| c.iter().cloned().fold(f32::MAX, f32::min));
    projection_within_matches(Mode::XRay, |c| c.iter().sum::<f32>() / c.len() as f32);
}

/// A masked image (NaN outside the mask, as resampled and skull-stripped images come):
/// MIP, MinIP and X-ray take the true values only, as empty space is left out, and a
/// column of NaN alone draws nothing. (NaN voxels are code 0, below every true value:
/// the MinIP was that code wherever a ray crossed the mask, the X-ray's mean counted it.)
#[test]
fn projections_leave_nan_voxels_out() {
    use focal::volume::encode::{SampleType, encode_values};
    let dims = UVec3::new(8, 6, 16);
    let value = |i: u32, j: u32, k: u32| {
        let masked = (i == 0 && j == 0) || ((i + j).is_multiple_of(2) && k >= 8);
        if masked { f64::NAN } else { 10.0 + ((i * 7 + j * 3 + k * 5) % 40) as f64 }
    };
    let values: Vec<f64> = (0..dims.z)
        .flat_map(|k| (0..dims.y).flat_map(move |j| (0..dims.x).map(move |i| (i, j, k))))
        .map(|(i, j, k)| value(i, j, k))
        .collect();
    let e = encode_values(&values, SampleType::F32).unwrap();
    let v = Volume::new("masked", Grid::centered(dims, Vec3::ONE), e.voxels, e.map, Source::default()).unwrap();
    assert_eq!(v.values.no_data, Some(0));
    let code_max = v.code_max() as f32;
    for (mode, reduce) in [
        (Mode::Mip, (|c: &[f32]| c.iter().cloned().fold(f32::MIN, f32::max)) as fn(&[f32]) -> f32),
        (Mode::MinIp, |c: &[f32]| c.iter().cloned().fold(f32::MAX, f32::min)),
        (Mode::XRay, |c: &[f32]| c.iter().sum::<f32>() / c.len() as f32),
    ] {
        let mut a = Appearance::new(mode, opaque_ramp());
        a.step = 1.0;
        let img = render(&RenderScene::single(Arc::new(v.clone()), a), &top_camera(dims), dims.x, dims.y).unwrap();
        for py in 0..dims.y {
            for px in 0..dims.x {
                let (i, j) = (px, dims.y - 1 - py);
                let column: Vec<f32> =
                    (0..dims.z).filter(|&k| !value(i, j, k).is_nan()).map(|k| v.code(i, j, k) as f32 / code_max).collect();
                let got = img.value[(py * dims.x + px) as usize];
                if column.is_empty() {
                    assert!(
                        got.is_nan() && img.at(px, py).truncate() == glam::Vec3::ZERO,
                        "{mode:?} ({px},{py}) drew {got} from NaN alone"
                    );
                } else {
                    let want = reduce(&column);
                    assert!((got - want).abs() < 2e-6, "{mode:?} pixel ({px},{py}): {got} vs {want} of the true values");
                }
            }
        }
    }
}

#[test]
fn a_projection_split_into_regions_is_one_projection_along_the_whole_ray() {
    // The volume as two regions along the ray (the parts of an exploded view at rest, a
    // same-look window and the rest): MIP, MinIP and X-ray of the pair equal those of the
    // whole volume, not the front part's value composited over the back part's.
    let dims = UVec3::new(24, 20, 16);
    let v = Arc::new(noise_volume(dims, false));
    for mode in [Mode::Mip, Mode::MinIp, Mode::XRay] {
        let mut a = Appearance::new(mode, opaque_ramp());
        a.step = 1.0;
        let whole = RenderScene::single(v.clone(), a.clone());
        let whole_img = render(&whole, &top_camera(dims), dims.x, dims.y).unwrap();
        let mut split = RenderScene::single(v.clone(), a.clone());
        let box_ = split.regions[0].clone();
        let lo = Vec3::splat(-0.5);
        let hi = dims.as_vec3() - 0.5;
        let mid = 7.5;
        // Two appearances equal by value, as an exploded view's parts have.
        split.appearances.push(a.clone());
        split.regions = vec![
            box_.cut_to_index_box(lo, Vec3::new(hi.x, hi.y, mid)),
            Region { appearance: 1, ..box_.cut_to_index_box(Vec3::new(lo.x, lo.y, mid), hi) },
        ];
        let split_img = render(&split, &top_camera(dims), dims.x, dims.y).unwrap();
        for (i, (w, s)) in whole_img.value.iter().zip(&split_img.value).enumerate() {
            assert!((w - s).abs() < 2e-6, "{mode:?} pixel {i}: whole {w}, split {s}");
        }
        let (w, s) = (whole_img.at(3, 4), split_img.at(3, 4));
        assert!((w - s).abs().max_element() < 1e-5, "{mode:?}: colour {w} whole, {s} split");
        // A different look is another projection: composited in depth order.
        split.appearances[1] = Appearance { shading: focal::region::Shading { ambient: 0.5, ..a.shading }, ..a.clone() };
        let apart = render(&split, &top_camera(dims), dims.x, dims.y).unwrap();
        assert_ne!(apart.value, split_img.value, "{mode:?}: regions with different looks were projected together");
    }
}

#[test]
fn orthographic_xray_equals_the_mean() {
    projection_matches(Mode::XRay, false, |c| c.iter().sum::<f32>() / c.len() as f32);
    projection_matches(Mode::XRay, true, |c| c.iter().sum::<f32>() / c.len() as f32);
}

/// Distance of every iso-surface hit from the sphere's centre.
fn iso_hit_radii(camera: &Camera, size: u32) -> Vec<f32> {
    let v = phantom::sphere(64, 20.0).unwrap();
    let mut a = Appearance::new(Mode::Iso, opaque_ramp());
    a.iso_value = 127.5; // normalised 0.5
    a.step = 0.5;
    let scene = RenderScene::single(Arc::new(v.clone()), a);
    let img = render(&scene, camera, size, size).unwrap();
    let mut radii = Vec::new();
    for py in 0..size {
        for px in 0..size {
            let d = img.depth[(py * size + px) as usize];
            if d.is_finite() {
                let ray = camera.ray(px as f32 + 0.5, py as f32 + 0.5, size, size);
                radii.push(ray.at(d).distance(Vec3::ZERO));
            }
        }
    }
    radii
}

#[test]
fn sphere_iso_surface_lies_at_the_analytic_radius() {
    // Sphere of radius 20 voxels centred at the origin (the 64³ grid is centred).
    let ortho =
        Camera { position: Vec3::new(0.0, 0.0, 60.0), rotation: Quat::IDENTITY, projection: Projection::Orthographic { height: 48.0 } };
    let persp = View::Oblique.frame(Vec3::ZERO, 40.0, false);
    for cam in [ortho, persp] {
        let radii = iso_hit_radii(&cam, 64);
        assert!(radii.len() > 500, "{} hits", radii.len());
        let worst = radii.iter().map(|r| (r - 20.0).abs()).fold(0.0, f32::max);
        // Left: the curvature of the ramp across a voxel (≈ 0.5²/(2·20) voxels) and the
        // 2⁻⁸ bisection interval.
        assert!(worst < 0.02, "worst radius error {worst} voxels");
    }
}

#[test]
fn picking_finds_the_first_visible_surface() {
    let v = phantom::sphere(64, 20.0).unwrap();
    let scene = RenderScene::single(Arc::new(v.clone()), Appearance::new(Mode::Dvr, opaque_ramp()));
    let ray = focal::region::Ray { origin: Vec3::new(-50.0, 0.3, 0.2), dir: Vec3::X };
    let hit = pick(&scene, ray).unwrap().expect("hit");
    // Opacity 1 for any value: the first sample inside the box is already opaque, so
    // use a threshold transfer function instead.
    assert!(hit.position.x < -20.0, "{hit:?}");
    let mut tf = opaque_ramp();
    tf.opacity = vec![OpacityPoint(0.0, 0.0), OpacityPoint(0.49, 0.0), OpacityPoint(0.51, 1.0)];
    let scene = RenderScene::single(Arc::new(v.clone()), Appearance::new(Mode::Dvr, tf));
    let hit = pick(&scene, ray).unwrap().expect("hit");
    assert!((hit.position.x + 20.0).abs() < 0.5, "{hit:?}");
    let miss = focal::region::Ray { origin: Vec3::new(-50.0, 40.0, 0.0), dir: Vec3::X };
    assert!(pick(&scene, miss).unwrap().is_none());
}

#[test]
fn picking_names_the_label_in_front_and_hidden_labels_let_the_next_through() {
    let head = phantom::head::generate(64).unwrap();
    let ids: Vec<u32> = head.labels.present_ids().into_iter().map(|(id, _)| id).collect();
    let mut styles = focal::transfer::LabelTransfer::from_table(&head.labels.table, ids.iter().copied(), 0.9);
    let v = Arc::new(head.labels.volume);
    let (lo, hi) = v.grid.world_bounds();
    // From the front through the middle of the head.
    let centre = (lo + hi) * 0.5;
    let ray = focal::region::Ray { origin: Vec3::new(centre.x + 3.0, lo.y - 50.0, centre.z + 10.0), dir: Vec3::Y };
    let picked = |styles: &focal::transfer::LabelTransfer| {
        let a = Appearance { lookup: Lookup::Labels(styles.clone()), ..Appearance::new(Mode::Dvr, opaque_ramp()) };
        let scene = RenderScene::single(v.clone(), a);
        let hit = pick(&scene, ray).unwrap().expect("the head is hit");
        (focal::reference::label_at(&scene, &hit).expect("a label volume"), hit.position.y)
    };
    let (first, y1) = picked(&styles);
    assert!(first != 0 && ids.contains(&first), "{first}");
    // Hide it: the pick goes deeper, to another label.
    if let Some(s) = styles.styles.get_mut(&first) {
        s.visible = false;
    }
    let (second, y2) = picked(&styles);
    assert!(second != first && second != 0 && y2 > y1, "{first} at {y1}, then {second} at {y2}");
    // Not a label volume: no label.
    let ct = Arc::new(Phantom::Head.generate(48).unwrap());
    let scene = RenderScene::single(ct, Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone").unwrap()));
    let hit = pick(&scene, ray).unwrap().expect("hit");
    assert_eq!(focal::reference::label_at(&scene, &hit), None);
}

#[test]
fn clip_planes_cut_the_region() {
    let dims = UVec3::new(24, 20, 16);
    let v = noise_volume(dims, false);
    let mut a = Appearance::new(Mode::Mip, opaque_ramp());
    a.step = 1.0;
    let mut scene = RenderScene::single(Arc::new(v.clone()), a);
    scene.regions[0] = scene.regions[0].clone().clipped(Plane::through(Vec3::ZERO, Vec3::X));
    let img = render(&scene, &top_camera(dims), dims.x, dims.y).unwrap();
    for px in 0..dims.x {
        let value = img.value[(5 * dims.x + px) as usize];
        // Pixel centres at x = px + 0.5 − 12: the left half (x < 0) keeps its data.
        assert_eq!(value.is_nan(), px >= 12, "pixel {px}");
    }
}

#[test]
fn two_overlapping_regions_composite_sample_by_sample() {
    let v = phantom::sphere(32, 10.0).unwrap();
    let mut tf = opaque_ramp();
    tf.opacity = vec![OpacityPoint(0.0, 0.0), OpacityPoint(1.0, 0.05)];
    let one = RenderScene::single(Arc::new(v.clone()), Appearance::new(Mode::Dvr, tf.clone()));
    let mut two = one.clone();
    two.regions.push(Region::volume_box(&v.grid, 0, 0));
    let cam = View::Anterior.frame(Vec3::ZERO, 28.0, true);
    let a = render(&one, &cam, 32, 32).unwrap();
    let b = render(&two, &cam, 32, 32).unwrap();
    // The same data twice doubles the optical depth: more opaque, never less.
    let (sa, sb): (f32, f32) = (a.alpha.iter().sum(), b.alpha.iter().sum());
    assert!(sb > sa * 1.3, "{sa} {sb}");
    for (x, y) in a.alpha.iter().zip(&b.alpha) {
        assert!(y + 1e-6 >= *x);
    }
}

#[test]
fn empty_space_skipping_does_not_change_the_image() {
    let h = Phantom::Head.generate(64).unwrap();
    let tf = presets::builtin("ct_bone").unwrap();
    let mut scene = RenderScene::single(Arc::new(h.clone()), Appearance::new(Mode::Dvr, tf));
    scene.jitter = true;
    let cam = View::Oblique.frame(h.grid.center(), 130.0, false);
    let skipped = render(&scene, &cam, 48, 48).unwrap();
    scene.skip_empty = false;
    let full = render(&scene, &cam, 48, 48).unwrap();
    assert_eq!(skipped.rgba, full.rgba);
    assert!(skipped.alpha.iter().any(|&a| a > 0.5), "the skull is visible");
}

#[test]
fn the_samples_a_picture_takes_are_counted_per_region() {
    // The skull: without skipping every sample position is a sample of the region; with
    // it the empty bricks' are not, and the march itself is the same.
    let h = Arc::new(Phantom::Head.generate(64).unwrap());
    let mut scene = RenderScene::single(h.clone(), Appearance::new(Mode::Dvr, presets::builtin("ct_bone").unwrap()));
    let cam = View::Oblique.frame(h.grid.center(), 130.0, false);
    let skipped = render(&scene, &cam, 32, 32).unwrap();
    scene.skip_empty = false;
    let full = render(&scene, &cam, 32, 32).unwrap();
    assert_eq!(full.classified, full.samples);
    assert_eq!(skipped.samples, full.samples);
    assert!(skipped.classified > 0 && skipped.classified < full.classified * 3 / 4, "{} of {}", skipped.classified, full.classified);
    // Two copies of a nearly transparent region (no ray ends early): each position is
    // a sample of both.
    let mut faint = opaque_ramp();
    faint.opacity = vec![OpacityPoint(0.0, 0.001), OpacityPoint(1.0, 0.001)];
    let mut one = RenderScene::single(h.clone(), Appearance::new(Mode::Dvr, faint));
    one.skip_empty = false;
    let mut two = one.clone();
    two.regions.push(Region::volume_box(&h.grid, 0, 0));
    let (a, b) = (render(&one, &cam, 32, 32).unwrap(), render(&two, &cam, 32, 32).unwrap());
    assert_eq!((b.samples, b.classified), (a.samples, 2 * a.classified));
}

#[test]
fn opacity_correction_keeps_the_image_across_step_sizes() {
    let h = Phantom::Head.generate(64).unwrap();
    let tf = presets::builtin("ct_skin_bone").unwrap();
    let cam = View::Anterior.frame(h.grid.center(), 130.0, false);
    let at = |step: f32| {
        let mut a = Appearance::new(Mode::Dvr, tf.clone());
        a.step = step;
        render(&RenderScene::single(Arc::new(h.clone()), a), &cam, 40, 40).unwrap()
    };
    let (fine, coarse) = (at(0.25), at(0.5));
    let diff: f32 = fine.alpha.iter().zip(&coarse.alpha).map(|(a, b)| (a - b).abs()).sum::<f32>() / fine.alpha.len() as f32;
    assert!(diff < 0.02, "mean opacity difference {diff}");
    // Without correction the coarse image would be clearly less opaque.
    assert!(fine.alpha.iter().sum::<f32>() > 1.0);
}

#[test]
fn gradient_modulation_hides_homogeneous_interiors() {
    // A large uniform cube: DVR sees a dense block, gradient-modulated DVR only its faces.
    let dims = UVec3::splat(32);
    let grid = Grid::centered(dims, Vec3::ONE);
    let codes = (0..32 * 32 * 32)
        .map(|i| {
            let (x, y, z) = (i % 32, i / 32 % 32, i / 1024);
            if (4..28).contains(&x) && (4..28).contains(&y) && (4..28).contains(&z) { 200u8 } else { 0 }
        })
        .collect();
    let v = Volume::new("cube", grid, Voxels::U8(codes), ValueMap::IDENTITY, Source::default()).unwrap();
    let mut tf = opaque_ramp();
    tf.opacity = vec![OpacityPoint(0.0, 0.0), OpacityPoint(0.5, 0.1)];
    let cam =
        Camera { position: Vec3::new(0.0, 0.0, 60.0), rotation: Quat::IDENTITY, projection: Projection::Orthographic { height: 40.0 } };
    let centre =
        |mode| render(&RenderScene::single(Arc::new(v.clone()), Appearance::new(mode, tf.clone())), &cam, 9, 9).unwrap().alpha[4 * 9 + 4];
    let (dvr, grad) = (centre(Mode::Dvr), centre(Mode::GradientDvr));
    assert!(dvr > 0.9, "{dvr}");
    assert!(grad < 0.5 * dvr && grad > 0.0, "{grad} vs {dvr}");
}

#[test]
fn label_volumes_render_with_their_colours() {
    let head = phantom::head::generate(64).unwrap();
    let mut styles =
        focal::transfer::LabelTransfer::from_table(&head.labels.table, head.labels.present_ids().into_iter().map(|(id, _)| id), 0.0);
    // Only the skull, opaque.
    let skull = phantom::head::label::SKULL as u32;
    styles.styles.get_mut(&skull).unwrap().opacity = 1.0;
    let a = Appearance { lookup: Lookup::Labels(styles), ..Appearance::new(Mode::Dvr, opaque_ramp()) };
    let scene = RenderScene::single(Arc::new(head.labels.volume.clone()), a);
    let cam = View::Anterior.frame(Vec3::ZERO, 130.0, true);
    let img = render(&scene, &cam, 32, 32).unwrap();
    // The centre pixel hits the skull (its colour is near white); corners see nothing.
    let c = img.at(16, 14);
    assert!(img.alpha[14 * 32 + 16] > 0.99 && c.x > 0.5 && c.y > 0.5, "{c}");
    assert_eq!(img.alpha[0], 0.0);
}

/// Opacity per millimetre is the full data's at every level of a pyramid
/// (`Volume::opacity_reference`): a uniform slab 16 mm thick seen through, at constant
/// opacity α = 0.05, accumulates 1 − (1 − α)^(D/ℓ) with ℓ the level-0 voxel (1 mm) —
/// 0.5599 — whether drawn from level 0 or from level 1 (2 mm voxels). Had level 1 kept
/// its own voxel as ℓ, it would accumulate 1 − 0.95⁸ = 0.3366.
#[test]
fn every_level_of_a_pyramid_is_as_opaque_per_millimetre_as_level_0() {
    use focal::volume::source::VoxelSource;
    use focal::volume::source::level::read_level;
    use focal::volume::source::memory::MemorySource;
    let dims = UVec3::new(16, 16, 16);
    let v =
        Volume::new("slab", Grid::centered(dims, Vec3::ONE), Voxels::U8(vec![100; 16 * 16 * 16]), ValueMap::IDENTITY, Source::default())
            .unwrap();
    let source = MemorySource::new(Arc::new(v), 8);
    assert!(source.info().levels.len() >= 2);
    let tf = TransferFunction {
        name: "constant".into(),
        space: ValueSpace::Relative,
        units: None,
        color: vec![ColorPoint(0.0, [1.0; 3])],
        opacity: vec![OpacityPoint(0.0, 0.05)],
        lambda_t: vec![],
        lambda_s: vec![],
    };
    let want = 1.0 - 0.95f32.powf(16.0);
    for level in [0, 1] {
        let (volume, _) = read_level(&source, level, &|_| {}).unwrap();
        assert_eq!(volume.opacity_reference(), 1.0);
        let mut a = Appearance::new(Mode::Dvr, tf.clone());
        a.shading.enabled = false;
        let img = render(&RenderScene::single(Arc::new(volume), a), &top_camera(dims), 8, 8).unwrap();
        let centre = img.alpha[(4 * 8 + 4) as usize];
        assert!((centre - want).abs() < 0.01, "level {level}: opacity {centre} vs {want}");
    }
}
