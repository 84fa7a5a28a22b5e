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
    assert_eq!(scene.regions.len(), 2, "the dataset and the window");
    let dataset = &scene.regions[0];
    assert_eq!(dataset.holes.len(), 1, "the window's box is a hole in the dataset");
    let strictly = |r: &Region, p: Vec3| r.planes.iter().all(|pl| pl.distance(p) < -1e-3);
    let mut inside = 0;
    for i in 0..9 {
        for j in 0..9 {
            for k in 0..9 {
                let p = Vec3::new(i as f32, j as f32, k as f32) * 25.0 - 100.0 + 0.37;
                let in_window = strictly(window, p);
                assert!(!(in_window && dataset.contains(p)), "{p}: the main view shows inside the clip window");
                if !window.contains(p) && strictly(&Region { holes: vec![], ..dataset.clone() }, p) {
                    assert!(dataset.contains(p), "{p}: outside the window the dataset is whole");
                }
                inside += usize::from(in_window);
            }
        }
    }
    assert!(inside > 5, "the lattice barely met the window: {inside}");
    // A ray through the window: the dataset before the box, the window, the dataset
    // behind it, end to end.
    let (o, d) = (Vec3::new(-300.0, 0.0, 0.0), Vec3::X);
    let data = dataset.intersect(o, d);
    let win = window.intersect(o, d);
    assert_eq!((data.len(), win.len()), (2, 1), "{data:?} {win:?}");
    assert!((data[0].1 - win[0].0).abs() < 1e-3 && (win[0].1 - data[1].0).abs() < 1e-3, "{data:?} {win:?}");
    // Without clip the dataset stays one region.
    let mut app = app_with_own_window();
    app.update();
    assert_eq!(regions(&app).len(), 2);
}

/// A phantom scene with one window of each kind.
const SCENE: &str = r#"(
    datasets: [
        (source: Phantom(kind: head, resolution: 32), appearance: (mode: dvr, preset: Some("ct_skin_bone")), translation: (5.0, 0.0, 0.0)),
        (source: PhantomLabels(resolution: 32), appearance: (labels: Some(())), visible: false),
    ],
    camera: Orbit(azimuth_deg: 30.0, elevation_deg: 10.0),
    pointer: Some((10.0, 20.0, 0.0)),
    markers: [(dataset: 0, position: (1.0, 2.0, 3.0)), (dataset: 1, position: (-4.0, 0.0, 8.0))],
    windows: [
        (center: (0.0, 0.0, 40.0), size: (60.0, 60.0, 60.0), clip: true, contents: [(dataset: 0, appearance: Some((mode: mip)))]),
        (center: (200.0, 0.0, 0.0), size: (50.0, 50.0, 50.0), source: Box(center: (0.0, 30.0, 0.0), size: (20.0, 20.0, 20.0), rotation_deg: (0.0, 0.0, 30.0)), contents: [(dataset: 1)]),
        (center: (0.0, -200.0, 0.0), size: (40.0, 40.0, 40.0), source: Pointer(size: (10.0, 10.0, 10.0)), contents: [(dataset: 0)], orientation: Window(1)),
        (attachment: User, center: (20.0, 20.0, -150.0), size: (12.0, 12.0, 12.0), fit: Some(uniform), orientation: MainView, contents: [(dataset: 0)]),
        (attachment: Dataset(0), center: (0.0, 0.0, -60.0), rotation_deg: (0.0, 20.0, 0.0), size: (30.0, 30.0, 30.0), contents: [(dataset: 0)]),
    ],
)"#;

#[test]
fn scene_windows_give_the_same_regions_in_the_app_and_the_reference() {
    use focal::render::headless::camera_bundle;
    use focal::scene::file::SceneFile;
    use focal::scene::load::{camera, load_datasets, render_scene_with_windows, visible_bounds, window_appearances};
    use focal::windows::spec::replace_windows;
    let base = std::path::Path::new(".");
    let scene = SceneFile::parse(SCENE, "t").unwrap();
    scene.validate().unwrap();
    let datasets = load_datasets(&scene, base).unwrap();
    let cam = camera(&scene.camera, visible_bounds(&datasets), 1.0);
    let reference = render_scene_with_windows(&datasets, &scene, &cam, base).unwrap();
    let mut app = app();
    let entities: Vec<Entity> =
        datasets.iter().map(|d| app.world_mut().spawn((d.component(), Transform::from_matrix(Mat4::from(d.transform)))).id()).collect();
    let viewer = app.world_mut().spawn(camera_bundle(&cam).0).id();
    let looks = window_appearances(&scene, &datasets, base).unwrap();
    replace_windows(app.world_mut(), &scene.windows, &looks, &entities, Some(viewer), scene.pointer.map(|(x, y, z)| Vec3::new(x, y, z)));
    app.update();
    let ecs = app.world().resource::<SceneRegions>().scene.clone();
    // The datasets (the head with the clip window's box as a hole), then the windows'
    // regions.
    assert_eq!(ecs.regions.len(), reference.regions.len());
    assert!(reference.regions.len() > 3);
    assert_eq!(reference.regions.iter().map(|r| r.holes.len()).sum::<usize>(), 1);
    // Same regions, maybe in another order (the app orders windows by entity).
    let same = |a: &Region, b: &Region| {
        let near = |p: &focal::region::Plane, q: &focal::region::Plane| {
            (p.normal - q.normal).length() < 1e-4 && (p.offset - q.offset).abs() < 1e-2
        };
        a.planes.len() == b.planes.len()
            && a.planes.iter().zip(&b.planes).all(|(p, q)| near(p, q))
            && a.holes.len() == b.holes.len()
            && a.holes.iter().flatten().zip(b.holes.iter().flatten()).all(|(p, q)| near(p, q))
            && Mat4::from(a.world_to_voxel).abs_diff_eq(Mat4::from(b.world_to_voxel), 1e-3)
            && ecs.appearances[a.appearance] == reference.appearances[b.appearance]
            && Arc::ptr_eq(&ecs.volumes[a.volume], &reference.volumes[b.volume])
    };
    let mut unmatched: Vec<&Region> = reference.regions.iter().collect();
    for (i, a) in ecs.regions.iter().enumerate() {
        let k = unmatched.iter().position(|b| same(a, b)).unwrap_or_else(|| panic!("app region {i} is not in the reference: {a:?}"));
        unmatched.remove(k);
    }
}

#[test]
fn window_specs_with_bad_indices_are_reported() {
    use focal::scene::file::SceneFile;
    let bad = |from: &str, to: &str| SceneFile::parse(&SCENE.replace(from, to), "t").unwrap().validate().unwrap_err();
    assert!(bad("contents: [(dataset: 1)]", "contents: [(dataset: 4)]").contains("window 1: content refers to dataset 4"));
    assert!(bad("Dataset(0)", "Dataset(3)").contains("window 4: attached to dataset 3"));
    assert!(bad("Window(1)", "Window(2)").contains("window 2: orientation coupled to window 2"));
    assert!(bad("size: (12.0, 12.0, 12.0)", "size: (12.0, 0.0, 12.0)").contains("window 3: size"));
    assert!(bad("(dataset: 1, position", "(dataset: 2, position").contains("marker 1: refers to dataset 2, the scene has 2"));
    // A typo in a field is a parse error naming it.
    assert!(SceneFile::parse(&SCENE.replace("clip: true", "clips: true"), "t").unwrap_err().contains("clips"));
    assert!(SceneFile::parse(&SCENE.replace("position: (1.0", "postion: (1.0"), "t").unwrap_err().contains("postion"));
}

#[test]
fn scene_markers_are_loaded_in_their_datasets_and_saved_back() {
    use focal::scene::file::SceneFile;
    use focal::windows::markers::Marker;
    use focal::windows::spec::{marker_spec, replace_markers};
    let scene = SceneFile::parse(SCENE, "t").unwrap();
    scene.validate().unwrap();
    let mut app = app();
    let entities: Vec<Entity> = (0..2).map(|_| app.world_mut().spawn(Transform::default()).id()).collect();
    // An old marker goes.
    app.world_mut().spawn(Marker { dataset: entities[0], position: Vec3::ZERO });
    replace_markers(app.world_mut(), &scene.markers, &entities);
    let world = app.world_mut();
    let mut markers: Vec<(Entity, Marker)> = world.query::<(Entity, &Marker)>().iter(world).map(|(e, m)| (e, *m)).collect();
    // In the scene's order (the first marker lies at x = 1, the second at x = -4).
    markers.sort_by(|(_, a), (_, b)| b.position.x.total_cmp(&a.position.x));
    assert_eq!(markers.len(), 2);
    assert_eq!(markers[1].1, Marker { dataset: entities[1], position: Vec3::new(-4.0, 0.0, 8.0) });
    let saved: Vec<_> = markers.iter().filter_map(|(_, m)| marker_spec(m, |e| entities.iter().position(|d| *d == e))).collect();
    assert_eq!(saved, scene.markers);
}

#[test]
fn window_entities_are_saved_as_the_specs_they_came_from() {
    use focal::scene::file::SceneFile;
    use focal::scene::load::{load_datasets, window_appearances};
    use focal::windows::spec::{OrientationSpec, SourceSpec, replace_windows, window_spec};
    let base = std::path::Path::new(".");
    let scene = SceneFile::parse(SCENE, "t").unwrap();
    let datasets = load_datasets(&scene, base).unwrap();
    let mut app = app();
    let entities: Vec<Entity> =
        datasets.iter().map(|d| app.world_mut().spawn((d.component(), Transform::from_matrix(Mat4::from(d.transform)))).id()).collect();
    let viewer = app.world_mut().spawn((Transform::from_xyz(0.0, -400.0, 0.0),)).id();
    let looks = window_appearances(&scene, &datasets, base).unwrap();
    replace_windows(app.world_mut(), &scene.windows, &looks, &entities, Some(viewer), None);
    app.update();
    let world = app.world_mut();
    let mut windows: Vec<(Entity, VolumeWindow, Transform)> = world
        .query::<(Entity, &VolumeWindow, &GlobalTransform)>()
        .iter(world)
        .map(|(e, w, g)| (e, w.clone(), g.compute_transform()))
        .collect();
    windows.sort_by_key(|(e, ..)| *e);
    let order: Vec<Entity> = windows.iter().map(|(e, ..)| *e).collect();
    let sources: Vec<(Entity, Transform, Vec3)> =
        world.query::<(Entity, &SourceBox, &GlobalTransform)>().iter(world).map(|(e, s, g)| (e, g.compute_transform(), s.size)).collect();
    let saved: Vec<_> = windows
        .iter()
        .map(|(_, w, pose)| {
            window_spec(
                w,
                *pose,
                |e| entities.iter().position(|d| *d == e),
                |b| sources.iter().find(|(e, ..)| *e == b).map(|(_, t, s)| (*t, *s)),
                &order,
            )
        })
        .collect();
    assert_eq!(saved.len(), scene.windows.len());
    let tuple_close = |a: (f32, f32, f32), b: (f32, f32, f32)| (Vec3::from(a) - Vec3::from(b)).length() < 1e-3;
    // Saved in entity order, which need not be the file's: pair them by pose and size.
    let original = |s: &focal::windows::spec::WindowSpec| {
        scene
            .windows
            .iter()
            .find(|o| tuple_close(s.center, o.center) && tuple_close(s.size, o.size))
            .unwrap_or_else(|| panic!("{s:?} is in no original"))
    };
    for s in &saved {
        let o = original(s);
        assert!(tuple_close(s.rotation_deg, o.rotation_deg), "{s:?} vs {o:?}");
        assert_eq!((s.attachment, s.clip, s.fit), (o.attachment, o.clip, o.fit));
        match (s.orientation, o.orientation) {
            // Coupled to the same window, whatever its index.
            (OrientationSpec::Window(a), OrientationSpec::Window(b)) => assert!(tuple_close(saved[a].center, scene.windows[b].center)),
            (a, b) => assert_eq!(a, b),
        }
        assert_eq!(s.contents.iter().map(|c| c.dataset).collect::<Vec<_>>(), o.contents.iter().map(|c| c.dataset).collect::<Vec<_>>());
        let modes =
            |w: &focal::windows::spec::WindowSpec| w.contents.iter().map(|c| c.appearance.as_ref().map(|a| a.mode)).collect::<Vec<_>>();
        assert_eq!(modes(s), modes(o));
        match (s.source, o.source) {
            (SourceSpec::Box { center: a, size: b, rotation_deg: c }, SourceSpec::Box { center: x, size: y, rotation_deg: z }) => {
                assert!(tuple_close(a, x) && tuple_close(b, y) && tuple_close(c, z))
            }
            (a, b) => assert_eq!(a, b),
        }
    }
}

#[test]
fn overlapping_clip_windows_cut_the_union_and_both_show() {
    let mut app = app();
    let data = head(&mut app);
    let bone = Appearance::new(Mode::Dvr, presets::builtin("ct_bone").unwrap());
    let mip = Appearance::new(Mode::Mip, presets::builtin("grayscale_ramp").unwrap());
    for (x, look) in [(-15.0, bone), (15.0, mip)] {
        let w =
            VolumeWindow { clip: true, ..VolumeWindow::new(Vec3::splat(50.0), vec![Content { dataset: data, appearance: Some(look) }]) };
        app.world_mut().spawn((w, Transform::from_xyz(x, 0.0, 0.0)));
    }
    app.update();
    let scene = app.world().resource::<SceneRegions>().scene.clone();
    let n = scene.regions.len();
    let (datasets, windows) = scene.regions.split_at(n - 2);
    assert!(datasets.len() == 1 && datasets[0].holes.len() == 2, "the head with both boxes as holes");
    let strictly = |r: &Region, p: Vec3| r.planes.iter().all(|pl| pl.distance(p) < -1e-3);
    let in_box = |c: f32, p: Vec3| (p - Vec3::new(c, 0.0, 0.0)).abs().max_element() < 25.0 - 1e-2;
    let mut both = 0;
    for i in 0..15 {
        for j in 0..15 {
            for k in 0..15 {
                let p = Vec3::new(i as f32, j as f32, k as f32) * 7.0 - 49.0 + 0.31;
                let (a, b) = (in_box(-15.0, p), in_box(15.0, p));
                // The datasets are cut by the union of the clip boxes…
                assert_eq!(datasets[0].contains(p), !a && !b, "{p}");
                // …and each window shows its own content in its whole box, overlap included.
                assert_eq!(strictly(&windows[0], p) || strictly(&windows[1], p), a || b, "{p}");
                if a && b {
                    assert!(strictly(&windows[0], p) && strictly(&windows[1], p));
                    both += 1;
                }
            }
        }
    }
    assert!(both > 50, "the grid barely met the overlap: {both}");
}

/// A ×2 magnifier at x = 200 (source: a 40 mm box at the head's centre) and a clip
/// window of its own source at (0, 0, 60), both showing `data`.
fn magnifier_and_clip(app: &mut App, data: Entity) -> (Entity, Entity) {
    let source = app.world_mut().spawn((SourceBox { size: Vec3::splat(40.0) }, Transform::default())).id();
    let content = vec![Content { dataset: data, appearance: None }];
    let magnifier = VolumeWindow { source: Source::Box(source), ..VolumeWindow::new(Vec3::splat(80.0), content.clone()) };
    let magnifier = app.world_mut().spawn((magnifier, Transform::from_xyz(200.0, 0.0, 0.0))).id();
    let clip = VolumeWindow { clip: true, ..VolumeWindow::new(Vec3::splat(30.0), content) };
    let clip = app.world_mut().spawn((clip, Transform::from_xyz(0.0, 0.0, 60.0))).id();
    (magnifier, clip)
}

#[test]
fn focus_follows_the_cursor_and_the_pointer_reaching_in() {
    use focal::region::Ray;
    use focal::windows::systems::{CursorRay, WindowFocus};
    let mut app = app();
    let data = head(&mut app);
    let (magnifier, clip) = magnifier_and_clip(&mut app, data);
    let pointer = app.world_mut().spawn((Pointer3d, Transform::from_xyz(0.0, 0.0, -500.0))).id();
    let focus = |app: &mut App, cursor: Option<Ray>| {
        app.world_mut().resource_mut::<CursorRay>().0 = cursor;
        app.update();
        app.world().resource::<WindowFocus>().0
    };
    let looking_down = |x: f32, z: f32| Some(Ray { origin: Vec3::new(x, -1000.0, z), dir: Vec3::Y });
    // Hovering each window, then empty space (the head alone: the main view).
    assert_eq!(focus(&mut app, looking_down(200.0, 0.0)), Some(magnifier));
    assert_eq!(focus(&mut app, looking_down(0.0, 60.0)), Some(clip));
    assert_eq!(focus(&mut app, looking_down(0.0, 0.0)), None);
    // Over the panels (no cursor ray) the focus stays where it was.
    assert_eq!(focus(&mut app, looking_down(200.0, 0.0)), Some(magnifier));
    assert_eq!(focus(&mut app, None), Some(magnifier));
    // The pointer reaching into the clip window takes the focus there, whatever the
    // cursor hovers.
    app.world_mut().get_mut::<Transform>(pointer).unwrap().translation = Vec3::new(5.0, 0.0, 62.0);
    assert_eq!(focus(&mut app, looking_down(200.0, 0.0)), Some(clip));
    // A removed window loses the focus.
    app.world_mut().despawn(clip);
    assert_eq!(focus(&mut app, None), None);
}

#[test]
fn markers_show_in_every_view_of_their_point() {
    use focal::windows::markers::{Marker, MarkerViews};
    use focal::windows::systems::{delete_marker, move_marker, place_marker};
    let mut app = app();
    let data = head(&mut app);
    let (magnifier, _clip) = magnifier_and_clip(&mut app, data);
    let pointer = app.world_mut().spawn((Pointer3d, Transform::from_xyz(5.0, 0.0, 0.0))).id();
    app.update();
    let views =
        |app: &App, e: Entity| app.world().get::<MarkerViews>(e).map(|v| v.0.iter().map(|m| m.at).collect::<Vec<_>>()).unwrap_or_default();
    let same = |a: &[Vec3], b: &[Vec3]| a.len() == b.len() && a.iter().zip(b).all(|(x, y)| close(*x, *y));
    // In the main view at (5, 0, 0): the marker is on the head there, and shows in the
    // magnifier at 200 + 2·(5, 0, 0).
    let m = place_marker(app.world_mut()).expect("the pointer is in the head");
    app.update();
    assert_eq!(app.world().get::<Marker>(m).unwrap().dataset, data);
    assert!(same(&views(&app, m), &[Vec3::new(5.0, 0.0, 0.0), Vec3::new(210.0, 0.0, 0.0)]), "{:?}", views(&app, m));
    // The pointer shows in the same views.
    assert!(same(&views(&app, pointer), &[Vec3::new(5.0, 0.0, 0.0), Vec3::new(210.0, 0.0, 0.0)]));
    // Reaching into the magnifier at (190, 10, 0) marks data point (−5, 5, 0): shown
    // there in the main view and at the pointer in the magnifier.
    app.world_mut().get_mut::<Transform>(pointer).unwrap().translation = Vec3::new(190.0, 10.0, 0.0);
    app.update();
    let reached = place_marker(app.world_mut()).unwrap();
    app.update();
    assert!(close(app.world().get::<Marker>(reached).unwrap().position, Vec3::new(-5.0, 5.0, 0.0)));
    assert!(same(&views(&app, reached), &[Vec3::new(-5.0, 5.0, 0.0), Vec3::new(190.0, 10.0, 0.0)]));
    // In the clip window's box (0, 0, 60): cut from the main view, shown in the clip
    // window; outside the magnifier's source.
    app.world_mut().get_mut::<Transform>(pointer).unwrap().translation = Vec3::new(0.0, 0.0, 60.0);
    app.update();
    let clipped = place_marker(app.world_mut()).unwrap();
    app.update();
    assert!(same(&views(&app, clipped), &[Vec3::new(0.0, 0.0, 60.0)]));
    // The marker follows its dataset when the dataset moves; the magnifier's source box
    // stays, so the first marker (now at (5, 0, 10)) shows at 200 + 2·(5, 0, 10).
    *app.world_mut().get_mut::<Transform>(data).unwrap() = Transform::from_xyz(0.0, 0.0, 10.0);
    app.update();
    app.update();
    assert!(same(&views(&app, m), &[Vec3::new(5.0, 0.0, 10.0), Vec3::new(210.0, 0.0, 20.0)]), "{:?}", views(&app, m));
    // Moving the source box moves where the magnifier shows it.
    let source = match app.world().get::<VolumeWindow>(magnifier).unwrap().source {
        Source::Box(b) => b,
        _ => unreachable!(),
    };
    app.world_mut().get_mut::<Transform>(source).unwrap().translation = Vec3::new(5.0, 0.0, 0.0);
    app.update();
    app.update();
    assert!(same(&views(&app, m), &[Vec3::new(5.0, 0.0, 10.0), Vec3::new(200.0, 0.0, 20.0)]), "{:?}", views(&app, m));
    // Moving a marker with the pointer: the pointer at the data point (5, 0, 12) in the
    // main view (2 mm from the first marker).
    app.world_mut().get_mut::<Transform>(pointer).unwrap().translation = Vec3::new(5.0, 0.0, 12.0);
    app.update();
    assert!(!move_marker(app.world_mut(), 1.0), "no marker within 1 mm");
    assert!(move_marker(app.world_mut(), 3.0));
    assert!(close(app.world().get::<Marker>(m).unwrap().position, Vec3::new(5.0, 0.0, 2.0)));
    // Deleting: the nearest within the radius goes, the others stay.
    assert!(delete_marker(app.world_mut(), 3.0));
    assert!(app.world().get_entity(m).is_err());
    assert!(app.world().get_entity(reached).is_ok() && app.world().get_entity(clipped).is_ok());
    assert!(!delete_marker(app.world_mut(), 3.0));
}
