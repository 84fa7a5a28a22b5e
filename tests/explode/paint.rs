//! Painting the selection headless: the brush dabs on the first visible point (on a
//! part where it is now, carried back to the data it shows), strokes undo one by one,
//! smoothing, the strokes saved in the spec; the forces follow, the parts do not change.

use std::sync::Arc;

use bevy::prelude::*;
use focal::dataset::Dataset;
use focal::explode::edit::{Edit, Splitter, apply, current_spec};
use focal::explode::paint::Brush;
use focal::explode::spec::ExplodeSource;
use focal::explode::spec::ExplodeSpec;
use focal::explode::splitters::ScreenAxis;
use focal::explode::{Exploded, ExplosionPoints, Part};

use focal::region::Camera;
use focal::volume::Volume;

use super::edit::head_exploded_as;

/// The head CT (64³) exploded around nothing (to paint from scratch); the camera in
/// front.
fn blank_head() -> (App, Entity, Camera) {
    head_exploded_as("(selection: Nothing)")
}

fn selection(app: &App, dataset: Entity) -> Arc<Volume> {
    app.world().get::<Exploded>(dataset).unwrap().selection.clone().unwrap()
}

fn selected(v: &Volume) -> usize {
    (0..v.voxels.len()).filter(|&i| v.voxels.code(i) > 0).count()
}

/// The voxel of the selection nearest to dataset-frame point `p`, and its code.
fn code_at(v: &Volume, p: Vec3) -> u16 {
    let q = v.grid.world_to_index().transform_point3(p).round().as_uvec3().min(v.grid.dims - 1);
    v.code(q.x, q.y, q.z)
}

fn dabs(app: &App, dataset: Entity) -> Vec<Vec3> {
    let spec = &app.world().get::<ExplodeSource>(dataset).unwrap().0;
    spec.paint.iter().flat_map(|s| s.centres().collect::<Vec<_>>()).collect()
}

#[test]
fn the_brush_paints_the_visible_surface_and_strokes_undo_one_by_one() {
    let (mut app, dataset, camera) = blank_head();
    assert_eq!(selected(&selection(&app, dataset)), 0);
    assert!(app.world().get::<ExplosionPoints>(dataset).unwrap().points.is_empty());
    let rests: Vec<_> = app.world_mut().query::<&Part>().iter(app.world()).map(|p| p.rest.clone()).collect();
    let brush = Brush { radius: 12.0, hardness: 0.5, erase: false };
    // A stroke of three dabs across the face.
    for (i, x) in [56.0, 64.0, 72.0].into_iter().enumerate() {
        let ray = camera.ray(x, 64.0, 128, 128);
        apply(app.world_mut(), Edit::Paint { dataset, ray, brush, new_stroke: i == 0 }).unwrap();
    }
    app.update();
    let spec = app.world().get::<ExplodeSource>(dataset).unwrap().0.clone();
    assert_eq!(spec.paint.len(), 1, "one stroke");
    assert_eq!(spec.paint[0].dabs.len(), 3);
    let one = selection(&app, dataset);
    // Each dab sits on the first visible point under its ray: in front of the centre
    // (the camera looks along −y), and the selection is full there.
    for d in dabs(&app, dataset) {
        assert!(d.y > 0.0 && d.y < 120.0, "on the head's front half: {d}");
        assert_eq!(code_at(&one, d), 255);
    }
    // A ball of 12 mm around each, half of it at full strength: about (4/3)π·6³ to
    // (4/3)π·12³ mm³ per dab at 3.75 mm voxels.
    let n = selected(&one);
    assert!(n > 30 && n < 3 * 140, "{n} voxels");
    // The forces follow (explosion points where the selection is), the parts do not.
    let points = &app.world().get::<ExplosionPoints>(dataset).unwrap().points;
    assert!(!points.is_empty(), "explosion points from the painted selection");
    let after: Vec<_> = app.world_mut().query::<&Part>().iter(app.world()).map(|p| p.rest.clone()).collect();
    assert_eq!(rests, after);
    // A second stroke erases the middle dab's core.
    let middle = dabs(&app, dataset)[1];
    let eraser = Brush { radius: 4.0, hardness: 1.0, erase: true };
    apply(app.world_mut(), Edit::Paint { dataset, ray: camera.ray(64.0, 64.0, 128, 128), brush: eraser, new_stroke: true }).unwrap();
    let two = selection(&app, dataset);
    assert!(selected(&two) < n);
    assert_eq!(code_at(&two, middle), 0);
    // Undo: the first stroke's selection again, voxel for voxel; then nothing.
    apply(app.world_mut(), Edit::UndoStroke { dataset }).unwrap();
    assert_eq!(selection(&app, dataset).voxels, one.voxels);
    apply(app.world_mut(), Edit::UndoStroke { dataset }).unwrap();
    assert_eq!(selected(&selection(&app, dataset)), 0);
    assert!(apply(app.world_mut(), Edit::UndoStroke { dataset }).unwrap_err().contains("no stroke"));
    // The brush over empty space says so and changes nothing.
    let miss = apply(app.world_mut(), Edit::Paint { dataset, ray: camera.ray(1.0, 1.0, 128, 128), brush, new_stroke: true });
    assert!(miss.unwrap_err().contains("nothing visible"));
}

#[test]
fn strokes_are_saved_smoothing_replays_them_and_moved_parts_paint_their_data() {
    let (mut app, dataset, camera) = blank_head();
    // Split the head into left and right halves and push the left one 50 mm to −x.
    let centre_ray = camera.ray(64.0, 64.0, 128, 128);
    apply(app.world_mut(), Edit::Split { dataset, splitter: Splitter::Axis { camera, ray: centre_ray, axis: ScreenAxis::Vertical } })
        .unwrap();
    let shift = Vec3::new(-50.0, 0.0, 0.0);
    let parts: Vec<(Entity, Part)> = app.world_mut().query::<(Entity, &Part)>().iter(app.world()).map(|(e, p)| (e, p.clone())).collect();
    let left = parts.iter().find(|(_, p)| p.rest.centroid().x < 0.0).unwrap().0;
    app.world_mut().get_mut::<Transform>(left).unwrap().translation = shift;
    app.update();
    // Painting the pushed half where it shows now: the dab lands on its data, 50 mm
    // towards +x from the point hit. A ray through x < −60 mm at y = 60 mm crosses the
    // box only where the pushed half is (x < −50 mm).
    let brush = Brush { radius: 10.0, hardness: 0.8, erase: false };
    let ray = (0..128)
        .map(|px| camera.ray(px as f32, 64.0, 128, 128))
        .find(|r| {
            let p = r.at((r.origin.y - 60.0) / -r.dir.y);
            p.x < -60.0 && p.x > -150.0
        })
        .unwrap();
    apply(app.world_mut(), Edit::Paint { dataset, ray, brush, new_stroke: true }).unwrap();
    let d = dabs(&app, dataset)[0];
    let hit = focal::reference::pick(&app.world().resource::<focal::dataset::SceneRegions>().scene, ray).unwrap().unwrap().position;
    assert!((d - (hit - shift)).length() < 1.0, "the dab at {d}, the hit at {hit}: the data under it is 50 mm to the right");
    // Saved: the spec lists the stroke; loading it gives the same selection.
    app.update();
    let saved = current_spec(app.world_mut(), dataset).unwrap();
    assert_eq!(saved.paint.len(), 1);
    let text = ron::to_string(&saved).unwrap();
    let reloaded: ExplodeSpec = ron::from_str(&text).unwrap();
    let data = app.world().get::<Dataset>(dataset).unwrap().volume.clone();
    let again = reloaded.selection(&data, |_| None).unwrap();
    let now = selection(&app, dataset);
    assert_eq!(again.voxels, now.voxels);
    // Smoothing smooths the base (here empty) and replays the strokes over it; the
    // setting is kept.
    apply(app.world_mut(), Edit::Smooth { dataset, passes: 2 }).unwrap();
    assert_eq!(selection(&app, dataset).voxels, now.voxels, "an empty base smooths to itself; the strokes come after");
    assert_eq!(app.world().get::<ExplodeSource>(dataset).unwrap().0.smooth, 2);
}

#[test]
fn smoothing_softens_a_binary_selection() {
    let (mut app, dataset, _) = head_exploded_as("(selection: Range(lo: 300.0, hi: 4000.0))");
    let binary = selection(&app, dataset);
    let soft = |v: &Volume| (0..v.voxels.len()).filter(|&i| (1..255).contains(&v.voxels.code(i))).count();
    assert_eq!(soft(&binary), 0);
    apply(app.world_mut(), Edit::Smooth { dataset, passes: 2 }).unwrap();
    let smooth = selection(&app, dataset);
    assert!(soft(&smooth) > selected(&binary) / 4, "soft edges: {} of {}", soft(&smooth), selected(&binary));
    assert!(selected(&smooth) > selected(&binary));
    // Back to 0 passes: the binary mask again.
    apply(app.world_mut(), Edit::Smooth { dataset, passes: 0 }).unwrap();
    assert_eq!(selection(&app, dataset).voxels, binary.voxels);
}
