//! Volumetric windows in a headless ECS app (no GPU): each attachment under camera and
//! dataset motion, each source's map from window points to data points with its
//! magnification, the pointer-following source, fit and orientation coupling, and clip
//! windows cutting the datasets' regions.

use std::sync::Arc;

use bevy::prelude::*;
use focal::FocalCorePlugins;
use focal::dataset::{Dataset, SceneRegions};
use focal::region::{Appearance, Mode, Region};
use focal::transfer::presets;
use focal::volume::phantom::Phantom;
use focal::windows::{Attachment, Automation, Content, Fit, Orientation, Pointer3d, Source, SourceBox, Viewer, VolumeWindow};

fn app() -> App {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, TransformPlugin, FocalCorePlugins));
    app
}

/// The head phantom (64³, 240 mm across, centred on the origin) as a dataset.
fn head(app: &mut App) -> Entity {
    let v = Arc::new(Phantom::Head.generate(64).unwrap());
    let a = Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone").unwrap());
    app.world_mut().spawn((Dataset::new(v, a), Transform::default())).id()
}

fn regions(app: &App) -> Vec<Region> {
    app.world().resource::<SceneRegions>().scene.regions.clone()
}

fn position(app: &App, e: Entity) -> Vec3 {
    app.world().get::<GlobalTransform>(e).unwrap().translation()
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-3
}

#[test]
fn each_attachment_follows_what_it_is_attached_to() {
    let mut app = app();
    let data = head(&mut app);
    let viewer = app.world_mut().spawn((Viewer, Transform::from_xyz(0.0, -300.0, 0.0))).id();
    let offset = Transform::from_xyz(0.0, 0.0, -100.0);
    let window = |attachment| VolumeWindow { attachment, ..VolumeWindow::new(Vec3::splat(40.0), vec![]) };
    let room = app.world_mut().spawn((window(Attachment::Room), Transform::from_xyz(50.0, 0.0, 0.0))).id();
    let user = app.world_mut().spawn((window(Attachment::User { offset }), Transform::default())).id();
    let on_data = app.world_mut().spawn((window(Attachment::Dataset { dataset: data, offset }), Transform::default())).id();
    app.update();
    assert!(close(position(&app, room), Vec3::new(50.0, 0.0, 0.0)));
    assert!(close(position(&app, user), Vec3::new(0.0, -300.0, -100.0)));
    assert!(close(position(&app, on_data), Vec3::new(0.0, 0.0, -100.0)));
    // The user moves (the camera orbits: turned 90° about z and moved): only the
    // user's window follows, turned with the viewer.
    let turn = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
    *app.world_mut().get_mut::<Transform>(viewer).unwrap() = Transform::from_xyz(300.0, 0.0, 0.0).with_rotation(turn);
    app.update();
    assert!(close(position(&app, user), Vec3::new(300.0, 0.0, -100.0)));
    let r = app.world().get::<GlobalTransform>(user).unwrap().to_scale_rotation_translation().1;
    assert!(r.angle_between(turn) < 1e-3, "{r} vs {turn}: {}", r.angle_between(turn));
    assert!(close(position(&app, room), Vec3::new(50.0, 0.0, 0.0)));
    assert!(close(position(&app, on_data), Vec3::new(0.0, 0.0, -100.0)));
    // The world moves (the dataset is grabbed and moved): only its window follows.
    *app.world_mut().get_mut::<Transform>(data).unwrap() = Transform::from_xyz(0.0, 20.0, 0.0);
    app.update();
    assert!(close(position(&app, on_data), Vec3::new(0.0, 20.0, -100.0)));
    assert!(close(position(&app, room), Vec3::new(50.0, 0.0, 0.0)));
    assert!(close(position(&app, user), Vec3::new(300.0, 0.0, -100.0)));
}

/// The window's region of `content` and the world point in the data its `p` shows
/// (through the dataset's own voxel map).
fn shows(data_region: &Region, window_region: &Region, p: Vec3) -> Vec3 {
    let voxel = window_region.world_to_voxel.transform_point3(p);
    data_region.world_to_voxel.inverse().transform_point3(voxel)
}

#[test]
fn a_source_box_maps_the_window_onto_it_and_magnifies() {
    let mut app = app();
    let data = head(&mut app);
    let source = app.world_mut().spawn((SourceBox { size: Vec3::splat(20.0) }, Transform::from_xyz(10.0, 20.0, 0.0))).id();
    let w = VolumeWindow {
        source: Source::Box(source),
        ..VolumeWindow::new(Vec3::splat(60.0), vec![Content { dataset: data, appearance: None }])
    };
    app.world_mut().spawn((w, Transform::from_xyz(200.0, 0.0, 0.0)));
    app.update();
    let r = regions(&app);
    assert_eq!(r.len(), 2, "the dataset and the window");
    // The window's centre shows the source's centre; 30 mm across the window (its
    // half width) are 10 mm of data: ×3.
    assert!(close(shows(&r[0], &r[1], Vec3::new(200.0, 0.0, 0.0)), Vec3::new(10.0, 20.0, 0.0)));
    assert!(close(shows(&r[0], &r[1], Vec3::new(230.0, 0.0, 0.0)), Vec3::new(20.0, 20.0, 0.0)));
    // The region is the window's box: a point just outside it is not in it.
    assert!(r[1].contains(Vec3::new(229.0, 29.0, -29.0)) && !r[1].contains(Vec3::new(231.0, 0.0, 0.0)));
    // Moving the source box moves what the window shows.
    *app.world_mut().get_mut::<Transform>(source).unwrap() = Transform::from_xyz(-30.0, 0.0, 5.0);
    app.update();
    let r = regions(&app);
    assert!(close(shows(&r[0], &r[1], Vec3::new(200.0, 0.0, 0.0)), Vec3::new(-30.0, 0.0, 5.0)));
    // Its own box as source: the data in place.
    let mut app = app_with_own_window();
    app.update();
    let r = regions(&app);
    assert!(close(shows(&r[0], &r[1], Vec3::new(5.0, 6.0, 7.0)), Vec3::new(5.0, 6.0, 7.0)));
}

fn app_with_own_window() -> App {
    let mut app = app();
    let data = head(&mut app);
    app.world_mut().spawn((VolumeWindow::new(Vec3::splat(50.0), vec![Content { dataset: data, appearance: None }]), Transform::default()));
    app
}

#[test]
fn a_pointer_source_follows_the_pointer() {
    let mut app = app();
    let data = head(&mut app);
    let pointer = app.world_mut().spawn((Pointer3d, Transform::from_xyz(0.0, 40.0, 0.0))).id();
    let w = VolumeWindow {
        source: Source::Pointer { size: Vec3::splat(10.0) },
        ..VolumeWindow::new(Vec3::splat(40.0), vec![Content { dataset: data, appearance: None }])
    };
    app.world_mut().spawn((w, Transform::from_xyz(0.0, 0.0, 200.0)));
    app.update();
    let r = regions(&app);
    assert!(close(shows(&r[0], &r[1], Vec3::new(0.0, 0.0, 200.0)), Vec3::new(0.0, 40.0, 0.0)));
    // ×4: 20 mm across the window are 5 mm around the pointer.
    assert!(close(shows(&r[0], &r[1], Vec3::new(20.0, 0.0, 200.0)), Vec3::new(5.0, 40.0, 0.0)));
    *app.world_mut().get_mut::<Transform>(pointer).unwrap() = Transform::from_xyz(-50.0, 0.0, 10.0);
    app.update();
    let r = regions(&app);
    assert!(close(shows(&r[0], &r[1], Vec3::new(0.0, 0.0, 200.0)), Vec3::new(-50.0, 0.0, 10.0)));
}

#[test]
fn fit_shows_the_whole_dataset_and_coupling_keeps_the_main_view_orientation() {
    let mut app = app();
    let data = head(&mut app);
    let turned = Quat::from_rotation_z(0.5);
    let w = VolumeWindow {
        automation: Automation { fit: Some(Fit::Uniform), orientation: Orientation::MainView },
        ..VolumeWindow::new(Vec3::splat(24.0), vec![Content { dataset: data, appearance: None }])
    };
    app.world_mut().spawn((w, Transform::from_xyz(0.0, 0.0, 300.0).with_rotation(turned)));
    app.update();
    let r = regions(&app);
    // A world-in-miniature: the data's box (240 mm, centred on the origin) fits a
    // 24 mm box — turned by 0.5 rad, so its extent along the window's axes is larger
    // than 240 and the factor smaller than 1/10.
    let centre = shows(&r[0], &r[1], Vec3::new(0.0, 0.0, 300.0));
    assert!(centre.length() < 1.0, "{centre}");
    let step = shows(&r[0], &r[1], Vec3::new(1.0, 0.0, 300.0)) - centre;
    let factor = 1.0 / step.length();
    let expected = 12.0 / (120.0 * (0.5f32.cos() + 0.5f32.sin()));
    assert!((factor - expected).abs() < 1e-3, "×{factor}, expected ×{expected}");
    // Coupled to the main view: a world x step in the window is a world x step in the data.
    assert!(step.normalize().dot(Vec3::X) > 0.9999, "{step}");
}

#[test]
fn clip_windows_cut_the_datasets_and_show_their_contents() {
    let mut app = app();
    let data = head(&mut app);
    let bone = Appearance::new(Mode::Dvr, presets::builtin("ct_bone").unwrap());
    let w = VolumeWindow {
        clip: true,
        ..VolumeWindow::new(Vec3::splat(60.0), vec![Content { dataset: data, appearance: Some(bone.clone()) }])
    };
    app.world_mut().spawn((w, Transform::from_xyz(30.0, 0.0, 0.0).with_rotation(Quat::from_rotation_y(0.3))));
    app.update();
    let scene = app.world().resource::<SceneRegions>().scene.clone();
    let window = scene.regions.last().unwrap();
    assert_eq!(scene.appearances[window.appearance], bone, "the window's own appearance");
    let pieces = &scene.regions[..scene.regions.len() - 1];
    assert!(pieces.len() > 1 && pieces.len() <= 6, "{} pieces", pieces.len());
    let strictly = |r: &Region, p: Vec3| r.planes.iter().all(|pl| pl.distance(p) < -1e-3);
    for i in 0..9 {
        for j in 0..9 {
            for k in 0..9 {
                let p = Vec3::new(i as f32, j as f32, k as f32) * 25.0 - 100.0 + 0.37;
                let in_window = strictly(window, p);
                let in_data = pieces.iter().filter(|r| strictly(r, p)).count();
                assert!(!(in_window && in_data > 0), "{p}: the main view shows inside the clip window");
                assert!(in_data <= 1, "{p}: pieces overlap");
                if !in_window && !window.contains(p) {
                    assert_eq!(in_data, 1, "{p}: outside the window the dataset is whole");
                }
            }
        }
    }
    // Without clip the dataset stays one region.
    let mut app = app_with_own_window();
    app.update();
    assert_eq!(regions(&app).len(), 2);
}
