//! Joints between parts (section 3.3 of Bruckner and Gröller 2006): constraints that
//! let a part move only in some ways, so an exploded view can show a lid opening on a
//! hinge, a drawer pulled out on a slider or a part swinging on a ball.
//!
//! A joint is an entity with [`PartJoint`], a child of the part it moves (rapier's way of
//! giving one body several joints); [`build_joints`] gives it the rapier
//! [`ImpulseJoint`] to the other part or to the world (a fixed body,
//! [`WorldAnchor`]). Parts move within their joints under all the forces of the
//! explosion, the viewing force included (figure 8's swing door).
//!
//! The joint's frame is given at rest, in the dataset's own frame, where every part's
//! body frame is the dataset's frame: the anchor and the axes are the same in both
//! bodies' local frames, so the rest pose always satisfies the joint and at degree 0 the
//! parts can return to it. The frame's x axis is the joint's main axis:
//!
//! | kind | free | limits |
//! |---|---|---|
//! | slider | translation along `axis` | mm along it |
//! | hinge | rotation about `axis` through `anchor` | degrees |
//! | ball | rotation about `anchor` | degrees about each axis of the frame |
//! | universal | rotation about `axis` and about `axis2` (made orthogonal to it) | degrees about each |
//! | fixed | nothing (parts of a group move as one) | — |

use bevy::prelude::*;
use bevy_rapier3d::prelude::*;
use serde::{Deserialize, Serialize};

use super::components::Part;

/// What a joint lets its part do.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum JointKind {
    Slider,
    Hinge,
    Ball,
    Universal,
    Fixed,
}

impl JointKind {
    pub const ALL: [JointKind; 4] = [JointKind::Hinge, JointKind::Slider, JointKind::Ball, JointKind::Universal];

    pub fn name(self) -> &'static str {
        match self {
            JointKind::Slider => "slider",
            JointKind::Hinge => "hinge",
            JointKind::Ball => "ball",
            JointKind::Universal => "universal",
            JointKind::Fixed => "fixed",
        }
    }

    /// The axes the joint locks, in its frame.
    pub fn locked(self) -> JointAxesMask {
        match self {
            JointKind::Slider => JointAxesMask::LIN_Y | JointAxesMask::LIN_Z | JointAxesMask::ANG_AXES,
            JointKind::Hinge => JointAxesMask::LIN_AXES | JointAxesMask::ANG_Y | JointAxesMask::ANG_Z,
            JointKind::Ball => JointAxesMask::LIN_AXES,
            JointKind::Universal => JointAxesMask::LIN_AXES | JointAxesMask::ANG_X,
            JointKind::Fixed => JointAxesMask::LIN_AXES | JointAxesMask::ANG_AXES,
        }
    }

    /// The free axes that limits apply to.
    fn limited(self) -> &'static [JointAxis] {
        match self {
            JointKind::Slider => &[JointAxis::LinX],
            JointKind::Hinge => &[JointAxis::AngX],
            JointKind::Ball => &[JointAxis::AngX, JointAxis::AngY, JointAxis::AngZ],
            JointKind::Universal => &[JointAxis::AngY, JointAxis::AngZ],
            JointKind::Fixed => &[],
        }
    }

    /// Whether limits are angles (degrees) rather than lengths (mm).
    pub fn angular(self) -> bool {
        !matches!(self, JointKind::Slider)
    }
}

/// A joint moving `part` relative to `to` (another part of the same dataset) or to the
/// world (`None`). Anchor and axes at rest, in the dataset's own frame.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct PartJoint {
    pub kind: JointKind,
    pub part: Entity,
    pub to: Option<Entity>,
    pub anchor: Vec3,
    pub axis: Vec3,
    /// The universal joint's second axis (made orthogonal to `axis`).
    pub axis2: Vec3,
    /// Lower and upper limit on each free axis (degrees or mm; `None`: free).
    pub limits: Option<(f32, f32)>,
}

impl PartJoint {
    pub fn new(kind: JointKind, part: Entity, to: Option<Entity>, anchor: Vec3, axis: Vec3) -> PartJoint {
        PartJoint { kind, part, to, anchor, axis, axis2: any_orthogonal(axis), limits: None }
    }
}

/// The world end of joints to the world: a fixed body at the dataset frame's origin.
#[derive(Component)]
pub struct WorldAnchor;

/// A unit vector orthogonal to `v` (any, when `v` is zero).
fn any_orthogonal(v: Vec3) -> Vec3 {
    v.try_normalize().unwrap_or(Vec3::X).any_orthonormal_vector()
}

/// The joint's frame: x along `axis`; y along `axis2` made orthogonal to it (or any
/// orthogonal direction); z = x × y. For the universal joint the free axes are y and z,
/// so x = `axis` × `axis2` and y = `axis`.
pub fn joint_frame(kind: JointKind, axis: Vec3, axis2: Vec3) -> Quat {
    let a = axis.try_normalize().unwrap_or(Vec3::X);
    let b = (axis2 - a * axis2.dot(a)).try_normalize().unwrap_or_else(|| a.any_orthonormal_vector());
    let (x, y) = match kind {
        JointKind::Universal => (a.cross(b), a),
        _ => (a, b),
    };
    Quat::from_mat3(&Mat3::from_cols(x, y, x.cross(y))).normalize()
}

/// The rapier joint of `joint` (both bodies' local frames are the dataset's at rest).
pub fn rapier_joint(joint: &PartJoint) -> GenericJoint {
    let frame = joint_frame(joint.kind, joint.axis, joint.axis2);
    let mut builder = GenericJointBuilder::new(joint.kind.locked())
        .local_basis1(frame)
        .local_basis2(frame)
        .local_anchor1(joint.anchor)
        .local_anchor2(joint.anchor);
    if let Some((lo, hi)) = joint.limits {
        let (lo, hi) = if joint.kind.angular() { (lo.to_radians(), hi.to_radians()) } else { (lo, hi) };
        for axis in joint.kind.limited() {
            builder = builder.limits(*axis, [lo.min(hi), lo.max(hi)]);
        }
    }
    let mut built = builder.build();
    built.set_contacts_enabled(false);
    built
}

/// Gives each new or changed joint its rapier joint (a child of its part; a changed
/// other end needs a new joint, which rapier cannot re-parent). Joints whose part or
/// other end is gone are removed.
// A Bevy system: its parameters are the resources and queries it uses, and a query's
// type names the components it reads; splitting them up would only hide that.
#[allow(clippy::type_complexity)]
pub fn build_joints(
    mut commands: Commands,
    joints: Query<(Entity, &PartJoint, Option<&ImpulseJoint>, Option<&ChildOf>), Or<(Changed<PartJoint>, Without<ImpulseJoint>)>>,
    all: Query<(Entity, &PartJoint)>,
    parts: Query<(), With<Part>>,
    anchors: Query<Entity, With<WorldAnchor>>,
) {
    let mut anchor = anchors.iter().next();
    for (e, j) in &all {
        if !parts.contains(j.part) || j.to.is_some_and(|t| !parts.contains(t)) {
            commands.entity(e).despawn();
        }
    }
    for (e, j, built, child_of) in &joints {
        if !parts.contains(j.part) || j.to.is_some_and(|t| !parts.contains(t)) {
            continue;
        }
        let parent = match j.to {
            Some(p) => p,
            None => *anchor.get_or_insert_with(|| commands.spawn((WorldAnchor, RigidBody::Fixed, Transform::default())).id()),
        };
        let data = ImpulseJoint::new(parent, TypedJoint::GenericJoint(rapier_joint(j)));
        let moved = child_of.is_none_or(|c| c.parent() != j.part) || built.is_some_and(|b| b.parent != parent);
        if moved && built.is_some() {
            commands.entity(e).despawn();
            commands.spawn((j.clone(), ChildOf(j.part), data, Transform::default()));
        } else if built != Some(&data) {
            commands.entity(e).insert((data, ChildOf(j.part), Transform::default()));
        }
    }
}

/// A joint tying a part to its group's first part (made by [`group_joints`]).
#[derive(Component)]
pub struct GroupJoint;

/// Keeps the parts of each group together: every member but the group's first (in
/// entity order) has a fixed joint to the first.
pub fn group_joints(
    mut commands: Commands,
    parts: Query<(Entity, &Part)>,
    changed: Query<(), Changed<Part>>,
    joints: Query<(Entity, &PartJoint), With<GroupJoint>>,
) {
    if changed.is_empty() {
        return;
    }
    let mut leaders: std::collections::BTreeMap<(Entity, u32), Entity> = Default::default();
    let mut members: Vec<(Entity, Entity, u32)> = parts.iter().filter_map(|(e, p)| Some((e, p.dataset, p.group?))).collect();
    members.sort();
    let mut wanted: Vec<(Entity, Entity)> = Vec::new();
    for (e, dataset, group) in members {
        let leader = *leaders.entry((dataset, group)).or_insert(e);
        if leader != e {
            wanted.push((e, leader));
        }
    }
    for (je, j) in &joints {
        if !wanted.contains(&(j.part, j.to.unwrap_or(Entity::PLACEHOLDER))) {
            commands.entity(je).despawn();
        }
    }
    for (member, leader) in wanted {
        if joints.iter().any(|(_, j)| j.part == member && j.to == Some(leader)) {
            continue;
        }
        let anchor = parts.get(member).map(|(_, p)| p.rest.centroid()).unwrap_or_default();
        commands.spawn((GroupJoint, PartJoint::new(JointKind::Fixed, member, Some(leader), anchor, Vec3::X)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_put_the_main_axis_on_x() {
        let q = joint_frame(JointKind::Hinge, Vec3::new(0.0, 0.0, 2.0), Vec3::X);
        assert!((q * Vec3::X - Vec3::Z).length() < 1e-6);
        assert!((q * Vec3::Y - Vec3::X).length() < 1e-6, "the second axis, orthogonal");
        // The second axis is made orthogonal to the first.
        let q = joint_frame(JointKind::Slider, Vec3::X, Vec3::new(1.0, 1.0, 0.0));
        assert!((q * Vec3::Y - Vec3::Y).length() < 1e-6);
        // Universal: the free axes y and z are the two axes, x their cross product.
        let q = joint_frame(JointKind::Universal, Vec3::Y, Vec3::Z);
        assert!((q * Vec3::Y - Vec3::Y).length() < 1e-6 && (q * Vec3::Z - Vec3::Z).length() < 1e-6);
        assert!((q * Vec3::X - Vec3::X).length() < 1e-6);
        // Degenerate axes still give a rotation.
        let q = joint_frame(JointKind::Hinge, Vec3::ZERO, Vec3::ZERO);
        assert!(q.is_finite() && (q.length() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn limits_are_radians_on_the_free_axes() {
        let j =
            PartJoint { limits: Some((90.0, -30.0)), ..PartJoint::new(JointKind::Hinge, Entity::PLACEHOLDER, None, Vec3::ONE, Vec3::Z) };
        let g = rapier_joint(&j);
        let l = g.limits(JointAxis::AngX).map(|l| [l.min, l.max]);
        let expect = [(-30f32).to_radians(), 90f32.to_radians()];
        assert!(l.is_some_and(|l| (l[0] - expect[0]).abs() < 1e-6 && (l[1] - expect[1]).abs() < 1e-6), "{l:?}");
        assert!(g.limits(JointAxis::LinX).is_none());
        assert_eq!(g.locked_axes(), JointKind::Hinge.locked());
        assert_eq!(g.local_anchor1(), Vec3::ONE);
        let s = rapier_joint(&PartJoint {
            limits: Some((0.0, 40.0)),
            ..PartJoint::new(JointKind::Slider, Entity::PLACEHOLDER, None, Vec3::ZERO, Vec3::X)
        });
        assert_eq!(s.limits(JointAxis::LinX).map(|l| [l.min, l.max]), Some([0.0, 40.0]), "slider limits in mm");
        assert!(!s.contacts_enabled());
    }
}
