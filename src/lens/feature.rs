//! The feature lens (Wang et al. 2005, §3.2): a magnifier whose focus region is a
//! segmented feature as projected in the current view. Rays through the feature's
//! projection bend to the virtual focal point, rays within `lb` of it bend by their
//! distance `d` to it, the others go straight — the drawn-outline magnifier with the
//! outline replaced by the feature's silhouette.
//!
//! Per view and frame:
//! 1. **Feature mask** on a coarse grid over the image ([`FIELD_ROWS`] rows): a cell is
//!    inside when the camera's own ray through its centre meets a voxel of the feature
//!    (a label of a label volume), found by marching the label volume with nearest
//!    sampling every half voxel. The march crosses only the label's box (the bricks
//!    whose code range holds it, [`crate::volume::BrickGrid::code_box`], a voxel
//!    wider): the samples outside it cannot meet the label, so the mask is the whole
//!    march's, and rays that miss the box take none.
//! 2. **Distance transform** of the mask: the exact Euclidean distance of every cell to
//!    the nearest inside cell and, inside, to the nearest outside cell (Felzenszwalb and
//!    Huttenlocher's separable lower-envelope algorithm), turned into a signed distance
//!    to the silhouette in lens units (half a cell off the cell centres).
//! 3. The lens centre is the silhouette's centroid (the central ray and `F` go through
//!    it) and its radius the equivalent radius `lr = √(area/π)`; the radial coordinate is
//!    `r = lr + d(s)`, as for a drawn outline ([`super::shape`]).
//!
//! The GPU does all three each frame in compute passes (`shaders/feature.wgsl`): the
//! same mask, then jump flooding (Rong and Tan 2006, with one extra pass of step 1)
//! for the nearest inside and outside cells, atomic sums for the centroid and area.
//! The lens systems then only describe the work ([`FeatureJob`]); the functions here
//! are the CPU reference (and serve the CPU renderer and the app's overlays). Jump
//! flooding is not exact: a few cells may take a seed slightly farther than the nearest.
//! Because the centre is only known after the mask, a feature lens takes its focus
//! depth on the view axis (through the image centre), not through its centroid.

use glam::Vec2;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::screen::Screen;
use crate::region::{Camera, Plane, RenderScene, box_planes, ray_convex};

/// Rows of the feature grid (columns follow the aspect ratio).
pub const FIELD_ROWS: u32 = 96;

/// Which feature a lens follows.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FeatureRef {
    /// The label.
    pub label: u32,
    /// Index of the region (visible dataset, in order) holding the label volume; by
    /// default the first region shown with labels.
    #[serde(default)]
    pub region: Option<usize>,
}

/// Floats before a silhouette's distances in the shader's buffer: centroid (2), the
/// equivalent radius, and 1 when the feature is in view (0 when not).
pub const FIELD_HEADER: usize = 4;

/// The grid of a feature's silhouette over one screen: [`FIELD_ROWS`] rows of square
/// cells (in lens units) covering the image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeatureGrid {
    pub cols: u32,
    pub rows: u32,
    /// Lens coordinates of the centre of cell (0, 0) (top left).
    pub origin: Vec2,
    /// Cell size (lens units; horizontal and vertical, equal up to rounding).
    pub step: Vec2,
}

impl FeatureGrid {
    pub fn of(screen: Screen) -> FeatureGrid {
        let (cols, rows) = ((FIELD_ROWS as f32 * screen.aspect()).round().max(1.0) as u32, FIELD_ROWS);
        let step = Vec2::new(2.0 * screen.aspect() / cols as f32, 2.0 / rows as f32);
        FeatureGrid { cols, rows, origin: Vec2::new(-screen.aspect() + 0.5 * step.x, 1.0 - 0.5 * step.y), step }
    }

    pub fn cells(&self) -> usize {
        (self.cols * self.rows) as usize
    }

    /// Lens coordinates of the centre of cell `i` (row major, top row first).
    pub fn centre(&self, i: usize) -> Vec2 {
        let c = self.cols as usize;
        self.origin + Vec2::new((i % c) as f32 * self.step.x, -((i / c) as f32) * self.step.y)
    }
}

/// What the GPU needs to find a feature's silhouette: the region holding the label
/// volume (index among the scene's regions), the label, the marching step (world units,
/// half the finest voxel spacing), the grid, and the world planes of a box outside
/// which no sample meets the label (`None`: the volume holds none of it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeatureJob {
    pub region: u32,
    pub label: u32,
    pub step: f32,
    pub grid: FeatureGrid,
    pub within: Option<[Plane; 6]>,
}

/// Voxels the box a mask marches is widened by on every side, beyond the bricks that
/// can hold the label (so rounding at its faces cannot lose a sample of it).
const WITHIN_MARGIN: f32 = 1.0;

impl FeatureJob {
    /// The job of `feature` in `scene` over `screen`; `None` when no region shows it.
    pub fn new(scene: &RenderScene, feature: &FeatureRef, screen: Screen) -> Option<FeatureJob> {
        let region = feature_region(scene, feature)?;
        let volume = scene.volumes.get(scene.regions[region].volume)?;
        let world_to_voxel = &scene.regions[region].world_to_voxel;
        let within = volume
            .bricks()
            .code_box(feature.label)
            .and_then(|(lo, hi)| box_planes(world_to_voxel, lo - WITHIN_MARGIN, hi + WITHIN_MARGIN).try_into().ok());
        Some(FeatureJob {
            region: region as u32,
            label: feature.label,
            step: 0.5 * volume.grid.min_spacing(),
            grid: FeatureGrid::of(screen),
            within,
        })
    }
}

/// Where a mask's march of the samples `start + (k + ½)·step` (k = 0, 1, …) begins on a
/// ray that enters the label's box at `entry` (`shaders/feature.wgsl` does the same):
/// the last k before the entry (0 where the ray starts inside), so that rounding cannot
/// lose a sample inside the box; the samples after it are those a march from `start`
/// takes.
pub fn first_sample(start: f32, entry: f32, step: f32) -> u32 {
    let k = ((entry - start) / step - 0.5).floor();
    if k.is_nan() || k <= 0.0 { 0 } else { k.min(u32::MAX as f32) as u32 }
}

/// A feature's silhouette in one view: its signed distance field on the grid.
#[derive(Clone, Debug, PartialEq)]
pub struct FeatureField {
    /// The cells (their centres and size in lens units).
    pub grid: FeatureGrid,
    /// Signed distance to the silhouette per cell, lens units, negative inside (row
    /// major, top row first).
    pub distance: Vec<f32>,
    /// Centroid of the silhouette (lens units) and its area (lens units²).
    pub centroid: Vec2,
    pub area: f32,
}

/// Squared Euclidean distance transform in one dimension (lower envelope of parabolas).
fn edt_1d(f: &[f32], out: &mut [f32]) {
    let n = f.len();
    let mut v = vec![0usize; n];
    let mut z = vec![0f32; n + 1];
    let mut k = 0usize;
    z[0] = f32::NEG_INFINITY;
    z[1] = f32::INFINITY;
    let mut first = None;
    for q in 0..n {
        if !f[q].is_finite() {
            continue;
        }
        if first.is_none() {
            first = Some(q);
            v[0] = q;
            continue;
        }
        loop {
            let p = v[k];
            let s = ((f[q] + (q * q) as f32) - (f[p] + (p * p) as f32)) / (2.0 * (q as f32 - p as f32));
            if s <= z[k] && k > 0 {
                k -= 1;
                continue;
            }
            if s <= z[k] {
                // k == 0 and the new parabola dominates everywhere.
                v[0] = q;
                z[1] = f32::INFINITY;
                break;
            }
            k += 1;
            v[k] = q;
            z[k] = s;
            z[k + 1] = f32::INFINITY;
            break;
        }
    }
    if first.is_none() {
        out.iter_mut().for_each(|o| *o = f32::INFINITY);
        return;
    }
    k = 0;
    for (q, o) in out.iter_mut().enumerate() {
        while z[k + 1] < q as f32 {
            k += 1;
        }
        let p = v[k];
        let d = q as f32 - p as f32;
        *o = d * d + f[p];
    }
}

/// Euclidean distance (in cells) from every cell to the nearest cell where `seed` holds
/// (infinity when there is none).
pub fn distance_transform(seed: &[bool], cols: usize, rows: usize) -> Vec<f32> {
    let mut g: Vec<f32> = seed.iter().map(|&s| if s { 0.0 } else { f32::INFINITY }).collect();
    let mut line = vec![0f32; cols.max(rows)];
    let mut out = vec![0f32; cols.max(rows)];
    for x in 0..cols {
        for y in 0..rows {
            line[y] = g[y * cols + x];
        }
        edt_1d(&line[..rows], &mut out[..rows]);
        for y in 0..rows {
            g[y * cols + x] = out[y];
        }
    }
    for y in 0..rows {
        line[..cols].copy_from_slice(&g[y * cols..(y + 1) * cols]);
        edt_1d(&line[..cols], &mut out[..cols]);
        g[y * cols..(y + 1) * cols].copy_from_slice(&out[..cols]);
    }
    g.into_iter().map(f32::sqrt).collect()
}

impl FeatureField {
    /// The field of a mask over a screen (`cols × rows` cells covering the image); `None`
    /// when the mask is empty.
    pub fn from_mask(mask: &[bool], grid: FeatureGrid) -> Option<FeatureField> {
        let (cols, rows) = (grid.cols, grid.rows);
        let (c, r) = (cols as usize, rows as usize);
        let inside = mask.iter().filter(|&&m| m).count();
        if inside == 0 {
            return None;
        }
        let step = grid.step;
        let cell = step.y;
        let to_in = distance_transform(mask, c, r);
        let outside: Vec<bool> = mask.iter().map(|m| !m).collect();
        let to_out = distance_transform(&outside, c, r);
        // A feature covering the whole grid has no outside: its cells lie at least their
        // distance to the grid's edge inside it.
        let to_edge = |i: usize| {
            let (x, y) = (i % c, i / c);
            (x.min(c - 1 - x).min(y).min(r - 1 - y) + 1) as f32
        };
        let distance = mask
            .iter()
            .enumerate()
            .map(|(i, &m)| {
                if !m {
                    (to_in[i] - 0.5) * cell
                } else if to_out[i].is_finite() {
                    -(to_out[i] - 0.5) * cell
                } else {
                    -(to_edge(i) - 0.5) * cell
                }
            })
            .collect();
        let mut sum = Vec2::ZERO;
        for (i, _) in mask.iter().enumerate().filter(|(_, m)| **m) {
            sum += grid.centre(i);
        }
        Some(FeatureField { grid, distance, centroid: sum / inside as f32, area: inside as f32 * step.x * step.y })
    }

    /// The header the shader reads before the distances ([`FIELD_HEADER`]).
    pub fn header(&self) -> [f32; FIELD_HEADER] {
        [self.centroid.x, self.centroid.y, self.equivalent_radius(), 1.0]
    }

    /// Equivalent radius `√(area/π)`.
    pub fn equivalent_radius(&self) -> f32 {
        (self.area / std::f32::consts::PI).sqrt()
    }

    /// Signed distance at lens coordinates `s` (bilinear between cell centres; beyond
    /// the grid, the edge value plus the distance to the edge).
    pub fn distance_at(&self, s: Vec2) -> f32 {
        let g = &self.grid;
        let gx = (s.x - g.origin.x) / g.step.x;
        let gy = (g.origin.y - s.y) / g.step.y;
        let (maxx, maxy) = ((g.cols - 1) as f32, (g.rows - 1) as f32);
        let (x, y) = (gx.clamp(0.0, maxx), gy.clamp(0.0, maxy));
        let beyond = Vec2::new((gx - x) * g.step.x, (gy - y) * g.step.y).length();
        let (x0, y0) = (x.floor() as usize, y.floor() as usize);
        let (x1, y1) = ((x0 + 1).min(g.cols as usize - 1), (y0 + 1).min(g.rows as usize - 1));
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let at = |x: usize, y: usize| self.distance[y * g.cols as usize + x];
        let top = at(x0, y0) + (at(x1, y0) - at(x0, y0)) * fx;
        let bottom = at(x0, y1) + (at(x1, y1) - at(x0, y1)) * fx;
        top + (bottom - top) * fy + beyond
    }
}

/// The region showing a feature: the one named, or the first shown with labels.
fn feature_region(scene: &RenderScene, feature: &FeatureRef) -> Option<usize> {
    let labels = |i: &usize| {
        scene.appearances.get(scene.regions[*i].appearance).is_some_and(|a| matches!(a.lookup, crate::region::Lookup::Labels(_)))
    };
    match feature.region {
        Some(i) => (i < scene.regions.len()).then_some(i),
        None => (0..scene.regions.len()).find(labels),
    }
}

/// The feature mask of a job seen by `camera` over `screen`.
pub fn feature_mask(scene: &RenderScene, job: &FeatureJob, camera: &Camera, screen: Screen) -> Vec<bool> {
    let (cols, rows) = (job.grid.cols, job.grid.rows);
    let Some(region) = scene.regions.get(job.region as usize) else { return vec![false; job.grid.cells()] };
    let Some(volume) = scene.volumes.get(region.volume) else { return vec![false; job.grid.cells()] };
    let Some(within) = job.within else { return vec![false; job.grid.cells()] };
    let sampler = volume.sampler();
    let (label, step) = (job.label, job.step);
    (0..rows * cols)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % cols, i / cols);
            let px = (x as f32 + 0.5) / cols as f32 * screen.width;
            let py = (y as f32 + 0.5) / rows as f32 * screen.height;
            let ray = camera.ray(px, py, screen.width as u32, screen.height as u32);
            let Some((entry, exit)) = ray_convex(&within, ray.origin, ray.dir) else { return false };
            region.intersect(ray.origin, ray.dir).into_iter().any(|(t0, t1)| {
                let start = t0.max(0.0);
                let end = t1.min(exit);
                (first_sample(start, entry, step)..)
                    .map(|k| start + (k as f32 + 0.5) * step)
                    .take_while(|&t| t < end)
                    .any(|t| sampler.nearest(region.world_to_voxel.transform_point3(ray.at(t))) as u32 == label)
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance_transform_is_euclidean() {
        // One seed in a 5×4 grid: distances are Euclidean by hand.
        let mut seed = vec![false; 20];
        seed[6] = true; // (1, 1)
        let d = distance_transform(&seed, 5, 4);
        assert_eq!(d[6], 0.0);
        assert!((d[0] - 2f32.sqrt()).abs() < 1e-6);
        assert!((d[19] - (9.0f32 + 4.0).sqrt()).abs() < 1e-6, "{}", d[19]);
        assert!((d[9] - (9.0f32 + 0.0).sqrt()).abs() < 1e-6);
        // Two seeds: the nearer one counts.
        seed[18] = true; // (3, 3)
        let d = distance_transform(&seed, 5, 4);
        assert!((d[19] - 1.0).abs() < 1e-6);
        // Brute force on a random mask.
        let mask: Vec<bool> = (0..77u32).map(|i| (i.wrapping_mul(2_654_435_761) >> 28) == 3).collect();
        let d = distance_transform(&mask, 11, 7);
        for (i, &got) in d.iter().enumerate() {
            let want = (0..77)
                .filter(|&j| mask[j])
                .map(|j| {
                    let (dx, dy) = ((i % 11) as f32 - (j % 11) as f32, (i / 11) as f32 - (j / 11) as f32);
                    (dx * dx + dy * dy).sqrt()
                })
                .fold(f32::INFINITY, f32::min);
            assert!((got - want).abs() < 1e-5 || (want.is_infinite() && got.is_infinite()), "cell {i}: {got} vs {want}");
        }
    }

    #[test]
    fn a_disc_gives_its_centroid_radius_and_distances() {
        // A disc of radius 0.4 lens units centred at (0.2, -0.1) on a square screen.
        let screen = Screen::new(200, 200);
        let grid = FeatureGrid::of(screen);
        let (cols, rows) = (grid.cols, grid.rows);
        let centre = Vec2::new(0.2, -0.1);
        let cell = 2.0 / rows as f32;
        let mask: Vec<bool> = (0..cols * rows)
            .map(|i| {
                let p = Vec2::new(-1.0 + (i % cols) as f32 * cell + 0.5 * cell, 1.0 - (i / cols) as f32 * cell - 0.5 * cell);
                (p - centre).length() < 0.4
            })
            .collect();
        let f = FeatureField::from_mask(&mask, grid).unwrap();
        assert!((f.centroid - centre).length() < 0.01, "{}", f.centroid);
        assert!((f.equivalent_radius() - 0.4).abs() < 0.01, "{}", f.equivalent_radius());
        // Distances to the silhouette, inside and out, within a cell.
        for (s, want) in
            [(centre, -0.4), (centre + Vec2::new(0.6, 0.0), 0.2), (centre + Vec2::new(0.0, 0.3), -0.1), (Vec2::new(-0.9, 0.9), 0.0)]
        {
            let want = if want == 0.0 { (Vec2::new(-0.9, 0.9) - centre).length() - 0.4 } else { want };
            let d = f.distance_at(s);
            assert!((d - want).abs() < 1.5 * cell, "{s}: {d} vs {want}");
        }
        assert!(FeatureField::from_mask(&vec![false; mask.len()], grid).is_none());
        // A feature filling the view stays a finite field (a zoom into the feature).
        let full = FeatureField::from_mask(&vec![true; mask.len()], grid).unwrap();
        assert!(full.distance.iter().all(|d| d.is_finite() && *d < 0.0));
        assert!(full.distance_at(Vec2::ZERO).is_finite() && full.distance_at(Vec2::new(3.0, 0.0)).is_finite());
    }

    /// A scene of the labelled head phantom (48³) shown as labels.
    fn labelled_head() -> (crate::scene::SceneFile, Vec<crate::scene::load::LoadedDataset>, RenderScene) {
        use crate::scene::load::{load_datasets, render_scene};
        let file =
            crate::scene::SceneFile::parse("(datasets: [(source: PhantomLabels(resolution: 48), appearance: (labels: Some(())))])", "t")
                .unwrap();
        let datasets = load_datasets(&file, std::path::Path::new(".")).unwrap();
        let scene = render_scene(&datasets, &file);
        (file, datasets, scene)
    }

    #[test]
    fn the_first_sample_is_the_last_before_the_entry() {
        // Samples at 1 + (k + ½)·2 = 2, 4, 6, …: entering at 7 the march starts at k = 2
        // (t = 6), at 6 exactly at k = 2 (t = 6: one before rounding can), before the
        // start at k = 0.
        assert_eq!(first_sample(1.0, 7.0, 2.0), 2);
        assert_eq!(first_sample(1.0, 6.0, 2.0), 2);
        assert_eq!(first_sample(1.0, 6.5, 2.0), 2);
        assert_eq!(first_sample(1.0, 8.1, 2.0), 3);
        assert_eq!(first_sample(1.0, -5.0, 2.0), 0);
        assert_eq!(first_sample(1.0, f32::NEG_INFINITY, 2.0), 0);
    }

    #[test]
    fn the_label_box_leaves_every_mask_as_the_whole_march() {
        use crate::region::Orbit;
        use glam::Vec3;
        let (_, _, scene) = labelled_head();
        let screen = Screen::new(96, 96);
        let ventricles = FeatureRef { label: crate::volume::phantom::head::label::VENTRICLES as u32, region: None };
        let job = FeatureJob::new(&scene, &ventricles, screen).unwrap();
        // The whole march: a box that holds the volume.
        let region = &scene.regions[job.region as usize];
        let dims = scene.volumes[region.volume].grid.dims.as_vec3();
        let everywhere = box_planes(&region.world_to_voxel, Vec3::splat(-1.0), dims).try_into().ok();
        let whole = FeatureJob { within: everywhere, ..job };
        let (centre, radius) = scene.bounding_sphere();
        let (mut inside, mut missed) = (0, 0);
        for (azimuth, elevation) in [(0.0, 0.0), (37.0, 20.0), (90.0, -10.0), (200.0, 60.0)] {
            let camera = Orbit {
                target: centre,
                azimuth_deg: azimuth,
                elevation_deg: elevation,
                distance: 3.0 * radius,
                projection: crate::region::Projection::Perspective { fov_y: 30f32.to_radians() },
            }
            .camera();
            let mask = feature_mask(&scene, &job, &camera, screen);
            assert_eq!(mask, feature_mask(&scene, &whole, &camera, screen), "azimuth {azimuth}");
            inside += mask.iter().filter(|m| **m).count();
            let within = job.within.unwrap();
            missed += (0..job.grid.cells() as u32)
                .filter(|i| {
                    let (x, y) = (i % job.grid.cols, i / job.grid.cols);
                    let ray =
                        camera.ray((x as f32 + 0.5) / job.grid.cols as f32 * 96.0, (y as f32 + 0.5) / job.grid.rows as f32 * 96.0, 96, 96);
                    ray_convex(&within, ray.origin, ray.dir).is_none()
                })
                .count();
        }
        // The ventricles are in view, and most rays miss their box (and march nothing).
        assert!(inside > 100, "{inside}");
        assert!(missed > 2 * job.grid.cells(), "{missed} of {}", 4 * job.grid.cells());
        // A label the volume lacks has no box and an empty mask.
        let absent = FeatureJob::new(&scene, &FeatureRef { label: 200, region: None }, screen).unwrap();
        assert!(absent.within.is_none());
    }

    #[test]
    fn a_feature_lens_bends_the_rays_through_its_silhouette() {
        use crate::lens::stack::{lens_ray, resolve_in};
        use crate::lens::{Lens, Shape};
        use crate::scene::load::{camera, visible_bounds};
        let (file, datasets, scene) = labelled_head();
        let cam = camera(&file.camera, visible_bounds(&datasets), 1.0);
        let screen = Screen::new(120, 120);
        let ventricles = FeatureRef { label: crate::volume::phantom::head::label::VENTRICLES as u32, region: None };
        let lens = Lens { shape: Shape::Feature(ventricles), ..Lens::magnifier(Vec2::ZERO, 0.3, 0.15, 2.0) };
        let resolved = resolve_in(&lens, &cam, screen, &scene).expect("the ventricles are in view");
        let field = resolved.field.clone().unwrap();
        assert!(field.area > 0.005 && field.area < 1.0, "{}", field.area);
        assert_eq!(resolved.center, field.centroid);
        // A circular magnifier with the same centre covering the whole image: inside the
        // silhouette the feature lens bends rays exactly as its focus region does.
        // (A feature lens takes its focus depth on the view axis.)
        let mut cover = crate::lens::stack::resolve(&Lens::magnifier(Vec2::ZERO, 4.0, 0.0, 2.0), &cam, screen, scene.bounding_sphere());
        cover.center = field.centroid;
        let (mut inside, mut outside) = (0, 0);
        for py in (0..120).step_by(3) {
            for px in (0..120).step_by(3) {
                let (x, y) = (px as f32 + 0.5, py as f32 + 0.5);
                let d = field.distance_at(screen.to_lens(x, y));
                let ray = lens_ray(&cam, screen, std::slice::from_ref(&resolved), x, y).unwrap();
                if d < -0.01 {
                    let focus = lens_ray(&cam, screen, std::slice::from_ref(&cover), x, y).unwrap();
                    assert!((ray.dir - focus.dir).length() < 1e-5, "({px}, {py})");
                    inside += 1;
                } else if d > resolved.border + 0.01 {
                    assert_eq!(ray, cam.ray(x, y, 120, 120), "({px}, {py})");
                    outside += 1;
                }
            }
        }
        assert!(inside > 5 && outside > 100, "{inside} {outside}");
        // A label nobody has: no lens.
        let none = Lens { shape: Shape::Feature(FeatureRef { label: 200, region: None }), ..lens };
        assert!(resolve_in(&none, &cam, screen, &scene).is_none());
    }
}
