//! The app: the window, its plugin (panels, camera control, loading, shortcuts) and the
//! systems that are the app's own (screenshots, automation, reframing, picking the
//! orbit centre).

use crate::context::ContextParams;
use std::path::PathBuf;

use bevy::camera::CameraOutputMode;
use bevy::camera::visibility::RenderLayers;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::diagnostic::FrameTimeDiagnosticsPlugin;
use bevy::prelude::*;
use bevy::render::render_resource::BlendState;
use bevy::render::view::screenshot::{Screenshot, save_to_disk};
use bevy::window::PrimaryWindow;
use bevy_egui::{EguiGlobalSettings, EguiPlugin, EguiPrimaryContextPass, PrimaryEguiContext};

use super::loading::{LoadRequest, LoadingPlugin, Reframe, Session};
use super::orbit::{OrbitCamera, PointerInViewport, toggle_fly};
use super::state::{AppState, DialogPurpose, MainCamera, default_scene, scene_bounds};
use super::viewport::viewport_logical;
use super::{clip_gizmo, explode_overlay, explode_panel, explode_tools, lenses, loading, orbit, panels, window_tools};
use crate::dataset::{SceneRegions, VolumeView};
use crate::region::View;

/// The app: panels, camera control, loading.
pub struct FocalAppPlugin {
    /// File, folder or scene to open at start (the default scene when `None`).
    pub initial: Option<PathBuf>,
    /// Automation for tests: screenshot after N frames to a path, then exit.
    pub screenshot_and_exit: Option<(u32, PathBuf)>,
    /// Open with the slice views shown.
    pub slices: bool,
    /// Restore the last session's view if it did not end cleanly (`focal --restore`).
    pub restore: bool,
    /// (Testing) Destroy the GPU device after this many drawn frames.
    pub lose_device_after: Option<u64>,
}

/// How the app starts, beyond what it opens.
#[derive(Clone, Copy, Debug, Default)]
pub struct RunOptions {
    /// The slice views shown.
    pub slices: bool,
    /// Restore the last session's view (`focal --restore`).
    pub restore: bool,
    /// (Testing) Destroy the GPU device after this many drawn frames, as a driver reset
    /// does (`focal --lose-device-after N`).
    pub lose_device_after: Option<u64>,
}

impl Plugin for FocalAppPlugin {
    fn build(&self, app: &mut App) {
        let initial = self.initial.clone();
        if let Some(frames) = self.lose_device_after {
            app.insert_resource(super::gpu_status::LoseDeviceAfter(frames));
        }
        app.add_plugins((EguiPlugin::default(), FrameTimeDiagnosticsPlugin::default(), LoadingPlugin))
            .insert_resource(AppState { screenshot_and_exit: self.screenshot_and_exit.clone(), ..Default::default() })
            .init_resource::<PointerInViewport>()
            .init_resource::<lenses::LensUi>()
            .init_resource::<clip_gizmo::ClipGizmo>()
            .init_resource::<window_tools::WindowTools>()
            .init_resource::<explode_tools::ExplodeUi>()
            .init_resource::<explode_overlay::CutPreview>()
            .init_resource::<super::under_cursor::UnderCursor>()
            .insert_resource(super::slice_views::SliceViews::shown(self.slices))
            .init_resource::<super::movie::MovieRecorder>()
            .init_resource::<super::rulers::RulerTool>()
            .insert_resource(super::settings::Settings::load())
            .insert_resource(super::recovery::Recovery::at_start(self.restore, self.screenshot_and_exit.is_some()))
            .add_systems(
                Startup,
                move |mut commands: Commands,
                      mut egui: ResMut<EguiGlobalSettings>,
                      mut load: MessageWriter<LoadRequest>,
                      mut recovery: ResMut<super::recovery::Recovery>| {
                    setup(&mut commands, &mut egui);
                    let restored = if recovery.restore_at_start {
                        let r = recovery.restore();
                        if r.is_none() {
                            warn!("--restore: the last session left no view to restore");
                        }
                        r
                    } else {
                        None
                    };
                    load.write(restored.unwrap_or_else(|| match &initial {
                        Some(p) => LoadRequest::Path(p.clone()),
                        None => LoadRequest::Scene(Box::new(default_scene()), PathBuf::new()),
                    }));
                },
            )
            .add_systems(Last, super::recovery::remove_on_exit)
            .add_systems(Update, (super::gpu_status::lose_device, super::gpu_status::quit_when_rendering_stops))
            .add_systems(
                Update,
                (
                    lenses::lens_input,
                    lenses::lens_keys,
                    explode_panel::explode_input,
                    clip_gizmo::clip_input,
                    window_tools::window_input,
                    orbit::orbit_input,
                    orbit::fly_keys,
                    shortcuts,
                    dropped_files,
                    centre_on_double_click,
                    super::rulers::ruler_on_surface,
                    reframe,
                    sync_view,
                    automation,
                    orbit::apply_orbit,
                )
                    .chain(),
            )
            // The exploded views' physics: as many steps as the frame's time asks for.
            .add_systems(
                Update,
                (
                    crate::explode::systems::run_steps,
                    open_explode_panel,
                    super::under_cursor::pick_under_cursor,
                    super::slice_views::slice_keys,
                    super::rulers::apply_rulers,
                    (super::settings::remember_opened, super::settings::save_settings).chain(),
                )
                    .after(orbit::apply_orbit),
            )
            .add_systems(
                EguiPrimaryContextPass,
                (
                    panels::ui,
                    explode_panel::explode_panel,
                    explode_overlay::explode_overlay,
                    super::streaming_status::streaming_status,
                    super::gpu_status::gpu_status,
                )
                    .chain(),
            );
    }
}

fn setup(commands: &mut Commands, egui: &mut EguiGlobalSettings) {
    // The 3D view and a separate camera for the panels, so the view can be limited to
    // the free part of the window.
    egui.auto_create_primary_context = false;
    let orbit = OrbitCamera::default();
    let (transform, projection) = orbit.bevy();
    commands.spawn((
        MainCamera,
        Camera3d::default(),
        Msaa::Off,
        Tonemapping::None,
        Camera { clear_color: Color::BLACK.into(), ..default() },
        transform,
        projection,
        orbit,
        VolumeView::default(),
        crate::interactive::InteractiveResolution::default(),
        crate::windows::Viewer,
    ));
    commands.spawn((
        PrimaryEguiContext,
        Camera2d,
        Msaa::Off,
        RenderLayers::none(),
        Camera {
            order: 1,
            output_mode: CameraOutputMode::Write { blend_state: Some(BlendState::ALPHA_BLENDING), clear_color: ClearColorConfig::None },
            // egui draws into this camera's texture, then blended over the 3D view: the
            // texture starts each frame transparent. (With MSAA, Bevy would load the
            // texture instead of clearing it, and its texture cache hands the same
            // textures to both cameras: earlier frames' text and pictures would show
            // through where no panel paints over them. egui smooths its own edges.)
            clear_color: ClearColorConfig::Custom(Color::NONE),
            ..default()
        },
    ));
    commands.spawn((DirectionalLight::default(), Transform::from_xyz(1.0, -2.0, 3.0).looking_at(Vec3::ZERO, Vec3::Z)));
}

/// Opens dropped files and folders.
fn dropped_files(mut drops: MessageReader<FileDragAndDrop>, mut load: MessageWriter<LoadRequest>) {
    for d in drops.read() {
        if let FileDragAndDrop::DroppedFile { path_buf, .. } = d {
            load.write(LoadRequest::Path(path_buf.clone()));
        }
    }
}

/// Keyboard shortcuts (ignored while egui has the keyboard).
fn shortcuts(
    keys: Res<ButtonInput<KeyCode>>,
    mut state: ResMut<AppState>,
    mut contexts: bevy_egui::EguiContexts,
    mut cams: Query<&mut OrbitCamera>,
    regions: Res<SceneRegions>,
    mut commands: Commands,
    mut datasets: Query<&mut crate::dataset::Dataset>,
) {
    if contexts.ctx_mut().is_ok_and(|c| c.egui_wants_keyboard_input()) {
        return;
    }
    let ctrl = keys.any_pressed([KeyCode::ControlLeft, KeyCode::ControlRight]);
    if keys.just_pressed(KeyCode::KeyH) || keys.just_pressed(KeyCode::F1) {
        state.show_help = !state.show_help;
    }
    if keys.just_pressed(KeyCode::KeyF) {
        state.show_fps = !state.show_fps;
    }
    if keys.just_pressed(KeyCode::KeyE) {
        state.show_explode = !state.show_explode;
    }
    if keys.just_pressed(KeyCode::F12) || (keys.just_pressed(KeyCode::KeyS) && !ctrl) {
        let path = screenshot_path();
        commands.spawn(Screenshot::primary_window()).observe(save_to_disk(path.clone()));
        state.last_screenshot = Some(path);
    }
    if ctrl && keys.just_pressed(KeyCode::KeyO) {
        state.dialog_purpose = DialogPurpose::Open;
        state.dialog.pick_file();
    }
    if ctrl && keys.just_pressed(KeyCode::KeyS) {
        state.dialog_purpose = DialogPurpose::SaveScene;
        state.dialog.save_file();
    }
    if keys.just_pressed(KeyCode::KeyM) {
        let selected = state.selected;
        if let Some(mut d) = datasets.iter_mut().nth(selected) {
            let modes = crate::region::Mode::ALL;
            let i = modes.iter().position(|m| *m == d.appearance.mode).unwrap_or(0);
            d.appearance.mode = modes[(i + 1) % modes.len()];
        }
    }
    for (key, delta) in [(KeyCode::BracketLeft, -ContextParams::KAPPA_T_STEP), (KeyCode::BracketRight, ContextParams::KAPPA_T_STEP)] {
        if keys.just_pressed(key)
            && let Some(mut d) = datasets.iter_mut().nth(state.selected)
        {
            d.appearance.context = d.appearance.context.with_kappa_t_step(delta);
        }
    }
    let Ok(mut orbit) = cams.single_mut() else { return };
    let views = [
        (KeyCode::Digit1, View::Anterior),
        (KeyCode::Digit2, View::Posterior),
        (KeyCode::Digit3, View::Left),
        (KeyCode::Digit4, View::Right),
        (KeyCode::Digit5, View::Superior),
        (KeyCode::Digit6, View::Inferior),
        (KeyCode::Digit7, View::Oblique),
    ];
    let bounds = scene_bounds(&regions);
    for (key, view) in views {
        if keys.just_pressed(key) {
            orbit.frame(view, bounds.0, bounds.1, 1.0);
        }
    }
    if keys.just_pressed(KeyCode::KeyR) {
        orbit.frame(View::Oblique, bounds.0, bounds.1, 1.0);
    }
    if keys.just_pressed(KeyCode::KeyP) {
        orbit.orthographic = !orbit.orthographic;
    }
    if keys.just_pressed(KeyCode::KeyV) {
        toggle_fly(&mut orbit, bounds);
    }
}

/// Opens the exploded view's panel when a dataset is exploded (a scene that explodes
/// one, or the panel's own Explode) and selects it.
fn open_explode_panel(
    added: Query<Entity, Added<crate::explode::Exploded>>,
    datasets: Query<Entity, With<crate::dataset::Dataset>>,
    mut state: ResMut<AppState>,
) {
    let Some(e) = added.iter().min() else { return };
    let mut all: Vec<Entity> = datasets.iter().collect();
    all.sort();
    state.show_explode = true;
    state.selected = all.iter().position(|d| *d == e).unwrap_or(state.selected);
}

/// Where screenshots go.
fn screenshot_path() -> PathBuf {
    let stamp = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.as_secs()).unwrap_or(0);
    let dir = PathBuf::from("out");
    let _ = std::fs::create_dir_all(&dir);
    dir.join(format!("screenshot-{stamp}.png"))
}

/// Frames a reframe waits for the panels to give the 3D view its part of the window.
const REFRAME_WAIT_FRAMES: u32 = 30;

/// Places the camera on newly loaded data: a scene's own camera, else an oblique view.
/// (Framing depends on the view's aspect: it waits until the panels have set the
/// viewport, else a load that finished before the first panel pass framed the data for
/// the whole window, closer than for the view beside the panels.)
fn reframe(mut session: ResMut<Session>, mut cams: Query<(&mut OrbitCamera, &Camera), With<MainCamera>>, mut waited: Local<u32>) {
    let Ok((mut orbit, camera)) = cams.single_mut() else { return };
    if session.reframe.is_none() {
        return;
    }
    if camera.viewport.is_none() && *waited < REFRAME_WAIT_FRAMES {
        *waited += 1;
        return;
    }
    *waited = 0;
    let Some(Reframe { bounds: (lo, hi), camera: spec }) = session.reframe.take() else { return };
    let aspect = camera.physical_viewport_size().map_or(1.0, |s| s.x as f32 / s.y.max(1) as f32);
    match spec {
        Some(spec) => orbit.set_from(&crate::scene::load::camera(&spec, (lo, hi), aspect), (lo + hi) * 0.5),
        None => orbit.frame(View::Oblique, lo, hi, aspect),
    }
}

/// Double-click centres the orbit on the first visible point under the cursor (picked
/// with the CPU reference renderer).
// A Bevy system: its parameters are the resources and queries it uses, and a query's
// type names the components it reads; splitting them up would only hide that.
#[allow(clippy::too_many_arguments)]
fn centre_on_double_click(
    buttons: Res<ButtonInput<MouseButton>>,
    windows: Query<&Window, With<PrimaryWindow>>,
    time: Res<Time<Real>>,
    pointer: Res<PointerInViewport>,
    regions: Res<SceneRegions>,
    mut last: Local<(f64, Vec2)>,
    mut cams: Query<(&mut OrbitCamera, &Camera), With<MainCamera>>,
    mut state: ResMut<AppState>,
    datasets: Query<(Entity, &crate::dataset::Dataset, Option<&crate::dataset::GpuVolume>)>,
) {
    let Ok(window) = windows.single() else { return };
    if !pointer.inside {
        return;
    }
    let Some(cursor) = orbit::double_click(&buttons, window, time.elapsed_secs_f64(), &mut last) else { return };
    let Ok((mut orbit, camera)) = cams.single_mut() else { return };
    let (origin, size) = viewport_logical(camera, window);
    let p = cursor - origin;
    let ray = orbit.camera().ray(p.x, p.y, size.x.max(1.0) as u32, size.y.max(1.0) as u32);
    if let Ok(Some(hit)) = crate::reference::pick(&regions.scene, ray) {
        orbit.target = hit.position;
        // On a label volume, the label there is picked (named and marked in its list).
        let picked = crate::reference::label_at(&regions.scene, &hit).and_then(|id| {
            let volume = regions.scene.regions.get(hit.region).and_then(|r| regions.scene.volumes.get(r.volume))?;
            let (entity, ..) = datasets.iter().find(|(_, d, gpu)| {
                std::sync::Arc::ptr_eq(&d.volume, volume) || gpu.is_some_and(|g| std::sync::Arc::ptr_eq(&g.volume, volume))
            })?;
            Some((entity, id))
        });
        if state.editor.picked_label != picked {
            state.editor.picked_label = picked;
        }
    }
}

/// Copies the app's background and switches to the camera.
fn sync_view(state: Res<AppState>, mut cams: Query<(&mut Camera, &mut VolumeView), With<MainCamera>>) {
    if !state.is_changed() {
        return;
    }
    for (mut cam, mut view) in &mut cams {
        let [r, g, b] = state.background;
        cam.clear_color = Color::srgb(r, g, b).into();
        let light = view.light;
        *view = VolumeView { light, ..state.view };
    }
}

/// Test automation: a screenshot after N frames (counted once loading is done, the ray
/// caster has drawn the volumes, no pipeline is still compiling and streamed volumes
/// have converged, as the headless render waits for them, at most
/// [`crate::render::headless::STREAM_WAIT`]: so the shot never shows a half-built
/// picture), and at rest at every pixel with as many of its jittered frames averaged
/// as the shot counts (a view that moved late, as a window's size arriving late on a loaded machine,
/// is still upscaled or averaging; at most [`SETTLE_FRAMES`] more frames are waited
/// for it), then exit as soon as it is written.
fn automation(
    mut state: ResMut<AppState>,
    mut commands: Commands,
    mut exit: MessageWriter<AppExit>,
    (loading, progress): (Query<(), With<loading::Loading>>, Option<Res<crate::render::RenderProgress>>),
    (stream, slices): (Option<Res<crate::streaming::bricked::StreamStatus>>, Res<super::slice_views::SliceViews>),
    (mut streaming_since, mut drawn_before): (Local<Option<std::time::Instant>>, Local<u64>),
    (views, mut waited): (Query<(&crate::interactive::InteractiveResolution, Option<&crate::dataset::view::Accumulate>)>, Local<u32>),
) {
    let Some((after, path)) = state.screenshot_and_exit.clone() else { return };
    let settled = progress.as_ref().is_some_and(|p| p.volumes_drawn() > 0 && p.pipelines_settled());
    if !loading.is_empty() || !settled {
        return;
    }
    // Only frames the ray caster drew count: a pipeline asked for after the others had
    // settled (a scene's lenses arrive a frame after its volumes) leaves frames undrawn
    // while it compiles.
    let drawn = progress.as_ref().map_or(0, |p| p.volumes_drawn());
    if drawn == *drawn_before {
        return;
    }
    *drawn_before = drawn;
    if state.frames == 0 && (!stream.is_none_or(|s| s.converged()) || slices.reading()) {
        let since = *streaming_since.get_or_insert_with(std::time::Instant::now);
        if since.elapsed() < crate::render::headless::STREAM_WAIT {
            return;
        }
        warn!("streaming did not converge within {:?}: the screenshot shows what had arrived", crate::render::headless::STREAM_WAIT);
    }
    if state.frames + 1 == after && !views.iter().all(|(v, a)| refined(v, a, after)) {
        *waited += 1;
        if *waited <= SETTLE_FRAMES {
            return;
        }
        if *waited == SETTLE_FRAMES + 1 {
            warn!("the view did not come to rest within {SETTLE_FRAMES} frames: the screenshot shows it as it is");
        }
    }
    state.frames += 1;
    if state.frames == after {
        let _ = std::fs::remove_file(&path);
        commands.spawn(Screenshot::primary_window()).observe(save_to_disk(path.clone()));
    }
    if state.frames > after && (path.exists() || state.frames > after + 20) {
        exit.write(AppExit::Success);
    }
}

/// How many frames past its count the screenshot automation waits for the view to come
/// to rest at every pixel.
const SETTLE_FRAMES: u32 = 120;

/// Whether a view shows the picture a screenshot after `frames` frames is of: not
/// adapting its resolution, or at rest at every pixel with as many of its jittered
/// frames averaged as the shot waited for (all of them where it waited longer).
fn refined(view: &crate::interactive::InteractiveResolution, average: Option<&crate::dataset::view::Accumulate>, frames: u32) -> bool {
    !view.enabled || (!view.moving && view.scale >= 1.0 && average.is_none_or(|a| a.index + 1 >= a.frames.min(frames)))
}

/// Runs the app.
pub fn run(initial: Option<PathBuf>, screenshot_and_exit: Option<(u32, PathBuf)>, window: (u32, u32), options: RunOptions) -> AppExit {
    let RunOptions { slices, restore, lose_device_after } = options;
    super::recovery::install_panic_hook();
    App::new()
        .add_plugins(DefaultPlugins.set(WindowPlugin {
            primary_window: Some(Window { title: "Focal".into(), resolution: window.into(), ..default() }),
            ..default()
        }))
        .add_plugins((crate::FocalPlugins, crate::windows::frames::WindowFramePlugin))
        .add_plugins(FocalAppPlugin { initial, screenshot_and_exit, slices, restore, lose_device_after })
        .run()
}
