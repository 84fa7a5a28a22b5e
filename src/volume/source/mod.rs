//! Where voxels come from: one trait, [`VoxelSource`], for a volume in memory
//! ([`memory::MemorySource`]), a pyramid on disk ([`crate::volume::readers::ome_zarr`])
//! and a procedural field of any size ([`procedural::ProceduralSource`]).
//!
//! A source is a resolution pyramid: level 0 is the finest, each further level halves
//! the one before (level `k` voxel `j` covers level-0 voxels `2ᵏj … 2ᵏ(j + 1) − 1`, its
//! centre at `(2ᵏ − 1)/2` level-0 voxels past theirs; see [`crate::volume::pyramid`]).
//! Every level has its own [`Grid`] in Focal's world frame. Values are handed out as
//! voxel codes ([`Voxels`], 8 or 16 bit) under one [`ValueMap`] fixed when the source is
//! opened, so bricks of any level read alike on the GPU.
//!
//! The renderer asks for one box of one level at a time ([`VoxelSource::read_box`]), from
//! several threads at once. A box that is only partly readable (a corrupt chunk, a
//! missing file) still comes back whole, the unreadable part at the fill value, with a
//! [`Fault`] naming the source and the chunk: a picture is drawn from what is there.
//! [`brick`] cuts the boxes the GPU's brick atlas holds (a brick plus its apron),
//! [`cache`] keeps decoded bricks within a budget, loading them in the background, and
//! [`lod`] picks the level each part of the view needs (lenses included).

pub mod brick;
pub mod cache;
pub mod level;
pub mod lod;
pub mod memory;
pub mod procedural;

use glam::UVec3;

use super::grid::{Grid, fmt_dims};
use super::{Source, ValueMap, Voxels};

/// One level of a source's pyramid.
#[derive(Clone, Debug, PartialEq)]
pub struct SourceLevel {
    /// Where the level's voxels lie (dimensions, spacing, origin, orientation).
    pub grid: Grid,
    /// The storage's own chunk shape: boxes aligned to it read fastest.
    pub chunk: UVec3,
}

/// What a source holds, known once it is opened.
#[derive(Clone, Debug)]
pub struct SourceInfo {
    /// Display name.
    pub name: String,
    /// Format, path, sample type and further facts.
    pub source: Source,
    /// Codes to real values, for every level.
    pub values: ValueMap,
    /// Bits per code: 8 or 16.
    pub bits: u32,
    /// Level 0 (finest) first.
    pub levels: Vec<SourceLevel>,
    /// What had to be interpreted on opening (a channel picked, units assumed, …).
    pub warnings: Vec<String>,
    /// The real value range of level 0 when the source knows it without reading it all
    /// (an OME-Zarr display window's min and max, a volume in memory's): what relative
    /// transfer functions resolve against when only a coarse level is in memory.
    pub range: Option<(f64, f64)>,
}

impl SourceInfo {
    /// Where the voxels come from, for messages: the file, folder or address the source
    /// was opened from, else its name (an OME-Zarr image's own name may be anything,
    /// "image" say, which tells a user nothing).
    pub fn location(&self) -> String {
        self.source.path.as_ref().map_or_else(|| self.name.clone(), |p| p.display().to_string())
    }

    /// The largest code (normalisation denominator).
    pub fn code_max(&self) -> u32 {
        if self.bits == 8 { u8::MAX as u32 } else { u16::MAX as u32 }
    }

    /// Codes, all zero, of the source's width.
    pub fn zeros(&self, len: usize) -> Voxels {
        if self.bits == 8 { Voxels::U8(vec![0; len]) } else { Voxels::U16(vec![0; len]) }
    }

    /// Voxels in all levels.
    pub fn total_voxels(&self) -> u64 {
        self.levels.iter().map(|l| l.grid.voxel_count() as u64).sum()
    }
}

/// Why part of a box holds the fill value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FaultKind {
    /// The store has no such chunk: by Zarr's rules it is all fill value (tools leave
    /// empty chunks out), so this is a note, not an error.
    Absent,
    /// The chunk is there but could not be read or decoded.
    Unreadable,
    /// The chunk was read, but some samples are NaN or infinite (drawn as code 0).
    NotFinite,
}

/// Part of a box that could not be read.
#[derive(Clone, Debug, PartialEq)]
pub struct Fault {
    /// The chunk (its store key, or a description) that failed.
    pub chunk: String,
    pub kind: FaultKind,
    /// Why.
    pub problem: String,
}

/// Voxels of a box, and what in it could not be read.
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    /// The box's codes, x fastest.
    pub voxels: Voxels,
    /// Chunks drawn at the fill value because they failed.
    pub faults: Vec<Fault>,
}

/// A request a source cannot serve at all.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{source_name}: {problem}")]
pub struct SourceError {
    /// The source (its path or name).
    pub source_name: String,
    pub problem: String,
}

impl SourceError {
    pub fn new(source_name: impl Into<String>, problem: impl Into<String>) -> Self {
        Self { source_name: source_name.into(), problem: problem.into() }
    }
}

/// A resolution pyramid of voxels, read a box at a time from any thread.
pub trait VoxelSource: Send + Sync {
    /// Grid, values and levels.
    fn info(&self) -> &SourceInfo;

    /// The codes of voxels `lo .. lo + size` of `level`, which must lie inside it.
    fn read_box(&self, level: usize, lo: UVec3, size: UVec3) -> Result<Block, SourceError>;

    /// Lets the source keep up to `bytes` of what it decoded for later reads (the
    /// chunks a box shares with the boxes beside it) and returns how many it may keep,
    /// which the caller takes from its own memory budget. A source that decodes nothing
    /// keeps nothing (the default).
    fn keep_decoded(&self, _bytes: u64) -> u64 {
        0
    }
}

/// Checks that a box lies inside a level of `info` (the common guard of every source).
pub fn check_box(info: &SourceInfo, level: usize, lo: UVec3, size: UVec3) -> Result<(), SourceError> {
    let Some(l) = info.levels.get(level) else {
        return Err(SourceError::new(info.location(), format!("level {level} asked for, the pyramid has {}", info.levels.len())));
    };
    let hi = lo.as_u64vec3() + size.as_u64vec3();
    let dims = l.grid.dims.as_u64vec3();
    if size.min_element() == 0 || hi.cmpgt(dims).any() {
        return Err(SourceError::new(
            info.location(),
            format!("box {lo} + {} lies outside level {level} ({})", fmt_dims(size), fmt_dims(l.grid.dims)),
        ));
    }
    Ok(())
}

/// The grid of level `k` of a pyramid over `base`: dimensions halved `k` times (rounding
/// up), spacing doubled, the origin moved to the centre of the first block of `2ᵏ`
/// level-0 voxels.
pub fn level_grid(base: &Grid, k: u32) -> Grid {
    let f = (1u32 << k) as f32;
    let mut dims = base.dims;
    for _ in 0..k {
        dims = super::pyramid::half_dims(dims);
    }
    let shift = base.direction * (base.spacing * (f - 1.0) * 0.5);
    Grid { dims, spacing: base.spacing * f, origin: base.origin + shift, direction: base.direction }
}

/// Number of levels that halve `dims` until every axis is at most `smallest` voxels
/// (at least one level).
pub fn level_count(dims: UVec3, smallest: u32) -> usize {
    let mut d = dims;
    let mut n = 1;
    while d.max_element() > smallest.max(1) {
        d = super::pyramid::half_dims(d);
        n += 1;
    }
    n
}

#[cfg(test)]
mod tests {
    use glam::{Mat3, Vec3};

    use super::*;

    #[test]
    fn level_grids_keep_block_centres_in_place() {
        // Spacing 2 along x from origin 10: level-0 voxels 0..4 lie at 10, 12, 14, 16.
        let base = Grid {
            dims: UVec3::new(5, 4, 1),
            spacing: Vec3::new(2.0, 1.0, 1.0),
            origin: Vec3::new(10.0, 0.0, 0.0),
            direction: Mat3::IDENTITY,
        };
        let l1 = level_grid(&base, 1);
        // Level-1 voxel 0 is the mean of level-0 voxels 0 and 1: centre 11; spacing 4.
        // Along z the one voxel stands in for its missing partner too: the centre moves
        // half a voxel as on the other axes.
        assert_eq!(l1.dims, UVec3::new(3, 2, 1));
        assert_eq!(l1.origin, Vec3::new(11.0, 0.5, 0.5));
        assert_eq!(l1.spacing, Vec3::new(4.0, 2.0, 2.0));
        let l2 = level_grid(&base, 2);
        // Level-2 voxel 0 covers level-0 voxels 0..3: centre (10 + 16)/2 = 13.
        assert_eq!(l2.origin.x, 13.0);
        assert_eq!(l2.dims, UVec3::new(2, 1, 1));
        // An oblique grid moves along its own axes.
        let flipped = Grid { direction: Mat3::from_diagonal(Vec3::new(-1.0, 1.0, 1.0)), ..base };
        assert_eq!(level_grid(&flipped, 1).origin.x, 9.0);
    }

    #[test]
    fn levels_stop_at_the_smallest_size() {
        assert_eq!(level_count(UVec3::splat(64), 64), 1);
        assert_eq!(level_count(UVec3::new(65, 3, 3), 64), 2);
        assert_eq!(level_count(UVec3::splat(8192), 32), 9);
    }
}
