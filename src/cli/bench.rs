//! `focal bench`: GPU frame times of fixed scenes, with ratios measured in the same run.
//!
//! Groups (all by default): `--skipping` (empty-space skipping on/off on a sparse label
//! volume: the head phantom's arteries alone), `--termination` (early ray termination
//! on/off on the dense head CT), `--modes` (every mode against DVR on the engine
//! phantom), `--lenses` (magic lenses against no lens on the head CT: a lens of factor
//! 1 (the lens code alone, same picture), a magnifier with and without anti-aliasing,
//! the sampling-rate and angular lenses, four lenses at once; goal: at most 10 %
//! overhead; then the feature lens on the labelled head while the camera orbits, its
//! silhouette found each frame on the GPU or on the CPU; goal: at most 25 %). Each line
//! ends with the ratio against its group's baseline; `--json` prints the same as JSON.

use std::sync::Arc;

use bevy::prelude::*;
use clap::Args;
use focal::FocalPlugins;
use focal::dataset::Dataset;
use focal::lens::systems::replace_lenses;
use focal::lens::{Lens, LensKind, Sampling};
use focal::region::{Appearance, Lookup, Mode, View};
use focal::render::VolumeView;
use focal::render::headless::Offscreen;
use focal::transfer::{LabelTransfer, presets};
use focal::volume::Volume;
use focal::volume::phantom::{self, Phantom};
use serde_json::json;

#[derive(Args)]
pub struct BenchArgs {
    /// Frames timed per configuration.
    #[arg(long, default_value_t = 5)]
    frames: u32,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "256x256")]
    size: String,
    /// Phantom resolution.
    #[arg(long, default_value_t = 128)]
    resolution: u32,
    /// Only the empty-space-skipping group.
    #[arg(long)]
    skipping: bool,
    /// Only the early-termination group.
    #[arg(long)]
    termination: bool,
    /// Only the modes group.
    #[arg(long)]
    modes: bool,
    /// Only the lenses group.
    #[arg(long)]
    lenses: bool,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

struct Row {
    group: &'static str,
    config: String,
    ms: f64,
    baseline: String,
    ratio: f64,
    note: String,
}

struct Bench {
    off: Offscreen,
    frames: u32,
}

impl Bench {
    fn show(&mut self, volume: Arc<Volume>, appearance: Appearance, view: VolumeView) -> Result<(f64, image::RgbaImage), String> {
        self.show_with(volume, appearance, view, false)
    }

    /// [`Self::show`]; with `orbit`, the camera turns half a degree about the volume
    /// every timed frame (so what depends on the camera is recomputed each frame).
    fn show_with(
        &mut self,
        volume: Arc<Volume>,
        appearance: Appearance,
        view: VolumeView,
        orbit: bool,
    ) -> Result<(f64, image::RgbaImage), String> {
        let world = self.off.world_mut();
        let old: Vec<Entity> = world.query_filtered::<Entity, With<Dataset>>().iter(world).collect();
        for e in old {
            world.despawn(e);
        }
        let (lo, hi) = appearance.visible_bounds(&volume).unwrap_or_else(|| volume.grid.world_bounds());
        self.off.world_mut().spawn((Dataset::new(volume, appearance), Transform::default()));
        let camera = View::Oblique.frame_box(lo, hi, self.off.width as f32 / self.off.height as f32, false);
        self.off.set_camera(&camera);
        self.off.set_view(view);
        let image = self.off.capture()?;
        let centre = (lo + hi) * 0.5;
        let t = self.off.time_frames_with(self.frames, |off, k| {
            if orbit {
                let turn = Quat::from_rotation_y((k + 1) as f32 * 0.5f32.to_radians());
                off.set_camera(&focal::region::Camera {
                    position: centre + turn * (camera.position - centre),
                    rotation: turn * camera.rotation,
                    ..camera
                });
            }
        });
        Ok((t.as_secs_f64() * 1000.0, image))
    }
}

/// Largest channel difference between two images, in 8-bit levels.
fn difference(a: &image::RgbaImage, b: &image::RgbaImage) -> u8 {
    a.pixels().zip(b.pixels()).flat_map(|(p, q)| (0..3).map(move |c| p[c].abs_diff(q[c]))).max().unwrap_or(0)
}

pub fn run(args: &BenchArgs) -> Result<(), String> {
    let (w, h) = args
        .size
        .split_once('x')
        .and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)))
        .ok_or_else(|| format!("size '{}' is not WIDTHxHEIGHT", args.size))?;
    let all = !(args.skipping || args.termination || args.modes || args.lenses);
    let off = Offscreen::new(w, h, |app| {
        app.add_plugins(FocalPlugins);
    })?;
    eprintln!("GPU: {}  image {w}×{h}, {} frames per configuration", off.adapter_name(), args.frames);
    let mut bench = Bench { off, frames: args.frames.max(1) };
    let still = VolumeView { jitter: false, ..Default::default() };
    let mut rows = Vec::new();

    if all || args.skipping {
        let head = phantom::head::generate(args.resolution)?;
        let arteries = phantom::head::label::ARTERIES as u32;
        let mut styles = LabelTransfer::from_table(&head.labels.table, head.labels.present_ids().into_iter().map(|(id, _)| id), 0.0);
        if let Some(s) = styles.styles.get_mut(&arteries) {
            s.opacity = 0.9;
        }
        let a = Appearance { lookup: Lookup::Labels(styles), ..Appearance::new(Mode::Dvr, presets::builtin("grayscale_ramp")?) };
        let labels = Arc::new(head.labels.volume);
        let (on, img_on) = bench.show(labels.clone(), a.clone(), still)?;
        let (off, img_off) = bench.show(labels, a, VolumeView { skip_empty: false, ..still })?;
        let base = "skipping on".to_string();
        rows.push(Row {
            group: "skipping",
            config: base.clone(),
            ms: on,
            baseline: base.clone(),
            ratio: 1.0,
            note: "head phantom arteries (label volume)".into(),
        });
        let note = format!("image differs by at most {} levels", difference(&img_on, &img_off));
        rows.push(Row { group: "skipping", config: "skipping off".into(), ms: off, baseline: base, ratio: off / on, note });
    }
    if all || args.termination {
        let ct = Arc::new(Phantom::Head.generate(args.resolution)?);
        let a = Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone")?);
        let (on, _) = bench.show(ct.clone(), a.clone(), still)?;
        let (off, _) = bench.show(ct, a, VolumeView { early_termination: false, ..still })?;
        let base = "termination on".to_string();
        rows.push(Row {
            group: "termination",
            config: base.clone(),
            ms: on,
            baseline: base.clone(),
            ratio: 1.0,
            note: "head phantom, CT skin + bone".into(),
        });
        rows.push(Row {
            group: "termination",
            config: "termination off".into(),
            ms: off,
            baseline: base,
            ratio: off / on,
            note: String::new(),
        });
    }
    if all || args.modes {
        let engine = Arc::new(Phantom::Engine.generate(args.resolution)?);
        let industrial = presets::builtin("industrial_ct")?;
        let ramp = presets::builtin("grayscale_ramp")?;
        let mut dvr = 0.0;
        for mode in Mode::ALL {
            let tf = if mode.is_projection() { ramp.clone() } else { industrial.clone() };
            let a = Appearance { iso_value: 90.0, ..Appearance::new(mode, tf) };
            let (ms, _) = bench.show(engine.clone(), a, still)?;
            if mode == Mode::Dvr {
                dvr = ms;
            }
            rows.push(Row {
                group: "modes",
                config: mode.name().into(),
                ms,
                baseline: "dvr".into(),
                ratio: ms / dvr.max(1e-9),
                note: "engine phantom".into(),
            });
        }
    }

    if all || args.lenses {
        let ct = Arc::new(Phantom::Head.generate(args.resolution)?);
        let a = Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone")?);
        let (plain, _) = bench.show(ct.clone(), a.clone(), still)?;
        let base = "no lens".to_string();
        rows.push(Row {
            group: "lenses",
            config: base.clone(),
            ms: plain,
            baseline: base.clone(),
            ratio: 1.0,
            note: "head phantom, CT skin + bone".into(),
        });
        let magnifier = Lens::magnifier(Vec2::new(0.1, 0.05), 0.3, 0.15, 2.5);
        let sampling =
            Lens { kind: LensKind::Sampling(Sampling::Cubic { center_rate: 3.0 }), ..Lens::magnifier(Vec2::ZERO, 0.5, 0.0, 1.0) };
        let fisheye =
            Lens { kind: LensKind::Angular { field_of_view: 120.0, whole_view: false }, ..Lens::magnifier(Vec2::ZERO, 0.5, 0.0, 1.0) };
        let four = vec![
            Lens::magnifier(Vec2::new(-0.5, 0.4), 0.25, 0.1, 2.0),
            Lens::magnifier(Vec2::new(0.5, 0.4), 0.25, 0.1, 3.0),
            Lens { center: Vec2::new(-0.5, -0.4), radius: 0.3, ..sampling.clone() },
            Lens { center: Vec2::new(0.5, -0.4), radius: 0.3, ..fisheye.clone() },
        ];
        // A magnifier of factor 1 bends no ray: the cost of the lens code alone, with
        // the picture unchanged (a real lens also changes what the rays cross).
        let null = Lens::magnifier(Vec2::new(0.1, 0.05), 0.3, 0.15, 1.0);
        let configs: Vec<(&str, Vec<Lens>, bool)> = vec![
            ("lens code (×1)", vec![null.clone()], false),
            ("lens code + AA", vec![null], true),
            ("magnifier", vec![magnifier.clone()], false),
            ("magnifier + AA", vec![magnifier], true),
            ("sampling + AA", vec![sampling], true),
            ("angular + AA", vec![fisheye], true),
            ("4 lenses + AA", four, true),
        ];
        for (name, lenses, antialias) in configs {
            replace_lenses(bench.off.world_mut(), &lenses);
            let (ms, _) = bench.show(ct.clone(), a.clone(), VolumeView { lens_antialias: antialias, ..still })?;
            rows.push(Row {
                group: "lenses",
                config: name.into(),
                ms,
                baseline: base.clone(),
                ratio: ms / plain.max(1e-9),
                note: "goal ≤ ×1.10".into(),
            });
        }
        replace_lenses(bench.off.world_mut(), &[]);

        // The feature lens needs its silhouette again whenever the camera moves: timed
        // while orbiting, silhouettes on the GPU (compute passes) and on the CPU.
        let head = phantom::head::generate(args.resolution)?;
        let labels = Appearance {
            lookup: Lookup::Labels(LabelTransfer::from_table(
                &head.labels.table,
                head.labels.present_ids().into_iter().map(|(id, _)| id),
                0.4,
            )),
            ..Appearance::new(Mode::Dvr, presets::builtin("grayscale_ramp")?)
        };
        let volume = Arc::new(head.labels.volume.clone());
        let (orbit, _) = bench.show_with(volume.clone(), labels.clone(), still, true)?;
        let base = "no lens, orbiting".to_string();
        rows.push(Row {
            group: "lenses",
            config: base.clone(),
            ms: orbit,
            baseline: base.clone(),
            ratio: 1.0,
            note: "head phantom labels".into(),
        });
        let ventricles = focal::lens::feature::FeatureRef { label: phantom::head::label::VENTRICLES as u32, region: None };
        let feature = Lens { shape: focal::lens::Shape::Feature(ventricles), ..Lens::magnifier(Vec2::ZERO, 0.3, 0.15, 2.5) };
        replace_lenses(bench.off.world_mut(), &[feature]);
        for (name, gpu) in [("feature (GPU)", true), ("feature (CPU)", false)] {
            let (ms, _) = bench.show_with(volume.clone(), labels.clone(), VolumeView { gpu_silhouettes: gpu, ..still }, true)?;
            rows.push(Row {
                group: "lenses",
                config: name.into(),
                ms,
                baseline: base.clone(),
                ratio: ms / orbit.max(1e-9),
                note: "silhouette every frame".into(),
            });
        }
        replace_lenses(bench.off.world_mut(), &[]);
    }

    if args.json {
        let v: Vec<_> =
            rows.iter().map(|r| json!({"group": r.group, "config": r.config, "ms_per_frame": r.ms, "baseline": r.baseline, "ratio": r.ratio, "note": r.note})).collect();
        println!("{}", serde_json::to_string_pretty(&v).map_err(|e| e.to_string())?);
    } else {
        for r in &rows {
            let note = if r.note.is_empty() { String::new() } else { format!("  ({})", r.note) };
            println!("{:<12} {:<16} {:>9.1} ms/frame  ×{:.2} vs {}{note}", r.group, r.config, r.ms, r.ratio, r.baseline);
        }
    }
    Ok(())
}
