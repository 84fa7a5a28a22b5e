//! Regions: the one rendering idea of Focal (see DESIGN.md, "One rendering idea").
//!
//! Everything that shows volume data is a [`Region`]: a convex polyhedron in world space
//! (a list of [`Plane`]s), an affine map from world space to the continuous voxel index
//! of one volume, and the index of an [`Appearance`]. A dataset on its own is one region
//! (its box, cut by clip planes); volumetric windows and exploded parts add regions with
//! other maps. The per-pixel function intersects the ray with every region, giving
//! intervals, and walks them front to back. This module holds the pure geometry, shared
//! by the CPU reference renderer, the GPU packing and the techniques that make regions;
//! [`appearance`] the looks (with two-level rendering's objects), [`appearance_spec`]
//! how scene files write them, [`camera`] cameras and rays, [`scene`] what a renderer
//! draws.

pub mod appearance;
pub mod appearance_spec;
pub mod camera;
pub mod scene;

use glam::{Affine3A, Vec3};

pub use appearance::{
    Appearance, Keep, Light, Lookup, MAX_CANDIDATES, MAX_OBJECTS, Mode, Object, ObjectTable, Segmentation, SelectionWeight, Shading,
};
pub use appearance_spec::{AppearanceSpec, LabelOverride, LabelsSpec, ObjectSpec, SegmentationSpec};
pub use camera::{Camera, Orbit, Projection, Ray, View};
pub use scene::RenderScene;

use crate::volume::Grid;

/// A half-space: points `p` with `normal · p ≤ offset` are inside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    pub normal: Vec3,
    pub offset: f32,
}

impl Plane {
    /// The half-space `normal · p ≤ normal · point` (normal pointing out of the region).
    pub fn through(point: Vec3, normal: Vec3) -> Plane {
        let n = normal.normalize_or_zero();
        Plane { normal: n, offset: n.dot(point) }
    }

    /// Signed distance of `p` outside the half-space (negative inside).
    pub fn distance(&self, p: Vec3) -> f32 {
        self.normal.dot(p) - self.offset
    }

    /// The same boundary with the other side inside.
    pub fn flipped(&self) -> Plane {
        Plane { normal: -self.normal, offset: -self.offset }
    }
}

/// The vertices of the convex polyhedron `planes` (points where three planes meet and
/// no plane excludes); empty when the polyhedron has no volume or is unbounded in a
/// way no three planes close.
pub fn vertices(planes: &[Plane]) -> Vec<Vec3> {
    use glam::Mat3;
    let mut out = Vec::new();
    let n = planes.len();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let (a, b, c) = (planes[i], planes[j], planes[k]);
                let m = Mat3::from_cols(a.normal, b.normal, c.normal).transpose();
                let det = m.determinant();
                if det.abs() < 1e-9 {
                    continue;
                }
                let p = m.inverse() * Vec3::new(a.offset, b.offset, c.offset);
                if planes.iter().all(|pl| pl.distance(p) <= 1e-4 * (1.0 + p.length())) {
                    out.push(p);
                }
            }
        }
    }
    out
}

/// The planes of the convex polyhedron `planes` that bound it: those with a face (three
/// vertices or more on them, of which two planes with the same face keep the first).
/// A polyhedron without volume is returned as it is.
pub fn bounding_planes(planes: &[Plane]) -> Vec<Plane> {
    let corners = vertices(planes);
    if !has_volume(planes) {
        return planes.to_vec();
    }
    let scale = corners.iter().map(|p| p.length()).fold(1.0, f32::max);
    let on = |pl: &Plane| corners.iter().filter(|p| pl.distance(**p).abs() <= 1e-4 * scale).count() >= 3;
    let mut out: Vec<Plane> = Vec::new();
    for pl in planes.iter().filter(|pl| on(pl)) {
        let same = |q: &Plane| (q.normal - pl.normal).length() < 1e-5 && (q.offset - pl.offset).abs() <= 1e-4 * scale;
        if !out.iter().any(same) {
            out.push(*pl);
        }
    }
    out
}

/// Whether the convex polyhedron `planes` has volume (its vertices do not all lie in
/// one plane).
pub fn has_volume(planes: &[Plane]) -> bool {
    let v = vertices(planes);
    if v.len() < 4 {
        return false;
    }
    let (lo, hi) = v.iter().fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(a, b), p| (a.min(*p), b.max(*p)));
    let scale = (hi - lo).max_element().max(1e-6);
    // Some vertex lies off the plane of three others by a noticeable fraction: a, the
    // vertex farthest from it, and the one farthest off their line (vertices repeat
    // where more than three planes meet, or planes do).
    let a = v[0];
    let Some(b) = v.iter().copied().max_by(|x, y| x.distance_squared(a).total_cmp(&y.distance_squared(a))) else { return false };
    let normal = v.iter().map(|p| (b - a).cross(*p - a)).max_by(|x, y| x.length().total_cmp(&y.length())).unwrap_or(Vec3::ZERO);
    let len = normal.length();
    len > 1e-9 * scale * scale && v.iter().any(|p| ((*p - a).dot(normal) / len).abs() > 1e-4 * scale)
}

/// Length of the longest diagonal of a box of `dims` voxels under the linear map
/// `voxel_to_world` (the largest of its four diagonals).
pub fn longest_diagonal(voxel_to_world: glam::Mat3, dims: Vec3) -> f32 {
    [Vec3::new(1.0, 1.0, 1.0), Vec3::new(1.0, -1.0, 1.0), Vec3::new(1.0, 1.0, -1.0), Vec3::new(1.0, -1.0, -1.0)]
        .iter()
        .map(|s| (voxel_to_world * (dims * *s)).length())
        .fold(0.0, f32::max)
}

/// A convex region of space showing one volume through an affine map, less any holes.
#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    pub planes: Vec<Plane>,
    /// Boxes cut out of the region (clip windows), six half-spaces each, normals out.
    /// A ray meets the region in its interval with the convex part less each hole's
    /// interval: at most one interval more per hole ([`subtract_interval`]).
    pub holes: Vec<[Plane; 6]>,
    /// World position → continuous voxel index of the volume.
    pub world_to_voxel: Affine3A,
    /// Index of the volume in the scene.
    pub volume: usize,
    /// Index of the appearance in the scene.
    pub appearance: usize,
}

impl Region {
    /// The box of a volume's voxel cells, showing that volume in place.
    pub fn volume_box(grid: &Grid, volume: usize, appearance: usize) -> Region {
        Self::volume_box_at(grid, Affine3A::IDENTITY, volume, appearance)
    }

    /// The box of a volume's voxel cells placed in the world by `transform` (the volume's
    /// own space → world).
    pub fn volume_box_at(grid: &Grid, transform: Affine3A, volume: usize, appearance: usize) -> Region {
        let world_to_voxel = grid.world_to_index() * transform.inverse();
        Region {
            planes: box_planes(&world_to_voxel, Vec3::splat(-0.5), grid.dims.as_vec3() - 0.5),
            holes: Vec::new(),
            world_to_voxel,
            volume,
            appearance,
        }
    }

    /// The region cut to the continuous voxel-index box `[lo, hi]` of its volume;
    /// planes that no longer bound it are dropped (so the box's planes replace the
    /// volume's, not add to them).
    pub fn cut_to_index_box(&self, lo: Vec3, hi: Vec3) -> Region {
        let mut planes = self.planes.clone();
        planes.extend(box_planes(&self.world_to_voxel, lo, hi));
        Region { planes: bounding_planes(&planes), ..self.clone() }
    }

    /// Adds a cutting plane (keeps the part with `normal · p ≤ offset`).
    pub fn clipped(mut self, plane: Plane) -> Region {
        self.planes.push(plane);
        self
    }

    /// Whether a world point lies inside (on the boundary counts as inside; inside a
    /// hole, off its boundary, does not).
    pub fn contains(&self, p: Vec3) -> bool {
        self.planes.iter().all(|pl| pl.distance(p) <= 1e-5) && !self.holes.iter().any(|h| h.iter().all(|pl| pl.distance(p) < -1e-5))
    }

    /// The parameter intervals of `origin + t·dir` inside the region, in increasing
    /// order: the convex part's interval less each hole's.
    pub fn intersect(&self, origin: Vec3, dir: Vec3) -> Vec<(f32, f32)> {
        let Some(whole) = ray_convex(&self.planes, origin, dir) else { return Vec::new() };
        let mut out = vec![whole];
        for hole in &self.holes {
            if let Some(cut) = ray_convex(hole, origin, dir) {
                out = out.into_iter().flat_map(|iv| subtract_interval(iv, cut)).collect();
            }
        }
        out
    }
}

/// Whether convex regions share volume that no hole of theirs holds (the renderer's
/// test of which regions a ray can be inside at once).
pub fn meet(regions: &[&Region]) -> bool {
    let all: Vec<Plane> = regions.iter().flat_map(|r| r.planes.iter().copied()).collect();
    if !has_volume(&all) {
        return false;
    }
    let corners = vertices(&all);
    let holds = |hole: &[Plane; 6]| corners.iter().all(|p| hole.iter().all(|pl| pl.distance(*p) <= 1e-4 * (1.0 + p.length())));
    !regions.iter().flat_map(|r| r.holes.iter()).any(holds)
}

/// `[a, b]` less the open interval `(c, d)`: none, one or two closed intervals (the
/// shader does the same in `region_intervals`).
pub fn subtract_interval((a, b): (f32, f32), (c, d): (f32, f32)) -> impl Iterator<Item = (f32, f32)> {
    let overlaps = c < b && d > a && c < d;
    let left = (overlaps && c > a).then_some((a, c));
    let right = (overlaps && d < b).then_some((d, b));
    let whole = (!overlaps).then_some((a, b));
    whole.into_iter().chain(left).chain(right)
}

/// Clips a ray against a convex set of half-spaces (Cyrus–Beck / Kay–Kajiya slabs):
/// each plane with `n·d < 0` can only raise the entry, `n·d > 0` only lowers the exit, and
/// a ray parallel to a plane is either wholly inside or wholly outside it.
pub fn ray_convex(planes: &[Plane], origin: Vec3, dir: Vec3) -> Option<(f32, f32)> {
    let (mut t0, mut t1) = (f32::NEG_INFINITY, f32::INFINITY);
    for p in planes {
        let denom = p.normal.dot(dir);
        let dist = p.offset - p.normal.dot(origin);
        if denom.abs() < 1e-12 {
            if dist < 0.0 {
                return None;
            }
            continue;
        }
        let t = dist / denom;
        if denom < 0.0 {
            t0 = t0.max(t);
        } else {
            t1 = t1.min(t);
        }
        if t0 > t1 {
            return None;
        }
    }
    (t0 <= t1).then_some((t0, t1))
}

/// World planes of the index-space box `[lo, hi]` under `world_to_index`
/// (`q = A·p + t`): the index plane `m·q ≤ c` is the world plane `(Aᵀm)·p ≤ c − m·t`.
pub fn box_planes(world_to_index: &Affine3A, lo: Vec3, hi: Vec3) -> Vec<Plane> {
    let a = glam::Mat3::from(world_to_index.matrix3);
    let t = Vec3::from(world_to_index.translation);
    let mut planes = Vec::with_capacity(6);
    for axis in 0..3 {
        let e = Vec3::AXES[axis];
        for (m, c) in [(e, hi[axis]), (-e, -lo[axis])] {
            let n = a.transpose() * m;
            let len = n.length();
            planes.push(Plane { normal: n / len, offset: (c - m.dot(t)) / len });
        }
    }
    planes
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Mat3, UVec3};

    #[test]
    fn volume_and_bounding_planes_with_repeated_planes() {
        let unit = box_planes(&Affine3A::IDENTITY, Vec3::ZERO, Vec3::ONE);
        assert!(has_volume(&unit));
        // The same box given twice (a region cut to a box it already had): its vertices
        // repeat, it still has volume, and each face keeps one plane.
        let twice: Vec<Plane> = unit.iter().chain(&unit).copied().collect();
        assert!(has_volume(&twice));
        assert_eq!(bounding_planes(&twice).len(), 6);
        // Cut to a slab of no thickness: no volume.
        let mut flat = twice.clone();
        flat.push(Plane { normal: Vec3::X, offset: 0.0 });
        assert!(!has_volume(&flat));
        // Cut by a plane through it: volume, seven planes of which the far x face goes.
        let mut cut = unit.clone();
        cut.push(Plane { normal: Vec3::X, offset: 0.5 });
        assert!(has_volume(&cut));
        assert_eq!(bounding_planes(&cut).len(), 6);
    }

    #[test]
    fn ray_box_entry_and_exit() {
        let g = Grid::new(UVec3::new(10, 10, 10), Vec3::splat(2.0)); // box from −1 to 19 mm
        let r = Region::volume_box(&g, 0, 0);
        let (t0, t1) = r.intersect(Vec3::new(-11.0, 5.0, 5.0), Vec3::X)[0];
        assert!((t0 - 10.0).abs() < 1e-5 && (t1 - 30.0).abs() < 1e-5, "{t0} {t1}");
        assert!(r.intersect(Vec3::new(-11.0, 25.0, 5.0), Vec3::X).is_empty());
        // Parallel ray outside a slab misses; inside it hits.
        assert!(r.intersect(Vec3::new(5.0, -5.0, 5.0), Vec3::Z).is_empty());
        assert!(r.contains(Vec3::new(0.0, 0.0, 0.0)));
        assert!(!r.contains(Vec3::new(-1.5, 0.0, 0.0)));
    }

    #[test]
    fn cutting_to_an_index_box_replaces_the_box_planes() {
        // Voxels 0..9 at 1 mm: the box −0.5 … 9.5; cut to voxels 2 … 5 (1.5 … 5.5 mm along
        // x, the whole box otherwise) with a clip plane at y ≤ 7 kept.
        let g = Grid::new(glam::UVec3::splat(10), Vec3::ONE);
        let r = Region::volume_box(&g, 0, 0).clipped(Plane::through(Vec3::new(0.0, 7.0, 0.0), Vec3::Y));
        let cut = r.cut_to_index_box(Vec3::new(1.5, -0.5, -0.5), Vec3::new(5.5, 9.5, 9.5));
        assert_eq!(cut.planes.len(), 6, "{:?}", cut.planes);
        let (t0, t1) = cut.intersect(Vec3::new(-10.0, 4.0, 4.0), Vec3::X)[0];
        assert!((t0 - 11.5).abs() < 1e-4 && (t1 - 15.5).abs() < 1e-4, "{t0} {t1}");
        let (_, t1) = cut.intersect(Vec3::new(3.0, -10.0, 4.0), Vec3::Y)[0];
        assert!((t1 - 17.0).abs() < 1e-4, "the clip plane stays: {t1}");
        // Redundant planes go, whatever their order; a face's twin is kept once.
        let twice: Vec<Plane> = r.planes.iter().chain(&r.planes).copied().collect();
        assert_eq!(bounding_planes(&twice).len(), 6);
    }

    #[test]
    fn holes_split_intervals_and_points() {
        // By hand: [0, 10] less (2, 4) is [0, 2] and [4, 10]; less (−1, 3): [3, 10];
        // less (8, 12): [0, 8]; less (−1, 11): nothing; less (11, 12): itself.
        let cut = |c| subtract_interval((0.0, 10.0), c).collect::<Vec<_>>();
        assert_eq!(cut((2.0, 4.0)), vec![(0.0, 2.0), (4.0, 10.0)]);
        assert_eq!(cut((-1.0, 3.0)), vec![(3.0, 10.0)]);
        assert_eq!(cut((8.0, 12.0)), vec![(0.0, 8.0)]);
        assert!(cut((-1.0, 11.0)).is_empty());
        assert_eq!(cut((11.0, 12.0)), vec![(0.0, 10.0)]);
        // A box of voxels 0..9 (−0.5 … 9.5 mm) with the cube 3..5 mm cut out: a ray along
        // x through the hole meets [−0.5, 3] and [5, 9.5]; one beside it the whole box.
        let g = Grid::new(glam::UVec3::splat(10), Vec3::ONE);
        let mut r = Region::volume_box(&g, 0, 0);
        let hole = box_planes(&glam::Affine3A::IDENTITY, Vec3::splat(3.0), Vec3::splat(5.0));
        r.holes.push(std::array::from_fn(|i| hole[i]));
        let through = r.intersect(Vec3::new(-10.0, 4.0, 4.0), Vec3::X);
        assert_eq!(through.len(), 2);
        assert!((through[0].0 - 9.5).abs() < 1e-5 && (through[0].1 - 13.0).abs() < 1e-5, "{through:?}");
        assert!((through[1].0 - 15.0).abs() < 1e-5 && (through[1].1 - 19.5).abs() < 1e-5, "{through:?}");
        assert_eq!(r.intersect(Vec3::new(-10.0, 6.0, 4.0), Vec3::X).len(), 1);
        assert!(!r.contains(Vec3::splat(4.0)) && r.contains(Vec3::new(4.0, 6.0, 4.0)) && r.contains(Vec3::new(3.0, 4.0, 4.0)));
    }

    #[test]
    fn oblique_boxes_and_clip_planes() {
        // Box rotated 90° about z: index x runs along world y.
        let axes = Mat3::from_cols(Vec3::Y, -Vec3::X, Vec3::Z);
        let g = Grid::from_axes(UVec3::new(4, 2, 2), axes, Vec3::ZERO).unwrap();
        let r = Region::volume_box(&g, 0, 0);
        // Along world y the box spans index x from −0.5 to 3.5.
        let (t0, t1) = r.intersect(Vec3::new(0.0, -10.0, 0.5), Vec3::Y)[0];
        assert!((t0 - 9.5).abs() < 1e-5 && (t1 - 13.5).abs() < 1e-5, "{t0} {t1}");
        // Clip away y > 1.
        let c = r.clipped(Plane::through(Vec3::new(0.0, 1.0, 0.0), Vec3::Y));
        let (_, t1) = c.intersect(Vec3::new(0.0, -10.0, 0.5), Vec3::Y)[0];
        assert!((t1 - 11.0).abs() < 1e-5);
        // Moved 5 mm along y: the box moves with it, and so does the voxel map.
        let moved = Region::volume_box_at(&g, Affine3A::from_translation(Vec3::Y * 5.0), 0, 0);
        let (t0, _) = moved.intersect(Vec3::new(0.0, -10.0, 0.5), Vec3::Y)[0];
        assert!((t0 - 14.5).abs() < 1e-5, "{t0}");
        assert!((moved.world_to_voxel.transform_point3(Vec3::new(0.0, 5.0, 0.0)) - Vec3::ZERO).length() < 1e-5);
        assert_eq!(Plane::through(Vec3::ONE, Vec3::X).flipped().distance(Vec3::ZERO), 1.0);
    }
}
