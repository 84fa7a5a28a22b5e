//! Packs a view's resolved lenses into its settings uniform (the lens systems decided
//! everything; this only lays it out for `shaders/focal/lens.wgsl`).

use glam::{UVec4, Vec4};

use super::gpu_types::{GpuLens, GpuSettings, lens_codes};
use crate::lens::shape::Shape;
use crate::lens::stack::Effect;
use crate::lens::{MAX_LENSES, ResolvedLens};

/// Writes `lenses` into `settings` (at most [`MAX_LENSES`]).
pub fn pack_lenses(settings: &mut GpuSettings, lenses: &[ResolvedLens]) {
    settings.lens_count = lenses.len().min(MAX_LENSES) as u32;
    for (i, lens) in lenses.iter().take(MAX_LENSES).enumerate() {
        let data = &mut settings.lens_data[i * lens_codes::DATA_PER_LENS..(i + 1) * lens_codes::DATA_PER_LENS];
        let (shape, vertices) = match &lens.shape {
            Shape::Circle => (lens_codes::CIRCLE, 0),
            Shape::Square => (lens_codes::SQUARE, 0),
            Shape::Polygon(points) => {
                for (slot, pair) in data.iter_mut().zip(points.chunks(2)) {
                    let b = pair.get(1).copied().unwrap_or_default();
                    *slot = Vec4::new(pair[0].x, pair[0].y, b.x, b.y);
                }
                (lens_codes::POLYGON, points.len() as u32)
            }
        };
        let (kind, profile, params) = match &lens.effect {
            Effect::Magnifier(m) => (lens_codes::MAGNIFIER, m.profile.code(), Vec4::new(m.plane, m.kappa, m.magnification, 0.0)),
            Effect::Sampling(table) => {
                for (slot, four) in data.iter_mut().zip(table.chunks(4)) {
                    *slot = Vec4::new(four[0], four[1], four[2], four[3]);
                }
                (lens_codes::SAMPLING, 0, Vec4::ZERO)
            }
            Effect::Angular { half_angle, whole_view } => {
                (lens_codes::ANGULAR, 0, Vec4::new(*half_angle, if *whole_view { 1.0 } else { 0.0 }, 0.0, 0.0))
            }
        };
        settings.lenses[i] = GpuLens {
            codes: UVec4::new(kind, shape, profile, vertices),
            geometry: Vec4::new(lens.center.x, lens.center.y, lens.radius, lens.border),
            params,
        };
    }
}
