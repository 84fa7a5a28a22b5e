//! GPU image tests: the ray caster on lavapipe (or any Vulkan device) against the CPU
//! reference and against measured properties of the image. One app and device serve
//! every test, run one after another (`harness = false`).
//!
//! Tolerance: the GPU filters textures in hardware, with sub-texel weights of limited
//! precision (8 fractional bits on lavapipe, as on most GPUs), so each sample may differ
//! from the reference's exact trilinear value by up to 1/256 of the local contrast; the
//! transfer function, shading and compositing propagate that. Images are compared in
//! 8-bit sRGB: the mean absolute difference must stay below 1 level and 99 % of the
//! pixels within 6 levels; a few pixels where a ray grazes a steep edge may differ more.

#[path = "gpu/bricked.rs"]
mod bricked;
#[path = "gpu/clip.rs"]
mod clip;
mod common;
#[path = "gpu/context.rs"]
mod context;
#[path = "gpu/explode.rs"]
mod explode;
#[path = "gpu/interactive.rs"]
mod interactive;
#[path = "gpu/lenses.rs"]
mod lenses;
#[path = "gpu/twolevel.rs"]
mod twolevel;
#[path = "gpu/windows.rs"]
mod windows;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;

use bevy::prelude::*;
use focal::FocalPlugins;
use focal::dataset::Dataset;
use focal::dataset::VolumeView;
use focal::reference::{RenderScene, render};
use focal::region::{Appearance, Camera as FocalCamera, Lookup, Mode, Projection as FocalProjection, View};
use focal::render::headless::Offscreen;
use focal::transfer::{ColorPoint, LabelTransfer, OpacityPoint, TransferFunction, ValueSpace, presets};
use focal::volume::phantom::{self, Phantom};
use focal::volume::{Grid, Source, ValueMap, Volume, Voxels};

const SIZE: u32 = 64;

struct Gpu {
    off: Offscreen,
}

impl Gpu {
    fn clear(&mut self) {
        let world = self.off.world_mut();
        let datasets: Vec<Entity> = world.query_filtered::<Entity, With<Dataset>>().iter(world).collect();
        let meshes: Vec<Entity> = world.query_filtered::<Entity, With<Mesh3d>>().iter(world).collect();
        let windows: Vec<Entity> = world.query_filtered::<Entity, With<focal::windows::VolumeWindow>>().iter(world).collect();
        let sources: Vec<Entity> = world.query_filtered::<Entity, With<focal::windows::SourceBox>>().iter(world).collect();
        let parts: Vec<Entity> = world.query_filtered::<Entity, With<focal::explode::Part>>().iter(world).collect();
        for e in datasets.into_iter().chain(meshes).chain(windows).chain(sources).chain(parts) {
            world.despawn(e);
        }
        self.off.set_view(VolumeView { jitter: false, ..Default::default() });
    }

    fn show(&mut self, volume: Arc<Volume>, appearance: Appearance, camera: &FocalCamera) -> image::RgbaImage {
        self.show_dataset(Dataset::new(volume, appearance), Transform::default(), camera)
    }

    fn show_dataset(&mut self, dataset: Dataset, transform: Transform, camera: &FocalCamera) -> image::RgbaImage {
        self.clear();
        self.off.world_mut().spawn((dataset, transform));
        self.off.set_camera(camera);
        self.off.capture().unwrap_or_else(|e| panic!("{e}"))
    }
}

fn cpu(volume: Arc<Volume>, appearance: Appearance, camera: &FocalCamera) -> image::RgbaImage {
    render(&RenderScene::single(volume, appearance), camera, SIZE, SIZE).unwrap().to_image().unwrap()
}

/// (mean absolute difference, 99th percentile, max) over all channels, 8-bit levels.
fn difference(a: &image::RgbaImage, b: &image::RgbaImage) -> (f32, u8, u8) {
    let mut d: Vec<u8> = a.pixels().zip(b.pixels()).flat_map(|(p, q)| (0..3).map(move |c| p[c].abs_diff(q[c]))).collect();
    let mean = d.iter().map(|&x| x as f32).sum::<f32>() / d.len() as f32;
    d.sort_unstable();
    (mean, d[d.len() * 99 / 100], d[d.len() - 1])
}

fn assert_matches(name: &str, gpu: &image::RgbaImage, cpu: &image::RgbaImage) {
    let (mean, p99, max) = difference(gpu, cpu);
    let dir = std::env::temp_dir().join("focal-gpu-tests");
    let _ = std::fs::create_dir_all(&dir);
    let _ = gpu.save(dir.join(format!("{name}-gpu.png")));
    let _ = cpu.save(dir.join(format!("{name}-cpu.png")));
    println!("    {name}: mean {mean:.3}, p99 {p99}, max {max} levels");
    assert!(
        mean < 1.0 && p99 <= 6,
        "{name}: GPU differs from the CPU reference (mean {mean:.3}, p99 {p99}, max {max}); images in {}",
        dir.display()
    );
    // Not a blank picture.
    assert!(cpu.pixels().any(|p| p[0] > 40 || p[1] > 40 || p[2] > 40), "{name}: the reference image is empty");
}

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

fn head() -> Arc<Volume> {
    Arc::new(Phantom::Head.generate(64).unwrap())
}

fn framed(v: &Volume, view: View, ortho: bool) -> FocalCamera {
    let (lo, hi) = v.grid.world_bounds();
    view.frame_box(lo, hi, 1.0, ortho)
}

fn each_mode_matches_the_reference(gpu: &mut Gpu) {
    let engine = Arc::new(Phantom::Engine.generate(64).unwrap());
    let h = head();
    let sphere = Arc::new(phantom::sphere(48, 16.0).unwrap());
    let industrial = presets::builtin("industrial_ct").unwrap();
    // MinIP needs bright surroundings: the engine with air and metal swapped.
    let inverted = {
        let Voxels::U8(c) = &engine.voxels else { unreachable!("the engine phantom is 8-bit") };
        Arc::new(
            Volume::new(
                "inverted engine",
                engine.grid.clone(),
                Voxels::U8(c.iter().map(|&v| 255 - v).collect()),
                ValueMap::IDENTITY,
                Source::default(),
            )
            .unwrap(),
        )
    };
    let cases: Vec<(&str, Arc<Volume>, Appearance, FocalCamera)> = vec![
        ("dvr_head", h.clone(), Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone").unwrap()), framed(&h, View::Oblique, false)),
        ("dvr_engine_ortho", engine.clone(), Appearance::new(Mode::Dvr, industrial.clone()), framed(&engine, View::Oblique, true)),
        (
            "gradient_dvr_engine",
            engine.clone(),
            Appearance::new(Mode::GradientDvr, industrial.clone()),
            framed(&engine, View::Anterior, false),
        ),
        (
            "mip_engine",
            engine.clone(),
            Appearance::new(Mode::Mip, presets::builtin("grayscale_ramp").unwrap()),
            framed(&engine, View::Superior, false),
        ),
        (
            "minip_inverted_engine",
            inverted.clone(),
            Appearance::new(Mode::MinIp, presets::builtin("grayscale_ramp").unwrap()),
            framed(&inverted, View::Left, true),
        ),
        (
            // MinIP above the air around the engine (radiology's value floor): the part,
            // not the black of the air every ray crosses.
            "minip_engine_above_air",
            engine.clone(),
            Appearance {
                projection_range: Some((80.0, 255.0)),
                ..Appearance::new(Mode::MinIp, presets::builtin("grayscale_ramp").unwrap())
            },
            framed(&engine, View::Oblique, false),
        ),
        (
            "xray_head",
            h.clone(),
            Appearance::new(Mode::XRay, presets::builtin("grayscale_ramp").unwrap()),
            framed(&h, View::Anterior, true),
        ),
        (
            "iso_sphere",
            sphere.clone(),
            Appearance { iso_value: 127.5, ..Appearance::new(Mode::Iso, opaque_ramp()) },
            framed(&sphere, View::Oblique, false),
        ),
    ];
    for (name, v, a, cam) in cases {
        let g = gpu.show(v.clone(), a.clone(), &cam);
        assert_matches(name, &g, &cpu(v, a, &cam));
    }
}

/// The head phantom's label volume, every label at opacity 0.3.
fn labelled_head() -> (Arc<Volume>, Appearance) {
    let h = phantom::head::generate(64).unwrap();
    let ids = h.labels.present_ids().into_iter().map(|(id, _)| id);
    let a = Appearance {
        lookup: Lookup::Labels(LabelTransfer::from_table(&h.labels.table, ids, 0.3)),
        ..Appearance::new(Mode::Dvr, opaque_ramp())
    };
    (Arc::new(h.labels.volume), a)
}

fn labels_match_the_reference(gpu: &mut Gpu) {
    let (v, a) = labelled_head();
    let cam = framed(&v, View::Oblique, false);
    let g = gpu.show(v.clone(), a.clone(), &cam);
    assert_matches("labels_head", &g, &cpu(v, a, &cam));
}

fn axis_aligned_mip_is_the_voxel_maximum(gpu: &mut Gpu) {
    let dims = UVec3::new(SIZE, SIZE, 20);
    let n = (dims.x * dims.y * dims.z) as usize;
    let codes: Vec<u8> = (0..n).map(|i| ((i as u64).wrapping_mul(2_654_435_761) >> 13) as u8).collect();
    let v =
        Arc::new(Volume::new("noise", Grid::centered(dims, Vec3::ONE), Voxels::U8(codes), ValueMap::IDENTITY, Source::default()).unwrap());
    let mut a = Appearance::new(Mode::Mip, opaque_ramp());
    a.step = 1.0;
    let cam = FocalCamera {
        position: Vec3::new(0.0, 0.0, 100.0),
        rotation: Quat::IDENTITY,
        projection: FocalProjection::Orthographic { height: SIZE as f32 },
    };
    let g = gpu.show(v.clone(), a, &cam);
    let (lo, hi) = (v.stats.min as f32, v.stats.max as f32);
    let mut worst = 0u8;
    for py in 0..SIZE {
        for px in 0..SIZE {
            let (i, j) = (px, SIZE - 1 - py);
            let max = (0..dims.z).map(|k| v.code(i, j, k)).max().unwrap_or(0) as f32;
            let want = ((max - lo) / (hi - lo) * 255.0).round() as u8;
            worst = worst.max(g.get_pixel(px, py)[0].abs_diff(want));
        }
    }
    println!("    axis-aligned MIP: worst difference {worst} levels");
    // Samples sit exactly on voxel centres, where hardware weights are 0 or 1: only the
    // 8-bit rounding of the output remains.
    assert!(worst <= 1, "MIP differs from the voxel maximum by {worst} levels");
    // The per-ray counts (render::counts): every ray crosses the 20 slices at one
    // sample a voxel (without brick skipping), and a volume in memory has no page table.
    gpu.off.set_view(VolumeView { jitter: false, skip_empty: false, ..Default::default() });
    let counts = focal::render::counts::decode(&gpu.off.capture_counts().unwrap_or_else(|e| panic!("{e}")));
    gpu.off.set_view(VolumeView { jitter: false, ..Default::default() });
    println!("    counts: {counts:?}");
    assert_eq!((counts.rays, counts.samples, counts.most), ((SIZE * SIZE) as u64, (SIZE * SIZE * dims.z) as u64, dims.z));
    assert_eq!(counts.lookups, 0.0);
    // With skipping, bricks that cannot raise a ray's maximum are jumped over.
    let skipped = focal::render::counts::decode(&gpu.off.capture_counts().unwrap_or_else(|e| panic!("{e}")));
    println!("    counts with skipping: {skipped:?}");
    assert!(skipped.samples < counts.samples, "{skipped:?}");
}

fn skipping_and_termination_keep_the_image(gpu: &mut Gpu) {
    let h = head();
    let a = Appearance::new(Mode::Dvr, presets::builtin("ct_bone").unwrap());
    let cam = framed(&h, View::Anterior, false);
    let with = gpu.show(h.clone(), a.clone(), &cam);
    gpu.off.set_view(VolumeView { jitter: false, skip_empty: false, ..Default::default() });
    let without = gpu.off.capture().unwrap();
    let (mean, _, max) = difference(&with, &without);
    println!("    skipping on/off: mean {mean:.4}, max {max}");
    assert!(max <= 1, "empty-space skipping changed the image (max {max} levels)");
    gpu.off.set_view(VolumeView { jitter: false, early_termination: false, ..Default::default() });
    let full = gpu.off.capture().unwrap();
    let (_, _, max) = difference(&with, &full);
    // Stopping at 99 % opacity leaves at most 1 % of the light.
    assert!(max <= 3, "early termination changed the image by {max} levels");
}

fn meshes_and_volume_mix_by_depth(gpu: &mut Gpu) {
    let sphere = Arc::new(phantom::sphere(48, 16.0).unwrap());
    let mut tf = opaque_ramp();
    tf.opacity = vec![OpacityPoint(0.0, 0.0), OpacityPoint(1.0, 0.02)];
    let cam = framed(&sphere, View::Anterior, true);
    let plain = gpu.show(sphere.clone(), Appearance::new(Mode::Dvr, tf.clone()), &cam);
    // A red cube inside the sphere, a green one in front of it.
    let world = gpu.off.world_mut();
    let mesh = world.resource_mut::<Assets<Mesh>>().add(Cuboid::new(8.0, 8.0, 8.0));
    let red = world.resource_mut::<Assets<StandardMaterial>>().add(StandardMaterial {
        base_color: Color::srgb(1.0, 0.0, 0.0),
        unlit: true,
        ..default()
    });
    let green = world.resource_mut::<Assets<StandardMaterial>>().add(StandardMaterial {
        base_color: Color::srgb(0.0, 1.0, 0.0),
        unlit: true,
        ..default()
    });
    world.spawn((Mesh3d(mesh.clone()), MeshMaterial3d(red), Transform::from_xyz(-10.0, 0.0, 0.0)));
    world.spawn((Mesh3d(mesh), MeshMaterial3d(green), Transform::from_xyz(10.0, 40.0, 0.0)));
    let mixed = gpu.off.capture().unwrap();
    // Pixel columns of the two cubes (the camera looks along −y from the front, so +x,
    // the patient's right, is on the image's left).
    let px = |x: f32| ((-x / (cam_height(&cam) * 0.5) * 0.5 + 0.5) * SIZE as f32) as u32;
    let (red_px, green_px, row) = (px(-10.0), px(10.0), SIZE / 2);
    let r = mixed.get_pixel(red_px, row);
    let g = mixed.get_pixel(green_px, row);
    let v = plain.get_pixel(red_px, row);
    println!("    red behind volume {r:?}, green in front {g:?}, volume alone {v:?}");
    // The green cube in front hides the volume: pure green.
    assert!(g[1] > 200 && g[0] < 30 && g[2] < 30, "{g:?}");
    // The red cube inside shows through the front half of the sphere, tinted by it; the
    // volume in front of it still adds light.
    assert!(r[0] > 100 && r[0] > r[1] && r[1] > 0, "{r:?}");
    // Behind the red cube the volume is cut: less grey than the volume alone there.
    assert!((r[1] as i32) < v[1] as i32, "{r:?} vs {v:?}");
}

fn cam_height(c: &FocalCamera) -> f32 {
    match c.projection {
        FocalProjection::Orthographic { height } => height,
        FocalProjection::Perspective { .. } => 1.0,
    }
}

fn two_datasets_in_one_scene(gpu: &mut Gpu) {
    let a = Arc::new(phantom::sphere(32, 10.0).unwrap());
    let mut b_vol = phantom::sphere(32, 6.0).unwrap();
    b_vol.grid.origin += Vec3::new(40.0, 0.0, 0.0);
    let b = Arc::new(b_vol);
    gpu.clear();
    let mut tf = opaque_ramp();
    tf.opacity = vec![OpacityPoint(0.0, 0.0), OpacityPoint(0.45, 0.0), OpacityPoint(0.55, 1.0)];
    let app = Appearance::new(Mode::Dvr, tf);
    gpu.off.world_mut().spawn((Dataset::new(a.clone(), app.clone()), Transform::default()));
    gpu.off.world_mut().spawn((Dataset::new(b.clone(), app.clone()), Transform::default()));
    let cam = View::Anterior.frame_box(Vec3::new(-16.0, -16.0, -16.0), Vec3::new(56.0, 16.0, 16.0), 1.0, true);
    gpu.off.set_camera(&cam);
    let img = gpu.off.capture().unwrap();
    let scene = RenderScene {
        regions: vec![focal::region::Region::volume_box(&a.grid, 0, 0), focal::region::Region::volume_box(&b.grid, 1, 1)],
        volumes: vec![a, b],
        appearances: vec![app.clone(), app],
        ..Default::default()
    };
    let reference = render(&scene, &cam, SIZE, SIZE).unwrap().to_image().unwrap();
    assert_matches("two_datasets", &img, &reference);
}

fn oversized_volumes_are_reduced_with_a_warning(gpu: &mut Gpu) {
    let before = *gpu.off.world_mut().resource::<focal::dataset::gpu_fit::GpuLimits>();
    gpu.off.world_mut().insert_resource(focal::dataset::gpu_fit::GpuLimits { max_dimension: 32, max_bytes: 1 << 30 });
    let h = head();
    let a = Appearance::new(Mode::Dvr, presets::builtin("ct_bone").unwrap());
    let img = gpu.show(h, a, &framed(&Phantom::Head.generate(64).unwrap(), View::Anterior, false));
    let world = gpu.off.world_mut();
    let warnings: Vec<String> = world.query::<&focal::dataset::GpuVolume>().iter(world).filter_map(|g| g.warning.clone()).collect();
    println!("    warning: {warnings:?}");
    assert_eq!(warnings.len(), 1);
    assert!(warnings[0].contains("1/2 resolution"), "{}", warnings[0]);
    assert!(img.pixels().any(|p| p[0] > 100), "the reduced volume is still drawn");
    gpu.off.world_mut().insert_resource(before);
}

/// Limits that promise more than the device holds (as a driver that overstates its
/// memory would): the atlas of a rod longer than the device's 3D textures is refused
/// inside the upload's error scopes (not by wgpu's uncaptured-error path, which quits);
/// the limits come down below it and the rod is drawn halved, with a message.
fn a_volume_the_device_refuses_comes_back_reduced_with_a_message(gpu: &mut Gpu) {
    use focal::dataset::gpu_fit::GpuLimits;
    use focal::render::health::{GpuMessages, RenderHealth};
    let world = gpu.off.world_mut();
    let device_max = world.resource::<bevy::render::renderer::RenderDevice>().limits().max_texture_dimension_3d;
    let before = *world.resource::<GpuLimits>();
    world.insert_resource(GpuLimits { max_dimension: device_max * 2, max_bytes: 1 << 30 });
    world.resource_mut::<GpuMessages>().0.clear();
    // A rod 8 voxels longer than the device's textures, 32 × 32 across with a bright
    // core, 64 mm long.
    let n = device_max + 8;
    let codes: Vec<u8> = (0..n as usize * 32 * 32)
        .map(|i| {
            let (y, z) = ((i / n as usize) % 32, i / (n as usize * 32));
            if (8..24).contains(&y) && (8..24).contains(&z) { 200 } else { 0 }
        })
        .collect();
    let grid = Grid::new(UVec3::new(n, 32, 32), Vec3::new(64.0 / n as f32, 1.0, 1.0));
    let rod = Arc::new(Volume::new("rod", grid, Voxels::U8(codes), ValueMap::IDENTITY, Source::default()).unwrap());
    let a = Appearance::new(Mode::Mip, presets::builtin("grayscale_ramp").unwrap());
    let img = gpu.show(rod.clone(), a, &framed(&rod, View::Anterior, false));
    let world = gpu.off.world_mut();
    let messages = world.resource::<GpuMessages>().0.clone();
    let limits = *world.resource::<GpuLimits>();
    let warnings: Vec<String> = world.query::<&focal::dataset::GpuVolume>().iter(world).filter_map(|g| g.warning.clone()).collect();
    let stopped = world.resource::<RenderHealth>().stopped();
    world.insert_resource(before);
    world.resource_mut::<GpuMessages>().0.clear();
    println!("    device 3D textures up to {device_max}; messages: {messages:?}; warnings: {warnings:?}");
    assert_eq!(stopped, None, "rendering goes on");
    assert!(messages.iter().any(|m| m.contains("the GPU refused the volume textures")), "{messages:?}");
    assert!(limits.max_dimension < n && limits.max_dimension <= device_max, "{limits:?}");
    assert!(warnings.iter().any(|w| w.contains("1/2 resolution")), "{warnings:?}");
    assert!(img.pixels().filter(|p| p[0] > 100).count() > 50, "the halved rod is drawn");
}

/// wgpu's error scopes belong to the thread that pushed them (its "std" feature, which
/// Bevy leaves off): an upload's scope on one thread neither catches another thread's
/// error nor is popped out of order by it. Without the feature the two scopes below are
/// one stack, and popping the first panics ("must be popped in reverse order") as the
/// app's uploads did beside Bevy's shader compiles.
fn error_scopes_are_kept_per_thread(gpu: &mut Gpu) {
    use std::sync::mpsc::channel;
    let device = gpu.off.world_mut().resource::<bevy::render::renderer::RenderDevice>().wgpu_device().clone();
    let too_long = device.limits().max_texture_dimension_3d + 1;
    let mine = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let (pushed, has_pushed) = channel();
    let (pop, may_pop) = channel();
    let other = std::thread::spawn(move || {
        let theirs = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let _ = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("longer than the device allows"),
            size: wgpu::Extent3d { width: too_long, height: 1, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: wgpu::TextureFormat::R8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let _ = pushed.send(());
        let _ = may_pop.recv();
        bevy::tasks::block_on(theirs.pop()).map(|e| e.to_string())
    });
    has_pushed.recv().expect("the other thread pushed its scope");
    let caught_here = bevy::tasks::block_on(mine.pop());
    let _ = pop.send(());
    let caught_there = other.join().expect("the other thread popped its scope");
    assert!(caught_here.is_none(), "this thread's scope caught the other's error: {caught_here:?}");
    assert!(caught_there.is_some_and(|e| e.contains("exceeds")), "the other thread's scope caught its own error");
}

/// A GPU test: its name and the function that runs it on the shared device.
type GpuTest = (&'static str, fn(&mut Gpu));

fn main() {
    let mut off = match Offscreen::new(SIZE, SIZE, |app| {
        app.add_plugins(FocalPlugins);
    }) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("GPU tests need a Vulkan device: {e}");
            std::process::exit(1);
        }
    };
    println!("GPU: {}", off.adapter_name());
    off.set_view(VolumeView { jitter: false, ..Default::default() });
    let mut gpu = Gpu { off };
    let tests: [GpuTest; 40] = [
        ("each_mode_matches_the_reference", each_mode_matches_the_reference),
        ("labels_match_the_reference", labels_match_the_reference),
        ("axis_aligned_mip_is_the_voxel_maximum", axis_aligned_mip_is_the_voxel_maximum),
        ("skipping_and_termination_keep_the_image", skipping_and_termination_keep_the_image),
        ("meshes_and_volume_mix_by_depth", meshes_and_volume_mix_by_depth),
        ("two_datasets_in_one_scene", two_datasets_in_one_scene),
        ("oversized_volumes_are_reduced_with_a_warning", oversized_volumes_are_reduced_with_a_warning),
        ("a_volume_the_device_refuses_comes_back_reduced_with_a_message", a_volume_the_device_refuses_comes_back_reduced_with_a_message),
        ("error_scopes_are_kept_per_thread", error_scopes_are_kept_per_thread),
        ("lenses_match_the_reference", lenses::lenses_match_the_reference),
        ("lens_ray_directions_match_the_reference", lenses::ray_directions_match_the_reference),
        ("magnifier_scales_a_sphere_by_m_squared", lenses::magnifier_scales_a_sphere_by_m_squared),
        ("outside_the_lens_the_image_is_unchanged", lenses::outside_the_lens_the_image_is_unchanged),
        ("antialiasing_removes_moire_where_lenses_compress", lenses::antialiasing_removes_moire_where_lenses_compress),
        ("feature_lens_matches_the_reference", lenses::feature_lens_matches_the_reference),
        ("a_lens_that_compresses_nothing_takes_no_more_samples", lenses::a_lens_that_compresses_nothing_takes_no_more_samples),
        ("antialiased_lenses_skip_empty_space_exactly", lenses::antialiased_lenses_skip_empty_space_exactly),
        (
            "a_reduced_resolution_is_the_picture_of_fewer_rays_upscaled",
            interactive::a_reduced_resolution_is_the_picture_of_fewer_rays_upscaled,
        ),
        ("a_view_at_rest_shows_the_mean_of_its_jittered_frames", interactive::a_view_at_rest_shows_the_mean_of_its_jittered_frames),
        ("context_matches_the_reference", context::context_matches_the_reference),
        ("kappa_t_zero_is_dvr_on_the_gpu", context::kappa_t_zero_is_dvr_on_the_gpu),
        ("clipping_matches_the_reference", clip::clipping_matches_the_reference),
        ("a_clip_box_inside_the_engine_makes_minip_useful", clip::a_clip_box_inside_the_engine_makes_minip_useful),
        ("occupancy_beyond_its_uniform_copy_matches_the_reference", clip::occupancy_beyond_its_uniform_copy_matches_the_reference),
        ("two_level_matches_the_reference", twolevel::two_level_matches_the_reference),
        ("overlapping_two_level_regions_match_the_reference", twolevel::overlapping_two_level_regions_match_the_reference),
        ("the_rest_draws_no_rim_beside_a_hidden_object", twolevel::the_rest_draws_no_rim_beside_a_hidden_object),
        ("a_clip_window_shows_nothing_of_the_main_view_inside", windows::a_clip_window_shows_nothing_of_the_main_view_inside),
        ("clip_windows_drawn_in_place_match_the_reference", windows::clip_windows_drawn_in_place_match_the_reference),
        ("a_magnifying_window_enlarges_its_source", windows::a_magnifying_window_enlarges_its_source),
        ("an_exploded_head_matches_the_reference", explode::an_exploded_head_matches_the_reference),
        ("eighteen_exploded_parts_match_the_reference", explode::eighteen_exploded_parts_match_the_reference),
        ("a_hundred_and_fifty_exploded_parts_match_the_reference", explode::a_hundred_and_fifty_exploded_parts_match_the_reference),
        ("a_mip_of_exploded_parts_is_one_maximum_along_the_ray", explode::a_mip_of_exploded_parts_is_one_maximum_along_the_ray),
        ("a_selection_on_its_own_grid_matches_the_reference", explode::a_selection_on_its_own_grid_matches_the_reference),
        ("bricked_ch2_converges_to_the_chosen_level_in_memory", bricked::bricked_ch2_converges_to_the_chosen_level_in_memory),
        ("two_level_on_bricked_data_matches_memory", bricked::two_level_on_bricked_data_matches_memory),
        ("exploded_parts_on_bricked_data_match_memory", bricked::exploded_parts_on_bricked_data_match_memory),
        ("context_on_bricked_data_normalises_by_the_levels_gradients", bricked::context_on_bricked_data_normalises_by_the_levels_gradients),
        (
            "a_still_bricked_view_keeps_its_frame_until_something_changes",
            bricked::a_still_bricked_view_keeps_its_frame_until_something_changes,
        ),
    ];
    let filter: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with('-')).collect();
    let mut failed = Vec::new();
    for (name, test) in tests {
        if !filter.is_empty() && !filter.iter().any(|f| name.contains(f.as_str())) {
            continue;
        }
        println!("test {name} ...");
        let t = std::time::Instant::now();
        match catch_unwind(AssertUnwindSafe(|| test(&mut gpu))) {
            Ok(()) => println!("test {name} ... ok ({:.1} s)", t.elapsed().as_secs_f32()),
            Err(_) => {
                println!("test {name} ... FAILED");
                failed.push(name);
            }
        }
    }
    if failed.is_empty() {
        println!("gpu: all passed");
    } else {
        println!("gpu: failed: {failed:?}");
        std::process::exit(1);
    }
}
