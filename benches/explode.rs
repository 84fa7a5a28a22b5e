//! CPU benchmark of exploded views' physics (run: `cargo bench --profile dev --bench
//! explode`): one step of 64 parts (the forces of equations 1–5 for every part, the
//! viewing force on, then one rapier step), settled at degree 1 first; and at degree 0
//! (the same step without the explosion, viewing and spacing forces). Goal (issue 7):
//! under 1 ms per step.

use std::collections::BTreeSet;
use std::hint::black_box;
use std::sync::Arc;

use bevy::prelude::*;
use criterion::{Criterion, criterion_group, criterion_main};
use focal::FocalCorePlugins;
use focal::dataset::Dataset;
use focal::explode::spec::{ExplodeSpec, LoadedExplode, PartsSpec, SelectionSpec, replace_explosion};
use focal::explode::{Exploded, step};
use focal::region::{Appearance, Mode};
use focal::transfer::presets;
use focal::volume::SelectionVolume;
use focal::volume::phantom::head;

/// A headless app with the head CT (64³) exploded in `grid` parts around its vessels,
/// the viewing force on, settled at `degree`.
fn exploded(grid: (u32, u32, u32), degree: f32) -> Option<App> {
    let phantom = head::generate(64).ok()?;
    let ids: BTreeSet<u32> = [6, 7, 8].into();
    let selection = SelectionVolume::from_labels(&phantom.labels, &ids).ok()?.volume;
    let ct = Arc::new(phantom.ct);
    let spec = ExplodeSpec {
        parts: PartsSpec::Grid(grid),
        degree,
        viewing: true,
        ..ExplodeSpec::around(SelectionSpec::Labels { dataset: 1, ids: vec![6, 7, 8] })
    };
    let loaded = LoadedExplode { exploded: spec.exploded(selection, None), parts: spec.parts(&ct).ok()?, spec };
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, TransformPlugin, FocalCorePlugins));
    let look = Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone").ok()?);
    let e = app.world_mut().spawn((Dataset::new(ct, look), Transform::default())).id();
    app.world_mut().spawn((focal::windows::Viewer, Transform::from_xyz(300.0, 500.0, 200.0)));
    replace_explosion(app.world_mut(), e, Some(&loaded));
    app.update();
    step(app.world_mut(), 240);
    app.world().get::<Exploded>(e)?;
    Some(app)
}

fn physics(c: &mut Criterion) {
    let mut g = c.benchmark_group("explode");
    g.sample_size(20);
    // Degree 0: no explosion, viewing or spacing force, so the step is the return force,
    // rapier and the schedule's fixed cost.
    let configs =
        [("8 parts, one step", (2, 2, 2), 1.0), ("64 parts, one step", (4, 4, 4), 1.0), ("64 parts at degree 0, one step", (4, 4, 4), 0.0)];
    for (name, grid, degree) in configs {
        let Some(mut app) = exploded(grid, degree) else { return };
        g.bench_function(name, |b| b.iter(|| step(black_box(app.world_mut()), 1)));
    }
    g.finish();
}

criterion_group!(benches, physics);
criterion_main!(benches);
