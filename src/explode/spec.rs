//! Exploded views in scene files: the spec on a dataset, what it loads to, and the
//! entities it becomes in an app.
//!
//! ```ron
//! explode: Some((
//!     selection: Labels(dataset: 1, ids: [7, 8]),   // or Range(lo: 300.0, hi: 3000.0)
//!     smooth: 1,                                     // binomial passes on the selection
//!     paint: [(radius: 8.0, hardness: 0.5, erase: false, dabs: [(10.0, 20.0, 30.0)])],
//!     look: Some((mode: dvr, preset: Some("ct_vessels"))),
//!     degree: 1.0, viewing: true, deltas: (0.5, 0.333, 0.1667),
//!     parts: Grid((2, 1, 2)),                        // or Planes([...]), Parts([[...], ...])
//!     fixed: [0],
//!     hidden: [3], groups: [[1, 2]], density: [(0, 4.0)],
//!     joints: [(kind: hinge, part: 1, to: None, anchor: (0.0, 60.0, 0.0), axis: (0.0, 0.0, 1.0),
//!               limits: Some((0.0, 90.0)))],
//! )),
//! ```
//!
//! `Grid((nx, ny, nz))` cuts the dataset's box into equal slabs along its axes;
//! `Planes` cuts every part a plane crosses, one plane after another (dataset frame, a
//! plane keeps `normal · p ≤ offset` on its first side); `Parts` lists each part's
//! planes (what the app saves). `fixed` lists parts (in the order the cuts give) that do
//! not move, `hidden` those that draw nothing, `groups` parts that move as one,
//! `density` parts heavier or lighter than the default (1). `paint` lists brush strokes
//! ([`super::paint`]) painted over the selection after the smoothing (`selection:
//! Nothing` starts from an empty one). Joints ([`super::joints`])
//! tie a part to another (`to: Some(index)`) or to the world (`to: None`); anchor and axes
//! at rest in the dataset's frame (mm), limits in degrees (mm for sliders), `axis2` the
//! universal joint's second axis.

use std::collections::BTreeSet;
use std::sync::Arc;

use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use super::components::{Exploded, Part};
use super::forces::Coefficients;
use super::joints::{JointKind, PartJoint};
use super::paint::{Stroke, paint_strokes};
use super::parts::Polyhedron;
use super::systems::{spawn_part, volume_polyhedron};
use crate::region::{Appearance, AppearanceSpec, Plane};
use crate::volume::{LabelVolume, SelectionVolume, Volume};

/// An exploded view of a dataset.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExplodeSpec {
    pub selection: SelectionSpec,
    /// Binomial smoothing passes on the (binary) selection.
    #[serde(default)]
    pub smooth: u32,
    /// Brush strokes painted over the selection, in order ([`super::paint`]).
    #[serde(default)]
    pub paint: Vec<Stroke>,
    /// How the selection is drawn (`None`: as the dataset).
    #[serde(default)]
    pub look: Option<AppearanceSpec>,
    #[serde(default)]
    pub degree: f32,
    #[serde(default)]
    pub viewing: bool,
    /// Parts fade by the viewing force on them (figure 9).
    #[serde(default)]
    pub fade: bool,
    /// δ_e, δ_v, δ_s of equation 5.
    #[serde(default = "default_deltas")]
    pub deltas: (f32, f32, f32),
    #[serde(default)]
    pub parts: PartsSpec,
    #[serde(default)]
    pub fixed: Vec<usize>,
    #[serde(default)]
    pub hidden: Vec<usize>,
    #[serde(default)]
    pub groups: Vec<Vec<usize>>,
    /// (part, density relative to the default).
    #[serde(default)]
    pub density: Vec<(usize, f32)>,
    #[serde(default)]
    pub joints: Vec<JointSpec>,
}

/// The scene-file spec an exploded dataset was made from (its selection and look; the
/// parts and joints it has now are in the world: `edit::current_spec`).
#[derive(Component, Clone, Debug)]
pub struct ExplodeSource(pub ExplodeSpec);

/// A joint in a scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointSpec {
    pub kind: JointKind,
    pub part: usize,
    /// The other part (`None`: the world).
    #[serde(default)]
    pub to: Option<usize>,
    pub anchor: (f32, f32, f32),
    #[serde(default = "x_axis")]
    pub axis: (f32, f32, f32),
    #[serde(default)]
    pub axis2: Option<(f32, f32, f32)>,
    #[serde(default)]
    pub limits: Option<(f32, f32)>,
}

fn x_axis() -> (f32, f32, f32) {
    (1.0, 0.0, 0.0)
}

fn vec3(t: (f32, f32, f32)) -> Vec3 {
    Vec3::new(t.0, t.1, t.2)
}

fn tuple(v: Vec3) -> (f32, f32, f32) {
    (v.x, v.y, v.z)
}

impl JointSpec {
    /// The joint, with `part(i)` the entity of part `i`.
    pub fn joint(&self, part: impl Fn(usize) -> Entity) -> PartJoint {
        let mut j = PartJoint::new(self.kind, part(self.part), self.to.map(&part), vec3(self.anchor), vec3(self.axis));
        if let Some(a) = self.axis2 {
            j.axis2 = vec3(a);
        }
        j.limits = self.limits;
        j
    }

    /// The spec of `joint`, with `index(e)` the index of part entity `e`.
    pub fn of(joint: &PartJoint, index: impl Fn(Entity) -> Option<usize>) -> Option<JointSpec> {
        Some(JointSpec {
            kind: joint.kind,
            part: index(joint.part)?,
            to: match joint.to {
                Some(t) => Some(index(t)?),
                None => None,
            },
            anchor: tuple(joint.anchor),
            axis: tuple(joint.axis),
            axis2: (joint.kind == JointKind::Universal).then(|| tuple(joint.axis2)),
            limits: joint.limits,
        })
    }

    fn validate(&self) -> Result<(), String> {
        let finite = |t: (f32, f32, f32)| vec3(t).is_finite();
        if !finite(self.anchor) || !finite(self.axis) || vec3(self.axis).length() < 1e-9 || self.axis2.is_some_and(|a| !finite(a)) {
            return Err("the anchor and axes must be finite, the axis not zero".into());
        }
        if self.to == Some(self.part) {
            return Err(format!("part {} is joined to itself", self.part));
        }
        if let Some((lo, hi)) = self.limits
            && !(lo.is_finite() && hi.is_finite())
        {
            return Err(format!("limits {lo}..{hi} must be finite"));
        }
        Ok(())
    }
}

fn default_deltas() -> (f32, f32, f32) {
    let c = Coefficients::default();
    (c.delta_explosion, c.delta_viewing, c.delta_spacing)
}

/// Where the selection comes from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum SelectionSpec {
    /// Label ids of a label dataset (index in `datasets`).
    Labels { dataset: usize, ids: Vec<u32> },
    /// The dataset's own voxels whose real value lies in `[lo, hi]`.
    Range { lo: f64, hi: f64 },
    /// Nothing (to paint the selection from scratch).
    Nothing,
}

/// How the background is cut into parts.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum PartsSpec {
    /// One part: the whole box.
    #[default]
    Whole,
    /// Equal slabs along the box's axes.
    Grid((u32, u32, u32)),
    /// Planes cutting every part they cross, in order.
    Planes(Vec<PlaneSpec>),
    /// Each part's planes.
    Parts(Vec<Vec<PlaneSpec>>),
}

/// A plane `normal · p ≤ offset` in the dataset's frame (mm).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneSpec {
    pub normal: (f32, f32, f32),
    pub offset: f32,
}

impl PlaneSpec {
    pub fn plane(&self) -> Plane {
        let n = Vec3::new(self.normal.0, self.normal.1, self.normal.2);
        let len = n.length().max(1e-12);
        Plane { normal: n / len, offset: self.offset / len }
    }
}

impl From<Plane> for PlaneSpec {
    fn from(p: Plane) -> Self {
        PlaneSpec { normal: (p.normal.x, p.normal.y, p.normal.z), offset: p.offset }
    }
}

impl ExplodeSpec {
    /// Around `selection`, with every default: one part, degree 0.
    pub fn around(selection: SelectionSpec) -> ExplodeSpec {
        ExplodeSpec {
            selection,
            smooth: 0,
            paint: Vec::new(),
            look: None,
            degree: 0.0,
            viewing: false,
            fade: false,
            deltas: default_deltas(),
            parts: PartsSpec::Whole,
            fixed: Vec::new(),
            hidden: Vec::new(),
            groups: Vec::new(),
            density: Vec::new(),
            joints: Vec::new(),
        }
    }

    /// Checks what can be checked without the data: the message names the problem.
    pub fn validate(&self, datasets: usize) -> Result<(), String> {
        if let SelectionSpec::Labels { dataset, ids } = &self.selection {
            if *dataset >= datasets {
                return Err(format!("the selection's labels refer to dataset {dataset}, the scene has {datasets}"));
            }
            if ids.is_empty() {
                return Err("the selection lists no label".into());
            }
        }
        if let SelectionSpec::Range { lo, hi } = self.selection
            && !(lo.is_finite() && hi.is_finite() && lo <= hi)
        {
            return Err(format!("the selection's range {lo}..{hi} is not a range"));
        }
        for (i, stroke) in self.paint.iter().enumerate() {
            stroke.validate().map_err(|e| format!("paint stroke {i}: {e}"))?;
        }
        let (e, v, s) = self.deltas;
        if ![self.degree, e, v, s].iter().all(|x| x.is_finite() && *x >= 0.0) {
            return Err(format!("degree {} and deltas {:?} must be finite and not negative", self.degree, self.deltas));
        }
        if self.smooth > 16 {
            return Err(format!("{} smoothing passes, at most 16", self.smooth));
        }
        for (i, j) in self.joints.iter().enumerate() {
            j.validate().map_err(|e| format!("joint {i}: {e}"))?;
        }
        if let Some((i, d)) = self.density.iter().find(|(_, d)| !(d.is_finite() && *d > 0.0)) {
            return Err(format!("part {i}: density {d} must be finite and above 0 (fixed parts are listed in fixed)"));
        }
        let plane_ok = |p: &PlaneSpec| {
            let n = Vec3::new(p.normal.0, p.normal.1, p.normal.2);
            n.is_finite() && n.length() > 1e-9 && p.offset.is_finite()
        };
        match &self.parts {
            PartsSpec::Grid((x, y, z)) if [*x, *y, *z].iter().any(|n| *n == 0 || *n > 16) => {
                Err(format!("a parts grid of {x}×{y}×{z}: each side 1 to 16"))
            }
            PartsSpec::Planes(planes) => match planes.iter().position(|p| !plane_ok(p)) {
                Some(i) => Err(format!("plane {i}: the normal must be finite and not zero")),
                None => Ok(()),
            },
            PartsSpec::Parts(parts) => match parts.iter().position(|planes| planes.len() < 4 || !planes.iter().all(plane_ok)) {
                Some(i) => Err(format!("part {i}: at least four planes, each with a finite normal that is not zero")),
                None => Ok(()),
            },
            _ => Ok(()),
        }
    }

    /// The parts of `volume`'s box this spec asks for, in order.
    pub fn parts(&self, volume: &Volume) -> Result<Vec<Polyhedron>, String> {
        let whole = volume_polyhedron(volume).ok_or("the dataset's box has no volume")?;
        let cut_by = |parts: Vec<Polyhedron>, plane: Plane| -> Vec<Polyhedron> {
            parts.into_iter().flat_map(|p| p.split(plane).map_or_else(|| vec![p.clone()], |(a, b)| vec![a, b])).collect()
        };
        let parts = match &self.parts {
            PartsSpec::Whole => vec![whole],
            PartsSpec::Grid(n) => {
                // Slabs along the grid's own axes (its voxel-index planes).
                let to_index = volume.grid.world_to_index();
                let dims = volume.dims().as_vec3();
                let mut parts = vec![whole];
                for (axis, count) in [n.0, n.1, n.2].into_iter().enumerate() {
                    for k in 1..count {
                        let at = -0.5 + dims[axis] * k as f32 / count as f32;
                        let mut hi = Vec3::splat(1e6);
                        hi[axis] = at;
                        let planes = crate::region::box_planes(&to_index, Vec3::splat(-1e6), hi);
                        parts = cut_by(parts, planes[axis * 2]);
                    }
                }
                parts
            }
            PartsSpec::Planes(planes) => planes.iter().fold(vec![whole], |parts, p| cut_by(parts, p.plane())),
            PartsSpec::Parts(parts) => parts
                .iter()
                .enumerate()
                .map(|(i, planes)| {
                    Polyhedron::new(&planes.iter().map(PlaneSpec::plane).collect::<Vec<_>>())
                        .ok_or_else(|| format!("part {i} has no volume"))
                })
                .collect::<Result<_, _>>()?,
        };
        let n = parts.len();
        let listed = [
            ("fixed", self.fixed.clone()),
            ("hidden", self.hidden.clone()),
            ("grouped", self.groups.concat()),
            ("density of", self.density.iter().map(|d| d.0).collect()),
            ("jointed", self.joints.iter().flat_map(|j| std::iter::once(j.part).chain(j.to)).collect()),
        ];
        for (what, indices) in listed {
            if let Some(bad) = indices.iter().find(|&&i| i >= n) {
                return Err(format!("{what} part {bad}: the cuts give {n} parts"));
            }
        }
        Ok(parts)
    }

    /// The selection this spec asks for on `data` (`labels`: the label datasets by
    /// index, with their tables).
    pub fn selection(&self, data: &Volume, label: impl Fn(usize) -> Option<LabelVolume>) -> Result<Volume, String> {
        let binary = match &self.selection {
            SelectionSpec::Labels { dataset, ids } => {
                let labels = label(*dataset).ok_or_else(|| format!("the selection's dataset {dataset} is not a label volume"))?;
                let ids: BTreeSet<u32> = ids.iter().copied().collect();
                // (On the data's grid: the label volume's may be another.)
                let sel = SelectionVolume::from_labels(&labels, &ids)?.resampled(&data.grid)?;
                if sel.volume.voxels.code_max() == 0 || !has_selected(&sel) {
                    return Err(format!("no voxel of dataset {dataset} has the labels {ids:?} inside the data's box"));
                }
                sel
            }
            SelectionSpec::Range { lo, hi } => {
                let sel = SelectionVolume::from_value_range(data, *lo, *hi)?;
                if !has_selected(&sel) {
                    return Err(format!("no voxel has a value in {lo}..{hi}"));
                }
                sel
            }
            SelectionSpec::Nothing => SelectionVolume::empty(data.grid.clone()),
        };
        let sel = if self.smooth > 0 { binary.smoothed(self.smooth)? } else { binary };
        Ok(paint_strokes(sel, &self.paint)?.volume)
    }

    /// The component this spec (with the selection and its look loaded) gives.
    pub fn exploded(&self, selection: Volume, look: Option<Appearance>) -> Exploded {
        let (e, v, s) = self.deltas;
        Exploded {
            coefficients: Coefficients {
                degree: self.degree,
                delta_explosion: e,
                delta_viewing: v,
                delta_spacing: s,
                ..Default::default()
            },
            viewing: self.viewing,
            fade: self.fade,
            selection: Some(Arc::new(selection)),
            selection_look: look,
            ..Default::default()
        }
    }
}

fn has_selected(sel: &SelectionVolume) -> bool {
    sel.volume.bricks().max.iter().any(|m| *m > 0)
}

/// An exploded view loaded from a scene file.
#[derive(Clone)]
pub struct LoadedExplode {
    pub exploded: Exploded,
    pub parts: Vec<Polyhedron>,
    /// Fixed, hidden, groups, densities and joints, by part index.
    pub spec: ExplodeSpec,
}

impl std::fmt::Debug for LoadedExplode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LoadedExplode")
            .field("coefficients", &self.exploded.coefficients)
            .field("parts", &self.parts.len())
            .field("fixed", &self.spec.fixed)
            .field("joints", &self.spec.joints.len())
            .finish()
    }
}

/// Gives dataset entity `dataset` its exploded view and parts (replacing any it had),
/// at rest. Returns the parts' entities in the order of `loaded.parts` (entity order
/// need not follow it: despawned entities are reused).
pub fn replace_explosion(world: &mut World, dataset: Entity, loaded: Option<&LoadedExplode>) -> Vec<Entity> {
    let old: Vec<Entity> = world.query::<(Entity, &Part)>().iter(world).filter(|(_, p)| p.dataset == dataset).map(|(e, _)| e).collect();
    for e in old {
        world.despawn(e);
    }
    let Some(loaded) = loaded else {
        world.entity_mut(dataset).remove::<(Exploded, super::components::ExplosionPoints, ExplodeSource)>();
        return Vec::new();
    };
    world.entity_mut(dataset).insert((loaded.exploded.clone(), ExplodeSource(loaded.spec.clone())));
    let spec = &loaded.spec;
    let group = |i: usize| spec.groups.iter().position(|g| g.contains(&i)).map(|g| g as u32);
    let entities: Vec<Entity> = loaded
        .parts
        .iter()
        .enumerate()
        .map(|(i, rest)| {
            let part = Part {
                fixed: spec.fixed.contains(&i),
                hidden: spec.hidden.contains(&i),
                group: group(i),
                density: spec.density.iter().find(|d| d.0 == i).map_or(1.0, |d| d.1),
                ..Part::new(dataset, rest.clone())
            };
            spawn_part(world, part, Transform::default())
        })
        .collect();
    for j in &spec.joints {
        world.spawn(j.joint(|i| entities.get(i).copied().unwrap_or(Entity::PLACEHOLDER)));
    }
    entities
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::phantom::Phantom;

    #[test]
    fn parse_validate_and_cut() {
        let spec: ExplodeSpec =
            ron::from_str("(selection: Range(lo: 300.0, hi: 4000.0), parts: Grid((2, 1, 3)), fixed: [5], degree: 1.5)").unwrap();
        spec.validate(1).unwrap();
        assert_eq!(spec.deltas, default_deltas());
        let head = Phantom::Head.generate(32).unwrap();
        let parts = spec.parts(&head).unwrap();
        assert_eq!(parts.len(), 6);
        let total: f32 = parts.iter().map(|p| p.volume()).sum();
        assert!((total - 240f32.powi(3)).abs() / 240f32.powi(3) < 1e-4, "the parts fill the box: {total}");
        // x halves at 0, z thirds at ±40 mm.
        assert!(parts.iter().all(|p| p.vertices.iter().all(|v| v.x <= 1e-3) || p.vertices.iter().all(|v| v.x >= -1e-3)));
        let sel = spec.selection(&head, |_| None).unwrap();
        assert!(sel.bricks().max.iter().any(|m| *m > 0), "bone is selected");
        // Errors name the problem.
        let bad: ExplodeSpec = ron::from_str("(selection: Labels(dataset: 3, ids: [1]))").unwrap();
        assert!(bad.validate(2).unwrap_err().contains("dataset 3"));
        let bad: ExplodeSpec = ron::from_str("(selection: Range(lo: 1.0, hi: 0.0))").unwrap();
        assert!(bad.validate(1).unwrap_err().contains("not a range"));
        let bad: ExplodeSpec = ron::from_str("(selection: Range(lo: 0.0, hi: 1.0), parts: Grid((0, 1, 1)))").unwrap();
        assert!(bad.validate(1).unwrap_err().contains("grid"));
        let bad: ExplodeSpec =
            ron::from_str("(selection: Range(lo: 0.0, hi: 1.0), parts: Planes([(normal: (0.0, 0.0, 0.0), offset: 1.0)]))").unwrap();
        assert!(bad.validate(1).unwrap_err().contains("plane 0"));
        // Labels on a grid of their own (the head's at half the resolution): the
        // selection comes on the data's grid.
        let coarse = crate::volume::phantom::head::generate(16).unwrap().labels;
        let by_label: ExplodeSpec = ron::from_str("(selection: Labels(dataset: 1, ids: [6, 7, 8]))").unwrap();
        let moved = by_label.selection(&head, |_| Some(coarse.clone())).unwrap();
        assert_eq!(moved.grid, head.grid);
        assert!(moved.bricks().max.iter().any(|m| *m > 0));
        let far: ExplodeSpec = ron::from_str("(selection: Range(lo: 90000.0, hi: 99999.0))").unwrap();
        assert!(far.selection(&head, |_| None).unwrap_err().contains("no voxel"));
        let fixed: ExplodeSpec = ron::from_str("(selection: Range(lo: 300.0, hi: 4000.0), fixed: [1])").unwrap();
        assert!(fixed.parts(&head).unwrap_err().contains("fixed part 1"));
        assert!(ron::from_str::<ExplodeSpec>("(selection: Range(lo: 0.0, hi: 1.0), degre: 1.0)").is_err(), "typos are errors");
        // Planes cut every part they cross: two planes through the centre, four parts.
        let planes: ExplodeSpec = ron::from_str(
            "(selection: Range(lo: 300.0, hi: 4000.0), parts: Planes([(normal: (1.0, 0.0, 0.0), offset: 0.0), (normal: (0.0, 1.0, 0.0), offset: 0.0)]))",
        )
        .unwrap();
        assert_eq!(planes.parts(&head).unwrap().len(), 4);
        // Joints, groups and densities: checked, and their part indices against the cuts.
        let layout = |tail: &str| {
            ron::from_str::<ExplodeSpec>(&format!("(selection: Range(lo: 300.0, hi: 4000.0), parts: Grid((2, 1, 2)), {tail})"))
        };
        let ok = layout("groups: [[0, 1]], density: [(2, 3.0)], joints: [(kind: hinge, part: 3, to: Some(2), anchor: (0.0, 0.0, 0.0), axis: (0.0, 0.0, 1.0), limits: Some((0.0, 90.0)))]").unwrap();
        ok.validate(1).unwrap();
        assert_eq!(ok.parts(&head).unwrap().len(), 4);
        let j = ok.joints[0].joint(|i| Entity::from_raw_u32(i as u32 + 10).unwrap());
        assert_eq!(
            (j.kind, j.part.index_u32(), j.to.map(|e| e.index_u32()), j.limits),
            (JointKind::Hinge, 13, Some(12), Some((0.0, 90.0)))
        );
        assert_eq!(JointSpec::of(&j, |e| Some(e.index_u32() as usize - 10)).as_ref(), Some(&ok.joints[0]), "saved as loaded");
        let e = |tail: &str| {
            layout(tail).map_err(|e| e.to_string()).and_then(|s| s.validate(1).and_then(|_| s.parts(&head).map(|_| ()))).unwrap_err()
        };
        assert!(e("joints: [(kind: slider, part: 9, anchor: (0.0, 0.0, 0.0))]").contains("jointed part 9"));
        assert!(e("joints: [(kind: ball, part: 1, to: Some(1), anchor: (0.0, 0.0, 0.0))]").contains("joint 0: part 1 is joined to itself"));
        assert!(e("joints: [(kind: hinge, part: 1, anchor: (0.0, 0.0, 0.0), axis: (0.0, 0.0, 0.0))]").contains("joint 0"));
        assert!(e("joints: [(kind: hing, part: 1, anchor: (0.0, 0.0, 0.0))]").contains("hing"), "a typo of the kind");
        assert!(e("density: [(1, 0.0)]").contains("density"));
        assert!(e("groups: [[1, 4]]").contains("grouped part 4"));
    }
}
