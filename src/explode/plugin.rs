//! The exploded view's plugin: rapier in its own schedule, the edits, the parts' systems
//! and their regions, in order.

use bevy::ecs::schedule::SingleThreadedExecutor;
use bevy::prelude::*;
use bevy_rapier3d::prelude::*;
use bevy_rapier3d::rapier::dynamics::IntegrationParameters;

use super::components::ExplodeTiming;
use super::edit;
use super::joints::{build_joints, group_joints};
use super::systems::{ExplodeStep, apply_forces, ensure_parts, exploded_regions, sync_bodies, update_points};
use crate::dataset::RegionSystems;

/// Exploded views (no GPU needed): rapier in [`ExplodeStep`], zero gravity, millimetres.
pub struct ExplodePlugin;

impl Plugin for ExplodePlugin {
    fn build(&self, app: &mut App) {
        let timing = ExplodeTiming::default();
        let init = RapierContextInitialization::InitializeDefaultRapierContext {
            integration_parameters: IntegrationParameters { length_unit: 1000.0, ..default() },
            rapier_configuration: RapierConfiguration { gravity: Vec3::ZERO, ..RapierConfiguration::new(1000.0) },
        };
        app.add_plugins(RapierPhysicsPlugin::<NoUserData>::default().with_custom_initialization(init).in_schedule(ExplodeStep))
            .insert_resource(TimestepMode::Fixed { dt: 1.0 / timing.steps_per_second, substeps: 1 })
            .insert_resource(timing)
            .add_systems(ExplodeStep, apply_forces.before(PhysicsSet::SyncBackend))
            // One thread runs the step's systems (apply_forces spreads the parts over
            // rayon's): waking the executor's threads for each of rapier's small
            // systems cost more than they do.
            .edit_schedule(ExplodeStep, |s| {
                s.set_executor(SingleThreadedExecutor::new());
            })
            .init_resource::<edit::ExplodeEdits>()
            .init_resource::<edit::CurrentSpecs>()
            .add_systems(
                Update,
                (edit::apply_edits, ensure_parts, group_joints, build_joints, update_points, sync_bodies, edit::update_current_specs)
                    .chain(),
            )
            .add_systems(PostUpdate, exploded_regions.in_set(RegionSystems::Modify).before(crate::windows::systems::window_regions));
    }
}
