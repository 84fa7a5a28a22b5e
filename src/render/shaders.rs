//! The WGSL of the ray caster, embedded in the binary under fixed handles. The shared
//! modules (`#define_import_path focal::…`) are registered by path so imports resolve;
//! the entry shader is referenced by [`RAYCAST`].

use bevy::asset::{Handle, uuid_handle};
use bevy::prelude::*;
use bevy::shader::Shader;

/// The ray-cast fragment shader.
pub const RAYCAST: Handle<Shader> = uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a11");

/// The compute shader of the feature lenses' silhouettes.
pub const FEATURE: Handle<Shader> = uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a12");

/// The pass that draws rays of a reduced resolution over the view (`render::reduced`).
pub const UPSCALE: Handle<Shader> = uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a13");

/// (fixed handle, file name, source) of every shader.
const SHADERS: [(Handle<Shader>, &str, &str); 20] = [
    (uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a01"), "shaders/focal/types.wgsl", include_str!("../../shaders/focal/types.wgsl")),
    (
        uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a02"),
        "shaders/focal/bindings.wgsl",
        include_str!("../../shaders/focal/bindings.wgsl"),
    ),
    (uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a03"), "shaders/focal/camera.wgsl", include_str!("../../shaders/focal/camera.wgsl")),
    (uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a04"), "shaders/focal/regions.wgsl", include_str!("../../shaders/focal/regions.wgsl")),
    (
        uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a05"),
        "shaders/focal/sampling.wgsl",
        include_str!("../../shaders/focal/sampling.wgsl"),
    ),
    (
        uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a06"),
        "shaders/focal/transfer.wgsl",
        include_str!("../../shaders/focal/transfer.wgsl"),
    ),
    (uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a07"), "shaders/focal/shading.wgsl", include_str!("../../shaders/focal/shading.wgsl")),
    (
        uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a08"),
        "shaders/focal/compositing.wgsl",
        include_str!("../../shaders/focal/compositing.wgsl"),
    ),
    (uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a09"), "shaders/focal/lens.wgsl", include_str!("../../shaders/focal/lens.wgsl")),
    (uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a0a"), "shaders/focal/context.wgsl", include_str!("../../shaders/focal/context.wgsl")),
    (
        uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a0b"),
        "shaders/focal/selection.wgsl",
        include_str!("../../shaders/focal/selection.wgsl"),
    ),
    (uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a0c"), "shaders/focal/samples.wgsl", include_str!("../../shaders/focal/samples.wgsl")),
    (
        uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a0d"),
        "shaders/focal/segments.wgsl",
        include_str!("../../shaders/focal/segments.wgsl"),
    ),
    (
        uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a0e"),
        "shaders/focal/two_level.wgsl",
        include_str!("../../shaders/focal/two_level.wgsl"),
    ),
    (uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a0f"), "shaders/focal/bricked.wgsl", include_str!("../../shaders/focal/bricked.wgsl")),
    (
        uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a10"),
        "shaders/focal/footprint.wgsl",
        include_str!("../../shaders/focal/footprint.wgsl"),
    ),
    (uuid_handle!("6a1f3a52-1b0e-4c5f-9d3e-2f6c0b8e7a14"), "shaders/focal/insets.wgsl", include_str!("../../shaders/focal/insets.wgsl")),
    (RAYCAST, "shaders/raycast.wgsl", include_str!("../../shaders/raycast.wgsl")),
    (FEATURE, "shaders/feature.wgsl", include_str!("../../shaders/feature.wgsl")),
    (UPSCALE, "shaders/upscale.wgsl", include_str!("../../shaders/upscale.wgsl")),
];

/// Environment variable naming a folder (a checkout's root) whose `shaders/` replace the
/// embedded ones at start-up: shader work without rebuilding the binary.
pub const SHADERS_FROM: &str = "FOCAL_SHADERS_FROM";

/// Inserts every shader into `Assets<Shader>` (from [`SHADERS_FROM`] when it is set; a
/// file that cannot be read there keeps the embedded source, with an error in the log).
pub fn register(app: &mut App) {
    let from = std::env::var_os(SHADERS_FROM).map(std::path::PathBuf::from);
    let mut shaders = app.world_mut().resource_mut::<Assets<Shader>>();
    for (handle, path, embedded) in SHADERS {
        let source = match &from {
            Some(root) => match std::fs::read_to_string(root.join(path)) {
                Ok(text) => {
                    warn!("{path}: read from {}", root.display());
                    std::borrow::Cow::Owned(text)
                }
                Err(e) => {
                    error!("{}: {e}; the embedded {path} is used", root.join(path).display());
                    std::borrow::Cow::Borrowed(embedded)
                }
            },
            None => std::borrow::Cow::Borrowed(embedded),
        };
        if let Err(e) = shaders.insert(handle.id(), Shader::from_wgsl(source, path)) {
            error!("cannot register {path}: {e}");
        }
    }
}
