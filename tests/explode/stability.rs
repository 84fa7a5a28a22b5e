//! The physics at the panel's extremes: every joint type, every slider at its ends, and
//! degenerate parts, for 10⁴ steps.

use bevy::prelude::*;
use focal::explode::parts::Polyhedron;
use focal::explode::systems::spawn_part;
use focal::explode::{Exploded, JointKind, Part, PartJoint, step};
use focal::region::Plane;

use super::{app, exploded_head, motion};

/// The box `lo`–`hi` as a polyhedron.
fn slab(lo: Vec3, hi: Vec3) -> Polyhedron {
    let planes: Vec<Plane> =
        (0..3).flat_map(|a| [Plane { normal: -Vec3::AXES[a], offset: -lo[a] }, Plane { normal: Vec3::AXES[a], offset: hi[a] }]).collect();
    Polyhedron::new(&planes).expect("a box with volume")
}

#[test]
fn sixty_four_joined_parts_at_the_sliders_extremes_stay_finite_and_near() {
    let mut app = app();
    let (dataset, mut parts) = exploded_head(&mut app, 4);
    // Degenerate parts: a slab one voxel (3.75 mm) thick through the middle, a sliver a
    // hundredth of a voxel thick, and a box outside the volume (no voxels at all).
    let degenerate = [
        slab(Vec3::new(-60.0, -60.0, -1.875), Vec3::new(60.0, 60.0, 1.875)),
        slab(Vec3::new(-30.0, -30.0, 10.0), Vec3::new(30.0, 30.0, 10.0375)),
        slab(Vec3::splat(500.0), Vec3::splat(520.0)),
    ];
    for rest in degenerate {
        parts.push(spawn_part(app.world_mut(), Part::new(dataset, rest), Transform::default()));
    }
    // Every joint type, to the world and between parts, with axes along and across.
    let kinds = [JointKind::Slider, JointKind::Hinge, JointKind::Ball, JointKind::Universal, JointKind::Fixed];
    for (i, &part) in parts.iter().enumerate().take(40) {
        let kind = kinds[i % kinds.len()];
        let to = (i % 2 == 1).then(|| parts[(i + 7) % parts.len()]);
        let axis = [Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Z, Vec3::new(-1.0, 2.0, 3.0)][i % 4];
        app.world_mut().spawn(PartJoint::new(kind, part, to, Vec3::new(i as f32, -(i as f32), 0.5 * i as f32), axis));
    }
    let viewer = app.world_mut().spawn((focal::windows::Viewer, Transform::from_xyz(0.0, 600.0, 0.0))).id();
    app.update();
    let diagonal = 240.0 * 3f32.sqrt();
    // (degree, δ explosion, δ viewing, δ spacing): the panel's sliders at their ends
    // (degree 0–16, each δ 0–2), held for 1 000 steps each while the eye moves.
    let settings = [
        (16.0, 2.0, 2.0, 2.0),
        (0.0, 2.0, 2.0, 2.0),
        (16.0, 0.0, 2.0, 0.0),
        (16.0, 2.0, 0.0, 2.0),
        (8.0, 2.0, 2.0, 0.0),
        (16.0, 2.0, 2.0, 2.0),
        (0.0, 0.0, 0.0, 0.0),
        (16.0, 0.0, 0.0, 2.0),
        (16.0, 2.0, 2.0, 2.0),
        (0.0, 2.0, 2.0, 2.0),
    ];
    let mut farthest = 0.0f32;
    for (round, &(degree, de, dv, ds)) in settings.iter().enumerate() {
        {
            let mut x = app.world_mut().get_mut::<Exploded>(dataset).unwrap();
            x.coefficients.degree = degree;
            x.coefficients.delta_explosion = de;
            x.coefficients.delta_viewing = dv;
            x.coefficients.delta_spacing = ds;
            x.viewing = dv > 0.0;
        }
        let angle = round as f32 * 0.7;
        app.world_mut().get_mut::<Transform>(viewer).unwrap().translation = Vec3::new(600.0 * angle.sin(), 600.0 * angle.cos(), 100.0);
        app.update();
        step(app.world_mut(), 1000);
        for p in &parts {
            let t = motion(&app, *p);
            assert!(t.translation.is_finite() && t.rotation.is_finite(), "round {round}: {t:?}");
            farthest = farthest.max(t.translation.length());
        }
        // Within ten of the volume's diagonals of where they started, whatever the forces.
        assert!(farthest < 10.0 * diagonal, "round {round}: a part went {farthest} mm");
    }
    eprintln!("farthest part: {farthest:.0} mm (the volume's diagonal: {diagonal:.0} mm)");
}
