//! The streaming system: each frame, for every bricked volume of the scene, the bricks
//! the views want ([`super::select::wanted`]) are asked of its cache (coarse first; the
//! cache loads them on its threads and never blocks the frame), and the renderer is told
//! which resident ones to draw: the wanted bricks and their ancestors that are in memory,
//! those whose codes every look using the volume shows as transparent marked empty.

use std::collections::BTreeSet;

use bevy::prelude::*;
use glam::Affine3A;

use super::bricked::{BrickFrame, BrickedDataset, BrickedScene, StreamBudget, StreamStatus};
use super::select::{Magnified, Seen, ViewFrame, wanted};
use super::unchanged::{Inputs, LastFrames, VolumeCounts, same_looks};
use crate::dataset::{DataBox, Dataset, SceneRegions, VolumeView};
use crate::lens::ViewLenses;
use crate::lens::stack::Effect;
use crate::region::appearance::CodeVisibility;
use crate::region::{Appearance, RenderScene};
use crate::volume::Volume;
use crate::volume::source::cache::{BrickKey, CacheStats};
use std::collections::HashMap;
use std::sync::Arc;

/// Gives each bricked dataset its [`DataBox`]: level 0's box, not its coarse volume's.
pub fn data_boxes(mut commands: Commands, added: Query<(Entity, &BrickedDataset), Changed<BrickedDataset>>) {
    for (e, b) in &added {
        let (lo, hi) = b.index_box();
        commands.entity(e).insert(DataBox { lo, hi });
    }
}

/// The views of volume cameras this frame.
pub fn view_frames(views: &Query<(&ViewLenses, &VolumeView)>) -> Vec<ViewFrame> {
    views
        .iter()
        .filter_map(|(l, _)| {
            let (camera, screen) = (l.camera?, l.screen?);
            let magnifiers = l
                .lenses
                .iter()
                .filter_map(|r| match &r.effect {
                    Effect::Magnifier(m) => {
                        Some(Magnified { center: r.center, reach: r.radius + r.border, magnification: m.magnification })
                    }
                    _ => None,
                })
                .collect();
            Some(ViewFrame { camera, screen, magnifiers })
        })
        .collect()
}

/// The regions of `scene` that show volume `v`, as the selection sees them.
fn seen_by(scene: &RenderScene, v: usize, coarse_index_to_dataset: Affine3A) -> Vec<Seen> {
    let dataset_from_index = coarse_index_to_dataset.inverse();
    scene
        .regions
        .iter()
        .filter(|r| r.volume == v)
        .map(|r| Seen { dataset_to_world: r.world_to_voxel.inverse() * dataset_from_index, planes: r.planes.clone() })
        .collect()
}

/// The visibility tests of each bricked volume's looks, made again only when a look
/// changes (each bakes the look's table).
#[derive(Default)]
pub struct VisibilityTests {
    made: HashMap<usize, (Vec<Appearance>, Option<Tests>)>,
}

/// One test per look of a volume.
type Tests = Arc<Vec<CodeVisibility>>;

impl VisibilityTests {
    /// The tests of `looks` on `volume`; `None` where a look may show any code.
    fn of(&mut self, volume: &Arc<Volume>, looks: &[&Appearance]) -> Option<Tests> {
        let key = Arc::as_ptr(volume) as usize;
        if let Some((_, tests)) = self.made.get(&key).filter(|(made, _)| same_looks(made, looks)) {
            return tests.clone();
        }
        let tests: Option<Vec<CodeVisibility>> = looks.iter().map(|a| a.code_visibility(volume)).collect();
        let tests = tests.map(Arc::new);
        self.made.insert(key, (looks.iter().map(|a| (*a).clone()).collect(), tests.clone()));
        tests
    }

    /// Forgets the volumes no longer in the scene.
    fn keep(&mut self, scene: &RenderScene) {
        self.made.retain(|k, _| scene.volumes.iter().any(|v| Arc::as_ptr(v) as usize == *k));
    }
}

/// Asks for the bricks the views want and publishes what to draw ([`BrickedScene`]);
/// a volume whose views, regions, looks and cache did not change keeps its last frame
/// ([`super::unchanged`]).
#[allow(clippy::too_many_arguments)]
pub fn stream_bricks(
    mut datasets: Query<(&Dataset, &mut BrickedDataset)>,
    regions: Res<SceneRegions>,
    views: Query<(&ViewLenses, &VolumeView)>,
    budget: Res<StreamBudget>,
    status: Res<StreamStatus>,
    mut out: ResMut<BrickedScene>,
    mut visibility: Local<VisibilityTests>,
    mut last: Local<LastFrames>,
) {
    let scene = &regions.scene;
    let frames = view_frames(&views);
    let mut volumes = vec![None; scene.volumes.len()];
    let mut total = VolumeCounts::default();
    let mut count = 0;
    for (v, entity) in regions.datasets.iter().enumerate() {
        let Ok((dataset, mut bricked)) = datasets.get_mut(*entity) else { continue };
        let Some(volume) = scene.volumes.get(v) else { continue };
        count += 1;
        let per_brick = bricked.cache.layout().stored().pow(3) as u64 * (bricked.bits() as u64 / 8);
        let cap = budget.gpu_bricks(bricked.bits()).min((budget.cpu_bytes / per_brick.max(1)) as usize) * 3 / 4;
        let inputs = Inputs {
            volume,
            frames: &frames,
            seen: seen_by(scene, v, volume.grid.world_to_index().inverse()),
            looks: scene.regions.iter().filter(|r| r.volume == v).filter_map(|r| scene.appearances.get(r.appearance)).collect(),
            cap,
        };
        let (frame, counts) = match last.unchanged(*entity, &inputs, &bricked.cache.stats()) {
            Some(kept) => kept,
            None => {
                let (frame, counts, cache) = select_frame(dataset, &mut bricked, &inputs, &mut visibility);
                last.keep(*entity, inputs, cache, frame.clone(), counts);
                (frame, counts)
            }
        };
        total = total.plus(counts);
        volumes[v] = Some(frame);
    }
    visibility.keep(scene);
    last.retain(&regions.datasets);
    status.update(|c| {
        c.bricked = count;
        c.views = frames.len();
        c.wanted = total.wanted;
        c.resident = total.resident;
        c.pending = total.pending;
        c.failed = total.failed;
        c.finest_wanted = total.finest;
    });
    out.volumes = volumes;
}

/// The frame of one bricked volume drawn anew: its wanted bricks asked of its cache, the
/// resident ones (and their resident ancestors) tested against its looks; with its
/// counts and the cache's counters once the bricks were asked for.
fn select_frame(
    dataset: &Dataset,
    bricked: &mut Mut<BrickedDataset>,
    inputs: &Inputs,
    visibility: &mut VisibilityTests,
) -> (BrickFrame, VolumeCounts, CacheStats) {
    let want = wanted(&bricked.levels, bricked.coarse, bricked.cache.layout(), &inputs.seen, inputs.frames, inputs.cap.max(1));
    bricked.cache.request(&want);
    let cache = bricked.cache.stats();
    // The wanted bricks and their ancestors below the coarse level, coarsest first.
    let mut keys: BTreeSet<(std::cmp::Reverse<u8>, BrickKey)> = BTreeSet::new();
    for k in &want {
        let mut a = *k;
        while (a.level as usize) < bricked.coarse && keys.insert((std::cmp::Reverse(a.level), a)) {
            a = a.parent();
        }
    }
    let tests = visibility.of(inputs.volume, &inputs.looks);
    // Only looks that weigh by the gradient magnitude need each level's largest
    // (loads compute it then).
    let magnitudes = inputs.looks.iter().any(|a| a.uses_gradient_magnitude());
    bricked.cache.want_gradients(magnitudes);
    let (mut drawn, mut empty, mut seen_gradients) = (Vec::new(), Vec::new(), Vec::new());
    // The coarse level's bricks (always at hand), then the streamed ones present.
    let coarse = bricked.coarse_bricks.iter().map(|(k, d)| (*k, d.clone()));
    for (k, data) in coarse.chain(keys.into_iter().filter_map(|(_, k)| bricked.cache.get(k).map(|d| (k, d)))) {
        if magnitudes {
            seen_gradients.push((k, data.clone()));
        }
        let shows = |(lo, hi): (u16, u16)| tests.as_ref().is_none_or(|t| t.is_empty() || t.iter().any(|f| f(lo, hi)));
        let mask = if shows(data.range) {
            data.sub_ranges.iter().enumerate().filter(|(_, r)| shows(**r)).fold(0u64, |m, (i, _)| m | 1 << i)
        } else {
            0
        };
        if mask == 0 {
            empty.push((k, data.range.0));
        } else {
            drawn.push((k, data, mask));
        }
    }
    let present: std::collections::HashSet<BrickKey> = drawn.iter().map(|(k, ..)| *k).chain(empty.iter().map(|(k, _)| *k)).collect();
    let resident = want.iter().filter(|k| present.contains(k)).count();
    for (k, e) in bricked.cache.errors() {
        warn!("{e} (brick {:?} of level {} of {}; drawn from a coarser level)", k.brick, k.level, dataset.volume.name);
    }
    for (k, faults) in bricked.cache.faulted() {
        warn!("{faults} (brick {:?} of level {} of {})", k.brick, k.level, dataset.volume.name);
    }
    // (Written only when a level's largest gradient grew: the component's change
    // ticks stay quiet otherwise.)
    if bricked.bypass_change_detection().see_gradients(seen_gradients.iter().map(|(k, d)| (*k, d.as_ref()))) {
        bricked.set_changed();
    }
    let counts = VolumeCounts {
        wanted: want.len(),
        resident,
        pending: cache.pending,
        failed: cache.failed,
        finest: want.iter().map(|k| k.level as usize).min(),
    };
    let frame = BrickFrame {
        table_dims: bricked.table_dims(),
        layout: bricked.cache.layout(),
        coarse: bricked.coarse,
        bits: bricked.bits(),
        complete: resident == want.len(),
        gradient_norms: bricked.gradient_norms(),
        drawn: std::sync::Arc::new(drawn),
        empty: std::sync::Arc::new(empty),
    };
    (frame, counts, cache)
}
