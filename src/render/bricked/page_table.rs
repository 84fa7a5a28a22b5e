//! The page table of a bricked dataset: a directory over one level and blocks below
//! it, each entry already resolved to the brick a sample there reads.
//!
//! Level `C` of the pyramid (the coarse level) is drawn from a whole volume in the
//! volume atlas; levels `0 … C−1` are drawn from bricks in the brick atlas. Bricks nest
//! (brick `b` of level `k` holds bricks `2b + o` of level `k − 1`, since
//! `q_k = (q + ½)/2ᵏ − ½`, [`crate::volume::pyramid::level_index`]), so the level-0
//! brick `b₀` holding a sample names its ancestors: `b₀ >> k` at level `k`.
//!
//! The table has one word per brick of the directory level `G = min(T, 3)` (`T = C − 1`
//! the finest streamed level's top), and a block under every directory brick with a
//! drawn descendant finer than `G`: for each level `l = 0 … G` one word per level-`l`
//! brick under it, `(2^(G−l))³` words, level 0 first (`8^G + … + 8 + 1` words,
//! [`block_offset`]). A level-`l` word is the answer for every sample in its brick of a
//! ray that steps at level `l` or coarser: the finest drawn brick **of level `l` or
//! coarser** holding it (its kind, level `k` and atlas slot), else the coarse volume;
//! with it the level `m ≥ l` over whose brick the answer holds (the box the ray caster
//! may cross at once when the answer is empty). A ray reads the words of its own level
//! (capped at `G`; a directory word without a block holds nothing finer than `G`), so
//! it never samples data finer than its step: the context beside a magnifier reads the
//! context's level, not the native bricks drawn for the lens, which it would alias and
//! pay for (four times the samples outside the bench's 4× lens: their small sub-blocks
//! hold the finest lattice's crests). A look-up is two reads and no loop
//! (`shaders/focal/bricked.wgsl`, checked against [`PageTree::locate`], itself checked
//! against sampling whole levels): on llvmpipe every lane runs every branch and one pass
//! of every loop, so the tree this replaced cost three times the volume's own fetches
//! even when its per-ray cache held.
//!
//! Words: bits 30–31 the kind (missing, empty, a brick in a slot, or in the directory
//! a block), 26–29 `k`, 22–25 `m`, then for a brick its slot's coordinates in the atlas
//! grid (7 bits each), for an empty brick its lowest code (16 bits), for a block its
//! word offset from the table's start (30 bits). Inside a brick the texel is
//! `origin + A + (q_k − b·B) + ½` (A the apron).
//!
//! Which bricks are drawn is decided elsewhere (the wanted bricks of the view and their
//! resident ancestors, [`crate::streaming`]): the table only records it, so the picture
//! does not depend on what earlier views left resident.

use std::collections::{HashMap, HashSet};

use glam::{UVec3, Vec3};

use crate::volume::source::brick::BrickLayout;
use crate::volume::source::cache::BrickKey;

/// What the table says of one brick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Page {
    /// Not drawn: a coarser level answers.
    Missing,
    /// Drawn, and nothing in it is visible: skipped (its lowest code stands for its
    /// samples).
    Empty(u16),
    /// In this atlas slot.
    Slot(u32),
}

/// Levels between the directory and level 0 at most: blocks of up to 8³ words.
pub const BLOCK_LEVELS: usize = 3;

/// Slots per axis of the atlas grid an entry can name.
pub const MAX_SLOTS_PER_AXIS: u32 = (1 << SLOT_BITS) - 1;

const SLOT_BITS: u32 = 7;
const KIND_SHIFT: u32 = 30;
const LEVEL_SHIFT: u32 = 26;
const HOLDS_SHIFT: u32 = 22;
const KIND_EMPTY: u32 = 1;
const KIND_BRICK: u32 = 2;
const KIND_BLOCK: u32 = 3;
const OFFSET_MASK: u32 = (1 << KIND_SHIFT) - 1;

/// The directory level of a table over streamed levels `0 … top`.
pub fn directory_level(top: usize) -> usize {
    top.min(BLOCK_LEVELS)
}

/// Words of a block before its level-`l` words, under a directory at level `g`:
/// `8^g + 8^(g−1) + … + 8^(g−l+1) = (8^(g+1) − 8^(g−l+1)) / 7` (the shader computes the
/// same closed form).
pub fn block_offset(g: usize, l: usize) -> usize {
    ((1usize << (3 * (g + 1))) - (1usize << (3 * (g - l.min(g) + 1)))) / 7
}

/// Words of a block under a directory at level `g`: every level's, `0 … g`.
pub fn block_len(g: usize) -> usize {
    block_offset(g, g) + 1
}

/// The word of `answer` (a drawn brick's page and level; `None`: the coarse volume),
/// holding over the level-`holds` brick; `grid` the atlas's slots per axis.
fn entry(answer: Option<(Page, usize)>, holds: usize, grid: UVec3) -> u32 {
    let (kind, level, low) = match answer {
        None | Some((Page::Missing, _)) => (0, 0, 0),
        Some((Page::Empty(code), k)) => (KIND_EMPTY, k, code as u32),
        Some((Page::Slot(s), k)) => {
            let c = UVec3::new(s % grid.x, s / grid.x % grid.y, s / (grid.x * grid.y));
            (KIND_BRICK, k, c.x | c.y << SLOT_BITS | c.z << (2 * SLOT_BITS))
        }
    };
    kind << KIND_SHIFT | (level as u32) << LEVEL_SHIFT | (holds as u32) << HOLDS_SHIFT | low
}

/// The table of one dataset.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PageTree {
    pub layout: BrickLayout,
    /// Voxel dims of levels `0 … T`.
    pub dims: Vec<UVec3>,
    pub words: Vec<u32>,
}

/// Where a sample reads: the coarse volume, an empty brick, or a brick's texel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Located {
    Coarse,
    Empty { level: usize },
    Texel { level: usize, texel: Vec3 },
}

/// Building one table: the drawn bricks, those with a drawn descendant, the words.
struct Builder<'a> {
    layout: BrickLayout,
    dims: &'a [UVec3],
    drawn: &'a HashMap<BrickKey, (Page, u64)>,
    inner: HashSet<BrickKey>,
    grid: UVec3,
    g: usize,
    words: Vec<u32>,
}

impl Builder<'_> {
    fn answer(&self, key: BrickKey, inherited: Option<(Page, usize)>) -> Option<(Page, usize)> {
        match self.drawn.get(&key) {
            Some((Page::Missing, _)) | None => inherited,
            Some((page, _)) => Some((*page, key.level as usize)),
        }
    }

    /// The children of `key` inside their level.
    fn children(&self, key: BrickKey) -> impl Iterator<Item = BrickKey> + use<> {
        let level = key.level as usize - 1;
        let limit = self.layout.bricks(self.dims[level]);
        let base = key.coords() * 2;
        (0..8u32)
            .map(move |o| base + UVec3::new(o & 1, o >> 1 & 1, o >> 2))
            .filter(move |c| c.cmplt(limit).all())
            .map(move |c| BrickKey::new(level, c))
    }

    /// Fills the words of directory bricks under `key` (level ≥ G).
    fn directory(&mut self, key: BrickKey, inherited: Option<(Page, usize)>) {
        let level = key.level as usize;
        let answer = self.answer(key, inherited);
        let ng = self.layout.bricks(self.dims[self.g]);
        let index = |c: UVec3| ((c.z * ng.y + c.y) * ng.x + c.x) as usize;
        if level == self.g {
            let at = index(key.coords());
            if level > 0 && self.inner.contains(&key) {
                let block = self.words.len();
                self.words[at] = KIND_BLOCK << KIND_SHIFT | block as u32;
                self.words.resize(block + block_len(self.g), 0);
                self.block(block, key.coords() << level as u32, key, inherited);
            } else {
                self.words[at] = entry(answer, level, self.grid);
            }
        } else if !self.inner.contains(&key) {
            let word = entry(answer, level, self.grid);
            let span = 1u32 << (level - self.g);
            let lo = key.coords() * span;
            let hi = (lo + span).min(ng);
            for z in lo.z..hi.z {
                for y in lo.y..hi.y {
                    for x in lo.x..hi.x {
                        self.words[index(UVec3::new(x, y, z))] = word;
                    }
                }
            }
        } else {
            for c in self.children(key).collect::<Vec<_>>() {
                self.directory(c, answer);
            }
        }
    }

    /// Fills the block at word `block` (level-0 bricks from `origin`) under `key`: its
    /// own level's word, and below it its children's or, where nothing finer is drawn,
    /// its answer for every finer level.
    fn block(&mut self, block: usize, origin: UVec3, key: BrickKey, inherited: Option<(Page, usize)>) {
        let level = key.level as usize;
        let answer = self.answer(key, inherited);
        let word = entry(answer, level, self.grid);
        let leaf = level == 0 || !self.inner.contains(&key);
        for l in if leaf { 0..=level } else { level..=level } {
            let w = 1u32 << (self.g - l);
            let lo = (key.coords() << (level - l) as u32) - (origin >> l as u32);
            let hi = (lo + (1u32 << (level - l))).min(UVec3::splat(w));
            let at = block + block_offset(self.g, l);
            for z in lo.z..hi.z {
                for y in lo.y..hi.y {
                    for x in lo.x..hi.x {
                        self.words[at + ((z * w + y) * w + x) as usize] = word;
                    }
                }
            }
        }
        if !leaf {
            for c in self.children(key).collect::<Vec<_>>() {
                self.block(block, origin, c, answer);
            }
        }
    }
}

impl PageTree {
    /// The table over levels of `dims` (`0 … T`, the coarse level left out) drawing the
    /// bricks of `drawn` (each with its sub-block mask), the atlas having `grid` slots
    /// per axis.
    pub fn build(dims: &[UVec3], layout: BrickLayout, drawn: &HashMap<BrickKey, (Page, u64)>, grid: UVec3) -> PageTree {
        let Some(top) = dims.len().checked_sub(1) else { return PageTree { layout, dims: Vec::new(), words: Vec::new() } };
        // Every strict ancestor of a drawn brick: the bricks with drawn descendants.
        let mut inner: HashSet<BrickKey> = HashSet::new();
        for k in drawn.keys().filter(|k| (k.level as usize) <= top) {
            let mut a = *k;
            while (a.level as usize) < top {
                a = a.parent();
                if !inner.insert(a) {
                    break;
                }
            }
        }
        let g = directory_level(top);
        let ng = layout.bricks(dims[g]);
        let mut b = Builder { layout, dims, drawn, inner, grid, g, words: vec![0; (ng.x * ng.y * ng.z) as usize] };
        let tb = layout.bricks(dims[top]);
        for z in 0..tb.z {
            for y in 0..tb.y {
                for x in 0..tb.x {
                    b.directory(BrickKey::new(top, UVec3::new(x, y, z)), None);
                }
            }
        }
        PageTree { layout, dims: dims.to_vec(), words: b.words }
    }

    /// Where continuous level-0 index `q` reads for a ray stepping at level `cap` (the
    /// finest drawn brick of level `cap` or coarser; `cap` above the directory level
    /// reads as at the directory level), and the level-0 box `[lo, hi)` over which the
    /// answer holds.
    pub fn locate(&self, q: Vec3, cap: usize) -> (Located, Vec3, Vec3) {
        let Some(top) = self.dims.len().checked_sub(1) else { return (Located::Coarse, Vec3::MIN, Vec3::MAX) };
        let size = self.layout.size;
        let g = directory_level(top) as u32;
        // The level-0 brick (clamped like the sample): its ancestors are b₀ >> k.
        let d0 = self.dims[0];
        let q0 = q.clamp(Vec3::ZERO, d0.as_vec3() - 1.0);
        let b0 = ((q0 + 0.5) / size as f32).floor().as_uvec3().min(self.layout.bricks(d0) - 1);
        let ng = self.layout.bricks(self.dims[g as usize]);
        let bg = b0 >> g;
        let mut word = self.words[((bg.z * ng.y + bg.y) * ng.x + bg.x) as usize];
        if word >> KIND_SHIFT == KIND_BLOCK {
            let l = cap.min(g as usize) as u32;
            let w = 1u32 << (g - l);
            let local = (b0 >> l) - (bg << (g - l));
            let at = (word & OFFSET_MASK) as usize + block_offset(g as usize, l as usize);
            word = self.words[at + ((local.z * w + local.y) * w + local.x) as usize];
        }
        let k = (word >> LEVEL_SHIFT & 15) as usize;
        let m = word >> HOLDS_SHIFT & 15;
        let found = match word >> KIND_SHIFT {
            KIND_EMPTY => Located::Empty { level: k },
            KIND_BRICK => {
                let mask = (1u32 << SLOT_BITS) - 1;
                let slot = UVec3::new(word & mask, word >> SLOT_BITS & mask, word >> (2 * SLOT_BITS) & mask);
                let qk = ((q + 0.5) / (1u32 << k) as f32 - 0.5).clamp(Vec3::ZERO, self.dims[k].as_vec3() - 1.0);
                let inside = qk - ((b0 >> k as u32) * size).as_vec3();
                Located::Texel { level: k, texel: (slot * self.layout.stored()).as_vec3() + self.layout.apron as f32 + inside + 0.5 }
            }
            _ => Located::Coarse,
        };
        let (lo, hi) = node_box(b0 >> m, size << m, self.layout.bricks(self.dims[m as usize]));
        (found, lo, hi)
    }
}

/// The level-0 box of brick `b` spanning `span` level-0 voxels per axis, among `bricks`:
/// `[b·span − ½, (b + 1)·span − ½)`, open to infinity past the first and last bricks
/// (samples beyond the level clamp to its edge bricks).
pub fn node_box(b: UVec3, span: u32, bricks: UVec3) -> (Vec3, Vec3) {
    let lo = b.as_vec3() * span as f32 - 0.5;
    let hi = (b + 1).as_vec3() * span as f32 - 0.5;
    let first = b.cmpeq(UVec3::ZERO);
    let last = (b + 1).cmpge(bricks);
    (Vec3::select(first, Vec3::splat(f32::MIN), lo), Vec3::select(last, Vec3::splat(f32::MAX), hi))
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::volume::source::memory::MemorySource;
    use crate::volume::source::{SourceLevel, VoxelSource, level_count, level_grid};
    use crate::volume::{Grid, Source, ValueMap, Volume, Voxels};

    /// The finest drawn brick of level `from` or coarser holding level-0 voxel index
    /// `q`, by brute force.
    fn finest_drawn(drawn: &HashMap<BrickKey, (Page, u64)>, dims: &[UVec3], size: u32, q: Vec3, from: usize) -> Option<(usize, Page)> {
        (from..dims.len()).find_map(|k| {
            let qk = ((q + 0.5) / (1u32 << k) as f32 - 0.5).clamp(Vec3::ZERO, dims[k].as_vec3() - 1.0);
            let b = ((qk + 0.5) / size as f32).floor().as_uvec3().min((dims[k] + size - 1) / size - 1);
            drawn.get(&BrickKey::new(k, b)).map(|(p, _)| (k, *p))
        })
    }

    #[test]
    fn every_entry_is_the_finest_drawn_brick_and_holds_over_its_box() {
        // Five streamed levels (200³ … 13³ in 8³ bricks): the directory over level 3,
        // blocks of 8³ level-0 bricks; drawn bricks scattered over every level.
        let mut dims = vec![UVec3::new(200, 180, 150)];
        for _ in 0..4 {
            let d = *dims.last().expect("level");
            dims.push((d + 1) / 2);
        }
        let layout = BrickLayout::new(8, 1);
        let grid = UVec3::new(16, 16, 16);
        let mut seed = 12345u64;
        let mut next = move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 33) as u32
        };
        let mut drawn = HashMap::new();
        for i in 0..300u32 {
            let k = (next() % 5) as usize;
            let n = layout.bricks(dims[k]);
            let b = UVec3::new(next() % n.x, next() % n.y, next() % n.z);
            let page = if i % 3 == 0 { Page::Empty(i as u16) } else { Page::Slot(i) };
            drawn.insert(BrickKey::new(k, b), (page, 0));
        }
        let tree = PageTree::build(&dims, layout, &drawn, grid);
        let same = |a: Located, b: Option<(usize, Page)>| match (a, b) {
            (Located::Coarse, None) => true,
            (Located::Empty { level }, Some((k, Page::Empty(_)))) => level == k,
            (Located::Texel { level, texel }, Some((k, Page::Slot(s)))) => {
                let slot = UVec3::new(s % 16, s / 16 % 16, s / 256);
                let lo = (slot * layout.stored()).as_vec3();
                level == k && texel.cmpge(lo).all() && texel.cmplt(lo + layout.stored() as f32).all()
            }
            _ => false,
        };
        let d = dims[0].as_vec3();
        // Every cap: a ray stepping at level l reads the finest drawn brick of level l or
        // coarser (above the directory level 3, of level 3 or coarser).
        for _ in 0..3000 {
            let q = Vec3::new(next() as f32, next() as f32, next() as f32) / u32::MAX as f32 * 2.2 * d - 0.1 * d - 0.5;
            for cap in 0..=4 {
                let from = cap.min(3);
                let (found, lo, hi) = tree.locate(q, cap);
                let want = finest_drawn(&drawn, &dims, 8, q, from);
                assert!(same(found, want), "{q} at level {cap}: {found:?} against {want:?}");
                assert!(q.cmpge(lo).all() && q.cmplt(hi).all(), "{q} outside its box {lo} … {hi}");
                for t in [0.0f32, 0.3, 0.7, 0.999] {
                    let p = lo.max(Vec3::splat(-3.0)) + (hi.min(d + 3.0) - lo.max(Vec3::splat(-3.0))) * t;
                    assert!(same(found, finest_drawn(&drawn, &dims, 8, p, from)), "{p} in the box of {q} at level {cap}");
                }
            }
        }
        // The blocks' sizes: 8³ + 4³ + 2³ + 1 words under a directory at level 3.
        assert_eq!((block_len(3), block_offset(3, 1), block_offset(3, 2), block_offset(3, 3)), (585, 512, 576, 584));
        assert_eq!((block_len(1), block_offset(1, 0), block_len(0)), (9, 0, 1));
    }

    /// Trilinear sampling of `n³` texel slots stored side by side along x.
    fn sample_atlas(atlas: &[f32], n: u32, slots: u32, t: Vec3) -> f32 {
        let w = n * slots;
        let at = |x: u32, y: u32, z: u32| atlas[((z * n + y) * w + x) as usize];
        let p = t - 0.5;
        let i = p.floor();
        let f = p - i;
        let i = i.as_uvec3();
        let mut v = 0.0;
        for c in 0..8u32 {
            let (dx, dy, dz) = (c & 1, c >> 1 & 1, c >> 2);
            let wgt =
                (if dx == 1 { f.x } else { 1.0 - f.x }) * (if dy == 1 { f.y } else { 1.0 - f.y }) * (if dz == 1 { f.z } else { 1.0 - f.z });
            v += wgt * at(i.x + dx, i.y + dy, i.z + dz);
        }
        v
    }

    #[test]
    fn samples_through_the_tree_equal_samples_of_the_whole_level() {
        // A 20³ ramp in 8³ bricks with an apron of 1; levels 20, 10 and the coarse 5.
        let dims = UVec3::splat(20);
        let codes: Vec<u16> = (0..8000u32).map(|i| ((i % 20) * 7 + (i / 20 % 20) * 3 + (i / 400) * 11) as u16).collect();
        let v = Arc::new(
            Volume::new("ramp", Grid::new(dims, Vec3::ONE), Voxels::U16(codes), ValueMap::IDENTITY, Source::default()).expect("volume"),
        );
        let source = MemorySource::new(v.clone(), 8);
        let levels: Vec<SourceLevel> =
            (0..level_count(dims, 8) as u32).map(|k| SourceLevel { grid: level_grid(&v.grid, k), chunk: UVec3::splat(8) }).collect();
        assert_eq!(levels.len(), 3);
        let layout = BrickLayout::new(8, 1);
        // Drawn: brick (1, 1, 1) of level 0 (its parent is not) and brick (1, 1, 1) of
        // level 1; the rest falls to the coarse level.
        let resident = [BrickKey::new(0, UVec3::ONE), BrickKey::new(1, UVec3::ONE)];
        let drawn: HashMap<BrickKey, (Page, u64)> = resident.iter().enumerate().map(|(s, k)| (*k, (Page::Slot(s as u32), !0))).collect();
        let table_dims = [levels[0].grid.dims, levels[1].grid.dims];
        let grid = UVec3::new(2, 1, 1);
        let tree = PageTree::build(&table_dims, layout, &drawn, grid);
        // The directory over level 1 (2³ bricks) and one block under level-1 brick
        // (0, 0, 0): 2³ level-0 bricks and the level-1 brick itself.
        assert_eq!(tree.words.len(), 8 + 8 + 1);
        let n = layout.stored();
        let blocks: Vec<Vec<f32>> = resident
            .iter()
            .map(|k| {
                let b = layout.read(&source, k.level as usize, k.coords()).expect("brick");
                (0..b.voxels.len()).map(|i| b.voxels.code(i) as f32).collect()
            })
            .collect();
        let mut atlas = vec![0.0; (n * n * n * 2) as usize];
        for (s, block) in blocks.iter().enumerate() {
            for z in 0..n {
                for y in 0..n {
                    for x in 0..n {
                        atlas[((z * n + y) * 2 * n + s as u32 * n + x) as usize] = block[((z * n + y) * n + x) as usize];
                    }
                }
            }
        }
        let whole = |k: usize, qk: Vec3| {
            let data = source.read_box(k, UVec3::ZERO, levels[k].grid.dims).expect("level").voxels;
            let d = levels[k].grid.dims;
            let at = |p: UVec3| data.code(((p.z * d.y + p.y) * d.x + p.x) as usize) as f32;
            let p = qk.clamp(Vec3::ZERO, d.as_vec3() - 1.0);
            let i = p.floor().as_uvec3().min(d - 1);
            let f = p - i.as_vec3();
            let mut v = 0.0;
            for c in 0..8u32 {
                let o = UVec3::new(c & 1, c >> 1 & 1, c >> 2);
                let wgt = (if o.x == 1 { f.x } else { 1.0 - f.x })
                    * (if o.y == 1 { f.y } else { 1.0 - f.y })
                    * (if o.z == 1 { f.z } else { 1.0 - f.z });
                v += wgt * at((i + o).min(d - 1));
            }
            v
        };
        // Inside brick (1, 1, 1) of level 0 and across its borders (the apron); inside
        // brick (1, 1, 1) of level 1 up to the volume's far edge; elsewhere the coarse level.
        let cases = [
            (Vec3::new(10.3, 11.7, 8.2), Some(0)),
            (Vec3::new(7.6, 8.1, 15.4), Some(0)),
            (Vec3::new(17.0, 18.2, 19.0), Some(1)),
            (Vec3::new(16.0, 15.6, 19.4), Some(1)),
            (Vec3::new(2.2, 3.3, 4.4), None),
            (Vec3::new(7.6, 8.1, 15.9), None),
        ];
        for (q, level) in cases {
            let (found, lo, hi) = tree.locate(q, 0);
            assert!(q.cmpge(lo).all() && q.cmplt(hi).all(), "{q} outside its box {lo} … {hi}");
            match (found, level) {
                (Located::Texel { level: k, texel }, Some(want)) => {
                    assert_eq!(k, want, "{q}");
                    let qk = (q + 0.5) / (1u32 << k) as f32 - 0.5;
                    let got = sample_atlas(&atlas, n, 2, texel);
                    let expect = whole(k, qk);
                    assert!((got - expect).abs() < 1e-3, "{q}: {got} against {expect}");
                }
                (Located::Coarse, None) => {}
                other => panic!("{q}: {other:?}"),
            }
            // Every point of the box gives the same answer.
            for t in [0.1f32, 0.5, 0.9] {
                let p = lo.max(Vec3::splat(-0.5)) + (hi.min(Vec3::splat(19.5)) - lo.max(Vec3::splat(-0.5))) * t;
                let same = |a: Located, b: Located| match (a, b) {
                    (Located::Texel { level: x, .. }, Located::Texel { level: y, .. }) => x == y,
                    (a, b) => a == b,
                };
                assert!(same(tree.locate(p, 0).0, found), "{p} in the box of {q}");
            }
        }
        // The box of a level-0 brick inside the volume, and open past its edges.
        assert_eq!(tree.locate(Vec3::splat(10.0), 0).1, Vec3::splat(7.5));
        assert_eq!(tree.locate(Vec3::splat(10.0), 0).2, Vec3::splat(15.5));
        assert_eq!(tree.locate(Vec3::splat(17.0), 0).2, Vec3::splat(f32::MAX));
        // A ray stepping at level 1 reads past the level-0 brick: level 1's (1, 1, 1)
        // where it is drawn, the coarse level under level-1 brick (0, 0, 0), which is
        // not (its level-0 child is, for finer rays).
        assert!(matches!(tree.locate(Vec3::new(17.0, 18.2, 19.0), 1).0, Located::Texel { level: 1, .. }));
        assert_eq!(tree.locate(Vec3::new(10.3, 11.7, 8.2), 1).0, Located::Coarse);
        // (That answer holds over level-1 brick (0, 0, 0): open below, 15.5 above.)
        let (_, lo, hi) = tree.locate(Vec3::new(10.3, 11.7, 8.2), 1);
        assert_eq!((lo, hi), (Vec3::splat(f32::MIN), Vec3::splat(15.5)));
        // An empty brick is reported with its level; nothing drawn is the coarse level.
        let empty = PageTree::build(&table_dims, layout, &HashMap::from([(BrickKey::new(1, UVec3::ZERO), (Page::Empty(3), 0))]), grid);
        assert_eq!(empty.locate(Vec3::splat(3.0), 0).0, Located::Empty { level: 1 });
        let none = PageTree::build(&table_dims, layout, &HashMap::new(), grid);
        assert_eq!(none.words.len(), 8);
        assert_eq!(none.locate(Vec3::splat(3.0), 0).0, Located::Coarse);
    }
}
