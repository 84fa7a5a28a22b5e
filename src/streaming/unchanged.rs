//! Selection on change only: a bricked volume's frame ([`BrickFrame`]) is drawn anew
//! only when something it depends on changed since the last frame: the views (cameras,
//! screens, magnifiers), the regions showing the volume, their looks, the brick budget,
//! or the cache (a brick arrived, was evicted or failed, or one is still on its way).
//! A still view of a converged volume then costs no selection at all: with a 4×
//! magnifier over the procedural 1024³ source the selection, the visibility tests of
//! every drawn brick's sub-blocks and the renderer's page table took 8–9 ms of every
//! frame (2 ms without the lens), on the cores the software rasteriser draws with.
//! The renderer keeps its page table for as long as it is handed the same frame
//! (`render::bricked::atlas`).

use std::collections::HashMap;
use std::sync::Arc;

use bevy::prelude::Entity;

use super::bricked::BrickFrame;
use super::select::{Seen, ViewFrame};
use crate::region::Appearance;
use crate::volume::Volume;
use crate::volume::source::cache::CacheStats;

/// What a bricked volume's selection depends on this frame, apart from its cache
/// (borrowed: compared every frame, copied only when a frame is drawn anew).
pub struct Inputs<'a> {
    pub volume: &'a Arc<Volume>,
    pub frames: &'a [ViewFrame],
    pub seen: Vec<Seen>,
    pub looks: Vec<&'a Appearance>,
    /// The most bricks the selection may want.
    pub cap: usize,
}

/// [`Inputs`] as a kept frame was drawn from (the volume held, so that no other volume
/// can take its address).
struct KeptInputs {
    volume: Arc<Volume>,
    frames: Vec<ViewFrame>,
    seen: Vec<Seen>,
    looks: Vec<Appearance>,
    cap: usize,
}

impl KeptInputs {
    fn of(inputs: Inputs) -> Self {
        let Inputs { volume, frames, seen, looks, cap } = inputs;
        KeptInputs { volume: volume.clone(), frames: frames.to_vec(), seen, looks: looks.into_iter().cloned().collect(), cap }
    }

    fn are(&self, now: &Inputs) -> bool {
        Arc::ptr_eq(&self.volume, now.volume)
            && self.cap == now.cap
            && self.frames == now.frames
            && self.seen == now.seen
            && same_looks(&self.looks, &now.looks)
    }
}

/// Whether `kept` are the looks `now`, in the same order.
pub fn same_looks(kept: &[Appearance], now: &[&Appearance]) -> bool {
    kept.len() == now.len() && kept.iter().zip(now).all(|(a, b)| a == *b)
}

/// One volume's part of the streaming status.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VolumeCounts {
    pub wanted: usize,
    pub resident: usize,
    pub pending: usize,
    pub failed: u64,
    pub finest: Option<usize>,
}

impl VolumeCounts {
    /// The counts of two volumes together.
    pub fn plus(self, other: VolumeCounts) -> VolumeCounts {
        VolumeCounts {
            wanted: self.wanted + other.wanted,
            resident: self.resident + other.resident,
            pending: self.pending + other.pending,
            failed: self.failed + other.failed,
            finest: self.finest.into_iter().chain(other.finest).min(),
        }
    }
}

struct Kept {
    inputs: KeptInputs,
    /// The cache's counters once the frame's bricks were asked for, before any was read.
    cache: CacheStats,
    frame: BrickFrame,
    counts: VolumeCounts,
}

/// The last frame drawn of each bricked dataset.
#[derive(Default)]
pub struct LastFrames(HashMap<Entity, Kept>);

impl LastFrames {
    /// The frame kept for `dataset` if `inputs` are those it was drawn from and the cache
    /// is as it was then, with nothing on its way (a load that lands changes its
    /// counters: `loaded`, `evicted`, `failed`).
    pub fn unchanged(&self, dataset: Entity, inputs: &Inputs, cache: &CacheStats) -> Option<(BrickFrame, VolumeCounts)> {
        let kept = self.0.get(&dataset)?;
        (kept.cache.pending == 0 && kept.cache == *cache && kept.inputs.are(inputs)).then(|| (kept.frame.clone(), kept.counts))
    }

    /// Keeps the frame just drawn of `dataset`; `cache`: the counters read after its
    /// bricks were asked for and before the resident ones were read.
    pub fn keep(&mut self, dataset: Entity, inputs: Inputs, cache: CacheStats, frame: BrickFrame, counts: VolumeCounts) {
        self.0.insert(dataset, Kept { inputs: KeptInputs::of(inputs), cache, frame, counts });
    }

    /// Forgets the datasets not among `present`.
    pub fn retain(&mut self, present: &[Entity]) {
        self.0.retain(|e, _| present.contains(e));
    }
}

#[cfg(test)]
mod tests {
    use glam::{UVec3, Vec3};

    use super::*;
    use crate::volume::source::brick::BrickLayout;
    use crate::volume::{Grid, Source, ValueMap, Voxels};

    fn volume() -> Arc<Volume> {
        let grid = Grid::new(UVec3::splat(4), Vec3::ONE);
        Arc::new(Volume::new("v", grid, Voxels::U8(vec![0; 64]), ValueMap::IDENTITY, Source::default()).expect("volume"))
    }

    fn frame() -> BrickFrame {
        BrickFrame {
            table_dims: vec![UVec3::splat(4)],
            layout: BrickLayout::new(8, 1),
            coarse: 0,
            bits: 8,
            drawn: Arc::new(Vec::new()),
            empty: Arc::new(Vec::new()),
            complete: true,
            gradient_norms: vec![1.0],
        }
    }

    #[test]
    fn a_frame_is_kept_only_while_its_inputs_and_its_cache_are_as_they_were() {
        let (v, w) = (volume(), volume());
        let inputs = |cap: usize| Inputs { volume: &v, frames: &[], seen: Vec::new(), looks: Vec::new(), cap };
        let cache = CacheStats { resident: 3, loaded: 3, ..Default::default() };
        let kept = frame();
        let counts = VolumeCounts { wanted: 3, resident: 3, ..Default::default() };
        let mut last = LastFrames::default();
        let e = Entity::from_raw_u32(7).expect("an entity");
        assert!(last.unchanged(e, &inputs(10), &cache).is_none(), "nothing kept yet");
        last.keep(e, inputs(10), cache, kept.clone(), counts);
        let (same, c) = last.unchanged(e, &inputs(10), &cache).expect("kept");
        assert!(Arc::ptr_eq(&same.drawn, &kept.drawn) && c == counts);
        // Another budget, another volume, a brick landed or evicted: drawn anew.
        assert!(last.unchanged(e, &inputs(11), &cache).is_none());
        let other = Inputs { volume: &w, ..inputs(10) };
        assert!(last.unchanged(e, &other, &cache).is_none(), "the same inputs of another volume");
        assert!(last.unchanged(e, &inputs(10), &CacheStats { loaded: 4, ..cache }).is_none());
        assert!(last.unchanged(e, &inputs(10), &CacheStats { evicted: 1, ..cache }).is_none());
        // Drawn while bricks were on their way: drawn again the next frame (they land
        // after the counters were read).
        last.keep(e, inputs(10), CacheStats { pending: 2, ..cache }, kept, counts);
        assert!(last.unchanged(e, &inputs(10), &CacheStats { pending: 2, ..cache }).is_none());
        last.retain(&[]);
        assert!(last.0.is_empty());
    }
}
