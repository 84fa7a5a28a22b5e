//! GPU tests of bricked rendering (issue 23) on real data: the Colin27 T1 MRI converted
//! to OME-Zarr, streamed brick by brick, must converge to the render of the same data
//! fully in memory at the level the view chose (plain and context-preserving DVR), and a
//! magnifier must show native voxels over a coarser context.
//!
//! Tolerance as the other GPU tests (mean below 1 level, 99 % within 6). What may differ:
//! the bricked dataset's box is level 0's (181 voxels of 1 mm: `BrickedDataset::index_box`)
//! and a level in memory has its own (level 1: 91 voxels of 2 mm, 1 mm longer on the far
//! faces, background in ch2; rays entering through those faces sample at another phase
//! of the step), and brick aprons are filtered exactly like whole textures. Opacities hold per
//! millimetre of level 0 at every level (`Volume::opacity_reference`), in memory and
//! bricked alike.

use super::*;
use focal::lens::{Lens, systems::replace_lenses};
use focal::render::gpu_types::features::BRICKED_ONLY;
use focal::streaming::bricked::{BrickedDataset, StreamStatus};
use focal::volume::convert::ome_zarr::{WriteOptions, write};
use focal::volume::readers::{ReadOptions, ome_zarr, read_volume};
use focal::volume::source::VoxelSource;
use focal::volume::source::level::read_level;

/// ch2 as an OME-Zarr pyramid in a scratch folder, opened.
fn ch2_pyramid() -> Arc<dyn VoxelSource> {
    let volume = read_volume(&common::data("mri/ch2.nii.gz"), &ReadOptions::default()).expect("ch2");
    let out = common::scratch("bricked-ch2").join("ch2.ome.zarr");
    write(&volume, &out, &WriteOptions::default(), &|_, _| {}).expect("convert");
    Arc::new(ome_zarr::open(&out).expect("open the pyramid"))
}

/// Level `k` of `source` in memory, its looks resolved against level 0's range (as the
/// bricked dataset's are).
fn level(source: &dyn VoxelSource, k: usize) -> Arc<Volume> {
    let (mut v, _) = read_level(source, k, &|_| {}).expect("level");
    if let Some((lo, hi)) = source.info().range {
        v.stats.min = v.stats.min.min(lo);
        v.stats.max = v.stats.max.max(hi);
    }
    Arc::new(v)
}

/// The converged render of `source` bricked; `only`: whether every region is bricked
/// (the ray caster then reads the brick atlas alone, `BRICKED_ONLY`).
fn show_bricked(
    gpu: &mut Gpu,
    source: &Arc<dyn VoxelSource>,
    appearance: &Appearance,
    camera: &FocalCamera,
    only: bool,
) -> image::RgbaImage {
    gpu.clear();
    let (bricked, coarse) = BrickedDataset::open(source.clone(), 256 << 20).expect("readable").expect("streamed");
    let first_within = source.info().levels.iter().position(|l| l.grid.voxel_count() <= 1 << 18).expect("a small level");
    assert_eq!(bricked.coarse, first_within, "the coarse level is the finest of at most 64³ voxels");
    gpu.off.world_mut().spawn((Dataset::new(Arc::new(coarse), appearance.clone()), Transform::default(), bricked));
    gpu.off.set_camera(camera);
    let img = gpu.off.capture().unwrap_or_else(|e| panic!("{e}"));
    let status = gpu.off.world_mut().resource::<StreamStatus>().clone();
    assert!(status.converged(), "streaming did not converge: {:?}", status.counts());
    // With the coarse level in the atlas, a scene of bricked regions alone samples the
    // brick atlas alone.
    let features = gpu.off.shader_features().unwrap_or(0);
    assert_eq!(features & BRICKED_ONLY != 0, only, "BRICKED_ONLY (features {features:#x})");
    img
}

/// Mean difference over the pixels within `radius` pixels of the image centre (or all).
fn mean_within(a: &image::RgbaImage, b: &image::RgbaImage, radius: Option<f32>) -> f32 {
    let c = SIZE as f32 / 2.0;
    let (mut sum, mut n) = (0.0, 0usize);
    for (x, y, p) in a.enumerate_pixels() {
        if radius.is_some_and(|r| ((x as f32 + 0.5 - c).powi(2) + (y as f32 + 0.5 - c).powi(2)).sqrt() > r) {
            continue;
        }
        let q = b.get_pixel(x, y);
        sum += (0..3).map(|i| p[i].abs_diff(q[i]) as f32).sum::<f32>();
        n += 3;
    }
    sum / n.max(1) as f32
}

pub fn bricked_ch2_converges_to_the_chosen_level_in_memory(gpu: &mut Gpu) {
    let source = ch2_pyramid();
    let appearance = Appearance::new(Mode::Dvr, presets::builtin("mr_default").unwrap());
    let centre = source.info().levels[0].grid.center();
    // An orthographic view 200 mm high over 64 pixels: 3.1 mm a pixel everywhere, so
    // level 1 (2 mm voxels) throughout; the coarse level 2 has 4 mm voxels.
    // (From the octant of the boxes' common corner: every ray enters through a face
    // level 0's box and level 1's share, so both march the same sample grid. Seen from
    // the far octant, rays entering through the far faces (level 1's box is 1 mm longer
    // there) sample at another phase: p99 7 levels on the sharp skin when the bricked
    // box was the coarse level's, 3 mm longer.)
    let eye = centre + Vec3::new(-0.45, -0.85, -0.27).normalize() * 400.0;
    let camera = FocalCamera::look_at(eye, centre, Vec3::Z, FocalProjection::Orthographic { height: 200.0 });
    let bricked = show_bricked(gpu, &source, &appearance, &camera, true);
    let status = gpu.off.world_mut().resource::<StreamStatus>().counts();
    assert_eq!(status.finest_wanted, Some(1), "{status:?}");
    assert!(status.wanted > 0 && status.on_gpu > 0, "{status:?}");
    let level1 = gpu.show(level(source.as_ref(), 1), appearance.clone(), &camera);
    assert_matches("bricked_ch2_level1", &bricked, &level1);
    // Not the coarse level: the bricks made a difference.
    let level2 = gpu.show(level(source.as_ref(), 2), appearance.clone(), &camera);
    let (coarse_mean, _, _) = difference(&bricked, &level2);
    println!("    against the coarse level: mean {coarse_mean:.3}");
    assert!(coarse_mean > 1.5 * difference(&bricked, &level1).0 + 0.3, "the bricked image is the coarse level's (mean {coarse_mean:.3})");

    // Context-preserving rendering (κt 3) on the bricked data: the same convergence.
    let context = Appearance {
        context: focal::context::ContextParams { kappa_t: 3.0, kappa_s: 0.5, ..Default::default() },
        ..Appearance::new(Mode::Context, presets::builtin("mr_default").unwrap())
    };
    let bricked_context = show_bricked(gpu, &source, &context, &camera, true);
    let level1_context = gpu.show(level(source.as_ref(), 1), context.clone(), &camera);
    assert_matches("bricked_ch2_context", &bricked_context, &level1_context);
    assert!(difference(&bricked_context, &bricked).0 > 1.0, "context-preserving rendering changed nothing");

    // A 4× magnifier over the middle: native voxels under it, level 1 around it.
    let plain = {
        show_bricked(gpu, &source, &appearance, &camera, true);
        gpu.off.capture_counts().unwrap_or_else(|e| panic!("{e}"))
    };
    let lens = Lens::magnifier(Vec2::ZERO, 0.5, 0.2, 4.0);
    replace_lenses(gpu.off.world_mut(), std::slice::from_ref(&lens));
    let magnified = show_bricked(gpu, &source, &appearance, &camera, true);
    let status = gpu.off.world_mut().resource::<StreamStatus>().counts();
    assert_eq!(status.finest_wanted, Some(0), "{status:?}");
    // Around the lens the context is the view without it: its rays read level 1, not
    // the native bricks drawn for the lens that they cross (the lens reaches 0.7 lens
    // units, 22.4 pixels; the level-0 bricks it wants reach further).
    let outside = |a: &image::RgbaImage, b: &image::RgbaImage| {
        let mut d: Vec<u8> = a
            .enumerate_pixels()
            .filter(|(x, y, _)| Vec2::new(*x as f32 - 31.5, *y as f32 - 31.5).length() > 24.0)
            .flat_map(|(x, y, p)| (0..3).map(move |c| (x, y, p[c], c)))
            .map(|(x, y, v, c)| v.abs_diff(b.get_pixel(x, y)[c]))
            .collect();
        d.sort_unstable();
        (d.iter().map(|&v| v as f32).sum::<f32>() / d.len().max(1) as f32, d[d.len() * 99 / 100], d[d.len() - 1])
    };
    let (mean, p99, max) = outside(&magnified, &bricked);
    println!("    around the lens against the view without it: mean {mean:.3}, p99 {p99}, max {max} levels");
    assert!(mean < 0.05 && p99 == 0, "the context around the lens changed (mean {mean:.3}, p99 {p99}, max {max})");
    // Rays under the focus step at level 0, twice as often as level 1's there without
    // the lens (they see other voxels, so only about); every sample looks its brick up
    // in the page table.
    let lensed = gpu.off.capture_counts().unwrap_or_else(|e| panic!("{e}"));
    let focus = |x: u32, y: u32| Vec2::new(x as f32 - 31.5, y as f32 - 31.5).length() < 12.0;
    use focal::render::counts::{decode, decode_where};
    let (before, after) = (decode_where(&plain, focus), decode_where(&lensed, focus));
    println!("    samples a ray in the focus: {:.1} without the lens, {:.1} with it", before.per_ray(), after.per_ray());
    assert!(after.per_ray() > 1.5 * before.per_ray(), "the lens's rays do not step finer: {after:?} vs {before:?}");
    assert!(decode(&plain).lookups_per_sample() >= 1.0, "{:?}", decode(&plain));
    // Stepping at the context's rate along the ray (VolumeView::lens_context_steps): the
    // same rays through the same native bricks at level 1's step, half the samples of
    // level 0's. (Not the counts of the view without the lens: its rays are others.)
    gpu.off.set_view(VolumeView { jitter: false, lens_context_steps: true, ..Default::default() });
    let fast_image = gpu.off.capture().unwrap_or_else(|e| panic!("{e}"));
    let fast = decode_where(&gpu.off.capture_counts().unwrap_or_else(|e| panic!("{e}")), focus);
    gpu.off.set_view(VolumeView { jitter: false, ..Default::default() });
    println!("    samples a ray in the focus at the context's steps: {:.1}", fast.per_ray());
    assert!(
        (2.0 * fast.per_ray() - after.per_ray()).abs() < 0.15 * after.per_ray(),
        "at the context's steps the lens's rays take {fast:?}, at their own {after:?}"
    );
    let (fast_mean, _, _) = difference(&fast_image, &magnified);
    assert!(fast_mean > 0.0 && fast_mean < 4.0, "context steps against native steps: mean {fast_mean:.3}");
    let native = gpu.show(level(source.as_ref(), 0), appearance.clone(), &camera);
    let blurred = gpu.show(level(source.as_ref(), 1), appearance.clone(), &camera);
    replace_lenses(gpu.off.world_mut(), &[]);
    let _ = magnified.save(std::env::temp_dir().join("focal-gpu-tests/bricked_ch2_magnifier-gpu.png"));
    let _ = native.save(std::env::temp_dir().join("focal-gpu-tests/bricked_ch2_magnifier-native.png"));
    // Inside the focus (0.5 lens units = 16 pixels; 12 pixels kept clear of the border).
    let (inside_native, inside_level1) = (mean_within(&magnified, &native, Some(12.0)), mean_within(&magnified, &blurred, Some(12.0)));
    println!("    under the lens: against level 0 mean {inside_native:.3}, against level 1 mean {inside_level1:.3}");
    assert!(inside_native < 1.0, "under the magnifier the image is not level 0's (mean {inside_native:.3})");
    assert!(inside_level1 > 2.0 * inside_native + 0.3, "level 0 and level 1 do not differ under the lens: the test shows nothing");
}

/// Two-level rendering (arteries DVR, skull MIP, ventricles X-ray, calcifications iso,
/// the rest DVR) of the 128³ head phantom's CT streamed from a pyramid in memory (coarse
/// level 1, 64³), in a view that wants level 0 throughout (0.9 of the head across 64
/// pixels: 1.8 voxels a pixel), against the CT in memory. (Context-preserving rendering
/// on bricked data has its own test below.)
pub fn two_level_on_bricked_data_matches_memory(gpu: &mut Gpu) {
    let (ct, look) = super::twolevel::segmented_head_at(128);
    let look = Appearance { mode: Mode::Dvr, ..look };
    let source: Arc<dyn VoxelSource> = Arc::new(focal::volume::source::memory::MemorySource::new(ct.clone(), 32));
    let centre = ct.grid.center();
    let extent = ct.grid.extent().max_element();
    let eye = centre + Vec3::new(0.6, -0.7, 0.4).normalize() * 2.0 * extent;
    let camera = FocalCamera::look_at(eye, centre, Vec3::Z, FocalProjection::Orthographic { height: 0.9 * extent });
    let bricked = show_bricked(gpu, &source, &look, &camera, false);
    let status = gpu.off.world_mut().resource::<StreamStatus>().counts();
    assert_eq!(status.finest_wanted, Some(0), "{status:?}");
    // Hidden for a few frames and shown again, the volume keeps its bricks on the GPU
    // (the atlas was given back as soon as no volume was bricked).
    let held = status.on_gpu;
    let visible = |gpu: &mut Gpu, on: bool| {
        let world = gpu.off.world_mut();
        let entities: Vec<Entity> = world.query_filtered::<Entity, With<Dataset>>().iter(world).collect();
        for e in entities {
            if let Some(mut d) = world.get_mut::<Dataset>(e) {
                d.visible = on;
            }
        }
    };
    visible(gpu, false);
    for _ in 0..3 {
        gpu.off.update();
    }
    let hidden = gpu.off.world_mut().resource::<StreamStatus>().counts();
    visible(gpu, true);
    gpu.off.update();
    let again = gpu.off.world_mut().resource::<StreamStatus>().counts();
    assert!(held > 0 && hidden.on_gpu == held && again.on_gpu == held, "hidden: {hidden:?}, shown again: {again:?}, before {held}");
    let memory = gpu.show(ct.clone(), look.clone(), &camera);
    assert_matches("bricked_two_level", &bricked, &memory);
    let plain = gpu.show(ct, Appearance { segmentation: None, ..look }, &camera);
    assert!(difference(&plain, &memory).0 > 2.0, "the segmentation changed little: the test shows nothing");
}

/// An exploded view on bricked data: the 128³ head phantom's CT streamed from a pyramid
/// in memory (coarse level 1), cut into two halves with the right one pushed aside
/// (placed by hand: headless apps step no physics), against the same two parts of the
/// CT in memory. Each part samples the bricks through the inverse of its motion.
pub fn exploded_parts_on_bricked_data_match_memory(gpu: &mut Gpu) {
    use focal::explode::systems::{spawn_part, volume_polyhedron};
    use focal::explode::{Exploded, Part};
    use focal::region::Plane;
    let ct = Arc::new(Phantom::Head.generate(128).expect("the head phantom"));
    let skin = Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone").expect("a built-in preset"));
    let source: Arc<dyn VoxelSource> = Arc::new(focal::volume::source::memory::MemorySource::new(ct.clone(), 32));
    let centre = ct.grid.center();
    let extent = ct.grid.extent().max_element();
    // (Near enough for level 0: a wider view, 1.6 extents high, wants the coarse level
    // alone and would test nothing streamed.)
    let aim = centre + Vec3::X * 0.15 * extent;
    let eye = aim + Vec3::new(0.2, -1.0, 0.3).normalize() * 2.0 * extent;
    let camera = FocalCamera::look_at(eye, aim, Vec3::Z, FocalProjection::Orthographic { height: 0.9 * extent });
    // The two halves of `volume`'s box, split at the middle, the right one moved by 0.3
    // of the extent along x.
    let halves = |world: &mut World, data: Entity, volume: &Volume| {
        let whole = volume_polyhedron(volume).expect("a box");
        let (left, right) = whole.split(Plane { normal: Vec3::X, offset: centre.x }).expect("two halves");
        spawn_part(world, Part::new(data, left), Transform::default());
        spawn_part(world, Part::new(data, right), Transform::from_translation(Vec3::X * 0.3 * extent));
    };

    gpu.clear();
    let (bricked, coarse) = BrickedDataset::open(source.clone(), 256 << 20).expect("readable").expect("streamed");
    assert_eq!(bricked.coarse, 1);
    let coarse = Arc::new(coarse);
    let world = gpu.off.world_mut();
    let data = world.spawn((Dataset::new(coarse.clone(), skin.clone()), Transform::default(), Exploded::default(), bricked)).id();
    halves(world, data, &coarse);
    gpu.off.set_camera(&camera);
    let streamed = gpu.off.capture().unwrap_or_else(|e| panic!("{e}"));
    let status = gpu.off.world_mut().resource::<StreamStatus>().clone();
    assert!(status.converged(), "streaming did not converge: {:?}", status.counts());
    assert_eq!(status.counts().finest_wanted, Some(0), "{:?}", status.counts());
    let features = gpu.off.shader_features().unwrap_or(0);
    assert_ne!(features & BRICKED_ONLY, 0, "both parts sample the brick atlas alone (features {features:#x})");

    gpu.clear();
    let world = gpu.off.world_mut();
    let data = world.spawn((Dataset::new(ct.clone(), skin.clone()), Transform::default(), Exploded::default())).id();
    halves(world, data, &ct);
    gpu.off.set_camera(&camera);
    let memory = gpu.off.capture().unwrap_or_else(|e| panic!("{e}"));
    assert_matches("bricked_exploded", &streamed, &memory);
    // Not the whole head: the parts moved.
    let whole = gpu.show(ct, skin, &camera);
    assert!(difference(&whole, &memory).0 > 2.0, "the halves did not move apart: the test shows nothing");
    gpu.clear();
}

/// Context-preserving rendering of the 128³ head phantom's noisy CT streamed bricked
/// (coarse level 1) in a view that wants level 0: its gradients are normalised by the
/// largest of level 0's bricks (`BrickedDataset::gradient_max`), as the CT in memory
/// normalises by its own, not by the coarse level's (per voxel of its level, the coarse
/// level's largest gradient is 1.6 times level 0's: normalised by it, every magnitude
/// would shrink and κs would ghost too little away).
pub fn context_on_bricked_data_normalises_by_the_levels_gradients(gpu: &mut Gpu) {
    let ct = Arc::new(Phantom::Head.generate(128).expect("the head phantom"));
    let source: Arc<dyn VoxelSource> = Arc::new(focal::volume::source::memory::MemorySource::new(ct.clone(), 32));
    let look = Appearance {
        context: focal::context::ContextParams { kappa_t: 2.0, kappa_s: 0.6, ..Default::default() },
        ..Appearance::new(Mode::Context, presets::builtin("ct_skin_bone").expect("a built-in preset"))
    };
    let centre = ct.grid.center();
    let extent = ct.grid.extent().max_element();
    let eye = centre + Vec3::new(-0.5, -0.8, 0.3).normalize() * 2.0 * extent;
    let camera = FocalCamera::look_at(eye, centre, Vec3::Z, FocalProjection::Orthographic { height: 0.9 * extent });
    let bricked = show_bricked(gpu, &source, &look, &camera, true);
    let status = gpu.off.world_mut().resource::<StreamStatus>().counts();
    assert_eq!(status.finest_wanted, Some(0), "{status:?}");
    let coarse_max = level(source.as_ref(), 1).gradient_max();
    println!("    largest gradient: level 0 {:.4}, coarse level {coarse_max:.4}", ct.gradient_max());
    let ratio = coarse_max.max(ct.gradient_max()) / coarse_max.min(ct.gradient_max());
    assert!(ratio > 1.3, "the levels' gradients hardly differ (×{ratio:.2}): the test shows nothing");
    let memory = gpu.show(ct, look, &camera);
    assert_matches("bricked_context_noisy", &bricked, &memory);
}

/// A still view of a converged bricked volume keeps its streaming frame and the page
/// table built from it (`streaming::unchanged`: no selection, no page table each frame),
/// and draws the same picture; a magnifier then added over the same volume is a change:
/// its native bricks come and level 0 is drawn under it, and taking it away brings the
/// first picture back. The head phantom's CT
/// (256³) streamed from a pyramid in memory (coarse level 2), 3 voxels a pixel: level 1
/// around the lens, level 0 under it.
pub fn a_still_bricked_view_keeps_its_frame_until_something_changes(gpu: &mut Gpu) {
    use focal::streaming::bricked::BrickedScene;
    let ct = Arc::new(Phantom::Head.generate(256).expect("the head phantom"));
    let look = Appearance::new(Mode::Dvr, presets::builtin("ct_bone").expect("preset"));
    let source: Arc<dyn VoxelSource> = Arc::new(focal::volume::source::memory::MemorySource::new(ct.clone(), 32));
    let centre = ct.grid.center();
    let voxel = ct.grid.spacing.max_element();
    let eye = centre + Vec3::new(0.6, -0.7, 0.4).normalize() * 300.0 * voxel;
    let camera = FocalCamera::look_at(eye, centre, Vec3::Z, FocalProjection::Orthographic { height: 3.0 * SIZE as f32 * voxel });
    let drawn = |gpu: &mut Gpu| {
        let scene = gpu.off.world_mut().resource::<BrickedScene>();
        scene.volumes.iter().flatten().next().map(|f| f.drawn.clone()).expect("a bricked frame")
    };
    let still = show_bricked(gpu, &source, &look, &camera, true);
    let status = gpu.off.world_mut().resource::<StreamStatus>().counts();
    assert_eq!(status.finest_wanted, Some(1), "{status:?}");
    let first = drawn(gpu);
    for _ in 0..3 {
        gpu.off.update();
    }
    assert!(Arc::ptr_eq(&first, &drawn(gpu)), "a still view selected its bricks again");
    let again = gpu.off.capture().unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(difference(&again, &still).2, 0, "the kept frame drew another picture");

    let lens = Lens::magnifier(Vec2::ZERO, 0.5, 0.2, 4.0);
    replace_lenses(gpu.off.world_mut(), std::slice::from_ref(&lens));
    let lensed = gpu.off.capture().unwrap_or_else(|e| panic!("{e}"));
    assert!(!Arc::ptr_eq(&first, &drawn(gpu)), "the magnifier did not change the frame");
    assert_eq!(gpu.off.world_mut().resource::<StreamStatus>().counts().finest_wanted, Some(0));
    replace_lenses(gpu.off.world_mut(), &[]);
    let without = gpu.off.capture().unwrap_or_else(|e| panic!("{e}"));
    assert_matches("bricked_lens_taken_away", &without, &still);
    // Under the lens (0.5 lens units = 16 pixels; 12 kept clear of its border) level 0,
    // as the magnifier over it in memory draws it, not level 1.
    replace_lenses(gpu.off.world_mut(), std::slice::from_ref(&lens));
    let native = gpu.show(level(source.as_ref(), 0), look.clone(), &camera);
    let blurred = gpu.show(level(source.as_ref(), 1), look.clone(), &camera);
    replace_lenses(gpu.off.world_mut(), &[]);
    let (to_native, to_level1) = (mean_within(&lensed, &native, Some(12.0)), mean_within(&lensed, &blurred, Some(12.0)));
    println!("    under the lens added to the still view: against level 0 mean {to_native:.3}, against level 1 mean {to_level1:.3}");
    assert!(to_native < 1.0, "under the magnifier added to a still view the image is not level 0's (mean {to_native:.3})");
    assert!(to_level1 > 2.0 * to_native + 0.3, "level 0 and level 1 do not differ under the lens: the test shows nothing");
}
