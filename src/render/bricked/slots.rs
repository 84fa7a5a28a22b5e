//! Slots of the GPU brick atlas: one 3D texture cut into `n.x × n.y × n.z` cubes of
//! `B + 2A` texels, each holding one brick with its apron. Bricks are placed in free
//! slots; when none is free the least recently drawn brick gives its slot up, never one
//! drawn in the current frame (a frame that needs more bricks than there are slots draws
//! the rest from coarser levels).

use std::collections::HashMap;
use std::hash::Hash;

use glam::UVec3;

/// The atlas's slots and which brick (`K`: a brick of some dataset) each holds.
#[derive(Clone, Debug)]
pub struct Slots<K> {
    /// Slots along each axis.
    pub grid: UVec3,
    /// Texels per slot edge (brick plus apron on both sides).
    pub edge: u32,
    held: Vec<Option<(K, u64)>>,
    by_key: HashMap<K, u32>,
    frame: u64,
}

impl<K: Copy + Eq + Hash> Slots<K> {
    /// As many slots of `edge` texels as fit a texture of at most `max_texels` per axis
    /// and `budget_bytes` in all (`texel_bytes` each), at most
    /// [`MAX_SLOTS_PER_AXIS`](super::page_table::MAX_SLOTS_PER_AXIS) per axis (the page
    /// table names a slot in 7 bits an axis); at least one.
    pub fn new(edge: u32, max_texels: u32, budget_bytes: u64, texel_bytes: u32) -> Slots<K> {
        let per_axis = (max_texels / edge.max(1)).clamp(1, super::page_table::MAX_SLOTS_PER_AXIS);
        let slot_bytes = edge as u64 * edge as u64 * edge as u64 * texel_bytes as u64;
        let count = (budget_bytes / slot_bytes.max(1)).max(1);
        // The most slots within the budget, as a near-cube.
        let mut grid = UVec3::ONE;
        for axis in [0usize, 1, 2].iter().cycle().take(3 * per_axis as usize) {
            let mut g = grid;
            g[*axis] += 1;
            if g[*axis] <= per_axis && g.x as u64 * g.y as u64 * g.z as u64 <= count {
                grid = g;
            }
        }
        let n = (grid.x * grid.y * grid.z) as usize;
        Slots { grid, edge, held: vec![None; n], by_key: HashMap::new(), frame: 0 }
    }

    /// Texels of the whole atlas texture.
    pub fn texture_size(&self) -> UVec3 {
        self.grid * self.edge
    }

    pub fn len(&self) -> usize {
        self.held.len()
    }

    pub fn is_empty(&self) -> bool {
        self.held.is_empty()
    }

    /// Starts a frame: bricks marked from now on are this frame's.
    pub fn next_frame(&mut self) {
        self.frame += 1;
    }

    /// The slot of a resident brick, marked as drawn this frame.
    pub fn touch(&mut self, key: K) -> Option<u32> {
        let slot = *self.by_key.get(&key)?;
        if let Some((_, used)) = &mut self.held[slot as usize] {
            *used = self.frame;
        }
        Some(slot)
    }

    /// The slot of a resident brick, without marking it.
    pub fn slot_of(&self, key: K) -> Option<u32> {
        self.by_key.get(&key).copied()
    }

    /// A slot for `key`: its own if resident, else a free one, else that of the least
    /// recently drawn brick not drawn this frame (which leaves). `None` when every slot
    /// holds a brick of this frame.
    pub fn place(&mut self, key: K) -> Option<(u32, Option<K>)> {
        if let Some(s) = self.touch(key) {
            return Some((s, None));
        }
        let slot = match self.held.iter().position(Option::is_none) {
            Some(free) => free,
            None => {
                let (i, _) = self
                    .held
                    .iter()
                    .enumerate()
                    .filter_map(|(i, h)| h.map(|(_, used)| (i, used)))
                    .filter(|&(_, used)| used < self.frame)
                    .min_by_key(|&(_, used)| used)?;
                i
            }
        };
        let evicted = self.held[slot].map(|(k, _)| k);
        if let Some(k) = evicted {
            self.by_key.remove(&k);
        }
        self.held[slot] = Some((key, self.frame));
        self.by_key.insert(key, slot as u32);
        Some((slot as u32, evicted))
    }

    /// Slots holding a brick.
    pub fn held(&self) -> usize {
        self.by_key.len()
    }

    /// Texel origin of a slot in the atlas.
    pub fn origin(&self, slot: u32) -> UVec3 {
        let g = self.grid;
        UVec3::new(slot % g.x, slot / g.x % g.y, slot / (g.x * g.y)) * self.edge
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::source::cache::BrickKey;

    fn key(x: u32) -> BrickKey {
        BrickKey::new(0, UVec3::new(x, 0, 0))
    }

    #[test]
    fn slots_fill_the_budget_as_a_near_cube() {
        // 34³ texels of 2 bytes = 78 608 bytes per slot; 64 MiB holds 853 slots: grown
        // an axis at a time, 10 × 9 × 9 = 810 (10 × 10 × 9 = 900 is too many).
        let s = Slots::<BrickKey>::new(34, 2048, 64 << 20, 2);
        assert_eq!(s.grid, UVec3::new(10, 9, 9));
        assert_eq!(s.texture_size(), UVec3::new(340, 306, 306));
        // The texture size limit wins over the budget.
        assert_eq!(Slots::<BrickKey>::new(34, 100, 1 << 40, 1).grid, UVec3::splat(2));
        assert_eq!(Slots::<BrickKey>::new(34, 2048, 1, 1).len(), 1);
        assert_eq!(s.origin(0), UVec3::ZERO);
        assert_eq!(s.origin(10 * 9 + 10 + 2), UVec3::new(2, 1, 1) * 34);
    }

    #[test]
    fn the_least_recently_drawn_brick_gives_its_slot_up_but_not_this_frames() {
        let mut s = Slots::new(4, 8, 8 * 64, 1);
        assert_eq!(s.len(), 8);
        s.next_frame();
        for i in 0..8 {
            assert_eq!(s.place(key(i)), Some((i, None)));
        }
        // All eight are this frame's: a ninth finds no slot.
        assert_eq!(s.place(key(8)), None);
        s.next_frame();
        assert_eq!(s.touch(key(0)), Some(0));
        assert_eq!(s.place(key(3)), Some((3, None)), "a resident brick keeps its slot");
        // Bricks 1, 2, 4… were last drawn a frame ago; 1 is the first of them.
        let (slot, evicted) = s.place(key(8)).expect("a slot");
        assert_eq!(evicted, Some(key(1)));
        assert_eq!(slot, 1);
        assert_eq!(s.slot_of(key(1)), None);
        assert_eq!(s.slot_of(key(8)), Some(1));
    }
}
