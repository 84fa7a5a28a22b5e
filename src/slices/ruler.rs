//! Distance rulers: two points of a dataset (its own frame, millimetres, so a ruler
//! moves with its dataset), placed in the slice views (Shift+click the first end, then
//! the second), drawn in the slices they pass through and in the 3D view with their
//! length, and saved with the scene (`rulers: [(dataset: 0, from: (x, y, z), to: …)]`).
//! The length is the Euclidean distance of the ends in the dataset's frame, whose unit
//! is the millimetre (`volume::grid`: spacing in mm), so anisotropic voxels measure
//! right.

use bevy::prelude::*;
use serde::{Deserialize, Serialize};

/// A ruler on a dataset entity.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct Ruler {
    pub dataset: Entity,
    /// Its ends in the dataset's frame (mm).
    pub from: Vec3,
    pub to: Vec3,
}

impl Ruler {
    /// Length in millimetres.
    pub fn length_mm(&self) -> f32 {
        self.from.distance(self.to)
    }
}

/// A ruler as saved: the index of its dataset in the scene and its ends in that
/// dataset's frame (mm).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RulerSpec {
    pub dataset: usize,
    pub from: (f32, f32, f32),
    pub to: (f32, f32, f32),
}

impl RulerSpec {
    /// Checks ruler `i` against a scene of `datasets` datasets.
    pub fn validate(&self, i: usize, datasets: usize) -> Result<(), String> {
        if self.dataset >= datasets {
            return Err(format!("ruler {i}: refers to dataset {}, the scene has {datasets}", self.dataset));
        }
        let finite = [self.from.0, self.from.1, self.from.2, self.to.0, self.to.1, self.to.2].iter().all(|v| v.is_finite());
        if !finite {
            return Err(format!("ruler {i}: its ends are not finite numbers"));
        }
        Ok(())
    }

    /// The saved form of `ruler`, whose dataset is `datasets[index]`.
    pub fn of(ruler: &Ruler, datasets: &[Entity]) -> Option<RulerSpec> {
        let dataset = datasets.iter().position(|d| *d == ruler.dataset)?;
        Some(RulerSpec { dataset, from: ruler.from.into(), to: ruler.to.into() })
    }
}

/// Replaces the rulers in `world` with `specs` on the dataset entities `datasets` (in
/// scene order).
pub fn replace_rulers(world: &mut World, specs: &[RulerSpec], datasets: &[Entity]) {
    let old: Vec<Entity> = world.query_filtered::<Entity, With<Ruler>>().iter(world).collect();
    for e in old {
        world.despawn(e);
    }
    for s in specs {
        if let Some(&dataset) = datasets.get(s.dataset) {
            world.spawn(Ruler { dataset, from: s.from.into(), to: s.to.into() });
        }
    }
}

/// Where a ruler shows on slice `index` of a view with normal index axis `normal`: the
/// part of it within half a voxel of the slice's plane, as the parameters (s0, s1) of
/// `from + s·(to − from)`; `None` where it does not come that close. (`qa`, `qb`: its
/// ends as continuous voxel indices.)
pub fn on_slice(qa: Vec3, qb: Vec3, normal: usize, index: u32) -> Option<(f32, f32)> {
    let (a, b) = (qa[normal] - index as f32, qb[normal] - index as f32);
    if (b - a).abs() < 1e-6 {
        return (a.abs() <= 0.5).then_some((0.0, 1.0));
    }
    let (s0, s1) = ((-0.5 - a) / (b - a), (0.5 - a) / (b - a));
    let (lo, hi) = (s0.min(s1).max(0.0), s0.max(s1).min(1.0));
    (lo <= hi).then_some((lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn length_in_millimetres_and_the_part_on_a_slice() {
        let mut world = World::new();
        let d = world.spawn_empty().id();
        // 3-4-12 → 13 mm.
        let r = Ruler { dataset: d, from: Vec3::new(1.0, 2.0, 3.0), to: Vec3::new(4.0, 6.0, 15.0) };
        assert_eq!(r.length_mm(), 13.0);
        // A ruler in the plane of slice 5 shows whole there, not on slice 6.
        assert_eq!(on_slice(Vec3::new(0.0, 0.0, 5.0), Vec3::new(9.0, 3.0, 5.2), 2, 5), Some((0.0, 1.0)));
        assert_eq!(on_slice(Vec3::new(0.0, 0.0, 5.0), Vec3::new(9.0, 3.0, 5.0), 2, 6), None);
        // Across slices 0 … 10: on slice 5 the tenth around its middle.
        let (s0, s1) = on_slice(Vec3::ZERO, Vec3::new(0.0, 0.0, 10.0), 2, 5).unwrap();
        assert!((s0 - 0.45).abs() < 1e-6 && (s1 - 0.55).abs() < 1e-6);
    }

    #[test]
    fn rulers_are_saved_and_restored_by_dataset_index() {
        let mut world = World::new();
        let (a, b) = (world.spawn_empty().id(), world.spawn_empty().id());
        let spec = RulerSpec { dataset: 1, from: (1.0, 2.0, 3.0), to: (4.0, 5.0, 6.0) };
        replace_rulers(&mut world, &[spec], &[a, b]);
        let rulers: Vec<Ruler> = world.query::<&Ruler>().iter(&world).copied().collect();
        assert_eq!(rulers.len(), 1);
        assert_eq!(rulers[0].dataset, b);
        assert_eq!(RulerSpec::of(&rulers[0], &[a, b]), Some(spec));
        assert!(RulerSpec { dataset: 2, ..spec }.validate(0, 2).unwrap_err().contains("refers to dataset 2"));
        assert!(RulerSpec { from: (f32::NAN, 0.0, 0.0), ..spec }.validate(0, 2).is_err());
        let text = ron::to_string(&spec).unwrap();
        assert_eq!(ron::from_str::<RulerSpec>(&text).unwrap(), spec);
    }
}
