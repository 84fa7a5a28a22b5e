//! Selection volumes: a degree of interest in `[0, 1]` per voxel.
//!
//! The selection is the *focus* object of the exploded views (and can shape a feature
//! lens). It is stored as 8-bit codes (`doi = code / 255`) on the grid of the volume it
//! selects from, so it samples like any other volume. It can be made from label ids or
//! from a value range, and binary masks can be smoothed into soft edges with a separable
//! binomial filter (`[1 2 1] / 4` per axis and pass, a discrete Gaussian).

use std::collections::BTreeSet;

use rayon::prelude::*;

use super::{Grid, LabelVolume, Source, ValueMap, Volume, Voxels};

/// Degree-of-interest volume.
#[derive(Clone, Debug)]
pub struct SelectionVolume {
    pub volume: Volume,
}

impl SelectionVolume {
    /// Wraps degree-of-interest codes (0 = not selected, 255 = fully selected).
    pub fn from_codes(grid: Grid, codes: Vec<u8>) -> Result<Self, String> {
        let source = Source { format: "selection".into(), ..Default::default() };
        Ok(Self { volume: Volume::new("selection", grid, Voxels::U8(codes), ValueMap::new(1.0 / 255.0, 0.0), source)? })
    }

    /// Nothing selected.
    pub fn empty(grid: Grid) -> Self {
        let n = grid.voxel_count();
        Self::from_codes(grid, vec![0; n]).unwrap_or_else(|e| unreachable!("a validated grid: {e}"))
    }

    /// Selects every voxel whose label id is in `ids`.
    pub fn from_labels(labels: &LabelVolume, ids: &BTreeSet<u32>) -> Result<Self, String> {
        let v = &labels.volume.voxels;
        let codes = (0..v.len()).into_par_iter().map(|i| if ids.contains(&(v.code(i) as u32)) { 255 } else { 0 }).collect();
        Self::from_codes(labels.volume.grid.clone(), codes)
    }

    /// Selects every voxel whose real value lies in `[lo, hi]`.
    pub fn from_value_range(volume: &Volume, lo: f64, hi: f64) -> Result<Self, String> {
        let v = &volume.voxels;
        let map = &volume.values;
        let codes = (0..v.len())
            .into_par_iter()
            .map(|i| {
                let x = map.to_real(v.code(i) as f64);
                if x >= lo && x <= hi { 255 } else { 0 }
            })
            .collect();
        Self::from_codes(volume.grid.clone(), codes)
    }

    /// The selection on another grid (one made from a label volume on a grid other
    /// than its data's, moved onto the data's: the explosion points, the GPU's second
    /// channel and painting all take the data's grid): each voxel of `grid` takes the
    /// mean degree of interest of trilinear samples spread over its cell, one per
    /// selection voxel its cell spans along each axis (at most 3, so a thin structure
    /// of a finer label grid leaves a partial degree of interest instead of falling
    /// between centres); 0 outside this selection's box of voxel cells.
    pub fn resampled(&self, grid: &Grid) -> Result<Self, String> {
        if *grid == self.volume.grid {
            return Ok(self.clone());
        }
        grid.validate()?;
        let to_index = self.volume.grid.world_to_index() * grid.index_to_world();
        let sampler = self.volume.sampler();
        let (lo, hi) = (glam::Vec3::splat(-0.5), self.volume.dims().as_vec3() - 0.5);
        let d = grid.dims;
        let m = to_index.matrix3;
        let n = [m.x_axis, m.y_axis, m.z_axis].map(|c| (c.length().ceil() as u32).clamp(1, 3));
        let offsets: Vec<glam::Vec3> = (0..n[0] * n[1] * n[2])
            .map(|s| {
                let (a, b, c) = (s % n[0], s / n[0] % n[1], s / (n[0] * n[1]));
                let at = |k: u32, n: u32| (k as f32 + 0.5) / n as f32 - 0.5;
                glam::Vec3::new(at(a, n[0]), at(b, n[1]), at(c, n[2]))
            })
            .collect();
        let codes = (0..grid.voxel_count())
            .into_par_iter()
            .map(|v| {
                let centre = glam::Vec3::new((v as u32 % d.x) as f32, (v as u32 / d.x % d.y) as f32, (v as u32 / (d.x * d.y)) as f32);
                let sum: f32 = offsets
                    .iter()
                    .map(|o| to_index.transform_point3(centre + *o))
                    .filter(|p| !(p.cmplt(lo).any() || p.cmpgt(hi).any()))
                    .map(|p| sampler.trilinear(p))
                    .sum();
                (sum / offsets.len() as f32 * 255.0).round().clamp(0.0, 255.0) as u8
            })
            .collect();
        Self::from_codes(grid.clone(), codes)
    }

    /// Degree of interest of voxel (i, j, k).
    pub fn doi(&self, i: u32, j: u32, k: u32) -> f32 {
        self.volume.code(i, j, k) as f32 / 255.0
    }

    /// Softens the edges with `passes` binomial passes along each axis.
    pub fn smoothed(&self, passes: u32) -> Result<Self, String> {
        let dims = self.volume.grid.dims;
        let Voxels::U8(codes) = &self.volume.voxels else {
            return Err("selection volumes hold 8-bit codes".into());
        };
        let mut f: Vec<f32> = codes.iter().map(|&c| c as f32).collect();
        let (nx, ny, nz) = (dims.x as usize, dims.y as usize, dims.z as usize);
        for _ in 0..passes {
            for (stride, n) in [(1usize, nx), (nx, ny), (nx * ny, nz)] {
                let src = f.clone();
                f.par_iter_mut().enumerate().for_each(|(i, out)| {
                    let pos = (i / stride) % n;
                    let prev = if pos > 0 { src[i - stride] } else { src[i] };
                    let next = if pos + 1 < n { src[i + stride] } else { src[i] };
                    *out = 0.25 * prev + 0.5 * src[i] + 0.25 * next;
                });
            }
        }
        Self::from_codes(self.volume.grid.clone(), f.into_iter().map(|x| x.round().clamp(0.0, 255.0) as u8).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::LabelTable;
    use glam::{UVec3, Vec3};

    #[test]
    fn a_selection_moves_onto_another_grid() {
        // 4 voxels of 2 mm (centres 0, 2, 4, 6 mm) with voxel 1 selected, onto 1 mm
        // voxels from −2 mm: centres at −2 (outside the box, which starts at −1), −1
        // (the first cell's edge: voxel 0's 0), 2 (voxel 1: 255), 3 (half way: 128),
        // 4 (voxel 2: 0) and 8 (outside).
        let coarse = Grid::new(UVec3::new(4, 1, 1), Vec3::splat(2.0));
        let s = SelectionVolume::from_codes(coarse.clone(), vec![0, 255, 0, 0]).unwrap();
        let mut fine = Grid::new(UVec3::new(11, 1, 1), Vec3::ONE);
        fine.origin = Vec3::new(-2.0, 0.0, 0.0);
        let r = s.resampled(&fine).unwrap();
        assert_eq!(r.volume.grid, fine);
        let at = |mm: i32| r.volume.code((mm + 2) as u32, 0, 0);
        assert_eq!((at(-2), at(-1), at(2), at(3), at(4), at(8)), (0, 0, 255, 128, 0, 0));
        // Onto voxels of 3 mm along x (centres 1, 4, 7 mm) from 1 mm ones with voxel 3
        // selected: the middle one spans 3, 4 and 5 mm, a third selected (a sample at
        // its centre alone would miss it).
        let thin =
            SelectionVolume::from_codes(Grid::new(UVec3::new(9, 1, 1), Vec3::ONE), (0..9).map(|i| if i == 3 { 255 } else { 0 }).collect())
                .unwrap();
        let mut wide = Grid::new(UVec3::new(3, 1, 1), Vec3::new(3.0, 1.0, 1.0));
        wide.origin = Vec3::new(1.0, 0.0, 0.0);
        let r = thin.resampled(&wide).unwrap();
        assert_eq!((r.volume.code(0, 0, 0), r.volume.code(1, 0, 0), r.volume.code(2, 0, 0)), (0, 85, 0));
        // On its own grid it is itself.
        assert_eq!(s.resampled(&coarse).unwrap().volume.voxels, s.volume.voxels);
    }

    #[test]
    fn selection_from_labels_and_ranges() {
        let grid = Grid::new(UVec3::new(4, 1, 1), Vec3::ONE);
        let v = Volume::new("v", grid.clone(), Voxels::U8(vec![0, 1, 2, 1]), ValueMap::IDENTITY, Source::default()).unwrap();
        let labels = LabelVolume::from_volume(v.clone(), LabelTable::default()).unwrap();
        let s = SelectionVolume::from_labels(&labels, &BTreeSet::from([1])).unwrap();
        assert_eq!((s.doi(0, 0, 0), s.doi(1, 0, 0), s.doi(2, 0, 0), s.doi(3, 0, 0)), (0.0, 1.0, 0.0, 1.0));
        let r = SelectionVolume::from_value_range(&v, 1.5, 2.0).unwrap();
        assert_eq!(r.doi(2, 0, 0), 1.0);
        assert_eq!(r.doi(1, 0, 0), 0.0);
    }

    #[test]
    fn smoothing_spreads_a_point_binomially() {
        let grid = Grid::new(UVec3::new(5, 1, 1), Vec3::ONE);
        let s = SelectionVolume::from_codes(grid, vec![0, 0, 255, 0, 0]).unwrap().smoothed(1).unwrap();
        // [1 2 1]/4 of 255 → 64, 128, 64 (rounded); y and z passes see clamped copies.
        assert_eq!(s.volume.voxels, Voxels::U8(vec![0, 64, 128, 64, 0]));
    }
}
