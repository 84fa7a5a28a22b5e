//! Editing exploded views headless: exploding from a spec, the splitters on the parts
//! where they are, undo, and the current state as a scene-file spec.

use std::sync::Arc;

use bevy::prelude::*;
use focal::dataset::Dataset;
use focal::explode::edit::{Edit, Splitter, apply, current_spec};
use focal::explode::spec::ExplodeSpec;
use focal::explode::splitters::ScreenAxis;
use focal::explode::{JointKind, Part, PartJoint, step};
use focal::region::{Appearance, Camera, Mode, Projection};
use focal::transfer::presets;
use focal::volume::phantom::Phantom;

use super::{app, set_degree};

fn parts(app: &mut App) -> Vec<(Entity, Part)> {
    let mut v: Vec<_> = app.world_mut().query::<(Entity, &Part)>().iter(app.world()).map(|(e, p)| (e, p.clone())).collect();
    v.sort_by_key(|p| p.0);
    v
}

/// The head CT (64³) exploded around its bone in one part; the camera in front.
fn head() -> (App, Entity, Camera) {
    head_exploded_as("(selection: Range(lo: 300.0, hi: 4000.0))")
}

/// The head CT (64³, skin and bone) exploded as the spec `spec` (RON) says, by the
/// edit the app makes; the camera in front, 600 mm out on +y.
pub fn head_exploded_as(spec: &str) -> (App, Entity, Camera) {
    let mut app = app();
    let v = Arc::new(Phantom::Head.generate(64).unwrap());
    let a = Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone").unwrap());
    let dataset = app.world_mut().spawn((Dataset::new(v, a), Transform::default())).id();
    let spec: ExplodeSpec = ron::from_str(spec).unwrap();
    apply(app.world_mut(), Edit::Explode { dataset, spec: Box::new(spec) }).unwrap();
    app.update();
    let camera = Camera::look_at(Vec3::new(0.0, 600.0, 0.0), Vec3::ZERO, Vec3::Z, Projection::Perspective { fov_y: 0.6 });
    (app, dataset, camera)
}

#[test]
fn splitters_cut_the_parts_where_they_are_and_undo_puts_them_back() {
    let (mut app, dataset, camera) = head();
    assert_eq!(parts(&mut app).len(), 1, "the background starts as one part");
    let whole = parts(&mut app)[0].1.rest.volume();
    // The axis splitter through the head's centre, seen from the front: the vertical
    // screen axis gives a left and a right half (the plane x = 0).
    let centre_ray = camera.ray(64.0, 64.0, 128, 128);
    let split = |app: &mut App, splitter| apply(app.world_mut(), Edit::Split { dataset, splitter });
    split(&mut app, Splitter::Axis { camera, ray: centre_ray, axis: ScreenAxis::Vertical }).unwrap();
    let p = parts(&mut app);
    assert_eq!(p.len(), 2);
    assert!((p[0].1.rest.volume() + p[1].1.rest.volume() - whole).abs() < 1e-3 * whole, "the halves fill the part");
    for (_, part) in &p {
        let xs: Vec<f32> = part.rest.vertices.iter().map(|v| v.x).collect();
        let (lo, hi) = (xs.iter().copied().fold(f32::INFINITY, f32::min), xs.iter().copied().fold(f32::NEG_INFINITY, f32::max));
        assert!(lo.abs() < 1.0 || hi.abs() < 1.0, "cut at x = 0: {lo}..{hi}");
    }
    // The depth splitter on the first visible point (where the skin, the bone and what
    // is behind have added up to the picking threshold): the part hit is cut parallel to
    // the image, its front slab still one half of the head (x ≥ 0), the other half whole.
    split(&mut app, Splitter::Depth { camera, ray: camera.ray(56.0, 64.0, 128, 128) }).unwrap();
    let p = parts(&mut app);
    assert_eq!(p.len(), 3);
    let ys =
        |part: &Part| part.rest.vertices.iter().map(|v| v.y).fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), y| (a.min(y), b.max(y)));
    let cut: Vec<f32> = p
        .iter()
        .map(|(_, part)| ys(part))
        .filter(|(lo, hi)| *lo > -119.0 || *hi < 119.0)
        .flat_map(|(lo, hi)| [lo, hi])
        .filter(|y| y.abs() < 119.0)
        .collect();
    assert!(cut.len() == 2 && (cut[0] - cut[1]).abs() < 1e-3 && cut[0].abs() < 100.0, "one depth, inside the head: {cut:?}");
    assert_eq!(
        p.iter()
            .filter(|(_, part)| {
                let (lo, hi) = ys(part);
                lo < -119.0 && hi > 119.0
            })
            .count(),
        1,
        "the other half is whole"
    );
    // A line across the whole view splits every part it crosses: a horizontal segment
    // through the middle cuts all three at z = 0.
    split(&mut app, Splitter::Line { camera, a: Vec2::new(2.0, 64.0), b: Vec2::new(126.0, 64.0), size: UVec2::splat(128) }).unwrap();
    assert_eq!(parts(&mut app).len(), 6);
    // A line beside the head crosses nothing.
    let missed = split(&mut app, Splitter::Line { camera, a: Vec2::new(0.0, 1.0), b: Vec2::new(3.0, 1.0), size: UVec2::splat(128) });
    assert!(missed.is_err(), "{missed:?}");
    // Nothing under the cursor.
    assert!(split(&mut app, Splitter::Axis { camera, ray: camera.ray(0.0, 0.0, 128, 128), axis: ScreenAxis::Horizontal }).is_err());
    // Undo, split by split (the line made three): back to the one part.
    for n in [5, 4, 3, 2, 1] {
        apply(app.world_mut(), Edit::Undo { dataset }).unwrap();
        assert_eq!(parts(&mut app).len(), n);
    }
    assert!(apply(app.world_mut(), Edit::Undo { dataset }).is_err(), "nothing left to undo");
    assert!((parts(&mut app)[0].1.rest.volume() - whole).abs() < 1e-3 * whole);
}

#[test]
fn splits_keep_joints_flags_and_motion_and_the_state_saves_as_a_spec() {
    let (mut app, dataset, camera) = head();
    let whole = parts(&mut app)[0].0;
    app.world_mut().get_mut::<Part>(whole).unwrap().density = 3.0;
    app.world_mut().spawn(PartJoint::new(JointKind::Hinge, whole, None, Vec3::new(100.0, -100.0, 0.0), Vec3::Z));
    set_degree(&mut app, dataset, 1.0);
    app.update();
    step(app.world_mut(), 60);
    let moved = *app.world().get::<Transform>(whole).unwrap();
    apply(
        app.world_mut(),
        Edit::Split { dataset, splitter: Splitter::Axis { camera, ray: camera.ray(64.0, 64.0, 128, 128), axis: ScreenAxis::Vertical } },
    )
    .unwrap();
    let p = parts(&mut app);
    assert_eq!(p.len(), 2);
    for (e, part) in &p {
        assert_eq!(part.density, 3.0);
        assert_eq!(*app.world().get::<Transform>(*e).unwrap(), moved, "halves start where the part was");
    }
    // The hinge at x = 100 went to the right half.
    let joints: Vec<PartJoint> = app.world_mut().query::<&PartJoint>().iter(app.world()).cloned().collect();
    assert_eq!(joints.len(), 1);
    let right = p.iter().find(|(_, part)| part.rest.centroid().x > 0.0).unwrap().0;
    assert_eq!(joints[0].part, right);
    // The state as a spec: two parts by their planes, the joint, the degree; loaded
    // back it gives the same parts.
    app.world_mut().get_mut::<Part>(right).unwrap().hidden = true;
    let spec = current_spec(app.world_mut(), dataset).unwrap();
    assert_eq!((spec.degree, spec.hidden.clone(), spec.joints.len(), spec.density.len()), (1.0, vec![1], 1, 2));
    let text = ron::to_string(&spec).unwrap();
    let back: ExplodeSpec = ron::from_str(&text).unwrap();
    back.validate(1).unwrap();
    let volume = app.world().get::<Dataset>(dataset).unwrap().volume.clone();
    let cut = back.parts(&volume).unwrap();
    assert_eq!(cut.len(), 2);
    for (a, (_, b)) in cut.iter().zip(&p) {
        assert!((a.volume() - b.rest.volume()).abs() < 1e-3 * b.rest.volume() && a.centroid().distance(b.rest.centroid()) < 0.01);
    }
    // Undoing the split gives the joint back to the whole part; un-exploding removes it all.
    apply(app.world_mut(), Edit::Undo { dataset }).unwrap();
    let joints: Vec<PartJoint> = app.world_mut().query::<&PartJoint>().iter(app.world()).cloned().collect();
    assert_eq!((joints.len(), joints[0].part), (1, parts(&mut app)[0].0));
    apply(app.world_mut(), Edit::Unexplode { dataset }).unwrap();
    app.update();
    assert!(parts(&mut app).is_empty());
    assert_eq!(app.world_mut().query::<&PartJoint>().iter(app.world()).count(), 0);
}
