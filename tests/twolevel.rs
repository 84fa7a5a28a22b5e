//! Two-level volume rendering on the CPU reference (`focal::twolevel`), against values
//! worked out by hand: a MIP object emits one value per segment (two segments: two
//! samples composited), segments composite front to back with the rest, a segmentation
//! whose parts all draw alike is plain DVR, hidden objects are holes (their samples do
//! not fall to the rest), value ranges move samples between objects, iso objects are
//! opaque at their first crossing. Scene files name labels by pattern and report typos.

use std::path::Path;
use std::sync::Arc;

use focal::reference::{DEPTH_THRESHOLD, RenderScene, prepare, trace};
use focal::region::{Appearance, Light, Mode, Ray};
use focal::region::{Object, Segmentation};
use focal::transfer::{ColorPoint, OpacityPoint, TransferFunction, ValueSpace};
use focal::volume::{Grid, Source, ValueMap, Volume, Voxels};
use glam::{UVec3, Vec3};

const N: u32 = 32;

/// Data and labels on one 32³ grid centred on the origin:
/// label 1, a ball of radius 7.5 at x = −8 holding a ball of value 150 (radius 5);
/// label 2, a cube of half-size 7 at x = +8 holding a cube of value 100 (half-size 5,
/// with a 2³ core of 220 at its centre), cut at z ∈ [−4, −2] by label 3; label 0, a
/// plate (60) at z ∈ [−13, −11] behind everything seen from +z, and empty space (0).
/// The labels reach 2 voxels beyond the data, so no sample of label 0 interpolates a
/// non-zero value of the ball or the cube: every number below is exact.
fn phantom() -> (Arc<Volume>, Arc<Volume>) {
    let c = (N as f32 - 1.0) * 0.5;
    let (mut data, mut labels) = (Vec::new(), Vec::new());
    for i in 0..N * N * N {
        let p = Vec3::new((i % N) as f32, (i / N % N) as f32, (i / (N * N)) as f32) - Vec3::splat(c);
        let cube = p - Vec3::new(8.0, 0.0, 0.0);
        let ball = (p - Vec3::new(-8.0, 0.0, 0.0)).length();
        let (v, l) = if ball < 7.5 {
            (if ball < 5.0 { 150 } else { 0 }, 1)
        } else if cube.abs().max_element() < 7.0 {
            let v = match cube.abs().max_element() {
                d if d < 1.0 => 220,
                d if d < 5.0 => 100,
                _ => 0,
            };
            (v, if (-4.0..=-2.0).contains(&p.z) { 3 } else { 2 })
        } else if (-13.0..=-11.0).contains(&p.z) {
            (60, 0)
        } else {
            (0, 0)
        };
        data.push(v);
        labels.push(l);
    }
    let grid = Grid::centered(UVec3::splat(N), Vec3::ONE);
    let volume = |name: &str, codes: Vec<u8>| {
        Arc::new(Volume::new(name, grid.clone(), Voxels::U8(codes), ValueMap::IDENTITY, Source::default()).unwrap())
    };
    (volume("data", data), volume("labels", labels))
}

/// White, opacity = value / 255.
fn ramp() -> TransferFunction {
    TransferFunction {
        name: "ramp".into(),
        space: ValueSpace::Absolute,
        units: None,
        color: vec![ColorPoint(0.0, [1.0, 1.0, 1.0])],
        opacity: vec![OpacityPoint(0.0, 0.0), OpacityPoint(255.0, 1.0)],
        lambda_t: vec![],
        lambda_s: vec![],
    }
}

fn unshaded(mode: Mode) -> Appearance {
    let mut a = Appearance::new(mode, ramp());
    a.shading.enabled = false;
    a
}

fn object(name: &str, labels: Vec<u32>, mode: Mode) -> Object {
    Object::new(name, labels, unshaded(mode))
}

fn scene(data: &Arc<Volume>, rest: Appearance, seg: Option<Segmentation>) -> RenderScene {
    RenderScene::single(data.clone(), Appearance { segmentation: seg, ..rest })
}

/// Colour and opacity of the ray along −z through (x, y).
fn pixel(scene: &RenderScene, x: f32, y: f32) -> glam::Vec4 {
    let regions = prepare(scene).unwrap();
    let ray = Ray { origin: Vec3::new(x, y, 60.0), dir: -Vec3::Z };
    trace::trace(&regions, Light::Headlight, ray, 0.5, DEPTH_THRESHOLD, false).color
}

fn close(a: f32, b: f32, tol: f32) -> bool {
    (a - b).abs() <= tol
}

#[test]
fn a_mip_object_emits_one_value_per_segment() {
    let (data, labels) = phantom();
    let mut hidden_slab = object("slab", vec![3], Mode::Dvr);
    hidden_slab.visible = false;
    let seg = Segmentation {
        table: None,
        labels,
        objects: vec![object("cube", vec![2], Mode::Mip), hidden_slab],
        rest_visible: false,
        own_values: false,
    };
    let s = scene(&data, unshaded(Mode::Dvr), Some(seg));
    // Off the core: the slab splits the cube into two segments of max 100 each, so two
    // samples of opacity 100/255 composite: 1 − (1 − a)², not one max (a).
    let a = 100.0 / 255.0;
    let side = pixel(&s, 8.0, 3.0);
    assert!(close(side.w, 1.0 - (1.0 - a) * (1.0 - a), 1e-4), "two segments: {} vs {}", side.w, 1.0 - (1.0 - a) * (1.0 - a));
    // Through the core: the front segment's max is the core's 220.
    let core = pixel(&s, 8.0, 0.0);
    let expect = 1.0 - (1.0 - 220.0 / 255.0) * (1.0 - a);
    assert!(close(core.w, expect, 1e-4), "core: {} vs {expect}", core.w);
    // White colour, premultiplied.
    assert!(close(core.x, core.w, 1e-5));
    // Nothing else draws: the ball is in no object and the rest is hidden.
    assert_eq!(pixel(&s, -8.0, 0.0).w, 0.0);
}

#[test]
fn segments_composite_front_to_back_with_the_rest() {
    let (data, labels) = phantom();
    let seg =
        Segmentation { table: None, labels, objects: vec![object("cube", vec![2, 3], Mode::Mip)], rest_visible: true, own_values: false };
    let s = scene(&data, unshaded(Mode::Dvr), Some(seg));
    // The plate alone (rest, DVR) seen where nothing is in front of it.
    let plate = pixel(&s, 0.0, 10.0).w;
    assert!(plate > 0.3, "the plate should show: {plate}");
    // Through the cube (one object, one segment: max 100) and then the plate behind.
    let a = 100.0 / 255.0;
    let both = pixel(&s, 8.0, 3.0).w;
    let expect = a + (1.0 - a) * plate;
    assert!(close(both, expect, 1e-3), "MIP over the plate: {both} vs {expect}");
}

#[test]
fn parts_that_all_draw_alike_are_plain_dvr() {
    let (data, labels) = phantom();
    let a = Appearance::new(Mode::Dvr, ramp());
    let plain = scene(&data, a.clone(), None);
    let objects = vec![Object::new("ball", vec![1], a.clone()), Object::new("cube", vec![2, 3], a.clone())];
    let seg = scene(&data, a.clone(), Some(Segmentation { table: None, labels, objects, rest_visible: true, own_values: false }));
    for (x, y) in [(-8.0, 0.0), (8.0, 0.0), (8.0, 3.0), (0.0, 10.0), (-6.0, 2.5), (3.0, -4.0)] {
        let (p, q) = (pixel(&plain, x, y), pixel(&seg, x, y));
        assert!((p - q).abs().max_element() < 1e-6, "({x}, {y}): plain {p} vs segmented {q}");
    }
}

#[test]
fn a_hidden_object_is_a_hole_not_the_rest() {
    let (data, labels) = phantom();
    let rest = unshaded(Mode::Dvr);
    let shown = scene(&data, rest.clone(), None);
    let mut ball = object("ball", vec![1], Mode::Dvr);
    ball.visible = false;
    let hidden = scene(&data, rest, Some(Segmentation { table: None, labels, objects: vec![ball], rest_visible: true, own_values: false }));
    let plate = pixel(&shown, 0.0, 10.0).w;
    let (with, without) = (pixel(&shown, -8.0, 0.0).w, pixel(&hidden, -8.0, 0.0).w);
    println!("ball shown {with}, hidden {without}, plate alone {plate}");
    assert!(with > 0.99, "the ball is opaque under the ramp: {with}");
    // Hidden: only the plate behind shows.
    assert!(close(without, plate, 1e-5), "hidden ball: {without} vs the plate alone {plate}");
}

#[test]
fn value_ranges_move_samples_between_objects() {
    let (data, labels) = phantom();
    let bright = |range: (f64, f64)| {
        let mut o = object("plate", vec![0], Mode::Mip);
        o.values = Some(range);
        let seg = Segmentation { table: None, labels: labels.clone(), objects: vec![o], rest_visible: false, own_values: false };
        pixel(&scene(&data, unshaded(Mode::Dvr), Some(seg)), 0.0, 10.0).w
    };
    // The plate's samples (60) are in the object: its MIP is 60/255.
    assert!(close(bright((50.0, 70.0)), 60.0 / 255.0, 1e-4));
    // Out of range they go to the rest, which is hidden.
    assert_eq!(bright((200.0, 255.0)), 0.0);
}

#[test]
fn an_iso_object_is_opaque_at_its_first_crossing() {
    let (data, labels) = phantom();
    let mut ball = object("ball", vec![1], Mode::Iso);
    ball.appearance.iso_value = 75.0;
    let seg = Segmentation { table: None, labels, objects: vec![ball], rest_visible: false, own_values: false };
    let s = scene(&data, unshaded(Mode::Dvr), Some(seg));
    let hit = pixel(&s, -8.0, 0.0);
    assert!(close(hit.w, 1.0, 1e-6), "{hit}");
    // Unshaded: the ramp's white.
    assert!(close(hit.x, 1.0, 1e-6));
    // Where the ray meets no ball there is nothing (the plate is the hidden rest).
    assert_eq!(pixel(&s, 0.0, 10.0).w, 0.0);
    // The depth is the ball's front surface (value 75 is half-way up its edge at z ≈ 5).
    let regions = prepare(&s).unwrap();
    let t =
        trace::trace(&regions, Light::Headlight, Ray { origin: Vec3::new(-8.0, 0.0, 60.0), dir: -Vec3::Z }, 0.5, DEPTH_THRESHOLD, false);
    assert!(close(60.0 - t.depth, 5.0, 0.6), "surface at z = {}", 60.0 - t.depth);
    // An iso-value every sample of the object reaches: the surface is the label's
    // boundary, where the segment starts. On this ray the last voxel of the ball (radius
    // 7.5 around (−8, 0, 0)) is the one centred at z = 6.5 (√(0.5 + 6.5²) < 7.5 <
    // √(0.5 + 7.5²)); its cell ends at z = 7, and the first sample inside lies at most
    // one step (0.5) below.
    let mut s = s;
    s.appearances[0].segmentation.as_mut().unwrap().objects[0].appearance.iso_value = 0.0;
    let regions = prepare(&s).unwrap();
    let t =
        trace::trace(&regions, Light::Headlight, Ray { origin: Vec3::new(-8.0, 0.0, 60.0), dir: -Vec3::Z }, 0.5, DEPTH_THRESHOLD, false);
    let z = 60.0 - t.depth;
    assert!(z > 6.5 - 1e-4 && z <= 7.0 + 1e-4, "boundary surface at z = {z}");
    assert!(close(t.color.w, 1.0, 1e-6));
}

#[test]
fn scene_files_name_labels_and_report_typos() {
    use focal::scene::file::SceneFile;
    use focal::scene::load_datasets;
    let text = |names: &str| {
        format!(
            r#"(datasets: [
                (source: File("../shared/data/mri/ch2.nii.gz"),
                 appearance: (mode: dvr, segmentation: Some((labels: 1, objects: [
                    (name: "hippocampus", names: [{names}], appearance: (mode: dvr)),
                    (name: "scalp", labels: [0], values: Some((125.0, 255.0)), appearance: (mode: mip)),
                 ])))),
                (source: File("../shared/data/labels/aal.nii.gz"), appearance: (labels: Some(())), visible: false),
            ])"#
        )
    };
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = SceneFile::parse(&text(r#""Hippocampus_*""#), "t").unwrap();
    let d = load_datasets(&scene, root).unwrap();
    let seg = d[0].appearance.segmentation.as_ref().unwrap();
    // AAL numbers the left and right hippocampus 37 and 38.
    assert_eq!(seg.objects[0].labels, vec![37, 38]);
    assert_eq!(seg.objects[1].values, Some((125.0, 255.0)));
    assert!(std::sync::Arc::ptr_eq(&seg.labels, &d[1].volume));
    let typo = SceneFile::parse(&text(r#""Hipocampus_*""#), "t").unwrap();
    let e = load_datasets(&typo, root).unwrap_err();
    assert!(e.contains("dataset 0") && e.contains("'hippocampus'") && e.contains("Hipocampus_*"), "{e}");
    let bad_index = SceneFile::parse(&text(r#""Hippocampus_*""#).replace("labels: 1,", "labels: 7,"), "t").unwrap();
    assert!(load_datasets(&bad_index, root).unwrap_err().contains("labels refers to dataset 7"));
}

#[test]
fn picking_names_the_label_of_a_segmented_volume() {
    let (data, labels) = phantom();
    let ball = object("ball", vec![1], Mode::Dvr);
    let seg = Segmentation { table: None, labels, objects: vec![ball], rest_visible: true, own_values: false };
    // The rest opaque from value 55: the plate stops a pick.
    let mut opaque = ramp();
    opaque.opacity = vec![OpacityPoint(0.0, 0.0), OpacityPoint(50.0, 0.0), OpacityPoint(55.0, 1.0)];
    let mut s = scene(&data, Appearance::new(Mode::Dvr, opaque), Some(seg));
    let ray = Ray { origin: Vec3::new(-8.0, 0.0, 60.0), dir: -Vec3::Z };
    let hit = focal::reference::pick(&s, ray).unwrap().unwrap();
    assert_eq!(focal::reference::label_at(&s, &hit), Some(1));
    // Hidden, the ball lets the pick through to the plate (label 0, the rest).
    s.appearances[0].segmentation.as_mut().unwrap().objects[0].visible = false;
    let hit = focal::reference::pick(&s, ray).unwrap().unwrap();
    assert_eq!(focal::reference::label_at(&s, &hit), Some(0));
    assert!(hit.position.z < -10.0, "{}", hit.position);
}

#[test]
fn segmentations_are_saved_and_load_back() {
    use focal::scene::file::SceneFile;
    use focal::scene::load_datasets;
    use focal::scene::save::{DatasetState, scene_file};
    let original = SceneFile::parse(
        r#"(datasets: [
            (source: Phantom(kind: head, resolution: 32), appearance: (mode: context, segmentation: Some((labels: 1, rest_visible: false, objects: [
                (name: "bone", names: ["skull"], values: Some((300.0, 3000.0)), appearance: (mode: mip, preset: Some("grayscale_ramp"))),
                (name: "vessels", names: ["arteries"], visible: false, appearance: (mode: dvr, preset: Some("ct_vessels"))),
            ])))),
            (source: PhantomLabels(resolution: 32), appearance: (labels: Some(())), visible: false),
        ])"#,
        "t",
    )
    .unwrap();
    let loaded = load_datasets(&original, Path::new(".")).unwrap();
    let states: Vec<DatasetState> = loaded.iter().map(DatasetState::of).collect();
    let cam = focal::region::View::Left.frame(Vec3::ZERO, 20.0, true);
    let saved = scene_file(&states, &cam, [0.0; 3], Light::Headlight, (64, 64), &[], Path::new("."));
    let text = saved.to_ron().unwrap();
    let again = load_datasets(&SceneFile::parse(&text, "saved").unwrap(), Path::new(".")).unwrap();
    let (a, b) = (loaded[0].appearance.segmentation.as_ref().unwrap(), again[0].appearance.segmentation.as_ref().unwrap());
    assert_eq!(a.objects, b.objects, "objects survive saving (names resolved to codes)");
    assert!(!b.rest_visible);
    assert_eq!(b.objects[0].labels, vec![focal::volume::phantom::head::label::SKULL as u32]);
}

#[test]
fn empty_bricks_are_those_where_no_part_draws() {
    let (data, labels) = phantom();
    let a = Appearance::new(Mode::Dvr, ramp());
    let plain = a.brick_occupancy(&data).unwrap();
    let alike = vec![Object::new("ball", vec![1], a.clone()), Object::new("cube", vec![2, 3], a.clone())];
    let segmented = |objects: Vec<Object>, rest_visible: bool| Appearance {
        segmentation: Some(Segmentation { table: None, labels: labels.clone(), objects, rest_visible, own_values: false }),
        ..a.clone()
    };
    let count = |o: &[bool]| o.iter().filter(|b| **b).count();
    // Parts drawn alike: the same bricks as without objects.
    assert_eq!(segmented(alike.clone(), true).brick_occupancy(&data).unwrap(), plain);
    // The rest hidden, the ball hidden too: only bricks with the cube's labels remain.
    let mut hidden = alike.clone();
    hidden[0].visible = false;
    let cube_only = segmented(hidden.clone(), false).brick_occupancy(&data).unwrap();
    let bricks = data.bricks();
    let at = |x: f32, y: f32, z: f32| bricks.index(bricks.brick_at(Vec3::new(x, y, z) + 15.5));
    assert!(cube_only[at(8.0, 0.0, 0.0)] && !cube_only[at(-8.0, 0.0, 0.0)]);
    assert!(count(&cube_only) < count(&plain), "{} vs {}", count(&cube_only), count(&plain));
    // With the rest shown, the ball's bricks stay: their label-0 voxels are the rest,
    // and the rest's transfer function is not zero over the brick's values.
    assert!(segmented(hidden, true).brick_occupancy(&data).unwrap()[at(-8.0, 0.0, 0.0)]);
    // A MIP object looks at every sample: a brick holding its labels is kept even where
    // its transfer function is zero over the brick's values; a DVR object is not.
    let mut high = ramp();
    high.opacity = vec![OpacityPoint(0.0, 0.0), OpacityPoint(250.0, 0.0), OpacityPoint(255.0, 1.0)];
    let with = |mode: Mode| {
        let o = Object::new("cube", vec![2, 3], Appearance::new(mode, high.clone()));
        segmented(vec![o], false).brick_occupancy(&data).unwrap()
    };
    let (mip, dvr) = (with(Mode::Mip), with(Mode::Dvr));
    assert!(mip[at(8.0, 0.0, 0.0)] && !dvr[at(8.0, 0.0, 0.0)]);
    assert_eq!(count(&dvr), 0);
}

/// A ball of 200 (label 1) in a field of 20 (label 0), on one 32³ grid.
fn ball_in_a_field() -> (Arc<Volume>, Arc<Volume>) {
    let c = (N as f32 - 1.0) * 0.5;
    let inside = |i: u32| (Vec3::new((i % N) as f32, (i / N % N) as f32, (i / (N * N)) as f32) - Vec3::splat(c)).length() < 8.0;
    let grid = Grid::centered(UVec3::splat(N), Vec3::ONE);
    let volume = |name: &str, codes: Vec<u8>| {
        Arc::new(Volume::new(name, grid.clone(), Voxels::U8(codes), ValueMap::IDENTITY, Source::default()).unwrap())
    };
    let data = (0..N * N * N).map(|i| if inside(i) { 200 } else { 20 }).collect();
    let labels = (0..N * N * N).map(|i| u8::from(inside(i))).collect();
    (volume("data", data), volume("labels", labels))
}

#[test]
fn no_objects_values_bleed_into_the_rest_beside_it() {
    // The ball hidden, the rest drawn opaque above 100: a value no voxel of the rest has,
    // so nothing may be drawn. Plain trilinear samples of the rest next to the ball mix
    // in its 200s (half a voxel out: 110), the rim two-level rendering must not draw;
    // each part's samples come from its own label's voxels.
    let (data, labels) = ball_in_a_field();
    let above_100 =
        TransferFunction { opacity: vec![OpacityPoint(0.0, 0.0), OpacityPoint(100.0, 0.0), OpacityPoint(101.0, 1.0)], ..ramp() };
    let rest =
        Appearance { shading: focal::region::Shading { enabled: false, ..Default::default() }, ..Appearance::new(Mode::Dvr, above_100) };
    let hidden = Object { visible: false, ..object("ball", vec![1], Mode::Dvr) };
    let seg = Segmentation { labels, table: None, objects: vec![hidden], rest_visible: true, own_values: true };
    let segmented = scene(&data, rest.clone(), Some(seg));
    let plain = scene(&data, rest, None);
    let mut rim = 0.0f32;
    for y in -10..=10 {
        for x in -10..=10 {
            let (x, y) = (x as f32 + 0.25, y as f32 - 0.35);
            rim = rim.max(pixel(&segmented, x, y).w);
        }
    }
    assert!(rim < 1e-6, "the rest draws a rim of opacity {rim} beside the hidden ball");
    // (The look itself draws the ball: the test can tell.)
    assert!(pixel(&plain, 0.25, -0.35).w > 0.5);
}
