//! The transfer-function editor: opacity control points drawn over the (log) histogram,
//! colour control points on a gradient bar beneath. For the context-preserving mode the
//! curve can show the λt or λs channel instead (section 5 of Bruckner et al. 2005: 1
//! everywhere until edited; λt = 0 makes a value range impenetrable, λs = 0 reduces it
//! to gradient-magnitude modulation).
//!
//! Drag a point to move it; double-click the plot to add a point (the colour bar to add
//! a colour point); right-click a point to remove it (the ends stay); click a colour
//! point to pick its colour.

use bevy_egui::egui::{self, Color32, Pos2, Rect, Sense, Stroke, StrokeKind, pos2, vec2};

use crate::transfer::function::{ColorPoint, OpacityPoint, TransferFunction, ValueSpace};
use crate::volume::Histogram;

/// What the editor remembers between frames.
#[derive(Default)]
pub struct EditorState {
    /// Colour point whose picker is open.
    pub picking: Option<usize>,
    /// The scalar channel the curve edits.
    pub channel: Channel,
    /// The label last picked in the viewport (dataset, label id), shown in the list.
    pub picked_label: Option<(bevy::prelude::Entity, u32)>,
    /// The object of a segmented dataset whose transfer function is edited (`None`:
    /// the dataset's own).
    pub object: Option<usize>,
}

/// The scalar channels of a transfer function.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Channel {
    #[default]
    Opacity,
    LambdaT,
    LambdaS,
}

impl Channel {
    pub const ALL: [Channel; 3] = [Channel::Opacity, Channel::LambdaT, Channel::LambdaS];

    pub fn name(self) -> &'static str {
        match self {
            Channel::Opacity => "opacity",
            Channel::LambdaT => "λt",
            Channel::LambdaS => "λs",
        }
    }

    /// The channel's points; an untouched λ channel (no points: 1 everywhere) gets its
    /// two ends at 1, the same function (the editor works on a copy that is kept only
    /// when edited).
    fn points(self, tf: &mut TransferFunction, lo: f64, hi: f64) -> &mut Vec<OpacityPoint> {
        let (a, b) = match tf.space {
            ValueSpace::Absolute => (lo, hi),
            ValueSpace::Relative => (0.0, 1.0),
        };
        let points = match self {
            Channel::Opacity => return &mut tf.opacity,
            Channel::LambdaT => &mut tf.lambda_t,
            Channel::LambdaS => &mut tf.lambda_s,
        };
        if points.is_empty() {
            points.extend([OpacityPoint(a, 1.0), OpacityPoint(b, 1.0)]);
        }
        points
    }
}

/// Display colour of an sRGB triple.
fn color32(c: [f32; 3]) -> Color32 {
    Color32::from_rgb((c[0] * 255.0) as u8, (c[1] * 255.0) as u8, (c[2] * 255.0) as u8)
}

/// Shows the editor; `lambda` offers the λ channels. Returns whether the function changed.
pub fn editor(ui: &mut egui::Ui, tf: &mut TransferFunction, hist: &Histogram, state: &mut EditorState, lambda: bool) -> bool {
    let (lo, hi) = (hist.min, hist.max.max(hist.min + 1e-9));
    // Control points live in value space or in fractions of the range.
    let space = tf.space.clone();
    let to_frac = |v: f64| match space {
        ValueSpace::Absolute => ((v - lo) / (hi - lo)) as f32,
        ValueSpace::Relative => v as f32,
    };
    let from_frac = |f: f32| match space {
        ValueSpace::Absolute => lo + f as f64 * (hi - lo),
        ValueSpace::Relative => f as f64,
    };
    let mut changed = false;
    if !lambda {
        state.channel = Channel::Opacity;
    } else {
        ui.horizontal(|ui| {
            ui.label("curve");
            for c in Channel::ALL {
                ui.selectable_value(&mut state.channel, c, c.name());
            }
            if state.channel != Channel::Opacity && ui.small_button("reset to 1").clicked() {
                match state.channel {
                    Channel::LambdaT => tf.lambda_t.clear(),
                    _ => tf.lambda_s.clear(),
                }
                changed = true;
            }
        });
    }
    let channel = state.channel;
    let width = ui.available_width().max(120.0);
    let (resp, painter) = ui.allocate_painter(vec2(width, 130.0), Sense::click());
    let r = resp.rect;
    painter.rect_filled(r, 2.0, Color32::from_gray(18));
    // Log histogram.
    let max = hist.counts.iter().map(|&c| ((c as f64) + 1.0).ln()).fold(1e-9, f64::max);
    let bw = r.width() / hist.counts.len().max(1) as f32;
    for (i, &c) in hist.counts.iter().enumerate() {
        let h = (((c as f64) + 1.0).ln() / max) as f32 * r.height();
        let x0 = r.left() + i as f32 * bw;
        painter.rect_filled(Rect::from_min_max(pos2(x0, r.bottom() - h), pos2(x0 + bw, r.bottom())), 0.0, Color32::from_gray(70));
    }
    let to_screen = |f: f32, a: f32| pos2(r.left() + f.clamp(-0.05, 1.05) * r.width(), r.bottom() - a * r.height());
    let from_screen = |p: Pos2| (((p.x - r.left()) / r.width()).clamp(0.0, 1.0), ((r.bottom() - p.y) / r.height()).clamp(0.0, 1.0));
    if resp.double_clicked()
        && let Some(p) = resp.interact_pointer_pos()
    {
        let (f, a) = from_screen(p);
        let points = channel.points(tf, lo, hi);
        points.push(OpacityPoint(from_frac(f), a));
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        changed = true;
    }
    let points = channel.points(tf, lo, hi);
    let n = points.len();
    let mut remove = None;
    let mut line = Vec::with_capacity(n);
    for (i, point) in points.iter_mut().enumerate() {
        let OpacityPoint(v, a) = *point;
        let c = to_screen(to_frac(v), a);
        let handle = ui.interact(Rect::from_center_size(c, vec2(12.0, 12.0)), resp.id.with(("opacity", i)), Sense::click_and_drag());
        if handle.dragged() {
            let d = handle.drag_delta();
            let f = (to_frac(v) + d.x / r.width()).clamp(0.0, 1.0);
            let a = (a - d.y / r.height()).clamp(0.0, 1.0);
            *point = OpacityPoint(from_frac(f), a);
            changed = true;
        }
        if handle.secondary_clicked() && n > 2 {
            remove = Some(i);
        }
        let fill = if handle.hovered() || handle.dragged() { Color32::YELLOW } else { Color32::WHITE };
        painter.circle_filled(c, 4.5, fill);
        line.push(c);
        handle.on_hover_text(format!("{v:.1}: {} {a:.3}", channel.name()));
    }
    if let Some(i) = remove {
        points.remove(i);
        changed = true;
    }
    if changed {
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    painter.line(line, Stroke::new(1.5, Color32::from_rgb(120, 190, 255)));
    painter.rect_stroke(r, 2.0, Stroke::new(1.0, Color32::GRAY), StrokeKind::Inside);

    // Colour bar.
    let (bar_resp, bar) = ui.allocate_painter(vec2(width, 22.0), Sense::click());
    let b = bar_resp.rect;
    let steps = 64;
    for i in 0..steps {
        let f0 = i as f32 / steps as f32;
        let c = tf.resolved(lo, hi).color_at(lo + (f0 as f64 + 0.5 / steps as f64) * (hi - lo));
        bar.rect_filled(
            Rect::from_min_max(
                pos2(b.left() + f0 * b.width(), b.top()),
                pos2(b.left() + (f0 + 1.0 / steps as f32) * b.width(), b.bottom()),
            ),
            0.0,
            color32(c),
        );
    }
    if bar_resp.double_clicked()
        && let Some(p) = bar_resp.interact_pointer_pos()
    {
        let f = ((p.x - b.left()) / b.width()).clamp(0.0, 1.0);
        let v = from_frac(f);
        let c = tf.resolved(lo, hi).color_at(lo + f as f64 * (hi - lo));
        tf.color.push(ColorPoint(v, c));
        tf.color.sort_by(|a, b| a.0.total_cmp(&b.0));
        changed = true;
    }
    let m = tf.color.len();
    let mut remove = None;
    for i in 0..m {
        let ColorPoint(v, c) = tf.color[i];
        let x = b.left() + to_frac(v).clamp(0.0, 1.0) * b.width();
        let marker = Rect::from_center_size(pos2(x, b.center().y), vec2(10.0, b.height()));
        let handle = ui.interact(marker, bar_resp.id.with(("color", i)), Sense::click_and_drag());
        if handle.dragged() {
            let f = (to_frac(v) + handle.drag_delta().x / b.width()).clamp(0.0, 1.0);
            tf.color[i].0 = from_frac(f);
            changed = true;
        }
        if handle.clicked() {
            state.picking = Some(i);
        }
        if handle.secondary_clicked() && m > 1 {
            remove = Some(i);
        }
        bar.rect_stroke(marker, 2.0, Stroke::new(2.0, if handle.hovered() { Color32::YELLOW } else { Color32::BLACK }), StrokeKind::Middle);
        bar.rect_filled(marker.shrink(2.0), 1.0, color32(c));
    }
    if let Some(i) = remove {
        tf.color.remove(i);
        state.picking = None;
        changed = true;
    }
    tf.color.sort_by(|a, b| a.0.total_cmp(&b.0));
    if let Some(i) = state.picking.filter(|&i| i < tf.color.len()) {
        ui.horizontal(|ui| {
            ui.label(format!("colour at {:.1}", tf.color[i].0));
            changed |= ui.color_edit_button_rgb(&mut tf.color[i].1).changed();
            if ui.small_button("done").clicked() {
                state.picking = None;
            }
        });
    }
    ui.label(egui::RichText::new("drag points · double-click adds · right-click removes").small().weak());
    changed
}
