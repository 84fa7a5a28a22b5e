//! A slice's voxels and its picture: greys through a window, label colours, and a label
//! volume laid over it where it shows.

use glam::{UVec3, Vec3};

use super::plane::Orientation;
use super::plane::SliceAxes;
use super::window_level::WindowLevel;
use crate::volume::labels::LabelTable;
use crate::volume::source::{SourceLevel, VoxelSource};
use crate::volume::{Grid, ValueMap, Volume};

/// One slice of a volume: its voxels' codes as the screen shows them (row by row, top
/// first), with what the codes mean.
#[derive(Clone, Debug, PartialEq)]
pub struct Slice {
    pub width: u32,
    pub height: u32,
    pub codes: Vec<u16>,
    pub values: ValueMap,
    pub axes: SliceAxes,
    /// Slice index along `axes.normal`.
    pub index: u32,
    /// The grid the voxels are on (a pyramid level's for a slice of a streamed level).
    pub grid: Grid,
}

/// The finest level of a pyramid whose `orientation` slices hold at most `max_pixels`
/// pixels (the coarsest when none does); `None` for a pyramid without levels.
pub fn finest_level_within(levels: &[SourceLevel], orientation: Orientation, max_pixels: u64) -> Option<usize> {
    let coarsest = levels.len().checked_sub(1)?;
    let fits = |k: &usize| {
        let grid = &levels[*k].grid;
        let (w, h) = SliceAxes::of(grid.direction, orientation).size(grid.dims);
        w as u64 * h as u64 <= max_pixels
    };
    Some((0..levels.len()).find(fits).unwrap_or(coarsest))
}

impl Slice {
    /// Slice `index` of a volume in memory (clamped to its slices).
    pub fn of_volume(volume: &Volume, axes: SliceAxes, index: u32) -> Slice {
        let dims = volume.dims();
        let index = index.min(axes.count(dims) - 1);
        let (width, height) = axes.size(dims);
        let mut codes = Vec::with_capacity(width as usize * height as usize);
        for y in 0..height {
            for x in 0..width {
                let v = axes.voxel(dims, index, x, y);
                codes.push(volume.code(v.x, v.y, v.z));
            }
        }
        Slice { width, height, codes, values: volume.values.clone(), axes, index, grid: volume.grid.clone() }
    }

    /// Slice `index` of level `level` of a streamed source (one voxel thick box read;
    /// chunks that fail read as the fill value, as in the 3D view).
    pub fn of_source(source: &dyn VoxelSource, level: usize, axes: SliceAxes, index: u32) -> Result<Slice, String> {
        let info = source.info();
        let l = info.levels.get(level).ok_or_else(|| format!("{}: no level {level}", info.location()))?;
        let dims = l.grid.dims;
        let index = index.min(axes.count(dims) - 1);
        let mut lo = UVec3::ZERO;
        lo[axes.normal] = index;
        let mut size = dims;
        size[axes.normal] = 1;
        let block = source.read_box(level, lo, size).map_err(|e| e.to_string())?;
        let (width, height) = axes.size(dims);
        let mut codes = Vec::with_capacity(width as usize * height as usize);
        for y in 0..height {
            for x in 0..width {
                let mut v = axes.voxel(dims, index, x, y);
                v[axes.normal] = 0;
                codes.push(block.voxels.code(((v.z * size.y + v.y) * size.x + v.x) as usize));
            }
        }
        Ok(Slice { width, height, codes, values: info.values.clone(), axes, index, grid: l.grid.clone() })
    }

    /// The grey picture through `window` (RGBA, opaque).
    pub fn grey(&self, window: &WindowLevel) -> Vec<[u8; 4]> {
        // One grey per code in use (at most 65 536), then a table look-up per pixel.
        let top = self.codes.iter().copied().max().unwrap_or(0) as usize;
        let table: Vec<u8> = (0..=top).map(|c| window.grey(self.values.to_real(c as f64))).collect();
        self.codes.iter().map(|&c| table[c as usize]).map(|g| [g, g, g, 255]).collect()
    }

    /// The picture of a label slice: each label's colour, background (0) black.
    pub fn labels(&self, table: &LabelTable) -> Vec<[u8; 4]> {
        self.codes
            .iter()
            .map(|&c| {
                let id = self.values.to_real(c as f64).round().max(0.0) as u32;
                if id == 0 {
                    [0, 0, 0, 255]
                } else {
                    let [r, g, b] = table.color(id);
                    [r, g, b, 255]
                }
            })
            .collect()
    }

    /// World position of pixel (x, y)'s voxel centre.
    pub fn world(&self, x: u32, y: u32) -> Vec3 {
        self.grid.index_to_world().transform_point3(self.axes.voxel(self.grid.dims, self.index, x, y).as_vec3())
    }
}

/// Lays the labels of `labels` (a label volume placed in the world by `labels_to_world`)
/// over `picture` of `slice` with `opacity`: each pixel takes the label at its voxel
/// centre (nearest label voxel); background (0) and outside the label volume leave the
/// pixel as it is.
pub fn overlay_labels(
    picture: &mut [[u8; 4]],
    slice: &Slice,
    labels: &Volume,
    labels_to_world: glam::Affine3A,
    table: &LabelTable,
    opacity: f32,
) {
    let to_index = labels.grid.world_to_index() * labels_to_world.inverse();
    let dims = labels.dims().as_ivec3();
    for y in 0..slice.height {
        for x in 0..slice.width {
            let q = to_index.transform_point3(slice.world(x, y)).round().as_ivec3();
            if q.cmplt(glam::IVec3::ZERO).any() || q.cmpge(dims).any() {
                continue;
            }
            let id = labels.real(q.x as u32, q.y as u32, q.z as u32).round().max(0.0) as u32;
            if id == 0 {
                continue;
            }
            let colour = table.color(id);
            let p = &mut picture[(y * slice.width + x) as usize];
            for c in 0..3 {
                p[c] = (p[c] as f32 * (1.0 - opacity) + colour[c] as f32 * opacity).round() as u8;
            }
        }
    }
}

/// The picture as an image.
pub fn to_image(width: u32, height: u32, pixels: &[[u8; 4]]) -> Option<image::RgbaImage> {
    image::RgbaImage::from_raw(width, height, pixels.iter().flatten().copied().collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::slices::plane::Orientation;
    use crate::volume::Voxels;
    use crate::volume::phantom::Phantom;

    /// Code of voxel v of a voxel array.
    fn code_at(voxels: &Voxels, dims: UVec3, v: UVec3) -> u16 {
        voxels.code(((v.z * dims.y + v.y) * dims.x + v.x) as usize)
    }

    #[test]
    fn a_slice_holds_its_voxels_in_screen_order() {
        let v = Phantom::Head.generate(32).unwrap();
        for o in Orientation::ALL {
            let axes = SliceAxes::of(v.grid.direction, o);
            let s = Slice::of_volume(&v, axes, 11);
            assert_eq!((s.width, s.height), axes.size(v.dims()));
            for (x, y) in [(0, 0), (5, 7), (s.width - 1, s.height - 1)] {
                let voxel = axes.voxel(v.dims(), 11, x, y);
                assert_eq!(s.codes[(y * s.width + x) as usize], code_at(&v.voxels, v.dims(), voxel), "{o:?} ({x}, {y})");
            }
            // Out of range: the last slice.
            assert_eq!(Slice::of_volume(&v, axes, 999).index, axes.count(v.dims()) - 1);
        }
    }

    #[test]
    fn greys_follow_the_window_and_labels_their_colours() {
        let v = Phantom::Head.generate(32).unwrap();
        let s = Slice::of_volume(&v, SliceAxes::of(v.grid.direction, Orientation::Axial), 16);
        let wl = WindowLevel::new(400.0, 40.0);
        let g = s.grey(&wl);
        for (i, &c) in s.codes.iter().enumerate() {
            assert_eq!(g[i][0], wl.grey(v.values.to_real(c as f64)));
        }
        let mut table = LabelTable::default();
        table.labels.insert(1, crate::volume::labels::Label { name: "one".into(), color: [200, 10, 20] });
        let labels = Slice { codes: vec![0, 1, 2], width: 3, height: 1, values: ValueMap::IDENTITY, ..s.clone() };
        let p = labels.labels(&table);
        assert_eq!(p[0], [0, 0, 0, 255]);
        assert_eq!(p[1], [200, 10, 20, 255]);
        assert_eq!(p[2][..3], crate::volume::labels::generated_color(2));
    }
}
