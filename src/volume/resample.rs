//! Downsampling a volume by two along every axis, for GPUs whose 3D-texture limits or
//! memory cannot hold it whole.
//!
//! Output voxel `i` averages input voxels `2i` and `2i + 1` along each axis (those that
//! exist at an odd edge), so it sits at input index `2i + 0.5`: the new grid has twice the
//! spacing and its origin moves by half an input voxel along each axis. Label volumes
//! keep the code of voxel `2i` instead of averaging ids.

use glam::{UVec3, Vec3};
use rayon::prelude::*;

use super::{Grid, Source, Volume, Voxels};

/// How to combine the voxels of a 2×2×2 block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Filter {
    Average,
    /// The first voxel of the block (categorical data such as labels).
    Nearest,
}

/// The volume at half resolution.
pub fn downsample2(volume: &Volume, filter: Filter) -> Result<Volume, String> {
    let d = volume.dims();
    let nd = (d + 1) / 2;
    let code = |x: u32, y: u32, z: u32| volume.voxels.code(volume.grid.linear_index(x, y, z)) as u32;
    let block = |i: usize| -> u16 {
        let (x, y, z) =
            ((i % nd.x as usize) as u32, (i / nd.x as usize % nd.y as usize) as u32, (i / (nd.x as usize * nd.y as usize)) as u32);
        let (x0, y0, z0) = (2 * x, 2 * y, 2 * z);
        if filter == Filter::Nearest {
            return code(x0, y0, z0) as u16;
        }
        let (mut block, mut n) = ([0u32; 8], 0);
        for zz in z0..(z0 + 2).min(d.z) {
            for yy in y0..(y0 + 2).min(d.y) {
                for xx in x0..(x0 + 2).min(d.x) {
                    block[n] = code(xx, yy, zz);
                    n += 1;
                }
            }
        }
        super::pyramid::block_mean(&block[..n], volume.values.no_data) as u16
    };
    let count = nd.x as usize * nd.y as usize * nd.z as usize;
    let voxels = match volume.voxels {
        Voxels::U8(_) => Voxels::U8((0..count).into_par_iter().map(|i| block(i) as u8).collect()),
        Voxels::U16(_) => Voxels::U16((0..count).into_par_iter().map(block).collect()),
    };
    let g = &volume.grid;
    let shift = if filter == Filter::Average { Vec3::splat(0.5) } else { Vec3::ZERO };
    let grid = Grid { dims: nd, spacing: g.spacing * 2.0, origin: g.index_to_world().transform_point3(shift), direction: g.direction };
    let source = Source {
        details: [volume.source.details.clone(), vec![("note".into(), format!("downsampled from {}", super::grid::fmt_dims(d)))]].concat(),
        ..volume.source.clone()
    };
    Volume::new(volume.name.clone(), grid, voxels, volume.values.clone(), source)
}

/// Halves `volume` until it fits `max_dim` voxels per axis and `max_bytes` of storage;
/// returns it with the number of halvings (0 when it already fits).
pub fn fit(volume: &Volume, max_dim: u32, max_bytes: u64, filter: Filter) -> Result<(Option<Volume>, u32), String> {
    let fits = |d: UVec3, bytes: u64| d.max_element() <= max_dim && bytes <= max_bytes;
    if fits(volume.dims(), volume.byte_len() as u64) {
        return Ok((None, 0));
    }
    let mut v = downsample2(volume, filter)?;
    let mut n = 1;
    while !fits(v.dims(), v.byte_len() as u64) {
        if v.dims().max_element() <= 1 {
            return Err("cannot fit even a single voxel".into());
        }
        v = downsample2(&v, filter)?;
        n += 1;
    }
    Ok((Some(v), n))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::ValueMap;

    #[test]
    fn averages_blocks_and_moves_the_grid() {
        // 3×2×2 voxels: the odd edge averages only what exists.
        let codes: Vec<u8> = (0..12).map(|i| i * 10).collect();
        let v =
            Volume::new("v", Grid::new(UVec3::new(3, 2, 2), Vec3::ONE), Voxels::U8(codes), ValueMap::IDENTITY, Source::default()).unwrap();
        let h = downsample2(&v, Filter::Average).unwrap();
        assert_eq!(h.dims(), UVec3::new(2, 1, 1));
        // Block (0..2, 0..2, 0..2): codes 0,10,30,40,60,70,90,100 → 50.
        assert_eq!(h.code(0, 0, 0), 50);
        // Block (2, 0..2, 0..2): codes 20,50,80,110 → 65.
        assert_eq!(h.code(1, 0, 0), 65);
        assert_eq!(h.grid.spacing, Vec3::splat(2.0));
        assert_eq!(h.grid.origin, Vec3::splat(0.5));
        let n = downsample2(&v, Filter::Nearest).unwrap();
        assert_eq!((n.code(0, 0, 0), n.code(1, 0, 0)), (0, 20));
        let (fitted, halvings) = fit(&v, 1, 1 << 20, Filter::Average).unwrap();
        assert_eq!((fitted.unwrap().dims(), halvings), (UVec3::ONE, 2));
        assert!(fit(&v, 4, 1 << 20, Filter::Average).unwrap().0.is_none());
    }
}
