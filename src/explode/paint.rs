//! Painting the selection with a volumetric brush (Bruckner and Gröller 2006, section 3:
//! besides labels and value ranges, the user paints the focus directly on the visible
//! surface of the volume).
//!
//! A dab is a ball of `radius` millimetres around a point of the dataset's frame (the
//! first visible point under the cursor, picked by the CPU reference). Its strength at
//! distance `d` from the centre is
//!
//! ```text
//!   b(d) = 1                     for d ≤ h·R
//!        = s((R − d) / (R − h·R)) for h·R < d < R,   s(x) = x²(3 − 2x)
//!        = 0                     for d ≥ R
//! ```
//!
//! with `h` the hardness (the share of the radius at full strength) and `s` the cubic
//! smoothstep (C¹: the selection's edge has no ridge for the shading to show). Adding
//! raises a voxel's degree of interest to the brush's, `doi' = max(doi, b)`; erasing
//! lowers it, `doi' = min(doi, 1 − b)`, so going over a place twice changes nothing more.
//! A stroke is the dabs of one drag with one brush. Strokes are kept in the exploded
//! view's spec ([`super::spec::ExplodeSpec::paint`]), after the labels or the value range
//! and the smoothing: a painted selection is saved with the scene, and undo replays the
//! strokes before the last one.
//!
//! Changing the selection moves the explosion points (the forces), never the parts.

use glam::{Mat3, Vec3};
use serde::{Deserialize, Serialize};

use crate::volume::{SelectionVolume, Volume, Voxels};

/// The brush's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Brush {
    /// Radius in millimetres.
    pub radius: f32,
    /// The share of the radius at full strength, 0..1.
    pub hardness: f32,
    /// Erase instead of add.
    pub erase: bool,
}

impl Default for Brush {
    fn default() -> Self {
        Brush { radius: 8.0, hardness: 0.5, erase: false }
    }
}

impl Brush {
    /// The strength `b(d)` at distance `d` from a dab's centre (module doc).
    pub fn strength(&self, d: f32) -> f32 {
        let r = self.radius.max(0.0);
        let inner = self.hardness.clamp(0.0, 1.0) * r;
        if d <= inner {
            return if r > 0.0 { 1.0 } else { 0.0 };
        }
        if d >= r {
            return 0.0;
        }
        let x = (r - d) / (r - inner);
        x * x * (3.0 - 2.0 * x)
    }

    /// A voxel's new code (`doi = code / 255`) under strength `b`.
    pub fn apply(&self, code: u8, b: f32) -> u8 {
        let c = (b.clamp(0.0, 1.0) * 255.0).round() as u8;
        if self.erase { code.min(255 - c) } else { code.max(c) }
    }
}

/// One drag of the brush: its settings and the centres of its dabs (dataset frame, mm).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stroke {
    pub radius: f32,
    #[serde(default = "default_hardness")]
    pub hardness: f32,
    #[serde(default)]
    pub erase: bool,
    pub dabs: Vec<(f32, f32, f32)>,
}

fn default_hardness() -> f32 {
    Brush::default().hardness
}

impl Stroke {
    /// A stroke of `brush` with no dabs yet.
    pub fn new(brush: Brush) -> Stroke {
        Stroke { radius: brush.radius, hardness: brush.hardness, erase: brush.erase, dabs: Vec::new() }
    }

    pub fn brush(&self) -> Brush {
        Brush { radius: self.radius, hardness: self.hardness, erase: self.erase }
    }

    /// The dabs' centres.
    pub fn centres(&self) -> impl Iterator<Item = Vec3> + '_ {
        self.dabs.iter().map(|d| Vec3::new(d.0, d.1, d.2))
    }

    /// Checks the numbers: the message names the problem.
    pub fn validate(&self) -> Result<(), String> {
        if !(self.radius.is_finite() && self.radius > 0.0) {
            return Err(format!("the brush radius {} must be a positive number of millimetres", self.radius));
        }
        if !(0.0..=1.0).contains(&self.hardness) {
            return Err(format!("the brush hardness {} must lie in 0..1", self.hardness));
        }
        if let Some(d) = self.centres().find(|c| !c.is_finite()) {
            return Err(format!("a dab at {d} is not a point"));
        }
        Ok(())
    }
}

/// `selection` with `brush` dabbed at each of `centres` (dataset frame, mm).
pub fn paint(selection: &Volume, brush: Brush, centres: impl IntoIterator<Item = Vec3>) -> Result<SelectionVolume, String> {
    let grid = &selection.grid;
    let Voxels::U8(codes) = &selection.voxels else {
        return Err("selection volumes hold 8-bit codes".into());
    };
    let mut codes = codes.clone();
    let (to_index, to_world) = (grid.world_to_index(), grid.index_to_world());
    // The ball's half extent along index axis a: the radius times the length of row a
    // of the world → index map.
    let m = Mat3::from(to_index.matrix3);
    let half = Vec3::new(m.row(0).length(), m.row(1).length(), m.row(2).length()) * brush.radius;
    let dims = grid.dims;
    let top = dims.as_vec3() - 1.0;
    for c in centres {
        let ci = to_index.transform_point3(c);
        let (lo, hi) = ((ci - half).ceil().max(Vec3::ZERO), (ci + half).floor().min(top));
        if lo.cmpgt(hi).any() {
            continue;
        }
        for k in lo.z as u32..=hi.z as u32 {
            for j in lo.y as u32..=hi.y as u32 {
                for i in lo.x as u32..=hi.x as u32 {
                    let b = brush.strength(to_world.transform_point3(Vec3::new(i as f32, j as f32, k as f32)).distance(c));
                    if b > 0.0 {
                        let index = ((k * dims.y + j) * dims.x + i) as usize;
                        codes[index] = brush.apply(codes[index], b);
                    }
                }
            }
        }
    }
    SelectionVolume::from_codes(grid.clone(), codes)
}

/// `selection` with every stroke painted, in order.
pub fn paint_strokes(selection: SelectionVolume, strokes: &[Stroke]) -> Result<SelectionVolume, String> {
    strokes.iter().try_fold(selection, |s, stroke| paint(&s.volume, stroke.brush(), stroke.centres()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::Grid;
    use glam::UVec3;

    #[test]
    fn the_brush_profile_by_hand() {
        let b = Brush { radius: 10.0, hardness: 0.5, erase: false };
        assert_eq!(b.strength(0.0), 1.0);
        assert_eq!(b.strength(5.0), 1.0);
        // Halfway through the soft rim x = ½: s = ¼·(3 − 1) = ½.
        assert!((b.strength(7.5) - 0.5).abs() < 1e-6);
        // x = ¼ (d = 8.75): 1/16·(3 − ½) = 0.15625.
        assert!((b.strength(8.75) - 0.156_25).abs() < 1e-6);
        assert_eq!(b.strength(10.0), 0.0);
        assert_eq!(b.strength(12.0), 0.0);
        // A hard brush is all or nothing.
        let hard = Brush { hardness: 1.0, ..b };
        assert_eq!((hard.strength(9.99), hard.strength(10.01)), (1.0, 0.0));
        // Adding keeps the larger, erasing the smaller of the code and 1 − b.
        assert_eq!(b.apply(100, 0.5), 128);
        assert_eq!(b.apply(200, 0.5), 200);
        let e = Brush { erase: true, ..b };
        assert_eq!(e.apply(200, 0.5), 127);
        assert_eq!(e.apply(100, 0.5), 100);
        assert_eq!(e.apply(255, 1.0), 0);
    }

    #[test]
    fn a_dab_selects_a_ball_in_millimetres_and_erasing_takes_it_back() {
        // 40 × 40 × 20 voxels of 0.5 × 0.5 × 1 mm: a ball of radius 5 mm is 10 voxels
        // across in x and y and 5 in z.
        let grid = Grid::new(UVec3::new(40, 40, 20), Vec3::new(0.5, 0.5, 1.0));
        let empty = SelectionVolume::empty(grid.clone());
        let centre = grid.index_to_world().transform_point3(Vec3::new(20.0, 20.0, 10.0));
        let hard = Brush { radius: 5.0, hardness: 1.0, erase: false };
        let s = paint(&empty.volume, hard, [centre]).unwrap();
        let selected = |s: &SelectionVolume, i, j, k| s.doi(i, j, k) > 0.5;
        assert!(selected(&s, 20, 20, 10));
        assert!(selected(&s, 30, 20, 10) && !selected(&s, 31, 20, 10), "5 mm = 10 voxels along x");
        assert!(selected(&s, 20, 20, 15) && !selected(&s, 20, 20, 16), "5 mm = 5 voxels along z");
        assert!(!selected(&s, 28, 28, 10), "(4, 4) mm off is 5.66 mm away");
        // The count matches the ball's volume: (4/3)π·5³ mm³ over 0.25 mm³ a voxel.
        let count = (0..40 * 40 * 20).filter(|&n| s.volume.voxels.code(n) == 255).count() as f32;
        let expected = 4.0 / 3.0 * std::f32::consts::PI * 125.0 / 0.25;
        assert!((count / expected - 1.0).abs() < 0.05, "{count} voxels, the ball holds {expected:.0}");
        // Erasing with a smaller brush makes a hole in the middle; the rim stays.
        let hole = paint(&s.volume, Brush { radius: 2.0, erase: true, ..hard }, [centre]).unwrap();
        assert!(!selected(&hole, 20, 20, 10) && selected(&hole, 28, 20, 10));
        // A dab outside the volume changes nothing.
        let outside = paint(&s.volume, hard, [Vec3::splat(-100.0)]).unwrap();
        assert_eq!(outside.volume.voxels, s.volume.voxels);
    }

    #[test]
    fn strokes_replay_in_order_and_check_their_numbers() {
        let grid = Grid::new(UVec3::splat(16), Vec3::ONE);
        let add = Stroke { radius: 4.0, hardness: 0.5, erase: false, dabs: vec![(8.0, 8.0, 8.0)] };
        let erase = Stroke { erase: true, ..add.clone() };
        let painted = paint_strokes(SelectionVolume::empty(grid.clone()), std::slice::from_ref(&add)).unwrap();
        assert_eq!(painted.doi(8, 8, 8), 1.0);
        // Soft rim: 3 mm off, x = 1/2: 0.5 → code 128.
        assert_eq!(painted.volume.code(11, 8, 8), 128);
        // Erasing with the same soft brush clears its core; in the rim each voxel keeps
        // min(doi, 1 − b): 3 mm off, min(128, 127).
        let both = paint_strokes(SelectionVolume::empty(grid.clone()), &[add.clone(), erase]).unwrap();
        assert_eq!(both.doi(8, 8, 8), 0.0);
        assert_eq!(both.volume.code(11, 8, 8), 127);
        // A hard brush takes back all it gave.
        let hard = Stroke { hardness: 1.0, ..add.clone() };
        let gone = paint_strokes(SelectionVolume::empty(grid), &[hard.clone(), Stroke { erase: true, ..hard }]).unwrap();
        assert!((0..16 * 16 * 16).all(|n| gone.volume.voxels.code(n) == 0));
        assert!(add.validate().is_ok());
        assert!(Stroke { radius: 0.0, ..add.clone() }.validate().unwrap_err().contains("radius"));
        assert!(Stroke { hardness: 1.5, ..add.clone() }.validate().unwrap_err().contains("hardness"));
        assert!(Stroke { dabs: vec![(f32::NAN, 0.0, 0.0)], ..add }.validate().unwrap_err().contains("dab"));
    }
}
