//! Which voxels a slice view shows, and how they lie on the screen.
//!
//! A slice view shows the dataset's own voxels, one pixel per voxel: a plane of the
//! voxel grid, the one of the three index planes whose normal is closest to the view's
//! anatomical axis (world space is RAS+: `volume::grid`). For an oblique acquisition
//! that is the index plane nearest the anatomical one, as radiology viewers show the
//! acquired slices; nothing is resampled, so every pixel is a voxel the file holds.
//!
//! On the screen, radiological convention (DICOM PS3.3 C.7.6.2.1.1 and what 3D Slicer
//! shows): axial slices are seen from the feet, the patient's right on the screen's
//! left and anterior up; coronal from the front, right on the left and superior up;
//! sagittal from the patient's left, anterior on the left and superior up. So the
//! screen's columns run towards world −x (axial, coronal) or −y (sagittal), its rows
//! (downwards) towards −y (axial) or −z (coronal, sagittal). Each in-plane index axis
//! is the one closest to its screen direction, flipped where it runs the other way.
//! For data without a patient frame (microscopy, simulations) the same planes are the
//! X, Y and Z views: normal to z, y and x.

use glam::{UVec3, Vec3};

/// The three slice views.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Orientation {
    /// Normal to superior (z): seen from the feet.
    Axial,
    /// Normal to anterior (y): seen from the front.
    Coronal,
    /// Normal to right (x): seen from the patient's left.
    Sagittal,
}

impl Orientation {
    pub const ALL: [Orientation; 3] = [Orientation::Axial, Orientation::Coronal, Orientation::Sagittal];

    /// World directions of the plane's normal, the screen's columns (left → right) and
    /// rows (top → bottom).
    pub fn world_axes(self) -> (Vec3, Vec3, Vec3) {
        match self {
            Orientation::Axial => (Vec3::Z, -Vec3::X, -Vec3::Y),
            Orientation::Coronal => (Vec3::Y, -Vec3::X, -Vec3::Z),
            Orientation::Sagittal => (Vec3::X, -Vec3::Y, -Vec3::Z),
        }
    }

    /// The name medical users know, and the one for data without a patient frame.
    pub fn names(self) -> (&'static str, &'static str) {
        match self {
            Orientation::Axial => ("axial", "Z"),
            Orientation::Coronal => ("coronal", "Y"),
            Orientation::Sagittal => ("sagittal", "X"),
        }
    }
}

impl std::str::FromStr for Orientation {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "axial" | "z" => Ok(Orientation::Axial),
            "coronal" | "y" => Ok(Orientation::Coronal),
            "sagittal" | "x" => Ok(Orientation::Sagittal),
            other => Err(format!("'{other}' is not a slice orientation (axial, coronal, sagittal; or z, y, x)")),
        }
    }
}

/// A slice view as index axes: the voxel axis the slices step along, and the voxel axes
/// of the screen's columns and rows with whether each runs against the screen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SliceAxes {
    pub orientation: Orientation,
    /// Index axis (0 = i, 1 = j, 2 = k) normal to the slices.
    pub normal: usize,
    /// Index axis of the columns, and whether index decreases left → right.
    pub column: (usize, bool),
    /// Index axis of the rows, and whether index decreases top → bottom.
    pub row: (usize, bool),
}

impl SliceAxes {
    /// The slice view `orientation` of a grid whose index axes point along the columns of
    /// `direction` (`Grid::direction`).
    pub fn of(direction: glam::Mat3, orientation: Orientation) -> SliceAxes {
        let (n, c, r) = orientation.world_axes();
        let axes = [direction.x_axis, direction.y_axis, direction.z_axis];
        let closest = |w: Vec3, skip: &[usize]| {
            (0..3).filter(|a| !skip.contains(a)).max_by(|&a, &b| axes[a].dot(w).abs().total_cmp(&axes[b].dot(w).abs())).unwrap_or(0)
        };
        let normal = closest(n, &[]);
        let column = closest(c, &[normal]);
        let row = (0..3).find(|a| *a != normal && *a != column).unwrap_or(0);
        SliceAxes { orientation, normal, column: (column, axes[column].dot(c) < 0.0), row: (row, axes[row].dot(r) < 0.0) }
    }

    /// Number of slices.
    pub fn count(&self, dims: UVec3) -> u32 {
        dims[self.normal]
    }

    /// Width and height of a slice in pixels (voxels).
    pub fn size(&self, dims: UVec3) -> (u32, u32) {
        (dims[self.column.0], dims[self.row.0])
    }

    /// The voxel shown at pixel (x, y) of slice `index`.
    pub fn voxel(&self, dims: UVec3, index: u32, x: u32, y: u32) -> UVec3 {
        let mut v = UVec3::ZERO;
        v[self.normal] = index;
        v[self.column.0] = if self.column.1 { dims[self.column.0] - 1 - x } else { x };
        v[self.row.0] = if self.row.1 { dims[self.row.0] - 1 - y } else { y };
        v
    }

    /// The pixel (x, y) and slice index showing continuous voxel index `q` (the inverse
    /// of [`Self::voxel`], continuous: pixel centres at whole values).
    pub fn pixel(&self, dims: UVec3, q: Vec3) -> (Vec3, u32) {
        let flip = |axis: (usize, bool)| if axis.1 { dims[axis.0] as f32 - 1.0 - q[axis.0] } else { q[axis.0] };
        let slice = q[self.normal].round().clamp(0.0, dims[self.normal] as f32 - 1.0) as u32;
        (Vec3::new(flip(self.column), flip(self.row), q[self.normal]), slice)
    }

    /// Millimetres per pixel along the columns and rows (`Grid::spacing`).
    pub fn pixel_mm(&self, spacing: Vec3) -> (f32, f32) {
        (spacing[self.column.0], spacing[self.row.0])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Mat3, Quat};

    #[test]
    fn an_ras_grid_shows_axial_slices_from_the_feet() {
        // Identity direction: i = right, j = anterior, k = superior.
        let a = SliceAxes::of(Mat3::IDENTITY, Orientation::Axial);
        // Columns run to the patient's left (−i), rows to posterior (−j).
        assert_eq!(a, SliceAxes { orientation: Orientation::Axial, normal: 2, column: (0, true), row: (1, true) });
        let dims = UVec3::new(4, 5, 6);
        assert_eq!(a.size(dims), (4, 5));
        assert_eq!(a.count(dims), 6);
        // The top-left pixel is the patient's right-anterior voxel.
        assert_eq!(a.voxel(dims, 2, 0, 0), UVec3::new(3, 4, 2));
        assert_eq!(a.voxel(dims, 2, 3, 4), UVec3::new(0, 0, 2));
        let s = SliceAxes::of(Mat3::IDENTITY, Orientation::Sagittal);
        // Sagittal: anterior on the left (columns towards −j), superior up (rows −k).
        assert_eq!(s, SliceAxes { orientation: Orientation::Sagittal, normal: 0, column: (1, true), row: (2, true) });
        let c = SliceAxes::of(Mat3::IDENTITY, Orientation::Coronal);
        assert_eq!(c, SliceAxes { orientation: Orientation::Coronal, normal: 1, column: (0, true), row: (2, true) });
    }

    #[test]
    fn an_lps_grid_and_an_oblique_one_take_their_nearest_axes() {
        // DICOM's LPS read into RAS: i towards the left (−x), j posterior (−y).
        let lps = Mat3::from_cols(-Vec3::X, -Vec3::Y, Vec3::Z);
        let a = SliceAxes::of(lps, Orientation::Axial);
        assert_eq!((a.normal, a.column, a.row), (2, (0, false), (1, false)));
        // A coronal acquisition: k along anterior, j along −superior.
        let coronal = Mat3::from_cols(Vec3::X, -Vec3::Z, Vec3::Y);
        let a = SliceAxes::of(coronal, Orientation::Axial);
        assert_eq!((a.normal, a.column, a.row), (1, (0, true), (2, true)));
        // Tilted by 20° about x: the nearest axes stay.
        let tilted = Mat3::from_quat(Quat::from_rotation_x(20f32.to_radians()));
        assert_eq!(SliceAxes::of(tilted, Orientation::Axial), SliceAxes::of(Mat3::IDENTITY, Orientation::Axial));
    }

    #[test]
    fn pixels_and_voxels_are_inverse() {
        let dims = UVec3::new(7, 5, 3);
        for o in Orientation::ALL {
            for dir in [Mat3::IDENTITY, Mat3::from_cols(-Vec3::X, -Vec3::Y, Vec3::Z), Mat3::from_cols(Vec3::Y, Vec3::Z, Vec3::X)] {
                let a = SliceAxes::of(dir, o);
                let (w, h) = a.size(dims);
                for (x, y) in [(0, 0), (w - 1, 0), (1, h - 1)] {
                    let v = a.voxel(dims, 1, x, y);
                    let (p, index) = a.pixel(dims, v.as_vec3());
                    assert_eq!((p.x, p.y, index), (x as f32, y as f32, 1), "{o:?} {dir}");
                }
            }
        }
    }

    #[test]
    fn names_parse_both_ways() {
        for o in Orientation::ALL {
            let (medical, axis) = o.names();
            assert_eq!(medical.parse::<Orientation>(), Ok(o));
            assert_eq!(axis.parse::<Orientation>(), Ok(o));
        }
        assert!("oblique".parse::<Orientation>().unwrap_err().contains("axial, coronal, sagittal"));
    }
}
