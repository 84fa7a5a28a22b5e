//! `focal bench`: GPU frame times of fixed scenes, with ratios measured in the same run.
//!
//! Groups (all by default): `--skipping` (empty-space skipping on/off on a sparse label
//! volume: the head phantom's arteries alone), `--termination` (early ray termination
//! on/off on the dense head CT), `--modes` (every mode against DVR on the engine
//! phantom), `--lenses` (magic lenses against no lens on the head CT: a lens of factor
//! 1 (the lens code alone, same picture), a magnifier with and without anti-aliasing,
//! the sampling-rate and angular lenses, four lenses at once; then the feature lens on the labelled head while the camera orbits, its
//! silhouette found each frame on the GPU or on the CPU),
//! `--context` (context-preserving rendering against DVR on the engine: at κt = 0, the
//! same picture, the cost of evaluating equation 5), `--twolevel`
//! (two-level rendering of the head CT split by its labels against no objects),
//! `--windows` (volumetric windows against none, [`windows`]: one and four clip windows
//! showing the dataset as it is; the cutaway, the windows of
//! the paper's figures 3–6, a window over the head without clip, two halves),
//! `--explode` (exploded views, [`explode`]: the paper's table 1, 1 to 64 parts at rest
//! and exploded against the plain ray caster), `--bricked`
//! (streaming brick by brick, [`bricked`]: orbiting a source 8× the cache against the
//! chosen level in memory, a magnifier over it, the first frame of 8192³, peak memory),
//! `--interactive` (the orbiting camera's frame with its rays at ½ and ¼ of the pixels
//! per axis and at the app's adaptive resolution, [`interactive`]). Each line
//! ends with the ratio against its group's baseline; `--json` prints the same as JSON,
//! `--save DIR` writes each configuration's picture, and `FOCAL_BENCH_SAMPLES=1` prints
//! every timed frame. Rows with a goal (one table of them: [`goals`]) show it and whether it was met, and a
//! last line counts the goals met and names those missed. Configurations are timed in interleaved rounds (one frame of each
//! per round, after an untimed round); a row's ratio is the geometric mean over the rounds
//! of its frame over the baseline's in the same round, the lowest and highest fifth left out
//! (`harness::Paired`), and `±` (`ratio_spread` in `--json`) half the interquartile range
//! of those ratios; its `ms` is the median frame. The rounds (60 by default) run in three
//! processes of this program one after another, and a row's ratio is the mean of theirs
//! ([`processes`]: a process has an offset of its own that more rounds in it do not
//! average); a group whose ratios' standard error (`ratio_se`) is still above 1 %
//! (`--precision`) takes the same rounds again in more processes, up to 12
//! (`--max-processes`). Frames on llvmpipe on a shared machine scatter by ±10 % from frame to frame;
//! how far runs agree is in docs/performance.md, "Noise".

use std::sync::Arc;

use bevy::prelude::*;
use focal::FocalPlugins;
use focal::context::{ContextParams, Power};
use focal::dataset::VolumeView;
use focal::lens::systems::replace_lenses;
use focal::lens::{Lens, LensKind, Sampling};
use focal::region::{Appearance, Lookup, Mode};
use focal::region::{Object, Segmentation};
use focal::render::headless::Offscreen;
use focal::transfer::{LabelTransfer, presets};
use focal::volume::phantom::{self, Phantom};
use serde_json::json;

mod args;
mod bricked;
mod explode;
mod goals;
mod harness;
mod interactive;
mod processes;
mod windows;

pub use args::BenchArgs;
use harness::{Bench, Row, difference, names, push_group};

pub fn run(args: &BenchArgs) -> Result<(), String> {
    let rows = if args.processes > 1 { processes::measure(args)? } else { measure(args)? };
    report(&rows, args.json)
}

/// Every row asked for, measured in this process.
fn measure(args: &BenchArgs) -> Result<Vec<Row>, String> {
    let (w, h) = args
        .size
        .split_once('x')
        .and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)))
        .ok_or_else(|| format!("size '{}' is not WIDTHxHEIGHT", args.size))?;
    let all = !args.groups().iter().any(|(_, on)| *on);
    let off = Offscreen::new(w, h, |app| {
        // (Render diagnostics: each pass's GPU time, where the adapter has timestamp
        // queries.)
        app.add_plugins((FocalPlugins, bevy::render::diagnostic::RenderDiagnosticsPlugin));
    })?;
    // (The CPU too: on llvmpipe the ratios depend on it, docs/performance.md "Another
    // machine, other ratios".)
    let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let threads = std::thread::available_parallelism().map_or(0, |n| n.get());
    eprintln!("GPU: {} on {}  image {w}×{h}, {} rounds", off.adapter_name(), harness::cpu(&cpuinfo, threads), args.frames);
    let mut bench = Bench {
        off,
        frames: args.frames.max(1),
        save: args.save.clone(),
        camera: None,
        counts: Vec::new(),
        count_images: Vec::new(),
        paired: Vec::new(),
        gpu_ms: Vec::new(),
    };
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
        let configs = [("skipping on", vec![], still), ("skipping off", vec![], VolumeView { skip_empty: false, ..still })];
        let (ms, images) = bench.interleaved(Arc::new(head.labels.volume), a, &configs, false)?;
        let note = format!("image differs by at most {} levels", difference(&images[0], &images[1]));
        push_group(&mut rows, &bench, "skipping", &names(&configs), &ms, "head phantom arteries (label volume)", &note);
        bench.save_images("skipping", &images)?;
    }
    if all || args.termination {
        let ct = Arc::new(Phantom::Head.generate(args.resolution)?);
        let a = Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone")?);
        let configs = [("termination on", vec![], still), ("termination off", vec![], VolumeView { early_termination: false, ..still })];
        let (ms, images) = bench.interleaved(ct, a, &configs, false)?;
        bench.save_images("termination", &images)?;
        push_group(&mut rows, &bench, "termination", &names(&configs), &ms, "head phantom, CT skin + bone", "");
    }
    if all || args.modes {
        let engine = Arc::new(Phantom::Engine.generate(args.resolution)?);
        let industrial = presets::builtin("industrial_ct")?;
        let ramp = presets::builtin("grayscale_ramp")?;
        let appearances: Vec<Appearance> = Mode::ALL
            .iter()
            .map(|&mode| {
                let tf = if mode.is_projection() { ramp.clone() } else { industrial.clone() };
                Appearance { iso_value: 90.0, ..Appearance::new(mode, tf) }
            })
            .collect();
        let names: Vec<&str> = Mode::ALL.iter().map(|m| m.name()).collect();
        let (ms, _) = bench.interleaved_appearances(engine, &appearances, still)?;
        push_group(&mut rows, &bench, "modes", &names, &ms, "engine phantom", "engine phantom");
    }

    if all || args.context {
        // Context-preserving rendering against DVR on the engine (shaded, so DVR fetches
        // the gradient too). κt = 0 is the DVR picture, and takes DVR's cost path
        // (ContextParams::is_plain_dvr: equation 5 leaves every opacity; goal ≤ ×1.05).
        // At κt = 3 the rays also go deeper (less becomes opaque early), so those frames
        // do more samples as well.
        let engine = Arc::new(Phantom::Engine.generate(args.resolution)?);
        let industrial = presets::builtin("industrial_ct")?;
        let context = |kappa_t: f32, power: Power| Appearance {
            context: ContextParams { kappa_t, kappa_s: 0.5, power },
            ..Appearance::new(Mode::Context, industrial.clone())
        };
        let names = ["dvr", "context κt 0", "context κt 3", "context κt 3 exact"];
        let appearances = [
            Appearance::new(Mode::Dvr, industrial.clone()),
            context(0.0, Power::Schlick),
            context(3.0, Power::Schlick),
            context(3.0, Power::Exact),
        ];
        let (ms, images) = bench.interleaved_appearances(engine, &appearances, still)?;
        let note = format!("κt 0 differs from DVR by at most {} levels", difference(&images[0], &images[1]));
        push_group(&mut rows, &bench, "context", &names, &ms, "engine phantom", &note);
        bench.save_images("context", &images)?;
    }

    if all || args.twolevel {
        // Two-level rendering on the head CT split by its labels, against the rest's
        // appearance alone. With every object drawn like the rest the picture is the
        // same: the cost of finding each sample's object (a label fetch, a table
        // lookup). Then arteries DVR, skull MIP, ventricles X-ray over a
        // context-preserving rest.
        let head = focal::volume::phantom::head::generate(args.resolution)?;
        let ct = Arc::new(head.ct);
        let labels = Arc::new(head.labels.volume);
        let rest = Appearance {
            context: ContextParams { kappa_t: 3.0, ..Default::default() },
            ..Appearance::new(Mode::Context, presets::builtin("ct_skin_bone")?)
        };
        let segmented = |objects: Vec<Object>, own_values: bool| Appearance {
            segmentation: Some(Segmentation { labels: labels.clone(), table: None, objects, rest_visible: true, own_values }),
            ..rest.clone()
        };
        use focal::volume::phantom::head::label;
        let alike = ["skull", "arteries"]
            .iter()
            .zip([label::SKULL, label::ARTERIES])
            .map(|(n, l)| Object::new(*n, vec![l as u32], rest.clone()))
            .collect();
        let objects = vec![
            Object::new("arteries", vec![label::ARTERIES as u32], Appearance::new(Mode::Dvr, presets::builtin("ct_vessels")?)),
            Object::new("skull", vec![label::SKULL as u32], Appearance::new(Mode::Mip, presets::builtin("grayscale_ramp")?)),
            Object::new("ventricles", vec![label::VENTRICLES as u32], Appearance::new(Mode::XRay, presets::builtin("grayscale_ramp")?)),
        ];
        // (With own values each sample near a boundary takes its value from its own
        // object's voxels: the cell's eight labels at every boundary sample.)
        let names = ["context (no objects)", "two-level, objects alike", "two-level, dvr + mip + xray", "two-level, own values"];
        let appearances = [rest.clone(), segmented(alike, false), segmented(objects.clone(), false), segmented(objects, true)];
        let (ms, images) = bench.interleaved_appearances(ct, &appearances, still)?;
        let note = format!("objects alike differ from no objects by at most {} levels", difference(&images[0], &images[1]));
        push_group(&mut rows, &bench, "twolevel", &names, &ms, "head phantom", &note);
        bench.save_images("twolevel", &images)?;
    }

    if all || args.windows {
        windows::group(&mut bench, &mut rows, args.resolution)?;
    }

    if all || args.explode {
        explode::group(&mut bench, &mut rows, args.resolution, &args.parts)?;
    }

    if all || args.bricked {
        bricked::group(&mut bench, &mut rows)?;
    }

    if all || args.interactive {
        interactive::group(&mut bench, &mut rows, args.resolution)?;
    }

    if all || args.lenses {
        let ct = Arc::new(Phantom::Head.generate(args.resolution)?);
        let a = Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone")?);
        let magnifier = Lens::magnifier(Vec2::new(0.1, 0.05), 0.3, 0.15, 2.5);
        // A magnifier of factor 1 bends no ray: the cost of the lens code alone, with
        // the picture unchanged (a real lens also changes what the rays cross).
        let null = Lens::magnifier(Vec2::new(0.1, 0.05), 0.3, 0.15, 1.0);
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
        let aa = |on: bool| VolumeView { lens_antialias: on, ..still };
        let configs = [
            ("no lens", vec![], still),
            ("lens code (×1)", vec![null.clone()], aa(false)),
            ("lens code + AA", vec![null], aa(true)),
            ("magnifier", vec![magnifier.clone()], aa(false)),
            ("magnifier + AA", vec![magnifier], aa(true)),
            ("sampling + AA", vec![sampling], aa(true)),
            ("angular + AA", vec![fisheye], aa(true)),
            ("4 lenses + AA", four, aa(true)),
        ];
        let (ms, images) = bench.interleaved(ct, a, &configs, false)?;
        bench.save_images("lenses", &images)?;
        push_group(&mut rows, &bench, "lenses", &names(&configs), &ms, "head phantom, CT skin + bone", "");

        // The feature lens needs its silhouette again whenever the camera moves: timed
        // while orbiting, silhouettes on the GPU (compute passes) and on the CPU.
        let head = phantom::head::generate(args.resolution)?;
        let styles = LabelTransfer::from_table(&head.labels.table, head.labels.present_ids().into_iter().map(|(id, _)| id), 0.4);
        let labels = Appearance { lookup: Lookup::Labels(styles), ..Appearance::new(Mode::Dvr, presets::builtin("grayscale_ramp")?) };
        let ventricles = focal::lens::feature::FeatureRef { label: phantom::head::label::VENTRICLES as u32, region: None };
        let feature = Lens { shape: focal::lens::Shape::Feature(ventricles), ..Lens::magnifier(Vec2::ZERO, 0.3, 0.15, 2.5) };
        let configs = [
            ("no lens, orbiting", vec![], still),
            ("feature (GPU)", vec![feature.clone()], VolumeView { gpu_silhouettes: true, ..still }),
            ("feature (CPU)", vec![feature], VolumeView { gpu_silhouettes: false, ..still }),
        ];
        let (ms, images) = bench.interleaved(Arc::new(head.labels.volume), labels, &configs, true)?;
        bench.save_images("feature-lens", &images)?;
        push_group(&mut rows, &bench, "lenses", &names(&configs), &ms, "labelled head phantom", "silhouette every frame");
        replace_lenses(bench.off.world_mut(), &[]);
    }

    Ok(rows)
}

/// The rows as text lines (or JSON), and the goals' count.
fn report(rows: &[Row], json: bool) -> Result<(), String> {
    if json {
        let v: Vec<_> = rows
            .iter()
            .map(|r| {
                let goal = goals::of(&r.group, &r.config);
                let by_process = (!r.by_process.is_empty()).then_some(&r.by_process);
                json!({"group": r.group, "config": r.config, "ms_per_frame": r.ms, "baseline": r.baseline, "ratio": r.ratio, "frame_rate_percent": r.frame_rate_percent(), "sample_ratio": r.sample_ratio, "ratio_spread": r.spread, "ratio_se": r.se, "ratio_by_process": by_process, "gpu_pass_ms": r.gpu_ms, "goal": goal.map(|g| g.ratio), "goal_met": goal.map(|g| g.met(r.ratio)), "note": r.note})
            })
            .collect();
        println!("{}", serde_json::to_string_pretty(&v).map_err(|e| e.to_string())?);
    } else {
        for r in rows {
            let samples = r.sample_ratio.map_or(String::new(), |s| format!(", its picture ×{s:.2} the samples"));
            let spread = r.spread.map_or(String::new(), |s| format!(" ±{s:.2}"));
            let gpu = r.gpu_ms.map_or(String::new(), |g| format!(", rays {g:.1} ms on the GPU"));
            let note = if r.note.is_empty() { String::new() } else { format!("  ({})", r.note) };
            let goal = goals::of(&r.group, &r.config).map_or(String::new(), |g| format!("  [{}]", g.verdict(r.ratio)));
            println!(
                "{:<12} {:<16} {:>9.1} ms/frame  ×{:.2}{spread} vs {} ({:.0} % of its frame rate{samples}{gpu}){note}{goal}",
                r.group,
                r.config,
                r.ms,
                r.ratio,
                r.baseline,
                r.frame_rate_percent()
            );
        }
    }
    // (On standard error beside the JSON.)
    if let Some(summary) = goals::summary(rows.iter().map(|r| (r.group.as_str(), r.config.as_str(), r.ratio))) {
        if json { eprintln!("{summary}") } else { println!("{summary}") }
    }
    Ok(())
}
