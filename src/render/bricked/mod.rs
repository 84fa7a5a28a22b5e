//! Bricked datasets on the GPU: the brick atlas's slots ([`slots`]), the page table of
//! each bricked volume ([`page_table`], a tree of the drawn bricks with the CPU look-up
//! the shader's follows), the marking of the packed regions that sample through it
//! ([`mark`]), and the per-frame uploads within a budget ([`atlas`]).
//!
//! The ray caster (`shaders/focal/bricked.wgsl`) samples a bricked region at level-0
//! index `q = (q_C + ½)·2^C − ½` of its coarse index `q_C`: the page table gives the
//! finest drawn brick holding `q` (or the coarse volume in the volume atlas), kept per
//! ray while `q` stays in the box the answer holds for. A ray steps at the level its
//! pixel footprint asks for where it enters the region (lenses included).

pub mod atlas;
pub mod mark;
pub mod page_table;
pub mod slots;
