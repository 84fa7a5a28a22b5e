//! GPU image tests of exploded views: parts moved by their rigid bodies (the data
//! travels with them) and the selection's own region, weighted by the degree of
//! interest, against the CPU reference of the same regions.

use super::*;
use focal::dataset::SceneRegions;
use focal::explode::systems::{spawn_part, volume_polyhedron};
use focal::explode::{Exploded, Part, step};
use focal::region::Plane;
use focal::volume::SelectionVolume;

pub fn an_exploded_head_matches_the_reference(gpu: &mut Gpu) {
    let ct = head();
    let skin = Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone").unwrap());
    gpu.clear();
    // The arteries and the calcifications of the labelled head as the selection, drawn
    // with the vessels' transfer function.
    let labels = phantom::head::generate(64).unwrap().labels;
    use phantom::head::label::{ARTERIES, CALCIFICATIONS};
    let ids = [ARTERIES as u32, CALCIFICATIONS as u32].into_iter().collect();
    let selection = SelectionVolume::from_labels(&labels, &ids).unwrap();
    let exploded = Exploded {
        selection_look: Some(Appearance::new(Mode::Dvr, presets::builtin("ct_vessels").unwrap())),
        ..Exploded::around(&selection)
    };
    let world = gpu.off.world_mut();
    let data = world.spawn((Dataset::new(ct.clone(), skin), Transform::default(), exploded)).id();
    // The box in two halves, left and right, pushed apart.
    let whole = volume_polyhedron(&ct).unwrap();
    let (left, right) = whole.split(Plane { normal: Vec3::X, offset: 0.0 }).unwrap();
    for rest in [left, right] {
        spawn_part(world, Part::new(data, rest), Transform::default());
    }
    let cam = framed(&ct, View::Anterior, true);
    gpu.off.set_camera(&cam);
    let at_rest = gpu.off.capture().unwrap();
    let cpu = |gpu: &mut Gpu| {
        let scene = gpu.off.world_mut().resource::<SceneRegions>().scene.clone();
        render(&scene, &cam, SIZE, SIZE).unwrap().to_image().unwrap()
    };
    assert_matches("exploded_at_rest", &at_rest, &cpu(gpu));
    gpu.off.world_mut().get_mut::<Exploded>(data).unwrap().coefficients.degree = 1.0;
    step(gpu.off.world_mut(), 400);
    let apart = gpu.off.capture().unwrap();
    assert_matches("exploded_apart", &apart, &cpu(gpu));
    // The halves moved off the middle: the middle column now shows the selection (the
    // arteries, red in the vessels' colours) or the background, not the skin it showed.
    let changed = (20..44).filter(|&y| apart.get_pixel(32, y).0[..3] != at_rest.get_pixel(32, y).0[..3]).count();
    assert!(changed > 10, "the middle changed in {changed} of 24 pixels");
    let red = apart.pixels().filter(|p| p[0] > 80 && p[0] as u16 > p[1] as u16 + 40).count();
    assert!(red > 10, "the arteries show: {red} pixels");
    gpu.clear();
}

/// 18 parts (a 3×3×2 grid) exploded: the ray tests them in runs of
/// `render::gpu_types::CLUSTER` (8, 8 and 2, with the selection's region) behind the
/// sphere around each run; every part must still be drawn where the reference draws it.
pub fn eighteen_exploded_parts_match_the_reference(gpu: &mut Gpu) {
    let ct = head();
    let skin = Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone").unwrap());
    gpu.clear();
    let labels = phantom::head::generate(64).unwrap().labels;
    let ids = [phantom::head::label::ARTERIES as u32].into_iter().collect();
    let selection = SelectionVolume::from_labels(&labels, &ids).unwrap();
    let world = gpu.off.world_mut();
    let data = world.spawn((Dataset::new(ct.clone(), skin), Transform::default(), Exploded::around(&selection))).id();
    use focal::explode::spec::{ExplodeSpec, PartsSpec, SelectionSpec};
    let grid = ExplodeSpec { parts: PartsSpec::Grid((3, 3, 2)), ..ExplodeSpec::around(SelectionSpec::Nothing) }.parts(&ct).unwrap();
    assert_eq!(grid.len(), 18);
    for rest in grid {
        spawn_part(world, Part::new(data, rest), Transform::default());
    }
    let cam = framed(&ct, View::Oblique, true);
    gpu.off.set_camera(&cam);
    // (A frame first: the parts get their bodies.)
    gpu.off.capture().unwrap();
    gpu.off.world_mut().get_mut::<Exploded>(data).unwrap().coefficients.degree = 1.0;
    step(gpu.off.world_mut(), 300);
    let apart = gpu.off.capture().unwrap();
    let scene = gpu.off.world_mut().resource::<SceneRegions>().scene.clone();
    assert!(scene.regions.len() >= 19, "{} regions: the parts apart, each its own", scene.regions.len());
    assert_matches("eighteen_parts_apart", &apart, &render(&scene, &cam, SIZE, SIZE).unwrap().to_image().unwrap());
    gpu.clear();
}
