//! GPU image tests of clipping: a moved, clipped dataset against the CPU reference of
//! the same region, and a clip box inside the engine turning MinIP from air-black into
//! the part's own minimum.

use super::*;
use focal::clip::{ClipBox, ClipPlane, Clipping};

pub fn clipping_matches_the_reference(gpu: &mut Gpu) {
    let engine = Arc::new(Phantom::Engine.generate(64).unwrap());
    let a = Appearance::new(Mode::Dvr, presets::builtin("industrial_ct").unwrap());
    let (lo, hi) = engine.grid.world_bounds();
    let centre = (lo + hi) * 0.5;
    // An oblique plane through the centre and a box around part of the block, in the
    // dataset's frame; the dataset turned and moved.
    let clip = Clipping {
        planes: vec![ClipPlane::new(centre, Vec3::new(1.0, 0.3, 0.5))],
        clip_box: Some(ClipBox { min: lo + (hi - lo) * 0.1, max: hi - (hi - lo) * 0.25, enabled: true }),
    };
    let transform = Transform::from_rotation(Quat::from_rotation_z(0.4)).with_translation(Vec3::new(5.0, -3.0, 2.0));
    let cam = framed(&engine, View::Oblique, false);
    let mut dataset = Dataset::new(engine.clone(), a.clone());
    dataset.clip = clip.clone();
    let g = gpu.show_dataset(dataset, transform, &cam);
    let mut scene = RenderScene::single(engine.clone(), a.clone());
    scene.regions[0] = clip.region(&engine.grid, transform.compute_affine(), 0);
    let c = render(&scene, &cam, SIZE, SIZE).unwrap().to_image().unwrap();
    assert_matches("clipped_engine", &g, &c);
    // And clipping removed something: the unclipped picture differs.
    let whole = gpu.show_dataset(Dataset::new(engine, a), transform, &cam);
    let (mean, _, _) = difference(&whole, &g);
    assert!(mean > 2.0, "the clip changed little (mean {mean})");
}

pub fn a_clip_box_inside_the_engine_makes_minip_useful(gpu: &mut Gpu) {
    // Every ray through the block's bounding box also crosses air, so MinIP is black;
    // clipped to a box inside the metal, the minimum is the metal's own (with its bores).
    let engine = Arc::new(Phantom::Engine.generate(64).unwrap());
    let a = Appearance::new(Mode::MinIp, presets::builtin("grayscale_ramp").unwrap());
    let (lo, hi) = engine.grid.world_bounds();
    let cam = framed(&engine, View::Superior, true);
    let black = gpu.show(engine.clone(), a.clone(), &cam);
    let mut dataset = Dataset::new(engine.clone(), a.clone());
    let c = (lo + hi) * 0.5;
    dataset.clip =
        Clipping { planes: vec![], clip_box: Some(ClipBox { min: c - (hi - lo) * 0.1, max: c + (hi - lo) * 0.1, enabled: true }) };
    let boxed = gpu.show_dataset(dataset, Transform::default(), &cam);
    let bright = |img: &image::RgbaImage| img.pixels().filter(|p| p[0] > 30).count();
    println!("    MinIP pixels above 30: whole box {}, clip box {}", bright(&black), bright(&boxed));
    assert!(bright(&boxed) > 20 * (bright(&black) + 1), "the clip box did not lift MinIP off the air");
}

/// Seven looks of one 256³ head, each in a slab of its own (seven clipped datasets):
/// their occupancy bits (three sets of a bit per brick, a run per distinct look) are
/// more than their uniform copy holds (`render::gpu_types::MAX_UNIFORM_OCCUPANCY`), so
/// the empty-space tests read them from storage; the picture is the reference's.
pub fn occupancy_beyond_its_uniform_copy_matches_the_reference(gpu: &mut Gpu) {
    use focal::render::gpu_types::features::UNIFORM_OCCUPANCY;
    gpu.clear();
    let head = Arc::new(Phantom::Head.generate(256).unwrap());
    let (lo, hi) = head.grid.world_bounds();
    let looks = ["ct_skin_bone", "ct_bone", "ct_vessels", "ct_soft_tissue", "grayscale_ramp", "industrial_ct", "mr_default"];
    let mut scene = RenderScene { volumes: vec![head.clone()], ..Default::default() };
    for (i, name) in looks.iter().enumerate() {
        let a = Appearance::new(Mode::Dvr, presets::builtin(name).unwrap());
        let slab = |k: usize| lo.x + (hi.x - lo.x) * k as f32 / looks.len() as f32;
        let clip = Clipping {
            planes: vec![],
            clip_box: Some(ClipBox { min: Vec3::new(slab(i), lo.y, lo.z), max: Vec3::new(slab(i + 1), hi.y, hi.z), enabled: true }),
        };
        let mut dataset = Dataset::new(head.clone(), a.clone());
        dataset.clip = clip.clone();
        gpu.off.world_mut().spawn((dataset, Transform::default()));
        let mut region = clip.region(&head.grid, Transform::default().compute_affine(), 0);
        region.appearance = i;
        scene.regions.push(region);
        scene.appearances.push(a);
    }
    let cam = framed(&head, View::Anterior, false);
    gpu.off.set_camera(&cam);
    let img = gpu.off.capture().unwrap();
    let packed = focal::render::pack::pack(&scene, 2048).unwrap();
    assert_eq!(packed.features & UNIFORM_OCCUPANCY, 0, "{} occupancy words fit their uniform copy", packed.occupancy.len());
    let reference = render(&scene, &cam, SIZE, SIZE).unwrap().to_image().unwrap();
    assert_matches("seven_looks_in_slabs", &img, &reference);
    gpu.clear();
}
