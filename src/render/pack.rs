//! Packing a [`RenderScene`] into the GPU layout: one [`GpuRegion`] per region, the
//! planes of all regions in one array, every lookup table in one RGBA atlas, the brick
//! occupancy bits of all regions in one word array, and every volume (and brick
//! min-max grid) at its place in one 3D texture atlas. One atlas instead of a texture
//! per volume: WGSL cannot index textures dynamically without binding arrays (absent
//! on software Vulkan), and a `switch` over texture slots in the inner loop multiplies
//! the sampling code.
//!
//! A selection weight's degree of interest, when its selection lies on its data's grid,
//! rides in a second channel of the data's texels ([`doi_channels`]).
//!
//! Packing reuses the CPU reference's preparation ([`crate::reference::prepare`]), so
//! both renderers classify, step and shade with the same numbers. It decides nothing.

use glam::{Mat3, Mat4, UVec3, UVec4, Vec4};

use crate::volume::pyramid::{MIP_LEVELS, half_dims};

use super::gpu_types::{CLUSTER, GpuRegion, context_power, mode, region_flags};
use crate::context::Power;
use crate::reference::prepare::{PreparedLookup, PreparedRegion};
use crate::region::{Mode, ObjectTable, Plane, RenderScene, meet};

/// Dimensions of a volume's boxes in the atlas: the volume, then (with `mips`) its levels.
fn volume_boxes(dims: UVec3, mips: bool) -> Vec<UVec3> {
    let mut boxes = vec![dims];
    if mips {
        for _ in 0..MIP_LEVELS {
            let last = boxes[boxes.len() - 1];
            if last == UVec3::ONE {
                break;
            }
            boxes.push(half_dims(last));
        }
    }
    boxes
}

fn mode_number(m: Mode) -> u32 {
    match m {
        Mode::Dvr => mode::DVR,
        Mode::Mip => mode::MIP,
        Mode::MinIp => mode::MIN_IP,
        Mode::XRay => mode::X_RAY,
        Mode::GradientDvr => mode::GRADIENT_DVR,
        Mode::Iso => mode::ISO,
        Mode::Context => mode::CONTEXT,
    }
}

/// Packs `scene` with atlases of at most `max_texture` texels per axis.
pub fn pack(scene: &RenderScene, max_texture: u32) -> Result<PackedScene, String> {
    let prepared = crate::reference::prepare(scene)?;
    let all = scene.all_volumes();
    let index_of = |v: &std::sync::Arc<crate::volume::Volume>| all.iter().position(|a| std::sync::Arc::ptr_eq(a, v));
    let channels = doi_channels(&prepared, &all);
    // The volumes each region samples: its own, and a segmentation's label volume.
    let uses: Vec<Vec<usize>> = prepared
        .iter()
        .map(|p| {
            let mut u = vec![p.region.volume];
            let appearance = scene.appearances.get(p.region.appearance);
            if let Some(seg) = appearance.and_then(|a| a.segmentation.as_ref()) {
                u.extend(index_of(&seg.labels));
            }
            // (A selection in its data's second channel needs no room of its own.)
            if let Some(w) = appearance.and_then(|a| a.selection.as_ref()).filter(|_| channels.is_none()) {
                u.extend(index_of(&w.volume));
            }
            u
        })
        .collect();
    let mut out = PackedScene::default();
    // Volumes in order of first use; those that no longer fit are dropped.
    for (p, used) in prepared.iter().zip(&uses) {
        let mut candidate = out.volumes.clone();
        for &v in used {
            if !candidate.contains(&v) {
                candidate.push(v);
            }
        }
        if candidate.len() == out.volumes.len() {
            continue;
        }
        let boxes = |mips: bool| -> Vec<UVec3> { candidate.iter().flat_map(|&v| volume_boxes(all[v].dims(), mips)).collect() };
        let bricks: Vec<UVec3> = candidate.iter().map(|&v| all[v].bricks().dims).collect();
        // Mip chains only while every volume's chain fits; volumes come first.
        let with_mips = if out.mips || out.volumes.is_empty() { atlas_layout(&boxes(true), max_texture) } else { None };
        let layout = with_mips.map(|a| (a, true)).or_else(|| atlas_layout(&boxes(false), max_texture).map(|a| (a, false)));
        match (layout, atlas_layout(&bricks, max_texture)) {
            (Some((a, mips)), Some(b)) => {
                out.volumes = candidate;
                out.atlas = a;
                out.mips = mips;
                out.brick_atlas = b;
            }
            _ => {
                out.dropped.push(format!("'{}' left out: the volumes of this view exceed one {max_texture}³ texture atlas", p.volume.name))
            }
        }
    }
    let mut next = 0;
    for &v in &out.volumes {
        let count = volume_boxes(all[v].dims(), out.mips).len();
        out.levels.push(out.atlas.offsets[next..next + count].to_vec());
        next += count;
    }
    out.doi_channels = out.volumes.iter().map(|&v| channels.as_ref().and_then(|c| c[v])).collect();
    let slot_of = |out: &PackedScene, v: usize| out.volumes.iter().position(|&u| u == v);
    let fused = companions(&prepared, channels.is_some());
    let in_place = insets(&prepared);
    let holes = kept_holes(&prepared, &in_place);
    let mut drawn_in = vec![false; prepared.len()];
    for b in fused.iter().flatten().chain(in_place.iter().map(|i| &i.window)) {
        drawn_in[*b] = true;
    }
    let mut segmented = Vec::new();
    let mut weighted = Vec::new();
    let mut hosts = Vec::new();
    // The regions the ray traverses, then those drawn in another's samples.
    let order = (0..prepared.len()).filter(|&i| !drawn_in[i]).chain((0..prepared.len()).filter(|&i| drawn_in[i]));
    let mut slots_of = vec![None; prepared.len()];
    let mut traversed = None;
    for i in order {
        let (p, used) = (&prepared[i], &uses[i]);
        if drawn_in[i] {
            traversed.get_or_insert(out.regions.len() as u32);
        }
        let slots: Option<Vec<usize>> = used.iter().map(|&v| slot_of(&out, v)).collect();
        let Some(slots) = slots else { continue };
        slots_of[i] = Some(out.regions.len() as u32);
        let levels = out.levels[slots[0]].clone();
        let mut region = pack_region(p, &holes[i], &levels, out.brick_atlas.offsets[slots[0]], &mut out);
        if let Some(objects) = &p.objects {
            region.mode = mode::TWO_LEVEL;
            if objects.on_grid {
                region.flags |= region_flags::ON_GRID;
            }
            if objects.own_values {
                region.flags |= region_flags::OWN_VALUES;
            }
            segmented.push((out.regions.len(), p, slots.clone()));
        }
        if let Some(w) = &p.weight {
            region.flags |= region_flags::SELECTION;
            if w.weight.keep == crate::region::Keep::Unselected {
                region.flags |= region_flags::KEEP_UNSELECTED;
            }
            weighted.push((out.regions.len(), p, slots.last().copied().unwrap_or(slots[0])));
        }
        if let Some(b) = fused[i] {
            hosts.push((out.regions.len(), b));
        }
        out.regions.push(region);
    }
    out.region_slots = slots_of;
    out.region_count = traversed.unwrap_or(out.regions.len() as u32);
    set_clusters(&mut out.regions[..out.region_count as usize]);
    for (a, b) in hosts {
        if let Some(record) = out.region_slots[b] {
            draw_in(&mut out, a, record as usize);
        }
    }
    for inset in &in_place {
        if let (Some(host), Some(window)) = (out.region_slots[inset.host], out.region_slots[inset.window]) {
            draw_in_place(&mut out, host as usize, window as usize, &prepared[inset.host].region.holes[inset.hole]);
        }
    }
    // Records the ray does not traverse: the parts and labels of segmented regions, the
    // selections of weighted ones.
    // (Ranges of the objects of the regions drawn: without, no sample reads one.)
    let value_ranges = segmented.iter().any(|(_, p, _)| p.objects.as_ref().is_some_and(|o| o.table.has_ranges()));
    for (index, p, slots) in segmented {
        let objects = pack_objects(p, &slots, &mut out);
        out.regions[index].objects = objects;
    }
    for (index, p, slot) in weighted {
        out.regions[index].objects.w = pack_selection(p, slot, &mut out);
    }
    // (A region drawn in another's samples overlaps nothing of its own.)
    let walked: Vec<&PreparedRegion> = prepared.iter().enumerate().filter(|(i, _)| !drawn_in[*i]).map(|(_, p)| p).collect();
    out.features = scene_features(&out.regions, overlaps(&walked));
    if fused.iter().any(Option::is_some) {
        out.features |= super::gpu_types::features::COMPANION;
    }
    out.features |= inset_features(&out.insets);
    if value_ranges {
        out.features |= super::gpu_types::features::VALUE_RANGES;
    }
    if channels.is_some() && out.features & super::gpu_types::features::SELECTION != 0 {
        out.features |= super::gpu_types::features::DOI_CHANNEL;
    }
    out.max_steps = march_bound(&out.regions[..out.region_count as usize], union_extent(&prepared));
    out.features |= uniform_copies(&out);
    // Empty scenes still bind (1-texel) atlases.
    out.atlas.size = out.atlas.size.max(UVec3::ONE);
    out.brick_atlas.size = out.brick_atlas.size.max(UVec3::ONE);
    if out.lut.is_empty() {
        out.lut.push([0; 4]);
    }
    let rows = out.lut_rows() as usize;
    out.lut.resize(rows * LUT_ATLAS_WIDTH as usize, [0; 4]);
    if out.occupancy.is_empty() {
        out.occupancy.push(0);
    }
    if out.planes.is_empty() {
        out.planes.push(Vec4::ZERO);
    }
    Ok(out)
}

/// Appends the part records of a segmented region (each object, then the rest: the
/// data volume with that part's appearance and value range) and its label record (the
/// label volume, mapped from world space, with the object table as its lookup).
/// Returns the region's `objects` field. `slots`: the data volume's, the labels'.
fn pack_objects(p: &PreparedRegion, slots: &[usize], out: &mut PackedScene) -> UVec4 {
    let Some(objects) = &p.objects else { return UVec4::ZERO };
    let first = out.regions.len() as u32;
    let data_levels = out.levels[slots[0]].clone();
    for (k, part) in objects.parts.iter().enumerate() {
        let mut r = pack_region(part, &part.region.holes, &data_levels, out.brick_atlas.offsets[slots[0]], out);
        (r.value_lo, r.value_hi) = objects.table.ranges.get(k).copied().unwrap_or(ObjectTable::UNBOUNDED);
        // Infinities do not survive every path to the GPU: the largest finite floats.
        (r.value_lo, r.value_hi) = (r.value_lo.max(f32::MIN), r.value_hi.min(f32::MAX));
        if !objects.visible[k] {
            r.mode = mode::OFF;
        }
        out.regions.push(r);
    }
    let label_slot = slots.get(1).copied().unwrap_or(slots[0]);
    let labels = objects.label_volume;
    let lut_offset = out.lut.len() as u32;
    out.lut.extend(objects.table.candidates.iter().map(|c| texel(c.map(|k| k as f32))));
    let world_to_labels = objects.data_to_label * p.region.world_to_voxel;
    // Each code's class after its candidates (`twolevel::code_classes`), and where a
    // cell may straddle labels (`twolevel::boundary_bricks`) as the occupancy bits
    // of the label record over its own bricks.
    // (With own values only: the shader reads neither otherwise.)
    let (mut flags, mut bricks, occupancy_offset) = (0, UVec4::ZERO, out.occupancy.len() as u32);
    if objects.own_values {
        out.lut.extend(objects.classes.iter().map(|&c| texel([c as f32, 0.0, 0.0, 0.0])));
        let grid = labels.bricks();
        let boundary = crate::twolevel::boundary_bricks(grid);
        bricks = grid.dims.extend(grid.size);
        out.occupancy.extend(occupancy_words(boundary.iter().copied()));
        flags = region_flags::OCCUPANCY;
    }
    out.regions.push(GpuRegion {
        world_to_voxel: Mat4::from(world_to_labels),
        dims: labels.dims().as_vec3().extend(labels.code_max() as f32),
        atlas_offset: out.levels[label_slot][0].as_vec3().extend(0.0),
        mode: mode::OFF,
        flags,
        bricks,
        occupancy_offset,
        lut_offset,
        lut_width: objects.table.candidates.len() as u32,
        ..Default::default()
    });
    UVec4::new(first, objects.parts.len() as u32, out.regions.len() as u32 - 1, 0)
}

/// Where `words` (a region's occupancy bits) lie in the scene's occupancy array: at an
/// earlier record's run of the same words (regions of one volume under one look, as an
/// exploded view's parts, share one run: 64 parts of a 128³ volume would need 24 576
/// words, more than their uniform copy holds), else appended.
fn place_occupancy(out: &mut PackedScene, words: &[u32]) -> u32 {
    let earlier = out.regions.iter().map(|r| r.occupancy_offset as usize).find(|&o| out.occupancy.get(o..o + words.len()) == Some(words));
    earlier.unwrap_or_else(|| {
        out.occupancy.extend_from_slice(words);
        out.occupancy.len() - words.len()
    }) as u32
}

/// One bit per brick, 32 a word.
fn occupancy_words(bits: impl ExactSizeIterator<Item = bool>) -> Vec<u32> {
    let mut words = vec![0u32; bits.len().div_ceil(32)];
    for (i, o) in bits.enumerate() {
        if o {
            words[i / 32] |= 1 << (i % 32);
        }
    }
    words
}

/// Most iterations any loop of the ray caster can make on one ray through `regions`:
/// every bound is this one number from the uniforms, never a per-ray value.
///
/// Why: llvmpipe runs a fragment shader on 8 lanes at once and keeps a loop going while
/// any lane of the group is in it. With the exit tests on per-ray values alone, a frame
/// of the 32³ head phantom at 64×64 took 5 s; with this bound added it takes 0.12 s and
/// the picture is the same. Measured: with a constant bound the frame time grew in
/// proportion to the constant (1 000: 0.1 s, 16 384: 0.9 s, 65 535: 3.5 s) while no
/// visible pixel reached it, so lanes that are never written (llvmpipe reports 4 352
/// invocations for 4 096 pixels) ran each loop to llvmpipe's own 65 535-iteration limit.
/// (Those lanes' rays have a NaN step; the shader now returns at once for them, which
/// made frames four times faster again, but the bound stays as the guard.)
///
/// The bound: a ray samples every region it crosses at its step, the smallest world step
/// of those regions (`raycast.wgsl`), so it takes at most Σ chord_r / min_r step_r + 1
/// per region samples. A region lies inside its volume's box, so its chord is at most
/// the box's longest diagonal; a region's smallest world step is native_step / σ_max of
/// its world→native map, and the Frobenius norm bounds σ_max from above. The samples of
/// one ray also lie between its first entry and last exit, so `extent` (the diagonal of
/// the regions' bounding box) bounds the chords' sum too: many small regions (the parts
/// of an exploded view) would otherwise multiply the bound. The outer loop also stops
/// once per gap and interval boundary: 3 more per region and per hole (a hole splits an
/// interval in two), and 2 spare.
pub fn march_bound(regions: &[GpuRegion], extent: Option<f32>) -> u32 {
    let mut chords = 0.0f64;
    let mut step = f64::INFINITY;
    for r in regions {
        let diagonal = crate::region::longest_diagonal(Mat3::from_mat4(r.world_to_voxel).inverse(), r.dims.truncate());
        let m = Mat3::from_mat4(r.to_native);
        let frobenius = (m.x_axis.length_squared() + m.y_axis.length_squared() + m.z_axis.length_squared()).sqrt();
        chords += diagonal as f64;
        step = step.min(r.native_step as f64 / frobenius.max(1e-12) as f64);
    }
    if let Some(e) = extent.filter(|e| e.is_finite()) {
        chords = chords.min(e as f64);
    }
    if regions.is_empty() || !chords.is_finite() || step.is_nan() || step <= 0.0 {
        return 2;
    }
    let intervals = regions.len() + regions.iter().map(|r| r.hole_count as usize).sum::<usize>();
    let bound = (chords / step).ceil() + 3.0 * intervals as f64 + 2.0;
    bound.min(u32::MAX as f64) as u32
}

/// The diagonal of the bounding box of every region's polyhedron: no ray's samples
/// span more (`None` when no region has a vertex).
fn union_extent(prepared: &[PreparedRegion]) -> Option<f32> {
    let points: Vec<glam::Vec3> = prepared.iter().flat_map(|p| crate::region::vertices(&p.region.planes)).collect();
    let lo = points.iter().copied().reduce(glam::Vec3::min)?;
    let hi = points.iter().copied().reduce(glam::Vec3::max)?;
    Some((hi - lo).length())
}

/// How the regions overlap, which decides the compositing code the shader needs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Overlaps {
    /// Two DVR-like regions overlap (DVR_PAIRS: the DVR loop takes both at each sample).
    pub dvr_pairs: bool,
    /// Other regions overlap, or three at once (MULTI_REGION: sample by sample).
    pub general: bool,
}

/// Which regions overlap with volume, and need compositing code for it. Regions that
/// only touch (a dataset and the clip window in its hole, two halves) need none; on
/// llvmpipe such code costs even where no pixel takes it (a single-region scene ran
/// 20 % slower with the general code, 10 % with the pair loop).
///
/// Without that code a sample inside several regions is the last one's, which is exact
/// where the others are transparent: so regions `a` before `b` need it only when the
/// visible part of `a` ([`PreparedRegion::visible_part`]: its occupied bricks) meets
/// `b` (a window beside a dataset, in the empty part of its box, needs nothing). Parts
/// meet when their convex parts share volume and a hole of neither holds the common part
/// (a clip window's region lies in the hole it cuts from the datasets); a common part
/// that only several holes together cover counts as meeting (the shader then merely has
/// code it does not need). Pairs that both composite every sample at once (DVR,
/// gradient-modulated, context-preserving, labels; not segmented) share the DVR loop,
/// unless a third region meets both; other overlaps are composited sample by sample.
pub fn overlaps(prepared: &[&PreparedRegion]) -> Overlaps {
    let visible: Vec<_> = prepared.iter().map(|p| p.visible_part()).collect();
    let dvr_like = |p: &PreparedRegion| p.objects.is_none() && matches!(p.mode, Mode::Dvr | Mode::GradientDvr | Mode::Context);
    let n = prepared.len();
    let pairs: Vec<(usize, usize)> = visible
        .iter()
        .enumerate()
        .flat_map(|(a, va)| (a + 1..n).filter(|&b| meet(&[va, prepared[b].region])).map(move |b| (a, b)))
        .collect();
    let mut out = Overlaps::default();
    for &(a, b) in &pairs {
        let third = (0..n).any(|c| c != a && c != b && meet(&[prepared[a].region, prepared[b].region, prepared[c].region]));
        if third || !dvr_like(prepared[a]) || !dvr_like(prepared[b]) {
            out.general = true;
        } else {
            out.dvr_pairs = true;
        }
    }
    out
}

/// The shader features a list of regions needs, with their [`overlaps`].
pub fn scene_features(regions: &[GpuRegion], overlaps: Overlaps) -> u32 {
    use super::gpu_types::features as f;
    let mut bits = if overlaps.general { f::MULTI_REGION } else { 0 };
    if overlaps.dvr_pairs {
        bits |= f::DVR_PAIRS;
    }
    for r in regions {
        let labels = r.flags & region_flags::LABELS != 0;
        bits |= match r.mode {
            mode::OFF => 0,
            mode::TWO_LEVEL => f::TWO_LEVEL,
            mode::MIP | mode::MIN_IP | mode::X_RAY if !labels => f::PROJECTION,
            mode::ISO if !labels => f::ISO,
            mode::GRADIENT_DVR if !labels => f::DVR | f::GRADIENT_MODULATION,
            mode::CONTEXT if !labels => f::DVR | f::CONTEXT,
            _ => f::DVR,
        };
        if labels {
            bits |= f::LABELS;
        }
        if r.flags & region_flags::SHADING != 0 {
            bits |= f::SHADING;
        }
        if r.hole_count > 0 {
            bits |= f::HOLES;
        }
        if r.flags & region_flags::ON_GRID != 0 {
            bits |= f::OWN_VALUES;
        }
        if reads_mips(r) {
            bits |= f::MIP_READS;
        }
        // (Weights act on DVR samples only: with DVR in the shader.)
        if r.flags & region_flags::SELECTION != 0 && bits & f::DVR != 0 {
            bits |= f::SELECTION;
        }
    }
    bits
}

/// Whether region `r` samples scalar values of a volume in memory (the only samples
/// that come from a mip chain: label codes are read whole, bricked volumes through
/// their page tables).
pub fn reads_mips(r: &GpuRegion) -> bool {
    r.mode != mode::OFF && r.flags & region_flags::LABELS == 0 && r.bricked.x == 0
}

/// Packs one region; `levels` are the atlas offsets of its volume and mip levels.
/// `holes`: the region's holes left after [`insets`] took theirs.
fn pack_region(p: &PreparedRegion, holes: &[[Plane; 6]], levels: &[UVec3], brick_offset: UVec3, out: &mut PackedScene) -> GpuRegion {
    let plane_offset = out.planes.len() as u32;
    out.planes.extend(p.region.planes.iter().map(gpu_plane));
    let hole_offset = out.planes.len() as u32;
    out.planes.extend(holes.iter().flatten().map(gpu_plane));
    let lut_offset = out.lut.len() as u32;
    let mut flags = 0;
    let (lut_a, lut_b, lut_width, labels) = match &p.lookup {
        PreparedLookup::Transfer { lut, a, b } => {
            out.lut.extend(lut.rgba.iter().map(|&c| texel(c)));
            // Context-preserving regions with λ channels read (λt, λs) from the next
            // `lut_width` texels (without, both are 1 and nothing is read).
            if p.mode == Mode::Context && lut.lambda.iter().any(|l| *l != [1.0, 1.0]) {
                out.lut.extend(lut.lambda.iter().map(|l| texel([l[0], l[1], 0.0, 0.0])));
                flags |= region_flags::LAMBDA;
            }
            (*a, *b, lut.rgba.len() as u32, false)
        }
        PreparedLookup::Labels(table) => {
            out.lut.extend(table.iter().map(|&c| texel(c)));
            (0.0, 0.0, table.len() as u32, true)
        }
    };
    if labels {
        flags |= region_flags::LABELS;
    }
    if p.shading.enabled {
        flags |= region_flags::SHADING;
    }
    let mut occupancy_offset = out.occupancy.len() as u32;
    let grid = p.volume.bricks();
    let bricks = grid.dims.extend(grid.size);
    if let Some((_, occ)) = &p.occupancy {
        flags |= region_flags::OCCUPANCY;
        // The bits of full-resolution samples, then those of mip samples up to level 1
        // and of coarser ones (every brick where they are unknown; sampling.wgsl
        // brick_occupied).
        let mut words = occupancy_words(occ.iter().copied());
        for k in 0..2 {
            match p.mip_occupancy.as_ref().map(|m| &m[k]).filter(|m| m.len() == occ.len()) {
                Some(m) => words.extend(occupancy_words(m.iter().copied())),
                None => words.extend(occupancy_words(occ.iter().map(|_| true))),
            }
        }
        occupancy_offset = place_occupancy(out, &words);
    }
    let s = &p.shading;
    GpuRegion {
        world_to_voxel: Mat4::from(p.region.world_to_voxel),
        normal_matrix: Mat4::from_mat3(p.normal_matrix),
        to_native: Mat4::from_mat3(p.to_native),
        dims: p.volume.dims().as_vec3().extend(p.volume.code_max() as f32),
        shading: Vec4::new(s.ambient, s.diffuse, s.specular, s.shininess),
        bricks,
        atlas_offset: levels[0].as_vec3().extend(0.0),
        brick_offset: brick_offset.extend(0),
        plane_offset,
        plane_count: p.region.planes.len() as u32,
        hole_offset,
        hole_count: holes.len() as u32,
        mode: mode_number(p.mode),
        flags,
        lut_offset,
        lut_width,
        occupancy_offset,
        lut_a,
        lut_b,
        native_step: p.native_step,
        reference_length: p.reference_length,
        iso: p.iso,
        gradient_max: p.gradient_max,
        mip_count: levels.len() as u32 - 1,
        value_lo: 0.0,
        value_hi: 0.0,
        mips: std::array::from_fn(|k| levels.get(k + 1).map_or(Vec4::ZERO, |o| o.as_vec3().extend(1.0))),
        context: Vec4::new(
            p.context.kappa_t,
            p.context.kappa_s,
            match p.context.power {
                Power::Schlick => context_power::SCHLICK,
                Power::Exact => context_power::EXACT,
            },
            0.0,
        ),
        sphere: p.sphere.0.extend(p.sphere.1),
        bounds: polyhedron_sphere(&p.region.planes),
        cluster: Vec4::ZERO,
        objects: UVec4::ZERO,
        bricked: UVec4::ZERO,
        bricked_scale: Vec4::ZERO,
        bricked_dims: UVec4::ZERO,
        projection: Vec4::new(p.projection.0, p.projection.1, p.projection_group.min(1 << 24) as f32, 0.0),
    }
}

/// The `cluster` sphere of the first region of every run of [`CLUSTER`] in `regions`
/// (the regions the ray traverses).
fn set_clusters(regions: &mut [GpuRegion]) {
    for run in regions.chunks_mut(CLUSTER) {
        let spheres: Vec<Vec4> = run.iter().map(|r| r.bounds).collect();
        run[0].cluster = sphere_around(&spheres);
    }
}

/// A sphere (centre, radius) around the spheres `spheres`: the centre of their bounding
/// box, the farthest reach from it, a little more for rounding; infinite when one is
/// (or there are none).
pub fn sphere_around(spheres: &[Vec4]) -> Vec4 {
    let infinite = Vec4::new(0.0, 0.0, 0.0, f32::MAX);
    if spheres.is_empty() || spheres.iter().any(|s| !s.is_finite() || s.w >= f32::MAX) {
        return infinite;
    }
    let lo = spheres.iter().map(|s| s.truncate() - s.w).fold(glam::Vec3::splat(f32::INFINITY), glam::Vec3::min);
    let hi = spheres.iter().map(|s| s.truncate() + s.w).fold(glam::Vec3::splat(f32::NEG_INFINITY), glam::Vec3::max);
    let center = (lo + hi) * 0.5;
    let radius = spheres.iter().map(|s| s.truncate().distance(center) + s.w).fold(0.0, f32::max);
    center.extend(radius * (1.0 + 1e-4) + 1e-3)
}

/// A sphere around the convex polyhedron `planes` (the centre of its vertices' bounding
/// box, the farthest vertex's distance, a little more for rounding); infinite when it
/// has no vertices.
pub fn polyhedron_sphere(planes: &[crate::region::Plane]) -> Vec4 {
    let points = crate::region::vertices(planes);
    let (Some(lo), Some(hi)) = (points.iter().copied().reduce(glam::Vec3::min), points.iter().copied().reduce(glam::Vec3::max)) else {
        return Vec4::new(0.0, 0.0, 0.0, f32::MAX);
    };
    let center = (lo + hi) * 0.5;
    let radius = points.iter().map(|p| p.distance(center)).fold(0.0, f32::max);
    center.extend(radius * (1.0 + 1e-4) + 1e-3)
}

mod insets;
mod packed;
mod selection;
pub use insets::{Inset, MAX_INSETS, inset_features, insets};
use insets::{draw_in_place, kept_holes};
pub use packed::{Atlas, LUT_ATLAS_WIDTH, PackedScene, atlas_layout, gpu_plane, texel, texel_colour};
pub use selection::{companions, constant_bricks, doi_channels, pair_table, unorm_pair};
use selection::{draw_in, pack_selection};

/// The buffers whose whole content fits their uniform copy (`render::upload::
/// UniformCopies`): the shader reads those there. On llvmpipe a storage buffer is read
/// lane by lane, with a branch per lane and word, even where every lane reads one
/// address; a uniform buffer in one load, or one gather.
fn uniform_copies(out: &PackedScene) -> u32 {
    use super::gpu_types::{MAX_UNIFORM_OCCUPANCY, MAX_UNIFORM_PLANES, MAX_UNIFORM_REGIONS, features};
    [
        (out.regions.len() <= MAX_UNIFORM_REGIONS, features::UNIFORM_REGIONS),
        (out.planes.len() <= MAX_UNIFORM_PLANES, features::UNIFORM_PLANES),
        (out.occupancy.len() <= MAX_UNIFORM_OCCUPANCY, features::UNIFORM_OCCUPANCY),
    ]
    .into_iter()
    .filter(|(fits, _)| *fits)
    .fold(0, |acc, (_, feature)| acc | feature)
}
#[cfg(test)]
mod tests;
