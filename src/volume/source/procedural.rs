//! A procedural pyramid of any size, computed a box at a time: tests and benchmarks at
//! scale (8192³ voxels is 1 TiB of 16-bit codes) without anything on disk.
//!
//! The field is a ball of gyroid lattices at three periods (256, 32 and 8 level-0
//! voxels) over a smooth core, so a coarse level shows the ball and the large cells and
//! only the finest levels show the smallest ones (gone from level 3 up). With `u = ωx`, each lattice is
//! `g = sin u·cos v + sin v·cos w + sin w·cos u`, a sum of products of one sine or cosine
//! per axis. The mean of `sin(ω(x₀ + i))` over the `n = 2ᵏ` voxels `i = 0 … n − 1` of a
//! level-`k` block is `sin(ω x_c) · Dₙ(ω)` with `x_c` the block's centre and
//! `Dₙ(ω) = sin(nω/2) / (n sin(ω/2))` (the Dirichlet kernel; likewise for the cosine), so
//! level `k` evaluates every lattice at the block centre times `Dₙ(ω)²`: the exact block
//! mean of level 0 for the lattices, which is what a 2×-averaging pyramid holds. Only the
//! slowly varying envelope and core are taken at the centre rather than averaged, and
//! codes are rounded: a level differs from the mean of the finer one by a few codes in
//! 65 535 ([`tests`] measures it).

use std::f32::consts::TAU;

use glam::{UVec3, Vec3};

use super::{Block, SourceError, SourceInfo, SourceLevel, VoxelSource, check_box, level_count, level_grid};
use crate::volume::{Grid, Source, ValueMap, Voxels};

/// Lattice periods in level-0 voxels and their amplitudes (of a value in 0..1).
const LATTICES: [(f32, f32); 3] = [(256.0, 0.2), (32.0, 0.1), (8.0, 0.05)];

/// Voxel spacing of procedural sources unless given (10 µm, as in micro-CT).
pub const DEFAULT_SPACING_MM: f32 = 0.01;

/// Dimensions from `N` (a cube) or `NXxNYxNZ`, as `procedural:8192` names them.
pub fn parse_dims(text: &str) -> Result<UVec3, String> {
    let parts: Vec<&str> = text.split('x').collect();
    let n: Vec<u32> = parts
        .iter()
        .map(|p| p.trim().parse::<u32>().map_err(|_| format!("procedural size '{text}' is not N or NXxNYxNZ")))
        .collect::<Result<_, _>>()?;
    match n[..] {
        [a] => Ok(UVec3::splat(a)),
        [a, b, c] => Ok(UVec3::new(a, b, c)),
        _ => Err(format!("procedural size '{text}' is not N or NXxNYxNZ")),
    }
}

/// The gyroid ball.
pub struct ProceduralSource {
    info: SourceInfo,
}

impl ProceduralSource {
    /// A field of `dims` voxels of `spacing` millimetres, centred on the origin, with
    /// levels down to at most 64 voxels per axis.
    pub fn new(dims: UVec3, spacing: Vec3) -> Result<Self, String> {
        if dims.max_element() > 1 << 16 {
            return Err(format!("procedural size {} exceeds 65536 voxels along an axis", super::super::grid::fmt_dims(dims)));
        }
        let base = Grid::centered(dims, spacing);
        base.validate()?;
        let n = level_count(dims, 64);
        let levels = (0..n as u32).map(|k| SourceLevel { grid: level_grid(&base, k), chunk: UVec3::splat(64) }).collect();
        let size = super::super::grid::fmt_dims(dims);
        let info = SourceInfo {
            name: format!("procedural {size}"),
            source: Source {
                format: "procedural".into(),
                path: None,
                sample_type: "uint16".into(),
                details: vec![("field".into(), "gyroid ball, lattice periods 256, 32, 8 voxels".into())],
            },
            values: ValueMap::IDENTITY,
            bits: 16,
            levels,
            warnings: Vec::new(),
            range: None,
        };
        Ok(Self { info })
    }

    /// The value (0..1) of level-0 voxel `(x, y, z)`; level-`k` values are block means.
    pub fn value(&self, level: u32, voxel: UVec3) -> f32 {
        let axes = [0, 1, 2].map(|a| Axis::new(self.info.levels[0].grid.dims[a], level, voxel[a], 1));
        field(&axes, [0, 0, 0])
    }
}

/// Per-axis terms of a run of voxels of one level: for each lattice `sin`, `cos` at the
/// block centres (attenuated by the Dirichlet kernel), and the centred coordinate.
struct Axis {
    sin: [Vec<f32>; 3],
    cos: [Vec<f32>; 3],
    /// Block centres relative to the field's centre, over its half-width.
    t: Vec<f32>,
}

impl Axis {
    fn new(dim0: u32, level: u32, lo: u32, len: u32) -> Axis {
        let n = (1u32 << level) as f32;
        let centre = |j: u32| n * j as f32 + (n - 1.0) * 0.5;
        let half = dim0 as f32 * 0.5;
        let t = (lo..lo + len).map(|j| (centre(j) + 0.5 - half) / half).collect();
        let term = |f: fn(f32) -> f32, i: usize| -> Vec<f32> {
            let w = TAU / LATTICES[i].0;
            let d = dirichlet(n, w);
            (lo..lo + len).map(|j| f(w * centre(j)) * d).collect()
        };
        Axis { sin: [0, 1, 2].map(|i| term(f32::sin, i)), cos: [0, 1, 2].map(|i| term(f32::cos, i)), t }
    }
}

/// Mean of `sin(ω(x₀ + i))`, `i = 0 … n − 1`, over `sin(ω x_c)`: `sin(nω/2) / (n sin(ω/2))`.
fn dirichlet(n: f32, w: f32) -> f32 {
    let s = (w * 0.5).sin();
    if n <= 1.0 || s.abs() < 1e-9 { 1.0 } else { (n * w * 0.5).sin() / (n * s) }
}

/// The field at element `at` of the three axes' runs.
#[inline]
fn field(axes: &[Axis; 3], at: [usize; 3]) -> f32 {
    let [x, y, z] = at;
    let (ax, ay, az) = (&axes[0], &axes[1], &axes[2]);
    let r2 = ax.t[x] * ax.t[x] + ay.t[y] * ay.t[y] + az.t[z] * az.t[z];
    // Ball of radius 0.85 (of the half-width), edge softened over 0.1.
    let envelope = smoothstep(0.95, 0.85, r2.sqrt());
    let mut lattice = 0.0;
    for (i, (_, amp)) in LATTICES.iter().enumerate() {
        let g = ax.sin[i][x] * ay.cos[i][y] + ay.sin[i][y] * az.cos[i][z] + az.sin[i][z] * ax.cos[i][x];
        lattice += amp * g / 1.5;
    }
    0.1 + envelope * (0.5 + lattice - 0.2 * r2)
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

impl VoxelSource for ProceduralSource {
    fn info(&self) -> &SourceInfo {
        &self.info
    }

    fn read_box(&self, level: usize, lo: UVec3, size: UVec3) -> Result<Block, SourceError> {
        check_box(&self.info, level, lo, size)?;
        let dims0 = self.info.levels[0].grid.dims;
        let axes = [0, 1, 2].map(|a| Axis::new(dims0[a], level as u32, lo[a], size[a]));
        let mut codes = Vec::with_capacity(size.x as usize * size.y as usize * size.z as usize);
        for z in 0..size.z as usize {
            for y in 0..size.y as usize {
                codes.extend((0..size.x as usize).map(|x| (field(&axes, [x, y, z]).clamp(0.0, 1.0) * 65535.0).round() as u16));
            }
        }
        Ok(Block { voxels: Voxels::U16(codes), faults: Vec::new() })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_dirichlet_kernel_is_the_mean_of_the_block() {
        // Independent: average sin(ω(x₀ + i)) directly.
        let (w, n, x0) = (TAU / 8.0, 4.0f32, 10.0f32);
        let mean = (0..4).map(|i| (w * (x0 + i as f32)).sin()).sum::<f32>() / n;
        let centre = x0 + 1.5;
        assert!((mean - (w * centre).sin() * dirichlet(n, w)).abs() < 1e-6);
        // A period of 8 averaged over 8 voxels vanishes.
        assert!(dirichlet(8.0, w).abs() < 1e-6);
        assert_eq!(dirichlet(1.0, w), 1.0);
    }

    #[test]
    fn each_level_is_the_block_mean_of_the_level_below() {
        let s = ProceduralSource::new(UVec3::splat(256), Vec3::splat(0.01)).expect("source");
        assert_eq!(s.info().levels.len(), 3);
        assert_eq!(s.info().levels[2].grid.dims, UVec3::splat(64));
        // In the ball's core the lattices are exact; across its soft surface the envelope
        // is taken at the block centre (within 1 % of the range).
        for (lo, tolerance) in [(UVec3::new(96, 96, 96), 8.0), (UVec3::new(8, 120, 128), 655.0)] {
            let fine = s.read_box(0, lo, UVec3::splat(16)).expect("fine");
            let coarse = s.read_box(1, lo / 2, UVec3::splat(8)).expect("coarse");
            let (Voxels::U16(f), Voxels::U16(c)) = (&fine.voxels, &coarse.voxels) else { panic!("16-bit codes") };
            let mut worst = 0.0f64;
            for z in 0..8 {
                for y in 0..8 {
                    for x in 0..8 {
                        let mut sum = 0.0;
                        for (dx, dy, dz) in (0..8).map(|i| (i & 1, i >> 1 & 1, i >> 2)) {
                            sum += f[((2 * z + dz) * 256 + (2 * y + dy) * 16 + 2 * x + dx) as usize] as f64;
                        }
                        worst = worst.max((sum / 8.0 - c[(z * 64 + y * 8 + x) as usize] as f64).abs());
                    }
                }
            }
            assert!(worst < tolerance, "level 1 differs from the mean of level 0 by {worst} codes at {lo}");
        }
        // Half a period of the finest lattice apart (and of opposite sign in the next),
        // level-0 voxels differ clearly: sin(31.5π) = −1 against sin(32.5π) = 1 gives
        // 2 · 0.05 / 1.5, the 32-voxel lattice adds 2 · 0.38 · 0.1 / 1.5.
        let step = s.value(0, UVec3::new(130, 128, 128)) - s.value(0, UVec3::new(126, 128, 128));
        assert!(step > 0.1, "{step}");
        // Two levels up it is damped to D₄(2π/8) = 1 / (4 sin(π/8)) = 0.653; three up a
        // block spans its whole period and it is gone.
        assert!((dirichlet(4.0, TAU / 8.0) - 0.653).abs() < 1e-3);
        assert!(dirichlet(8.0, TAU / 8.0).abs() < 1e-6);
    }

    #[test]
    fn sizes_parse_as_a_cube_or_three_edges() {
        assert_eq!(parse_dims("8192"), Ok(UVec3::splat(8192)));
        assert_eq!(parse_dims("64x32x16"), Ok(UVec3::new(64, 32, 16)));
        assert!(parse_dims("64x32").is_err());
        assert!(parse_dims("big").is_err());
        assert!(ProceduralSource::new(UVec3::new(0, 4, 4), Vec3::ONE).is_err());
    }

    #[test]
    fn sizes_of_a_terabyte_cost_nothing_to_open() {
        let s = ProceduralSource::new(UVec3::splat(8192), Vec3::splat(0.01)).expect("source");
        assert_eq!(s.info().levels.len(), 8);
        assert_eq!(s.info().levels[7].grid.dims, UVec3::splat(64));
        let b = s.read_box(0, UVec3::splat(4000), UVec3::splat(8)).expect("box");
        assert_eq!(b.voxels.len(), 512);
    }
}
