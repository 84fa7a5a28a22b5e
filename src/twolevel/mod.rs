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
use crate::volume::BrickGrid;

/// Each label code's class: codes with the same candidate objects (so the same part for
/// every value) share the class of the first of them; codes past the table are the rest.
pub fn code_classes(table: &ObjectTable, codes: usize) -> Vec<u16> {
    let rest = [0u16; crate::region::appearance::MAX_CANDIDATES];
    let mut first = std::collections::HashMap::new();
    (0..codes).map(|c| *first.entry(table.candidates.get(c).copied().unwrap_or(rest)).or_insert(c as u16)).collect()
}

/// The label bricks where a sample's cell may hold more than one label: those of more
/// than one code. A brick's code range covers every voxel a trilinear sample in it
/// touches (`volume::bricks`: a one-voxel apron), so a brick of one code holds whole
/// cells of one label, and of one object.
pub fn boundary_bricks(labels: &BrickGrid) -> Vec<bool> {
    labels.min.iter().zip(&labels.max).map(|(lo, hi)| lo != hi).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boundary_bricks_are_those_of_more_than_one_code() {
        use crate::volume::{Grid, Source, ValueMap, Volume, Voxels};
        let bricks = |change: u32| {
            let codes = (0..40u32).map(|x| if x < change { 3 } else { 5 }).collect();
            let grid = Grid::centered(glam::UVec3::new(40, 1, 1), glam::Vec3::ONE);
            let labels = Volume::new("l", grid, Voxels::U8(codes), ValueMap::IDENTITY, Source::default()).unwrap();
            boundary_bricks(labels.bricks())
        };
        // 40 voxels along x in bricks of 8, codes 3 below the change and 5 from it. At
        // x = 20 brick 2 holds it; with their aprons bricks 1 (voxels 7–16) and 3
        // (23–32) hold one code each.
        assert_eq!(bricks(20), vec![false, false, true, false, false]);
        // At a brick's edge (x = 16) the aprons take the change into both bricks.
        assert_eq!(bricks(16), vec![false, true, true, false, false]);
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
