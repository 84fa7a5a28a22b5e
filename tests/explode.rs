//! Exploded views in a headless app: parts as rapier bodies stepped by hand.

use std::sync::Arc;

use bevy::prelude::*;
use focal::FocalCorePlugins;
use focal::dataset::Dataset;
use focal::explode::systems::{spawn_part, volume_polyhedron};
use focal::explode::{Exploded, ExplosionPoints, Part, step};
use focal::region::{Appearance, Mode, Plane, ray_convex};
use focal::transfer::presets;
use focal::volume::phantom::Phantom;
use focal::volume::{SelectionVolume, Volume};

#[path = "explode/edit.rs"]
mod edit;
#[path = "explode/joints.rs"]
mod joints;
#[path = "explode/paint.rs"]
mod paint;
#[path = "explode/stability.rs"]
mod stability;

fn app() -> App {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, TransformPlugin, FocalCorePlugins));
    app
}

/// A sphere of radius `r` mm at the centre of `volume`'s grid selected.
fn central_selection(volume: &Volume, r: f32) -> SelectionVolume {
    let g = &volume.grid;
    let to_world = g.index_to_world();
    let codes = (0..g.voxel_count())
        .map(|i| {
            let (x, y, z) = (i as u32 % g.dims.x, i as u32 / g.dims.x % g.dims.y, i as u32 / (g.dims.x * g.dims.y));
            let p = to_world.transform_point3(Vec3::new(x as f32, y as f32, z as f32));
            if p.distance(g.center()) <= r { 255 } else { 0 }
        })
        .collect();
    SelectionVolume::from_codes(g.clone(), codes).unwrap()
}

/// The head CT (64³, 240 mm) exploded around a 40 mm sphere at its centre, its box
/// split into `n`³ parts by planes along the axes. Returns the dataset and the parts.
fn exploded_head(app: &mut App, n: u32) -> (Entity, Vec<Entity>) {
    let v = Arc::new(Phantom::Head.generate(64).unwrap());
    let a = Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone").unwrap());
    let exploded = Exploded::around(&central_selection(&v, 40.0));
    let dataset = app.world_mut().spawn((Dataset::new(v.clone(), a), Transform::default(), exploded)).id();
    let mut pieces = vec![volume_polyhedron(&v).unwrap()];
    let (lo, hi) = v.grid.world_bounds();
    for axis in 0..3 {
        for k in 1..n {
            let at = lo[axis] + (hi[axis] - lo[axis]) * k as f32 / n as f32;
            let plane = Plane { normal: Vec3::AXES[axis], offset: at };
            pieces = pieces.into_iter().flat_map(|p| p.split(plane).map_or_else(|| vec![p.clone()], |(a, b)| vec![a, b])).collect();
        }
    }
    assert_eq!(pieces.len(), (n * n * n) as usize);
    let parts = pieces.into_iter().map(|rest| spawn_part(app.world_mut(), Part::new(dataset, rest), Transform::default())).collect();
    app.update();
    (dataset, parts)
}

fn motion(app: &App, part: Entity) -> Transform {
    *app.world().get::<Transform>(part).unwrap()
}

fn set_degree(app: &mut App, dataset: Entity, degree: f32) {
    app.world_mut().get_mut::<Exploded>(dataset).unwrap().coefficients.degree = degree;
}

fn centre(app: &App, part: Entity) -> Vec3 {
    let p = app.world().get::<Part>(part).unwrap();
    motion(app, part).transform_point(p.rest.centroid())
}

/// The share of the explosion points that some part hides from `eye` (the segment from
/// the eye to the point crosses a part before it).
fn hidden_share(app: &App, dataset: Entity, parts: &[Entity], eye: Vec3) -> f32 {
    let points = &app.world().get::<ExplosionPoints>(dataset).unwrap().points;
    let hidden = points
        .iter()
        .filter(|p| {
            let to = p.position - eye;
            parts.iter().any(|&e| {
                let part = app.world().get::<Part>(e).unwrap();
                let m = motion(app, e).compute_affine();
                let planes: Vec<Plane> =
                    part.rest.planes.iter().map(|pl| focal::explode::splitters::in_part_frame(*pl, m.inverse())).collect();
                ray_convex(&planes, eye, to).is_some_and(|(t0, t1)| t1 > 0.0 && t0 < 0.999)
            })
        })
        .count();
    hidden as f32 / points.len().max(1) as f32
}

#[test]
fn at_degree_zero_every_part_stays_in_place() {
    let mut app = app();
    let (_, parts) = exploded_head(&mut app, 2);
    step(app.world_mut(), 300);
    for p in parts {
        let t = motion(&app, p);
        assert!(t.translation.length() < 1e-3 && t.rotation.angle_between(Quat::IDENTITY) < 1e-4, "{t:?}");
    }
}

#[test]
fn raising_the_degree_moves_parts_off_the_selection_and_back() {
    let mut app = app();
    let (dataset, parts) = exploded_head(&mut app, 2);
    let points = app.world().get::<ExplosionPoints>(dataset).unwrap().points.clone();
    // Within the bricks the 40 mm sphere touches (30 mm bricks, with their aprons).
    assert!(!points.is_empty() && points.iter().all(|p| p.position.length() < 40.0 + 30.0 * 3f32.sqrt()), "{points:?}");
    let eye = Vec3::new(40.0, 600.0, 90.0);
    let before: Vec<f32> = parts.iter().map(|p| centre(&app, *p).length()).collect();
    let hidden_before = hidden_share(&app, dataset, &parts, eye);
    assert!(hidden_before > 0.99, "at rest the parts hide the selection: {hidden_before}");
    set_degree(&mut app, dataset, 1.0);
    step(app.world_mut(), 600);
    let after: Vec<f32> = parts.iter().map(|p| centre(&app, *p).length()).collect();
    for (b, a) in before.iter().zip(&after) {
        assert!(a > &(b + 10.0), "every part moved away from the selection: {b} → {a}");
    }
    let hidden_after = hidden_share(&app, dataset, &parts, eye);
    assert!(hidden_after < 0.9 * hidden_before, "the selection shows: {hidden_before} → {hidden_after}");
    // A higher degree moves them further, and shows more of the selection.
    set_degree(&mut app, dataset, 2.0);
    step(app.world_mut(), 600);
    let further: Vec<f32> = parts.iter().map(|p| centre(&app, *p).length()).collect();
    assert!(further.iter().zip(&after).all(|(f, a)| f > a), "{after:?} → {further:?}");
    let hidden_further = hidden_share(&app, dataset, &parts, eye);
    assert!(hidden_further < hidden_after && hidden_further < 0.6, "{hidden_after} → {hidden_further}");
    // Back to 0: every part returns to its place.
    set_degree(&mut app, dataset, 0.0);
    step(app.world_mut(), 2000);
    for p in &parts {
        let t = motion(&app, *p);
        assert!(t.translation.length() < 0.5 && t.rotation.angle_between(Quat::IDENTITY) < 1e-2, "{t:?}");
    }
}

#[test]
fn a_part_of_infinite_mass_never_moves() {
    let mut app = app();
    let (dataset, parts) = exploded_head(&mut app, 2);
    app.world_mut().get_mut::<Part>(parts[0]).unwrap().fixed = true;
    app.update();
    set_degree(&mut app, dataset, 2.0);
    step(app.world_mut(), 400);
    assert_eq!(motion(&app, parts[0]), Transform::default(), "the fixed part");
    assert!(motion(&app, parts[1]).translation.length() > 5.0, "the others move");
}

#[test]
fn parts_become_regions_that_carry_their_data() {
    let mut app = app();
    let (dataset, parts) = exploded_head(&mut app, 2);
    set_degree(&mut app, dataset, 1.0);
    step(app.world_mut(), 300);
    app.update();
    let scene = app.world().resource::<focal::dataset::SceneRegions>().scene.clone();
    assert_eq!(scene.regions.len(), parts.len() + 1, "one region per part, then the selection's");
    let keep = |r: &focal::region::Region| scene.appearances[r.appearance].selection.as_ref().map(|w| w.keep);
    assert!(scene.regions[..parts.len()].iter().all(|r| keep(r) == Some(focal::region::Keep::Unselected)));
    assert_eq!(keep(&scene.regions[parts.len()]), Some(focal::region::Keep::Selected));
    let scene = focal::region::RenderScene { regions: scene.regions[..parts.len()].to_vec(), ..scene };
    // Each part's centre maps back to where it was at rest.
    for e in &parts {
        let part = app.world().get::<Part>(*e).unwrap();
        let now = centre(&app, *e);
        let holding: Vec<_> = scene.regions.iter().filter(|r| r.contains(now)).collect();
        assert_eq!(holding.len(), 1, "one part holds each centre");
        let g = &app.world().get::<Dataset>(dataset).unwrap().volume.grid;
        let rest_voxel = g.world_to_index().transform_point3(part.rest.centroid());
        assert!((holding[0].world_to_voxel.transform_point3(now) - rest_voxel).length() < 1e-2);
    }
    // A hidden part draws nothing.
    app.world_mut().get_mut::<Part>(parts[0]).unwrap().hidden = true;
    app.update();
    assert_eq!(app.world().resource::<focal::dataset::SceneRegions>().scene.regions.len(), parts.len());
}

#[test]
fn sixty_four_parts_stay_stable_for_ten_thousand_steps() {
    let mut app = app();
    let (dataset, parts) = exploded_head(&mut app, 4);
    let diagonal = 240.0 * 3f32.sqrt();
    for round in 0..10 {
        // The degree goes up and down, as a user drags the slider.
        set_degree(&mut app, dataset, [0.0, 1.0, 3.0, 0.5, 2.0, 0.0, 3.0, 3.0, 1.0, 0.0][round]);
        step(app.world_mut(), 1000);
        for p in &parts {
            let t = motion(&app, *p);
            assert!(t.translation.is_finite() && t.rotation.is_finite(), "round {round}: {t:?}");
            assert!(t.translation.length() < 2.0 * diagonal, "round {round}: a part flew off to {}", t.translation);
        }
    }
    // Ended at degree 0: all back.
    let worst = parts.iter().map(|p| motion(&app, *p).translation.length()).fold(0.0, f32::max);
    assert!(worst < 1.0, "{worst} mm off");
}

#[test]
fn at_rest_the_exploded_dataset_looks_as_before_and_exploded_its_selection_stays() {
    use focal::reference::render;
    use focal::region::{RenderScene, View};
    let mut app = app();
    let (dataset, _) = exploded_head(&mut app, 2);
    app.update();
    let exploded = app.world().resource::<focal::dataset::SceneRegions>().scene.clone();
    let d = app.world().get::<Dataset>(dataset).unwrap().clone();
    let plain = RenderScene::single(d.volume.clone(), d.appearance.clone());
    let cam = View::Anterior.frame(Vec3::ZERO, 140.0, true);
    let (a, b) = (render(&plain, &cam, 40, 40).unwrap(), render(&exploded, &cam, 40, 40).unwrap());
    // The parts draw the data less the selection, the selection the rest: the same
    // picture but where the degree of interest falls from 1 to 0 (there both draw a
    // fraction and the two fractions composite to a little less).
    let diff: Vec<f32> = a.rgba.iter().zip(&b.rgba).map(|(p, q)| (*p - *q).abs().max_element()).collect();
    let mean = diff.iter().sum::<f32>() / diff.len() as f32;
    assert!(mean < 0.01, "mean difference {mean}");
    // Cut open at the front (skin and skull off the selection): seen through a clip plane
    // the selection's data shows; exploded, the selection alone still draws it where it
    // was, the parts pushed away.
    set_degree(&mut app, dataset, 2.0);
    step(app.world_mut(), 600);
    app.update();
    let scene = app.world().resource::<focal::dataset::SceneRegions>().scene.clone();
    let n = scene.regions.len();
    let selection_only = RenderScene { regions: scene.regions[n - 1..].to_vec(), ..scene.clone() };
    let parts_only = RenderScene { regions: scene.regions[..n - 1].to_vec(), ..scene };
    let (s, p) = (render(&selection_only, &cam, 40, 40).unwrap(), render(&parts_only, &cam, 40, 40).unwrap());
    let centre = 20 * 40 + 20;
    assert!(s.alpha[centre] > 0.5, "the selection draws its data at the centre: {}", s.alpha[centre]);
    let covered = s.alpha.iter().filter(|a| **a > 0.05).count();
    assert!(covered > 20 && covered < 400, "the 40 mm sphere, not more: {covered} pixels");
    // And the parts have left the middle of the view (the 2×2×2 octants part along
    // the axes): its ray meets less of them than it met of the whole head.
    assert!(p.alpha[centre] < 0.5 * a.alpha[centre], "{} vs {}", p.alpha[centre], a.alpha[centre]);
}

#[test]
fn parts_at_rest_draw_as_one_region_and_the_selection_only_where_it_can_draw() {
    use focal::dataset::SceneRegions;
    let mut app = app();
    let (dataset, parts) = exploded_head(&mut app, 4);
    app.update();
    let scene = app.world().resource::<SceneRegions>().scene.clone();
    // At rest: the 64 parts as the one box, and the selection's region.
    assert_eq!(scene.regions.len(), 2);
    let volume = app.world().get::<Dataset>(dataset).unwrap().volume.clone();
    let (lo, hi) = volume.grid.world_bounds();
    let box_vertices = focal::region::vertices(&scene.regions[0].planes);
    assert!(box_vertices.iter().all(|v| v.cmpge(lo - 1e-3).all() && v.cmple(hi + 1e-3).all()));
    // The selection's region holds the 40 mm sphere and little more (its bricks of 8
    // voxels, 30 mm at 3.75 mm a voxel, aprons included).
    let sel = focal::region::vertices(&scene.regions[1].planes);
    let centre = volume.grid.center();
    assert!(sel.iter().all(|v| (*v - centre).abs().max_element() < 40.0 + 2.0 * 30.0), "{sel:?}");
    assert!(sel.iter().any(|v| (*v - centre).abs().max_element() >= 40.0));
    // The two overlap: the ray caster is told to composite both there (a sample inside
    // both must not be the selection's alone), the selection drawn in the parts'
    // samples (render::pack::companions) or the two paired.
    let prepared = focal::reference::prepare(&scene).unwrap();
    assert!(focal::render::pack::overlaps(&prepared.iter().collect::<Vec<_>>()).dvr_pairs);
    use focal::render::gpu_types::features::{COMPANION, DVR_PAIRS};
    assert_ne!(focal::render::pack::pack(&scene, 2048).unwrap().features & (COMPANION | DVR_PAIRS), 0);
    // Exploded: a region per part; the parts that do not meet the selection's box
    // draw without its weight, those that do with it.
    set_degree(&mut app, dataset, 1.0);
    step(app.world_mut(), 120);
    app.update();
    let scene = app.world().resource::<SceneRegions>().scene.clone();
    assert_eq!(scene.regions.len(), parts.len() + 1);
    let weighted = scene.regions[..parts.len()].iter().filter(|r| scene.appearances[r.appearance].selection.is_some()).count();
    assert!(weighted > 0 && weighted < parts.len(), "{weighted} of {} parts weighted", parts.len());
    // Back at rest, one box again.
    set_degree(&mut app, dataset, 0.0);
    step(app.world_mut(), 1200);
    app.update();
    assert_eq!(app.world().resource::<SceneRegions>().scene.regions.len(), 2);
}

#[test]
fn scene_files_explode_datasets() {
    use focal::scene::file::SceneFile;
    use focal::scene::load::{apply, load_datasets};
    let text = r#"(
        datasets: [
            (source: Phantom(kind: head, resolution: 32), explode: Some((
                selection: Labels(dataset: 1, ids: [7]), parts: Grid((2, 1, 2)), fixed: [3], degree: 0.5,
                groups: [[1, 2]], hidden: [0],
                joints: [(kind: hinge, part: 0, anchor: (0.0, 0.0, 0.0), axis: (0.0, 0.0, 1.0))],
            ))),
            (source: PhantomLabels(resolution: 32), appearance: (labels: Some(())), visible: false),
        ],
        frames: [(name: "up", set: [Explode(dataset: 0, degree: Some(2.0), viewing: Some(true))], settle: Some(100))],
    )"#;
    let mut scene = SceneFile::parse(text, "t.ron").unwrap();
    scene.validate().unwrap();
    let base = std::path::Path::new(".");
    let mut datasets = load_datasets(&scene, base).unwrap();
    let x = datasets[0].explode.as_ref().unwrap();
    assert_eq!((x.parts.len(), x.spec.fixed.clone(), x.exploded.coefficients.degree), (4, vec![3], 0.5));
    assert!(x.exploded.selection.as_ref().unwrap().bricks().max.iter().any(|m| *m > 0), "the arteries are selected");
    let change = scene.frames[0].set[0].clone();
    apply(&change, &mut datasets, &mut scene, base).unwrap();
    let x = datasets[0].explode.as_ref().unwrap();
    assert!(x.exploded.coefficients.degree == 2.0 && x.exploded.viewing);
    // In an app: the dataset exploded into its parts, the fixed one fixed.
    let mut app = app();
    let e = app.world_mut().spawn((datasets[0].component(), Transform::default())).id();
    focal::explode::spec::replace_explosion(app.world_mut(), e, datasets[0].explode.as_ref());
    let parts: Vec<Part> = app.world_mut().query::<&Part>().iter(app.world()).cloned().collect();
    assert_eq!(parts.len(), 4);
    assert_eq!(parts.iter().filter(|p| p.fixed).count(), 1);
    assert_eq!(parts.iter().filter(|p| p.hidden).count(), 1);
    assert_eq!(parts.iter().filter(|p| p.group == Some(0)).count(), 2);
    let joints: Vec<focal::explode::PartJoint> = app.world_mut().query::<&focal::explode::PartJoint>().iter(app.world()).cloned().collect();
    assert_eq!(joints.len(), 1);
    assert!(joints[0].kind == focal::explode::JointKind::Hinge && joints[0].to.is_none());
    // Mistakes name the dataset and the problem.
    let err = |t: &str| SceneFile::parse(t, "t.ron").and_then(|s| s.validate().map(|_| s)).err().unwrap_or_default();
    assert!(
        err("(datasets: [(source: Phantom(kind: head), explode: Some((selection: Labels(dataset: 4, ids: [1]))))])")
            .contains("dataset 0: explode")
    );
    assert!(
        err("(datasets: [(source: Phantom(kind: head), explode: Some((selection: Range(lo: 0.0, hi: 1.0), degre: 1.0)))])")
            .contains("degre")
    );
    assert!(
        err("(datasets: [(source: Phantom(kind: head))], frames: [(name: \"a\", set: [Explode(dataset: 0, degree: Some(1.0))])])")
            .contains("not exploded")
    );
}

#[test]
fn the_viewing_force_clears_the_view_and_follows_the_camera() {
    use focal::windows::Viewer;
    let run = |viewing: bool, eyes: &[Vec3]| -> Vec<(f32, f32)> {
        let mut app = app();
        let (dataset, parts) = exploded_head(&mut app, 2);
        let viewer = app.world_mut().spawn((Viewer, Transform::from_translation(eyes[0]))).id();
        {
            let mut x = app.world_mut().get_mut::<Exploded>(dataset).unwrap();
            x.coefficients.degree = 1.0;
            x.viewing = viewing;
        }
        let mut out = Vec::new();
        for eye in eyes {
            app.world_mut().get_mut::<Transform>(viewer).unwrap().translation = *eye;
            app.update();
            // Right after the camera moved, then settled.
            let before = hidden_share(&app, dataset, &parts, *eye);
            step(app.world_mut(), 800);
            out.push((before, hidden_share(&app, dataset, &parts, *eye)));
        }
        out
    };
    let eyes = [Vec3::new(40.0, 600.0, 90.0), Vec3::new(600.0, 60.0, -120.0)];
    let plain = run(false, &eyes);
    let viewed = run(true, &eyes);
    // From the first eye the viewing force hides less of the selection than the
    // explosion alone.
    assert!(viewed[0].1 < plain[0].1, "{viewed:?} vs {plain:?}");
    // The camera turns: the parts, arranged for the old view, hide the selection from
    // the new one; the viewing force moves them off its rays again.
    assert!(viewed[1].1 < viewed[1].0, "after turning: {:?}", viewed[1]);
    assert!(viewed[1].1 < plain[1].1, "{viewed:?} vs {plain:?}");
}

#[test]
fn parts_in_the_way_fade_by_the_viewing_force() {
    use focal::explode::components::PartFade;
    use focal::explode::spec::ExplodeSpec;
    let mut app = app();
    let (dataset, parts) = exploded_head(&mut app, 2);
    let eye = Vec3::new(0.0, 700.0, 0.0);
    app.world_mut().spawn((focal::windows::Viewer, Transform::from_translation(eye)));
    {
        let mut x = app.world_mut().get_mut::<Exploded>(dataset).unwrap();
        x.coefficients.degree = 1.0;
        x.viewing = true;
        x.fade = true;
    }
    app.update();
    step(app.world_mut(), 5);
    app.update();
    let fade = |app: &App, e: Entity| app.world().get::<PartFade>(e).unwrap().0;
    let (front, back): (Vec<Entity>, Vec<Entity>) =
        parts.iter().partition(|&&e| app.world().get::<Part>(e).unwrap().rest.centroid().y > 0.0);
    // The front octants lie between the eye and the selection; the back ones behind it.
    for (&f, &b) in front.iter().zip(&back) {
        assert!(fade(&app, f) < 0.6 && fade(&app, b) > fade(&app, f), "front {} back {}", fade(&app, f), fade(&app, b));
    }
    // The regions draw the front parts with their opacity scaled, the back ones less so.
    let scene = &app.world().resource::<focal::dataset::SceneRegions>().scene;
    let max_opacity = |i: usize| match &scene.appearances[scene.regions[i].appearance].lookup {
        focal::region::Lookup::Transfer(tf) => tf.opacity.iter().map(|p| p.1).fold(0.0, f32::max),
        _ => 1.0,
    };
    let full = presets::builtin("ct_skin_bone").unwrap().opacity.iter().map(|p| p.1).fold(0.0, f32::max);
    let scaled: Vec<f32> = (0..8).map(|i| max_opacity(i) / full).collect();
    let mut fades: Vec<f32> = parts.iter().map(|e| fade(&app, *e)).collect();
    let mut got = scaled.clone();
    fades.sort_by(f32::total_cmp);
    got.sort_by(f32::total_cmp);
    assert!(fades.iter().zip(&got).all(|(a, b)| (a - b).abs() < 1e-4), "{fades:?} vs {got:?}");
    // Off, every part is opaque again; the spec carries the switch.
    app.world_mut().get_mut::<Exploded>(dataset).unwrap().fade = false;
    step(app.world_mut(), 1);
    assert!(parts.iter().all(|e| fade(&app, *e) == 1.0));
    let spec: ExplodeSpec = ron::from_str("(selection: Range(lo: 0.0, hi: 1.0), fade: true)").unwrap();
    assert!(spec.exploded(Phantom::Sphere.generate(8).unwrap(), None).fade);
}
