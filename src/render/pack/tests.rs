//! Tests of the packing: region records, clusters, selections' brick kinds, overlaps
//! and the march bound.

use std::sync::Arc;

use glam::Vec3;

use super::*;
use crate::region::{Appearance, Plane, Region};
use crate::transfer::presets;
use crate::volume::phantom;

fn region(voxel_to_world: Mat3, dims: f32, native_step: f32) -> GpuRegion {
    let world_to_voxel = voxel_to_world.inverse();
    GpuRegion {
        world_to_voxel: Mat4::from_mat3(world_to_voxel),
        // Native = world here, so world→native per index is the identity after the
        // world→voxel map: to_native = index_to_native · world_to_voxel.
        to_native: Mat4::from_mat3(voxel_to_world * world_to_voxel),
        dims: Vec4::new(dims, dims, dims, 255.0),
        native_step,
        ..Default::default()
    }
}

#[test]
fn every_run_of_regions_has_a_sphere_around_its_own() {
    // 19 regions: runs 0..8, 8..16, 16..19, each with its sphere in its first record.
    let mut regions: Vec<GpuRegion> = (0..19)
        .map(|i| GpuRegion { bounds: Vec4::new(i as f32 * 10.0, (i % 3) as f32, 0.0, 1.0 + (i % 4) as f32), ..Default::default() })
        .collect();
    set_clusters(&mut regions);
    for (k, run) in regions.chunks(CLUSTER).enumerate() {
        let c = run[0].cluster;
        for r in run {
            let b = r.bounds;
            assert!(b.truncate().distance(c.truncate()) + b.w <= c.w, "run {k}: {b} outside {c}");
        }
    }
    assert_eq!(regions.chunks(CLUSTER).count(), 3);
    // Tight for two spheres on a line: centres 0 and 10, radii 1 and 3 → [−1, 13].
    let s = sphere_around(&[Vec4::new(0.0, 0.0, 0.0, 1.0), Vec4::new(10.0, 0.0, 0.0, 3.0)]);
    assert!((s.truncate() - Vec3::new(6.0, 0.0, 0.0)).length() < 1e-5 && (s.w - 7.0).abs() < 0.01, "{s}");
    // An infinite member (a region without vertices) makes the run infinite.
    assert_eq!(sphere_around(&[Vec4::new(0.0, 0.0, 0.0, f32::MAX), Vec4::ONE]).w, f32::MAX);
    assert_eq!(sphere_around(&[]).w, f32::MAX);
}

#[test]
fn selection_bricks_by_kind() {
    use crate::volume::BrickGrid;
    // Bricks: none selected, all, a mix, one middle code, and a 17th (second word).
    let mut bricks = BrickGrid { size: 8, dims: glam::UVec3::new(17, 1, 1), min: vec![0; 17], max: vec![0; 17] };
    (bricks.min[1], bricks.max[1]) = (255, 255);
    (bricks.min[2], bricks.max[2]) = (0, 255);
    (bricks.min[3], bricks.max[3]) = (10, 10);
    (bricks.min[16], bricks.max[16]) = (0, 3);
    let words = constant_bricks(&bricks, 255);
    assert_eq!(words.len(), 2);
    let kind = |i: usize| (words[i / 16] >> (2 * (i % 16))) & 3;
    assert_eq!((kind(0), kind(1), kind(2), kind(3), kind(4), kind(16)), (0, 1, 2, 2, 0, 2));
}

#[test]
fn march_bound_by_hand() {
    // 32³ unit voxels, half-voxel steps: diagonal √3·32, smallest step bounded below
    // by 0.5/‖I‖_F = 0.5/√3, so 192 samples, + 3 per region + 2.
    let cube = region(Mat3::IDENTITY, 32.0, 0.5);
    assert_eq!(march_bound(&[cube], None), 197);
    // Voxels twice as long in x: diagonal |(64, 32, 32)| = 78.38…, same steps:
    // 78.38·2√3 = 271.5 → 272, + 5.
    let long = region(Mat3::from_diagonal(Vec3::new(2.0, 1.0, 1.0)), 32.0, 0.5);
    assert_eq!(march_bound(&[long], None), 277);
    // Two regions: chords add up, the smaller step counts, 3 per region.
    let fine = region(Mat3::IDENTITY, 32.0, 0.25);
    assert_eq!(march_bound(&[cube, fine], None), 384 + 384 + 8);
    assert_eq!(march_bound(&[], None), 2);
    // Two halves of one box: the chords of a ray through both add up to at most the
    // box's diagonal, 32√3: 192 samples, + 3 per region + 2.
    let diagonal = 32.0 * 3f32.sqrt();
    assert_eq!(march_bound(&[cube, cube], Some(diagonal)), 192 + 6 + 2);
    // The extent only ever lowers the bound.
    assert_eq!(march_bound(&[cube], Some(1e6)), 197);
    // Each hole splits an interval: 3 more.
    let holed = GpuRegion { hole_count: 2, ..cube };
    assert_eq!(march_bound(&[holed], None), 197 + 6);
}

#[test]
fn march_bound_exceeds_the_samples_of_any_ray() {
    // A rotated, anisotropic volume: every ray's chord / step (+1) stays below.
    let m = Mat3::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.7) * Mat3::from_diagonal(Vec3::new(0.5, 1.0, 3.0));
    let r = region(m, 40.0, 0.5);
    let bound = march_bound(&[r], None) as f32;
    let lo = Vec3::splat(-0.5);
    let hi = Vec3::splat(39.5);
    let mut longest = 0.0f32;
    for i in 0..2000 {
        // Directions on a Fibonacci sphere, rays through the volume's centre.
        let z = 1.0 - 2.0 * (i as f32 + 0.5) / 2000.0;
        let a = i as f32 * 2.399_963;
        let dir = Vec3::new((1.0 - z * z).sqrt() * a.cos(), (1.0 - z * z).sqrt() * a.sin(), z);
        let centre = m * Vec3::splat(19.5);
        let (qo, qd) = (m.inverse() * (centre - dir * 1e4), m.inverse() * dir);
        // Slab test in voxel space.
        let (t0, t1) = (0..3).fold((f32::MIN, f32::MAX), |(a, b), k| {
            let (u, v) = ((lo[k] - qo[k]) / qd[k], (hi[k] - qo[k]) / qd[k]);
            (a.max(u.min(v)), b.min(u.max(v)))
        });
        let world_step = r.native_step / (Mat3::from_mat4(r.to_native) * dir).length();
        longest = longest.max((t1 - t0) / world_step + 1.0);
    }
    assert!(longest > 0.5 * bound, "the bound is far too loose: {longest} of {bound}");
    assert!(longest <= bound, "a ray takes {longest} samples, more than the bound {bound}");
}

#[test]
fn overlapping_regions_need_the_multi_region_code_touching_ones_do_not() {
    use super::super::gpu_types::features;
    let v = Arc::new(phantom::sphere(16, 5.0).unwrap());
    let tf = presets::builtin("grayscale_ramp").unwrap();
    let mut scene = RenderScene::single(v.clone(), Appearance::new(Mode::Dvr, tf));
    let whole = Region::volume_box(&v.grid, 0, 0);
    let centre = (v.grid.world_bounds().0 + v.grid.world_bounds().1) * 0.5;
    // Two halves of the volume touch along a plane: no overlap.
    scene.regions =
        vec![whole.clone().clipped(Plane::through(centre, glam::Vec3::X)), whole.clone().clipped(Plane::through(centre, -glam::Vec3::X))];
    let packed = pack(&scene, 2048).unwrap();
    assert_eq!(packed.region_count, 2);
    assert_eq!(packed.features & (features::MULTI_REGION | features::DVR_PAIRS | features::HOLES), 0);
    // The whole volume and one half overlap: two DVR regions, the pair loop.
    scene.regions[0] = whole.clone();
    assert_eq!(pack(&scene, 2048).unwrap().features & (features::MULTI_REGION | features::DVR_PAIRS), features::DVR_PAIRS);
    // A third region over both, or a MIP region in the pair: sample by sample.
    let mut three = scene.clone();
    three.regions.push(whole.clone());
    assert_ne!(pack(&three, 2048).unwrap().features & features::MULTI_REGION, 0);
    let mut mixed = scene.clone();
    mixed.appearances.push(Appearance::new(Mode::Mip, presets::builtin("grayscale_ramp").unwrap()));
    mixed.regions[1].appearance = 1;
    assert_ne!(pack(&mixed, 2048).unwrap().features & features::MULTI_REGION, 0);
    // Unless that half is a hole in the whole (a clip window and its content, here
    // showing other voxels: a window showing the same ones is drawn in place,
    // `insets`).
    scene.regions[1].world_to_voxel = glam::Affine3A::from_translation(glam::Vec3::X) * scene.regions[1].world_to_voxel;
    let (lo, hi) = v.grid.world_bounds();
    let half = crate::region::box_planes(&glam::Affine3A::IDENTITY, glam::Vec3::new(centre.x, lo.y - 1.0, lo.z - 1.0), hi + 1.0);
    scene.regions[0].holes.push(std::array::from_fn(|i| half[i]));
    let packed = pack(&scene, 2048).unwrap();
    assert_eq!(packed.features & (features::MULTI_REGION | features::DVR_PAIRS), 0);
    assert_eq!((packed.regions[0].hole_count, packed.regions[0].hole_offset), (1, 6));
    assert_ne!(packed.features & features::HOLES, 0, "the hole code is compiled in");
    // A hole that holds only part of the common part leaves an overlap.
    let small = crate::region::box_planes(&glam::Affine3A::IDENTITY, centre, hi + 1.0);
    scene.regions[0].holes[0] = std::array::from_fn(|i| small[i]);
    assert_ne!(pack(&scene, 2048).unwrap().features & features::DVR_PAIRS, 0);
}

#[test]
fn a_region_over_the_empty_part_of_a_box_needs_no_overlap_code() {
    use super::super::gpu_types::features;
    // A sphere of radius 6 mm in a 64 mm box at 1 mm: the ramp makes the zeros around
    // it transparent, so only the bricks at the centre are visible.
    let v = Arc::new(phantom::sphere(64, 6.0).unwrap());
    let ramp = presets::builtin("grayscale_ramp").unwrap();
    let mut scene = RenderScene::single(v.clone(), Appearance::new(Mode::Dvr, ramp.clone()));
    let corner = |lo: f32, hi: f32| {
        let planes = crate::region::box_planes(&glam::Affine3A::IDENTITY, glam::Vec3::splat(lo), glam::Vec3::splat(hi));
        Region { planes, ..Region::volume_box(&v.grid, 0, 1) }
    };
    scene.appearances.push(Appearance::new(Mode::Mip, ramp.clone()));
    // A MIP region in a corner of the box, after the dataset: the dataset is
    // transparent there, the sample is the window's.
    scene.regions.push(corner(18.0, 30.0));
    let bits = |s: &RenderScene| pack(s, 2048).unwrap().features & (features::MULTI_REGION | features::DVR_PAIRS);
    assert_eq!(bits(&scene), 0);
    // Over the sphere it needs the general code.
    scene.regions[1] = corner(-4.0, 4.0);
    assert_eq!(bits(&scene), features::MULTI_REGION);
    // Before the dataset in region order, the MIP region would lose its samples to
    // the dataset's transparent ones: it needs the code too.
    scene.regions.swap(0, 1);
    scene.regions[0] = corner(18.0, 30.0);
    assert_eq!(bits(&scene), features::MULTI_REGION);
    // Two DVR regions over the sphere: the pair loop.
    scene.regions = vec![Region::volume_box(&v.grid, 0, 0), Region { appearance: 0, ..corner(-4.0, 4.0) }];
    assert_eq!(bits(&scene), features::DVR_PAIRS);
}

#[test]
fn packs_regions_planes_luts_and_the_atlas() {
    let v = Arc::new(phantom::sphere(16, 5.0).unwrap());
    let tf = presets::builtin("grayscale_ramp").unwrap();
    let mut scene = RenderScene::single(v.clone(), Appearance::new(Mode::Mip, tf.clone()));
    scene.regions.push(Region::volume_box(&v.grid, 0, 0).clipped(Plane::through(glam::Vec3::ZERO, glam::Vec3::X)));
    let packed = pack(&scene, 2048).unwrap();
    assert_eq!(packed.regions.len(), 2);
    assert_eq!(packed.volumes, vec![0]);
    // The volume and its mip levels 8³, 4³, 2³ stacked along z.
    assert_eq!(packed.atlas.size, UVec3::new(16, 16, 30));
    assert!(packed.mips);
    assert_eq!(packed.regions[1].mip_count, 3);
    assert_eq!(
        packed.regions[1].mips,
        [glam::Vec4::new(0.0, 0.0, 16.0, 1.0), glam::Vec4::new(0.0, 0.0, 24.0, 1.0), glam::Vec4::new(0.0, 0.0, 28.0, 1.0)]
    );
    assert_eq!((packed.regions[0].plane_offset, packed.regions[0].plane_count), (0, 6));
    assert_eq!((packed.regions[1].plane_offset, packed.regions[1].plane_count), (6, 7));
    assert_eq!(packed.regions[0].mode, mode::MIP);
    // 8-bit volume: a 256-texel table per region, both in the first atlas row.
    assert_eq!((packed.regions[1].lut_offset, packed.regions[1].lut_width), (256, 256));
    assert_eq!(packed.lut.len(), LUT_ATLAS_WIDTH as usize);
    assert_eq!(packed.regions[0].dims, glam::Vec4::new(16.0, 16.0, 16.0, 255.0));
    use crate::render::gpu_types::features as f;
    assert_eq!(
        packed.features,
        f::PROJECTION | f::SHADING | f::MULTI_REGION | f::MIP_READS | f::UNIFORM_PLANES | f::UNIFORM_REGIONS | f::UNIFORM_OCCUPANCY
    );
    // Regions reading a mip chain: scalar samples of volumes in memory, not label codes,
    // not bricked volumes, not regions that draw nothing.
    let scalar = packed.regions[1];
    assert!(super::reads_mips(&scalar));
    assert!(!super::reads_mips(&GpuRegion { flags: scalar.flags | region_flags::LABELS, ..scalar }));
    assert!(!super::reads_mips(&GpuRegion { bricked: glam::UVec4::new(1, 0, 0, 0), ..scalar }));
    assert!(!super::reads_mips(&GpuRegion { mode: mode::OFF, ..scalar }));
}

#[test]
fn shelf_layout_stacks_then_starts_columns() {
    let a = atlas_layout(&[UVec3::new(4, 5, 6), UVec3::new(3, 2, 4), UVec3::new(2, 2, 5)], 10).unwrap();
    // 6 + 4 = 10 fits the first column; the third box starts a column at x = 4.
    assert_eq!(a.offsets, vec![UVec3::ZERO, UVec3::new(0, 0, 6), UVec3::new(4, 0, 0)]);
    assert_eq!(a.size, UVec3::new(6, 5, 10));
    assert!(atlas_layout(&[UVec3::new(11, 1, 1)], 10).is_none());
    assert!(atlas_layout(&[UVec3::splat(8), UVec3::splat(8)], 10).is_none());
}

#[test]
fn volumes_beyond_the_atlas_are_reported() {
    let tf = presets::builtin("grayscale_ramp").unwrap();
    let mut scene = RenderScene::default();
    scene.appearances.push(Appearance::new(Mode::Dvr, tf));
    for i in 0..3 {
        let v = Arc::new(phantom::sphere(8, 2.0).unwrap());
        scene.regions.push(Region::volume_box(&v.grid, i, 0));
        scene.volumes.push(v);
    }
    // A 16³ atlas holds two 8³ volumes stacked, not three (16 along x also fails).
    let packed = pack(&scene, 16).unwrap();
    assert_eq!(packed.regions.len(), 3, "three volumes fit as two columns");
    // With their mip chains (15 texels deep each) only two would: the chains go.
    assert!(!packed.mips && packed.regions.iter().all(|r| r.mip_count == 0));
    let two = RenderScene { volumes: scene.volumes[..2].to_vec(), regions: scene.regions[..2].to_vec(), ..scene.clone() };
    assert!(pack(&two, 16).unwrap().mips);
    let packed = pack(&scene, 12).unwrap();
    assert_eq!(packed.regions.len(), 1);
    assert_eq!(packed.dropped.len(), 2);
    assert_eq!(packed.region_slots.iter().filter(|s| s.is_none()).count(), 2);
    assert_eq!(packed.region_slots.iter().flatten().count(), packed.regions.len());
    // DVR regions carry their occupancy bits.
    assert!(packed.regions.iter().all(|r| r.flags & region_flags::OCCUPANCY != 0));
}

#[test]
fn a_selection_on_its_datas_grid_rides_in_the_second_channel() {
    use super::super::gpu_types::features;
    use crate::region::{Keep, SelectionWeight};
    use crate::volume::{Grid, SelectionVolume};
    let v = Arc::new(phantom::sphere(16, 5.0).unwrap());
    let selected = |grid: Grid| {
        let n = grid.dims.element_product() as usize;
        Arc::new(SelectionVolume::from_codes(grid, (0..n).map(|i| if i % 7 == 0 { 255 } else { 0 }).collect()).unwrap().volume)
    };
    // The data less the selection, and the selection drawn over it (an exploded view at
    // rest).
    let scene_with = |a: &Arc<crate::volume::Volume>, b: &Arc<crate::volume::Volume>| {
        let look = |s: &Arc<crate::volume::Volume>, keep| Appearance {
            selection: Some(SelectionWeight { volume: s.clone(), keep }),
            ..Appearance::new(Mode::Dvr, presets::builtin("grayscale_ramp").unwrap())
        };
        let mut scene = RenderScene::single(v.clone(), look(a, Keep::Unselected));
        scene.appearances.push(look(b, Keep::Selected));
        scene.regions.push(Region { appearance: 1, ..scene.regions[0].clone() });
        scene
    };
    // On the data's grid: one atlas volume, the data, carrying the selection (scene
    // volume 1) in its second channel; the regions are still weighted (their selection
    // records give the degree of interest's scale and which side they keep).
    let on_grid = selected(v.grid.clone());
    let packed = pack(&scene_with(&on_grid, &on_grid), 2048).unwrap();
    assert_ne!(packed.features & features::DOI_CHANNEL, 0);
    assert_eq!((packed.volumes.clone(), packed.doi_channels.clone()), (vec![0], vec![Some(1)]));
    assert_eq!(packed.regions[0].flags & region_flags::SELECTION, region_flags::SELECTION);
    assert_eq!(packed.regions[1].flags & region_flags::KEEP_UNSELECTED, 0);
    // The selection's region lies in the data's with the same map: it is drawn in the
    // data's samples (a record after the one region the ray traverses), and the data's
    // region skips only bricks where neither draws.
    assert_eq!(packed.region_count, 1);
    assert_eq!((packed.regions[0].flags & region_flags::COMPANION, packed.regions[0].objects.z), (region_flags::COMPANION, 1));
    assert_eq!(packed.features & (features::COMPANION | features::DVR_PAIRS | features::MULTI_REGION), features::COMPANION);
    assert_eq!(packed.region_slots, vec![Some(0), Some(1)]);
    // One lookup classifies a sample under both looks: the pair table holds, at each
    // texel, the data's colour and the selection's, as 16-bit normalised numbers.
    let (host, drawn) = (packed.regions[0], packed.regions[1]);
    assert_eq!((host.lut_width, host.lut_a, host.lut_b), (drawn.lut_width, drawn.lut_a, drawn.lut_b));
    let pair = host.objects.y as usize;
    assert!(pair >= (drawn.lut_offset + drawn.lut_width) as usize);
    let unorm = |bits: u32| (bits & 0xFFFF) as f32 / 65535.0;
    for i in 0..host.lut_width as usize {
        let bits = packed.lut[pair + i];
        let looks = [unorm(bits[0]), unorm(bits[0] >> 16), unorm(bits[1]), unorm(bits[1] >> 16)];
        let others = [unorm(bits[2]), unorm(bits[2] >> 16), unorm(bits[3]), unorm(bits[3] >> 16)];
        for (decoded, table) in [(looks, host.lut_offset as usize), (others, drawn.lut_offset as usize)] {
            let texel = texel_colour(packed.lut[table + i]);
            assert!(decoded.iter().zip(texel).all(|(d, t)| (d - t).abs() <= 0.5 / 65535.0 + 1e-7), "texel {i}: {decoded:?} {texel:?}");
        }
    }
    // (Tables that map a sample otherwise, or hold a channel beyond 1, could share no
    // pair table: not drawn in.)
    let scene = scene_with(&on_grid, &on_grid);
    let prepared = || crate::reference::prepare(&scene).unwrap();
    assert_eq!(companions(&prepared(), true), vec![Some(1), None]);
    let (mut mapped, mut bright) = (prepared(), prepared());
    if let PreparedLookup::Transfer { a, .. } = &mut mapped[1].lookup {
        *a *= 2.0;
    }
    if let PreparedLookup::Transfer { lut, .. } = &mut bright[0].lookup {
        lut.rgba[7][0] = 1.5;
    }
    assert_eq!((companions(&mapped, true), companions(&bright, true)), (vec![None, None], vec![None, None]));
    let words = |r: &GpuRegion| &packed.occupancy[r.occupancy_offset as usize..][..v.bricks().len().div_ceil(32)];
    assert!(words(&packed.regions[0]).iter().zip(words(&packed.regions[1])).all(|(a, b)| a & b == *b));
    // Inside it but shifted by a voxel, it samples other voxels: a region of its own,
    // paired with the data's.
    let mut moved = scene_with(&on_grid, &on_grid);
    let shifted = Region::volume_box_at(&v.grid, glam::Affine3A::from_translation(v.grid.spacing * Vec3::X), 0, 1);
    moved.regions[1] = shifted.cut_to_index_box(Vec3::splat(-0.5), Vec3::new(13.5, 15.5, 15.5));
    let packed = pack(&moved, 2048).unwrap();
    assert_eq!((packed.region_count, packed.features & (features::COMPANION | features::DVR_PAIRS)), (2, features::DVR_PAIRS));
    // Shaded otherwise than the data's look, it needs a gradient of its own: paired.
    let mut glossy = scene_with(&on_grid, &on_grid);
    glossy.appearances[1].shading.specular = 0.9;
    assert_eq!(pack(&glossy, 2048).unwrap().features & (features::COMPANION | features::DVR_PAIRS), features::DVR_PAIRS);
    // So is a look that steps finer than the data's: the ray takes its step.
    let mut finer = scene_with(&on_grid, &on_grid);
    finer.appearances[1].step = 0.25;
    assert_eq!(pack(&finer, 2048).unwrap().features & (features::COMPANION | features::DVR_PAIRS), features::DVR_PAIRS);
    // And a coarser one: one opacity correction serves both looks only at one step.
    let mut coarser = scene_with(&on_grid, &on_grid);
    coarser.appearances[1].step = 2.0;
    assert_eq!(pack(&coarser, 2048).unwrap().features & (features::COMPANION | features::DVR_PAIRS), features::DVR_PAIRS);
    // So is a look that modulates by the gradient.
    let mut modulated = scene_with(&on_grid, &on_grid);
    modulated.appearances[1].mode = Mode::GradientDvr;
    assert_eq!(pack(&modulated, 2048).unwrap().features & features::COMPANION, 0);
    // On a grid of its own (twice as coarse): the weights sample it in its own box.
    let coarse = selected(Grid::new(glam::UVec3::splat(8), v.grid.spacing * 2.0));
    let packed = pack(&scene_with(&coarse, &coarse), 2048).unwrap();
    assert_eq!(packed.features & features::DOI_CHANNEL, 0);
    assert_eq!((packed.volumes.clone(), packed.doi_channels.clone()), (vec![0, 1], vec![None, None]));
    // Two selections of one volume: one channel cannot hold both.
    let other = selected(v.grid.clone());
    let packed = pack(&scene_with(&on_grid, &other), 2048).unwrap();
    assert_eq!((packed.features & features::DOI_CHANNEL, packed.volumes.len()), (0, 3));
    // No weights, no channel.
    let plain = RenderScene::single(v.clone(), Appearance::new(Mode::Dvr, presets::builtin("grayscale_ramp").unwrap()));
    assert_eq!(pack(&plain, 2048).unwrap().doi_channels, vec![None]);
}

#[test]
fn a_pair_texel_holds_two_colours_as_16_bit_normalised_numbers() {
    // Worked by hand, ⌊0.5 + 65535·x⌋: 1 → 0xFFFF, 0.5 → 32768 = 0x8000, 0.25 → 16384 =
    // 0x4000, 0 → 0, 0.75 → 49151 = 0xBFFF, 0.001 → ⌊66.035⌋ = 0x42; out of 0…1
    // clamped; the first of each two in the lower 16 bits (WGSL's unpack2x16unorm).
    let texel = unorm_pair([1.0, 0.5, 0.25, 0.0], [0.75, 1.5, -0.5, 0.001]);
    assert_eq!(texel, [0x8000_FFFF, 0x0000_4000, 0xFFFF_BFFF, 0x0042_0000]);
}

#[test]
fn context_preserving_dvr_at_kappa_t_zero_takes_dvrs_cost_path() {
    // κt = 0 is DVR (ContextParams::is_plain_dvr): packed as DVR, no context code in the
    // pipeline; κt > 0, or λs zero somewhere (0⁰ = 1: gradient modulation), stays.
    let v = Arc::new(phantom::sphere(16, 5.0).unwrap());
    let tf = presets::builtin("grayscale_ramp").unwrap();
    let with = |kappa_t: f32, tf: crate::transfer::TransferFunction| {
        let a = Appearance {
            context: crate::context::ContextParams { kappa_t, kappa_s: 0.5, ..Default::default() },
            ..Appearance::new(crate::region::Mode::Context, tf)
        };
        pack(&RenderScene::single(v.clone(), a), 2048).unwrap()
    };
    let zero = with(0.0, tf.clone());
    assert_eq!(zero.regions[0].mode, mode::DVR);
    assert_eq!(zero.features & super::super::gpu_types::features::CONTEXT, 0);
    let open = with(3.0, tf.clone());
    assert_eq!(open.regions[0].mode, mode::CONTEXT);
    assert_ne!(open.features & super::super::gpu_types::features::CONTEXT, 0);
    let lambda = crate::transfer::TransferFunction {
        lambda_s: vec![crate::transfer::OpacityPoint(0.0, 0.0), crate::transfer::OpacityPoint(1.0, 1.0)],
        ..tf
    };
    assert_eq!(with(0.0, lambda).regions[0].mode, mode::CONTEXT);
}

#[test]
fn a_part_record_is_its_regions_but_for_its_look() {
    // The shader reads a part's look and takes the rest from its segmented region's
    // record (two_level.wgsl part_record): every other field the march reads of a part
    // must be the region's.
    use super::super::gpu_types::features;
    use crate::region::{Object, Segmentation};
    use crate::volume::phantom::head::{self, label};
    let h = head::generate(32).unwrap();
    let ct = Arc::new(h.ct);
    let rest = Appearance::new(Mode::Context, presets::builtin("ct_skin_bone").unwrap());
    let shaded = Appearance { shading: crate::region::Shading { enabled: false, ..Default::default() }, ..rest.clone() };
    let objects = vec![
        Object::new("arteries", vec![label::ARTERIES as u32], Appearance::new(Mode::Dvr, presets::builtin("ct_vessels").unwrap())),
        Object::new("skull", vec![label::SKULL as u32], Appearance::new(Mode::Mip, presets::builtin("grayscale_ramp").unwrap())),
        Object::new("ventricles", vec![label::VENTRICLES as u32], Appearance::new(Mode::Iso, presets::builtin("grayscale_ramp").unwrap())),
        Object::new("brain", vec![label::GREY_MATTER as u32, label::WHITE_MATTER as u32], shaded),
    ];
    let segmented = |objects: Vec<Object>, own_values: bool| Appearance {
        segmentation: Some(Segmentation {
            labels: Arc::new(h.labels.volume.clone()),
            table: None,
            objects,
            rest_visible: true,
            own_values,
        }),
        ..rest.clone()
    };
    for own_values in [false, true] {
        let packed = pack(&RenderScene::single(ct.clone(), segmented(objects.clone(), own_values)), 2048).unwrap();
        let region = packed.regions[0];
        assert_eq!(region.mode, mode::TWO_LEVEL);
        let first = region.objects.x as usize;
        let parts = &packed.regions[first..first + region.objects.y as usize];
        assert_eq!(parts.len(), 5);
        let modes: Vec<u32> = parts.iter().map(|p| p.mode).collect();
        assert_eq!(modes, [mode::DVR, mode::MIP, mode::ISO, mode::CONTEXT, mode::CONTEXT]);
        for part in parts {
            let look = GpuRegion {
                mode: part.mode,
                flags: part.flags,
                lut_offset: part.lut_offset,
                lut_width: part.lut_width,
                lut_a: part.lut_a,
                lut_b: part.lut_b,
                iso: part.iso,
                shading: part.shading,
                context: part.context,
                projection: part.projection,
                // (Read of the part's own record, or never read of a part: its step
                // is the region's, `ratios`.)
                native_step: part.native_step,
                value_lo: part.value_lo,
                value_hi: part.value_hi,
                plane_offset: part.plane_offset,
                plane_count: part.plane_count,
                hole_offset: part.hole_offset,
                hole_count: part.hole_count,
                occupancy_offset: part.occupancy_offset,
                bounds: part.bounds,
                cluster: part.cluster,
                objects: part.objects,
                ..region
            };
            assert_eq!(*part, look, "own values {own_values}");
        }
        // No object takes a range of values: the shader reads no range.
        assert_eq!(packed.features & features::VALUE_RANGES, 0);
    }
    // The skull's bone alone: its range is read.
    let mut ranged = objects.clone();
    ranged[1].values = Some((300.0, 3000.0));
    let packed = pack(&RenderScene::single(ct.clone(), segmented(ranged, false)), 2048).unwrap();
    assert_eq!(packed.features & features::VALUE_RANGES, features::VALUE_RANGES);
    let skull = packed.regions[packed.regions[0].objects.x as usize + 1];
    assert!(skull.value_lo > 0.0 && skull.value_hi < 1.0, "{} {}", skull.value_lo, skull.value_hi);
}

#[test]
fn the_records_planes_and_occupancy_ride_in_uniform_copies_while_they_fit() {
    use super::super::gpu_types::{GpuRegion, MAX_UNIFORM_OCCUPANCY, MAX_UNIFORM_PLANES, MAX_UNIFORM_REGIONS, features};
    use bevy::render::render_resource::ShaderType;
    let copies = features::UNIFORM_REGIONS | features::UNIFORM_PLANES | features::UNIFORM_OCCUPANCY;
    let v = Arc::new(phantom::sphere(16, 5.0).unwrap());
    let tf = presets::builtin("grayscale_ramp").unwrap();
    let mut scene = RenderScene::single(v.clone(), Appearance::new(Mode::Dvr, tf));
    let whole = Region::volume_box(&v.grid, 0, 0);
    let centre = (v.grid.world_bounds().0 + v.grid.world_bounds().1) * 0.5;
    scene.regions = vec![whole.clone().clipped(Plane::through(centre, Vec3::X)), whole.clipped(Plane::through(centre, -Vec3::X))];
    let packed = pack(&scene, 2048).unwrap();
    assert_eq!(packed.features & copies, copies);
    // The two halves (one volume, one look) share one run of occupancy bits: three sets
    // of one bit per brick.
    let (a, b) = (packed.regions[0], packed.regions[1]);
    assert_ne!(a.flags & region_flags::OCCUPANCY, 0);
    assert_eq!(a.occupancy_offset, b.occupancy_offset);
    let bricks = (a.bricks.x * a.bricks.y * a.bricks.z) as usize;
    assert_eq!(packed.occupancy.len(), 3 * bricks.div_ceil(32));
    // Under another look (nothing visible: no brick occupied), each half has its own.
    let mut looks = scene.clone();
    let mut clear = presets::builtin("grayscale_ramp").unwrap();
    clear.opacity.iter_mut().for_each(|p| p.1 = 0.0);
    looks.appearances.push(Appearance::new(Mode::Dvr, clear));
    looks.regions[1].appearance = 1;
    let two = pack(&looks, 2048).unwrap();
    assert_ne!(two.regions[0].occupancy_offset, two.regions[1].occupancy_offset);
    assert_eq!(two.occupancy.len(), 6 * bricks.div_ceil(32));
    assert_ne!(two.occupancy[..3 * bricks.div_ceil(32)], two.occupancy[3 * bricks.div_ceil(32)..]);
    // Each copy holds 64 KiB at most, what a uniform binding may hold on every device;
    // the records' is as many as fit.
    let record = GpuRegion::min_size().get();
    assert_eq!(record % 16, 0, "a record ends at a 16-byte boundary: one stride in both address spaces");
    assert!(record * MAX_UNIFORM_REGIONS as u64 <= 65536 && record * (MAX_UNIFORM_REGIONS as u64 + 1) > 65536, "{record}");
    assert_eq!((MAX_UNIFORM_PLANES * 16, MAX_UNIFORM_OCCUPANCY * 4), (65536, 65536));
    // One past a copy's room, that buffer is read from storage; the others stay.
    let mut big = packed.clone();
    big.regions.resize(MAX_UNIFORM_REGIONS + 1, GpuRegion::default());
    assert_eq!(super::uniform_copies(&big), copies & !features::UNIFORM_REGIONS);
    let mut big = packed.clone();
    big.planes.resize(MAX_UNIFORM_PLANES + 1, glam::Vec4::ZERO);
    assert_eq!(super::uniform_copies(&big), copies & !features::UNIFORM_PLANES);
    let mut big = packed.clone();
    big.occupancy.resize(MAX_UNIFORM_OCCUPANCY + 1, 0);
    assert_eq!(super::uniform_copies(&big), copies & !features::UNIFORM_OCCUPANCY);
    big.occupancy.truncate(MAX_UNIFORM_OCCUPANCY);
    assert_eq!(super::uniform_copies(&big), copies);
}
