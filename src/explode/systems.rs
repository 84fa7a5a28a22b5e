//! The exploded view's systems: parts and their rapier bodies, the forces of every step,
//! and parts as regions.
//!
//! The physics runs in a schedule of its own, [`ExplodeStep`]: one run is one rapier
//! step of `1 / steps_per_second` seconds ([`ExplodeTiming`]), the forces applied just
//! before it. The app runs as many steps a frame as the frame's time asks for (at most
//! `max_steps_per_frame`); tests and scripted scenes call [`step`] by hand. Parts do not
//! collide (they start touching everywhere; the spacing force keeps them apart).

use bevy::ecs::schedule::ScheduleLabel;
use bevy::math::Affine3A;
use bevy::prelude::*;
use bevy_rapier3d::prelude::*;

use super::components::{ExplodeTiming, Exploded, ExplosionPoints, Part, PartFade};
use super::forces::fade;
use super::forces::{PartNow, Scale, Surroundings, Wrench, part_wrench};
use super::parts::Polyhedron;
use super::points::explosion_points;
use super::regions::{
    PlacedPart, drawn_part, holds_selection, moving_as_one, part_regions, selection_box, selection_region, spatial_order,
};
use crate::dataset::{Dataset, GpuVolume, SceneRegions};
use crate::region::{Appearance, Keep, Region, SelectionWeight, box_planes};
use crate::transfer::Lut;
use crate::volume::Volume;
use crate::windows::Viewer;

/// The schedule of one physics step.
#[derive(ScheduleLabel, Debug, Clone, PartialEq, Eq, Hash)]
pub struct ExplodeStep;

/// Runs `n` physics steps.
pub fn step(world: &mut World, n: u32) {
    for _ in 0..n {
        world.run_schedule(ExplodeStep);
    }
}

/// The app's stepping: as many steps as the frame's time asks for (the app adds it;
/// headless apps step by hand with [`step`]).
pub fn run_steps(world: &mut World) {
    let any = world.query_filtered::<(), With<Part>>().iter(world).next().is_some();
    if !any {
        return;
    }
    let timing = *world.resource::<ExplodeTiming>();
    let dt = world.resource::<Time>().delta_secs();
    let n = ((dt * timing.steps_per_second).round() as u32).clamp(1, timing.max_steps_per_frame);
    step(world, n);
}

/// The volume the dataset's parts show (the GPU's copy when it had to be reduced).
fn shown(d: &Dataset, gpu: Option<&GpuVolume>) -> std::sync::Arc<Volume> {
    gpu.map(|g| g.volume.clone()).unwrap_or_else(|| d.volume.clone())
}

/// The box of a volume's voxel cells in its own frame.
pub fn volume_polyhedron(volume: &Volume) -> Option<Polyhedron> {
    Polyhedron::new(&box_planes(&volume.grid.world_to_index(), Vec3::splat(-0.5), volume.dims().as_vec3() - 0.5))
}

/// Stiffness of the return spring near rest, per unit mass (1/s²): a part of default
/// density settles back in about a third of a second.
const STIFFNESS: f32 = 30.0;

/// The units of the forces on a part of `volume`'s dataset that fills `share` of its box:
/// `ℓ` a quarter of the box's diagonal, and a unit force that gives the part, at the
/// default density, an acceleration of 30 ℓ/s². Forces grow with a part's size, so parts
/// of any size move alike; a denser (heavier) part moves less.
pub fn force_scale(volume: &Volume, share: f32) -> Scale {
    let (lo, hi) = volume.grid.world_bounds();
    let length = (hi - lo).length() / 4.0;
    Scale { length, force: STIFFNESS * length * share }
}

/// Damping that makes the return spring critically damped near rest for a part of
/// `density` times the default (linear and angular, 1/s: `2√(k/m)`, the angular
/// stiffness of a box-like part about 4.5 times the linear one per inertia).
fn damping(density: f32) -> Damping {
    let per = (STIFFNESS / density.max(1e-3)).sqrt();
    Damping { linear_damping: 2.0 * per, angular_damping: 2.0 * 2.2 * per }
}

/// Density giving the whole box of `volume` a mass of 1.
fn base_density(volume: &Volume) -> f32 {
    let e = volume.grid.extent();
    1.0 / (e.x * e.y * e.z).max(1e-9)
}

/// The rapier components of a part.
fn body(part: &Part, volume: &Volume) -> impl Bundle {
    let collider = Collider::convex_hull(&part.rest.vertices).unwrap_or_else(|| Collider::ball(1.0));
    (
        if part.fixed { RigidBody::Fixed } else { RigidBody::Dynamic },
        collider,
        ColliderMassProperties::Density(part.density * base_density(volume)),
        damping(part.density),
        Sleeping::disabled(),
        CollisionGroups::new(Group::GROUP_2, Group::NONE),
        ExternalForce::default(),
        Velocity::default(),
        PartFade::default(),
    )
}

/// Gives each exploded dataset without parts its first part: its whole box.
pub fn ensure_parts(mut commands: Commands, datasets: Query<(Entity, &Dataset), With<Exploded>>, parts: Query<&Part>) {
    for (e, d) in &datasets {
        if parts.iter().any(|p| p.dataset == e) {
            continue;
        }
        let Some(rest) = volume_polyhedron(&d.volume) else { continue };
        let part = Part::new(e, rest);
        commands.spawn((body(&part, &d.volume), part, Transform::default()));
    }
}

/// Spawns `part` (of a dataset showing `volume`) at rest with its rapier body.
pub fn spawn_part(world: &mut World, part: Part, motion: Transform) -> Entity {
    let volume = world.get::<Dataset>(part.dataset).map(|d| d.volume.clone());
    let mut e = world.spawn((part.clone(), motion));
    if let Some(v) = volume {
        e.insert(body(&part, &v));
    }
    e.id()
}

/// Keeps each part's body kind and mass in step with it (infinite mass = fixed).
// A Bevy system: its parameters are the resources and queries it uses, and a query's
// type names the components it reads; splitting them up would only hide that.
#[allow(clippy::type_complexity)]
pub fn sync_bodies(
    mut parts: Query<(&Part, &mut RigidBody, &mut ColliderMassProperties, &mut Damping, &mut ExternalForce), Changed<Part>>,
    datasets: Query<&Dataset>,
) {
    for (p, mut body, mut mass, mut damp, mut force) in &mut parts {
        let d = damping(p.density);
        if *damp != d {
            *damp = d;
        }
        let kind = if p.fixed { RigidBody::Fixed } else { RigidBody::Dynamic };
        if *body != kind {
            *body = kind;
            force.set_changed();
        }
        if let Ok(d) = datasets.get(p.dataset) {
            let m = ColliderMassProperties::Density(p.density * base_density(&d.volume));
            if *mass != m {
                *mass = m;
            }
        }
    }
}

/// Recomputes the explosion points of datasets whose selection or look changed.
// A Bevy system: its parameters are the resources and queries it uses, and a query's
// type names the components it reads; splitting them up would only hide that.
#[allow(clippy::type_complexity)]
pub fn update_points(
    mut commands: Commands,
    datasets: Query<
        (Entity, &Dataset, &Exploded, Option<&ExplosionPoints>),
        Or<(Changed<Exploded>, Changed<Dataset>, Without<ExplosionPoints>)>,
    >,
) {
    for (e, d, x, old) in &datasets {
        let points = match &x.selection {
            Some(sel) => {
                let v = &d.volume;
                let map = &v.values;
                let lut = match &d.appearance.lookup {
                    crate::region::Lookup::Transfer(tf) => Some(Lut::for_volume(tf, v)),
                    crate::region::Lookup::Labels(_) => None,
                };
                let visible = |lo: u16, hi: u16| {
                    lut.as_ref().is_none_or(|l| l.max_opacity_between(map.to_real(lo as f64), map.to_real(hi as f64)) > 0.0)
                };
                explosion_points(&v.grid, v.bricks(), sel.bricks(), visible, x.max_points)
            }
            None => Vec::new(),
        };
        let new = ExplosionPoints { points };
        if old != Some(&new) {
            commands.entity(e).insert(new);
        }
    }
}

/// The least opacity a part fades to (some context stays).
const FADE_FLOOR: f32 = 0.1;

/// Sets every part's external force and torque for the coming step (equations 1–5, in
/// the dataset's frame).
// A Bevy system: its parameters are the resources and queries it uses, and a query's
// type names the components it reads; splitting them up would only hide that.
#[allow(clippy::type_complexity)]
pub fn apply_forces(
    mut parts: Query<(Entity, &Part, &Transform, &mut ExternalForce, Option<&mut PartFade>)>,
    datasets: Query<(&Dataset, &Exploded, Option<&ExplosionPoints>, &GlobalTransform)>,
    viewers: Query<&GlobalTransform, With<Viewer>>,
) {
    use rayon::prelude::*;
    let viewer = viewers.iter().next().map(|g| g.translation());
    // Each dataset's parts, in entity order, with their centres now.
    let mut by_dataset: std::collections::BTreeMap<Entity, Vec<(Entity, &Part, Affine3A, Vec3)>> = Default::default();
    for (e, p, t, ..) in &parts {
        let m = t.compute_affine();
        by_dataset.entry(p.dataset).or_default().push((e, p, m, m.transform_point3(p.rest.centroid())));
    }
    // The wrenches, the parts in parallel (each reads the others' centres only).
    let mut out: Vec<(Entity, bool, Wrench, f32)> = Vec::new();
    for (dataset, members) in &by_dataset {
        let Ok((d, x, points, global)) = datasets.get(*dataset) else { continue };
        let centers: Vec<Vec3> = members.iter().map(|m| m.3).collect();
        let eye = if x.viewing { viewer.map(|v| global.affine().inverse().transform_point3(v)) } else { None };
        let empty = ExplosionPoints::default();
        let around = Surroundings { points: &points.unwrap_or(&empty).points, centers: &centers, eye };
        let e = d.volume.grid.extent();
        let box_volume = (e.x * e.y * e.z).max(1e-9);
        let wrenches: Vec<(Entity, bool, Wrench, f32)> = members
            .par_iter()
            .enumerate()
            .map(|(index, (e, p, m, center))| {
                let scale = force_scale(&d.volume, p.rest.volume() / box_volume);
                let now = PartNow { index, rest: &p.rest, to_world: *m, center_of_mass: *center };
                let w = part_wrench(&now, &around, &x.coefficients, scale);
                // Fixed parts fade too (they are in the way as much).
                let o = if x.fade && eye.is_some() { fade(w.in_view, FADE_FLOOR) } else { 1.0 };
                (*e, p.fixed, w, o)
            })
            .collect();
        out.extend(wrenches);
    }
    drop(by_dataset);
    for (e, fixed, w, o) in out {
        let Ok((_, _, _, mut force, part_fade)) = parts.get_mut(e) else { continue };
        if let Some(mut f) = part_fade
            && f.0 != o
        {
            f.0 = o;
        }
        if fixed {
            continue;
        }
        let f = ExternalForce { force: w.force, torque: w.torque };
        if *force != f {
            *force = f;
        }
    }
}

/// Replaces each exploded dataset's region by its parts' regions (drawing the data less
/// the selection) and the selection's own region (the box of its non-zero bricks, not
/// moved, drawing the data in the selection), the parts first; parts that all move
/// alike draw as one region, the others in Z order of their rest centres
/// ([`super::regions`]).
pub fn exploded_regions(
    parts: Query<(&Part, &Transform, Option<&PartFade>)>,
    datasets: Query<(Entity, &Dataset, &Exploded, Option<&GpuVolume>, &GlobalTransform)>,
    mut out: ResMut<SceneRegions>,
) {
    if datasets.is_empty() {
        return;
    }
    let mut scene = out.scene.clone();
    let mut changed = false;
    // Each exploded dataset's region (the one showing its volume), from the last back so
    // earlier indices stay valid.
    let mut targets: Vec<(usize, usize, Entity)> = datasets
        .iter()
        .filter_map(|(e, ..)| {
            let volume = out.datasets.iter().position(|d| *d == e)?;
            let region = scene.regions.iter().position(|r| r.volume == volume)?;
            Some((region, volume, e))
        })
        .collect();
    targets.sort_by_key(|t| std::cmp::Reverse(t.0));
    for (region_index, volume_index, entity) in targets {
        let Ok((_, d, x, gpu, global)) = datasets.get(entity) else { continue };
        if parts.iter().all(|(p, ..)| p.dataset != entity) {
            continue;
        }
        let all: Vec<_> = parts.iter().filter(|(p, ..)| p.dataset == entity).collect();
        // (In Z order of their rest centres: neighbours share a cluster of regions.)
        let shown_parts: Vec<_> = all.iter().filter(|(p, ..)| !p.hidden).collect();
        let centres: Vec<Vec3> = shown_parts.iter().map(|(p, ..)| p.rest.centroid()).collect();
        let visible: Vec<_> = spatial_order(&centres).into_iter().map(|i| shown_parts[i]).collect();
        let fades: Vec<f32> = visible.iter().map(|(.., f)| f.map_or(1.0, |f| f.0)).collect();
        let grid = &shown(d, gpu).grid;
        let selection_box = x.selection.as_deref().and_then(selection_box);
        let motions: Vec<Affine3A> = visible.iter().map(|(_, t, _)| t.compute_affine()).collect();
        // All parts shown, moving alike and looking alike: one region, the box.
        let whole = volume_polyhedron(&d.volume);
        let one = moving_as_one(&motions, grid.extent().length())
            .filter(|_| visible.len() == all.len() && fades.iter().all(|f| *f == fades[0]))
            .zip(whole.as_ref());
        let (placed, fades): (Vec<PlacedPart>, Vec<f32>) = match one {
            Some((motion, rest)) => (vec![PlacedPart { rest, motion }], vec![fades[0]]),
            None => (visible.iter().zip(&motions).map(|((p, ..), m)| PlacedPart { rest: &p.rest, motion: *m }).collect(), fades),
        };
        let mut regions = part_regions(grid, global.affine(), &d.clip, volume_index, &placed);
        let own = scene.appearances.get(volume_index).cloned().unwrap_or_else(|| d.appearance.clone());
        let weighted = |look: &Appearance, keep: Keep| match &x.selection {
            Some(selection) => Appearance { selection: Some(SelectionWeight { volume: selection.clone(), keep }), ..look.clone() },
            None => look.clone(),
        };
        // The parts' look: the data less the selection where they meet its box, faded per
        // part (one look per opacity step).
        let mut looks: Vec<((u32, bool), usize)> = Vec::new();
        for ((r, o), p) in regions.iter_mut().zip(&fades).zip(&placed) {
            let near = x.selection.as_deref().is_some_and(|s| holds_selection(p.rest, s));
            let key = ((o * 1000.0).round() as u32, near);
            r.appearance = match looks.iter().find(|l| l.0 == key) {
                Some(l) => l.1,
                None => {
                    let look = if near { weighted(&own, Keep::Unselected) } else { own.clone() };
                    scene.appearances.push(look.with_opacity_scaled(*o));
                    looks.push((key, scene.appearances.len() - 1));
                    scene.appearances.len() - 1
                }
            };
        }
        if let Some(b) = &selection_box {
            let look = weighted(x.selection_look.as_ref().unwrap_or(&own), Keep::Selected);
            let dataset = Region { appearance: scene.appearances.len(), ..d.clip.region(grid, global.affine(), volume_index) };
            if let Some(region) = drawn_part(selection_region(dataset, b, global.affine()), &look, &shown(d, gpu)) {
                scene.appearances.push(look);
                regions.push(region);
            }
        }
        scene.regions.splice(region_index..=region_index, regions);
        changed = true;
    }
    if changed && out.scene != scene {
        out.scene = scene;
    }
}
