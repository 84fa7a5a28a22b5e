//! Packs a view's resolved lenses into its settings uniform, and the silhouettes of its
//! feature lenses into a storage buffer of their own (the lens systems decided
//! everything; this only lays it out for `shaders/focal/lens.wgsl`).

use bevy::prelude::*;
use bevy::render::extract_component::ExtractComponent;
use bevy::render::sync_component::SyncComponent;
use glam::{UVec4, Vec4};

use super::gpu_types::{GpuLens, GpuSettings, lens_codes};
use crate::lens::feature::{FIELD_HEADER, FeatureJob};
use crate::lens::shape::Shape;
use crate::lens::stack::Effect;
use crate::lens::{MAX_LENSES, ResolvedLens, ViewLenses};

/// The silhouettes of a view's feature lenses, one after another in lens order (each
/// lens's data holds its offset): a header ([`FIELD_HEADER`]) and the signed distances.
/// Those the CPU found are in `values`; the others are zeros there and `jobs` (offset,
/// job) for the compute passes to fill.
#[derive(Component, Clone, Debug, Default, PartialEq)]
pub struct GpuFeatureFields {
    pub values: Vec<f32>,
    pub jobs: Vec<(u32, FeatureJob)>,
}

/// The silhouettes of `lenses`, concatenated.
pub fn feature_data(lenses: &[ResolvedLens]) -> GpuFeatureFields {
    let mut out = GpuFeatureFields::default();
    for lens in lenses.iter().take(MAX_LENSES) {
        match (&lens.field, &lens.job) {
            (Some(field), _) => {
                out.values.extend(field.header());
                out.values.extend(&field.distance);
            }
            (None, Some(job)) => {
                out.jobs.push((out.values.len() as u32, *job));
                out.values.resize(out.values.len() + FIELD_HEADER + job.grid.cells(), 0.0);
            }
            (None, None) => {}
        }
    }
    out
}

impl SyncComponent for ViewLenses {
    type Target = GpuFeatureFields;
}

impl ExtractComponent for ViewLenses {
    type QueryData = &'static ViewLenses;
    type QueryFilter = With<Camera3d>;
    type Out = GpuFeatureFields;

    fn extract_component(lenses: &ViewLenses) -> Option<GpuFeatureFields> {
        Some(feature_data(&lenses.lenses))
    }
}

/// Writes `lenses` into `settings` (at most [`MAX_LENSES`]).
pub fn pack_lenses(settings: &mut GpuSettings, lenses: &[ResolvedLens]) {
    settings.lens_count = lenses.len().min(MAX_LENSES) as u32;
    let mut field_offset = 0usize;
    for (i, lens) in lenses.iter().take(MAX_LENSES).enumerate() {
        let data = &mut settings.lens_data[i * lens_codes::DATA_PER_LENS..(i + 1) * lens_codes::DATA_PER_LENS];
        let grid = lens.field.as_ref().map(|f| f.grid);
        let (shape, vertices) = match (&lens.shape, grid.or(lens.job.map(|j| j.grid))) {
            (_, Some(grid)) => {
                data[0] = Vec4::new(grid.cols as f32, grid.rows as f32, grid.origin.x, grid.origin.y);
                data[1] = Vec4::new(grid.step.x, grid.step.y, field_offset as f32, 0.0);
                field_offset += FIELD_HEADER + grid.cells();
                (lens_codes::FEATURE, 0)
            }
            (Shape::Circle | Shape::Feature(_), None) => (lens_codes::CIRCLE, 0),
            (Shape::Square, None) => (lens_codes::SQUARE, 0),
            (Shape::Polygon(points), None) => {
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
