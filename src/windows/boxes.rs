//! Oriented boxes: windows and source boxes.
//!
//! A box is a centre, a rotation and half extents; its local coordinates run over
//! `[-1, 1]³`, so the map between two boxes is "same local coordinates"
//! ([`crate::windows::mapping`]). A clip window's box is cut out of the datasets'
//! regions as a hole (its six half-spaces, [`OrientedBox::planes`]).

use glam::{Affine3A, Mat3, Quat, Vec3};

use crate::region::Plane;

/// A box in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrientedBox {
    pub center: Vec3,
    pub rotation: Quat,
    /// Half the extent along each of the box's own axes.
    pub half: Vec3,
}

impl OrientedBox {
    /// The axis-aligned box `[lo, hi]`.
    pub fn aligned(lo: Vec3, hi: Vec3) -> OrientedBox {
        OrientedBox { center: (lo + hi) * 0.5, rotation: Quat::IDENTITY, half: (hi - lo).abs() * 0.5 }
    }

    /// Local coordinates (`[-1, 1]³` inside) → world.
    pub fn to_world(&self) -> Affine3A {
        Affine3A::from_mat3_translation(Mat3::from_quat(self.rotation) * Mat3::from_diagonal(self.half), self.center)
    }

    /// World → local coordinates (the inverse of [`Self::to_world`]; a flat box maps
    /// everything to its plane).
    pub fn to_local(&self) -> Affine3A {
        let inv_half = Vec3::select(self.half.cmpgt(Vec3::splat(1e-12)), self.half.recip(), Vec3::ZERO);
        let r = Mat3::from_quat(self.rotation.inverse());
        Affine3A::from_mat3_translation(Mat3::from_diagonal(inv_half) * r, -(Mat3::from_diagonal(inv_half) * (r * self.center)))
    }

    /// The six half-spaces whose intersection is the box (normals point out).
    pub fn planes(&self) -> Vec<Plane> {
        let axes = Mat3::from_quat(self.rotation);
        (0..3)
            .flat_map(|a| {
                let n = axes.col(a);
                [Plane::through(self.center + n * self.half[a], n), Plane::through(self.center - n * self.half[a], -n)]
            })
            .collect()
    }

    /// Whether a world point lies inside (boundary included).
    pub fn contains(&self, p: Vec3) -> bool {
        let l = self.to_local().transform_point3(p);
        l.abs().max_element() <= 1.0 + 1e-5
    }

    /// The eight corners.
    pub fn corners(&self) -> [Vec3; 8] {
        let m = self.to_world();
        std::array::from_fn(|c| {
            m.transform_point3(Vec3::new(
                if c & 1 == 0 { -1.0 } else { 1.0 },
                if c & 2 == 0 { -1.0 } else { 1.0 },
                if c & 4 == 0 { -1.0 } else { 1.0 },
            ))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::region::{has_volume, vertices};

    fn unit_cube() -> Vec<Plane> {
        OrientedBox::aligned(Vec3::splat(-1.0), Vec3::splat(1.0)).planes()
    }

    #[test]
    fn local_and_world_coordinates_invert() {
        let b = OrientedBox { center: Vec3::new(1.0, 2.0, 3.0), rotation: Quat::from_rotation_z(0.7), half: Vec3::new(2.0, 1.0, 0.5) };
        let p = Vec3::new(0.3, -0.8, 0.9);
        assert!((b.to_local().transform_point3(b.to_world().transform_point3(p)) - p).length() < 1e-5);
        // The local x axis runs along the rotated x axis, scaled by the half extent.
        let x = b.to_world().transform_point3(Vec3::X) - b.center;
        assert!((x - Vec3::new(0.7f32.cos(), 0.7f32.sin(), 0.0) * 2.0).length() < 1e-5);
        assert!(b.contains(b.center + Vec3::new(0.0, 0.0, 0.49)) && !b.contains(b.center + Vec3::new(0.0, 0.0, 0.51)));
        assert!(b.corners().iter().all(|c| b.contains(*c)));
    }

    #[test]
    fn a_cube_has_eight_vertices() {
        assert_eq!(vertices(&unit_cube()).len(), 8);
        assert!(has_volume(&unit_cube()));
        // Two opposite half-spaces that do not overlap: empty.
        let empty = [Plane::through(Vec3::ZERO, Vec3::X), Plane::through(Vec3::X, -Vec3::X)];
        let mut planes = unit_cube();
        planes.extend(empty);
        assert!(!has_volume(&planes));
    }

    #[test]
    fn a_box_cut_out_as_a_hole() {
        use crate::region::{Region, ray_convex};
        let cut = OrientedBox { center: Vec3::new(0.2, 0.0, 0.0), rotation: Quat::from_rotation_y(0.3), half: Vec3::splat(0.4) };
        let planes = cut.planes();
        let region = Region {
            planes: unit_cube(),
            holes: vec![std::array::from_fn(|i| planes[i])],
            world_to_voxel: Affine3A::IDENTITY,
            volume: 0,
            appearance: 0,
        };
        // Every point of a grid over the cube is in the region exactly when it is not
        // in the box.
        let mut n = 0;
        for i in 0..11 {
            for j in 0..11 {
                for k in 0..11 {
                    let p = Vec3::new(i as f32, j as f32, k as f32) * 0.19 - 0.95 + Vec3::splat(0.003);
                    let in_box = cut.to_local().transform_point3(p).abs().max_element() < 1.0;
                    assert_eq!(region.contains(p), !in_box, "{p}");
                    n += usize::from(in_box);
                }
            }
        }
        assert!(n > 20, "the grid barely met the box: {n}");
        // Along any ray the intervals are the cube's chord less the box's.
        for (o, d) in [(Vec3::new(-3.0, 0.1, 0.05), Vec3::X), (Vec3::new(-2.0, -1.5, 0.2), Vec3::new(1.0, 0.8, -0.1).normalize())] {
            let total: f32 = region.intersect(o, d).iter().map(|(a, b)| b - a).sum();
            let (a, b) = ray_convex(&unit_cube(), o, d).unwrap();
            let hole = ray_convex(&planes, o, d).map_or(0.0, |(c, e)| (e.min(b) - c.max(a)).max(0.0));
            assert!((total - (b - a - hole)).abs() < 1e-5, "{total} vs {} − {hole}", b - a);
            assert!(hole > 0.1, "the ray misses the box");
        }
    }
}
