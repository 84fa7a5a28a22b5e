//! Level of detail: which level of a pyramid a part of the view needs, and which bricks.
//!
//! A pixel at distance `d` along a perspective view of vertical field of view `θ` and `H`
//! pixels covers `f = 2 d tan(θ/2) / H` millimetres (orthographic: the view height over
//! `H` everywhere). Where a lens magnifies by `m` the pixel sees `f / m` of the data. Level
//! `k` has voxels `2ᵏ s₀` (s₀ the finest spacing), so the coarsest level whose voxels are
//! no larger than the footprint, `k = ⌊log₂(f / s₀)⌋` clamped to the pyramid, loses
//! nothing the pixel could show: the image does not change when the data is finer than
//! needed, and a magnifier at 8× asks for three levels finer than its context.
//!
//! [`select`] refines from the coarsest level down: a brick whose nearest point needs a
//! finer level than its own is replaced by its (up to eight) children, down to level 0,
//! until the wanted number of bricks is reached (the rest stay at the level they got).

use glam::{UVec3, Vec3};

use super::SourceLevel;
use super::brick::BrickLayout;
use super::cache::BrickKey;

/// Millimetres one pixel covers at `distance` in a perspective view (`fov_y` radians,
/// `height` pixels), seen through a magnification `magnification`.
pub fn pixel_footprint(distance: f32, fov_y: f32, height: u32, magnification: f32) -> f32 {
    2.0 * distance.max(0.0) * (fov_y * 0.5).tan() / height.max(1) as f32 / magnification.max(1e-6)
}

/// The coarsest level whose voxels (`2ᵏ · finest`) are no larger than `footprint`.
pub fn level_for(footprint: f32, finest: f32, levels: usize) -> usize {
    if footprint.is_nan() || footprint <= finest || levels <= 1 {
        return 0;
    }
    ((footprint / finest).log2().floor() as usize).min(levels - 1)
}

/// Distance from `eye` to the nearest point of the box `lo .. hi`.
pub fn box_distance(eye: Vec3, lo: Vec3, hi: Vec3) -> f32 {
    (eye.clamp(lo, hi) - eye).length()
}

/// The bricks to draw: refined from the coarsest level while `footprint(lo, hi)` (the
/// smallest pixel footprint over a world box, lenses included) asks for a finer level,
/// keeping only boxes where `visible(lo, hi)`, and stopping at `max_bricks`. Coarse
/// bricks come first, so a truncated list still covers the view.
pub fn select(
    levels: &[SourceLevel],
    layout: BrickLayout,
    footprint: impl Fn(Vec3, Vec3) -> f32,
    visible: impl Fn(Vec3, Vec3) -> bool,
    max_bricks: usize,
) -> Vec<BrickKey> {
    let Some(coarsest) = levels.len().checked_sub(1) else { return Vec::new() };
    let finest = levels[0].grid.spacing.min_element();
    let bounds = |k: &BrickKey| {
        let g = &levels[k.level as usize].grid;
        let lo = (k.coords() * layout.size).as_vec3() - 0.5;
        let hi = ((k.coords() + 1) * layout.size).min(g.dims).as_vec3() - 0.5;
        g.index_box_world_bounds(lo, hi)
    };
    let all = |level: usize| {
        let n = layout.bricks(levels[level].grid.dims);
        (0..n.z).flat_map(move |z| (0..n.y).flat_map(move |y| (0..n.x).map(move |x| BrickKey::new(level, UVec3::new(x, y, z)))))
    };
    let mut chosen: Vec<BrickKey> = Vec::new();
    let mut frontier: Vec<BrickKey> = all(coarsest).filter(|k| visible(bounds(k).0, bounds(k).1)).collect();
    while let Some(k) = frontier.pop() {
        let (lo, hi) = bounds(&k);
        let want = level_for(footprint(lo, hi), finest, levels.len());
        let remaining = chosen.len() + frontier.len() + 1;
        if want < k.level as usize && remaining + 7 <= max_bricks {
            let child_level = k.level as usize - 1;
            let n = layout.bricks(levels[child_level].grid.dims);
            for i in 0..8u32 {
                let c = k.coords() * 2 + UVec3::new(i & 1, i >> 1 & 1, i >> 2);
                if c.cmplt(n).all() {
                    let child = BrickKey::new(child_level, c);
                    let (clo, chi) = bounds(&child);
                    if visible(clo, chi) {
                        frontier.push(child);
                    }
                }
            }
        } else {
            chosen.push(k);
        }
    }
    chosen.sort_by_key(|k| std::cmp::Reverse(k.level));
    chosen
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::Grid;
    use crate::volume::source::{level_count, level_grid};

    #[test]
    fn the_footprint_picks_the_level_whose_voxels_fit_a_pixel() {
        // 60° field of view, 1000 pixels, 100 mm away: 2 · 100 · tan 30° / 1000 = 0.11547 mm.
        let f = pixel_footprint(100.0, 60f32.to_radians(), 1000, 1.0);
        assert!((f - 0.115_47).abs() < 1e-5);
        // A magnifier at 8× shrinks it eightfold.
        assert!((pixel_footprint(100.0, 60f32.to_radians(), 1000, 8.0) - f / 8.0).abs() < 1e-7);
        // Finest spacing 0.01: 0.11547 / 0.01 = 11.5 → level 3 (voxels 0.08 ≤ 0.115 < 0.16).
        assert_eq!(level_for(f, 0.01, 10), 3);
        assert_eq!(level_for(f / 8.0, 0.01, 10), 0, "at 8× the lens needs native voxels");
        assert_eq!(level_for(0.08, 0.01, 10), 3);
        assert_eq!(level_for(0.0799, 0.01, 10), 2);
        assert_eq!(level_for(1000.0, 0.01, 4), 3, "clamped to the pyramid");
        assert_eq!(level_for(f32::NAN, 0.01, 4), 0);
        assert_eq!(box_distance(Vec3::new(5.0, 0.0, 0.0), Vec3::ZERO, Vec3::ONE), 4.0);
        assert_eq!(box_distance(Vec3::splat(0.5), Vec3::ZERO, Vec3::ONE), 0.0);
    }

    #[test]
    fn selection_refines_near_the_eye_and_inside_a_lens() {
        // 256³ voxels of 1 mm in 32³ bricks: levels 256, 128, 64, 32.
        let base = Grid::new(UVec3::splat(256), Vec3::ONE);
        let levels: Vec<SourceLevel> =
            (0..level_count(base.dims, 32) as u32).map(|k| SourceLevel { grid: level_grid(&base, k), chunk: UVec3::splat(32) }).collect();
        assert_eq!(levels.len(), 4);
        let layout = BrickLayout::new(32, 1);
        // Far away every pixel covers 8 mm: the coarsest level's single brick.
        let far = select(&levels, layout, |_, _| 8.0, |_, _| true, 1000);
        assert_eq!(far, vec![BrickKey::new(3, UVec3::ZERO)]);
        // 1 mm everywhere: all of level 0 (8³ bricks).
        let near = select(&levels, layout, |_, _| 1.0, |_, _| true, 1000);
        assert_eq!(near.len(), 512);
        assert!(near.iter().all(|k| k.level == 0));
        // Coarse context (4 mm) with a 4× lens over the box x < 64: level 0 there only.
        let lens = |lo: Vec3, _hi: Vec3| if lo.x < 63.0 { 1.0 } else { 4.0 };
        let mixed = select(&levels, layout, lens, |_, _| true, 1000);
        let fine: Vec<_> = mixed.iter().filter(|k| k.level == 0).collect();
        assert!(!fine.is_empty() && fine.iter().all(|k| k.brick.0 < 2), "{fine:?}");
        assert!(mixed.iter().any(|k| k.level == 2));
        // The voxels covered add up to the whole volume, once.
        let covered: u64 = mixed.iter().map(|k| (32u64 << k.level).pow(3)).sum();
        assert_eq!(covered, 256u64.pow(3));
        // A budget stops refinement but still covers the view, coarse bricks first.
        let capped = select(&levels, layout, |_, _| 1.0, |_, _| true, 20);
        assert!(capped.len() <= 20);
        let covered: u64 = capped.iter().map(|k| (32u64 << k.level).pow(3)).sum();
        assert_eq!(covered, 256u64.pow(3));
        assert!(capped.windows(2).all(|w| w[0].level >= w[1].level));
        // Invisible boxes are left out.
        let half = select(&levels, layout, |_, _| 1.0, |lo, _| lo.z < 127.0, 1000);
        assert_eq!(half.len(), 256);
    }
}
