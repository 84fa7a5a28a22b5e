//! An engine-block-like mechanical part with internal cavities (8-bit, industrial CT
//! style: air 0, cast aluminium 110, steel 230).
//!
//! A rounded aluminium block holds four vertical cylinder bores with steel liners, a
//! crankshaft tunnel along x with steel bearing rings, a closed coolant jacket around
//! the bore row (channels that do not reach the outside: internal cavities), an
//! oil gallery drilled along the block, bolt holes at the corners and a steel valve seat
//! at the top of every bore. World frame: x along the crank, z up; 240 mm long.

use glam::{UVec3, Vec3};

use super::shapes::{Layer, Shape, hash_noise, paint};
use crate::volume::{Grid, Source, ValueMap, Volume, Voxels};

/// Length of the block's field of view along x, in millimetres.
pub const FIELD_OF_VIEW: f32 = 240.0;

const AIR: f32 = 0.0;
const ALUMINIUM: f32 = 110.0;
const STEEL: f32 = 230.0;

/// Bore centres (x) of the four cylinders.
pub fn bore_centers() -> [f32; 4] {
    [-72.0, -24.0, 24.0, 72.0]
}

/// Half-extents (x, y) of the coolant loops (at z = 18 and z = −2, radius 4).
pub fn coolant_loop() -> (f32, f32) {
    (100.0, 32.0)
}

fn layers() -> Vec<Layer> {
    let mut l = vec![Layer::new(
        Shape::RoundBox { center: Vec3::new(0.0, 0.0, 0.0), half: Vec3::new(110.0, 45.0, 52.0), round: 8.0 },
        ALUMINIUM,
        1,
    )];
    // Coolant jacket: two closed rectangular loops of channel around the bore row, at two
    // heights (internal cavities: nowhere do they reach the outside).
    for z in [18.0f32, -2.0] {
        let (x, y) = coolant_loop();
        let corners = [Vec3::new(-x, -y, z), Vec3::new(x, -y, z), Vec3::new(x, y, z), Vec3::new(-x, y, z)];
        for i in 0..4 {
            l.push(Layer::new(Shape::Capsule { a: corners[i], b: corners[(i + 1) % 4], r: 4.0 }, AIR, 0));
        }
    }
    // Steel liners, then the bores themselves (open at the top).
    for x in bore_centers() {
        l.push(Layer::new(Shape::Cylinder { center: Vec3::new(x, 0.0, 12.0), axis: Vec3::Z, half_length: 42.0, r: 21.5 }, STEEL, 2));
    }
    for x in bore_centers() {
        l.push(Layer::new(Shape::Cylinder { center: Vec3::new(x, 0.0, 14.0), axis: Vec3::Z, half_length: 42.0, r: 18.0 }, AIR, 0));
        // Valve seat ring near the top.
        l.push(Layer::new(Shape::Torus { center: Vec3::new(x, 0.0, 48.0), axis: Vec3::Z, major: 15.0, minor: 2.5 }, STEEL, 3));
    }
    // Crankshaft tunnel with bearing rings.
    l.push(Layer::new(Shape::Cylinder { center: Vec3::new(0.0, 0.0, -36.0), axis: Vec3::X, half_length: 115.0, r: 16.0 }, AIR, 0));
    for x in [-96.0f32, -48.0, 0.0, 48.0, 96.0] {
        l.push(Layer::new(Shape::Torus { center: Vec3::new(x, 0.0, -36.0), axis: Vec3::X, major: 17.0, minor: 2.5 }, STEEL, 3));
    }
    // Oil gallery (a closed drilled channel) and corner bolt holes.
    l.push(Layer::new(Shape::Capsule { a: Vec3::new(-95.0, 32.0, -20.0), b: Vec3::new(95.0, 32.0, -20.0), r: 3.5 }, AIR, 0));
    for (x, y) in [(-100.0f32, -35.0f32), (-100.0, 35.0), (100.0, -35.0), (100.0, 35.0), (0.0, 36.0), (0.0, -36.0)] {
        l.push(Layer::new(Shape::Cylinder { center: Vec3::new(x, y, 30.0), axis: Vec3::Z, half_length: 24.0, r: 4.0 }, AIR, 0));
    }
    l
}

/// Generates the engine phantom on an `n × n × n/2` grid.
pub fn generate(n: u32) -> Result<Volume, String> {
    let n = n.max(8);
    let h = FIELD_OF_VIEW / n as f32;
    let grid = Grid::centered(UVec3::new(n, n, (n / 2).max(4)), Vec3::splat(h));
    let painted = paint(grid.dims, h, 2.0, grid.origin, AIR, &layers(), |i, v| if v > 5.0 { v + 3.0 * hash_noise(i, 7) } else { v });
    let codes = painted.values.iter().map(|&v| v.round().clamp(0.0, 255.0) as u8).collect();
    let source = Source {
        format: "phantom".into(),
        path: None,
        sample_type: "uint8".into(),
        details: vec![("phantom".into(), "engine block".into())],
    };
    Volume::new("engine phantom", grid, Voxels::U8(codes), ValueMap::IDENTITY, source)
}
