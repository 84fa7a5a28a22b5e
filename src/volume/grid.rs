//! Volume geometry: where every voxel sits in world space.
//!
//! World space is patient (or scanner) space in millimetres with RAS+ axes (x towards the
//! patient's right→left is *negative*, i.e. +x = Right, +y = Anterior, +z = Superior), the
//! NIfTI convention. Readers of LPS formats (DICOM, MetaImage, NRRD with an LPS `space`)
//! flip x and y when they build a [`Grid`], so every dataset lands in one frame and
//! oblique acquisitions are placed correctly next to each other.
//!
//! A voxel index `(i, j, k)` is continuous: integer values are voxel *centres*. The voxel
//! at index `p` is at `origin + direction · (spacing ⊙ p)`. The box the data fills covers
//! whole voxel cells, from index `-0.5` to `n - 0.5` on each axis; texture coordinates
//! put voxel centres at `(p + 0.5) / n`, as a GPU 3D texture does.

use glam::{Affine3A, Mat3, UVec3, Vec3};

/// Dimensions, spacing, origin and orientation of a regular grid.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// Number of voxels along the index axes i, j, k (fastest first).
    pub dims: UVec3,
    /// Distance between neighbouring voxel centres along i, j, k, in millimetres.
    pub spacing: Vec3,
    /// World position of the centre of voxel (0, 0, 0).
    pub origin: Vec3,
    /// Columns are the unit world directions of the i, j and k axes (direction cosines).
    pub direction: Mat3,
}

impl Grid {
    /// An axis-aligned grid with its first voxel at the world origin.
    pub fn new(dims: UVec3, spacing: Vec3) -> Self {
        Self { dims, spacing, origin: Vec3::ZERO, direction: Mat3::IDENTITY }
    }

    /// An axis-aligned grid whose box is centred on the world origin.
    pub fn centered(dims: UVec3, spacing: Vec3) -> Self {
        let mut grid = Self::new(dims, spacing);
        grid.origin = -(dims.as_vec3() - 1.0) * spacing * 0.5;
        grid
    }

    /// Builds a grid from a 3×4 index→world affine (columns: i, j, k step vectors, then
    /// the origin), as NIfTI sform, NRRD `space directions` and DICOM orientation give.
    pub fn from_axes(dims: UVec3, axes: Mat3, origin: Vec3) -> Result<Self, String> {
        let spacing = Vec3::new(axes.x_axis.length(), axes.y_axis.length(), axes.z_axis.length());
        if !spacing.is_finite() || spacing.min_element() <= 0.0 {
            return Err(format!("voxel axes have zero or invalid length: {spacing}"));
        }
        let direction = Mat3::from_cols(axes.x_axis / spacing.x, axes.y_axis / spacing.y, axes.z_axis / spacing.z);
        let grid = Self { dims, spacing, origin, direction };
        grid.validate()?;
        Ok(grid)
    }

    /// Checks that the geometry is usable: positive dimensions, finite positive spacing,
    /// finite origin and a non-degenerate orientation.
    pub fn validate(&self) -> Result<(), String> {
        if self.dims.min_element() == 0 {
            return Err(format!("dimensions {} contain a zero", fmt_dims(self.dims)));
        }
        if !self.spacing.is_finite() || self.spacing.min_element() <= 0.0 {
            return Err(format!("voxel spacing {} is not positive and finite", self.spacing));
        }
        if !self.origin.is_finite() {
            return Err(format!("origin {} is not finite", self.origin));
        }
        let det = self.direction.determinant();
        if !det.is_finite() || det.abs() < 1e-3 {
            return Err("orientation matrix is degenerate (axes are parallel or zero)".into());
        }
        Ok(())
    }

    /// Number of voxels.
    pub fn voxel_count(&self) -> usize {
        self.dims.x as usize * self.dims.y as usize * self.dims.z as usize
    }

    /// Offset of voxel (i, j, k) in the voxel array (x fastest).
    #[inline]
    pub fn linear_index(&self, i: u32, j: u32, k: u32) -> usize {
        (k as usize * self.dims.y as usize + j as usize) * self.dims.x as usize + i as usize
    }

    /// The map from continuous voxel index to world position.
    pub fn index_to_world(&self) -> Affine3A {
        Affine3A::from_mat3_translation(self.direction * Mat3::from_diagonal(self.spacing), self.origin)
    }

    /// The map from world position to continuous voxel index.
    pub fn world_to_index(&self) -> Affine3A {
        self.index_to_world().inverse()
    }

    /// The map from continuous voxel index to texture coordinates (voxel centres at
    /// `(p + 0.5) / n`).
    pub fn index_to_texture(&self) -> Affine3A {
        let n = self.dims.as_vec3();
        Affine3A::from_scale_rotation_translation(1.0 / n, glam::Quat::IDENTITY, 0.5 / n)
    }

    /// The map from world position to texture coordinates.
    pub fn world_to_texture(&self) -> Affine3A {
        self.index_to_texture() * self.world_to_index()
    }

    /// The eight world-space corners of the box covered by the voxel cells.
    pub fn corners(&self) -> [Vec3; 8] {
        self.index_box_corners(Vec3::splat(-0.5), self.dims.as_vec3() - 0.5)
    }

    /// The world-space corners of the continuous index box `[lo, hi]`.
    pub fn index_box_corners(&self, lo: Vec3, hi: Vec3) -> [Vec3; 8] {
        let m = self.index_to_world();
        std::array::from_fn(|c| {
            let p =
                Vec3::new(if c & 1 == 0 { lo.x } else { hi.x }, if c & 2 == 0 { lo.y } else { hi.y }, if c & 4 == 0 { lo.z } else { hi.z });
            m.transform_point3(p)
        })
    }

    /// Axis-aligned world bounds of the continuous index box `[lo, hi]`.
    pub fn index_box_world_bounds(&self, lo: Vec3, hi: Vec3) -> (Vec3, Vec3) {
        self.index_box_corners(lo, hi).iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), &c| (a.min(c), b.max(c)))
    }

    /// Axis-aligned world bounds of the data box.
    pub fn world_bounds(&self) -> (Vec3, Vec3) {
        self.index_box_world_bounds(Vec3::splat(-0.5), self.dims.as_vec3() - 0.5)
    }

    /// World position of the centre of the data box.
    pub fn center(&self) -> Vec3 {
        self.index_to_world().transform_point3((self.dims.as_vec3() - 1.0) * 0.5)
    }

    /// Physical size of the box along each index axis, in millimetres.
    pub fn extent(&self) -> Vec3 {
        self.dims.as_vec3() * self.spacing
    }

    /// The smallest voxel spacing: the unit length transfer-function opacities refer to.
    pub fn min_spacing(&self) -> f32 {
        self.spacing.min_element()
    }

    /// Whether the index axes are (within rounding) orthogonal to each other.
    pub fn is_orthogonal(&self) -> bool {
        let d = self.direction;
        d.x_axis.dot(d.y_axis).abs() < 1e-4 && d.x_axis.dot(d.z_axis).abs() < 1e-4 && d.y_axis.dot(d.z_axis).abs() < 1e-4
    }

    /// Anatomical label of each index axis: the dominant world direction it points to,
    /// e.g. `"RAS"` for an axis-aligned NIfTI or `"LPS"` for a typical DICOM series.
    pub fn orientation_code(&self) -> String {
        let code = |v: Vec3| {
            let a = v.abs();
            if a.x >= a.y && a.x >= a.z {
                if v.x >= 0.0 { 'R' } else { 'L' }
            } else if a.y >= a.z {
                if v.y >= 0.0 { 'A' } else { 'P' }
            } else if v.z >= 0.0 {
                'S'
            } else {
                'I'
            }
        };
        [self.direction.x_axis, self.direction.y_axis, self.direction.z_axis].into_iter().map(code).collect()
    }
}

/// Formats dimensions as `256×256×128`.
pub fn fmt_dims(d: UVec3) -> String {
    format!("{}×{}×{}", d.x, d.y, d.z)
}

/// Flips an LPS vector into RAS (and back): negate x and y.
#[inline]
pub fn lps_to_ras(v: Vec3) -> Vec3 {
    Vec3::new(-v.x, -v.y, v.z)
}

/// Flips the rows of an LPS axis matrix into RAS.
pub fn lps_axes_to_ras(m: Mat3) -> Mat3 {
    Mat3::from_cols(lps_to_ras(m.x_axis), lps_to_ras(m.y_axis), lps_to_ras(m.z_axis))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn index_world_texture_round_trip() {
        let axes = Mat3::from_cols(Vec3::new(0.0, 2.0, 0.0), Vec3::new(-1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 3.0));
        let g = Grid::from_axes(UVec3::new(10, 20, 5), axes, Vec3::new(1.0, 2.0, 3.0)).unwrap();
        assert_eq!(g.spacing, Vec3::new(2.0, 1.0, 3.0));
        // Voxel (1, 2, 1): origin + 1*(0,2,0) + 2*(-1,0,0) + 1*(0,0,3) = (-1, 4, 6).
        let w = g.index_to_world().transform_point3(Vec3::new(1.0, 2.0, 1.0));
        assert!((w - Vec3::new(-1.0, 4.0, 6.0)).length() < 1e-5, "{w}");
        let back = g.world_to_index().transform_point3(w);
        assert!((back - Vec3::new(1.0, 2.0, 1.0)).length() < 1e-5);
        // Voxel 0's centre is half a texel in: 0.5 / 10.
        let t = g.world_to_texture().transform_point3(g.origin);
        assert!((t - Vec3::new(0.05, 0.025, 0.1)).length() < 1e-6, "{t}");
        assert_eq!(g.orientation_code(), "ALS");
    }

    #[test]
    fn corners_cover_whole_cells() {
        let g = Grid::new(UVec3::new(4, 2, 2), Vec3::ONE);
        let (lo, hi) = g.world_bounds();
        assert_eq!(lo, Vec3::splat(-0.5));
        assert_eq!(hi, Vec3::new(3.5, 1.5, 1.5));
        let c = Grid::centered(UVec3::new(4, 2, 2), Vec3::splat(2.0));
        let (lo, hi) = c.world_bounds();
        assert_eq!(lo, -hi);
        assert_eq!(c.center(), Vec3::ZERO);
    }

    #[test]
    fn rejects_degenerate_geometry() {
        let flat = Mat3::from_cols(Vec3::X, Vec3::X, Vec3::Z);
        assert!(Grid::from_axes(UVec3::splat(2), flat, Vec3::ZERO).is_err());
        assert!(Grid::from_axes(UVec3::splat(2), Mat3::ZERO, Vec3::ZERO).is_err());
        let mut g = Grid::new(UVec3::new(2, 0, 2), Vec3::ONE);
        assert!(g.validate().is_err());
        g.dims = UVec3::splat(2);
        g.spacing = Vec3::new(1.0, f32::NAN, 1.0);
        assert!(g.validate().is_err());
    }
}
