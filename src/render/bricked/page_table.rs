//! The page table of a bricked dataset: one `u32` per brick of every level, saying where
//! in the atlas its voxels are (`slot + 2`), that it is not resident (`0`) or that it
//! holds nothing visible (`1`, skipped), and per level where its entries start.
//!
//! A sample at continuous level-0 index `q` wanting level `k` reads level `k` at
//! `q_k = (q + ½)/2ᵏ − ½` ([`crate::volume::pyramid::level_index`]): brick
//! `b = ⌊(q_k + ½)/B⌋` (clamped to the level), and inside its slot the texel
//! `origin + A + (q_k − b·B) + ½` (A the apron). A brick that is not resident sends the
//! look-up to the next coarser level, down to the coarsest, which is always resident.
//! [`PageTable::locate`] is that look-up on the CPU, the reference for the shader's.

use glam::{UVec3, Vec3};

use crate::volume::source::SourceLevel;
use crate::volume::source::brick::BrickLayout;
use crate::volume::source::cache::BrickKey;

/// What the table says of one brick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Page {
    /// Not in the atlas: look at a coarser level.
    Missing,
    /// Resident but nothing in it is visible: skip it.
    Empty,
    /// In this atlas slot.
    Slot(u32),
}

impl Page {
    pub fn code(self) -> u32 {
        match self {
            Page::Missing => 0,
            Page::Empty => 1,
            Page::Slot(s) => s + 2,
        }
    }

    pub fn from_code(code: u32) -> Page {
        match code {
            0 => Page::Missing,
            1 => Page::Empty,
            s => Page::Slot(s - 2),
        }
    }
}

/// One level's place in the table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LevelEntry {
    /// Voxels of the level.
    pub dims: UVec3,
    /// Bricks along each axis.
    pub bricks: UVec3,
    /// Index of its first entry.
    pub offset: u32,
}

/// The table of one dataset.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PageTable {
    pub layout: BrickLayout,
    pub levels: Vec<LevelEntry>,
    pub entries: Vec<u32>,
}

/// Where a sample reads: the level used, and the texel position in the atlas.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Located {
    pub level: usize,
    pub texel: Vec3,
}

impl PageTable {
    /// The table of a pyramid, each brick as `page(key)` says.
    pub fn build(levels: &[SourceLevel], layout: BrickLayout, page: impl Fn(BrickKey) -> Page) -> PageTable {
        let mut entries = Vec::new();
        let mut out = Vec::with_capacity(levels.len());
        for (k, l) in levels.iter().enumerate() {
            let bricks = layout.bricks(l.grid.dims);
            out.push(LevelEntry { dims: l.grid.dims, bricks, offset: entries.len() as u32 });
            for z in 0..bricks.z {
                for y in 0..bricks.y {
                    for x in 0..bricks.x {
                        entries.push(page(BrickKey::new(k, UVec3::new(x, y, z))).code());
                    }
                }
            }
        }
        PageTable { layout, levels: out, entries }
    }

    /// The page of brick `b` of level `k`.
    pub fn page(&self, k: usize, b: UVec3) -> Page {
        let l = &self.levels[k];
        let i = l.offset + (b.z * l.bricks.y + b.y) * l.bricks.x + b.x;
        Page::from_code(self.entries[i as usize])
    }

    /// Where continuous level-0 index `q` reads when it wants level `want`: the finest
    /// resident level from `want` up, `None` when that brick is empty (nothing to draw)
    /// or no level holds it; `origin(slot)` gives a slot's texel origin.
    pub fn locate(&self, q: Vec3, want: usize, origin: impl Fn(u32) -> UVec3) -> Option<Located> {
        let size = self.layout.size as f32;
        for k in want.min(self.levels.len().saturating_sub(1))..self.levels.len() {
            let l = &self.levels[k];
            let qk = (q + 0.5) / (1u32 << k) as f32 - 0.5;
            let qk = qk.clamp(Vec3::ZERO, l.dims.as_vec3() - 1.0);
            let b = ((qk + 0.5) / size).floor().as_uvec3().min(l.bricks - 1);
            match self.page(k, b) {
                Page::Missing => continue,
                Page::Empty => return None,
                Page::Slot(s) => {
                    let inside = qk - (b * self.layout.size).as_vec3();
                    let texel = origin(s).as_vec3() + self.layout.apron as f32 + inside + 0.5;
                    return Some(Located { level: k, texel });
                }
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::volume::source::memory::MemorySource;
    use crate::volume::source::{VoxelSource, level_count, level_grid};
    use crate::volume::{Grid, Source, ValueMap, Volume, Voxels};

    #[test]
    fn codes_round_trip() {
        for p in [Page::Missing, Page::Empty, Page::Slot(0), Page::Slot(77)] {
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
    fn samples_through_the_table_equal_samples_of_the_whole_level() {
        // A 20³ ramp in 8³ bricks with an apron of 1; levels 20, 10, 5.
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
        // Level 0 resident only for brick (1, 1, 1); level 1 for nothing; level 2 whole.
        let resident = [BrickKey::new(0, UVec3::ONE), BrickKey::new(2, UVec3::ZERO)];
        let table =
            PageTable::build(&levels, layout, |k| resident.iter().position(|r| *r == k).map_or(Page::Missing, |s| Page::Slot(s as u32)));
        assert_eq!(table.entries.len(), 27 + 8 + 1);
        // The atlas: each resident brick's stored box, slots side by side along x.
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
        // Inside brick (1, 1, 1) of level 0, across its borders (the apron), and outside
        // it where level 1 is missing and level 2 answers.
        for q in [Vec3::new(10.3, 11.7, 8.2), Vec3::new(7.6, 8.1, 15.9), Vec3::new(2.2, 3.3, 4.4), Vec3::new(19.0, 0.0, 19.0)] {
            let loc = table.locate(q, 0, origin).expect("located");
            let inside = q.cmpge(Vec3::splat(7.5)).all() && q.cmplt(Vec3::splat(15.5)).all();
            assert_eq!(loc.level, if inside { 0 } else { 2 }, "{q}");
            let qk = (q + 0.5) / (1u32 << loc.level) as f32 - 0.5;
            let got = sample_atlas(&atlas, n, 2, loc.texel);
            let want = whole(loc.level, qk);
            assert!((got - want).abs() < 1e-3, "{q}: {got} against {want}");
        }
        // An empty brick stops the look-up.
        let empty = PageTable::build(&levels, layout, |_| Page::Empty);
        assert_eq!(empty.locate(Vec3::splat(3.0), 0, origin), None);
        let missing = PageTable::build(&levels, layout, |_| Page::Missing);
        assert_eq!(missing.locate(Vec3::splat(3.0), 0, origin), None);
    }
}
