//! Which bricks the views want: the level-of-detail selection
//! ([`crate::volume::source::lod::select`]) over every region that shows a bricked
//! volume, in every view, with the lenses' magnification.
//!
//! A brick (a box in the dataset's own millimetres) is seen through each region that
//! shows its volume: `dataset → world` is the inverse of the region's world → voxel map
//! composed with the coarse level's voxel → dataset map, so a volumetric window that
//! magnifies, or an exploded part that moved, asks for what it shows. Its footprint is
//! the smallest over views and regions of the pixel footprint at the box's nearest point
//! (`2d·tan(θ/2)/H`, orthographic `h/H`), divided by the magnification of any magnifier
//! whose focus or border the projected box meets, and converted from world to dataset
//! millimetres by the map's largest scale. A box no region and no view sees is left out.
//!
//! Where a view has magnifiers, the context beside them still wants its own level: its
//! rays read nothing finer than their footprint asks for (`render::bricked::page_table`),
//! so the bricks of the views without their magnifiers are wanted too (the coarser cut;
//! where the two cuts differ, under and around the lenses, both are drawn).

use std::collections::HashSet;

use glam::{Affine3A, Vec2, Vec3};

use crate::lens::screen::Screen;
use crate::region::{Camera, Plane, Projection};
use crate::volume::source::SourceLevel;
use crate::volume::source::brick::BrickLayout;
use crate::volume::source::cache::BrickKey;
use crate::volume::source::lod::{box_distance, pixel_footprint, select};

/// One view: its camera, image and the magnifiers over it.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewFrame {
    pub camera: Camera,
    pub screen: Screen,
    pub magnifiers: Vec<Magnified>,
}

/// A magnifier's reach on screen (lens units: NDC with x times the aspect) and power.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Magnified {
    pub center: Vec2,
    pub reach: f32,
    pub magnification: f32,
}

/// A region showing the volume: dataset millimetres → world, and its planes (world).
#[derive(Clone, Debug, PartialEq)]
pub struct Seen {
    pub dataset_to_world: Affine3A,
    pub planes: Vec<Plane>,
}

fn corners(lo: Vec3, hi: Vec3) -> [Vec3; 8] {
    std::array::from_fn(|c| {
        Vec3::new(if c & 1 == 0 { lo.x } else { hi.x }, if c & 2 == 0 { lo.y } else { hi.y }, if c & 4 == 0 { lo.z } else { hi.z })
    })
}

/// Largest factor by which `m` stretches a length.
fn largest_scale(m: &Affine3A) -> f32 {
    let l = m.matrix3;
    l.x_axis.length().max(l.y_axis.length()).max(l.z_axis.length()).max(1e-12)
}

/// Whether the world box with these corners can show in `region` seen by `view`.
fn visible(world: &[Vec3; 8], region: &Seen, view: &ViewFrame) -> bool {
    if region.planes.iter().any(|p| world.iter().all(|c| p.normal.dot(*c) > p.offset + 1e-4)) {
        return false;
    }
    match lens_box(world, view) {
        Some((lo, hi)) => {
            let a = view.screen.aspect();
            lo.x <= a && hi.x >= -a && lo.y <= 1.0 && hi.y >= -1.0
        }
        // Partly behind a perspective camera: seen unless wholly behind it.
        None => world.iter().any(|c| view.camera.to_ndc(*c, 1.0).is_some()),
    }
}

/// The box's projection in lens units; `None` when a corner lies behind the camera.
fn lens_box(world: &[Vec3; 8], view: &ViewFrame) -> Option<(Vec2, Vec2)> {
    let a = view.screen.aspect();
    let mut lo = Vec2::splat(f32::MAX);
    let mut hi = Vec2::splat(f32::MIN);
    for c in world {
        let (x, y) = view.camera.to_ndc(*c, a)?;
        let p = Vec2::new(x * a, y);
        lo = lo.min(p);
        hi = hi.max(p);
    }
    Some((lo, hi))
}

/// Dataset millimetres one pixel covers at the box (world corners `world`).
fn footprint(world: &[Vec3; 8], region: &Seen, view: &ViewFrame) -> f32 {
    let lo = world.iter().copied().fold(Vec3::splat(f32::MAX), Vec3::min);
    let hi = world.iter().copied().fold(Vec3::splat(f32::MIN), Vec3::max);
    let plain = match view.camera.projection {
        Projection::Perspective { fov_y } => {
            pixel_footprint(box_distance(view.camera.position, lo, hi), fov_y, view.screen.height as u32, 1.0)
        }
        Projection::Orthographic { height } => height / view.screen.height.max(1.0),
    };
    let magnification = match lens_box(world, view) {
        None => view.magnifiers.iter().map(|m| m.magnification).fold(1.0, f32::max),
        Some((blo, bhi)) => view
            .magnifiers
            .iter()
            .filter(|m| (m.center.clamp(blo, bhi) - m.center).length() <= m.reach)
            .map(|m| m.magnification)
            .fold(1.0, f32::max),
    };
    plain / magnification.max(1e-6) / largest_scale(&region.dataset_to_world)
}

/// The bricks of levels `0 … coarse − 1` the views want (coarse first), at most
/// `max_bricks` of the refinement (bricks of the coarse level itself, which the coarse
/// volume draws, are left out).
pub fn wanted(
    levels: &[SourceLevel],
    coarse: usize,
    layout: BrickLayout,
    regions: &[Seen],
    views: &[ViewFrame],
    max_bricks: usize,
) -> Vec<BrickKey> {
    if regions.is_empty() || views.is_empty() || coarse == 0 {
        return Vec::new();
    }
    let lensed = cut(levels, coarse, layout, regions, views, max_bricks);
    if views.iter().all(|v| v.magnifiers.is_empty()) {
        return lensed;
    }
    // Both cuts, coarsest first (the context's bricks are few, and most of the picture),
    // within the budget.
    let context: Vec<ViewFrame> = views.iter().map(|v| ViewFrame { magnifiers: Vec::new(), ..v.clone() }).collect();
    let mut chosen = cut(levels, coarse, layout, regions, &context, max_bricks);
    let known: HashSet<BrickKey> = chosen.iter().copied().collect();
    chosen.extend(lensed.into_iter().filter(|k| !known.contains(k)));
    chosen.sort_by_key(|k| std::cmp::Reverse(k.level));
    chosen.truncate(max_bricks);
    chosen
}

/// The cut of the pyramid `views` want through `regions` (the selection of [`wanted`]
/// for one set of views).
fn cut(
    levels: &[SourceLevel],
    coarse: usize,
    layout: BrickLayout,
    regions: &[Seen],
    views: &[ViewFrame],
    max_bricks: usize,
) -> Vec<BrickKey> {
    let levels = &levels[..=coarse.min(levels.len() - 1)];
    let each = |lo: Vec3, hi: Vec3, f: &mut dyn FnMut(&[Vec3; 8], &Seen, &ViewFrame)| {
        let local = corners(lo, hi);
        for r in regions {
            let world = local.map(|c| r.dataset_to_world.transform_point3(c));
            for v in views {
                f(&world, r, v);
            }
        }
    };
    let fp = |lo: Vec3, hi: Vec3| {
        let mut best = f32::MAX;
        each(lo, hi, &mut |w, r, v| {
            if visible(w, r, v) {
                best = best.min(footprint(w, r, v));
            }
        });
        best
    };
    let seen = |lo: Vec3, hi: Vec3| {
        let mut any = false;
        each(lo, hi, &mut |w, r, v| any |= visible(w, r, v));
        any
    };
    let coarse_bricks = {
        let n = layout.bricks(levels[coarse.min(levels.len() - 1)].grid.dims);
        (n.x * n.y * n.z) as usize
    };
    select(levels, layout, fp, seen, max_bricks + coarse_bricks).into_iter().filter(|k| (k.level as usize) < coarse).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::Grid;
    use crate::volume::source::{level_count, level_grid};
    use glam::UVec3;

    /// 512³ voxels of 1 mm centred at the origin in 32³ bricks: levels 512 … 32 (five).
    fn levels() -> Vec<SourceLevel> {
        let base = Grid::centered(UVec3::splat(512), Vec3::ONE);
        (0..level_count(base.dims, 32) as u32).map(|k| SourceLevel { grid: level_grid(&base, k), chunk: UVec3::splat(32) }).collect()
    }

    fn view(distance: f32, magnifiers: Vec<Magnified>) -> ViewFrame {
        let camera =
            Camera::look_at(Vec3::new(0.0, -distance, 0.0), Vec3::ZERO, Vec3::Z, Projection::Perspective { fov_y: 30f32.to_radians() });
        ViewFrame { camera, screen: Screen::new(256, 256), magnifiers }
    }

    fn whole() -> Seen {
        Seen { dataset_to_world: Affine3A::IDENTITY, planes: Vec::new() }
    }

    #[test]
    fn far_views_want_coarse_bricks_and_a_magnifier_native_ones_under_it() {
        let levels = levels();
        let layout = BrickLayout::new(32, 1);
        // 5 m to the centre, 4.744 m to the front: a pixel covers 2·4744·tan 15°/256 ≈
        // 9.9 mm there (11.0 at the back): level 3 throughout; the coarse level is 4.
        let far = wanted(&levels, 4, layout, &[whole()], &[view(5000.0, vec![])], 10_000);
        assert!(!far.is_empty() && far.iter().all(|k| k.level == 3), "{far:?}");
        // Nearer, 1.5 m: 2.6 mm a pixel at the front, 3.7 at the back: level 1.
        let near = wanted(&levels, 4, layout, &[whole()], &[view(1500.0, vec![])], 10_000);
        assert!(near.iter().any(|k| k.level == 1) && near.iter().all(|k| k.level >= 1), "finest {:?}", near.iter().map(|k| k.level).min());
        // An 8× magnifier in the middle of the far view: level 0 under it only.
        let lens = Magnified { center: Vec2::ZERO, reach: 0.05, magnification: 8.0 };
        let magnified = wanted(&levels, 4, layout, &[whole()], &[view(5000.0, vec![lens])], 10_000);
        let fine: Vec<_> = magnified.iter().filter(|k| k.level == 0).collect();
        assert!(!fine.is_empty(), "no native bricks under the lens");
        // Level-0 bricks lie near the view axis (x, z near 0, the lens' middle: its reach
        // of 0.05 lens units is about 65 mm, two bricks; a refined level-1 or level-2
        // brick brings all its children), through the whole depth.
        assert!(fine.iter().all(|k| (k.coords().x as i32 - 8).abs() <= 6 && (k.coords().z as i32 - 8).abs() <= 6), "{fine:?}");
        assert!(fine.iter().any(|k| k.coords().y == 0) && fine.iter().any(|k| k.coords().y == 15));
        // The context's own bricks (level 3 throughout) are wanted beside the lens's.
        assert!(far.iter().all(|k| magnified.contains(k)), "the context's cut is not wanted under a lens");
        let histogram: Vec<usize> = (0..4).map(|l| magnified.iter().filter(|k| k.level == l).count()).collect();
        // (Level 3's eight bricks all touch the view axis, so all are refined; level 2's
        // away from it stay, and level 0 covers under a fifth of the volume.)
        assert!(histogram[2] > 0 && histogram[0] < 4096 / 5, "the context stays coarse: {histogram:?}");
        // A region that magnifies the data 4× (a window) wants two levels finer.
        let window = Seen { dataset_to_world: Affine3A::from_scale(Vec3::splat(4.0)), planes: Vec::new() };
        // (6.024 m to the centre, 5 m to the front of the 2 m box: 10.5 world mm a pixel,
        // 2.6 of the data's.)
        let zoomed = wanted(&levels, 4, layout, &[window], &[view(6024.0, vec![])], 10_000);
        assert!(zoomed.iter().all(|k| k.level == 1), "{:?}", zoomed.iter().map(|k| k.level).collect::<std::collections::BTreeSet<_>>());
        // Behind the camera, nothing.
        let behind = Seen { dataset_to_world: Affine3A::from_translation(Vec3::new(0.0, -10_000.0, 0.0)), planes: Vec::new() };
        let cam = view(4000.0, vec![]);
        let w = corners(Vec3::splat(-10.0), Vec3::splat(10.0)).map(|c| behind.dataset_to_world.transform_point3(c));
        assert!(!visible(&w, &behind, &cam));
        // The budget caps the refinement.
        let capped = wanted(&levels, 4, layout, &[whole()], &[view(300.0, vec![])], 50);
        assert!(capped.len() <= 50 + 8);
    }
}
