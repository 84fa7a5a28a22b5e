//! Two-level volume rendering of segmented data (Hauser, Mroz, Bischi, Gröller,
//! "Two-level volume rendering", IEEE TVCG 7(3), 2001; used for the magic-lens paper's
//! figures 5 and 15).
//!
//! A data volume is split into *objects* by a label volume: every object lists label
//! codes (and optionally a range of data values), and has its own rendering mode and
//! transfer function. Along a ray, the samples form *segments*: runs of consecutive
//! samples in the same object. Rendering has two levels:
//!
//! 1. **Local**: each segment is rendered with its object's mode. DVR-like modes
//!    (DVR, gradient-modulated, context-preserving) composite their samples front to
//!    back; MIP / MinIP / X-ray keep the max / min / mean of the segment's samples and
//!    classify that one value through the object's transfer function when the segment
//!    ends; an iso-surface object contributes its first crossing inside the segment,
//!    shaded and opaque. Hidden objects contribute nothing.
//! 2. **Global**: the segments' results are composited front to back with "over",
//!    `C += (1 − A)·α·c`, `A += (1 − A)·α`, in the order the ray meets them. For DVR
//!    objects local and global compositing are the same operation, so their samples go
//!    straight into the ray's accumulator; a projection segment enters it as one sample
//!    where the segment ends. (Hauser et al. also describe MIP as a global method; Focal
//!    composites globally with "over" only.)
//!
//! Samples in no object belong to *the rest*, rendered with the data volume's own
//! appearance (typically a faint or context-preserving view of everything else).
//!
//! The description ([`Segmentation`], [`Object`]) and the pure object lookup both
//! renderers use ([`ObjectTable`]) are part of a region's look, in
//! [`crate::region::appearance`] (an object's look is an appearance again, so the two
//! cannot live apart). This folder holds what is two-level rendering's alone: [`spec`],
//! how scene files name objects (label codes, names matched in the label table, value
//! ranges) and how they are resolved against the label volume. The CPU reference
//! (`reference::trace`) and the shader (`shaders/focal/two_level.wgsl`)
//! implement the compositing.
//!
//! [`Segmentation`]: crate::region::Segmentation
//! [`Object`]: crate::region::Object
//! [`ObjectTable`]: crate::region::ObjectTable

pub mod spec;
