//! The decoded-brick cache between a [`VoxelSource`] and the GPU: bricks are requested
//! by key, read and decoded on background threads, kept within a byte budget with
//! least-recently-used eviction, and looked up without ever waiting.
//!
//! A request for a brick that is neither resident nor on its way starts a load on the
//! cache's spawner (rayon's pool by default; the app hands in Bevy's task pool). The
//! renderer polls [`BrickCache::finished`] each frame for what arrived and, for a brick
//! not yet there, draws the finest coarser brick that is ([`BrickCache::best_available`]:
//! brick `b` of level `l` lies inside brick `b / 2` of level `l + 1`, the brick size
//! being the same on every level). The coarsest level is pinned: once loaded it is never
//! evicted, so there is always something to draw.

use std::collections::{HashMap, HashSet};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, OnceLock};

use glam::UVec3;

use super::brick::{BrickLayout, code_range};
use super::{Block, Fault, SourceError, VoxelSource};
use crate::volume::Voxels;

/// A brick of one level.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BrickKey {
    pub level: u8,
    pub brick: UVec3Key,
}

/// Brick coordinates as a hashable triple.
pub type UVec3Key = (u32, u32, u32);

impl BrickKey {
    pub fn new(level: usize, brick: UVec3) -> Self {
        Self { level: level as u8, brick: (brick.x, brick.y, brick.z) }
    }

    pub fn coords(&self) -> UVec3 {
        UVec3::new(self.brick.0, self.brick.1, self.brick.2)
    }

    /// The brick of the next coarser level that holds this one.
    pub fn parent(&self) -> BrickKey {
        BrickKey::new(self.level as usize + 1, self.coords() / 2)
    }
}

/// A decoded brick with its apron.
#[derive(Debug)]
pub struct BrickData {
    pub voxels: Voxels,
    /// Smallest and largest code (apron included), for empty-space skipping.
    pub range: (u16, u16),
    /// The same per 8³ sub-block ([`BrickLayout::sub_ranges`]).
    pub sub_ranges: Vec<(u16, u16)>,
    /// Chunks of it that could not be read.
    pub faults: Vec<Fault>,
    layout: BrickLayout,
    gradient_max: OnceLock<f32>,
}

impl BrickData {
    /// A brick read with `layout`, with its code ranges.
    pub fn new(layout: BrickLayout, block: Block) -> Self {
        BrickData {
            range: code_range(&block.voxels),
            sub_ranges: layout.sub_ranges(&block.voxels),
            voxels: block.voxels,
            faults: block.faults,
            layout,
            gradient_max: OnceLock::new(),
        }
    }

    /// Largest gradient magnitude over its owned voxels (normalised units per voxel of
    /// its level; the apron holds their neighbours): the context-preserving and
    /// gradient-modulated looks normalise by the largest of a level's
    /// (`streaming::bricked::BrickedDataset::gradient_max`). Computed when first asked
    /// (central differences over every voxel: for every load it made the first frame of
    /// 8192³ seven times slower, ×1.6 of its 1 s goal, though only those looks need it).
    pub fn gradient_max(&self) -> f32 {
        *self.gradient_max.get_or_init(|| {
            let l = self.layout;
            let (n, a) = (UVec3::splat(l.stored()), UVec3::splat(l.apron));
            crate::volume::sample::max_gradient_magnitude_in(&self.voxels, n, a, a + l.size)
        })
    }

    pub fn bytes(&self) -> u64 {
        self.voxels.byte_len() as u64
    }
}

/// How loads run: a function that runs a job on some thread.
pub type Spawner = Arc<dyn Fn(Box<dyn FnOnce() + Send>) + Send + Sync>;

/// What the cache holds now.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CacheStats {
    pub resident: usize,
    pub pending: usize,
    pub bytes: u64,
    pub budget: u64,
    /// Bricks loaded since the cache was made, and bricks evicted.
    pub loaded: u64,
    pub evicted: u64,
    /// Loads that failed as a whole.
    pub failed: u64,
}

struct Entry {
    data: Arc<BrickData>,
    last_used: u64,
}

#[derive(Default)]
struct State {
    entries: HashMap<BrickKey, Entry>,
    pending: HashSet<BrickKey>,
    /// Bricks whose load failed: not asked for again (their coarser level is drawn).
    refused: HashSet<BrickKey>,
    finished: Vec<BrickKey>,
    errors: Vec<(BrickKey, SourceError)>,
    /// Bricks that loaded with chunks drawn at the fill value, and what failed.
    faulted: Vec<(BrickKey, String)>,
    clock: u64,
    bytes: u64,
    loaded: u64,
    evicted: u64,
    failed: u64,
}

/// Bricks of one source, decoded, within a byte budget.
pub struct BrickCache {
    source: Arc<dyn VoxelSource>,
    layout: BrickLayout,
    budget: u64,
    spawner: Spawner,
    state: Arc<Mutex<State>>,
    /// Whether loads compute their bricks' largest gradient ([`BrickData::gradient_max`]).
    gradients: Arc<AtomicBool>,
}

impl BrickCache {
    /// A cache of `budget` bytes over `source`, loading on rayon's pool.
    pub fn new(source: Arc<dyn VoxelSource>, layout: BrickLayout, budget: u64) -> Self {
        let spawner: Spawner = Arc::new(rayon::spawn::<Box<dyn FnOnce() + Send>>);
        Self::with_spawner(source, layout, budget, spawner)
    }

    pub fn with_spawner(source: Arc<dyn VoxelSource>, layout: BrickLayout, budget: u64, spawner: Spawner) -> Self {
        Self { source, layout, budget, spawner, state: Arc::new(Mutex::new(State::default())), gradients: Arc::new(AtomicBool::new(false)) }
    }

    /// Whether loads from now on compute their bricks' largest gradient on the loading
    /// thread (when a look of the volume needs it), rather than the frame that first
    /// asks for it.
    pub fn want_gradients(&self, on: bool) {
        self.gradients.store(on, Ordering::Relaxed);
    }

    pub fn source(&self) -> &Arc<dyn VoxelSource> {
        &self.source
    }

    pub fn layout(&self) -> BrickLayout {
        self.layout
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        lock(&self.state)
    }

    /// The brick if it is resident (and marks it used).
    pub fn get(&self, key: BrickKey) -> Option<Arc<BrickData>> {
        let mut s = self.lock();
        s.clock += 1;
        let now = s.clock;
        s.entries.get_mut(&key).map(|e| {
            e.last_used = now;
            e.data.clone()
        })
    }

    /// The brick, or the finest coarser one holding it that is resident.
    pub fn best_available(&self, key: BrickKey) -> Option<(BrickKey, Arc<BrickData>)> {
        let levels = self.source.info().levels.len();
        let mut k = key;
        loop {
            if let Some(d) = self.get(k) {
                return Some((k, d));
            }
            if k.level as usize + 1 >= levels {
                return None;
            }
            k = k.parent();
        }
    }

    /// Starts loading the bricks that are neither resident nor pending, in the order
    /// given (most wanted first). Keys outside the pyramid are ignored.
    pub fn request(&self, keys: &[BrickKey]) {
        let info = self.source.info();
        let mut start = Vec::new();
        {
            let mut s = self.lock();
            for &k in keys {
                let Some(level) = info.levels.get(k.level as usize) else { continue };
                if self.layout.bricks(level.grid.dims).cmple(k.coords()).any() {
                    continue;
                }
                if !s.entries.contains_key(&k) && !s.refused.contains(&k) && s.pending.insert(k) {
                    start.push(k);
                }
            }
        }
        for k in start {
            let (source, layout, state, budget) = (self.source.clone(), self.layout, self.state.clone(), self.budget);
            let gradients = self.gradients.clone();
            let pinned = info.levels.len() - 1;
            (self.spawner)(Box::new(move || {
                // A panicking read must neither abort the pool nor leave the key pending.
                let read = crate::volume::caught::caught(|| layout.read(source.as_ref(), k.level as usize, k.coords()));
                let result = read.unwrap_or_else(|_| {
                    Err(SourceError::new(source.info().location(), format!("reading brick {:?} of level {} panicked", k.brick, k.level)))
                });
                // Decoded before the lock is taken: BrickData::new runs rayon work, and
                // a rayon worker waiting on it may steal another load of this cache,
                // which would then wait on the lock this job holds (a deadlock that hung
                // the bricked renders).
                let result = result.map(|block| {
                    let faults =
                        block.faults.iter().any(|f| f.kind != super::FaultKind::Absent).then(|| {
                            format!("{}: {}", source.info().location(), super::level::summarize(&block.faults).unwrap_or_default())
                        });
                    let data = BrickData::new(layout, block);
                    if gradients.load(Ordering::Relaxed) {
                        data.gradient_max();
                    }
                    (faults, Arc::new(data))
                });
                let mut s = lock(&state);
                s.pending.remove(&k);
                match result {
                    Ok((faults, data)) => {
                        // (Chunks absent from the store are the fill value by the Zarr
                        // specification: a sparse pyramid is full of them.)
                        if let Some(faults) = faults {
                            s.faulted.push((k, faults));
                        }
                        insert(&mut s, k, data, budget, pinned);
                        s.finished.push(k);
                    }
                    Err(e) => {
                        s.failed += 1;
                        s.refused.insert(k);
                        s.errors.push((k, e));
                    }
                }
            }));
        }
    }

    /// Bricks that arrived since the last call.
    pub fn finished(&self) -> Vec<BrickKey> {
        std::mem::take(&mut self.lock().finished)
    }

    /// Loads that failed since the last call.
    pub fn errors(&self) -> Vec<(BrickKey, SourceError)> {
        std::mem::take(&mut self.lock().errors)
    }

    /// Bricks loaded since the last call with chunks that could not be read (drawn at
    /// the fill value there), with the message naming the source and the chunks.
    pub fn faulted(&self) -> Vec<(BrickKey, String)> {
        std::mem::take(&mut self.lock().faulted)
    }

    pub fn stats(&self) -> CacheStats {
        let s = self.lock();
        CacheStats {
            resident: s.entries.len(),
            pending: s.pending.len(),
            bytes: s.bytes,
            budget: self.budget,
            loaded: s.loaded,
            evicted: s.evicted,
            failed: s.failed,
        }
    }

    /// Whether nothing is on its way.
    pub fn idle(&self) -> bool {
        self.lock().pending.is_empty()
    }
}

fn lock(state: &Mutex<State>) -> MutexGuard<'_, State> {
    // A load that panicked leaves the state as consistent as a finished one.
    state.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Adds a brick, then evicts the least recently used unpinned bricks past the budget.
fn insert(s: &mut State, key: BrickKey, data: Arc<BrickData>, budget: u64, pinned: usize) {
    s.clock += 1;
    s.bytes += data.bytes();
    s.loaded += 1;
    let now = s.clock;
    if let Some(old) = s.entries.insert(key, Entry { data, last_used: now }) {
        s.bytes -= old.data.bytes();
    }
    while s.bytes > budget {
        let victim =
            s.entries.iter().filter(|(k, _)| k.level as usize != pinned && **k != key).min_by_key(|(_, e)| e.last_used).map(|(k, _)| *k);
        let Some(v) = victim else { break };
        if let Some(e) = s.entries.remove(&v) {
            s.bytes -= e.data.bytes();
            s.evicted += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use std::time::{Duration, Instant};

    use glam::Vec3;

    use super::*;
    use crate::volume::source::procedural::ProceduralSource;
    use crate::volume::source::{FaultKind, SourceInfo};

    fn wait_idle(c: &BrickCache) {
        let start = Instant::now();
        while !c.idle() {
            assert!(start.elapsed() < Duration::from_secs(20), "loads did not finish");
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    fn source() -> Arc<dyn VoxelSource> {
        Arc::new(ProceduralSource::new(UVec3::splat(256), Vec3::splat(0.01)).expect("source"))
    }

    #[test]
    fn many_loads_on_the_rayon_pool_all_finish() {
        // Every brick of a 256³ source at once, on the default (rayon) spawner: each
        // load decodes with rayon work of its own (the largest gradient's), so a load
        // that held the cache's lock while it waited for that work deadlocked here (a
        // worker stole another load). (It took a few rounds to hang on two cores;
        // without the fix the test hangs, as the lock is held, rather than failing.)
        let layout = BrickLayout::new(32, 1);
        let keys: Vec<BrickKey> = (0..8u32 * 8 * 8).map(|i| BrickKey::new(0, UVec3::new(i % 8, i / 8 % 8, i / 64))).collect();
        for _ in 0..20 {
            let c = BrickCache::new(source(), layout, 1 << 30);
            c.want_gradients(true);
            c.request(&keys);
            wait_idle(&c);
            assert_eq!(c.stats().resident, keys.len());
        }
    }

    #[test]
    fn bricks_load_in_the_background_and_match_the_source() {
        let layout = BrickLayout::new(16, 1);
        let c = BrickCache::new(source(), layout, 64 << 20);
        let k = BrickKey::new(0, UVec3::new(3, 4, 5));
        assert!(c.get(k).is_none());
        c.request(&[k, k, BrickKey::new(0, UVec3::new(99, 0, 0)), BrickKey::new(9, UVec3::ZERO)]);
        wait_idle(&c);
        assert_eq!(c.finished(), vec![k], "one load per key; keys outside the pyramid are ignored");
        let d = c.get(k).expect("resident");
        let direct = layout.read(c.source().as_ref(), 0, k.coords()).expect("read");
        assert_eq!(d.voxels, direct.voxels);
        assert_eq!(d.range, code_range(&direct.voxels));
        assert_eq!(c.stats().resident, 1);
        assert_eq!(c.stats().bytes, 18 * 18 * 18 * 2);
    }

    /// A source whose level-0 reads come back with one unreadable and one absent chunk.
    struct Faulty(Arc<dyn VoxelSource>, FaultKind);

    impl VoxelSource for Faulty {
        fn info(&self) -> &SourceInfo {
            self.0.info()
        }

        fn read_box(&self, level: usize, lo: UVec3, size: UVec3) -> Result<Block, SourceError> {
            let mut block = self.0.read_box(level, lo, size)?;
            if level == 0 {
                block.faults.push(Fault { chunk: "0/c/1/2/3".into(), kind: self.1, problem: "gzip: invalid header".into() });
                block.faults.push(Fault { chunk: "0/c/1/2/4".into(), kind: FaultKind::Absent, problem: "absent".into() });
            }
            Ok(block)
        }
    }

    #[test]
    fn a_brick_with_unreadable_chunks_is_drawn_and_named() {
        let c = BrickCache::new(Arc::new(Faulty(source(), FaultKind::Unreadable)), BrickLayout::new(16, 1), 64 << 20);
        let (fine, coarse) = (BrickKey::new(0, UVec3::new(1, 2, 3)), BrickKey::new(1, UVec3::ZERO));
        c.request(&[fine, coarse]);
        wait_idle(&c);
        assert!(c.get(fine).is_some(), "drawn from what is there");
        let faulted = c.faulted();
        assert_eq!(faulted.len(), 1, "{faulted:?}");
        let (k, message) = &faulted[0];
        assert_eq!(*k, fine);
        assert!(message.contains("procedural") && message.contains("0/c/1/2/3") && message.contains("invalid header"), "{message}");
        assert!(c.errors().is_empty() && c.stats().failed == 0, "a brick drawn is not a failed load");
        // Absent chunks alone (a sparse pyramid's empty space) are no fault.
        let sparse = BrickCache::new(Arc::new(Faulty(source(), FaultKind::Absent)), BrickLayout::new(16, 1), 64 << 20);
        sparse.request(&[fine]);
        wait_idle(&sparse);
        assert!(sparse.get(fine).is_some() && sparse.faulted().is_empty());
    }

    #[test]
    fn a_missing_brick_falls_back_to_the_finest_coarser_one() {
        let c = BrickCache::new(source(), BrickLayout::new(16, 1), 64 << 20);
        // 256³ at 16³ bricks: levels 256, 128, 64 (the pinned coarsest).
        let fine = BrickKey::new(0, UVec3::new(7, 2, 9));
        assert_eq!(fine.parent(), BrickKey::new(1, UVec3::new(3, 1, 4)));
        assert!(c.best_available(fine).is_none());
        c.request(&[BrickKey::new(2, UVec3::new(1, 0, 2))]);
        wait_idle(&c);
        assert_eq!(c.best_available(fine).map(|(k, _)| k), Some(BrickKey::new(2, UVec3::new(1, 0, 2))));
        c.request(&[fine.parent()]);
        wait_idle(&c);
        assert_eq!(c.best_available(fine).map(|(k, _)| k), Some(fine.parent()));
    }

    #[test]
    fn the_budget_evicts_the_least_recently_used_but_never_the_coarsest_level() {
        let layout = BrickLayout::new(16, 1);
        let brick = 18 * 18 * 18 * 2;
        let c = BrickCache::new(source(), layout, 3 * brick);
        let coarse = BrickKey::new(2, UVec3::ZERO);
        let a = BrickKey::new(0, UVec3::new(0, 0, 0));
        let b = BrickKey::new(0, UVec3::new(1, 0, 0));
        c.request(&[coarse]);
        wait_idle(&c);
        c.request(&[a]);
        wait_idle(&c);
        c.request(&[b]);
        wait_idle(&c);
        // Use a, so b is the least recent of the evictable ones.
        assert!(c.get(a).is_some());
        let d = BrickKey::new(0, UVec3::new(2, 0, 0));
        c.request(&[d]);
        wait_idle(&c);
        let s = c.stats();
        assert_eq!((s.resident, s.evicted, s.bytes), (3, 1, 3 * brick));
        assert!(c.get(b).is_none(), "the least recently used brick went");
        assert!(c.get(coarse).is_some() && c.get(a).is_some() && c.get(d).is_some());
        // With a budget below one brick the pinned level still stays.
        let tiny = BrickCache::new(source(), layout, 1);
        tiny.request(&[coarse, a]);
        wait_idle(&tiny);
        assert!(tiny.get(coarse).is_some());
    }

    #[test]
    fn loads_run_on_the_spawner_given() {
        let jobs: Jobs = Arc::default();
        let queue = jobs.clone();
        let spawner: Spawner = Arc::new(move |job| lock_jobs(&queue).push(job));
        let c = BrickCache::with_spawner(source(), BrickLayout::new(16, 1), 1 << 20, spawner);
        let k = BrickKey::new(1, UVec3::ONE);
        c.request(&[k]);
        assert_eq!(c.stats().pending, 1);
        assert!(c.get(k).is_none(), "nothing waits for a load");
        for job in lock_jobs(&jobs).drain(..) {
            job();
        }
        assert!(c.get(k).is_some() && c.idle());
    }

    type Jobs = Arc<Mutex<Vec<Box<dyn FnOnce() + Send>>>>;

    fn lock_jobs<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
        m.lock().unwrap_or_else(|p| p.into_inner())
    }
}
