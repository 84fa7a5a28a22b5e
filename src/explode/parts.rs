//! Convex parts of an exploded dataset and splitting them (Bruckner and Gröller 2006,
//! section 3.1).
//!
//! The background (everything not selected) starts as one part, the dataset's box, and
//! is cut into convex parts by planes. A part is a convex polyhedron given by half-spaces
//! in the dataset's own frame (so it moves with the dataset), with its vertices for the
//! forces (the return force acts at them) and the collider (their convex hull). Splitting
//! a part by a plane gives the two halves `P ∩ {n·p ≤ d}` and `P ∩ {n·p ≥ d}`: they
//! partition it, and a plane that misses the part (one half without volume) leaves it
//! whole.

use glam::Vec3;

use crate::region::{Plane, bounding_planes, has_volume, vertices};

/// A convex polyhedron in a dataset's own frame, with what the forces ask of it every
/// step (its centroid, volume and radius, each face's plane) computed once.
#[derive(Clone, Debug, PartialEq)]
pub struct Polyhedron {
    /// Half-spaces (normals out), only those that bound it.
    pub planes: Vec<Plane>,
    /// Its vertices.
    pub vertices: Vec<Vec3>,
    /// Each face's vertices in order around it (one face per plane).
    pub faces: Vec<Vec<Vec3>>,
    /// The plane of each face (unit normal out).
    face_planes: Vec<Plane>,
    /// Each face's edges: start, direction to the end, 1 / its squared length.
    edges: Vec<Vec<(Vec3, Vec3, f32)>>,
    centroid: Vec3,
    volume: f32,
    radius: f32,
}

impl Polyhedron {
    /// The polyhedron of `planes`, or `None` when it has no volume.
    pub fn new(planes: &[Plane]) -> Option<Polyhedron> {
        if !has_volume(planes) {
            return None;
        }
        let planes = bounding_planes(planes);
        let vertices = dedup(vertices(&planes));
        Some(Polyhedron::with(planes, vertices))
    }

    /// The polyhedron of `planes` with `vertices`: its faces and measures.
    fn with(planes: Vec<Plane>, vertices: Vec<Vec3>) -> Polyhedron {
        let (face_planes, faces): (Vec<Plane>, Vec<Vec<Vec3>>) = faces(&planes, &vertices).into_iter().unzip();
        let edges = faces
            .iter()
            .map(|f| {
                (0..f.len())
                    .map(|i| {
                        let (a, b) = (f[i], f[(i + 1) % f.len()]);
                        (a, b - a, 1.0 / (b - a).length_squared().max(1e-20))
                    })
                    .collect()
            })
            .collect();
        let mut p = Polyhedron { planes, vertices, faces, face_planes, edges, centroid: Vec3::ZERO, volume: 0.0, radius: 0.0 };
        let (volume, centroid) = p.volume_and_centroid();
        p.volume = volume;
        p.centroid = centroid;
        p.radius = p.vertices.iter().map(|v| v.distance(centroid)).fold(0.0, f32::max);
        p
    }

    /// The axis-aligned box `[lo, hi]`.
    pub fn cuboid(lo: Vec3, hi: Vec3) -> Polyhedron {
        let planes: Vec<Plane> = (0..3)
            .flat_map(|a| [Plane { normal: Vec3::AXES[a], offset: hi[a] }, Plane { normal: -Vec3::AXES[a], offset: -lo[a] }])
            .collect();
        let vertices: Vec<Vec3> = (0..8)
            .map(|c: usize| {
                Vec3::new(if c & 1 == 0 { lo.x } else { hi.x }, if c & 2 == 0 { lo.y } else { hi.y }, if c & 4 == 0 { lo.z } else { hi.z })
            })
            .collect();
        Polyhedron::with(planes, vertices)
    }

    /// The two halves on either side of `plane` (the one `plane` keeps first), or `None`
    /// when the plane does not cut the part with volume on both sides.
    pub fn split(&self, plane: Plane) -> Option<(Polyhedron, Polyhedron)> {
        let scale = self.vertices.iter().map(|v| v.length()).fold(1.0, f32::max);
        let side = |v: &Vec3| plane.distance(*v) / scale;
        // Quick rejection: all vertices (nearly) on one side.
        if self.vertices.iter().all(|v| side(v) > -1e-5) || self.vertices.iter().all(|v| side(v) < 1e-5) {
            return None;
        }
        let with = |p: Plane| {
            let mut planes = self.planes.clone();
            planes.push(p);
            Polyhedron::new(&planes)
        };
        Some((with(plane)?, with(plane.flipped())?))
    }

    /// The volume and centroid of the solid (tetrahedra from the vertex mean to each
    /// face).
    fn volume_and_centroid(&self) -> (f32, Vec3) {
        let apex = self.vertex_mean().as_dvec3();
        let (volume, moment) = self.faces.iter().fold((0.0f64, glam::DVec3::ZERO), |(v, m), face| {
            let (a, fan) = (face[0].as_dvec3(), &face[1..]);
            fan.windows(2).fold((v, m), |(v, m), e| {
                let (b, c) = (e[0].as_dvec3(), e[1].as_dvec3());
                let vol = (a - apex).dot((b - apex).cross(c - apex)).abs() / 6.0;
                (v + vol, m + (apex + a + b + c) * 0.25 * vol)
            })
        });
        (volume as f32, if volume <= 0.0 { self.vertex_mean() } else { (moment / volume).as_vec3() })
    }

    /// The centroid of the solid.
    pub fn centroid(&self) -> Vec3 {
        self.centroid
    }

    /// The volume of the solid.
    pub fn volume(&self) -> f32 {
        self.volume
    }

    /// The distance of the farthest vertex from the centroid.
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// Where `plane` cuts the polyhedron: the cut face's vertices in order around it
    /// (empty when the plane misses it or only touches it).
    pub fn section(&self, plane: Plane) -> Vec<Vec3> {
        let Some((half, _)) = self.split(plane) else { return Vec::new() };
        faces(&[plane], &half.vertices).into_iter().next().map_or_else(Vec::new, |(_, face)| face)
    }

    /// The mean of the vertices.
    pub fn vertex_mean(&self) -> Vec3 {
        self.vertices.iter().copied().sum::<Vec3>() / self.vertices.len().max(1) as f32
    }

    /// Whether a point lies inside (boundary included).
    pub fn contains(&self, p: Vec3) -> bool {
        self.planes.iter().all(|pl| pl.distance(p) <= 1e-4)
    }

    /// The point of the polyhedron closest to `p` (`p` itself inside), by projecting onto
    /// the faces, edges and vertices. Only faces that face `p` are tried: the closest
    /// point lies on one (`p − q` is in the cone of the normals of the faces at `q`, so
    /// it has a positive part along one of them). Faces wind counterclockwise about their
    /// outward normal.
    pub fn closest_point(&self, p: Vec3) -> Vec3 {
        if self.contains(p) {
            return p;
        }
        // A face's foot that lies in the polyhedron is the answer: the polyhedron lies in
        // the face's half-space, so no point of it is nearer than that plane.
        for plane in &self.face_planes {
            let d = plane.distance(p);
            if d > 0.0 {
                let q = p - plane.normal * d;
                if self.contains(q) {
                    return q;
                }
            }
        }
        // Otherwise it lies on an edge (or a vertex) of a face that faces p.
        let mut best = self.vertices.first().copied().unwrap_or(p);
        let mut best_d = best.distance_squared(p);
        for (edges, plane) in self.edges.iter().zip(&self.face_planes) {
            if plane.distance(p) <= 0.0 {
                continue;
            }
            for &(a, ab, inv) in edges {
                let q = a + ab * ((p - a).dot(ab) * inv).clamp(0.0, 1.0);
                let d = q.distance_squared(p);
                if d < best_d {
                    (best, best_d) = (q, d);
                }
            }
        }
        best
    }
}

/// Each plane's face: the plane (unit normal) and the vertices on it in order around it
/// (planes with fewer than three vertices on them have none).
fn faces(planes: &[Plane], vertices: &[Vec3]) -> Vec<(Plane, Vec<Vec3>)> {
    let scale = vertices.iter().map(|v| v.length()).fold(1.0, f32::max);
    planes
        .iter()
        .filter_map(|pl| {
            let on: Vec<Vec3> = vertices.iter().copied().filter(|v| pl.distance(*v).abs() <= 1e-4 * scale).collect();
            if on.len() < 3 {
                return None;
            }
            let c = on.iter().copied().sum::<Vec3>() / on.len() as f32;
            let u = (on[0] - c).normalize_or_zero();
            let w = pl.normal.cross(u);
            let angle = |a: &Vec3| (*a - c).dot(w).atan2((*a - c).dot(u));
            let mut sorted = on;
            sorted.sort_by(|a, b| angle(a).total_cmp(&angle(b)));
            let n = pl.normal.length().max(1e-30);
            Some((Plane { normal: pl.normal / n, offset: pl.offset / n }, sorted))
        })
        .collect()
}

/// Vertices without the near-duplicates where more than three planes meet.
fn dedup(points: Vec<Vec3>) -> Vec<Vec3> {
    let scale = points.iter().map(|v| v.length()).fold(1.0, f32::max);
    let mut out: Vec<Vec3> = Vec::with_capacity(points.len());
    for p in points {
        if !out.iter().any(|q| q.distance(p) <= 1e-4 * scale) {
            out.push(p);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_split_partitions_the_part() {
        let cube = Polyhedron::cuboid(Vec3::ZERO, Vec3::splat(2.0));
        assert_eq!((cube.vertices.len(), cube.planes.len()), (8, 6));
        assert!((cube.volume() - 8.0).abs() < 1e-4 && (cube.centroid() - Vec3::ONE).length() < 1e-5);
        // An oblique plane through (1, 1, 1): the halves' volumes add up to the cube's,
        // each point of a lattice lies in exactly one (off the plane), and the plane is
        // a face of both.
        let plane = Plane::through(Vec3::ONE, Vec3::new(1.0, 0.5, 0.25));
        let (a, b) = cube.split(plane).unwrap();
        assert!((a.volume() + b.volume() - 8.0).abs() < 1e-3, "{} + {}", a.volume(), b.volume());
        // Through the centre of a centrally symmetric solid: equal halves.
        assert!((a.volume() - 4.0).abs() < 1e-3);
        for i in 0..10 {
            for j in 0..10 {
                for k in 0..10 {
                    let p = Vec3::new(i as f32, j as f32, k as f32) * 0.2 + 0.1 + 0.003;
                    if plane.distance(p).abs() < 1e-3 {
                        continue;
                    }
                    assert_eq!(a.contains(p) as u8 + b.contains(p) as u8, 1, "{p}");
                    assert_eq!(a.contains(p), plane.distance(p) < 0.0);
                }
            }
        }
        for half in [&a, &b] {
            let on = half.vertices.iter().filter(|v| plane.distance(**v).abs() < 1e-4).count();
            assert!(on >= 3, "the cut is a face");
        }
        // A plane beside the cube, or touching a face, cuts nothing.
        assert!(cube.split(Plane::through(Vec3::splat(3.0), Vec3::X)).is_none());
        assert!(cube.split(Plane::through(Vec3::ZERO, Vec3::X)).is_none());
    }

    #[test]
    fn closest_points_are_no_farther_than_any_point_of_the_part() {
        // A cube cut obliquely twice; points around it on a lattice; every closest point
        // lies in the part and no lattice point of the part is nearer.
        let cube = Polyhedron::cuboid(Vec3::ZERO, Vec3::splat(2.0));
        let (a, _) = cube.split(Plane::through(Vec3::new(1.2, 1.0, 0.8), Vec3::new(1.0, 0.6, 0.3).normalize())).unwrap();
        let (part, _) = a.split(Plane::through(Vec3::new(0.5, 1.0, 1.0), Vec3::new(-0.4, 1.0, 0.7).normalize())).unwrap();
        let lattice = |n: i32, lo: f32, step: f32| {
            (0..n * n * n).map(move |i| Vec3::new((i % n) as f32, (i / n % n) as f32, (i / (n * n)) as f32) * step + Vec3::splat(lo))
        };
        let inside: Vec<Vec3> = lattice(21, 0.0, 0.1).filter(|q| part.contains(*q)).chain(part.vertices.iter().copied()).collect();
        assert!(inside.len() > 100);
        for p in lattice(9, -1.5, 0.62) {
            let q = part.closest_point(p);
            assert!(part.planes.iter().all(|pl| pl.distance(q) < 1e-4), "{q} is in the part");
            let nearest = inside.iter().map(|x| x.distance(p)).fold(f32::INFINITY, f32::min);
            assert!(q.distance(p) <= nearest + 1e-4, "{p}: {q} at {} but a point at {nearest}", q.distance(p));
        }
    }

    #[test]
    fn sections_are_the_cut_faces() {
        // The unit cube cut at x = ¼: the square x = ¼, 0 ≤ y, z ≤ 1, in order around.
        let cube = Polyhedron::cuboid(Vec3::ZERO, Vec3::ONE);
        let s = cube.section(Plane::through(Vec3::new(0.25, 0.0, 0.0), Vec3::X));
        assert_eq!(s.len(), 4);
        assert!(s.iter().all(|v| (v.x - 0.25).abs() < 1e-5));
        for (a, b) in s.iter().zip(s.iter().cycle().skip(1)) {
            assert!((a.distance(*b) - 1.0).abs() < 1e-5, "neighbours share an edge: {a} {b}");
        }
        // Across a corner: a triangle; x + y + z = 2.5 cuts off the corner (1, 1, 1).
        let t = cube.section(Plane::through(Vec3::new(1.0, 1.0, 0.5), Vec3::ONE));
        assert_eq!(t.len(), 3);
        // Missing or touching: nothing.
        assert!(cube.section(Plane::through(Vec3::splat(2.0), Vec3::X)).is_empty());
        assert!(cube.section(Plane::through(Vec3::ONE, Vec3::X)).is_empty());
    }

    #[test]
    fn faces_centroids_and_closest_points() {
        // A wedge: the unit cube cut by x + y ≤ 1 (a triangular prism of volume ½, its
        // centroid at (⅓, ⅓, ½)).
        let (wedge, _) =
            Polyhedron::cuboid(Vec3::ZERO, Vec3::ONE).split(Plane::through(Vec3::new(0.5, 0.5, 0.0), Vec3::new(1.0, 1.0, 0.0))).unwrap();
        assert_eq!(wedge.vertices.len(), 6);
        assert_eq!(wedge.faces.len(), 5);
        assert!((wedge.volume() - 0.5).abs() < 1e-5);
        assert!((wedge.centroid() - Vec3::new(1.0 / 3.0, 1.0 / 3.0, 0.5)).length() < 1e-5, "{}", wedge.centroid());
        // Closest points: inside itself; beyond the slanted face its foot; beyond an
        // edge and a corner, those.
        assert_eq!(wedge.closest_point(Vec3::splat(0.2)), Vec3::splat(0.2));
        assert!((wedge.closest_point(Vec3::new(1.0, 1.0, 0.5)) - Vec3::new(0.5, 0.5, 0.5)).length() < 1e-5);
        assert!((wedge.closest_point(Vec3::new(-1.0, -1.0, 0.5)) - Vec3::new(0.0, 0.0, 0.5)).length() < 1e-5);
        assert!((wedge.closest_point(Vec3::new(-1.0, -1.0, 2.0)) - Vec3::new(0.0, 0.0, 1.0)).length() < 1e-5);
    }
}
