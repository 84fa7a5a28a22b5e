//! The page table of a bricked dataset, as a tree of its drawn bricks.
//!
//! Level `C` of the pyramid (the coarse level) is drawn from a whole volume in the
//! volume atlas; levels `0 … C−1` are drawn from bricks in the brick atlas. The table
//! holds one node for every brick of level `T = C − 1` (the top grid), and below any
//! node with a drawn descendant a block of its eight children (bricks nest: brick `b` of
//! level `k` holds bricks `2b + o` of level `k − 1`, since `q_k = (q + ½)/2ᵏ − ½`,
//! [`crate::volume::pyramid::level_index`]). A node is four words: its [`Page`] (`slot +
//! 2`, [`EMPTY_PAGE`] with the lowest code, `0` missing), the word index of its child
//! block (`0` none), and for a brick in a slot the 64 bits of its 8³ sub-blocks that
//! hold something visible (bit `x + 4y + 16z`; empty-space skipping at the granularity
//! a volume in memory has).
//!
//! A sample at continuous level-0 index `q` descends from the top node holding it while
//! nodes have children, keeping the last page that is not missing: the finest drawn brick
//! holding it, else the coarse volume. The result is the same for every `q` in the box of
//! the last node visited, which the shader keeps as a cache (`shaders/focal/bricked.wgsl`,
//! checked against [`PageTree::locate`], itself checked against sampling whole levels).
//! Inside the brick the texel is `origin + A + (q_k − b·B) + ½` (A the apron).
//!
//! Which bricks are drawn is decided elsewhere (the wanted bricks of the view and their
//! resident ancestors, [`crate::dataset::bricked`]): the table only records it, so the
//! picture does not depend on what earlier views left resident.
//!
//! Words, from the tree's start: `T`, the top grid's brick counts (3), then per level
//! `0 … T` its voxel dims (3) and a zero, then the nodes.

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

/// The page word of an empty brick: this bit and its lowest code.
pub const EMPTY_PAGE: u32 = 1 << 31;

impl Page {
    pub fn code(self) -> u32 {
        match self {
            Page::Missing => 0,
            Page::Empty(c) => EMPTY_PAGE | c as u32,
            Page::Slot(s) => s + 2,
        }
    }

    pub fn from_code(code: u32) -> Page {
        match code {
            0 | 1 => Page::Missing,
            c if c >= EMPTY_PAGE => Page::Empty((c - EMPTY_PAGE) as u16),
            s => Page::Slot(s - 2),
        }
    }
}

/// Words per node: page, child block, sub-block mask (two words).
pub const NODE: usize = 4;

fn write_node(words: &mut [u32], at: usize, node: Option<&(Page, u64)>) {
    let (page, mask) = node.copied().unwrap_or((Page::Missing, 0));
    words[at] = page.code();
    if let Page::Slot(_) = page {
        words[at + 2] = mask as u32;
        words[at + 3] = (mask >> 32) as u32;
    }
}

/// Words before the nodes: `T`, the top grid (3), and four per level `0 … T`.
pub fn header_words(top: usize) -> usize {
    4 + 4 * (top + 1)
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

impl PageTree {
    /// The tree over levels of `dims` (`0 … T`, the coarse level left out) drawing the
    /// bricks of `drawn` (each with its sub-block mask).
    pub fn build(dims: &[UVec3], layout: BrickLayout, drawn: &HashMap<BrickKey, (Page, u64)>) -> PageTree {
        let top = dims.len().saturating_sub(1);
        let mut words = Vec::new();
        if dims.is_empty() {
            return PageTree { layout, dims: Vec::new(), words };
        }
        let top_bricks = layout.bricks(dims[top]);
        words.extend([top as u32, top_bricks.x, top_bricks.y, top_bricks.z]);
        for d in dims {
            words.extend([d.x, d.y, d.z, 0]);
        }
        // Every drawn brick and its ancestors up to the top: the nodes with children.
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
        let first = words.len();
        let n = (top_bricks.x * top_bricks.y * top_bricks.z) as usize;
        words.resize(first + NODE * n, 0);
        // Breadth-first: (node word, key) whose children are still to place.
        let mut queue = Vec::new();
        for z in 0..top_bricks.z {
            for y in 0..top_bricks.y {
                for x in 0..top_bricks.x {
                    let key = BrickKey::new(top, UVec3::new(x, y, z));
                    let at = first + NODE * ((z * top_bricks.y + y) * top_bricks.x + x) as usize;
                    write_node(&mut words, at, drawn.get(&key));
                    if inner.contains(&key) {
                        queue.push((at, key));
                    }
                }
            }
        }
        while let Some((at, key)) = queue.pop() {
            let block = words.len();
            words[at + 1] = block as u32;
            words.resize(block + 8 * NODE, 0);
            let level = key.level as usize - 1;
            let limit = layout.bricks(dims[level]);
            for o in 0..8u32 {
                let c = key.coords() * 2 + UVec3::new(o & 1, o >> 1 & 1, o >> 2);
                if c.cmpge(limit).any() {
                    continue;
                }
                let child = BrickKey::new(level, c);
                let w = block + NODE * o as usize;
                write_node(&mut words, w, drawn.get(&child));
                if inner.contains(&child) {
                    queue.push((w, child));
                }
            }
        }
        PageTree { layout, dims: dims.to_vec(), words }
    }

    /// Where continuous level-0 index `q` reads, `origin(slot)` giving a slot's texel
    /// origin; and the level-0 box `[lo, hi)` over which the answer holds.
    pub fn locate(&self, q: Vec3, origin: impl Fn(u32) -> UVec3) -> (Located, Vec3, Vec3) {
        let Some(top) = self.dims.len().checked_sub(1) else { return (Located::Coarse, Vec3::MIN, Vec3::MAX) };
        let size = self.layout.size;
        let w = |i: usize| self.words[i];
        // The level-0 brick (clamped like the sample) whose ancestors the descent visits.
        let brick_at = |k: usize| {
            let d = self.dims[k].as_vec3();
            let qk = ((q + 0.5) / (1u32 << k) as f32 - 0.5).clamp(Vec3::ZERO, d - 1.0);
            ((qk + 0.5) / size as f32).floor().as_uvec3().min(self.layout.bricks(self.dims[k]) - 1)
        };
        let tb = UVec3::new(w(1), w(2), w(3));
        let b = brick_at(top);
        let mut node = header_words(top) + NODE * ((b.z * tb.y + b.y) * tb.x + b.x) as usize;
        let mut found = Located::Coarse;
        let mut k = top;
        loop {
            let b = brick_at(k);
            match Page::from_code(w(node)) {
                Page::Missing => {}
                Page::Empty(_) => found = Located::Empty { level: k },
                Page::Slot(s) => {
                    let qk = ((q + 0.5) / (1u32 << k) as f32 - 0.5).clamp(Vec3::ZERO, self.dims[k].as_vec3() - 1.0);
                    let inside = qk - (b * size).as_vec3();
                    found = Located::Texel { level: k, texel: origin(s).as_vec3() + self.layout.apron as f32 + inside + 0.5 };
                }
            }
            let children = w(node + 1) as usize;
            if children == 0 || k == 0 {
                let (lo, hi) = node_box(b, size << k, self.layout.bricks(self.dims[k]));
                return (found, lo, hi);
            }
            let c = brick_at(k - 1).saturating_sub(b * 2).min(UVec3::ONE);
            node = children + NODE * (c.x + 2 * c.y + 4 * c.z) as usize;
            k -= 1;
        }
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

    #[test]
    fn codes_round_trip() {
        for p in [Page::Missing, Page::Empty(0), Page::Empty(65535), Page::Slot(0), Page::Slot(77)] {
            assert_eq!(Page::from_code(p.code()), p);
        }
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
        let tree = PageTree::build(&table_dims, layout, &drawn);
        // Header 4 + 8, the top grid's 8 nodes, one child block (level 0 under (0,0,0)).
        assert_eq!(tree.words.len(), 12 + 8 * NODE + 8 * NODE);
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
        let origin = |s: u32| UVec3::new(s * n, 0, 0);
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
            let (found, lo, hi) = tree.locate(q, origin);
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
                assert!(same(tree.locate(p, origin).0, found), "{p} in the box of {q}");
            }
        }
        // The box of a level-0 brick inside the volume, and open past its edges.
        assert_eq!(tree.locate(Vec3::splat(10.0), origin).1, Vec3::splat(7.5));
        assert_eq!(tree.locate(Vec3::splat(10.0), origin).2, Vec3::splat(15.5));
        assert_eq!(tree.locate(Vec3::splat(17.0), origin).2, Vec3::splat(f32::MAX));
        // An empty brick is reported with its level; nothing drawn is the coarse level.
        let empty = PageTree::build(&table_dims, layout, &HashMap::from([(BrickKey::new(1, UVec3::ZERO), (Page::Empty(3), 0))]));
        assert_eq!(empty.locate(Vec3::splat(3.0), origin).0, Located::Empty { level: 1 });
        let none = PageTree::build(&table_dims, layout, &HashMap::new());
        assert_eq!(none.words.len(), 12 + 8 * NODE);
        assert_eq!(none.locate(Vec3::splat(3.0), origin).0, Located::Coarse);
    }
}
