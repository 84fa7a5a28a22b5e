//! What the GPU refused, and whether the renderer stopped: for the app and the headless
//! renderer to act on instead of a wgpu panic or a silent quit.
//!
//! - **Uploads run inside error scopes** (out-of-memory, then validation: [`scoped`]).
//!   Whatever the device refuses there (memory it does not have, a texture beyond its
//!   limits) is an error value, not wgpu's uncaptured-error path. The render world
//!   records a [`Refusal`] and draws nothing of that scene until its volumes change.
//! - **A refusal of the volumes lowers [`GpuLimits`]** below what was refused: half its
//!   largest edge and half its bytes, and the datasets are fitted again
//!   ([`crate::dataset::gpu_fit`]: halved, with the warning the Data panel shows), so
//!   the scene comes back reduced; a refused brick cache halves the streaming GPU
//!   budget. Below [`MIN_EDGE`] voxels or [`MIN_BYTES`] nothing is tried again and the
//!   message says the scene cannot be drawn.
//! - **A lost device, or an error outside the scopes,** reaches Bevy's
//!   [`RenderErrorHandler`] (whose default quits at once). Ours records why and stops
//!   rendering; the app then keeps the user's session for the next start and quits
//!   with the message ([`crate::ui`]), the headless renderer returns it as its error.

use std::sync::{Arc, Mutex};

use bevy::prelude::*;
use bevy::render::error_handler::{ErrorType, RenderError, RenderErrorHandler, RenderErrorPolicy};
use bevy::render::renderer::RenderDevice;
use wgpu::ErrorFilter;

use crate::dataset::Dataset;
use crate::dataset::gpu_fit::GpuLimits;
use crate::streaming::bricked::StreamBudget;

/// Smallest 3D-texture edge worth trying after refusals.
pub const MIN_EDGE: u32 = 16;
/// Fewest bytes worth trying after refusals.
pub const MIN_BYTES: u64 = 1 << 20;

/// What an upload that the device refused was for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refused {
    /// The volume atlas and the scene's buffers.
    Volumes,
    /// The streamed bricks' cache atlas.
    BrickCache,
}

/// An upload the device refused.
#[derive(Clone, Debug, PartialEq)]
pub struct Refusal {
    pub what: Refused,
    /// The device's reason (wgpu's error).
    pub reason: String,
    /// The largest texture edge and the bytes of what was refused.
    pub largest_edge: u32,
    pub bytes: u64,
}

#[derive(Default, Debug)]
struct State {
    refused: Vec<Refusal>,
    stopped: Option<String>,
}

/// Shared by the main and render worlds (as [`super::RenderProgress`] is).
#[derive(Resource, Clone, Default)]
pub struct RenderHealth(Arc<Mutex<State>>);

impl RenderHealth {
    fn with<T>(&self, f: impl FnOnce(&mut State) -> T) -> T {
        let mut state = self.0.lock().unwrap_or_else(|e| e.into_inner());
        f(&mut state)
    }

    /// Records an upload the device refused (render world).
    pub fn refuse(&self, refusal: Refusal) {
        error!("the GPU refused {}: {}", refusal.describe(), refusal.reason);
        self.with(|s| s.refused.push(refusal));
    }

    /// The refusals since the last call (main world).
    pub fn take_refused(&self) -> Vec<Refusal> {
        self.with(|s| std::mem::take(&mut s.refused))
    }

    /// Why the renderer stopped (a lost device, an error outside the scopes), if it did.
    pub fn stopped(&self) -> Option<String> {
        self.with(|s| s.stopped.clone())
    }

    /// Records why rendering stopped; whether this was the first reason.
    fn stop(&self, why: String) -> bool {
        self.with(|s| {
            let first = s.stopped.is_none();
            s.stopped.get_or_insert(why);
            first
        })
    }
}

impl Refusal {
    fn describe(&self) -> String {
        let what = match self.what {
            Refused::Volumes => "the volume textures and buffers",
            Refused::BrickCache => "the brick cache",
        };
        format!("{what} ({} MiB, {} texels along the longest edge)", self.bytes.div_ceil(1 << 20), self.largest_edge)
    }
}

/// Runs `upload` inside out-of-memory and validation error scopes: its result, or the
/// device's reason for refusing it.
///
/// wgpu keeps error scopes per thread only with its "std" feature, which Bevy leaves
/// off: without it they were one stack for every thread, and Bevy's shader compiles on
/// the async compute threads popped ours out of order ("error scopes must be popped in
/// reverse order", in CI). The crate's manifest turns it on, and
/// the GPU test `error_scopes_are_kept_per_thread` proves it.
pub fn scoped<T>(device: &RenderDevice, upload: impl FnOnce() -> T) -> Result<T, String> {
    let device = device.wgpu_device();
    let memory = device.push_error_scope(ErrorFilter::OutOfMemory);
    let validation = device.push_error_scope(ErrorFilter::Validation);
    let out = upload();
    // (Scopes pop in the reverse order; on native backends the futures are ready.)
    let invalid = bevy::tasks::block_on(validation.pop());
    let out_of_memory = bevy::tasks::block_on(memory.pop());
    match (out_of_memory, invalid) {
        (Some(e), _) => Err(format!("out of GPU memory: {}", innermost(&e))),
        (None, Some(e)) => Err(format!("beyond what the device allows: {}", innermost(&e))),
        (None, None) => Ok(out),
    }
}

/// The line of a wgpu error that says what failed ("Dimension X value 4104 exceeds the
/// limit of 4096"): its last (the causes come after the kind of error).
fn innermost(e: &wgpu::Error) -> String {
    let text = e.to_string();
    text.lines().map(str::trim).rfind(|l| !l.is_empty()).unwrap_or(&text).to_string()
}

/// Bevy's handler for render errors outside the scopes: records why, stops rendering.
pub fn error_handler() -> RenderErrorHandler {
    RenderErrorHandler(|error: &RenderError, main_world: &mut World, _render_world: &mut World| {
        let why = match error.ty {
            ErrorType::DeviceLost => format!("the graphics device was lost ({})", error.description),
            ErrorType::OutOfMemory => "the graphics device ran out of memory".to_string(),
            _ => format!("the graphics device reported an error ({:?}: {})", error.ty, error.description),
        };
        // (Bevy asks again every frame after a stop: said once.)
        if main_world.get_resource::<RenderHealth>().is_some_and(|h| h.stop(why.clone())) {
            error!("rendering stopped: {why}");
        }
        RenderErrorPolicy::StopRendering
    })
}

/// The messages of refused uploads, for the app to show (main world).
#[derive(Resource, Default, Debug, Clone)]
pub struct GpuMessages(pub Vec<String>);

/// Lowers the limits below what the device refused and fits the datasets again, or
/// gives up below [`MIN_EDGE`] / [`MIN_BYTES`] (main world).
pub fn lower_limits_after_refusals(
    health: Res<RenderHealth>,
    mut limits: ResMut<GpuLimits>,
    mut budget: Option<ResMut<StreamBudget>>,
    mut datasets: Query<&mut Dataset>,
    mut messages: ResMut<GpuMessages>,
) {
    for r in health.take_refused() {
        let message = match r.what {
            Refused::Volumes => match lowered(*limits, &r) {
                Some(l) => {
                    *limits = l;
                    datasets.iter_mut().for_each(|mut d| d.set_changed());
                    format!(
                        "the GPU refused {} ({}): volumes are now fitted to {} texels along an axis and {} MiB",
                        r.describe(),
                        r.reason,
                        l.max_dimension,
                        l.max_bytes >> 20
                    )
                }
                None => format!(
                    "the GPU refused {} ({}); anything smaller is not worth drawing: the scene is not drawn",
                    r.describe(),
                    r.reason
                ),
            },
            Refused::BrickCache => match budget.as_deref_mut().filter(|b| b.gpu_bytes.min(r.bytes) / 2 >= MIN_BYTES) {
                Some(b) => {
                    // (Below what was refused: the cache may be smaller than the budget.)
                    b.gpu_bytes = b.gpu_bytes.min(r.bytes) / 2;
                    format!("the GPU refused {} ({}): the brick cache is now {} MiB", r.describe(), r.reason, b.gpu_bytes >> 20)
                }
                None => format!("the GPU refused {} ({}): streamed volumes are not drawn", r.describe(), r.reason),
            },
        };
        warn!("{message}");
        messages.0.push(message);
    }
}

/// Limits below a refused upload: half its longest edge and half its bytes (never
/// above the limits now), `None` below the least worth trying.
pub fn lowered(limits: GpuLimits, refused: &Refusal) -> Option<GpuLimits> {
    let l =
        GpuLimits { max_dimension: limits.max_dimension.min(refused.largest_edge / 2), max_bytes: limits.max_bytes.min(refused.bytes / 2) };
    (l.max_dimension >= MIN_EDGE && l.max_bytes >= MIN_BYTES).then_some(l)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_halve_below_what_was_refused_and_stop_at_the_least_worth_trying() {
        let limits = GpuLimits { max_dimension: 2048, max_bytes: 2 << 30 };
        let refusal = |edge, bytes| Refusal { what: Refused::Volumes, reason: String::new(), largest_edge: edge, bytes };
        // A 4100-texel atlas of 8 MiB: at most 2050 along an axis, but never above 2048.
        assert_eq!(lowered(limits, &refusal(4100, 8 << 20)), Some(GpuLimits { max_dimension: 2048, max_bytes: 4 << 20 }));
        // A 1 GiB atlas of 1024 texels a side: 512 and 512 MiB.
        assert_eq!(lowered(limits, &refusal(1024, 1 << 30)), Some(GpuLimits { max_dimension: 512, max_bytes: 512 << 20 }));
        // Nothing under 16 texels or 1 MiB is tried.
        assert_eq!(lowered(limits, &refusal(24, 1 << 30)), None);
        assert_eq!(lowered(limits, &refusal(1024, 1 << 20)), None);
    }

    /// Bevy's render errors: the handler records why in plain words and stops
    /// rendering instead of quitting (the app keeps the session first).
    #[test]
    fn a_lost_device_stops_rendering_with_its_reason() {
        let mut main_world = World::new();
        let health = RenderHealth::default();
        main_world.insert_resource(health.clone());
        let lost = RenderError { ty: ErrorType::DeviceLost, description: "driver reset".into(), source: None };
        let policy = (error_handler().0)(&lost, &mut main_world, &mut World::new());
        assert!(matches!(policy, RenderErrorPolicy::StopRendering));
        assert_eq!(health.stopped().as_deref(), Some("the graphics device was lost (driver reset)"));
        // The first reason stays.
        let memory = RenderError { ty: ErrorType::OutOfMemory, description: String::new(), source: None };
        let _ = (error_handler().0)(&memory, &mut main_world, &mut World::new());
        assert_eq!(health.stopped().as_deref(), Some("the graphics device was lost (driver reset)"));
        // Refusals are handed over once.
        health.refuse(Refusal { what: Refused::BrickCache, reason: "test".into(), largest_edge: 512, bytes: 1 << 28 });
        assert_eq!(health.take_refused().len(), 1);
        assert!(health.take_refused().is_empty());
    }
}
