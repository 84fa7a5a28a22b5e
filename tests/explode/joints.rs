//! Joints and groups of exploded parts: each joint lets its part move only as it says,
//! under the explosion's forces.

use bevy::prelude::*;
use focal::explode::{JointKind, Part, PartJoint, step};

use super::{app, centre, exploded_head, motion, set_degree};

/// The part of the 2×2×2 head whose centre lies in the octant of `signs`.
fn octant(app: &App, parts: &[Entity], signs: Vec3) -> Entity {
    *parts.iter().find(|&&e| (app.world().get::<Part>(e).unwrap().rest.centroid() * signs).min_element() > 0.0).unwrap()
}

/// Explodes the 2×2×2 head with `joint` (made for the part of octant `signs`) and
/// returns the part, its motion settled at degree 2, and the motion of the same part
/// without the joint.
fn exploded_with(signs: Vec3, joint: impl Fn(Entity) -> PartJoint) -> (Part, Transform, Transform) {
    let run = |joined: bool| {
        let mut app = app();
        let (dataset, parts) = exploded_head(&mut app, 2);
        let part = octant(&app, &parts, signs);
        if joined {
            app.world_mut().spawn(joint(part));
        }
        set_degree(&mut app, dataset, 2.0);
        app.update();
        step(app.world_mut(), 600);
        (app.world().get::<Part>(part).unwrap().clone(), motion(&app, part))
    };
    let (part, joined) = run(true);
    (part, joined, run(false).1)
}

#[test]
fn a_slider_joint_only_translates_along_its_axis() {
    let signs = Vec3::new(1.0, -1.0, 1.0);
    let axis = Vec3::new(1.0, -1.0, 0.0).normalize();
    let (_, t, free) = exploded_with(signs, |p| PartJoint::new(JointKind::Slider, p, None, Vec3::ZERO, axis));
    // Free, the corner part moves out along all three axes (and turns a little).
    assert!(free.translation.reject_from(axis).length() > 5.0, "{free:?}");
    let along = t.translation.dot(axis);
    assert!(along > 5.0, "the part slides out: {t:?}");
    assert!(t.translation.reject_from(axis).length() < 0.02 * along, "off the axis: {t:?}");
    assert!(t.rotation.angle_between(Quat::IDENTITY) < 0.2f32.to_radians(), "turned: {t:?}");
}

#[test]
fn a_hinge_only_rotates_about_its_axis_and_keeps_its_limits() {
    // The octant x > 0, y < 0, z > 0 hinged on its vertical edge at x = 120, y = 0 (the
    // explosion pushes its inner corner away from the centre, about that edge).
    let signs = Vec3::new(1.0, -1.0, 1.0);
    let anchor = Vec3::new(120.0, 0.0, 0.0);
    let hinge = |p| PartJoint::new(JointKind::Hinge, p, None, anchor, Vec3::Z);
    let (_, t, free) = exploded_with(signs, hinge);
    assert!(free.transform_point(anchor).distance(anchor) > 5.0, "free, the edge moves: {free:?}");
    assert!(t.transform_point(anchor).distance(anchor) < 0.5, "the hinge stays: {t:?}");
    assert!(t.transform_point(anchor + Vec3::Z * 100.0).distance(anchor + Vec3::Z * 100.0) < 0.5, "the whole axis stays: {t:?}");
    let (axis, angle) = t.rotation.to_axis_angle();
    assert!(angle > 3f32.to_radians(), "the part swings open: {:.2}°", angle.to_degrees());
    assert!(axis.cross(Vec3::Z).length() < 0.01, "about the hinge's axis: {axis}");
    // With limits of ±(a third of that), the part stops at the limit.
    let limit = angle.to_degrees() / 3.0;
    let (_, limited, _) = exploded_with(signs, |p| PartJoint { limits: Some((-limit, limit)), ..hinge(p) });
    let a = limited.rotation.angle_between(Quat::IDENTITY).to_degrees();
    assert!(a > 0.8 * limit && a < 1.1 * limit, "{a:.2}° within ±{limit:.2}°");
}

#[test]
fn ball_and_universal_joints_keep_their_anchor() {
    let signs = Vec3::new(-1.0, 1.0, 1.0);
    let anchor = Vec3::new(-120.0, 120.0, 0.0);
    for kind in [JointKind::Ball, JointKind::Universal] {
        let (_, t, free) = exploded_with(signs, |p| PartJoint::new(kind, p, None, anchor, Vec3::Z));
        assert!(free.transform_point(anchor).distance(anchor) > 5.0, "{kind:?}");
        assert!(t.transform_point(anchor).distance(anchor) < 0.5, "{kind:?}: {t:?}");
        assert!(t.rotation.angle_between(Quat::IDENTITY) > 1f32.to_radians(), "{kind:?} turns: {t:?}");
    }
}

#[test]
fn a_joint_between_parts_and_a_group_keep_the_parts_together() {
    let mut app = app();
    let (dataset, parts) = exploded_head(&mut app, 2);
    let a = octant(&app, &parts, Vec3::new(1.0, 1.0, 1.0));
    let b = octant(&app, &parts, Vec3::new(1.0, 1.0, -1.0));
    let c = octant(&app, &parts, Vec3::new(-1.0, -1.0, 1.0));
    let d = octant(&app, &parts, Vec3::new(-1.0, -1.0, -1.0));
    // a and b grouped; d hinged to c along their shared face's x edge.
    for e in [a, b] {
        app.world_mut().get_mut::<Part>(e).unwrap().group = Some(7);
    }
    app.world_mut().spawn(PartJoint::new(JointKind::Hinge, d, Some(c), Vec3::new(0.0, -120.0, 0.0), Vec3::X));
    set_degree(&mut app, dataset, 2.0);
    app.update();
    let start = (centre(&app, a), centre(&app, c));
    step(app.world_mut(), 600);
    let (ta, tb) = (motion(&app, a), motion(&app, b));
    assert!(centre(&app, a).distance(start.0) > 5.0, "the group moves");
    assert!(ta.translation.distance(tb.translation) < 0.2 && ta.rotation.angle_between(tb.rotation) < 1e-3, "as one: {ta:?} {tb:?}");
    let (tc, td) = (motion(&app, c), motion(&app, d));
    assert!(centre(&app, c).distance(start.1) > 5.0, "the hinged pair moves");
    let edge = Vec3::new(0.0, -120.0, 0.0);
    assert!(tc.transform_point(edge).distance(td.transform_point(edge)) < 0.5, "d stays on c's hinge");
    // Ungrouped, the pair comes apart (the group joint is removed).
    for e in [a, b] {
        app.world_mut().get_mut::<Part>(e).unwrap().group = None;
    }
    app.update();
    step(app.world_mut(), 600);
    let (ta, tb) = (motion(&app, a), motion(&app, b));
    assert!(ta.translation.distance(tb.translation) > 5.0, "apart again: {ta:?} {tb:?}");
    // Back at degree 0 every part returns to rest, joints and all.
    set_degree(&mut app, dataset, 0.0);
    app.update();
    step(app.world_mut(), 1200);
    for e in [a, b, c, d] {
        let t = motion(&app, e);
        assert!(t.translation.length() < 0.5 && t.rotation.angle_between(Quat::IDENTITY) < 0.01, "{t:?}");
    }
}
