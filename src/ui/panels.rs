//! The egui panels: menu bar, dataset, transfer function, rendering and camera panels,
//! help, frame rate, errors and load progress.

use bevy::diagnostic::{DiagnosticsStore, FrameTimeDiagnosticsPlugin};
use bevy::prelude::*;
use bevy::window::PrimaryWindow;
use bevy_egui::egui::{self, Color32, RichText};
use bevy_egui::{EguiContexts, egui::Ui};

use super::loading::{DatasetOrigin, LoadRequest, Loading, Session};
use super::orbit::{OrbitCamera, PointerInViewport};
use super::state::{AppState, DialogPurpose, MainCamera, SHORTCUTS, default_scene, scene_bounds};
use super::viewport::set_viewport;
use super::{lenses, objects_panel, tf_editor};
use crate::context::{ContextParams, Power};
use crate::dataset::{Dataset, GpuVolume, SceneLight, SceneRegions};
use crate::interactive::InteractiveResolution;
use crate::region::{Light, Lookup, Mode};
use crate::transfer::presets;

fn dataset_row(entity: Entity, d: &Dataset, t: &Transform) -> super::windows_panel::DatasetRow {
    super::windows_panel::DatasetRow { entity, name: d.volume.name.clone(), appearance: d.appearance.clone(), transform: *t }
}

/// The focused window's corner handles and its parameter menu (opened by a right-click
/// on it) beside it.
fn window_menu(
    ctx: &egui::Context,
    free: egui::Rect,
    p: &mut super::windows_panel::WindowParams,
    datasets: &DatasetQuery,
    orbit: &OrbitCamera,
    regions: &SceneRegions,
) {
    let focused = p.focus.0.and_then(|e| p.windows.get(e).ok()).map(|(_, w, g)| crate::windows::systems::window_box(w, g));
    super::window_tools::overlay(ctx, free, &p.tools, focused, orbit);
    let Some((e, at)) = p.tools.menu else { return };
    let mut rows: Vec<_> = datasets.iter().map(|(e, d, _, _, t)| dataset_row(e, d, t)).collect();
    rows.sort_by_key(|r| r.entity);
    let (lo, hi) = scene_bounds(regions);
    let mut open = true;
    let mut remove = None;
    egui::Window::new("Window parameters")
        .id(egui::Id::new(("window_menu", e)))
        .open(&mut open)
        .default_pos(free.min + egui::vec2(at.x + 16.0, at.y))
        .resizable(false)
        .collapsible(false)
        .show(ctx, |ui| {
            if let Ok((_, mut w, g)) = p.windows.get_mut(e)
                && super::windows_panel::window_settings(ui, &mut w, g, orbit.bevy().0, &rows, (hi - lo).length())
            {
                remove = Some(w.source);
            }
        });
    if let Some(source) = remove {
        super::windows_panel::despawn_window(&mut p.commands, e, source);
        open = false;
    }
    if !open || p.windows.get(e).is_err() {
        p.tools.menu = None;
    }
}

/// The datasets as the panels read and edit them.
type DatasetQuery<'w, 's> =
    Query<'w, 's, (Entity, &'static mut Dataset, Option<&'static GpuVolume>, Option<&'static DatasetOrigin>, &'static Transform)>;

/// More of what the panels read and edit (a tuple: a system takes at most 16
/// parameters).
type MoreParams<'w, 's> = (
    Res<'w, crate::explode::edit::CurrentSpecs>,
    ResMut<'w, super::slice_views::SliceViews>,
    Query<'w, 's, &'static crate::slices::ruler::Ruler>,
    ResMut<'w, super::movie::MovieRecorder>,
    ResMut<'w, super::settings::Settings>,
    ResMut<'w, super::rulers::RulerTool>,
    Query<'w, 's, &'static crate::streaming::bricked::BrickedDataset>,
    Res<'w, super::under_cursor::UnderCursor>,
    ResMut<'w, super::recovery::Recovery>,
);

/// Everything the panels read and edit.
// A Bevy system: its parameters are the resources and queries it uses, and a query's
// type names the components it reads; splitting them up would only hide that.
#[allow(clippy::too_many_arguments)]
pub fn ui(
    mut contexts: EguiContexts,
    mut state: ResMut<AppState>,
    mut session: ResMut<Session>,
    mut datasets: DatasetQuery,
    loading: Query<&Loading>,
    mut cams: Query<(&mut OrbitCamera, &mut Camera, Option<&mut InteractiveResolution>), With<MainCamera>>,
    windows: Query<&Window, With<PrimaryWindow>>,
    diagnostics: Res<DiagnosticsStore>,
    mut pointer: ResMut<PointerInViewport>,
    mut light: ResMut<SceneLight>,
    regions: Res<SceneRegions>,
    mut load: MessageWriter<LoadRequest>,
    mut lens_params: lenses::LensParams,
    clip_gizmo: Res<super::clip_gizmo::ClipGizmo>,
    mut window_params: super::windows_panel::WindowParams,
    (explode_specs, mut slice_views, rulers, mut movie, mut settings, mut ruler_tool, bricked, under_cursor, mut recovery): MoreParams,
) -> Result {
    let ctx = contexts.ctx_mut()?.clone();
    let mut root = Ui::new(
        ctx.clone(),
        "focal_root".into(),
        egui::UiBuilder::new().layer_id(egui::LayerId::background()).max_rect(ctx.viewport_rect()),
    );

    egui::Panel::top("menu").show(&mut root, |ui| {
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if ui.button("Open file…  (Ctrl+O)").clicked() {
                    state.dialog_purpose = DialogPurpose::Open;
                    state.dialog.pick_file();
                }
                if ui.button("Open DICOM or OME-Zarr folder…").clicked() {
                    state.dialog_purpose = DialogPurpose::Open;
                    state.dialog.pick_directory();
                }
                ui.menu_button("Open recent", |ui| {
                    if settings.recent.is_empty() {
                        ui.label("(nothing yet)");
                    }
                    for path in &settings.recent {
                        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| path.display().to_string());
                        if ui.button(name).on_hover_text(path.display().to_string()).clicked() {
                            load.write(LoadRequest::Path(path.clone()));
                        }
                    }
                });
                if ui.button("Save scene…  (Ctrl+S)").clicked() {
                    state.dialog_purpose = DialogPurpose::SaveScene;
                    state.dialog.save_file();
                }
                if ui.button("Record movie…").on_hover_text("A turntable or the scene's animation, as PNGs and a GIF").clicked() {
                    movie.open = true;
                }
                if ui.button("Head phantom").clicked() {
                    load.write(LoadRequest::Scene(Box::new(default_scene()), Default::default()));
                }
            });
            ui.menu_button("View", |ui| {
                ui.checkbox(&mut state.show_help, "Help  (H)");
                ui.checkbox(&mut state.show_fps, "Frame rate  (F)");
                ui.checkbox(&mut state.show_explode, "Exploded view  (E)");
                ui.checkbox(&mut slice_views.show, "Slice views  (L)");
            });
            for l in &loading {
                ui.separator();
                ui.label(format!("Loading {}", short(&l.what)));
                match l.progress.fraction() {
                    Some(f) => ui.add(egui::ProgressBar::new(f).desired_width(160.0).show_percentage()),
                    None => ui.spinner(),
                };
            }
            if let Some(p) = &state.last_screenshot {
                ui.separator();
                ui.label(RichText::new(format!("screenshot: {}", p.display())).small());
            }
        });
    });

    let view_forward = cams.single().map(|(o, ..)| o.camera().forward()).unwrap_or(Vec3::NEG_Z);
    let mut ds: Vec<_> = datasets.iter_mut().collect();
    ds.sort_by_key(|(e, ..)| *e);
    let selected = state.selected.min(ds.len().saturating_sub(1));
    // Resizable, at most two fifths of the window: long values wrap inside it.
    let widest = (ctx.viewport_rect().width() * 0.4).max(240.0);
    let remembered = settings.panel_width.unwrap_or(DEFAULT_PANEL_WIDTH);
    let panel = egui::Panel::left("controls").resizable(true).default_size(remembered.min(widest)).max_size(widest).show(&mut root, |ui| {
        egui::ScrollArea::vertical().show(ui, |ui| {
            egui::CollapsingHeader::new("Data").default_open(true).show(ui, |ui| {
                for (i, (_, d, gpu, _, _)) in ds.iter_mut().enumerate() {
                    ui.horizontal(|ui| {
                        ui.checkbox(&mut d.visible, "");
                        // (Long names are cut to the panel, whole on hover.)
                        let name = egui::Button::selectable(i == selected, &d.volume.name).truncate();
                        if ui.add(name).on_hover_text(&d.volume.name).clicked() {
                            state.selected = i;
                        }
                    });
                    if let Some(w) = gpu.and_then(|g| g.warning.as_ref()) {
                        ui.label(RichText::new(format!("⚠ {w}")).color(Color32::YELLOW).small());
                    }
                }
                if let Some((_, d, ..)) = ds.get(selected) {
                    dataset_info(ui, d);
                }
            });
            let sources: Vec<objects_panel::LabelSource> = ds
                .iter()
                .enumerate()
                .filter(|(i, (_, d, ..))| *i != selected && d.labels.is_some())
                .map(|(_, (_, d, gpu, ..))| objects_panel::LabelSource {
                    name: d.volume.name.clone(),
                    volume: gpu.map_or_else(|| d.volume.clone(), |g| g.volume.clone()),
                    table: d.labels.clone(),
                })
                .collect();
            if let Some((entity, d, _, _, transform)) = ds.get_mut(selected) {
                let entity = *entity;
                if matches!(d.appearance.lookup, Lookup::Transfer(_)) && (!sources.is_empty() || d.appearance.segmentation.is_some()) {
                    egui::CollapsingHeader::new("Objects (two-level)").default_open(true).show(ui, |ui| {
                        let picked = state.editor.picked_label.filter(|(e, _)| *e == entity).map(|(_, id)| id);
                        let mut seg = d.appearance.segmentation.clone();
                        let sel = objects_panel::Selection { picked, editing: &mut state.editor.object };
                        objects_panel::panel(ui, &d.volume, &mut seg, &sources, sel);
                        if seg != d.appearance.segmentation {
                            d.appearance.segmentation = seg;
                        }
                    });
                }
                // With a window in focus that shows this dataset, the look edited is the
                // window's own (Borst et al.: panel settings apply to the focused view).
                let window_look = super::windows_panel::focused_look(&window_params, entity, &d.appearance);
                let mut in_window = window_look.as_ref().map(|(_, a)| Dataset { appearance: a.clone(), ..(**d).clone() });
                let (suffix, edited) = match (&window_look, in_window.as_mut()) {
                    (Some((k, _)), Some(w)) => (format!(" (window {k})"), w),
                    _ => (String::new(), &mut **d),
                };
                egui::CollapsingHeader::new(format!("Transfer function{suffix}"))
                    .id_salt("transfer")
                    .default_open(true)
                    .show(ui, |ui| transfer_panel(ui, edited, entity, &mut state.editor));
                egui::CollapsingHeader::new(format!("Rendering{suffix}"))
                    .id_salt("rendering")
                    .default_open(true)
                    .show(ui, |ui| rendering_panel(ui, edited, &mut state, &mut light));
                if let (Some((_, before)), Some(w)) = (window_look, in_window)
                    && w.appearance != before
                {
                    super::windows_panel::set_focused_look(&mut window_params, entity, w.appearance);
                }
                egui::CollapsingHeader::new("Clipping").default_open(false).show(ui, |ui| {
                    // Planes live in the dataset's frame: the view direction taken there.
                    let view_dir = transform.rotation.inverse() * view_forward;
                    let bounds = d.volume.grid.world_bounds();
                    let mut clip = d.clip.clone();
                    super::clip_panel::panel(ui, &mut clip, bounds, view_dir);
                    if clip != d.clip {
                        d.clip = clip;
                    }
                });
            }
            egui::CollapsingHeader::new("Lenses").default_open(true).show(ui, |ui| lenses::panel(ui, &mut lens_params));
            egui::CollapsingHeader::new("Volumetric windows").default_open(false).show(ui, |ui| {
                let rows: Vec<_> = ds.iter().map(|(e, d, _, _, t)| dataset_row(*e, d, t)).collect();
                let (lo, hi) = scene_bounds(&regions);
                if let Ok((orbit, ..)) = cams.single() {
                    super::windows_panel::panel(ui, &mut window_params, &rows, selected, orbit, (hi - lo).length());
                }
            });
            egui::CollapsingHeader::new("Camera").default_open(true).show(ui, |ui| {
                if let Ok((mut orbit, _, adapt)) = cams.single_mut() {
                    super::camera_panel::camera_panel(ui, &mut orbit, scene_bounds(&regions));
                    if let Some(mut adapt) = adapt {
                        super::camera_panel::interaction_panel(ui, &mut adapt);
                    }
                }
            });
        });
    });
    // The width the user dragged the panel to, remembered once the drag is over.
    let width = panel.response.rect.width();
    if (width - remembered).abs() > 1.0 && width < widest - 1.0 && !ctx.input(|i| i.pointer.any_down()) {
        settings.panel_width = Some(width);
    }

    // The slice views of the selected dataset under the 3D view, with a label dataset
    // to lay over them.
    let slice_base;
    // (The rulers, read once a frame for the slices and the 3D view.)
    let all_rulers: Vec<crate::slices::ruler::Ruler> = rulers.iter().copied().collect();
    {
        let mut rows: Vec<_> = datasets.iter().map(|(e, d, _, _, t)| (e, d, t)).collect();
        rows.sort_by_key(|(e, ..)| *e);
        // (A label volume selected beside data: the data's slices with the labels over
        // them, as an atlas over its MRI is read.)
        let selected_row = rows.get(state.selected.min(rows.len().saturating_sub(1))).copied();
        let shown = match selected_row {
            Some(row) if row.1.labels.is_some() => rows.iter().copied().find(|(_, d, _)| d.labels.is_none()).or(Some(row)),
            other => other,
        };
        slice_base = shown.map(|(e, ..)| e);
        let labels = rows.iter().copied().find(|(e, d, _)| d.labels.is_some() && shown.is_some_and(|s| s.0 != *e));
        let mut cuts = super::slice_views::Cuts::default();
        if slice_views.show {
            cuts.boxes = window_params.windows.iter().map(|(_, w, g)| crate::windows::systems::window_box(w, g).corners()).collect();
            // (The 3D view's size as last laid out: the lenses' units follow its aspect.)
            if let Ok((orbit, camera, _)) = cams.single()
                && let Some(size) = camera.logical_viewport_size()
            {
                let screen = crate::lens::Screen { width: size.x.max(1.0), height: size.y.max(1.0) };
                let camera = orbit.camera();
                cuts.lenses = lens_params
                    .ordered()
                    .iter()
                    .filter_map(|(_, l, _)| crate::slices::lens_outline::LensRays::of(l, &camera, screen))
                    .collect();
            }
        }
        let source = shown.and_then(|(e, ..)| bricked.get(e).ok()).map(|b| b.cache.source().clone());
        super::slice_views::panel(&mut root, &mut slice_views, shown, labels, (&cuts, source.as_ref()), (&all_rulers, &mut ruler_tool));
    }
    // The rest of the window is the 3D viewport.
    let free = root.available_rect_before_wrap();
    if let (Ok((_, mut camera, _)), Ok(window)) = (cams.single_mut(), windows.single()) {
        set_viewport(&mut camera, window, free, ctx.zoom_factor());
    }
    let over_free = ctx.pointer_hover_pos().is_some_and(|p| free.contains(p));
    pointer.inside = over_free && !ctx.is_pointer_over_egui() && !ctx.egui_is_using_pointer();
    pointer.height = free.height();
    lenses::overlay(&ctx, free, &mut lens_params, &regions);
    {
        let mut rows: Vec<_> = datasets.iter().map(|(e, d, _, _, t)| (e, d, t)).collect();
        rows.sort_by_key(|(e, ..)| *e);
        let chosen = rows.get(state.selected.min(rows.len().saturating_sub(1))).copied();
        let camera = cams.single().ok().map(|(o, ..)| o.camera());
        super::clip_gizmo::overlay(&ctx, free, &clip_gizmo, chosen, camera);
        let base = rows.iter().copied().find(|(e, ..)| Some(*e) == slice_base);
        super::slice_views::planes_overlay(&ctx, free, &slice_views, base, camera);
        let slice_probe = slice_views.probe.as_deref().filter(|_| slice_views.show);
        super::under_cursor::probe_overlay(&ctx, free, slice_probe.or(under_cursor.probe.as_deref()));
        let placed: Vec<_> = all_rulers
            .iter()
            .filter_map(|r| rows.iter().find(|(e, ..)| *e == r.dataset).map(|(_, _, t)| (*r, t.compute_affine())))
            .collect();
        let begun =
            ruler_tool.start.and_then(|(e, p)| rows.iter().find(|(d, ..)| *d == e).map(|(_, _, t)| t.compute_affine().transform_point3(p)));
        super::rulers::overlay(&ctx, free, camera, &placed, begun);
    }
    if let Ok((orbit, ..)) = cams.single() {
        window_menu(&ctx, free, &mut window_params, &datasets, orbit, &regions);
    }

    if state.show_help {
        let mut open = true;
        egui::Window::new("Help").open(&mut open).resizable(false).show(&ctx, |ui| {
            egui::Grid::new("shortcuts").striped(true).show(ui, |ui| {
                for (k, what) in SHORTCUTS {
                    ui.label(RichText::new(*k).strong());
                    ui.label(*what);
                    ui.end_row();
                }
            });
        });
        state.show_help = open;
    }
    if state.show_fps {
        let fps = diagnostics.get(&FrameTimeDiagnosticsPlugin::FPS).and_then(|d| d.smoothed()).unwrap_or(0.0);
        let ms = diagnostics.get(&FrameTimeDiagnosticsPlugin::FRAME_TIME).and_then(|d| d.smoothed()).unwrap_or(0.0);
        // (The share of the pixels the rays are drawn at while the view moves.)
        let drawn = cams.single().ok().and_then(|(.., a)| a.filter(|a| a.enabled && a.scale < 1.0).map(|a| a.scale));
        let drawn = drawn.map_or(String::new(), |s| format!("  rays at {:.0} %", s * 100.0));
        egui::Area::new("fps".into()).fixed_pos(free.right_top() + egui::vec2(-260.0, 8.0)).show(&ctx, |ui| {
            ui.label(RichText::new(format!("{fps:.1} fps  {ms:.1} ms{drawn}")).color(Color32::LIGHT_GREEN).monospace());
        });
    }
    if let Some(e) = session.error.clone() {
        let mut open = true;
        egui::Window::new("Could not open").open(&mut open).show(&ctx, |ui| {
            ui.label(RichText::new(e).color(Color32::LIGHT_RED));
            ui.label("The data shown before is still there.");
        });
        if !open {
            session.error = None;
        }
    }

    state.dialog.update(&ctx);
    let picked = state.dialog.take_picked().map(|p| (p, state.dialog_purpose));
    // The view as it is now, as a scene file's text.
    let scene_now = || {
        // The saved datasets, in the order ds_states writes them.
        let mut saved: Vec<Entity> = datasets.iter().filter(|(_, _, _, o, _)| o.is_some()).map(|(e, ..)| e).collect();
        saved.sort();
        let windows = window_params.specs(&saved);
        let rulers: Vec<_> = rulers.iter().filter_map(|r| crate::slices::ruler::RulerSpec::of(r, &saved)).collect();
        scene_text(
            &ds_states(&datasets),
            ViewState {
                camera: cams.single().map(|(o, ..)| o.camera()).ok(),
                background: state.background,
                light: light.0,
                lenses: &lens_params.ordered().into_iter().map(|(_, l, _)| l).collect::<Vec<_>>(),
                rendering: crate::scene::file::RenderingSpec::of(&state.view),
            },
            &session,
            (windows, rulers),
            &explode_specs,
        )
    };

    // Writes the view as it is now as a scene file (`.ron` added when missing).
    let save = |path: &std::path::Path| {
        let path = if path.extension().is_some_and(|e| e == "ron") { path.to_path_buf() } else { path.with_extension("ron") };
        std::fs::write(&path, scene_now()?).map_err(|e| format!("{}: {e}", path.display()))
    };
    // The view kept for recovery (nothing while a load is under way: the view is the
    // old one, or none).
    if loading.is_empty() && datasets.iter().any(|(_, _, _, o, _)| o.is_some()) {
        recovery.autosave(std::time::Instant::now(), scene_now);
    }
    super::recovery::offer(&ctx, &mut recovery, &mut load);

    // Movies.
    let animation = session.scene.as_ref().and_then(|s| s.animation.as_ref()).map(|a| (a.duration_s, a.fps));
    movie.window(&ctx, animation);
    let aspect = cams.single().ok().and_then(|(_, c, _)| c.logical_viewport_size()).map(|s| s.x / s.y.max(1.0)).unwrap_or(1.0);
    movie.start_requested(aspect, save);

    // File dialogs.
    if let Some((path, purpose)) = picked {
        match purpose {
            DialogPurpose::Open => {
                load.write(LoadRequest::Path(path));
            }
            DialogPurpose::SaveScene => {
                if let Err(e) = save(&path) {
                    session.error = Some(e);
                }
            }
        }
    }
    Ok(())
}

fn short(s: &str) -> String {
    std::path::Path::new(s).file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| s.to_string())
}

fn dataset_info(ui: &mut Ui, d: &Dataset) {
    let v = &d.volume;
    let g = &v.grid;
    let units = v.values.units.clone().map(|u| format!(" {u}")).unwrap_or_default();
    // (Values wrap: a long description or path must not widen the panel.)
    let width = ui.available_width();
    egui::Grid::new("info").num_columns(2).max_col_width((width - 90.0).max(80.0)).show(ui, |ui| {
        let mut row = |k: &str, val: String| {
            ui.label(RichText::new(k).weak());
            ui.add(egui::Label::new(val).wrap());
            ui.end_row();
        };
        row("format", format!("{} ({})", v.source.format, v.source.sample_type));
        row("size", crate::volume::grid::fmt_dims(g.dims));
        row("spacing", format!("{:.3} × {:.3} × {:.3} mm", g.spacing.x, g.spacing.y, g.spacing.z));
        row("orientation", g.orientation_code());
        row("values", format!("{:.1} … {:.1}{units}", v.stats.min, v.stats.max));
        row("mean ± sd", format!("{:.1} ± {:.1}", v.stats.mean, v.stats.std_dev));
        for (k, val) in v.source.details.iter().take(6) {
            row(k, val.clone());
        }
    });
}

fn transfer_panel(ui: &mut Ui, d: &mut Dataset, entity: Entity, editor: &mut tf_editor::EditorState) {
    let hist = d.volume.stats.histogram.clone();
    // A segmented dataset's object, or the dataset itself (the rest).
    let object = editor.object.filter(|k| d.appearance.segmentation.as_ref().is_some_and(|s| *k < s.objects.len()));
    let appearance = match (object, &mut d.appearance.segmentation) {
        (Some(k), Some(seg)) => {
            ui.label(RichText::new(format!("editing object '{}'", seg.objects[k].name)).strong());
            &mut seg.objects[k].appearance
        }
        _ => &mut d.appearance,
    };
    let lambda = appearance.mode == Mode::Context;
    match &mut appearance.lookup {
        Lookup::Transfer(tf) => {
            egui::ComboBox::from_label("preset").selected_text(tf.name.clone()).show_ui(ui, |ui| {
                for key in presets::names() {
                    if let Ok(p) = presets::builtin(key)
                        && ui.selectable_label(tf.name == p.name, &p.name).clicked()
                    {
                        *tf = p;
                    }
                }
            });
            if let (Some(u), Some(v)) = (&tf.units, &d.volume.values.units)
                && u != v
            {
                ui.label(RichText::new(format!("⚠ preset for {u}, data in {v}")).color(Color32::YELLOW));
            }
            let mut edited = tf.clone();
            if tf_editor::editor(ui, &mut edited, &hist, editor, lambda) {
                *tf = edited;
            }
        }
        Lookup::Labels(styles) => {
            let table = d.labels.clone();
            let picked = editor.picked_label.filter(|(e, _)| *e == entity).map(|(_, id)| id);
            let name_of = |id: u32| table.as_ref().map(|t| t.name(id)).unwrap_or_else(|| format!("label {id}"));
            match picked {
                Some(id) => ui.label(RichText::new(format!("picked: {} ({id})", name_of(id))).strong()),
                None => ui.label(RichText::new("double-click the view to pick a label").small().weak()),
            };
            egui::ScrollArea::vertical().max_height(260.0).show(ui, |ui| {
                for (id, s) in styles.styles.iter_mut().filter(|(id, _)| **id != 0) {
                    ui.horizontal(|ui| {
                        ui.checkbox(&mut s.visible, "");
                        ui.color_edit_button_rgb(&mut s.color);
                        ui.add(egui::Slider::new(&mut s.opacity, 0.0..=1.0).show_value(false));
                        let name = name_of(*id);
                        if picked == Some(*id) {
                            ui.label(RichText::new(format!("▶ {name}")).strong().color(Color32::YELLOW));
                        } else {
                            ui.label(name);
                        }
                    });
                }
            });
        }
    }
}

/// A projection's value range: off, or low and high within the data's range (low kept
/// at most high).
fn projection_range_controls(ui: &mut Ui, range: &mut Option<(f64, f64)>, (lo, hi): (f64, f64)) {
    let mut on = range.is_some();
    if ui
        .checkbox(&mut on, "only values within a range")
        .on_hover_text("MinIP above the air around an object, MIP below metal: samples outside are left out")
        .changed()
    {
        // Off to on: from a tenth of the way up (above the background) to the top.
        *range = on.then_some((lo + 0.1 * (hi - lo), hi));
    }
    if let Some((low, high)) = range {
        ui.add(egui::Slider::new(low, lo..=hi).text("lowest value"));
        ui.add(egui::Slider::new(high, lo..=hi).text("highest value"));
        *high = high.max(*low);
    }
}

fn rendering_panel(ui: &mut Ui, d: &mut Dataset, state: &mut AppState, light: &mut SceneLight) {
    let a = &mut d.appearance;
    egui::ComboBox::from_label("mode").selected_text(mode_name(a.mode)).show_ui(ui, |ui| {
        for m in Mode::ALL {
            ui.selectable_value(&mut a.mode, m, mode_name(m));
        }
    });
    if a.mode == Mode::Iso {
        let (lo, hi) = (d.volume.stats.min, d.volume.stats.max);
        ui.add(egui::Slider::new(&mut a.iso_value, lo..=hi).text("iso-value"));
    }
    if a.mode.is_projection() {
        projection_range_controls(ui, &mut a.projection_range, (d.volume.stats.min, d.volume.stats.max));
    }
    if a.mode == Mode::Context {
        let c = &mut a.context;
        ui.add(egui::Slider::new(&mut c.kappa_t, 0.0..=ContextParams::KAPPA_T_MAX).text("κt (depth)"))
            .on_hover_text("How far the view reaches into the volume ([ and ] step it)");
        ui.add(egui::Slider::new(&mut c.kappa_s, 0.0..=ContextParams::KAPPA_S_MAX).text("κs (sharpness)"))
            .on_hover_text("How sharp the boundary between cleared and kept is");
        let mut exact = c.power == Power::Exact;
        if ui.checkbox(&mut exact, "exact power (instead of Schlick's approximation)").changed() {
            c.power = if exact { Power::Exact } else { Power::Schlick };
        }
        ui.label(RichText::new("λt, λs: curves in the transfer function editor").small().weak());
    }
    ui.add(egui::Slider::new(&mut a.step, 0.1..=2.0).logarithmic(true).text("step (voxels)"));
    ui.checkbox(&mut a.shading.enabled, "shading");
    if a.shading.enabled {
        ui.add(egui::Slider::new(&mut a.shading.ambient, 0.0..=1.0).text("ambient"));
        ui.add(egui::Slider::new(&mut a.shading.diffuse, 0.0..=1.0).text("diffuse"));
        ui.add(egui::Slider::new(&mut a.shading.specular, 0.0..=1.0).text("specular"));
        ui.add(egui::Slider::new(&mut a.shading.shininess, 1.0..=128.0).logarithmic(true).text("shininess"));
    }
    ui.horizontal(|ui| {
        ui.label("light");
        let mut fixed = matches!(light.0, Light::Direction(_));
        if ui.radio_value(&mut fixed, false, "headlight").changed() || ui.radio_value(&mut fixed, true, "fixed").changed() {
            light.0 = if fixed { Light::Direction(Vec3::new(0.4, 0.6, 0.7)) } else { Light::Headlight };
        }
    });
    if let Light::Direction(dir) = &mut light.0 {
        let (mut az, mut el) = ((-dir.x).atan2(dir.y).to_degrees(), dir.z.clamp(-1.0, 1.0).asin().to_degrees());
        let c1 = ui.add(egui::Slider::new(&mut az, -180.0..=180.0).text("light azimuth")).changed();
        let c2 = ui.add(egui::Slider::new(&mut el, -89.0..=89.0).text("light elevation")).changed();
        if c1 || c2 {
            let (a, e) = (az.to_radians(), el.to_radians());
            *dir = Vec3::new(-a.sin() * e.cos(), a.cos() * e.cos(), e.sin());
        }
    }
    ui.horizontal(|ui| {
        ui.label("background");
        ui.color_edit_button_rgb(&mut state.background);
    });
    ui.checkbox(&mut state.view.jitter, "jitter ray starts");
    ui.checkbox(&mut state.view.skip_empty, "skip empty space");
    ui.checkbox(&mut state.view.early_termination, "early ray termination");
    ui.checkbox(&mut state.view.lens_antialias, "anti-alias where lenses compress");
    ui.checkbox(&mut state.view.lens_context_steps, "fast lenses on streamed data").on_hover_text(
        "Under a lens, streamed data steps along the ray at the context's rate: native voxels across, \
         about the cost of no lens, but structures thin along the ray may be missed",
    );
}

fn mode_name(m: Mode) -> &'static str {
    match m {
        Mode::Dvr => "DVR",
        Mode::Mip => "MIP",
        Mode::MinIp => "MinIP",
        Mode::XRay => "X-ray",
        Mode::GradientDvr => "gradient-modulated DVR",
        Mode::Iso => "iso-surface",
        Mode::Context => "context-preserving",
    }
}

type DatasetRow<'a> = (Entity, &'a DatasetOrigin, &'a Dataset, &'a Transform);

fn ds_states<'a>(datasets: &'a DatasetQuery) -> Vec<DatasetRow<'a>> {
    let mut rows: Vec<_> = datasets.iter().filter_map(|(e, d, _, o, t)| o.map(|o| (e, o, d, t))).collect();
    rows.sort_by_key(|r| r.0);
    rows
}

/// The side panel's width (points) until the user drags it.
const DEFAULT_PANEL_WIDTH: f32 = 330.0;

/// What the view shows besides the datasets, for saving it.
struct ViewState<'a> {
    camera: Option<crate::region::Camera>,
    background: [f32; 3],
    light: Light,
    lenses: &'a [crate::lens::Lens],
    rendering: crate::scene::file::RenderingSpec,
}

/// The app's state as a scene file's text.
fn scene_text(
    rows: &[DatasetRow],
    view: ViewState,
    session: &Session,
    (windows, rulers): (crate::windows::spec::WindowScene, Vec<crate::slices::ruler::RulerSpec>),
    explode: &crate::explode::edit::CurrentSpecs,
) -> Result<String, String> {
    use crate::scene::save::{DatasetState, scene_file};
    let ViewState { camera, background, light, lenses, rendering } = view;
    let states: Vec<DatasetState> = rows
        .iter()
        .map(|(e, o, d, t)| DatasetState {
            explode: explode.0.get(e).cloned().unwrap_or_else(|| o.0.explode.clone()),
            spec: &o.0,
            appearance: &d.appearance,
            translation: t.translation,
            rotation: t.rotation,
            visible: d.visible,
            clip: &d.clip,
        })
        .collect();
    let camera = camera.ok_or("no camera")?;
    let size = session.scene.as_ref().map(|s| s.size).unwrap_or((512, 512));
    let mut scene = scene_file(&states, &camera, background, light, size, lenses, &session.base);
    scene.rendering = rendering;
    scene.windows = windows.windows;
    scene.pointer = windows.pointer;
    scene.markers = windows.markers;
    scene.rulers = rulers;
    // The loaded scene's animation, while it still fits what the view has (its lenses
    // and datasets).
    scene.animation = session.scene.as_ref().and_then(|s| s.animation.clone()).filter(|a| a.validate(&scene.animation_refers()).is_ok());
    scene.to_ron()
}
