//! Bricked datasets on the GPU (issue 23, in progress): the brick atlas's slots
//! ([`slots`]) and the page table that maps every brick of every level to a slot
//! ([`page_table`], with the CPU look-up the shader's will be checked against).
//!
//! Not yet wired into the pass: the shader's sampling through the table, the per-frame
//! uploads from [`crate::volume::source::cache::BrickCache`] and the level per sample
//! ([`crate::volume::source::lod`]) come next.

pub mod page_table;
pub mod slots;
