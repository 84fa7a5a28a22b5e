//! Exploded views in scene files: the spec on a dataset, what it loads to, and the
//! entities it becomes in an app.
//!
//! ```ron
//! explode: Some((
//!     selection: Labels(dataset: 1, ids: [7, 8]),   // or Range(lo: 300.0, hi: 3000.0)
//!     smooth: 1,                                     // binomial passes on the selection
//!     look: Some((mode: dvr, preset: Some("ct_vessels"))),
//!     degree: 1.0, viewing: true, deltas: (0.5, 0.333, 0.1667),
//!     parts: Grid((2, 1, 2)),                        // or Planes([...]), Parts([[...], ...])
//!     fixed: [0],
//! )),
//! ```
//!
//! `Grid((nx, ny, nz))` cuts the dataset's box into equal slabs along its axes;
//! `Planes` cuts every part a plane crosses, one plane after another (dataset frame, a
//! plane keeps `normal · p ≤ offset` on its first side); `Parts` lists each part's
//! planes (what the app saves). `fixed` lists parts (in the order the cuts give) that do
//! not move.

use std::collections::BTreeSet;
use std::sync::Arc;

use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use super::components::{Exploded, Part};
use super::forces::Coefficients;
use super::parts::Polyhedron;
use super::systems::{spawn_part, volume_polyhedron};
use crate::region::{Appearance, Plane};
use crate::scene::file::AppearanceSpec;
use crate::volume::{LabelVolume, SelectionVolume, Volume};

/// An exploded view of a dataset.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExplodeSpec {
    pub selection: SelectionSpec,
    /// Binomial smoothing passes on the (binary) selection.
    #[serde(default)]
    pub smooth: u32,
    /// How the selection is drawn (`None`: as the dataset).
    #[serde(default)]
    pub look: Option<AppearanceSpec>,
    #[serde(default)]
    pub degree: f32,
    #[serde(default)]
    pub viewing: bool,
    /// δ_e, δ_v, δ_s of equation 5.
    #[serde(default = "default_deltas")]
    pub deltas: (f32, f32, f32),
    #[serde(default)]
    pub parts: PartsSpec,
    #[serde(default)]
    pub fixed: Vec<usize>,
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
        let (e, v, s) = self.deltas;
        if ![self.degree, e, v, s].iter().all(|x| x.is_finite() && *x >= 0.0) {
            return Err(format!("degree {} and deltas {:?} must be finite and not negative", self.degree, self.deltas));
        }
        if self.smooth > 16 {
            return Err(format!("{} smoothing passes, at most 16", self.smooth));
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
                    Polyhedron::new(&planes.iter().map(PlaneSpec::plane).collect::<Vec<_>>()).ok_or_else(|| format!("part {i} has no volume"))
                })
                .collect::<Result<_, _>>()?,
        };
        if let Some(bad) = self.fixed.iter().find(|&&i| i >= parts.len()) {
            return Err(format!("fixed part {bad}: the cuts give {} parts", parts.len()));
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
                let sel = SelectionVolume::from_labels(&labels, &ids)?;
                if sel.volume.voxels.code_max() == 0 || !has_selected(&sel) {
                    return Err(format!("no voxel of dataset {dataset} has the labels {ids:?}"));
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
        };
        let sel = if self.smooth > 0 { binary.smoothed(self.smooth)? } else { binary };
        Ok(sel.volume)
    }

    /// The component this spec (with the selection and its look loaded) gives.
    pub fn exploded(&self, selection: Volume, look: Option<Appearance>) -> Exploded {
        let (e, v, s) = self.deltas;
        Exploded {
            coefficients: Coefficients { degree: self.degree, delta_explosion: e, delta_viewing: v, delta_spacing: s, ..Default::default() },
            viewing: self.viewing,
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
    pub fixed: Vec<usize>,
}

impl std::fmt::Debug for LoadedExplode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LoadedExplode")
            .field("coefficients", &self.exploded.coefficients)
            .field("parts", &self.parts.len())
            .field("fixed", &self.fixed)
            .finish()
    }
}

/// Gives dataset entity `dataset` its exploded view and parts (replacing any it had),
/// at rest.
pub fn replace_explosion(world: &mut World, dataset: Entity, loaded: Option<&LoadedExplode>) {
    let old: Vec<Entity> = world.query::<(Entity, &Part)>().iter(world).filter(|(_, p)| p.dataset == dataset).map(|(e, _)| e).collect();
    for e in old {
        world.despawn(e);
    }
    let Some(loaded) = loaded else {
        world.entity_mut(dataset).remove::<(Exploded, super::components::ExplosionPoints)>();
        return;
    };
    world.entity_mut(dataset).insert(loaded.exploded.clone());
    for (i, rest) in loaded.parts.iter().enumerate() {
        let part = Part { fixed: loaded.fixed.contains(&i), ..Part::new(dataset, rest.clone()) };
        spawn_part(world, part, Transform::default());
    }
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
        let bad: ExplodeSpec = ron::from_str("(selection: Range(lo: 0.0, hi: 1.0), parts: Planes([(normal: (0.0, 0.0, 0.0), offset: 1.0)]))").unwrap();
        assert!(bad.validate(1).unwrap_err().contains("plane 0"));
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
    }
}
