//! Fitting datasets to the GPU: a volume larger than the device's 3D-texture limit or
//! the memory budget is halved until it fits ([`crate::volume::resample::fit`]), with a
//! warning the app shows and the log records. The full-resolution volume stays for the
//! CPU (picking, statistics).

use std::sync::Arc;

use bevy::prelude::*;

use super::{Dataset, GpuVolume};
use crate::region::Lookup;
use crate::volume::resample::{Filter, fit};

/// Limits the GPU volume of every dataset must respect.
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct GpuLimits {
    /// Largest 3D texture edge (the device's `max_texture_dimension_3d`).
    pub max_dimension: u32,
    /// Largest volume texture in bytes.
    pub max_bytes: u64,
}

impl Default for GpuLimits {
    fn default() -> Self {
        Self { max_dimension: 2048, max_bytes: 2 << 30 }
    }
}

/// Attaches a reduced [`GpuVolume`] to datasets that exceed the limits.
pub fn fit_datasets(mut commands: Commands, limits: Res<GpuLimits>, datasets: Query<(Entity, &Dataset), Changed<Dataset>>) {
    for (entity, d) in &datasets {
        let filter = if matches!(d.appearance.lookup, Lookup::Labels(_)) { Filter::Nearest } else { Filter::Average };
        match fit(&d.volume, limits.max_dimension, limits.max_bytes, filter) {
            Ok((None, _)) => {
                commands.entity(entity).remove::<GpuVolume>();
            }
            Ok((Some(v), halvings)) => {
                let warning = format!(
                    "{} is {} voxels, more than this GPU holds (3D textures up to {} per axis, {} MiB): shown at 1/{} resolution ({})",
                    d.volume.name,
                    crate::volume::grid::fmt_dims(d.volume.dims()),
                    limits.max_dimension,
                    limits.max_bytes >> 20,
                    1 << halvings,
                    crate::volume::grid::fmt_dims(v.dims()),
                );
                warn!("{warning}");
                commands.entity(entity).insert(GpuVolume { volume: Arc::new(v), warning: Some(warning) });
            }
            Err(e) => error!("{}: cannot fit the GPU: {e}", d.volume.name),
        }
    }
}
