//! `focal bench --interactive`: the moving camera's frame at a reduced resolution
//! (`render::reduced`, issue 24) against full resolution, on the head CT while the
//! camera orbits: every pixel, a half and a quarter of them per axis timed in
//! interleaved rounds, then the app's adaptive resolution (`interactive`, holding 50 ms)
//! orbiting on its own: its frame's median and the scale it settled at.

use std::sync::Arc;

use bevy::prelude::*;
use focal::dataset::VolumeView;
use focal::interactive::InteractiveResolution;
use focal::region::{Appearance, Mode};
use focal::transfer::presets;
use focal::volume::phantom::Phantom;

use super::harness::{Bench, Row, names, orbited, push_group};

/// Frames the adaptive row orbits before it is timed (the controller settles), and
/// timed.
const SETTLE: u32 = 20;
const TIMED: u32 = 30;

pub(super) fn group(bench: &mut Bench, rows: &mut Vec<Row>, resolution: u32) -> Result<(), String> {
    let ct = Arc::new(Phantom::Head.generate(resolution)?);
    let look = Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone")?);
    let still = VolumeView { jitter: false, ..Default::default() };
    let at = |resolution: f32| VolumeView { resolution, ..still };
    let configs = [
        ("full resolution, orbiting", vec![], at(1.0)),
        ("½ resolution, orbiting", vec![], at(0.5)),
        ("¼ resolution, orbiting", vec![], at(0.25)),
    ];
    // (The centre Bench::place frames the camera on, which the orbit turns about.)
    let (lo, hi) = look.visible_bounds(&ct).unwrap_or_else(|| ct.grid.world_bounds());
    let centre = (lo + hi) * 0.5;
    let (ms, images) = bench.interleaved(ct, look, &configs, true)?;
    bench.save_images("interactive", &images)?;
    let full = ms[0];
    let first = rows.len();
    push_group(
        rows,
        bench,
        "interactive",
        &names(&configs),
        &ms,
        "head phantom, CT skin + bone, orbiting",
        "rays drawn at a fraction of the pixels per axis, upscaled",
    );
    // (Samples are counted per pixel of the view, at full resolution: the reduced rows
    // draw a quarter and a sixteenth of the rays.)
    for row in rows.iter_mut().skip(first + 1) {
        row.sample_ratio = None;
    }

    // The app's adaptive resolution, orbiting on its own (it follows the frames it
    // measures, so it is not interleaved with the fixed ones).
    let camera = bench.camera.ok_or("no view placed")?;
    let target = InteractiveResolution::default().target_ms;
    let cam_entity = bench.off.camera();
    bench.off.set_view(still);
    bench.off.world_mut().entity_mut(cam_entity).insert(InteractiveResolution::default());
    let mut turn = 0u32;
    let mut orbit = |off: &mut focal::render::headless::Offscreen| {
        turn += 1;
        off.set_camera(&orbited(&camera, centre, turn));
    };
    for _ in 0..SETTLE {
        orbit(&mut bench.off);
        bench.off.update();
    }
    let mut frames = Vec::new();
    let mut scales = Vec::new();
    for _ in 0..TIMED {
        orbit(&mut bench.off);
        let t = std::time::Instant::now();
        bench.off.update();
        frames.push(t.elapsed().as_secs_f64() * 1000.0);
        scales.push(bench.off.world_mut().get::<VolumeView>(cam_entity).map_or(1.0, |v| v.resolution));
    }
    bench.off.world_mut().entity_mut(cam_entity).remove::<(InteractiveResolution, focal::dataset::view::Accumulate)>();
    bench.off.set_view(still);
    frames.sort_by(f64::total_cmp);
    scales.sort_by(f32::total_cmp);
    let median = frames[frames.len() / 2];
    let scale = scales[scales.len() / 2];
    rows.push(Row {
        group: "interactive".into(),
        config: format!("adaptive ({target:.0} ms), orbiting"),
        ms: median,
        baseline: "full resolution, orbiting".into(),
        ratio: median / full.max(1e-9),
        sample_ratio: None,
        spread: None,
        se: None,
        gpu_ms: None,
        note: format!(
            "median frame {median:.1} ms against the {target:.0} ms it holds; settled at {:.0} % of the pixels per axis (range {:.0}–{:.0} %)",
            scale * 100.0,
            scales[0] * 100.0,
            scales[scales.len() - 1] * 100.0
        ),
        by_process: Vec::new(),
    });
    Ok(())
}
