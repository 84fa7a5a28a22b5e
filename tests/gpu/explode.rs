//! GPU image tests of exploded views: parts moved by their rigid bodies (the data
//! travels with them) and the selection's own region, weighted by the degree of
//! interest, against the CPU reference of the same regions.

use super::*;
use focal::dataset::SceneRegions;
use focal::explode::systems::{spawn_part, volume_polyhedron};
use focal::explode::{Exploded, Part, step};
use focal::region::Plane;
use focal::render::gpu_types::features::UNIFORM_REGIONS;
use focal::volume::SelectionVolume;

/// The selection on the data's grid: its degree of interest rides in the second channel
/// of the data's texels (`render::pack::doi_channels`).
pub fn an_exploded_head_matches_the_reference(gpu: &mut Gpu) {
    exploded_halves(gpu, true);
}

/// The selection on a grid of its own (the data's shifted by half a voxel): the weights
/// sample it in its own box of the atlas.
pub fn a_selection_on_its_own_grid_matches_the_reference(gpu: &mut Gpu) {
    exploded_halves(gpu, false);
}

/// The head in two halves, at rest and pushed apart, against the reference; `carried`:
/// the selection on the data's grid, so that the packed scene carries its degree of
/// interest with the data (else on a grid shifted by half a voxel).
fn exploded_halves(gpu: &mut Gpu, carried: bool) {
    let ct = head();
    let skin = Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone").unwrap());
    gpu.clear();
    // The arteries and the calcifications of the labelled head as the selection, drawn
    // with the vessels' transfer function.
    let labels = phantom::head::generate(64).unwrap().labels;
    use phantom::head::label::{ARTERIES, CALCIFICATIONS};
    let ids = [ARTERIES as u32, CALCIFICATIONS as u32].into_iter().collect();
    let mut selection = SelectionVolume::from_labels(&labels, &ids).unwrap();
    if !carried {
        let mut grid = selection.volume.grid.clone();
        grid.origin += grid.spacing * 0.5;
        let codes = (0..selection.volume.voxels.len()).map(|i| selection.volume.voxels.code(i) as u8).collect();
        selection = SelectionVolume::from_codes(grid, codes).unwrap();
    }
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
    let scene = gpu.off.world_mut().resource::<SceneRegions>().scene.clone();
    let features = focal::render::pack::pack(&scene, 2048).unwrap().features;
    use focal::render::gpu_types::features::{COMPANION, DOI_CHANNEL};
    assert_eq!(features & DOI_CHANNEL != 0, carried);
    // At rest the selection is drawn in the parts' samples (render::pack::companions).
    assert_eq!(features & COMPANION != 0, carried);
    assert_matches(&format!("exploded_at_rest_{carried}"), &at_rest, &cpu(gpu));
    // The head's look modulated by the gradient (its opacity lowered where the data is
    // flat): the selection's look in its samples lies behind the head's opacity as
    // modulated, as the reference composites it.
    let look = gpu.off.world_mut().get::<Dataset>(data).unwrap().appearance.clone();
    gpu.off.world_mut().get_mut::<Dataset>(data).unwrap().appearance = Appearance { mode: Mode::GradientDvr, ..look.clone() };
    let modulated = gpu.off.capture().unwrap();
    let scene = gpu.off.world_mut().resource::<SceneRegions>().scene.clone();
    assert_eq!(focal::render::pack::pack(&scene, 2048).unwrap().features & COMPANION != 0, carried);
    assert_matches(&format!("exploded_at_rest_modulated_{carried}"), &modulated, &cpu(gpu));
    gpu.off.world_mut().get_mut::<Dataset>(data).unwrap().appearance = look;
    // At rest with the head nearly transparent and the selection drawn by a grey ramp:
    // the selection, drawn in the parts' samples, shows through the head.
    let skin = gpu.off.world_mut().get::<Dataset>(data).unwrap().appearance.clone();
    gpu.off.world_mut().get_mut::<Dataset>(data).unwrap().appearance = skin.clone().with_opacity_scaled(0.02);
    let vessels = gpu.off.world_mut().get::<Exploded>(data).unwrap().selection_look.clone();
    let white = Appearance::new(Mode::Dvr, presets::builtin("grayscale_ramp").unwrap());
    gpu.off.world_mut().get_mut::<Exploded>(data).unwrap().selection_look = Some(white);
    let through = gpu.off.capture().unwrap();
    assert_matches(&format!("exploded_see_through_{carried}"), &through, &cpu(gpu));
    // (Without the selection's region the reference differs in more pixels than
    // assert_matches lets pass, so a selection left out of the parts' samples fails it.)
    let mut without = gpu.off.world_mut().resource::<SceneRegions>().scene.clone();
    without
        .regions
        .retain(|r| without.appearances[r.appearance].selection.as_ref().is_none_or(|w| w.keep != focal::region::Keep::Selected));
    let bare = render(&without, &cam, SIZE, SIZE).unwrap().to_image().unwrap();
    let shown = through.pixels().zip(bare.pixels()).filter(|(p, q)| (0..3).any(|c| p[c].abs_diff(q[c]) > 6)).count();
    assert!(shown > 41, "the selection shows through the head: {shown} pixels");
    // The same under a magnifier whose border compresses (anti-aliased from the mip
    // levels): the selection is drawn only inside its own region there too.
    let lenses = [focal::lens::Lens::magnifier(Vec2::new(0.05, -0.05), 0.3, 0.25, 2.5)];
    focal::lens::systems::replace_lenses(gpu.off.world_mut(), &lenses);
    let lensed = gpu.off.capture().unwrap();
    let scene = gpu.off.world_mut().resource::<SceneRegions>().scene.clone();
    let cpu_lensed = focal::reference::render_lensed(&scene, &cam, &lenses, SIZE, SIZE).unwrap().to_image().unwrap();
    assert_matches(&format!("exploded_see_through_lensed_{carried}"), &lensed, &cpu_lensed);
    focal::lens::systems::replace_lenses(gpu.off.world_mut(), &[]);
    gpu.off.world_mut().get_mut::<Dataset>(data).unwrap().appearance = skin;
    gpu.off.world_mut().get_mut::<Exploded>(data).unwrap().selection_look = vessels;
    gpu.off.world_mut().get_mut::<Exploded>(data).unwrap().coefficients.degree = 1.0;
    step(gpu.off.world_mut(), 400);
    let apart = gpu.off.capture().unwrap();
    assert_matches(&format!("exploded_apart_{carried}"), &apart, &cpu(gpu));
    // The halves moved off the middle: the middle column now shows the selection (the
    // arteries, red in the vessels' colours) or the background, not the skin it showed.
    let changed = (20..44).filter(|&y| apart.get_pixel(32, y).0[..3] != at_rest.get_pixel(32, y).0[..3]).count();
    assert!(changed > 10, "the middle changed in {changed} of 24 pixels");
    let red = apart.pixels().filter(|p| p[0] > 80 && p[0] as u16 > p[1] as u16 + 40).count();
    assert!(red > 10, "the arteries show: {red} pixels");
    gpu.clear();
}

/// The head with `look`, exploded around the arteries into 18 parts (a 3×3×2 grid) at
/// rest and framed obliquely: the dataset and the camera.
fn eighteen_parts(gpu: &mut Gpu, look: Appearance) -> (Entity, FocalCamera) {
    grid_parts(gpu, look, (3, 3, 2))
}

/// The head with `look`, exploded around the arteries into a grid of `cells` parts at
/// rest and framed obliquely: the dataset and the camera.
fn grid_parts(gpu: &mut Gpu, look: Appearance, cells: (u32, u32, u32)) -> (Entity, FocalCamera) {
    let ct = head();
    gpu.clear();
    let labels = phantom::head::generate(64).unwrap().labels;
    let ids = [phantom::head::label::ARTERIES as u32].into_iter().collect();
    let selection = SelectionVolume::from_labels(&labels, &ids).unwrap();
    let world = gpu.off.world_mut();
    let data = world.spawn((Dataset::new(ct.clone(), look), Transform::default(), Exploded::around(&selection))).id();
    use focal::explode::spec::{ExplodeSpec, PartsSpec, SelectionSpec};
    let grid = ExplodeSpec { parts: PartsSpec::Grid(cells), ..ExplodeSpec::around(SelectionSpec::Nothing) }.parts(&ct).unwrap();
    assert_eq!(grid.len() as u32, cells.0 * cells.1 * cells.2);
    for rest in grid {
        spawn_part(world, Part::new(data, rest), Transform::default());
    }
    let cam = framed(&ct, View::Oblique, true);
    gpu.off.set_camera(&cam);
    (data, cam)
}

/// The picture now against the reference of the same regions (at least `regions`).
fn matches_its_reference(gpu: &mut Gpu, name: &str, cam: &FocalCamera, regions: usize) {
    let img = gpu.off.capture().unwrap();
    let scene = gpu.off.world_mut().resource::<SceneRegions>().scene.clone();
    assert!(scene.regions.len() >= regions, "{name}: {} regions, not {regions}", scene.regions.len());
    assert_matches(name, &img, &render(&scene, cam, SIZE, SIZE).unwrap().to_image().unwrap());
}

/// Pushes the parts of `data` apart (degree 1, 300 steps).
fn push_apart(gpu: &mut Gpu, data: Entity) {
    gpu.off.world_mut().get_mut::<Exploded>(data).unwrap().coefficients.degree = 1.0;
    step(gpu.off.world_mut(), 300);
}

/// 18 parts (a 3×3×2 grid) exploded: the ray tests them in runs of
/// `render::gpu_types::CLUSTER` (8, 8 and 2, with the selection's region) behind the
/// sphere around each run; every part must still be drawn where the reference draws it.
pub fn eighteen_exploded_parts_match_the_reference(gpu: &mut Gpu) {
    let (data, cam) = eighteen_parts(gpu, Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone").unwrap()));
    // (A frame first: the parts get their bodies.)
    gpu.off.capture().unwrap();
    push_apart(gpu, data);
    matches_its_reference(gpu, "eighteen_parts_apart", &cam, 19);
    assert_ne!(packed_features(gpu) & UNIFORM_REGIONS, 0, "the region records in their uniform copy");
    gpu.clear();
}

fn packed_features(gpu: &mut Gpu) -> u32 {
    let scene = gpu.off.world_mut().resource::<SceneRegions>().scene.clone();
    focal::render::pack::pack(&scene, 2048).unwrap().features
}

/// 150 parts (a 6×5×5 grid) exploded: more region records than their uniform copy holds
/// (`render::gpu_types::MAX_UNIFORM_REGIONS`), so the shader reads them from storage
/// (the planes and the occupancy bits still from theirs); every part is drawn where the
/// reference draws it.
pub fn a_hundred_and_fifty_exploded_parts_match_the_reference(gpu: &mut Gpu) {
    let (data, cam) = grid_parts(gpu, Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone").unwrap()), (6, 5, 5));
    gpu.off.capture().unwrap();
    push_apart(gpu, data);
    matches_its_reference(gpu, "a_hundred_and_fifty_parts_apart", &cam, 151);
    assert_eq!(packed_features(gpu) & UNIFORM_REGIONS, 0, "the region records in storage");
    gpu.clear();
}

/// A MIP of an exploded view is one maximum along the whole ray (not each part's maximum
/// composited over the next): the 18 parts, at rest and pushed apart, against the
/// reference. (Parts that move alike draw as one region; pushed apart each is its own.)
pub fn a_mip_of_exploded_parts_is_one_maximum_along_the_ray(gpu: &mut Gpu) {
    let (data, cam) = eighteen_parts(gpu, Appearance::new(Mode::Mip, presets::builtin("grayscale_ramp").unwrap()));
    matches_its_reference(gpu, "mip_parts_at_rest", &cam, 1);
    push_apart(gpu, data);
    matches_its_reference(gpu, "mip_parts_apart", &cam, 18);
    gpu.clear();
}
