//! Two-level volume rendering of segmented data (Hauser, Mroz, Bischi, Gröller,
//! "Two-level volume rendering", IEEE TVCG 7(3), 2001; used for the magic-lens paper's
//! figures 5 and 15).
//!
//! A data volume is split into *objects* by a label volume: every object lists label
//! codes (and optionally a range of data values), and has its own rendering mode and
//! transfer function. Along a ray, the samples form *segments*: runs of consecutive
//! samples in the same object. Rendering has two levels:
//!
//! 1. **Local**: each segment is rendered with its object's mode. DVR-like modes
//!    (DVR, gradient-modulated, context-preserving) composite their samples front to
//!    back; MIP / MinIP / X-ray keep the max / min / mean of the segment's samples and
//!    classify that one value through the object's transfer function when the segment
//!    ends; an iso-surface object contributes its first crossing inside the segment,
//!    shaded and opaque. Hidden objects contribute nothing.
//! 2. **Global**: the segments' results are composited front to back with "over",
//!    `C += (1 − A)·α·c`, `A += (1 − A)·α`, in the order the ray meets them. For DVR
//!    objects local and global compositing are the same operation, so their samples go
//!    straight into the ray's accumulator; a projection segment enters it as one sample
//!    where the segment ends. (Hauser et al. also describe MIP as a global method; Focal
//!    composites globally with "over" only.)
//!
//! Samples in no object belong to *the rest*, rendered with the data volume's own
//! appearance (typically a faint or context-preserving view of everything else).
//!
//! The description ([`Segmentation`], [`Object`]) and the pure object lookup both
//! renderers use ([`ObjectTable`]) are part of a region's look, in
//! [`crate::region::appearance`] (an object's look is an appearance again, so the two
//! cannot live apart). This folder holds what is two-level rendering's alone: [`spec`],
//! how scene files name objects (label codes, names matched in the label table, value
//! ranges) and how they are resolved against the label volume. The CPU reference
//! (`reference::trace`) and the shader (`shaders/focal/two_level.wgsl`)
//! implement the compositing.
//!
//! **Object boundaries.** A sample's object is its nearest label voxel's, but a plain
//! trilinear sample beside a boundary mixes in the other object's voxels: the soft
//! tissue next to a skull drawn as its own object reads bone values, and the rest's
//! transfer function draws them as a rim. Where the label volume lies on the data's grid,
//! each sample's value is interpolated from the voxels of its own label alone (the
//! trilinear weights renormalised over them: `reference::prepare::PreparedObjects::own_value`,
//! `two_level.wgsl` own_value), as two-level renderers filter each object on its own
//! (Hadwiger et al., "High-quality two-level volume rendering of segmented data sets",
//! VIS 2003, §4). The GPU fetches the cell's eight labels only in [`boundary_bricks`].
//!
//! [`Segmentation`]: crate::region::Segmentation
//! [`Object`]: crate::region::Object
//! [`ObjectTable`]: crate::region::ObjectTable

pub mod spec;

use crate::region::ObjectTable;
use crate::volume::{BrickGrid, Volume, Voxels};

/// Each label code's class: codes with the same candidate objects (so the same part for
/// every value) share the class of the first of them; codes past the table are the rest.
pub fn code_classes(table: &ObjectTable, codes: usize) -> Vec<u16> {
    let rest = [0u16; crate::region::appearance::MAX_CANDIDATES];
    let of = |c: usize| table.candidates.get(c).copied().unwrap_or(rest);
    (0..codes).map(|c| (0..=c).find(|&d| of(d) == of(c)).unwrap_or(c) as u16).collect()
}

/// The bricks of `labels` (its own brick grid) where a sample's cell may hold voxels of
/// more than one class ([`code_classes`]): [`boundary_bricks`] over the classes.
pub fn class_boundary_bricks(labels: &Volume, table: &ObjectTable) -> (glam::UVec4, Vec<bool>) {
    let classes = code_classes(table, labels.code_max() as usize + 1);
    let codes = (0..labels.voxels.len()).map(|i| classes.get(labels.voxels.code(i) as usize).copied().unwrap_or(u16::MAX)).collect();
    let grid = BrickGrid::build(&Voxels::U16(codes), labels.dims(), labels.bricks().size);
    (grid.dims.extend(grid.size), boundary_bricks(&grid))
}

/// The label bricks where a sample's cell may hold more than one label: all but those
/// that hold one code, as do their 26 neighbours, the same one (a cell's eight voxels lie
/// within its nearest voxel's brick and the bricks around it). `labels`: the label
/// volume's brick grid (per brick the smallest and largest code).
pub fn boundary_bricks(labels: &BrickGrid) -> Vec<bool> {
    let d = labels.dims.as_ivec3();
    let index = |b: glam::IVec3| (b.z * d.y * d.x + b.y * d.x + b.x) as usize;
    let mut out = Vec::with_capacity(labels.min.len());
    for z in 0..d.z {
        for y in 0..d.y {
            for x in 0..d.x {
                let b = glam::IVec3::new(x, y, z);
                let code = labels.min[index(b)];
                let mut uniform = true;
                for n in (-1..=1).flat_map(|k| (-1..=1).flat_map(move |j| (-1..=1).map(move |i| glam::IVec3::new(i, j, k)))) {
                    let c = b + n;
                    if c.cmpge(glam::IVec3::ZERO).all() && c.cmplt(d).all() {
                        let i = index(c);
                        uniform &= labels.min[i] == code && labels.max[i] == code;
                    }
                }
                out.push(!uniform);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boundary_bricks_are_those_next_to_a_change_of_label() {
        // Five bricks in a row: codes 0, 0, 0–1, 1, 1 (min–max). Brick 2 holds two labels;
        // 1 and 3 border it; 0 and 4 see one label all around.
        let grid = BrickGrid { size: 8, dims: glam::UVec3::new(5, 1, 1), min: vec![0, 0, 0, 1, 1], max: vec![0, 0, 1, 1, 1] };
        assert_eq!(boundary_bricks(&grid), vec![false, true, true, true, false]);
        // Two one-label bricks of different codes side by side: both.
        let grid = BrickGrid { size: 8, dims: glam::UVec3::new(2, 1, 1), min: vec![3, 4], max: vec![3, 4] };
        assert_eq!(boundary_bricks(&grid), vec![true, true]);
        // One label everywhere: none.
        let grid = BrickGrid { size: 8, dims: glam::UVec3::new(2, 2, 2), min: vec![7; 8], max: vec![7; 8] };
        assert!(boundary_bricks(&grid).iter().all(|b| !b));
    }

    #[test]
    fn codes_of_the_same_objects_are_one_class() {
        // Codes 0 and 3: no object (the rest); 1 and 2: object 0; 4: objects 0 then 1.
        let table = ObjectTable {
            candidates: vec![[0, 0, 0, 0], [1, 0, 0, 0], [1, 0, 0, 0], [0, 0, 0, 0], [1, 2, 0, 0]],
            ranges: vec![(f32::MIN, f32::MAX); 2],
        };
        assert_eq!(code_classes(&table, 6), vec![0, 1, 1, 0, 4, 0]);
    }
}
