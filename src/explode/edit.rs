//! Editing exploded views: exploding a dataset around a selection, the three splitters
//! of section 3.1 applied to the parts where they are now, and undoing splits; painting
//! the selection with the brush, undoing strokes, smoothing it.
//!
//! The app's panel and viewport tools queue [`Edit`]s in [`ExplodeEdits`];
//! [`apply_edits`] (an exclusive system) carries them out on the world, so headless
//! tests drive the same code. A split replaces a part by its two halves at the part's
//! current motion, with its flags (fixed, hidden, density, group); joints on the part
//! move to the half holding their anchor. Each dataset keeps a stack of its splits;
//! undo puts the last split part back (its halves' joints return to it).
//!
//! Splitters pick the first visible *background* point (the parts, not the selection)
//! with the CPU reference's first hit.

use bevy::prelude::*;
use glam::Affine3A;

use super::components::{Exploded, Part};
use super::joints::{GroupJoint, PartJoint};
use super::paint::{Brush, Stroke, paint};
use super::parts::Polyhedron;
use super::spec::{ExplodeSource, ExplodeSpec, LoadedExplode, PartsSpec, PlaneSpec, replace_explosion};
use super::splitters::{ScreenAxis, axis_plane, depth_plane, in_part_frame, line_plane, segment_crosses};
use super::systems::spawn_part;
use crate::dataset::{Dataset, SceneRegions};
use crate::region::{Camera, Keep, Plane, Ray};
use crate::volume::LabelVolume;

/// A splitter applied in the current view.
#[derive(Clone, Debug)]
pub enum Splitter {
    /// Split the first part hit by `ray` along the plane through the hit whose normal is
    /// the view direction × the screen axis.
    Axis { camera: Camera, ray: Ray, axis: ScreenAxis },
    /// Split the first part hit by `ray` at the hit's depth, parallel to the image.
    Depth { camera: Camera, ray: Ray },
    /// Split every part whose projection the screen segment `a`–`b` (pixels of a `size`
    /// image) crosses, along the plane through it.
    Line { camera: Camera, a: Vec2, b: Vec2, size: UVec2 },
}

/// One editing step.
#[derive(Clone, Debug)]
pub enum Edit {
    /// Explodes `dataset` as `spec` says (its selection's label dataset is an index into
    /// the datasets in entity order).
    Explode {
        dataset: Entity,
        spec: Box<ExplodeSpec>,
    },
    /// Back to the plain dataset.
    Unexplode {
        dataset: Entity,
    },
    Split {
        dataset: Entity,
        splitter: Splitter,
    },
    /// Puts the last split part of `dataset` back.
    Undo {
        dataset: Entity,
    },
    /// Picks the part first hit by `ray` and the point hit ([`ExplodeEdits::picked`]),
    /// for a joint.
    Pick {
        dataset: Entity,
        ray: Ray,
    },
    /// Dabs `brush` on the selection at the first visible point of `dataset` under
    /// `ray` ([`super::paint`]); `new_stroke` starts a stroke (one step of undo).
    Paint {
        dataset: Entity,
        ray: Ray,
        brush: Brush,
        new_stroke: bool,
    },
    /// Takes back the last stroke painted on `dataset`'s selection.
    UndoStroke {
        dataset: Entity,
    },
    /// Smooths `dataset`'s selection with `passes` binomial passes (before the strokes).
    Smooth {
        dataset: Entity,
        passes: u32,
    },
}

/// A picked point on a part: the part, the point in the world and in the part's rest
/// frame (the dataset's frame at rest, where joints are given), and the part's rotation
/// into the world (to carry world axes into the rest frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Picked {
    pub part: Entity,
    pub world: Vec3,
    pub rest: Vec3,
    pub to_world: Affine3A,
}

/// Edits waiting for [`apply_edits`], and what the last one said went wrong.
#[derive(Resource, Default)]
pub struct ExplodeEdits {
    pub queue: Vec<Edit>,
    pub error: Option<String>,
    pub picked: Option<Picked>,
}

/// One split, to undo it.
#[derive(Clone, Debug)]
struct SplitRecord {
    /// The part split, and its entity then.
    part: Part,
    entity: Entity,
    halves: [Entity; 2],
}

/// Each dataset's splits, last on top.
#[derive(Component, Clone, Debug, Default)]
pub struct SplitHistory(Vec<SplitRecord>);

impl SplitHistory {
    pub fn len(&self) -> usize {
        self.0.len()
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

/// Carries out the queued edits.
pub fn apply_edits(world: &mut World) {
    let queue = std::mem::take(&mut world.resource_mut::<ExplodeEdits>().queue);
    for edit in queue {
        let result = apply(world, edit);
        world.resource_mut::<ExplodeEdits>().error = result.err();
    }
}

/// Carries out one edit.
pub fn apply(world: &mut World, edit: Edit) -> Result<(), String> {
    match edit {
        Edit::Explode { dataset, spec } => explode(world, dataset, &spec),
        Edit::Unexplode { dataset } => {
            replace_explosion(world, dataset, None);
            world.entity_mut(dataset).remove::<SplitHistory>();
            Ok(())
        }
        Edit::Split { dataset, splitter } => split(world, dataset, &splitter).map(|_| ()),
        Edit::Undo { dataset } => undo(world, dataset),
        Edit::Pick { dataset, ray } => {
            let hit = first_background_hit(world, ray)?.ok_or("no part under the cursor")?;
            let part = part_at(world, dataset, hit).ok_or("no part under the cursor")?;
            let motion = world.get::<Transform>(part).map_or(Affine3A::IDENTITY, |t| t.compute_affine());
            let to_world = dataset_to_world(world, dataset) * motion;
            world.resource_mut::<ExplodeEdits>().picked =
                Some(Picked { part, world: hit, rest: to_world.inverse().transform_point3(hit), to_world });
            Ok(())
        }
        Edit::Paint { dataset, ray, brush, new_stroke } => paint_at(world, dataset, ray, brush, new_stroke),
        Edit::UndoStroke { dataset } => {
            let mut source = world.get_mut::<ExplodeSource>(dataset).ok_or("the dataset is not exploded")?;
            source.0.paint.pop().ok_or("no stroke to undo")?;
            reselect(world, dataset)
        }
        Edit::Smooth { dataset, passes } => {
            world.get_mut::<ExplodeSource>(dataset).ok_or("the dataset is not exploded")?.0.smooth = passes;
            reselect(world, dataset)
        }
    }
}

/// The selection `spec` asks for on `dataset` (its labels from the datasets in entity
/// order).
fn selection_of(world: &mut World, dataset: Entity, spec: &ExplodeSpec) -> Result<crate::volume::Volume, String> {
    let mut datasets: Vec<(Entity, Dataset)> = world.query::<(Entity, &Dataset)>().iter(world).map(|(e, d)| (e, d.clone())).collect();
    datasets.sort_by_key(|d| d.0);
    spec.validate(datasets.len())?;
    let data = datasets.iter().find(|d| d.0 == dataset).map(|d| d.1.volume.clone()).ok_or("no such dataset")?;
    let label = |i: usize| {
        let (_, d) = datasets.get(i)?;
        Some(LabelVolume { volume: (*d.volume).clone(), table: (**d.labels.as_ref()?).clone() })
    };
    spec.selection(&data, label)
}

/// Recomputes `dataset`'s selection from its spec (after its strokes or smoothing
/// changed); the parts stay as they are.
fn reselect(world: &mut World, dataset: Entity) -> Result<(), String> {
    let spec = world.get::<ExplodeSource>(dataset).ok_or("the dataset is not exploded")?.0.clone();
    let selection = selection_of(world, dataset, &spec)?;
    let mut x = world.get_mut::<Exploded>(dataset).ok_or("the dataset is not exploded")?;
    x.selection = Some(std::sync::Arc::new(selection));
    Ok(())
}

/// One dab of the brush (see [`Edit::Paint`]): at the data point under the first
/// visible point of the scene on `ray` (a part's or the selection's region of
/// `dataset`, carried back to the dataset's frame by that region's map), added to the
/// spec's last stroke and painted on the selection.
fn paint_at(world: &mut World, dataset: Entity, ray: Ray, brush: Brush, new_stroke: bool) -> Result<(), String> {
    let regions = world.resource::<SceneRegions>();
    let hit = crate::reference::pick(&regions.scene, ray)?.ok_or("nothing visible under the brush")?;
    let region = regions.scene.regions.get(hit.region).ok_or("nothing visible under the brush")?;
    if regions.datasets.get(region.volume) != Some(&dataset) {
        return Err("the brush is over another dataset".into());
    }
    let shown = regions.scene.volumes.get(region.volume).ok_or("nothing visible under the brush")?;
    let at = shown.grid.index_to_world().transform_point3(region.world_to_voxel.transform_point3(hit.position));
    let mut source = world.get_mut::<ExplodeSource>(dataset).ok_or("the dataset is not exploded")?;
    let strokes = &mut source.0.paint;
    if new_stroke || strokes.last().is_none_or(|s| s.brush() != brush) {
        strokes.push(Stroke::new(brush));
    }
    if let Some(s) = strokes.last_mut() {
        s.dabs.push((at.x, at.y, at.z));
    }
    let mut x = world.get_mut::<Exploded>(dataset).ok_or("the dataset is not exploded")?;
    let selection = x.selection.as_ref().ok_or("the exploded view has no selection")?;
    let painted = paint(selection, brush, [at])?;
    x.selection = Some(std::sync::Arc::new(painted.volume));
    Ok(())
}

/// Explodes `dataset` as `spec` says, at rest.
fn explode(world: &mut World, dataset: Entity, spec: &ExplodeSpec) -> Result<(), String> {
    let selection = selection_of(world, dataset, spec)?;
    let data = world.get::<Dataset>(dataset).map(|d| d.volume.clone()).ok_or("no such dataset")?;
    let old = world.get::<Exploded>(dataset).cloned();
    let mut exploded = spec.exploded(selection, None);
    // Re-exploding keeps the look and the viewing settings.
    if let Some(old) = old {
        exploded.selection_look = old.selection_look;
    }
    let loaded = LoadedExplode { exploded, parts: spec.parts(&data)?, spec: spec.clone() };
    replace_explosion(world, dataset, Some(&loaded));
    world.entity_mut(dataset).insert(SplitHistory::default());
    Ok(())
}

/// The parts of `dataset`: entity, part, motion (in the dataset's frame), in entity order.
fn parts_of(world: &mut World, dataset: Entity) -> Vec<(Entity, Part, Transform)> {
    let mut v: Vec<_> = world
        .query::<(Entity, &Part, &Transform)>()
        .iter(world)
        .filter(|(_, p, _)| p.dataset == dataset)
        .map(|(e, p, t)| (e, p.clone(), *t))
        .collect();
    v.sort_by_key(|p| p.0);
    v
}

fn dataset_to_world(world: &World, dataset: Entity) -> Affine3A {
    world.get::<GlobalTransform>(dataset).map_or(Affine3A::IDENTITY, |g| g.affine())
}

/// The first visible background point on `ray` (world), picked by the CPU reference in
/// the scene without the selection's regions.
fn first_background_hit(world: &World, ray: Ray) -> Result<Option<Vec3>, String> {
    background_hit(&world.resource::<SceneRegions>().scene, ray)
}

/// The first visible point of `scene` on `ray` that is not the selection's (what the
/// splitters cut at).
pub fn background_hit(scene: &crate::region::RenderScene, ray: Ray) -> Result<Option<Vec3>, String> {
    let mut scene = scene.clone();
    let appearances = scene.appearances.clone();
    scene.regions.retain(|r| appearances.get(r.appearance).is_none_or(|a| a.selection.as_ref().is_none_or(|s| s.keep != Keep::Selected)));
    Ok(crate::reference::pick(&scene, ray)?.map(|h| h.position))
}

/// The part of `dataset` at world point `p` (the nearest, for a point on a face).
fn part_at(world: &mut World, dataset: Entity, p: Vec3) -> Option<Entity> {
    let to_world = dataset_to_world(world, dataset);
    let parts = parts_of(world, dataset);
    nearest_part(parts.iter().map(|(e, part, t)| (*e, part, to_world * t.compute_affine())), p)
}

/// Of `parts` (entity, part, rest frame → world), the shown one nearest to world point
/// `p`.
pub fn nearest_part<'a>(parts: impl Iterator<Item = (Entity, &'a Part, Affine3A)>, p: Vec3) -> Option<Entity> {
    parts
        .filter(|(_, part, _)| !part.hidden)
        .map(|(e, part, to_world)| {
            let rest = to_world.inverse().transform_point3(p);
            (e, part.rest.closest_point(rest).distance(rest))
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(e, _)| e)
}

/// The part of `dataset` first hit on `ray` and the plane `plane(hit)`.
fn picked_cut(world: &mut World, dataset: Entity, ray: Ray, plane: impl Fn(Vec3) -> Plane) -> Result<Vec<(Entity, Plane)>, String> {
    let hit = first_background_hit(world, ray)?.ok_or("nothing visible under the cursor to split")?;
    Ok(part_at(world, dataset, hit).map(|e| (e, plane(hit))).into_iter().collect())
}

/// Applies a splitter to `dataset`'s parts; returns the halves made.
pub fn split(world: &mut World, dataset: Entity, splitter: &Splitter) -> Result<Vec<Entity>, String> {
    let to_world = dataset_to_world(world, dataset);
    let cuts: Vec<(Entity, Plane)> = match splitter {
        Splitter::Axis { camera, ray, axis } => picked_cut(world, dataset, *ray, |hit| axis_plane(camera, hit, *axis))?,
        Splitter::Depth { camera, ray } => picked_cut(world, dataset, *ray, |hit| depth_plane(camera, hit))?,
        Splitter::Line { camera, a, b, size } => {
            let plane = line_plane(camera, *a, *b, size.x, size.y).ok_or("the line is too short")?;
            parts_of(world, dataset)
                .into_iter()
                .filter(|(_, p, t)| {
                    !p.hidden && segment_crosses(camera, &p.rest, to_world * t.compute_affine(), plane, *a, *b, size.as_vec2())
                })
                .map(|(e, ..)| (e, plane))
                .collect()
        }
    };
    let mut made = Vec::new();
    for (part, plane) in cuts {
        let Some(t) = world.get::<Transform>(part).copied() else { continue };
        if let Some(halves) = split_part(world, part, in_part_frame(plane, to_world * t.compute_affine())) {
            made.extend(halves);
        }
    }
    if made.is_empty() {
        return Err("the cut misses every part".into());
    }
    Ok(made)
}

/// The joints that end at `part` (on it or to it), but not group joints (rebuilt from
/// the groups).
fn joints_at(world: &mut World, part: Entity) -> Vec<(Entity, PartJoint)> {
    world
        .query_filtered::<(Entity, &PartJoint), Without<GroupJoint>>()
        .iter(world)
        .filter(|(_, j)| j.part == part || j.to == Some(part))
        .map(|(e, j)| (e, j.clone()))
        .collect()
}

/// Moves `part`'s joints to `new` (`pick(anchor)`: which new entity takes the joint).
fn move_joints(world: &mut World, part: Entity, pick: impl Fn(Vec3) -> Entity) {
    for (e, mut j) in joints_at(world, part) {
        world.despawn(e);
        let to = pick(j.anchor);
        if j.part == part {
            j.part = to;
        }
        if j.to == Some(part) {
            j.to = Some(to);
        }
        world.spawn(j);
    }
}

/// Replaces `part` by its halves along `plane` (its rest frame), moved as it is.
/// `None` (nothing changes) when the plane misses it.
pub fn split_part(world: &mut World, part: Entity, plane: Plane) -> Option<[Entity; 2]> {
    let p = world.get::<Part>(part)?.clone();
    let t = *world.get::<Transform>(part)?;
    let (a, b) = p.rest.split(plane)?;
    let halves = [a, b].map(|rest| spawn_part(world, Part { rest, ..p.clone() }, t));
    let rests: Vec<Polyhedron> = halves.iter().filter_map(|h| world.get::<Part>(*h).map(|p| p.rest.clone())).collect();
    move_joints(world, part, |anchor| {
        let d = |i: usize| rests.get(i).map_or(f32::INFINITY, |r| r.closest_point(anchor).distance(anchor));
        if d(0) <= d(1) { halves[0] } else { halves[1] }
    });
    world.despawn(part);
    let dataset = p.dataset;
    let record = SplitRecord { part: p, entity: part, halves };
    match world.get_mut::<SplitHistory>(dataset) {
        Some(mut h) => h.0.push(record),
        None => {
            if let Ok(mut e) = world.get_entity_mut(dataset) {
                e.insert(SplitHistory(vec![record]));
            }
        }
    }
    Some(halves)
}

/// Puts the last split part of `dataset` back, where its first half is now.
pub fn undo(world: &mut World, dataset: Entity) -> Result<(), String> {
    let record = world.get_mut::<SplitHistory>(dataset).and_then(|mut h| h.0.pop()).ok_or("no split to undo")?;
    let t = world.get::<Transform>(record.halves[0]).copied().unwrap_or_default();
    let whole = spawn_part(world, record.part, t);
    // Earlier splits knew the part by its old entity.
    if let Some(mut h) = world.get_mut::<SplitHistory>(dataset) {
        for half in h.0.iter_mut().flat_map(|r| r.halves.iter_mut()) {
            if *half == record.entity {
                *half = whole;
            }
        }
    }
    for half in record.halves {
        move_joints(world, half, |_| whole);
        if world.get_entity(half).is_ok() {
            world.despawn(half);
        }
    }
    Ok(())
}

/// The exploded view of `dataset` as it is now, as a scene-file spec: the parts listed
/// by their planes, their flags, joints and the coefficients (`None`: not exploded).
pub fn current_spec(world: &mut World, dataset: Entity) -> Option<ExplodeSpec> {
    let source = world.get::<ExplodeSource>(dataset)?.0.clone();
    let x = world.get::<Exploded>(dataset)?.clone();
    let parts = parts_of(world, dataset);
    let joints: Vec<PartJoint> = world.query_filtered::<&PartJoint, Without<GroupJoint>>().iter(world).cloned().collect();
    Some(spec_of(&source, &x, &parts.iter().map(|(e, p, _)| (*e, p)).collect::<Vec<_>>(), &joints))
}

/// The spec of an exploded view made from `source`, with `parts` (in entity order) and
/// the `joints` (any dataset's: those of other parts are left out).
pub fn spec_of(source: &ExplodeSpec, x: &Exploded, parts: &[(Entity, &Part)], joints: &[PartJoint]) -> ExplodeSpec {
    let index = |e: Entity| parts.iter().position(|p| p.0 == e);
    let flagged = |f: &dyn Fn(&Part) -> bool| parts.iter().enumerate().filter(|(_, p)| f(p.1)).map(|(i, _)| i).collect::<Vec<_>>();
    let mut groups: std::collections::BTreeMap<u32, Vec<usize>> = Default::default();
    for (i, p) in parts.iter().enumerate() {
        if let Some(g) = p.1.group {
            groups.entry(g).or_default().push(i);
        }
    }
    let mut joints: Vec<_> = joints.iter().filter_map(|j| super::spec::JointSpec::of(j, index)).collect();
    joints.sort_by_key(|a| (a.part, a.to));
    let c = x.coefficients;
    ExplodeSpec {
        degree: c.degree,
        viewing: x.viewing,
        fade: x.fade,
        deltas: (c.delta_explosion, c.delta_viewing, c.delta_spacing),
        parts: PartsSpec::Parts(parts.iter().map(|p| p.1.rest.planes.iter().map(|pl| PlaneSpec::from(*pl)).collect()).collect()),
        fixed: flagged(&|p| p.fixed),
        hidden: flagged(&|p| p.hidden),
        groups: groups.into_values().filter(|g| g.len() > 1).collect(),
        density: parts.iter().enumerate().filter(|(_, p)| p.1.density != 1.0).map(|(i, p)| (i, p.1.density)).collect(),
        joints,
        ..source.clone()
    }
}

/// Every dataset's exploded view as it is now (`None`: not exploded), for saving.
#[derive(Resource, Default)]
pub struct CurrentSpecs(pub std::collections::HashMap<Entity, Option<ExplodeSpec>>);

/// Keeps [`CurrentSpecs`] up to date when parts, joints or explosions change.
// A Bevy system: its parameters are the resources and queries it uses, and a query's
// type names the components it reads; splitting them up would only hide that.
#[allow(clippy::type_complexity)]
pub fn update_current_specs(
    datasets: Query<(Entity, Option<&ExplodeSource>, Option<&Exploded>), With<Dataset>>,
    parts: Query<(Entity, &Part)>,
    joints: Query<&PartJoint, Without<GroupJoint>>,
    changed: Query<(), Or<(Changed<Part>, Changed<PartJoint>, Changed<Exploded>)>>,
    removed: (RemovedComponents<Part>, RemovedComponents<PartJoint>, RemovedComponents<Exploded>),
    mut out: ResMut<CurrentSpecs>,
) {
    let (mut a, mut b, mut c) = removed;
    let any_removed = a.read().count() + b.read().count() + c.read().count() > 0;
    if changed.is_empty() && !any_removed && out.0.len() == datasets.iter().len() {
        return;
    }
    let joints: Vec<PartJoint> = joints.iter().cloned().collect();
    let mut all: Vec<(Entity, &Part)> = parts.iter().collect();
    all.sort_by_key(|p| p.0);
    out.0 = datasets
        .iter()
        .map(|(e, source, x)| {
            let mine: Vec<(Entity, &Part)> = all.iter().filter(|p| p.1.dataset == e).copied().collect();
            (e, source.zip(x).map(|(s, x)| spec_of(&s.0, x, &mine, &joints)))
        })
        .collect();
}
