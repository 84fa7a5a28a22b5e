//! `focal bench --bricked`: streaming brick by brick (issue 23), ratios in one run.
//!
//! - **orbit, resident**: the procedural 1024³ source (2 GiB of codes, 8× the brick
//!   cache of 256 MiB), the camera orbiting half a degree a frame once the working set
//!   is resident, against the same view of the level the view chose, whole in memory
//!   (goal ≤ ×2: the page-table indirection's cost);
//! - **magnifier**: a 4× magnifier over the bricked view (native bricks under it)
//!   against the bricked view without it (goal ≤ ×1.3), and the same magnifier stepping
//!   at the context's rate along the ray (`VolumeView::lens_context_steps`): what the
//!   lens costs apart from its finer samples;
//! - **first frame 8192³**: from opening the 8192³ procedural source (1 TiB of codes) to
//!   its first drawn frame, the coarse level (goal under 1 s; the ratio is against 1 s);
//! - **peak memory**: peak resident memory of `focal render procedural:1024` in a child
//!   process with the default budgets (goal under 1 GiB) and with a 200 MiB brick cache
//!   (the source 10× larger than it), beside a phantom's render (the process's own cost):
//!   the ratio is the growth over the phantom's against the cache budget.

use std::sync::Arc;
use std::time::Instant;

use bevy::prelude::*;
use focal::dataset::{Dataset, VolumeView};
use focal::lens::Lens;
use focal::lens::systems::replace_lenses;
use focal::region::{Appearance, Mode, View};
use focal::streaming::bricked::{BrickedDataset, CPU_BUDGET_VAR, StreamBudget, StreamStatus};
use focal::volume::source::VoxelSource;
use focal::volume::source::level::read_level;
use focal::volume::source::procedural::ProceduralSource;

use focal::render::counts::RayCounts;

use super::harness::{Bench, Row};

/// The look of the procedural ball: only the lattices' crests opaque (as the example).
fn crests() -> Result<Appearance, String> {
    let tf = focal::transfer::presets::parse(
        r#"(name: "lattice crests", space: Absolute, units: None,
            color: [(40000.0, (0.9, 0.55, 0.25)), (50000.0, (1.0, 0.9, 0.7))],
            opacity: [(0.0, 0.0), (41000.0, 0.0), (45000.0, 0.25), (52000.0, 0.8)])"#,
        "bench",
    )?;
    Ok(Appearance::new(Mode::Dvr, tf))
}

fn procedural(edge: u32) -> Result<Arc<dyn VoxelSource>, String> {
    Ok(Arc::new(ProceduralSource::new(UVec3::splat(edge), Vec3::splat(focal::volume::source::procedural::DEFAULT_SPACING_MM))?))
}

fn clear(bench: &mut Bench) {
    let world = bench.off.world_mut();
    let old: Vec<Entity> = world.query_filtered::<Entity, With<Dataset>>().iter(world).collect();
    for e in old {
        world.despawn(e);
    }
}

/// The GPU counts of the two configurations of the last [`Bench::rounds`].
fn counted(bench: &Bench) -> Result<(RayCounts, RayCounts), String> {
    match bench.counts[..] {
        [a, b] => Ok((a, b)),
        _ => Err(format!("{} configurations counted, two timed", bench.counts.len())),
    }
}

fn row(group: &'static str, config: &str, ms: f64, baseline: &str, base_ms: f64, note: String) -> Row {
    Row {
        group: group.into(),
        config: config.into(),
        ms,
        baseline: baseline.into(),
        ratio: ms / base_ms.max(1e-9),
        sample_ratio: None,
        spread: None,
        se: None,
        gpu_ms: None,
        note,
        by_process: Vec::new(),
    }
}

/// [`row`] for configuration `i` of the last [`Bench::rounds`]: its paired ratio and spread.
fn paired_row(bench: &Bench, i: usize, config: &str, ms: &[f64], baseline: &str, note: String) -> Row {
    let base = row("bricked", config, ms[i], baseline, ms[0], note);
    match bench.paired.get(i) {
        Some(p) => Row { ratio: p.ratio, spread: Some(p.spread), se: Some(p.se), gpu_ms: bench.gpu_ms.get(i).copied().flatten(), ..base },
        None => base,
    }
}

pub(super) fn group(bench: &mut Bench, rows: &mut Vec<Row>) -> Result<(), String> {
    let look = crests()?;
    let still = VolumeView { jitter: false, ..Default::default() };
    bench.off.set_view(still);

    // Orbit, resident: the bricked source against the chosen level in memory.
    clear(bench);
    let source = procedural(1024)?;
    let budget = StreamBudget::default();
    let (bricked, coarse) = BrickedDataset::open(source.clone(), budget.cpu_bytes.min(256 << 20))?.map_err(|e| e.to_string())?;
    let streamed = bench.off.world_mut().spawn((Dataset::new(Arc::new(coarse), look.clone()), Transform::default(), bricked)).id();
    let (lo, hi) = source.info().levels[0].grid.world_bounds();
    let aspect = bench.off.width as f32 / bench.off.height as f32;
    let camera = View::Oblique.frame_box(lo, hi, aspect, false);
    bench.off.set_camera(&camera);
    let converge = Instant::now();
    let first = bench.off.capture()?;
    let status = bench.off.world_mut().resource::<StreamStatus>().clone();
    let counts = status.counts();
    let level = counts.finest_wanted.unwrap_or(0);
    let converged_ms = converge.elapsed().as_secs_f64() * 1000.0;
    let (whole, _) = read_level(source.as_ref(), level, &|_| {}).map_err(|e| e.to_string())?;
    let mut in_memory = Dataset::new(Arc::new(whole), look.clone());
    in_memory.visible = false;
    let memory = bench.off.world_mut().spawn((in_memory, Transform::default())).id();
    let show = |off: &mut focal::render::headless::Offscreen, bricked: bool| {
        for (e, on) in [(streamed, bricked), (memory, !bricked)] {
            if let Some(mut d) = off.world_mut().get_mut::<Dataset>(e) {
                d.visible = on;
            }
        }
    };
    let centre = (lo + hi) * 0.5;
    let (ms, images) = bench.rounds(camera, centre, 2, true, |off, i| show(off, i == 1))?;
    let diff = super::harness::difference(&images[0], &images[1]);
    let (memory_counts, bricked_counts) = counted(bench)?;
    rows.push(row(
        "bricked",
        &format!("level {level} in memory"),
        ms[0],
        &format!("level {level} in memory"),
        ms[0],
        format!(
            "procedural 1024³ (2 GiB of codes, 8× the 256 MiB brick cache), orbiting; {} bricks, converged in {converged_ms:.0} ms",
            counts.wanted
        ),
    ));
    rows.push(Row {
        sample_ratio: Some(bricked_counts.samples as f64 / memory_counts.samples.max(1) as f64),
        ..paired_row(
            bench,
            1,
            "orbit, resident",
            &ms,
            &format!("level {level} in memory"),
            format!("pictures differ by at most {diff} levels; {:.1} page look-ups a sample", bricked_counts.lookups_per_sample()),
        )
    });
    bench.save_images("bricked", &[first, images[1].clone()])?;

    // A 4× magnifier over the bricked view, its rays stepping at their own footprint's
    // level (native) and at the camera's (VolumeView::lens_context_steps).
    show(&mut bench.off, true);
    bench.off.set_camera(&camera);
    let lens = Lens::magnifier(Vec2::new(0.05, 0.0), 0.3, 0.15, 4.0);
    let (ms, images) = bench.rounds(camera, centre, 3, false, |off, i| {
        replace_lenses(off.world_mut(), if i >= 1 { std::slice::from_ref(&lens) } else { &[] });
        off.set_view(VolumeView { lens_context_steps: i == 2, ..still });
    })?;
    let finest = status.counts().finest_wanted;
    let [plain, lensed, fast] = bench.counts[..] else {
        return Err(format!("{} configurations counted, three timed", bench.counts.len()));
    };
    replace_lenses(bench.off.world_mut(), &[]);
    bench.off.set_view(still);
    rows.push(row("bricked", "no lens", ms[0], "no lens", ms[0], "the bricked view above, still".into()));
    // (The lens's rays step at the level of their magnified footprint, two levels finer
    // under a 4× focus: at equal cost per sample the frame costs its sample ratio.)
    let per_ray = |c: &RayCounts| format!("samples per ray {:.0} → {:.0} (most {} → {})", plain.per_ray(), c.per_ray(), plain.most, c.most);
    rows.push(Row {
        sample_ratio: Some(lensed.samples as f64 / plain.samples.max(1) as f64),
        ..paired_row(
            bench,
            1,
            "magnifier 4×",
            &ms,
            "no lens",
            format!("finest level wanted {}; {}", finest.map_or("-".into(), |l| l.to_string()), per_ray(&lensed)),
        )
    });
    let (diff, share) = (super::harness::difference(&images[1], &images[2]), super::harness::share_differing(&images[1], &images[2], 16));
    rows.push(Row {
        sample_ratio: Some(fast.samples as f64 / plain.samples.max(1) as f64),
        ..paired_row(
            bench,
            2,
            "magnifier 4×, context steps",
            &ms,
            "no lens",
            format!(
                "the same native bricks stepped at the context's rate along the ray (the lens code's own cost); {}; differs from native steps by more than 16 levels in {share:.0} % of the drawn pixels (at most {diff})",
                per_ray(&fast)
            ),
        )
    });
    bench.save_images("bricked-magnifier", &images)?;

    // The first frame of 8192³.
    clear(bench);
    let t = Instant::now();
    let huge = procedural(8192)?;
    let (bricked, coarse) = BrickedDataset::open(huge.clone(), budget.cpu_bytes)?.map_err(|e| e.to_string())?;
    let opened = t.elapsed().as_secs_f64() * 1000.0;
    bench.off.world_mut().spawn((Dataset::new(Arc::new(coarse), look.clone()), Transform::default(), bricked));
    let (lo, hi) = huge.info().levels[0].grid.world_bounds();
    bench.off.set_camera(&View::Oblique.frame_box(lo, hi, aspect, false));
    let frames = bench.off.first_frame()?;
    let first_ms = t.elapsed().as_secs_f64() * 1000.0;
    rows.push(row(
        "bricked",
        "first frame 8192³",
        first_ms,
        "1 s goal",
        1000.0,
        format!("opening (the coarse level 64³ computed) {opened:.0} ms, then {frames} frames to the first drawn"),
    ));
    clear(bench);

    // Peak memory of renders in child processes.
    let render = |input: &str, cache_mb: Option<u64>| -> Result<f64, String> {
        let exe = std::env::current_exe().map_err(|e| e.to_string())?;
        let out = std::env::temp_dir().join(format!("focal-bench-{}.png", std::process::id()));
        let mut cmd = std::process::Command::new(exe);
        cmd.args(["render", input, "--size", "256x256", "--report-memory", "-o"]).arg(&out);
        if let Some(mb) = cache_mb {
            cmd.env(CPU_BUDGET_VAR, mb.to_string());
        }
        let result = cmd.output().map_err(|e| format!("focal render {input}: {e}"))?;
        let _ = std::fs::remove_file(&out);
        let text = String::from_utf8_lossy(&result.stderr);
        text.lines()
            .find_map(|l| l.strip_prefix("peak resident memory: ").and_then(|r| r.trim_end_matches(" MiB").trim().parse::<f64>().ok()))
            .ok_or_else(|| {
                format!("focal render {input} reported no peak memory (exit {}): {}", result.status, text.lines().last().unwrap_or(""))
            })
    };
    let phantom = render("phantom:head", None)?;
    let default = render("procedural:1024", None)?;
    let small = render("procedural:1024", Some(200))?;
    rows.push(row(
        "bricked",
        "rss phantom",
        phantom,
        "rss phantom",
        phantom,
        "MiB (not ms): focal render of the head phantom, the process's own memory".into(),
    ));
    rows.push(row(
        "bricked",
        "rss 1024³ default",
        default,
        "1 GiB goal",
        1024.0,
        "MiB: focal render procedural:1024 (2 GiB of 16-bit codes), default budgets".into(),
    ));
    rows.push(row(
        "bricked",
        "rss 1024³, 200 MiB cache",
        small - phantom,
        "200 MiB cache",
        200.0,
        format!("MiB above the phantom's ({small:.0} in all): the source is 10× the cache"),
    ));
    Ok(())
}
