//! Rendering without a window: a Bevy app with Focal's plugins drawing into an image
//! target, read back after each capture. Used by `focal render`, the GPU image tests and
//! `focal bench`.
//!
//! Pipelines compile synchronously, and a capture waits a few frames after the scene
//! changes so the volume upload and the pipeline are in place.

use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use bevy::asset::RenderAssetUsages;
use bevy::camera::RenderTarget;
use bevy::camera::ScalingMode;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::prelude::*;
use bevy::render::RenderPlugin;
use bevy::render::pipelined_rendering::PipelinedRenderingPlugin;
use bevy::render::render_resource::{Extent3d, PollType, TextureDimension, TextureFormat, TextureUsages};
use bevy::render::renderer::{RenderAdapterInfo, RenderDevice};
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::window::ExitCondition;
use bevy::winit::WinitPlugin;

use super::VolumeView;
use super::pipeline::RaycastPipelineId;
use super::upload::GpuScene;
use crate::streaming::bricked::StreamStatus;

/// Longest wait of a headless render for streaming to converge.
pub const STREAM_WAIT: Duration = Duration::from_secs(300);
use crate::region::{Camera as FocalCamera, Projection as FocalProjection};
use bevy::render::RenderApp;
use bevy::render::render_resource::{CachedPipelineState, PipelineCache};

/// Most frames to wait for the pipeline and the upload, and for a capture.
const MAX_WAIT_FRAMES: u32 = 20;

/// The Bevy camera components that show a Focal camera.
pub fn camera_bundle(cam: &FocalCamera) -> (Transform, Projection) {
    let projection = match cam.projection {
        FocalProjection::Perspective { fov_y } => Projection::Perspective(PerspectiveProjection { fov: fov_y, near: 0.1, ..default() }),
        FocalProjection::Orthographic { height } => Projection::Orthographic(OrthographicProjection {
            near: 0.0,
            far: 1.0e6,
            scaling_mode: ScalingMode::FixedVertical { viewport_height: height },
            ..OrthographicProjection::default_3d()
        }),
    };
    (Transform { translation: cam.position, rotation: cam.rotation, scale: Vec3::ONE }, projection)
}

/// An app that renders into an image.
pub struct Offscreen {
    app: App,
    target: Handle<Image>,
    camera: Entity,
    pub width: u32,
    pub height: u32,
}

impl Offscreen {
    /// Builds the app and its GPU device; `plugins` adds Focal's (or a test's) plugins.
    pub fn new(width: u32, height: u32, plugins: impl FnOnce(&mut App)) -> Result<Offscreen, String> {
        if width == 0 || height == 0 || width > 16384 || height > 16384 {
            return Err(format!("image size {width}×{height} is not 1..16384 on each side"));
        }
        let mut app = App::new();
        let defaults = DefaultPlugins
            .set(WindowPlugin { primary_window: None, exit_condition: ExitCondition::DontExit, ..default() })
            .set(RenderPlugin { synchronous_pipeline_compilation: true, ..default() })
            .disable::<WinitPlugin>()
            // One update = one rendered frame, so a GPU wait covers the frame just updated.
            .disable::<PipelinedRenderingPlugin>();
        // The global logger can be installed once per process.
        static LOGGER: std::sync::Once = std::sync::Once::new();
        let mut first = false;
        LOGGER.call_once(|| first = true);
        if first {
            app.add_plugins(defaults);
        } else {
            app.add_plugins(defaults.disable::<bevy::log::LogPlugin>());
        }
        plugins(&mut app);
        app.finish();
        app.cleanup();
        if app.world().get_resource::<RenderDevice>().is_none() {
            return Err("no GPU device (install mesa-vulkan-drivers for software Vulkan, and set WGPU_BACKEND=vulkan)".into());
        }
        let mut target = Image::new_uninit(
            Extent3d { width, height, depth_or_array_layers: 1 },
            TextureDimension::D2,
            TextureFormat::Rgba8UnormSrgb,
            RenderAssetUsages::RENDER_WORLD,
        );
        target.texture_descriptor.usage |= TextureUsages::RENDER_ATTACHMENT | TextureUsages::COPY_SRC;
        let world = app.world_mut();
        let target = world.resource_mut::<Assets<Image>>().add(target);
        let camera = world
            .spawn((
                Camera3d::default(),
                RenderTarget::Image(target.clone().into()),
                Msaa::Off,
                Tonemapping::None,
                Camera { clear_color: Color::BLACK.into(), ..default() },
                Transform::from_xyz(0.0, -500.0, 0.0).looking_at(Vec3::ZERO, Vec3::Z),
                VolumeView::default(),
            ))
            .id();
        Ok(Offscreen { app, target, camera, width, height })
    }

    /// The adapter the app renders with (`llvmpipe` on software Vulkan).
    pub fn adapter_name(&self) -> String {
        self.app.world().get_resource::<RenderAdapterInfo>().map(|i| i.name.clone()).unwrap_or_default()
    }

    pub fn world_mut(&mut self) -> &mut World {
        self.app.world_mut()
    }

    pub fn camera(&self) -> Entity {
        self.camera
    }

    /// Points the camera.
    pub fn set_camera(&mut self, cam: &FocalCamera) {
        let (transform, projection) = camera_bundle(cam);
        self.app.world_mut().entity_mut(self.camera).insert((transform, projection));
    }

    /// Sets the background (display sRGB).
    pub fn set_background(&mut self, rgb: [f32; 3]) {
        let color = Color::srgb(rgb[0], rgb[1], rgb[2]);
        if let Some(mut cam) = self.app.world_mut().get_mut::<Camera>(self.camera) {
            cam.clear_color = color.into();
        }
    }

    /// Sets the ray-caster switches of the camera.
    pub fn set_view(&mut self, view: VolumeView) {
        self.app.world_mut().entity_mut(self.camera).insert(view);
    }

    /// Runs one frame and waits for the GPU.
    pub fn update(&mut self) {
        self.app.update();
        if let Some(device) = self.app.world().get_resource::<RenderDevice>() {
            let _ = device.wgpu_device().poll(PollType::Wait { submission_index: None, timeout: None });
        }
    }

    /// The error of the ray-cast pipeline, if it failed to build (a broken shader must
    /// fail the render, not yield a picture without the volume).
    pub fn pipeline_error(&self) -> Option<String> {
        let world = self.app.get_sub_app(RenderApp)?.world();
        let cache = world.get_resource::<PipelineCache>()?;
        let mut states = world.try_query::<&RaycastPipelineId>()?;
        states.iter(world).find_map(|id| match cache.get_render_pipeline_state(id.0) {
            CachedPipelineState::Err(e) => Some(format!("the ray-cast shader failed to build: {e}")),
            _ => None,
        })
    }

    /// The ray caster's shader features in the last frame (`render::gpu_types::features`).
    pub fn shader_features(&self) -> Option<u32> {
        let world = self.app.get_sub_app(RenderApp)?.world();
        let scene = world.get_resource::<GpuScene>()?;
        let atlas = world.get_resource::<crate::render::bricked::atlas::BrickAtlas>()?;
        Some(crate::render::bricked::mark::pipeline_features(scene.features, atlas.coarse_in_atlas))
    }

    /// Whether the last frame drew the volumes: the scene is uploaded and every view's
    /// pipeline is built.
    fn ready(&self) -> bool {
        let Some(world) = self.app.get_sub_app(RenderApp).map(|a| a.world()) else { return false };
        let (Some(cache), Some(scene)) = (world.get_resource::<PipelineCache>(), world.get_resource::<GpuScene>()) else { return false };
        let Some(mut ids) = world.try_query::<&RaycastPipelineId>() else { return false };
        let ids: Vec<_> = ids.iter(world).map(|id| id.0).collect();
        scene.ready() && !ids.is_empty() && ids.iter().all(|&id| matches!(cache.get_render_pipeline_state(id), CachedPipelineState::Ok(_)))
    }

    /// Renders and reads back the image (sRGB-encoded RGBA8).
    pub fn capture(&mut self) -> Result<image::RgbaImage, String> {
        let mut frames = 0;
        loop {
            self.update();
            if let Some(e) = self.pipeline_error().or_else(|| self.stopped()) {
                return Err(e);
            }
            if self.ready() {
                break;
            }
            frames += 1;
            if frames >= MAX_WAIT_FRAMES {
                return Err("the ray caster did not get ready (no volume uploaded or no pipeline)".into());
            }
        }
        self.wait_for_streaming();
        let captured: Arc<Mutex<Option<Image>>> = default();
        let sink = captured.clone();
        self.app.world_mut().spawn(Screenshot::image(self.target.clone())).observe(move |ev: On<ScreenshotCaptured>| {
            if let Ok(mut slot) = sink.lock() {
                *slot = Some(ev.image.clone());
            }
        });
        for _ in 0..MAX_WAIT_FRAMES {
            self.update();
            let image = captured.lock().ok().and_then(|mut s| s.take());
            if let Some(image) = image {
                let dynamic = image.try_into_dynamic().map_err(|e| format!("captured image: {e}"))?;
                return Ok(dynamic.to_rgba8());
            }
        }
        Err("the GPU produced no image".into())
    }

    /// Renders the per-ray counts of the current view (`render::counts::decode` reads
    /// them): the view's switches with `debug_counts` and a black background for one
    /// capture, then as they were.
    pub fn capture_counts(&mut self) -> Result<image::RgbaImage, String> {
        let world = self.app.world_mut();
        let view = world.get::<VolumeView>(self.camera).copied().unwrap_or_default();
        let clear = world.get::<Camera>(self.camera).map(|c| c.clear_color);
        if let Some(mut cam) = world.get_mut::<Camera>(self.camera) {
            cam.clear_color = Color::BLACK.into();
        }
        self.set_view(VolumeView { debug_counts: true, ..view });
        let image = self.capture();
        self.set_view(view);
        if let (Some(clear), Some(mut cam)) = (clear, self.app.world_mut().get_mut::<Camera>(self.camera)) {
            cam.clear_color = clear;
        }
        image
    }

    /// Why rendering stopped (a lost device), if it did.
    fn stopped(&self) -> Option<String> {
        self.app.world().get_resource::<super::health::RenderHealth>().and_then(|h| h.stopped())
    }

    /// Runs frames until the volumes are drawn once (whatever streaming has brought by
    /// then); the frames it took.
    pub fn first_frame(&mut self) -> Result<u32, String> {
        let progress = self.app.world().get_resource::<super::RenderProgress>().cloned().ok_or("no renderer")?;
        let before = progress.volumes_drawn();
        for k in 1..=MAX_WAIT_FRAMES {
            self.update();
            if let Some(e) = self.pipeline_error().or_else(|| self.stopped()) {
                return Err(e);
            }
            if self.ready() && progress.volumes_drawn() > before {
                return Ok(k);
            }
        }
        Err("the ray caster did not get ready (no volume uploaded or no pipeline)".into())
    }

    /// Runs frames until every brick the view wants is drawn (bricked datasets), at most
    /// [`STREAM_WAIT`]; a picture that did not converge is logged.
    pub fn wait_for_streaming(&mut self) -> bool {
        let Some(status) = self.app.world().get_resource::<StreamStatus>().cloned() else { return true };
        let start = Instant::now();
        loop {
            if status.converged() {
                let c = status.counts();
                if c.bricked > 0 {
                    info!(
                        "streaming converged after {:.2} s: {} bricks wanted (finest level {}), {} on the GPU",
                        start.elapsed().as_secs_f32(),
                        c.wanted,
                        c.finest_wanted.map_or("-".into(), |l| l.to_string()),
                        c.on_gpu
                    );
                }
                return true;
            }
            if start.elapsed() > STREAM_WAIT {
                let c = status.counts();
                warn!(
                    "streaming did not converge within {} s: {} of {} wanted bricks in memory, {} loading, {} not yet on the GPU",
                    STREAM_WAIT.as_secs(),
                    c.resident,
                    c.wanted,
                    c.pending,
                    c.not_uploaded
                );
                return false;
            }
            if status.counts().pending > 0 {
                // (The loads run on other threads: a frame less for them to wait on.)
                std::thread::sleep(Duration::from_millis(5));
            }
            self.update();
        }
    }

    /// Average wall-clock time of `frames` frames (after the scene settled).
    pub fn time_frames(&mut self, frames: u32) -> Duration {
        self.time_frames_with(frames, |_, _| {})
    }

    /// [`Self::time_frames`], calling `before(self, k)` ahead of frame `k` (to move the
    /// camera, say).
    pub fn time_frames_with(&mut self, frames: u32, mut before: impl FnMut(&mut Self, u32)) -> Duration {
        for _ in 0..MAX_WAIT_FRAMES {
            self.update();
            if self.ready() {
                break;
            }
        }
        let t = Instant::now();
        for k in 0..frames.max(1) {
            before(self, k);
            self.update();
        }
        t.elapsed() / frames.max(1)
    }
}
