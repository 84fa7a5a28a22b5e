//! Built-in procedural phantoms, so Focal runs with no files at all.
//!
//! - [`head`]: a CT-like head with skin, skull (with a burr hole), brain, ventricles,
//!   vessels, a lesion and tiny calcifications, plus a matching label volume;
//! - [`engine`]: a mechanical part with bores, liners and closed internal cavities;
//! - [`sphere`]: a ball with a one-voxel linear edge ramp whose 0.5 iso-surface is at an
//!   exactly known radius, for tests;
//! - [`lattice`]: a cubic lattice of thin bars, fine detail that shows magnification
//!   and aliasing (lens tests and figures).
//!
//! All are painted from signed-distance shapes ([`shapes`]) in parallel; 256³ takes a
//! fraction of a second (see `benches/volume.rs`).

pub mod engine;
pub mod head;
pub mod shapes;

use std::str::FromStr;

use glam::{UVec3, Vec3};
use serde::{Deserialize, Serialize};

use super::{Grid, Source, ValueMap, Volume, Voxels};
use shapes::{Layer, Shape, paint};

/// The phantoms by name (for the command line and scene files).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Phantom {
    Head,
    Engine,
    Sphere,
    Lattice,
}

impl Phantom {
    pub const ALL: [Phantom; 4] = [Phantom::Head, Phantom::Engine, Phantom::Sphere, Phantom::Lattice];

    pub fn name(self) -> &'static str {
        match self {
            Phantom::Head => "head",
            Phantom::Engine => "engine",
            Phantom::Sphere => "sphere",
            Phantom::Lattice => "lattice",
        }
    }

    /// Generates the phantom's intensity volume at resolution `n` (voxels along its
    /// longest axis).
    pub fn generate(self, n: u32) -> Result<Volume, String> {
        match self {
            Phantom::Head => Ok(head::generate(n)?.ct),
            Phantom::Engine => engine::generate(n),
            Phantom::Sphere => sphere(n, n as f32 * 0.35),
            Phantom::Lattice => lattice(n),
        }
    }
}

impl FromStr for Phantom {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        Phantom::ALL
            .into_iter()
            .find(|p| p.name() == s.trim().to_ascii_lowercase())
            .ok_or_else(|| format!("unknown phantom '{s}' (expected head, engine, sphere or lattice)"))
    }
}

/// The source record of an 8-bit test phantom.
fn source_u8(detail: String) -> Source {
    Source { format: "phantom".into(), path: None, sample_type: "uint8".into(), details: vec![("phantom".into(), detail)] }
}

/// A ball of radius `radius` voxels centred in an `n³` unit-spacing grid, value 1 inside
/// and 0 outside (8-bit codes 255 and 0), with a linear edge ramp two voxels wide
/// ([`shapes::paint`]): the normalised value 0.5 lies exactly at the radius, and
/// trilinear interpolation of the ramp is exact up to the sphere's curvature.
pub fn sphere(n: u32, radius: f32) -> Result<Volume, String> {
    let n = n.max(4);
    let grid = Grid::centered(UVec3::splat(n), Vec3::ONE);
    let layers = [Layer::new(Shape::Ellipsoid { center: Vec3::ZERO, radii: Vec3::splat(radius) }, 255.0, 1)];
    let painted = paint(grid.dims, 1.0, 2.0, grid.origin, 0.0, &layers, |_, v| v);
    let codes = painted.values.iter().map(|&v| v.round() as u8).collect();
    Volume::new("sphere phantom", grid, Voxels::U8(codes), ValueMap::IDENTITY, source_u8(format!("sphere r = {radius} voxels")))
}

/// A cubic lattice in an `n³` unit-spacing grid: bars along the three axes, one every
/// `period = max(4, n/24)` voxels, `⌈period/3⌉` voxels thick (8-bit 255 in the bars, 0
/// between them).
pub fn lattice(n: u32) -> Result<Volume, String> {
    let n = n.max(4);
    let period = (n / 24).max(4);
    let width = period.div_ceil(3);
    let grid = Grid::centered(UVec3::splat(n), Vec3::ONE);
    let on = |c: u32| c % period < width;
    let codes = (0..n * n * n)
        .map(|i| {
            let (x, y, z) = (i % n, (i / n) % n, i / (n * n));
            let axes = on(x) as u32 + on(y) as u32 + on(z) as u32;
            if axes >= 2 { 255 } else { 0 }
        })
        .collect();
    Volume::new(
        "lattice phantom",
        grid,
        Voxels::U8(codes),
        ValueMap::IDENTITY,
        source_u8(format!("lattice, bars every {period} voxels, {width} thick")),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn head_has_every_structure() {
        let h = head::generate(96).unwrap();
        let ids: Vec<u32> = h.labels.present_ids().iter().map(|(id, _)| *id).collect();
        for id in 0..=10 {
            assert!(ids.contains(&id), "label {id} missing at 96³: {ids:?}");
        }
        assert_eq!(h.ct.values.units.as_deref(), Some("HU"));
        // Air, soft tissue and bone are all present in HU.
        assert!(h.ct.stats.min <= -990.0 && h.ct.stats.max >= 1100.0, "{} {}", h.ct.stats.min, h.ct.stats.max);
        // Deep in the left hemisphere: white matter (26 HU ± noise).
        let q = h.ct.grid.world_to_index().transform_point3(Vec3::new(-35.0, 10.0, 40.0)).round().as_uvec3();
        let hu = h.ct.real(q.x, q.y, q.z);
        assert!((18.0..34.0).contains(&hu), "{hu}");
        assert_eq!(h.labels.id(q.x, q.y, q.z), head::label::WHITE_MATTER as u32);
        // The burr hole: the skull surface point on its axis is not bone.
        let (hole, _) = head::burr_hole();
        let idx = h.ct.grid.world_to_index().transform_point3(hole).round().as_uvec3();
        assert_ne!(h.labels.id(idx.x, idx.y, idx.z), head::label::SKULL as u32);
    }

    #[test]
    fn engine_has_internal_cavities() {
        let e = engine::generate(128).unwrap();
        // Inside a coolant channel (a cavity surrounded by metal) the value is air.
        let p = Vec3::new(40.0, engine::coolant_loop().1, 18.0);
        let i = e.grid.world_to_index().transform_point3(p).round().as_uvec3();
        assert!(e.code(i.x, i.y, i.z) < 20, "{}", e.code(i.x, i.y, i.z));
        // Directly above it (z = 30) is solid metal.
        let i = e.grid.world_to_index().transform_point3(p + Vec3::Z * 12.0).round().as_uvec3();
        assert!(e.code(i.x, i.y, i.z) > 90);
        assert_eq!("engine".parse::<Phantom>().unwrap(), Phantom::Engine);
        assert!("brain".parse::<Phantom>().is_err());
    }

    #[test]
    fn sphere_edge_is_at_the_radius() {
        // n = 33: voxel 16 is the centre; voxel 26 is exactly 10 voxels out, on the surface.
        let s = sphere(33, 10.0).unwrap();
        let v = |i: u32| s.code(i, 16, 16) as f32 / 255.0;
        assert!((v(26) - 0.5).abs() < 0.01, "{}", v(26));
        assert_eq!((v(16), v(32)), (1.0, 0.0));
        // The ramp is two voxels wide: linear in the distance d, 0.5 − d/2.
        assert_eq!((v(25), v(27)), (1.0, 0.0));
        let off = s.code(26, 17, 16) as f32 / 255.0; // d = √101 − 10
        assert!((off - (0.5 - (101f32.sqrt() - 10.0) / 2.0)).abs() < 0.003, "{off}");
    }

    #[test]
    fn lattice_bars_have_their_period_and_width() {
        let v = lattice(96).unwrap();
        // Period 4, width 2: a voxel is on a bar when two of its coordinates are 0 or 1
        // modulo 4; the fraction is 3·(1/2)²·(1/2) + (1/2)³ = 1/2.
        let on = (0..v.voxels.len()).filter(|&i| v.voxels.code(i) == 255).count();
        assert!((on as f32 / v.voxels.len() as f32 - 0.5).abs() < 1e-6);
        assert_eq!(v.code(1, 1, 3), 255);
        assert_eq!(v.code(2, 3, 1), 0);
        assert_eq!("lattice".parse::<Phantom>().unwrap(), Phantom::Lattice);
    }
}
