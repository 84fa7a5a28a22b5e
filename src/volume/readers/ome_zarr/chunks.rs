//! Decoded chunks kept for reuse, least recently used first out, within a byte budget.
//!
//! A streamed brick is read with an apron (`BrickLayout`: 32³ voxels and 2 on each
//! side), so its box touches up to eight chunks of 64³, and each of those chunks is
//! touched by the bricks around it: read a box at a time, every chunk was fetched and
//! decompressed once for each brick that touches it, 8 times each for an inner chunk
//! and, for the small parts the aprons take, at 64³ voxels decoded for a few thousand
//! used. Kept decoded (as codes, with what was wrong with them), a chunk is fetched
//! and decoded once while its neighbours' bricks come in. A chunk that could not be
//! read is not kept, so a later read tries again (an HTTP error may pass). Two loader
//! threads that miss the same chunk at once both decode it (the second copy replaces
//! the first): rare with the loader's few threads, and no thread waits for another.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, MutexGuard};

use glam::UVec3;

use crate::volume::source::Fault;
use crate::volume::source::memory::copy_overlap;

/// A chunk: its level and its index along x, y, z.
pub type ChunkId = (usize, [u64; 3]);

/// A box of a level as codes (x fastest) and what was wrong with its chunk.
pub struct Decoded {
    pub lo: UVec3,
    pub size: UVec3,
    pub codes: Vec<u16>,
    pub faults: Vec<Fault>,
}

impl Decoded {
    /// Bytes it holds.
    fn bytes(&self) -> u64 {
        (self.codes.len() * std::mem::size_of::<u16>()) as u64
    }

    /// Copies the voxels it shares with the box `lo .. lo + size` into `out` (that box's
    /// codes, x fastest).
    pub fn copy_into(&self, lo: UVec3, size: UVec3, out: &mut [u16]) {
        copy_overlap((&self.codes, self.lo, self.size), (out, lo, size));
    }
}

/// The kept chunks.
#[derive(Default)]
pub struct ChunkCache {
    inner: Mutex<Kept>,
}

#[derive(Default)]
struct Kept {
    budget: u64,
    bytes: u64,
    /// Uses so far: a chunk's last use orders the evictions.
    clock: u64,
    chunks: HashMap<ChunkId, (Arc<Decoded>, u64)>,
}

impl ChunkCache {
    fn kept(&self) -> MutexGuard<'_, Kept> {
        // (A reader that panicked left the map whole: every change to it is one call.)
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Keeps up to `bytes` of decoded chunks from now on (0: none, the default).
    pub fn set_budget(&self, bytes: u64) {
        let mut kept = self.kept();
        kept.budget = bytes;
        kept.evict_to(bytes);
    }

    /// Whether chunks are kept at all.
    pub fn keeps(&self) -> bool {
        self.kept().budget > 0
    }

    /// The chunk `id` if it is kept.
    pub fn get(&self, id: ChunkId) -> Option<Arc<Decoded>> {
        let mut kept = self.kept();
        kept.clock += 1;
        let now = kept.clock;
        let (chunk, used) = kept.chunks.get_mut(&id)?;
        *used = now;
        Some(chunk.clone())
    }

    /// Keeps `chunk` as `id`, evicting the least recently used chunks to make room (a
    /// chunk larger than the whole budget is not kept).
    pub fn insert(&self, id: ChunkId, chunk: Arc<Decoded>) {
        let mut kept = self.kept();
        let size = chunk.bytes();
        if size > kept.budget {
            return;
        }
        if let Some((old, _)) = kept.chunks.remove(&id) {
            kept.bytes -= old.bytes();
        }
        let budget = kept.budget;
        kept.evict_to(budget - size);
        kept.clock += 1;
        let now = kept.clock;
        kept.bytes += size;
        kept.chunks.insert(id, (chunk, now));
    }

    /// Bytes kept now.
    #[cfg(test)]
    fn bytes(&self) -> u64 {
        self.kept().bytes
    }
}

impl Kept {
    /// Evicts the least recently used chunks until at most `bytes` are kept.
    fn evict_to(&mut self, bytes: u64) {
        while self.bytes > bytes {
            let Some(oldest) = self.chunks.iter().min_by_key(|(_, (_, used))| *used).map(|(id, _)| *id) else { break };
            if let Some((chunk, _)) = self.chunks.remove(&oldest) {
                self.bytes -= chunk.bytes();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chunk(lo: u32, edge: u32, value: u16) -> Arc<Decoded> {
        let size = UVec3::splat(edge);
        Arc::new(Decoded { lo: UVec3::splat(lo), size, codes: vec![value; (edge * edge * edge) as usize], faults: Vec::new() })
    }

    #[test]
    fn the_least_recently_used_chunk_goes_first_and_the_budget_holds() {
        let cache = ChunkCache::default();
        assert!(!cache.keeps());
        cache.insert((0, [0, 0, 0]), chunk(0, 4, 1));
        assert!(cache.get((0, [0, 0, 0])).is_none(), "kept without a budget");
        // Room for two chunks of 4³ codes (128 bytes each).
        cache.set_budget(300);
        cache.insert((0, [0, 0, 0]), chunk(0, 4, 1));
        cache.insert((0, [1, 0, 0]), chunk(4, 4, 2));
        // The first is used again: the second is now the least recently used.
        assert!(cache.get((0, [0, 0, 0])).is_some());
        cache.insert((1, [0, 0, 0]), chunk(0, 4, 3));
        assert!(cache.get((0, [1, 0, 0])).is_none());
        assert!(cache.get((0, [0, 0, 0])).is_some() && cache.get((1, [0, 0, 0])).is_some());
        assert_eq!(cache.bytes(), 256);
        // Too large for the whole budget: not kept, nothing evicted for it.
        cache.insert((0, [2, 0, 0]), chunk(8, 8, 4));
        assert!(cache.get((0, [2, 0, 0])).is_none());
        assert_eq!(cache.bytes(), 256);
        // A smaller budget evicts down to it.
        cache.set_budget(130);
        assert_eq!(cache.bytes(), 128);
        assert!(cache.get((1, [0, 0, 0])).is_some(), "the most recently used stays");
    }

    #[test]
    fn a_chunk_copies_the_part_a_box_shares_with_it() {
        // A 2×2×2 chunk at (1,1,1), codes 0..8 (x fastest), into a 3³ box at the origin.
        let d = Decoded { lo: UVec3::ONE, size: UVec3::splat(2), codes: (0..8).collect(), faults: Vec::new() };
        let mut out = vec![99u16; 27];
        d.copy_into(UVec3::ZERO, UVec3::splat(3), &mut out);
        let at = |x: usize, y: usize, z: usize| out[(z * 3 + y) * 3 + x];
        assert_eq!((at(1, 1, 1), at(2, 1, 1), at(1, 2, 1), at(2, 2, 2)), (0, 1, 2, 7));
        assert_eq!((at(0, 0, 0), at(0, 1, 1), at(2, 2, 0)), (99, 99, 99));
        // A box it does not meet is left as it was.
        let mut other = vec![5u16; 8];
        d.copy_into(UVec3::splat(3), UVec3::splat(2), &mut other);
        assert!(other.iter().all(|&c| c == 5));
    }
}
