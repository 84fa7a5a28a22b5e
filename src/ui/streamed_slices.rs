//! Native slices of streamed datasets in the slice views. A streamed dataset holds only a
//! coarse level in memory; each view asks for its slice through the crosshair at the
//! finest level whose slice fits [`MAX_APP_SLICE_PIXELS`], read on the compute pool
//! ([`Slice::of_source`]: one voxel-thick box). Until it arrives the view shows the level
//! in memory and says which level is on its way. A view has one read at a time: while
//! the crosshair is dragged, the read under way finishes before the next one starts.

use std::sync::Arc;

use bevy::prelude::*;
use bevy::tasks::{AsyncComputeTaskPool, Task, futures::check_ready};

use crate::slices::image::finest_level_within;
use crate::slices::{Orientation, Slice, SliceAxes, crosshair};
use crate::volume::source::VoxelSource;

/// Largest native slice read for a view: a finer level's would be larger than the view
/// shows (and slower to read); the finest level within it is taken.
pub const MAX_APP_SLICE_PIXELS: u64 = 2048 * 2048;

/// A slice of a streamed dataset: which level, which index along the view's normal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Wanted {
    pub dataset: Entity,
    pub level: usize,
    pub index: u32,
}

impl Wanted {
    /// The slice view `o` wants of `source` through `point` (the dataset's frame), and
    /// the axes of that level; `None` for a source without levels.
    pub fn of(source: &dyn VoxelSource, dataset: Entity, o: Orientation, point: Vec3) -> Option<(Wanted, SliceAxes)> {
        let levels = &source.info().levels;
        let level = finest_level_within(levels, o, MAX_APP_SLICE_PIXELS)?;
        let grid = &levels[level].grid;
        let axes = SliceAxes::of(grid.direction, o);
        Some((Wanted { dataset, level, index: crosshair::slice_through(&axes, grid, point) }, axes))
    }
}

/// Where a native slice stands.
#[derive(Debug)]
pub enum Native {
    /// Being read.
    Reading,
    /// Read: the caller keeps it.
    Ready(Slice),
    /// Handed over already (the caller has it).
    Taken,
    Failed(String),
}

/// The reads of the three views.
#[derive(Default)]
pub struct StreamedSlices {
    reads: [Option<(Wanted, Read)>; 3],
}

enum Read {
    Running(Task<Result<Slice, String>>),
    Taken,
    Failed(String),
}

impl StreamedSlices {
    /// Where view `k`'s slice `wanted` stands, starting its read when it is new.
    pub fn poll(&mut self, k: usize, wanted: Wanted, axes: SliceAxes, source: &Arc<dyn VoxelSource>) -> Native {
        let entry = &mut self.reads[k];
        // One read at a time per view (a read cannot be stopped once it runs): a read the
        // crosshair has left finishes first, unused, then the one wanted now starts.
        if let Some((w, Read::Running(task))) = entry
            && *w != wanted
        {
            if check_ready(task).is_none() {
                return Native::Reading;
            }
            *entry = None;
        }
        if entry.as_ref().is_none_or(|(w, _)| *w != wanted) {
            let source = source.clone();
            let task =
                AsyncComputeTaskPool::get().spawn(async move { Slice::of_source(source.as_ref(), wanted.level, axes, wanted.index) });
            *entry = Some((wanted, Read::Running(task)));
        }
        let Some((_, read)) = entry else { return Native::Reading };
        match read {
            Read::Running(task) => match check_ready(task) {
                None => Native::Reading,
                Some(Ok(slice)) => {
                    *read = Read::Taken;
                    Native::Ready(slice)
                }
                Some(Err(e)) => {
                    *read = Read::Failed(e.clone());
                    Native::Failed(e)
                }
            },
            Read::Taken => Native::Taken,
            Read::Failed(e) => Native::Failed(e.clone()),
        }
    }

    /// Whether a read is under way (the screenshot automation waits for them).
    pub fn reading(&self) -> bool {
        self.reads.iter().flatten().any(|(_, r)| matches!(r, Read::Running(_)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::source::procedural::ProceduralSource;

    #[test]
    fn a_streamed_slice_is_read_at_the_finest_level_that_fits_and_handed_over_once() {
        bevy::tasks::AsyncComputeTaskPool::get_or_init(bevy::tasks::TaskPool::default);
        // 256³ voxels: level 0's slices (256²) fit, so the views read level 0.
        let source: Arc<dyn VoxelSource> = Arc::new(ProceduralSource::new(UVec3::splat(256), Vec3::ONE).unwrap());
        let dataset = Entity::from_raw_u32(3).unwrap();
        let centre = Vec3::ZERO;
        let (wanted, axes) = Wanted::of(source.as_ref(), dataset, Orientation::Axial, centre).unwrap();
        assert_eq!((wanted.level, wanted.index), (0, 128));
        let mut reads = StreamedSlices::default();
        let start = std::time::Instant::now();
        let slice = loop {
            match reads.poll(1, wanted, axes, &source) {
                Native::Reading if start.elapsed().as_secs() < 60 => std::thread::sleep(std::time::Duration::from_millis(5)),
                Native::Ready(slice) => break slice,
                other => panic!("{other:?}"),
            }
        };
        assert_eq!((slice.width, slice.height, slice.index), (256, 256, 128));
        assert_eq!(slice, Slice::of_source(source.as_ref(), 0, axes, 128).unwrap());
        assert!(matches!(reads.poll(1, wanted, axes, &source), Native::Taken), "handed over once");
        assert!(!reads.reading());
        // The crosshair moves: a new read.
        let next = Wanted { index: 10, ..wanted };
        assert!(matches!(reads.poll(1, next, axes, &source), Native::Reading | Native::Ready(_)));
    }
}
