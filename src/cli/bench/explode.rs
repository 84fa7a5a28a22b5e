//! The exploded views group of `focal bench`: the paper's table 1, the frame rate with
//! 1, 2, 4, …, 64 parts, at rest and exploded, against the plain ray caster on the same
//! head CT in the same run.
//!
//! The head is cut into a grid of parts (1×1×1 up to 4×4×4) around its arteries,
//! ventricles and calcifications (the phantom's labels). "At rest" draws the parts in
//! place (the picture of the plain head, plus the selection's region); "exploded" draws
//! them where degree 1 settles them (300 steps of 1/120 s, simulated once per count in a
//! headless app, then placed). Goal (issue 7): at least 80 % of the plain frame rate
//! (ratio ≤ ×1.25) at 64 parts; the paper fell to 30 %.
//!
//! Each row also gives its picture's samples against the plain picture's, counted by
//! the CPU reference: a ray caster that pays per sample cannot draw a picture that needs
//! ×s the samples at more than 100/s % of the plain frame rate, on any hardware.

use std::collections::BTreeSet;
use std::sync::Arc;

use bevy::prelude::*;
use focal::FocalCorePlugins;
use focal::dataset::Dataset;
use focal::explode::spec::{ExplodeSpec, LoadedExplode, PartsSpec, SelectionSpec, replace_explosion};
use focal::explode::{Exploded, step};
use focal::region::{Appearance, Mode};
use focal::render::headless::Offscreen;
use focal::transfer::presets;
use focal::volume::SelectionVolume;
use focal::volume::phantom::head;

use super::harness::{Bench, Row, difference, push_group};

/// The grids of 1, 2, 4, …, 64 parts.
const GRIDS: [(u32, u32, u32); 7] = [(1, 1, 1), (2, 1, 1), (2, 2, 1), (2, 2, 2), (4, 2, 2), (4, 4, 2), (4, 4, 4)];

/// The parts' motions where degree 1 settles them, in the order the spec cuts them.
fn settled(data: &Dataset, loaded: &LoadedExplode) -> Vec<Transform> {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, TransformPlugin, FocalCorePlugins));
    let e = app.world_mut().spawn((data.clone(), Transform::default())).id();
    let parts = replace_explosion(app.world_mut(), e, Some(loaded));
    if let Some(mut x) = app.world_mut().get_mut::<Exploded>(e) {
        x.coefficients.degree = 1.0;
    }
    app.update();
    step(app.world_mut(), 300);
    parts.iter().map(|p| app.world().get::<Transform>(*p).copied().unwrap_or_default()).collect()
}

/// The group; `only`: the part counts to time (all when empty).
pub fn group(bench: &mut Bench, rows: &mut Vec<Row>, resolution: u32, only: &[usize]) -> Result<(), String> {
    let phantom = head::generate(resolution)?;
    let ct = Arc::new(phantom.ct);
    let skin = Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone")?);
    let vessels = Appearance::new(Mode::Dvr, presets::builtin("ct_vessels")?);
    let ids: BTreeSet<u32> = [6, 7, 8].into();
    let selection = SelectionVolume::from_labels(&phantom.labels, &ids)?.volume;
    let data = Dataset::new(ct.clone(), skin.clone());
    // Each count's explosion and its settled motions.
    let mut configs: Vec<(LoadedExplode, Vec<Transform>)> = Vec::new();
    let counted = |g: &(u32, u32, u32)| only.is_empty() || only.contains(&((g.0 * g.1 * g.2) as usize));
    for grid in GRIDS.into_iter().filter(counted) {
        let spec = ExplodeSpec {
            parts: PartsSpec::Grid(grid),
            ..ExplodeSpec::around(SelectionSpec::Labels { dataset: 1, ids: ids.iter().copied().collect() })
        };
        let loaded = LoadedExplode { exploded: spec.exploded(selection.clone(), Some(vessels.clone())), parts: spec.parts(&ct)?, spec };
        let motions = settled(&data, &loaded);
        configs.push((loaded, motions));
    }
    let mut names: Vec<String> = vec!["plain ray caster".into()];
    for (loaded, _) in &configs {
        let n = loaded.parts.len();
        names.push(format!("{n} part{}, at rest", if n == 1 { "" } else { "s" }));
        names.push(format!("{n} part{}, exploded", if n == 1 { "" } else { "s" }));
    }
    let mut set = |off: &mut Offscreen, i: usize| {
        let world = off.world_mut();
        let Some(e) = world.query_filtered::<Entity, With<Dataset>>().iter(world).next() else { return };
        if i == 0 {
            replace_explosion(world, e, None);
            return;
        }
        let (loaded, motions) = &configs[(i - 1) / 2];
        let parts = replace_explosion(world, e, Some(loaded));
        if i.is_multiple_of(2) {
            // (By the spec's order: despawned entities are reused, so entity order
            // shuffled the motions among the parts from the second round on.)
            for (p, m) in parts.into_iter().zip(motions) {
                if let Some(mut t) = world.get_mut::<Transform>(p) {
                    *t = *m;
                }
            }
        }
    };
    let (ms, images) = bench.interleaved_by(ct.clone(), skin.clone(), names.len(), false, &mut set)?;
    let samples = bench.classified_samples(names.len(), &mut set)?;
    bench.save_images("explode", &images)?;
    let last = configs.last().map_or(0, |c| c.0.parts.len());
    let note = format!(
        "{last} parts at rest differ from the plain head by at most {} levels (the selection drawn with its own look)",
        difference(&images[0], &images[images.len().saturating_sub(2)])
    );
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let first = rows.len();
    push_group(rows, bench, "explode", &names, &ms, "head phantom", &note);
    // Each picture's samples against the plain one's: at equal cost per sample, the
    // frame rate cannot exceed 100 % / that ratio.
    for (row, n) in rows[first..].iter_mut().zip(&samples) {
        row.sample_ratio = Some(*n as f64 / samples[0].max(1) as f64);
    }
    Ok(())
}
