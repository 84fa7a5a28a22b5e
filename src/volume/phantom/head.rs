//! A CT-like head phantom in Hounsfield units, with a matching label volume.
//!
//! World frame RAS (x right, y anterior, z superior), centred on the origin, 240 mm
//! across. Layers, outside in: scalp (40 HU), subcutaneous fat (−90 HU), skull
//! (1200 HU cortical bone) with a burr hole over the right parietal bone, grey matter
//! (38 HU) and white matter (26 HU), two lateral ventricles and the third ventricle
//! (CSF, 6 HU), contrast-filled arteries (a circle-of-Willis-like ring with middle
//! cerebral branches, 320 HU), an enhancing lesion (90 HU), eyes (vitreous 10 HU, lens
//! 110 HU) and a cluster of sub-millimetre to 2 mm calcifications (700–900 HU) near the
//! lesion: the small dense structures a magic lens is for. A little deterministic
//! noise (±6 HU) inside the head keeps renderings honest.

use glam::{UVec3, Vec3};

use super::shapes::{Layer, Shape, hash_noise, paint};
use crate::volume::{Grid, Label, LabelTable, LabelVolume, Source, ValueMap, Volume, Voxels};

/// Field of view of the head phantom in millimetres.
pub const FIELD_OF_VIEW: f32 = 240.0;

/// Label ids of the head phantom.
pub mod label {
    pub const SCALP: u8 = 1;
    pub const FAT: u8 = 2;
    pub const SKULL: u8 = 3;
    pub const GREY_MATTER: u8 = 4;
    pub const WHITE_MATTER: u8 = 5;
    pub const VENTRICLES: u8 = 6;
    pub const ARTERIES: u8 = 7;
    pub const CALCIFICATIONS: u8 = 8;
    pub const LESION: u8 = 9;
    pub const EYES: u8 = 10;
}

/// The CT volume and its labels.
pub struct HeadPhantom {
    pub ct: Volume,
    pub labels: LabelVolume,
}

/// Centres and radii (mm) of the calcification cluster.
pub fn calcifications() -> Vec<(Vec3, f32)> {
    let c = Vec3::new(28.0, 18.0, 22.0);
    let offsets = [
        (Vec3::new(0.0, 0.0, 0.0), 2.0),
        (Vec3::new(4.0, 1.5, -1.0), 1.2),
        (Vec3::new(-3.0, 3.5, 1.5), 1.0),
        (Vec3::new(2.0, -4.0, 2.5), 0.8),
        (Vec3::new(-4.5, -2.0, -2.0), 1.5),
        (Vec3::new(6.0, -1.0, 3.0), 0.7),
        (Vec3::new(1.0, 5.0, -3.0), 0.9),
    ];
    offsets.iter().map(|&(o, r)| (c + o, r)).collect()
}

/// Centre and radius of the burr hole in the skull (axis points from the centre of the head).
pub fn burr_hole() -> (Vec3, f32) {
    (Vec3::new(45.0, -20.0, 62.0), 7.0)
}

fn layers() -> Vec<Layer> {
    use label::*;
    let e = |c: Vec3, r: Vec3| Shape::Ellipsoid { center: c, radii: r };
    let mut l = vec![
        // Neck and head outline.
        Layer::new(Shape::Capsule { a: Vec3::new(0.0, -10.0, -120.0), b: Vec3::new(0.0, -10.0, -40.0), r: 55.0 }, 40.0, SCALP),
        Layer::new(e(Vec3::new(0.0, 0.0, 5.0), Vec3::new(78.0, 98.0, 92.0)), 40.0, SCALP),
        // Nose.
        Layer::new(Shape::Capsule { a: Vec3::new(0.0, 92.0, 0.0), b: Vec3::new(0.0, 106.0, -22.0), r: 9.0 }, 40.0, SCALP),
        Layer::new(e(Vec3::new(0.0, 0.0, 5.0), Vec3::new(74.0, 94.0, 88.0)), -90.0, FAT),
        Layer::new(e(Vec3::new(0.0, -2.0, 8.0), Vec3::new(70.0, 89.0, 83.0)), 1200.0, SKULL),
    ];
    // Burr hole: a short cylinder through the skull, filled with soft tissue.
    let (hole, r) = burr_hole();
    let axis = hole.normalize();
    l.push(Layer::new(Shape::Cylinder { center: hole, axis, half_length: 9.0, r }, 30.0, FAT));
    l.extend([
        Layer::new(e(Vec3::new(0.0, -2.0, 10.0), Vec3::new(63.0, 82.0, 76.0)), 38.0, GREY_MATTER),
        Layer::new(e(Vec3::new(0.0, -2.0, 12.0), Vec3::new(54.0, 72.0, 64.0)), 26.0, WHITE_MATTER),
        // Lateral ventricles (bananas approximated by capsules) and the third ventricle.
        Layer::new(Shape::Capsule { a: Vec3::new(-12.0, 22.0, 18.0), b: Vec3::new(-15.0, -28.0, 20.0), r: 6.5 }, 6.0, VENTRICLES),
        Layer::new(Shape::Capsule { a: Vec3::new(12.0, 22.0, 18.0), b: Vec3::new(15.0, -28.0, 20.0), r: 6.5 }, 6.0, VENTRICLES),
        Layer::new(Shape::Capsule { a: Vec3::new(-15.0, -28.0, 20.0), b: Vec3::new(-22.0, -40.0, 2.0), r: 4.5 }, 6.0, VENTRICLES),
        Layer::new(Shape::Capsule { a: Vec3::new(15.0, -28.0, 20.0), b: Vec3::new(22.0, -40.0, 2.0), r: 4.5 }, 6.0, VENTRICLES),
        Layer::new(e(Vec3::new(0.0, -2.0, 4.0), Vec3::new(2.5, 14.0, 9.0)), 6.0, VENTRICLES),
        // Enhancing lesion.
        Layer::new(e(Vec3::new(28.0, 18.0, 22.0), Vec3::new(12.0, 10.0, 9.0)), 90.0, LESION),
    ]);
    // Arteries: a ring at the skull base and middle cerebral branches.
    let ring: Vec<Vec3> = (0..=8)
        .map(|i| {
            let a = i as f32 / 8.0 * std::f32::consts::TAU;
            Vec3::new(14.0 * a.cos(), -4.0 + 10.0 * a.sin(), -18.0)
        })
        .collect();
    for w in ring.windows(2) {
        l.push(Layer::new(Shape::Capsule { a: w[0], b: w[1], r: 1.6 }, 320.0, ARTERIES));
    }
    let branches = [
        (Vec3::new(14.0, -4.0, -18.0), Vec3::new(38.0, 2.0, -10.0), Vec3::new(52.0, -6.0, 10.0), Vec3::new(50.0, -30.0, 30.0)),
        (Vec3::new(-14.0, -4.0, -18.0), Vec3::new(-38.0, 2.0, -10.0), Vec3::new(-52.0, -6.0, 10.0), Vec3::new(-50.0, -30.0, 30.0)),
        (Vec3::new(0.0, 6.0, -18.0), Vec3::new(0.0, 40.0, 0.0), Vec3::new(4.0, 50.0, 30.0), Vec3::new(6.0, 10.0, 58.0)),
        (Vec3::new(0.0, -14.0, -18.0), Vec3::new(0.0, -30.0, -40.0), Vec3::new(0.0, -20.0, -80.0), Vec3::new(0.0, -15.0, -115.0)),
    ];
    for (a, b, c, d) in branches {
        for w in [a, b, c, d].windows(2) {
            l.push(Layer::new(Shape::Capsule { a: w[0], b: w[1], r: 1.3 }, 320.0, ARTERIES));
        }
    }
    // Eyes: vitreous and lens.
    for s in [-1.0f32, 1.0] {
        l.push(Layer::new(e(Vec3::new(s * 32.0, 70.0, -8.0), Vec3::splat(12.0)), 10.0, EYES));
        l.push(Layer::new(e(Vec3::new(s * 32.0, 81.0, -8.0), Vec3::new(4.5, 1.8, 4.5)), 110.0, EYES));
    }
    for (c, r) in calcifications() {
        l.push(Layer::new(e(c, Vec3::splat(r)), 700.0 + 100.0 * r, CALCIFICATIONS));
    }
    l
}

/// The label table of the head phantom.
pub fn label_table() -> LabelTable {
    use label::*;
    let mut t = LabelTable::default();
    for (id, name, color) in [
        (SCALP, "scalp", [222, 170, 140]),
        (FAT, "subcutaneous fat", [250, 220, 110]),
        (SKULL, "skull", [240, 235, 220]),
        (GREY_MATTER, "grey matter", [150, 150, 160]),
        (WHITE_MATTER, "white matter", [235, 235, 240]),
        (VENTRICLES, "ventricles", [80, 140, 230]),
        (ARTERIES, "arteries", [220, 40, 40]),
        (CALCIFICATIONS, "calcifications", [255, 255, 90]),
        (LESION, "lesion", [170, 60, 200]),
        (EYES, "eyes", [110, 200, 210]),
    ] {
        t.labels.insert(id as u32, Label { name: name.into(), color });
    }
    t
}

/// Generates the head phantom on an `n³` grid.
pub fn generate(n: u32) -> Result<HeadPhantom, String> {
    let n = n.max(8);
    let h = FIELD_OF_VIEW / n as f32;
    let grid = Grid::centered(UVec3::splat(n), Vec3::splat(h));
    let layers = layers();
    let painted = paint(grid.dims, h, 3.0, grid.origin, -1000.0, &layers, |i, v| if v > -500.0 { v + 6.0 * hash_noise(i, 11) } else { v });
    let codes: Vec<u16> = painted.values.iter().map(|&hu| (hu + 1024.0).round().clamp(0.0, 4095.0) as u16).collect();
    let source =
        Source { format: "phantom".into(), path: None, sample_type: "int16".into(), details: vec![("phantom".into(), "CT head".into())] };
    let ct = Volume::new(
        "head phantom",
        grid.clone(),
        Voxels::U16(codes),
        ValueMap::new(1.0, -1024.0).with_units(Some("HU".into())),
        source.clone(),
    )?;
    let lv = Volume::new(
        "head phantom labels",
        grid,
        Voxels::U8(painted.labels),
        ValueMap::IDENTITY,
        Source { sample_type: "uint8".into(), ..source },
    )?;
    Ok(HeadPhantom { ct, labels: LabelVolume { volume: lv, table: label_table() } })
}
