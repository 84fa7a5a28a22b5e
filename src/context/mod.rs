//! Context-preserving volume rendering (Bruckner, Grimm, Kanitsar, Gröller 2005): a
//! rendering mode whose opacity fades flat, lit, near and unoccluded parts so the
//! inside shows through while the edges of the outside stay as context.
//!
//! [`model`] holds equation 5, Schlick's approximation (equation 7) and the normalised
//! eye distance as pure functions; the parameters (κt, κs, the power's evaluation) are
//! part of a region's [`crate::region::Appearance`], the data-dependent λt, λs
//! (section 5) two channels of its [`crate::transfer::TransferFunction`]. The CPU
//! reference (`reference::trace`) and the shader (`shaders/focal/context.wgsl`)
//! evaluate the same function.

pub mod model;

pub use model::{ContextParams, Power};
