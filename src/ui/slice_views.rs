//! The slice views beside the 3D view (View ▸ Slice views, or L): axial, coronal and
//! sagittal slices of the selected dataset at its voxels' resolution, linked by one
//! crosshair (`slices::crosshair`), with window/level (right drag, presets, auto) and a
//! label dataset laid over in its colours. Click or drag in a slice: the crosshair
//! moves there; wheel: the next or previous slice; Shift+click twice: a distance ruler
//! (`slices::ruler`); the value under the cursor shows in the 3D view's corner. The 3D
//! view shows the three planes' outlines and the rulers.

use std::sync::Arc;

use bevy::prelude::*;
use bevy_egui::egui::{self, Color32, Rect, Stroke, pos2};

use super::rulers::{RULER, RulerTool, draw_ruler};
use super::streamed_slices::{Native, StreamedSlices, Wanted};
use crate::dataset::Dataset;
use crate::region::Ray;
use crate::slices::lens_outline::{self, LensRays};
use crate::slices::ruler::{self, Ruler};
use crate::slices::{CT_PRESETS, Orientation, Slice, SliceAxes, WindowLevel, crosshair, outline, overlay_labels};
use crate::volume::Volume;
use crate::volume::source::VoxelSource;

/// The views' colours, as 3D Slicer's: axial red, coronal green, sagittal yellow.
pub fn colour(o: Orientation) -> Color32 {
    match o {
        Orientation::Axial => Color32::from_rgb(240, 80, 80),
        Orientation::Coronal => Color32::from_rgb(90, 210, 90),
        Orientation::Sagittal => Color32::from_rgb(240, 220, 80),
    }
}

/// The colour of the lenses' outlines on the slices (as the 3D view draws them).
const LENS_OUTLINE: Color32 = Color32::from_gray(225);
/// The colour of the windows' outlines on the slices.
const WINDOW_OUTLINE: Color32 = Color32::from_rgb(90, 200, 255);

/// Opacity of a label dataset laid over the slices.
const OVERLAY_OPACITY: f32 = 0.45;

/// What the slice views show and what they drew.
#[derive(Resource, Default)]
pub struct SliceViews {
    pub show: bool,
    /// The crosshair in the shown dataset's frame (`None`: its centre).
    pub crosshair: Option<Vec3>,
    /// The window per dataset (`None`: auto until the user sets one).
    pub window: Option<(Entity, WindowLevel)>,
    /// Lay the other datasets' labels over the slices.
    pub overlay: bool,
    /// The value under the cursor, for the status line.
    pub probe: Option<String>,
    pictures: [Option<Picture>; 3],
    /// Native slices of a streamed dataset being read.
    streamed: StreamedSlices,
}

impl SliceViews {
    /// Whether a native slice is being read (the screenshot automation waits).
    pub fn reading(&self) -> bool {
        self.show && self.streamed.reading()
    }

    /// The views, shown or not (a label dataset laid over them).
    pub fn shown(show: bool) -> SliceViews {
        SliceViews { show, overlay: true, ..Default::default() }
    }
}

/// A slice's texture and what it shows.
struct Picture {
    /// The slice it shows, or stands in for until a streamed one arrives.
    wanted: SliceKey,
    /// Whether it shows that slice's own voxels (not the level in memory standing in).
    native: bool,
    look: Look,
    texture: egui::TextureHandle,
    slice: Slice,
}

/// (Volumes by their address: a loaded or replaced volume is a new one.)
#[derive(Clone, Copy, PartialEq)]
struct SliceKey {
    dataset: Entity,
    volume: usize,
    /// The pyramid level of a streamed dataset (`None`: the volume in memory).
    level: Option<usize>,
    index: u32,
}

/// How a slice is painted: its window (grey data) and the label volume laid over it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Look {
    window: Option<(u64, u64)>,
    overlay: Option<usize>,
}

/// One dataset as the views need it: entity, component, transform.
pub type Shown<'a> = (Entity, &'a Dataset, &'a Transform);

/// What the slices outline where they cut it (world space): the volumetric windows'
/// boxes (corners) and the lenses (the camera's rays through their outlines).
#[derive(Default)]
pub struct Cuts {
    pub boxes: Vec<[Vec3; 8]>,
    pub lenses: Vec<LensRays>,
}

/// The panel under the 3D view (`root`'s bottom), for dataset `shown`; `labels` a label
/// dataset to lay over; `cuts` the windows and lenses to outline where a slice passes
/// through them.
pub fn panel(
    root: &mut egui::Ui,
    views: &mut SliceViews,
    shown: Option<Shown>,
    labels: Option<Shown>,
    (cuts, source): (&Cuts, Option<&Arc<dyn VoxelSource>>),
    (rulers, tool): (&[Ruler], &mut RulerTool),
) {
    if !views.show {
        return;
    }
    let Some((entity, dataset, transform)) = shown else { return };
    // The windows and lenses in the dataset's frame.
    let to_dataset = transform.compute_affine().inverse();
    let ray = |r: &Ray| Ray { origin: to_dataset.transform_point3(r.origin), dir: to_dataset.transform_vector3(r.dir) };
    let cuts = Cuts {
        boxes: cuts.boxes.iter().map(|b| b.map(|c| to_dataset.transform_point3(c))).collect(),
        lenses: cuts
            .lenses
            .iter()
            .map(|l| LensRays { rim: l.rim.iter().map(ray).collect(), outer: l.outer.iter().map(ray).collect() })
            .collect(),
    };
    let volume = &dataset.volume;
    let grid = &volume.grid;
    let point = views.crosshair.unwrap_or_else(|| grid.index_to_world().transform_point3((grid.dims.as_vec3() - 1.0) * 0.5));
    let window = match views.window {
        Some((e, w)) if e == entity => w,
        _ => WindowLevel::auto(&volume.stats),
    };
    let is_labels = dataset.labels.is_some();
    views.probe = None;
    egui::Panel::bottom("slice_views").resizable(true).default_size(280.0).min_size(120.0).show(root, |ui| {
        ui.horizontal_wrapped(|ui| {
            ui.label(egui::RichText::new(format!("Slices of {}", volume.name)).strong());
            if !is_labels {
                ui.separator();
                let mut w = window;
                ui.label("Window")
                    .on_hover_text("Width of the values shown as greys (the data's units); right drag in a slice: left/right");
                ui.add(egui::DragValue::new(&mut w.width).speed(range_step(volume)).range(1.0..=f64::MAX));
                ui.label("Level").on_hover_text("Centre of the window; right drag in a slice: up/down");
                ui.add(egui::DragValue::new(&mut w.level).speed(range_step(volume)));
                egui::ComboBox::from_id_salt("wl_preset").selected_text("Preset").show_ui(ui, |ui| {
                    if ui.selectable_label(false, "auto (1st–99th percentile)").clicked() {
                        w = WindowLevel::auto(&volume.stats);
                    }
                    for (name, width, level) in CT_PRESETS {
                        if ui.selectable_label(false, format!("CT {name} ({width}/{level})")).clicked() {
                            w = WindowLevel::new(width, level);
                        }
                    }
                });
                if w != window {
                    views.window = Some((entity, w));
                }
            }
            let mine: Vec<Ruler> = rulers.iter().copied().filter(|r| r.dataset == entity).collect();
            ui.separator();
            if tool.start.is_some_and(|(e, _)| e == entity) {
                ui.label(egui::RichText::new("ruler: Shift+click its other end (Esc: cancel)").color(RULER));
            } else {
                ui.label(format!("rulers: {}", mine.len())).on_hover_text("Shift+click two points in the slices: a distance ruler");
                if !mine.is_empty() && ui.small_button("clear").clicked() {
                    tool.clear = Some(entity);
                }
            }
            if labels.is_some() {
                ui.separator();
                ui.checkbox(&mut views.overlay, "Labels over").on_hover_text("Lay the label dataset over the slices in its colours");
            }
        });
        // Three columns with the spacing between them.
        let room = ui.available_size();
        let gap = ui.spacing().item_spacing.x;
        let cell = egui::vec2(((room.x - 2.0 * gap) / 3.0 - 2.0).max(16.0), (room.y - 22.0).max(16.0));
        ui.horizontal(|ui| {
            for (k, o) in Orientation::ALL.into_iter().enumerate() {
                ui.vertical(|ui| {
                    ui.set_width(cell.x);
                    view(
                        ui,
                        views,
                        k,
                        o,
                        (entity, dataset, source),
                        point,
                        window,
                        labels.filter(|_| views.overlay),
                        cell,
                        (&cuts, rulers, &mut *tool),
                    );
                });
            }
        });
    });
}

/// A step of the window drags: a 500th of the value range.
fn range_step(volume: &Volume) -> f64 {
    ((volume.stats.max - volume.stats.min) / 500.0).max(0.01)
}

/// One slice view: header, picture, crosshair, interaction.
#[allow(clippy::too_many_arguments)]
fn view(
    ui: &mut egui::Ui,
    views: &mut SliceViews,
    k: usize,
    o: Orientation,
    (entity, dataset, source): (Entity, &Dataset, Option<&Arc<dyn VoxelSource>>),
    point: Vec3,
    window: WindowLevel,
    overlay: Option<Shown>,
    cell: egui::Vec2,
    (cuts, rulers, tool): (&Cuts, &[Ruler], &mut RulerTool),
) {
    let volume = &dataset.volume;
    let memory_axes = SliceAxes::of(volume.grid.direction, o);
    let memory_index = crosshair::slice_through(&memory_axes, &volume.grid, point);
    // A streamed dataset's slice comes from the finest level that fits, read in the
    // background; the level in memory stands in until it arrives.
    let streamed = source.and_then(|s| Wanted::of(s.as_ref(), entity, o, point).map(|(w, a)| (s, w, a)));
    let wanted = SliceKey {
        dataset: entity,
        volume: Arc::as_ptr(volume) as usize,
        level: streamed.map(|(_, w, _)| w.level),
        index: streamed.map_or(memory_index, |(_, w, _)| w.index),
    };
    let native = match streamed {
        Some((s, w, a)) => views.streamed.poll(k, w, a, s),
        None => Native::Taken,
    };
    let look = Look {
        window: dataset.labels.is_none().then(|| (window.width.to_bits(), window.level.to_bits())),
        overlay: overlay.map(|(_, d, _)| Arc::as_ptr(&d.volume) as usize),
    };
    let (medical, axis) = o.names();
    let reading = matches!(native, Native::Reading);
    let failed = if let Native::Failed(e) = &native { Some(e.clone()) } else { None };
    let fresh = match native {
        Native::Ready(slice) => Some((slice, true)),
        _ if views.pictures[k].as_ref().is_none_or(|p| p.wanted != wanted) => {
            Some((Slice::of_volume(volume, memory_axes, memory_index), streamed.is_none()))
        }
        _ => None,
    };
    let paint = |slice: &Slice| {
        let mut pixels = match &dataset.labels {
            Some(table) => slice.labels(table),
            None => slice.grey(&window),
        };
        if let Some((_, labels, transform)) = overlay
            && let Some(table) = &labels.labels
        {
            overlay_labels(&mut pixels, slice, &labels.volume, transform.compute_affine(), table, OVERLAY_OPACITY);
        }
        let rgba: Vec<u8> = pixels.iter().flatten().copied().collect();
        egui::ColorImage::from_rgba_unmultiplied([slice.width as usize, slice.height as usize], &rgba)
    };
    if let Some((slice, is_native)) = fresh {
        let image = paint(&slice);
        let texture = match views.pictures[k].take() {
            Some(mut p) => {
                p.texture.set(image, egui::TextureOptions::NEAREST);
                p.texture
            }
            None => ui.ctx().load_texture(format!("slice_{medical}"), image, egui::TextureOptions::NEAREST),
        };
        views.pictures[k] = Some(Picture { wanted, native: is_native, look, texture, slice });
    } else if let Some(p) = views.pictures[k].as_mut()
        && p.look != look
    {
        p.texture.set(paint(&p.slice), egui::TextureOptions::NEAREST);
        p.look = look;
    }
    let Some(picture) = &views.pictures[k] else { return };
    // Geometry from the slice shown (a pyramid level's grid for a native streamed one).
    let (grid, axes, index) = (&picture.slice.grid, picture.slice.axes, picture.slice.index);
    let mut header = format!("{medical} ({axis})  {} / {}", index + 1, axes.count(grid.dims));
    let level = streamed.map(|(_, w, _)| w.level);
    match (level, failed) {
        (Some(l), Some(e)) => header += &format!("  · level {l} unreadable: {e}"),
        (Some(l), None) if reading && !picture.native => header += &format!("  · reading level {l}…"),
        (Some(l), None) if picture.native && l > 0 => header += &format!("  · level {l}"),
        _ => {}
    }
    ui.label(egui::RichText::new(header).color(colour(o)));
    let size = crosshair::fit((picture.slice.width, picture.slice.height), axes.pixel_mm(grid.spacing), glam::Vec2::new(cell.x, cell.y));
    let (rect, response) = ui.allocate_exact_size(egui::vec2(size.x, size.y), egui::Sense::click_and_drag());
    let painter = ui.painter_at(rect);
    painter.image(picture.texture.id(), rect, Rect::from_min_max(pos2(0.0, 0.0), pos2(1.0, 1.0)), Color32::WHITE);
    let (w, h) = (picture.slice.width as f32, picture.slice.height as f32);
    let to_screen = |px: glam::Vec2| pos2(rect.left() + (px.x + 0.5) / w * rect.width(), rect.top() + (px.y + 0.5) / h * rect.height());
    let to_pixel =
        |p: egui::Pos2| glam::Vec2::new((p.x - rect.left()) / rect.width() * w - 0.5, (p.y - rect.top()) / rect.height() * h - 0.5);
    // The other two planes through the crosshair, in their colours.
    let at = to_screen(crosshair::pixel_of(&axes, grid, point));
    for other in Orientation::ALL.into_iter().filter(|x| *x != o) {
        let along_rows = SliceAxes::of(grid.direction, other).normal == axes.column.0;
        let line = if along_rows {
            [pos2(at.x, rect.top()), pos2(at.x, rect.bottom())]
        } else {
            [pos2(rect.left(), at.y), pos2(rect.right(), at.y)]
        };
        painter.line_segment(line, Stroke::new(1.0, colour(other).gamma_multiply(0.8)));
    }
    // The windows this slice passes through, as the 3D view outlines them.
    for b in &cuts.boxes {
        let mut outline: Vec<egui::Pos2> = outline::section(b, grid, &axes, index).into_iter().map(to_screen).collect();
        if let Some(&first) = outline.first() {
            outline.push(first);
            painter.extend(egui::Shape::dashed_line(&outline, Stroke::new(1.5, WINDOW_OUTLINE), 6.0, 4.0));
        }
    }
    // The lenses, as the 3D view sees them through this slice: the focus rim solid, the
    // border's outer edge dashed, each over a dark halo.
    let to_index = grid.world_to_index();
    for lens in &cuts.lenses {
        for (rays, dashed) in [(&lens.rim, false), (&lens.outer, true)] {
            for curve in lens_outline::section(rays, to_index, grid, &axes, index) {
                let points: Vec<egui::Pos2> = curve.into_iter().map(to_screen).collect();
                let halo = Stroke::new(3.0, Color32::from_black_alpha(140));
                let line = Stroke::new(1.2, LENS_OUTLINE);
                if dashed {
                    painter.extend(egui::Shape::dashed_line(&points, line, 6.0, 4.0));
                } else {
                    painter.add(egui::Shape::line(points.clone(), halo));
                    painter.add(egui::Shape::line(points, line));
                }
            }
        }
    }
    // The rulers of this dataset where they pass through this slice, with their length.
    for r in rulers.iter().filter(|r| r.dataset == entity) {
        let Some((s0, s1)) = ruler::on_slice(to_index.transform_point3(r.from), to_index.transform_point3(r.to), axes.normal, index) else {
            continue;
        };
        let at = |s: f32| to_screen(crosshair::pixel_of(&axes, grid, r.from.lerp(r.to, s)));
        draw_ruler(&painter, (at(s0), s0 == 0.0), (at(s1), s1 == 1.0), r.length_mm(), 12.0);
    }
    // A ruler begun follows the cursor.
    if let Some((_, start)) = tool.start.filter(|(e, _)| *e == entity)
        && let Some(p) = response.hover_pos()
    {
        painter.line_segment([to_screen(crosshair::pixel_of(&axes, grid, start)), p], Stroke::new(1.0, RULER));
    }
    painter.rect_stroke(rect, 0.0, Stroke::new(1.0, colour(o)), egui::StrokeKind::Inside);
    // Interaction: Shift+click places a ruler's ends, a click or drag the crosshair.
    let mut ruler_end = None;
    let shift = ui.input(|i| i.modifiers.shift);
    if response.clicked()
        && shift
        && let Some(p) = response.interact_pointer_pos()
    {
        let point = crosshair::point_at(&axes, grid, index, to_pixel(p));
        ruler_end = Some(point);
    } else if (response.clicked() || response.dragged_by(egui::PointerButton::Primary))
        && let Some(p) = response.interact_pointer_pos()
    {
        views.crosshair = Some(crosshair::point_at(&axes, grid, index, to_pixel(p)));
    }
    if response.dragged_by(egui::PointerButton::Secondary) && dataset.labels.is_none() {
        let d = response.drag_delta();
        views.window = Some((entity, window.dragged(d.x, d.y, range_step(volume))));
    }
    if let Some(p) = response.hover_pos() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            let count = axes.count(grid.dims) as i64;
            let next = (index as i64 + scroll.signum() as i64).clamp(0, count - 1) as u32;
            let mut q = grid.world_to_index().transform_point3(point);
            q[axes.normal] = next as f32;
            let moved = grid.index_to_world().transform_point3(q);
            views.crosshair = Some(moved);
        }
        views.probe = probe(&picture.slice, dataset, to_pixel(p), level.filter(|_| picture.native));
    }
    if let Some(point) = ruler_end {
        tool.end(entity, point);
    }
}

/// The value (and label) of the voxel under continuous pixel `px`.
/// (`level`: the pyramid level the slice's voxels are of, when not the volume's own.)
fn probe(slice: &Slice, dataset: &Dataset, px: glam::Vec2, level: Option<usize>) -> Option<String> {
    let (x, y) = (px.x.round(), px.y.round());
    if x < 0.0 || y < 0.0 || x >= slice.width as f32 || y >= slice.height as f32 {
        return None;
    }
    let v = slice.axes.voxel(slice.grid.dims, slice.index, x as u32, y as u32);
    let code = slice.codes[(y as u32 * slice.width + x as u32) as usize];
    let value = slice.values.to_real(code as f64);
    let of_level = level.filter(|l| *l > 0).map(|l| format!(" of level {l}")).unwrap_or_default();
    Some(match &dataset.labels {
        Some(table) => format!("voxel ({}, {}, {}){of_level}: label {} {}", v.x, v.y, v.z, value, table.name(value as u32)),
        None => format!("voxel ({}, {}, {}){of_level}: {}", v.x, v.y, v.z, slice.values.describe(code as u32)),
    })
}

/// The three planes' outlines in the 3D view (`free`), for the dataset shown.
pub fn planes_overlay(ctx: &egui::Context, free: Rect, views: &SliceViews, shown: Option<Shown>, camera: Option<crate::region::Camera>) {
    let (true, Some((_, dataset, transform)), Some(camera)) = (views.show, shown, camera) else { return };
    let grid = &dataset.volume.grid;
    let point = views.crosshair.unwrap_or_else(|| grid.index_to_world().transform_point3((grid.dims.as_vec3() - 1.0) * 0.5));
    let painter = ctx.layer_painter(egui::LayerId::new(egui::Order::Background, egui::Id::new("slice_planes"))).with_clip_rect(free);
    let to_world = transform.compute_affine();
    for o in Orientation::ALL {
        let axes = SliceAxes::of(grid.direction, o);
        let index = crosshair::slice_through(&axes, grid, point);
        let corners = crosshair::corners(&axes, grid, index);
        let on_screen: Option<Vec<egui::Pos2>> = corners
            .iter()
            .map(|c| {
                camera
                    .to_pixel(to_world.transform_point3(*c), free.width(), free.height())
                    .map(|p| pos2(free.left() + p.x, free.top() + p.y))
            })
            .collect();
        if let Some(mut outline) = on_screen {
            outline.push(outline[0]);
            painter.line(outline, Stroke::new(1.5, colour(o)));
        }
    }
}

/// L: the slice views on and off.
pub fn slice_keys(keys: Res<ButtonInput<KeyCode>>, mut contexts: bevy_egui::EguiContexts, mut views: ResMut<SliceViews>) {
    if contexts.ctx_mut().is_ok_and(|c| c.egui_wants_keyboard_input()) {
        return;
    }
    if keys.just_pressed(KeyCode::KeyL) {
        views.show = !views.show;
    }
}
