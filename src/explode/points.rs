//! Explosion points (Bruckner and Gröller 2006, section 3.2): where the selection is,
//! from a simultaneous traversal of min-max octrees of the data and of the selection.
//!
//! The leaves are the bricks of the volumes' min-max grids ([`crate::volume::BrickGrid`]:
//! code ranges with a one-voxel apron). A leaf counts when the transfer function makes
//! some of the data's range visible there and the selection's range is not all zero.
//! Level `k` of the octree merges `2^k` bricks along each axis; the traversal stops at
//! the first level with at most `max_points` counting nodes, and each such node gives a
//! point at the mean centre of its counting bricks, jittered within a brick by a
//! deterministic hash, weighted by how many bricks count in it (its size in the
//! selection).

use glam::{UVec3, Vec3};

use super::forces::ExplosionPoint;
use crate::volume::{BrickGrid, Grid};

/// Explosion points in the dataset's own frame. `data` and `selection` are the min-max
/// grids of the data and the selection volumes (on the same grid), `grid` the data's
/// grid; `visible(lo, hi)` tells whether the transfer function gives the data codes
/// `lo..=hi` any opacity. Empty when the grids differ or nothing is selected.
pub fn explosion_points(
    grid: &Grid,
    data: &BrickGrid,
    selection: &BrickGrid,
    visible: impl Fn(u16, u16) -> bool,
    max_points: usize,
) -> Vec<ExplosionPoint> {
    if data.dims != selection.dims || data.size != selection.size {
        return Vec::new();
    }
    let leaves: Vec<UVec3> = (0..data.len())
        .filter(|&i| selection.max[i] > 0 && visible(data.min[i], data.max[i]))
        .map(|i| UVec3::new(i as u32 % data.dims.x, i as u32 / data.dims.x % data.dims.y, i as u32 / (data.dims.x * data.dims.y)))
        .collect();
    if leaves.is_empty() {
        return Vec::new();
    }
    let centre = |b: UVec3| {
        let (lo, hi) = data.brick_bounds(b);
        (lo + hi) * 0.5
    };
    let levels = 32 - data.dims.max_element().leading_zeros();
    for k in 0..=levels {
        let mut nodes: std::collections::BTreeMap<(u32, u32, u32), (Vec3, u32)> = std::collections::BTreeMap::new();
        for b in &leaves {
            let n = *b >> k;
            let e = nodes.entry((n.x, n.y, n.z)).or_insert((Vec3::ZERO, 0));
            e.0 += centre(*b);
            e.1 += 1;
        }
        if nodes.len() <= max_points.max(1) || k == levels {
            let to_world = grid.index_to_world();
            return nodes
                .into_iter()
                .map(|((x, y, z), (sum, count))| {
                    let jitter = Vec3::new(hash(x, y, z, 1), hash(x, y, z, 2), hash(x, y, z, 3)) - 0.5;
                    let index = sum / count as f32 + jitter * data.size as f32 * 0.5;
                    ExplosionPoint { position: to_world.transform_point3(index), weight: count as f32 }
                })
                .collect();
        }
    }
    Vec::new()
}

/// A deterministic number in `[0, 1)` for a node and a channel (the renderers' jitter
/// hash).
fn hash(x: u32, y: u32, z: u32, c: u32) -> f32 {
    crate::reference::trace::jitter(x.wrapping_add(z.wrapping_mul(7_919)), y, c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::Voxels;

    #[test]
    fn points_sit_where_selected_data_is_visible() {
        // 32³ unit voxels, bricks of 8: data visible everywhere (code 100), the selection
        // a cube of voxels 0..15 in x, y, z (the first 2×2×2 bricks and their aprons).
        let dims = UVec3::splat(32);
        let grid = Grid::new(dims, Vec3::ONE);
        let data = BrickGrid::build(&Voxels::U8(vec![100; 32 * 32 * 32]), dims, 8);
        let sel: Vec<u8> = (0..32 * 32 * 32).map(|i| if i % 32 < 16 && i / 32 % 32 < 16 && i / 1024 < 16 { 255 } else { 0 }).collect();
        let selection = BrickGrid::build(&Voxels::U8(sel), dims, 8);
        // With room for every leaf: the bricks touched by the selection (its 2³ bricks
        // and, through the aprons, the next layer: 3³ = 27), each of weight 1.
        let all = explosion_points(&grid, &data, &selection, |_, hi| hi > 0, 1000);
        assert_eq!(all.len(), 27);
        assert!(all.iter().all(|p| p.weight == 1.0 && p.position.max_element() < 24.0));
        // Limited to 8: level 1 (16-voxel nodes), whose weights sum to the 27 bricks.
        let few = explosion_points(&grid, &data, &selection, |_, hi| hi > 0, 8);
        assert_eq!(few.len(), 8);
        assert_eq!(few.iter().map(|p| p.weight).sum::<f32>(), 27.0);
        // Data the transfer function hides gives none; so does a selection of zeros.
        assert!(explosion_points(&grid, &data, &selection, |_, _| false, 1000).is_empty());
        let none = BrickGrid::build(&Voxels::U8(vec![0; 32 * 32 * 32]), dims, 8);
        assert!(explosion_points(&grid, &data, &none, |_, hi| hi > 0, 1000).is_empty());
        // Deterministic.
        assert_eq!(all, explosion_points(&grid, &data, &selection, |_, hi| hi > 0, 1000));
    }
}
