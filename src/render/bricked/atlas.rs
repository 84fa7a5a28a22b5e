//! The brick atlas on the GPU and the page buffer, updated every frame that streaming
//! hands the renderer new frames.
//!
//! One 3D texture of [`Slots`] (8-bit, or 16-bit where a bricked source has 16-bit
//! codes, in the volume atlas's format so both normalise alike) sized by the GPU
//! budget, and one storage buffer of `u32` words: the slot grid (4), `1 / texture size`
//! as float bits (3) and the word where the sub-block masks start, the directory (each
//! bricked volume's table start), the masks (two words per slot: its brick's 64
//! sub-blocks), then the tables ([`PageTree`], block offsets relative to their table).
//! The drawn bricks not yet in the atlas are uploaded coarse first, at most the budget's
//! per frame; the rest are drawn from coarser levels until a later frame brings them
//! (the status counts them, and the headless render waits for none to be left).

use std::collections::HashMap;
use std::sync::Arc;

use bevy::prelude::*;
use bevy::render::render_resource::{
    Buffer, BufferDescriptor, BufferUsages, Extent3d, Origin3d, TexelCopyBufferLayout, TexelCopyTextureInfo, Texture, TextureAspect,
    TextureFormat, TextureView, TextureViewDescriptor,
};
use bevy::render::renderer::{RenderAdapter, RenderDevice, RenderQueue};

use super::page_table::{Page, PageTree};
use super::slots::Slots;
use crate::render::extract::ExtractedScene;
use crate::render::upload::{GpuScene, sampled_3d, sixteen_bit_formats, texel16};
use crate::streaming::bricked::{BrickFrame, StreamStatus};
use crate::volume::Voxels;
use crate::volume::source::cache::BrickKey;

/// Words before the directory.
pub const PAGE_HEADER: usize = 8;

/// Words before each volume's page tree: the gradient normalisation of its levels
/// `0 … C` as `f32` bits (`BrickFrame::gradient_norms`; levels are 4 bits of a page
/// word, so at most 16).
pub const GRADIENT_NORMS: usize = 16;

/// Frames without any bricked volume after which the atlas is given back (hiding a
/// bricked volume for a moment, or switching between it and another, keeps its bricks).
pub const RELEASE_AFTER_FRAMES: u32 = 600;

/// A brick of some dataset (its coarse volume's address) in the atlas.
type SlotKey = (usize, BrickKey);

/// The brick atlas, its slots and the page buffer.
#[derive(Resource, Default)]
pub struct BrickAtlas {
    texture: Option<(Texture, TextureFormat)>,
    pub view: Option<TextureView>,
    slots: Option<Slots<SlotKey>>,
    pub pages: Option<Buffer>,
    capacity: u64,
    /// Consecutive frames without a bricked volume.
    idle_frames: u32,
    /// Whether every coarse-level brick of this frame's bricked volumes is in the atlas
    /// or empty (each of their samples then reads the atlas).
    pub coarse_in_atlas: bool,
    /// What the page buffer was last built from, where every drawn brick found its slot.
    built: Option<Built>,
    /// The cache size the device refused (not asked for again; the main world halves
    /// the budget).
    refused: Option<UVec3>,
}

/// The frames a page buffer was built from: each bricked volume's place in the
/// directory, its volume and the streaming frame (its bricks' lists held, so that a new
/// frame's lists cannot take their addresses). Streaming hands the renderer the same
/// lists while nothing changed (`streaming::unchanged`): the slots, masks and page
/// tables are then those already on the GPU.
struct Built(Vec<(usize, Arc<crate::volume::Volume>, BrickFrame)>);

impl Built {
    fn of(frames: &[(usize, &BrickFrame)], extracted: &ExtractedScene) -> Option<Built> {
        let volume = |v: usize| extracted.scene.volumes.get(v).cloned();
        frames.iter().map(|(v, f)| Some((*v, volume(*v)?, (*f).clone()))).collect::<Option<Vec<_>>>().map(Built)
    }

    fn holds(&self, frames: &[(usize, &BrickFrame)], extracted: &ExtractedScene) -> bool {
        self.0.len() == frames.len()
            && self.0.iter().zip(frames).all(|((v, volume, built), (w, frame))| {
                v == w
                    && extracted.scene.volumes.get(*w).is_some_and(|x| Arc::ptr_eq(x, volume))
                    && Arc::ptr_eq(&built.drawn, &frame.drawn)
                    && Arc::ptr_eq(&built.empty, &frame.empty)
                    && built.gradient_norms == frame.gradient_norms
                    && built.table_dims == frame.table_dims
            })
    }
}

impl BrickAtlas {
    pub fn ready(&self) -> bool {
        self.view.is_some() && self.pages.is_some()
    }
}

/// Texels of a brick's codes in `format` (8-bit codes as they are; else as the volume
/// atlas writes them).
fn texels(voxels: &Voxels, format: TextureFormat) -> Vec<u8> {
    if format == TextureFormat::R8Unorm {
        return voxels.as_bytes().to_vec();
    }
    (0..voxels.len()).flat_map(|i| texel16(voxels.code(i), voxels.bits(), format)).collect()
}

/// Places, uploads and tables the bricks the main world drew this frame.
pub fn upload_bricks(
    extracted: Option<Res<ExtractedScene>>,
    gpu: Res<GpuScene>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    adapter: Res<RenderAdapter>,
    (status, health): (Res<StreamStatus>, Res<crate::render::health::RenderHealth>),
    mut atlas: ResMut<BrickAtlas>,
) {
    let Some(extracted) = extracted else { return };
    let frames: Vec<(usize, &BrickFrame)> =
        gpu.bricked_directory.iter().filter_map(|&v| extracted.bricked.get(v).and_then(Option::as_ref).map(|f| (v, f))).collect();
    let format = if frames.iter().any(|(_, f)| f.bits == 16) { sixteen_bit_formats(&adapter)[0] } else { TextureFormat::R8Unorm };
    let bpp = if format == TextureFormat::R8Unorm { 1 } else { 2 };
    let edge = frames.first().map_or(1, |(_, f)| f.layout.stored());
    let want_slots = !frames.is_empty();
    atlas.idle_frames = if want_slots { 0 } else { atlas.idle_frames.saturating_add(1) };
    let release = atlas.idle_frames >= RELEASE_AFTER_FRAMES;
    let wanted = || Slots::new(edge, device.limits().max_texture_dimension_3d, extracted.budget.gpu_bytes, bpp);
    let stale = match (&atlas.texture, &atlas.slots) {
        // (After a refusal, the halved budget's size is tried when it differs.)
        (Some((_, f)), Some(s)) if want_slots => {
            *f != format || s.edge != edge || atlas.refused.is_some_and(|r| r != wanted().texture_size())
        }
        (Some(_), Some(s)) => release && s.len() > 1,
        _ => true,
    };
    if stale {
        // (A size the device refused: one slot of the bricks' size, so the pass still
        // binds an atlas, in-memory volumes are drawn and streamed ones coarser, until
        // the halved budget asks for less.)
        let slots = match want_slots.then(wanted) {
            Some(s) if atlas.refused != Some(s.texture_size()) => s,
            Some(_) => Slots::new(edge, edge, 0, bpp),
            None => Slots::new(1, 1, 1, 1),
        };
        let size = slots.texture_size();
        let make = |size: UVec3| {
            let texture = device.create_texture(&sampled_3d("focal brick cache atlas", size, format));
            let view = texture.create_view(&TextureViewDescriptor::default());
            (texture, view)
        };
        let made = crate::render::health::scoped(&device, || make(size));
        let (texture, view, slots) = match made {
            Ok((texture, view)) => {
                if slots.len() > 1 {
                    atlas.refused = None;
                }
                (texture, view, slots)
            }
            Err(reason) => {
                let s = size.as_u64vec3();
                health.refuse(crate::render::health::Refusal {
                    what: crate::render::health::Refused::BrickCache,
                    reason,
                    largest_edge: size.max_element(),
                    bytes: s.x * s.y * s.z * bpp as u64,
                });
                atlas.refused = Some(size);
                let one = Slots::new(edge, edge, 0, bpp);
                let (texture, view) = make(one.texture_size());
                (texture, view, one)
            }
        };
        atlas.view = Some(view);
        atlas.texture = Some((texture, format));
        atlas.slots = Some(slots);
    }
    if stale {
        atlas.built = None;
    }
    if atlas.built.as_ref().is_some_and(|b| b.holds(&frames, &extracted)) {
        return;
    }
    let (Some((texture, _)), Some(mut slots)) = (atlas.texture.clone(), atlas.slots.take()) else { return };
    slots.next_frame();
    let size = slots.texture_size().as_vec3();
    let mut words: Vec<u32> = vec![slots.grid.x, slots.grid.y, slots.grid.z, slots.edge];
    words.extend((1.0 / size).to_array().map(f32::to_bits));
    let dir_at = PAGE_HEADER;
    let masks_at = dir_at + frames.len();
    words.push(masks_at as u32);
    words.resize(masks_at + 2 * slots.len(), 0);
    let (mut uploads, mut not_uploaded, mut not_placed) = (0usize, 0usize, 0usize);
    let mut coarse_in_atlas = true;
    for (i, (v, frame)) in frames.iter().enumerate() {
        let id = extracted.scene.volumes.get(*v).map_or(0, |a| Arc::as_ptr(a) as usize);
        let mut drawn: HashMap<BrickKey, (Page, u64)> = frame.empty.iter().map(|(k, c)| (*k, (Page::Empty(*c), 0))).collect();
        for (k, data, mask) in frame.drawn.iter() {
            if let Some(s) = slots.touch((id, *k)) {
                drawn.insert(*k, (Page::Slot(s), *mask));
                continue;
            }
            if uploads >= extracted.budget.uploads_per_frame {
                not_uploaded += 1;
                continue;
            }
            let Some((s, _)) = slots.place((id, *k)) else {
                // Every slot holds a brick of this frame: the rest are drawn coarser.
                not_placed += 1;
                continue;
            };
            let o = slots.origin(s);
            let n = frame.layout.stored();
            queue.write_texture(
                TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: 0,
                    origin: Origin3d { x: o.x, y: o.y, z: o.z },
                    aspect: TextureAspect::All,
                },
                &texels(&data.voxels, format),
                TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(n * bpp), rows_per_image: Some(n) },
                Extent3d { width: n, height: n, depth_or_array_layers: n },
            );
            uploads += 1;
            drawn.insert(*k, (Page::Slot(s), *mask));
        }
        for (page, mask) in drawn.values() {
            if let Page::Slot(s) = page {
                words[masks_at + 2 * *s as usize] = *mask as u32;
                words[masks_at + 2 * *s as usize + 1] = (*mask >> 32) as u32;
            }
        }
        coarse_in_atlas &= frame.drawn.iter().all(|(k, ..)| k.level as usize != frame.coarse || drawn.contains_key(k));
        let tree = PageTree::build(&frame.table_dims, frame.layout, &drawn, slots.grid);
        let norm = |k: usize| frame.gradient_norms.get(k.min(frame.coarse)).copied().unwrap_or(1.0);
        words.extend((0..GRADIENT_NORMS).map(|k| norm(k).to_bits()));
        words[dir_at + i] = words.len() as u32;
        words.extend(tree.words);
    }
    status.update(|c| {
        c.on_gpu = slots.held();
        c.not_uploaded = not_uploaded;
    });
    atlas.slots = Some(slots);
    atlas.coarse_in_atlas = coarse_in_atlas;
    atlas.built = if not_uploaded + not_placed == 0 { Built::of(&frames, &extracted) } else { None };
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    if atlas.pages.is_none() || atlas.capacity < bytes.len() as u64 {
        let capacity = (bytes.len() as u64).next_power_of_two().max(256);
        atlas.pages = Some(device.create_buffer(&BufferDescriptor {
            label: Some("focal page tables"),
            size: capacity,
            usage: BufferUsages::STORAGE | BufferUsages::COPY_DST,
            mapped_at_creation: false,
        }));
        atlas.capacity = capacity;
    }
    if let Some(pages) = &atlas.pages {
        queue.write_buffer(pages, 0, &bytes);
    }
}
