//! The app: background loading as headless ECS (no window, no GPU), and the whole app in
//! a virtual X server (Xvfb) on software Vulkan, checked by its screenshot.

mod common;

use std::process::Command;
use std::time::Duration;

use bevy::prelude::*;
use common::{data, scratch};
use focal::FocalCorePlugins;
use focal::dataset::Dataset;
use focal::ui::loading::{LoadRequest, LoadingPlugin, Session};

fn headless_app() -> App {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, TransformPlugin, FocalCorePlugins, LoadingPlugin));
    app
}

/// Updates until `done` holds (loads run on the task pool).
fn run_until(app: &mut App, done: impl Fn(&mut World) -> bool) {
    for _ in 0..600 {
        app.update();
        if done(app.world_mut()) {
            return;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    panic!("timed out");
}

fn dataset_names(world: &mut World) -> Vec<String> {
    world.query::<&Dataset>().iter(world).map(|d| d.volume.name.clone()).collect()
}

#[test]
fn files_load_in_the_background_and_failures_keep_the_data() {
    let mut app = headless_app();
    app.world_mut().write_message(LoadRequest::Path(data("ct/fuel.nii.gz")));
    run_until(&mut app, |w| !dataset_names(w).is_empty());
    assert_eq!(dataset_names(app.world_mut()), vec!["fuel"]);
    let session = app.world().resource::<Session>();
    assert!(session.error.is_none());
    // A plain data file gets a standard view.
    assert!(session.reframe.as_ref().is_some_and(|r| r.camera.is_none()));

    // A broken file: an error to show, and the fuel data stays.
    let dir = scratch("app-bad");
    let bad = dir.join("broken.nrrd");
    std::fs::write(&bad, "NRRD0004\ntype: short\n").unwrap();
    app.world_mut().write_message(LoadRequest::Path(bad));
    run_until(&mut app, |w| w.resource::<Session>().error.is_some());
    let e = app.world().resource::<Session>().error.clone().unwrap();
    assert!(e.contains("broken.nrrd"), "{e}");
    assert_eq!(dataset_names(app.world_mut()), vec!["fuel"]);

    // A label volume opens as labels (its table lies beside it).
    app.world_mut().write_message(LoadRequest::Path(data("labels/aal.nii.gz")));
    run_until(&mut app, |w| dataset_names(w) == vec!["aal"]);
    let world = app.world_mut();
    let d = world.query::<&Dataset>().single(world).unwrap();
    assert!(matches!(d.appearance.lookup, focal::region::Lookup::Labels(_)));
    assert_eq!(d.labels.as_ref().map(|t| t.name(1)), Some("Precentral_L".to_string()));
}

#[test]
fn scene_files_load_with_all_their_datasets() {
    let mut app = headless_app();
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/ch2_aal.ron");
    app.world_mut().write_message(LoadRequest::Path(scene));
    run_until(&mut app, |w| dataset_names(w).len() == 2);
    // The camera is the scene's own.
    let session = app.world().resource::<Session>();
    let own = session.scene.as_ref().map(|s| s.camera.clone());
    assert!(own.is_some() && session.reframe.as_ref().map(|r| r.camera.clone()) == Some(own));
    // The scene's regions follow: one per visible dataset.
    app.update();
    assert_eq!(app.world().resource::<focal::dataset::SceneRegions>().scene.regions.len(), 2);
}

#[test]
fn the_app_opens_a_window_and_shows_the_phantom() {
    if Command::new("xvfb-run").arg("--help").output().is_err() {
        panic!("xvfb-run is missing (scripts/test.sh installs xvfb)");
    }
    let dir = scratch("app-window");
    let shot = dir.join("app.png");
    let out = app_in_xvfb("1024x768", &config_dir(&shot))
        .args(["--frames", "4", "--window", "640x400", "--screenshot"])
        .arg(&shot)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let img = image::open(&shot).unwrap().to_rgba8();
    assert_eq!(img.dimensions(), (640, 400));
    // The left panel is drawn (grey UI pixels) and the viewport shows the phantom
    // (warm skin/bone colours) on black.
    let panel = img.get_pixel(100, 300);
    assert!(panel[0] > 15 && panel[0] < 80, "panel {panel:?} in {}", shot.display());
    let warm = img.pixels().filter(|p| p[0] > 150 && p[0] as u32 > p[2] as u32 + 20).count();
    assert!(warm > 2000, "only {warm} phantom-coloured pixels");
}

/// The settings folder of an app run writing `shot` (beside it, never the user's own).
fn config_dir(shot: &std::path::Path) -> std::path::PathBuf {
    shot.parent().unwrap_or(std::path::Path::new(".")).join("config")
}

/// Pixels right of column `left` and below row `top` for which `f` holds.
fn count_in(img: &image::RgbaImage, left: u32, top: u32, f: &dyn Fn(&image::Rgba<u8>) -> bool) -> usize {
    let (w, h) = img.dimensions();
    (top..h).flat_map(|y| (left..w).map(move |x| (x, y))).filter(|&(x, y)| f(img.get_pixel(x, y))).count()
}

/// The app in Xvfb on a `screen` (`WIDTHxHEIGHT`), its settings in `config`.
fn app_in_xvfb(screen: &str, config: &std::path::Path) -> Command {
    let mut c = Command::new("xvfb-run");
    c.args(["-a", "-s", &format!("-screen 0 {screen}x24")])
        .arg(env!("CARGO_BIN_EXE_focal"))
        .env("WGPU_BACKEND", std::env::var("WGPU_BACKEND").unwrap_or_else(|_| "vulkan".into()))
        .env("FOCAL_CONFIG_DIR", config);
    c
}

/// The app on `scene` (with `options`) in Xvfb on a `screen`, its window `window`: the
/// screenshot it writes to `shot` after `frames` frames (its settings beside `shot`).
fn run_app(
    scene: &std::path::Path,
    options: &[&str],
    frames: u32,
    (screen, window): (&str, &str),
    shot: &std::path::Path,
) -> image::RgbaImage {
    let out = app_in_xvfb(screen, &config_dir(shot))
        .arg(scene)
        .args(options)
        .args(["--frames", &frames.to_string(), "--window", window, "--screenshot"])
        .arg(shot)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    image::open(shot).unwrap().to_rgba8()
}

/// The app's screenshot of `scene` with `options` after 4 frames (in Xvfb, 900×600).
fn app_screenshot_with(scene: &std::path::Path, options: &[&str], shot: &std::path::Path) -> image::RgbaImage {
    run_app(scene, options, 4, ("1024x768", "900x600"), shot)
}

/// The app's screenshot of `scene` after `frames` frames (in Xvfb).
fn app_screenshot(scene: &std::path::Path, frames: u32, shot: &std::path::Path) -> image::RgbaImage {
    run_app(scene, &[], frames, ("1024x768", "800x500"), shot)
}

#[test]
fn the_app_simulates_exploded_views_and_opens_their_panel() {
    let dir = scratch("app-explode");
    // The head in two halves around the brain, at degree 0 and at degree 6.
    let scene = |degree: f32| {
        let text = format!(
            r#"(datasets: [
                (source: Phantom(kind: head, resolution: 64), appearance: (mode: dvr, preset: Some("ct_skin_bone")),
                 explode: Some((selection: Labels(dataset: 1, ids: [4, 5, 6]), parts: Grid((2, 1, 1)), degree: {degree:.1}))),
                (source: PhantomLabels(resolution: 64), appearance: (labels: Some(())), visible: false),
            ], camera: View(view: anterior))"#
        );
        let path = dir.join(format!("explode_{degree}.ron"));
        std::fs::write(&path, text).unwrap();
        path
    };
    let rest = app_screenshot(&scene(0.0), 40, &dir.join("rest.png"));
    let apart = app_screenshot(&scene(6.0), 40, &dir.join("apart.png"));
    // The panel opened on its own: the same window in both (its title bar's pixels
    // differ from the plain app's nowhere else than in the viewport).
    let differ = rest.pixels().zip(apart.pixels()).filter(|(a, b)| (0..3).any(|c| (a[c] as i32 - b[c] as i32).abs() > 40)).count();
    assert!(differ > 3000, "the halves moved apart in the app: {differ} pixels differ ({})", dir.display());
}

fn lenses(world: &mut World) -> Vec<(u32, focal::lens::Lens)> {
    let mut v: Vec<_> =
        world.query::<(&focal::lens::Lens, &focal::lens::systems::LensOrder)>().iter(world).map(|(l, o)| (o.0, l.clone())).collect();
    v.sort_by_key(|(o, _)| *o);
    v
}

#[test]
fn scenes_bring_their_lenses_and_data_files_keep_them() {
    let dir = scratch("app-lenses");
    let scene = dir.join("lensed.ron");
    std::fs::write(
        &scene,
        "(datasets: [(source: Phantom(kind: sphere, resolution: 16))],
          lenses: [(kind: magnifier(magnification: 3.0), center: (0.1, 0.0)), (kind: angular(field_of_view: 120.0), radius: 0.2)])",
    )
    .unwrap();
    let mut app = headless_app();
    app.world_mut().write_message(LoadRequest::Path(scene.clone()));
    run_until(&mut app, |w| !lenses(w).is_empty());
    let loaded = lenses(app.world_mut());
    assert_eq!(loaded.len(), 2);
    assert_eq!(loaded[0].1.kind_name(), "magnifier");
    assert_eq!(loaded[1].1.kind_name(), "angular");
    assert_eq!(loaded[0].1.center, Vec2::new(0.1, 0.0));

    // A data file keeps the lenses the user placed.
    app.world_mut().write_message(LoadRequest::Path(data("ct/fuel.nii.gz")));
    run_until(&mut app, |w| dataset_names(w) == vec!["fuel"]);
    app.update();
    assert_eq!(lenses(app.world_mut()).len(), 2);

    // A scene without lenses clears them.
    let plain = dir.join("plain.ron");
    std::fs::write(&plain, "(datasets: [(source: Phantom(kind: sphere, resolution: 16))])").unwrap();
    app.world_mut().write_message(LoadRequest::Path(plain));
    run_until(&mut app, |w| dataset_names(w) != vec!["fuel"]);
    app.update();
    assert!(lenses(app.world_mut()).is_empty());
}

#[test]
fn scenes_bring_their_windows() {
    use focal::windows::{Attachment, Source, VolumeWindow};
    let dir = scratch("app-windows");
    let scene = dir.join("windows.ron");
    std::fs::write(
        &scene,
        "(datasets: [(source: Phantom(kind: sphere, resolution: 16)), (source: Phantom(kind: head, resolution: 16))],
          windows: [
            (center: (0.0, 0.0, 0.0), size: (8.0, 8.0, 8.0), clip: true, contents: [(dataset: 1, appearance: Some((mode: mip)))]),
            (center: (50.0, 0.0, 0.0), size: (8.0, 8.0, 8.0), source: Box(center: (0.0, 0.0, 0.0), size: (4.0, 4.0, 4.0)), attachment: Dataset(0), contents: [(dataset: 0)]),
          ])",
    )
    .unwrap();
    let mut app = headless_app();
    app.world_mut().write_message(LoadRequest::Path(scene));
    let windows = |w: &mut World| w.query::<&VolumeWindow>().iter(w).cloned().collect::<Vec<_>>();
    run_until(&mut app, |w| windows(w).len() == 2);
    let mut loaded = windows(app.world_mut());
    loaded.sort_by_key(|w| w.clip);
    let head =
        app.world_mut().query::<(Entity, &Dataset)>().iter(app.world()).find(|(_, d)| d.volume.name.contains("head")).map(|(e, _)| e);
    let (magnifier, clip) = (&loaded[0], &loaded[1]);
    assert!(clip.clip && clip.contents[0].dataset == head.unwrap());
    assert_eq!(clip.contents[0].appearance.as_ref().map(|a| a.mode), Some(focal::region::Mode::Mip));
    assert!(matches!(magnifier.source, Source::Box(_)) && matches!(magnifier.attachment, Attachment::Dataset { .. }));
    // The regions: two datasets (both with the clip window's box as a hole: it cuts every
    // dataset of the main view) and the windows' contents.
    app.update();
    let scene = &app.world().resource::<focal::dataset::SceneRegions>().scene;
    assert!(scene.regions.len() >= 4, "{} regions", scene.regions.len());
    assert_eq!(scene.regions.iter().map(|r| r.holes.len()).collect::<Vec<_>>()[..2], [1, 1], "the box a hole in each dataset");
}

/// Interactive resolution as the app's camera carries it: a moving camera whose frames
/// take 200 ms draws fewer pixels (towards the 50 ms target), and once it rests the
/// picture refines to every pixel.
#[test]
fn a_moving_view_draws_fewer_pixels_and_refines_at_rest() {
    use bevy::time::TimeUpdateStrategy;
    use focal::dataset::VolumeView;
    use focal::dataset::view::Accumulate;
    use focal::interactive::InteractiveResolution;
    let mut app = headless_app();
    app.insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_millis(200)));
    let camera = app
        .world_mut()
        .spawn((Camera3d::default(), Transform::from_xyz(0.0, -100.0, 0.0), VolumeView::default(), InteractiveResolution::default()))
        .id();
    let resolution = |app: &App| app.world().get::<VolumeView>(camera).map(|v| v.resolution);
    for _ in 0..3 {
        app.update();
    }
    assert_eq!(resolution(&app), Some(1.0), "at rest from the start");
    // Orbit: a new camera position every frame.
    let mut drawn = Vec::new();
    for k in 0..8 {
        if let Some(mut t) = app.world_mut().get_mut::<Transform>(camera) {
            *t = Transform::from_xyz(100.0 * ((k + 1) as f32 * 0.1).sin(), -100.0 * ((k + 1) as f32 * 0.1).cos(), 0.0);
        }
        app.update();
        drawn.push(resolution(&app).unwrap_or(f32::NAN));
    }
    // (Frames of 200 ms against 50: a quarter of the pixels per axis would do; each
    // frame steps by at most (50/200)^¼.)
    assert!(drawn.iter().all(|s| *s < 1.0), "{drawn:?}");
    assert!(drawn.windows(2).all(|w| w[1] <= w[0]) && drawn[7] <= 0.3, "{drawn:?}");
    let moving = app.world().get::<InteractiveResolution>(camera).map(|a| a.moving);
    assert_eq!(moving, Some(true));
    // At rest: after 150 ms without change the scale doubles every frame up to 1.
    let mut rest = Vec::new();
    for _ in 0..6 {
        app.update();
        rest.push(resolution(&app).unwrap_or(f32::NAN));
    }
    assert_eq!(rest.last(), Some(&1.0), "{rest:?}");
    assert!(rest.windows(2).all(|w| w[1] >= w[0]), "{rest:?}");
    // At every pixel and at rest, frames of different jitter are averaged: the index
    // of the average and the jitter's seed count the frames.
    let accumulated = |app: &App| app.world().get::<Accumulate>(camera).map(|a| a.index);
    let seed = |app: &App| app.world().get::<VolumeView>(camera).map(|v| v.frame);
    let before = accumulated(&app).unwrap_or(0);
    app.update();
    app.update();
    assert_eq!(accumulated(&app), Some(before + 2));
    assert_eq!(seed(&app), Some(before + 2));
    // A switch of the view turned at rest is a change too: the average starts anew.
    if let Some(mut v) = app.world_mut().get_mut::<VolumeView>(camera) {
        v.skip_empty = false;
    }
    app.update();
    assert_eq!(accumulated(&app), None, "a switch turned at rest kept the old average");
    for _ in 0..8 {
        app.update();
    }
    assert!(accumulated(&app).is_some(), "no average at rest after the switch");
    // Moving again: no average, the seed back to 0.
    if let Some(mut t) = app.world_mut().get_mut::<Transform>(camera) {
        t.translation.x += 5.0;
    }
    app.update();
    assert_eq!(accumulated(&app), None);
    assert_eq!(seed(&app), Some(0));
    // Switched off, the view draws every pixel while it moves.
    if let Some(mut a) = app.world_mut().get_mut::<InteractiveResolution>(camera) {
        a.enabled = false;
    }
    if let Some(mut t) = app.world_mut().get_mut::<Transform>(camera) {
        t.translation.z += 10.0;
    }
    app.update();
    assert_eq!(resolution(&app), Some(1.0));
}

/// The first column of the 3D viewport in an app screenshot: right of the panel's
/// separator line (a grey column between the panel's fill and the black view).
fn viewport_left(img: &image::RgbaImage) -> Option<u32> {
    let (w, h) = img.dimensions();
    let grey = |x: u32, y: u32| {
        let p = img.get_pixel(x, y);
        p[0] == p[1] && p[1] == p[2]
    };
    (1..w / 2)
        .find(|&x| {
            [h / 4, h / 2, 3 * h / 4].iter().all(|&y| {
                let (before, line, after) = (img.get_pixel(x - 1, y)[0], img.get_pixel(x, y)[0], img.get_pixel(x + 1, y)[0]);
                grey(x, y) && line > before && line > 40 && after == 0
            })
        })
        .map(|x| x + 1)
}

#[test]
fn the_app_shows_what_streaming_does_in_the_viewport_over_a_clean_picture() {
    let dir = scratch("app-streaming");
    let scene = dir.join("procedural.ron");
    // A procedural volume, streamed brick by brick, drawn in blues (no yellow in it).
    std::fs::write(
        &scene,
        r#"(datasets: [(source: Procedural(dims: (256, 256, 256)), appearance: (mode: dvr, transfer: Some((
                name: "blue crests", space: Absolute, units: None,
                color: [(40000.0, (0.2, 0.4, 0.9)), (50000.0, (0.6, 0.8, 1.0))],
                opacity: [(0.0, 0.0), (41000.0, 0.0), (45000.0, 0.25), (52000.0, 0.8)]))))],
            camera: Orbit(azimuth_deg: 35.0, elevation_deg: 25.0, zoom: 0.9))"#,
    )
    .unwrap();
    let shot = dir.join("app.png");
    // (The shot waits for the streamed picture to converge, then 10 frames.)
    let img = app_screenshot(&scene, 10, &shot);
    let (w, h) = img.dimensions();
    let left = viewport_left(&img).unwrap_or_else(|| panic!("no panel beside the viewport in {}", shot.display()));
    assert!(left > 100 && left < w / 2, "viewport from x = {left} in {}", shot.display());
    // The status line (grey once every brick it asks for is drawn) sits at the bottom
    // left of the viewport, 8 points in: none of it over the panel or at the border.
    let text = |x: u32, y: u32| {
        let p = img.get_pixel(x, y);
        p[0] > 110 && p[0].abs_diff(p[1]) < 12 && p[1].abs_diff(p[2]) < 12
    };
    let band = h - 40..h;
    let columns: Vec<u32> = (left..w).filter(|&x| band.clone().any(|y| text(x, y))).collect();
    assert!(columns.len() > 100, "no status line at the bottom of the viewport in {}", shot.display());
    assert!((left + 6..left + 20).contains(&columns[0]), "the status line starts at x = {} (viewport from {left})", columns[0]);
    // Nothing of earlier frames remains: no yellow (the status line while bricks
    // were still loading) anywhere in the viewport.
    let stale = (left..w).flat_map(|x| (0..h).map(move |y| (x, y))).filter(|&(x, y)| {
        let p = img.get_pixel(x, y);
        p[0] > 150 && p[1] > 150 && p[2] < 90
    });
    assert_eq!(stale.count(), 0, "yellow text of earlier frames in {}", shot.display());
}

#[test]
fn the_app_shows_slice_views_of_the_data_under_the_3d_view() {
    let dir = scratch("app-slices");
    let shot = dir.join("slices.png");
    // ch2 with a clip window on the patient's left, front and top (the axial and sagittal
    // slices through the middle pass through it) and a ruler in the middle axial slice
    // (z = 19 mm: voxel 90 of an origin at −71).
    let scene = dir.join("window.ron");
    let text = format!(
        r#"(datasets: [(source: File({:?}), appearance: (mode: dvr, preset: Some("mr_default")))],
            rulers: [(dataset: 0, from: (-40.0, -20.0, 19.0), to: (30.0, 40.0, 19.0))],
            windows: [(center: (-30.0, 30.0, 30.0), size: (60.0, 50.0, 50.0), clip: true,
                       contents: [(dataset: 0, appearance: Some((mode: dvr, preset: Some("grayscale_ramp"))))])])"#,
        data("mri/ch2.nii.gz")
    );
    std::fs::write(&scene, text).unwrap();
    let img = app_screenshot_with(&scene, &["--slices"], &shot);
    let (w, h) = img.dimensions();
    // Under the 3D view, right of the side panel: the three slices (MRI greys, the brain
    // bright), each framed in its view's colour with the crosshair's lines.
    let left = viewport_left(&img).unwrap_or(w / 3);
    let bottom = |f: &dyn Fn(&image::Rgba<u8>) -> bool| count_in(&img, left, h * 6 / 10, f);
    let greys = bottom(&|p| p[0] == p[1] && p[1] == p[2] && p[0] > 90);
    let red = bottom(&|p| p[0] > 200 && p[1] < 110 && p[2] < 110);
    let green = bottom(&|p| p[1] > 180 && p[0] < 130 && p[2] < 130);
    let yellow = bottom(&|p| p[0] > 200 && p[1] > 190 && p[2] < 120);
    let outline = bottom(&|p| p[2] as i32 > p[0] as i32 + 60 && p[1] as i32 > p[0] as i32 + 30);
    println!("bottom of the window: {greys} bright greys, {red} red, {green} green, {yellow} yellow, {outline} window outline pixels");
    assert!(outline > 60, "the window's outline on the slices: {outline} pixels in {}", shot.display());
    // The ruler (magenta) lies in the axial slice: a line of 92 mm with its length.
    let ruler = bottom(&|p| p[0] > 180 && p[2] > 150 && p[1] < 120);
    assert!(ruler > 100, "the ruler on the slices: {ruler} pixels in {}", shot.display());
    assert!(greys > 5000, "the slices show little of the MRI: {greys} grey pixels in {}", shot.display());
    assert!(red > 100 && green > 100 && yellow > 100, "frames and crosshairs: {red} red, {green} green, {yellow} yellow");
    // The 3D view is still drawn above them.
    let view = (h / 10..h / 2).flat_map(|y| (left..w).map(move |x| (x, y))).filter(|&(x, y)| img.get_pixel(x, y)[0] > 60).count();
    assert!(view > 2000, "the 3D view shows {view} lit pixels");

    // The atlas over its MRI (the label volume is the scene's selected dataset): the
    // slices show the MRI's greys with the labels' colours over them.
    let shot = dir.join("atlas.png");
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/ch2_aal.ron");
    let img = app_screenshot_with(&scene, &["--slices"], &shot);
    let (w, h) = img.dimensions();
    let left = viewport_left(&img).unwrap_or(w / 3);
    let count = |f: &dyn Fn(&image::Rgba<u8>) -> bool| count_in(&img, left, h * 6 / 10, f);
    let greys = count(&|p| p[0] == p[1] && p[1] == p[2] && p[0] > 90);
    let coloured = count(&|p| p.0[..3].iter().max().unwrap() - p.0[..3].iter().min().unwrap() > 60);
    println!("atlas over MRI: {greys} greys, {coloured} coloured pixels");
    assert!(greys > 2000 && coloured > 2000, "{greys} greys, {coloured} coloured pixels in {}", shot.display());
}

#[test]
fn a_long_description_does_not_widen_the_panel() {
    // A NIfTI-1 file with an 80-character description and a long name (MR_Gd-like).
    let dir = scratch("app-long");
    let mut h = vec![0u8; 352];
    h[0..4].copy_from_slice(&348i32.to_le_bytes());
    for (i, d) in [3i16, 32, 32, 32, 1, 1, 1, 1].iter().enumerate() {
        h[40 + 2 * i..42 + 2 * i].copy_from_slice(&d.to_le_bytes());
    }
    h[70..72].copy_from_slice(&2i16.to_le_bytes()); // uint8
    h[72..74].copy_from_slice(&8i16.to_le_bytes());
    for (i, p) in [1.0f32, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0].iter().enumerate() {
        h[76 + 4 * i..80 + 4 * i].copy_from_slice(&p.to_le_bytes());
    }
    h[108..112].copy_from_slice(&352f32.to_le_bytes());
    h[112..116].copy_from_slice(&1f32.to_le_bytes());
    let description = "Gd-enhanced T1 MPRAGE 3D sagittal 1mm iso TR2300 TE2.98 TI900 FA9 GRAPPA2 v2.1";
    h[148..148 + description.len()].copy_from_slice(description.as_bytes());
    h[344..348].copy_from_slice(b"n+1\0");
    // A bright ball in the middle.
    let voxels: Vec<u8> = (0..32 * 32 * 32)
        .map(|n: i32| {
            let (x, y, z) = (n % 32 - 16, n / 32 % 32 - 16, n / 1024 - 16);
            if x * x + y * y + z * z < 100 { 200 } else { 0 }
        })
        .collect();
    h.extend(voxels);
    let file = dir.join("sub-01_ses-baseline_acq-MPRAGEgadolinium_run-01_T1w_defaced_resampled.nii");
    std::fs::write(&file, h).unwrap();
    let img = app_screenshot(&file, 4, &dir.join("long.png"));
    let (w, _) = img.dimensions();
    let left = viewport_left(&img).unwrap_or(w);
    assert!(left < w * 45 / 100, "the panel takes {left} of {w} pixels");
}

#[test]
fn the_app_remembers_its_panel_width_and_the_files_it_opened() {
    let dir = scratch("app-settings");
    let shot = dir.join("wide.png");
    let config = config_dir(&shot);
    std::fs::create_dir_all(&config).unwrap();
    std::fs::write(config.join("settings.ron"), "(panel_width: Some(450.0))").unwrap();
    let file = common::data("ct/fuel.nii.gz");
    let img = run_app(&file, &[], 2, ("1280x800", "1200x700"), &shot);
    let left = viewport_left(&img).expect("the viewport's edge");
    assert!((440..=462).contains(&left), "the panel is {left} px wide, not the 450 remembered ({})", shot.display());
    // The file is the first recent one, the width still remembered.
    let (settings, warning) = focal::ui::settings::Settings::read(&config.join("settings.ron"));
    assert_eq!(warning, None);
    assert_eq!(settings.recent.first(), Some(&std::fs::canonicalize(&file).unwrap()));
    assert_eq!(settings.panel_width, Some(450.0));
}

#[test]
fn the_slices_of_a_streamed_pyramid_show_its_native_voxels() {
    // ch2 as an OME-Zarr pyramid (levels 181×217×181, 91×109×91, 46×55×46): the app
    // keeps the 4 mm level in memory, the slice views read level 0's slices (1 mm).
    let dir = scratch("app-streamed-slices");
    let zarr = dir.join("ch2.ome.zarr");
    let out = Command::new(env!("CARGO_BIN_EXE_focal"))
        .arg("convert")
        .arg(data("mri/ch2.nii.gz"))
        .arg(&zarr)
        .args(["--chunk", "64", "--force"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let shot = dir.join("slices.png");
    let img = app_screenshot_with(&zarr, &["--slices"], &shot);
    let (w, h) = img.dimensions();
    let left = viewport_left(&img).unwrap_or(w / 3);
    // Neighbouring grey pixels of the slices that are exactly equal: the 4 mm level
    // magnified shows blocks (about three in four pairs equal), 1 mm voxels vary.
    let grey = |p: &image::Rgba<u8>| p[0] == p[1] && p[1] == p[2] && p[0] > 60;
    let (mut equal, mut pairs) = (0usize, 0usize);
    for y in h * 6 / 10..h {
        for x in left..w - 1 {
            let (a, b) = (img.get_pixel(x, y), img.get_pixel(x + 1, y));
            if grey(a) && grey(b) {
                pairs += 1;
                equal += usize::from(a == b);
            }
        }
    }
    println!("{equal} of {pairs} neighbouring grey pairs equal");
    assert!(pairs > 5000, "the slices show little: {pairs} grey pairs in {}", shot.display());
    assert!((equal as f64) < 0.45 * pairs as f64, "blocky slices: {equal} of {pairs} pairs equal in {}", shot.display());
}

/// A lost GPU device (the app destroys its own, as a driver reset does): the app says
/// why it stops and exits with an error, and leaves its view, with the reason, for the
/// next start to offer.
#[test]
fn a_lost_device_leaves_a_message_and_the_session() {
    let dir = scratch("app-device-lost");
    let scene = dir.join("engine-lens.ron");
    std::fs::write(
        &scene,
        r#"(datasets: [(source: Phantom(kind: engine, resolution: 48), appearance: (mode: dvr, preset: Some("industrial_ct")))],
            lenses: [(kind: magnifier(magnification: 2.0), center: (0.1, 0.0), radius: 0.25)])"#,
    )
    .unwrap();
    let config = dir.join("config");
    let mut app = app_in_xvfb("1024x768", &config)
        .arg(&scene)
        .args(["--window", "800x500", "--lose-device-after", "10"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // (The app must end by itself: a hang after the loss is a failure, not a wait.)
    let started = std::time::Instant::now();
    let status = loop {
        if let Some(s) = app.try_wait().unwrap() {
            break Some(s);
        }
        if started.elapsed() > Duration::from_secs(240) {
            let _ = app.kill();
            break None;
        }
        std::thread::sleep(Duration::from_millis(200));
    };
    let mut log = String::new();
    let _ = std::io::Read::read_to_string(&mut app.stderr.take().unwrap(), &mut log);
    let status = status.unwrap_or_else(|| panic!("the app did not end within 240 s of losing its device:\n{log}"));
    assert!(!status.success(), "a lost device is an error exit:\n{log}");
    // (Bevy reports the loss to the render error handler, or its own readbacks panic
    // on the destroyed device first: either way the app says it stopped, and why.)
    assert!(log.contains("Focal stopped: the graphics device was lost") || log.contains("Focal stopped: the renderer failed"), "{log}");
    let recovery = config.join("recovery.ron");
    let saved = focal::scene::read_scene(&recovery).unwrap_or_else(|e| panic!("the view is kept ({e}):\n{log}"));
    assert_eq!((saved.datasets.len(), saved.lenses.len()), (1, 1));
    let reason = std::fs::read_to_string(config.join("recovery-reason.txt")).unwrap();
    assert!(reason.contains("the graphics device was lost") || reason.contains("the renderer failed"), "{reason}");
}

/// A session killed with SIGKILL comes back: the app writes its view for recovery while
/// it runs (and removes it when it exits cleanly); `focal --restore` opens it, and shows
/// what the killed session showed.
#[test]
fn a_killed_session_is_restored() {
    let dir = scratch("app-recovery");
    let scene = dir.join("engine-lens.ron");
    std::fs::write(
        &scene,
        r#"(datasets: [(source: Phantom(kind: engine, resolution: 64), appearance: (mode: dvr, preset: Some("industrial_ct")))],
            camera: Orbit(azimuth_deg: 30.0, elevation_deg: 25.0, zoom: 0.85),
            lenses: [(kind: magnifier(magnification: 2.5), center: (-0.2, -0.1), radius: 0.3, border: 0.12)])"#,
    )
    .unwrap();
    // A clean run: its picture, and no recovery file left behind.
    let shot = dir.join("before.png");
    // (30 frames: on a loaded machine the lens's pipeline may still be compiling after 4.)
    let before = app_screenshot(&scene, 30, &shot);
    let config = config_dir(&shot);
    let recovery = config.join("recovery.ron");
    assert!(!recovery.exists(), "a clean exit leaves no recovery file");
    // The same scene, killed once its view is saved.
    let mut app = app_in_xvfb("1024x768", &config)
        .arg(&scene)
        .args(["--window", "800x500"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    while !recovery.exists() && started.elapsed() < Duration::from_secs(300) {
        std::thread::sleep(Duration::from_millis(200));
    }
    assert!(recovery.exists(), "no recovery file within 300 s");
    // (The app itself, not xvfb-run, whose command line also names it.)
    let pattern = format!("^{} {}", env!("CARGO_BIN_EXE_focal"), scene.display());
    let killed = Command::new("pkill").args(["-KILL", "-f", &pattern]).status().unwrap();
    assert!(killed.success(), "no process matched {pattern}");
    let _ = app.wait();
    let saved = focal::scene::read_scene(&recovery).expect("the recovery file is a valid scene");
    assert_eq!((saved.datasets.len(), saved.lenses.len()), (1, 1));
    // Restored: the killed session's view, then a clean exit that leaves nothing.
    let restored_shot = dir.join("restored.png");
    let out = app_in_xvfb("1024x768", &config)
        .args(["--restore", "--window", "800x500", "--frames", "30", "--screenshot"])
        .arg(&restored_shot)
        .output()
        .unwrap();
    let log = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{log}");
    assert!(log.contains("restored the last session's view"), "{log}");
    assert!(!recovery.exists() && !config.join("recovery-previous.ron").exists());
    let after = image::open(&restored_shot).unwrap().to_rgba8();
    assert_eq!(after.dimensions(), before.dimensions());
    // (The same view; its jittered frames accumulate over a number of frames that depends
    // on the machine's load, so shading differs by a few levels.)
    let n = (before.width() * before.height()) as f64;
    let mean =
        before.pixels().zip(after.pixels()).map(|(a, b)| (0..3).map(|c| a[c].abs_diff(b[c]) as f64).sum::<f64>() / 3.0).sum::<f64>() / n;
    let drawn = |img: &image::RgbaImage| count_in(img, img.width() * 2 / 5, 30, &|p| p.0[..3].iter().any(|&c| c > 20)) as f64;
    let (was, is) = (drawn(&before), drawn(&after));
    println!("restored: mean {mean:.2} levels, {is} drawn pixels for {was}");
    assert!(
        mean < 8.0 && (is - was).abs() < 0.03 * was,
        "the restored view differs from the killed one: mean {mean:.1} levels, {is} drawn pixels for {was} ({})",
        restored_shot.display()
    );
}
