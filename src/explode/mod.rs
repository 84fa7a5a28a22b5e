//! Exploded views of volume data (Bruckner and Gröller, "Exploded Views for Volume
//! Data", IEEE TVCG 12(5), 2006): the parts of a dataset around a selection (the
//! focus) are pushed aside by forces in a rigid-body simulation, so the selection shows
//! while the parts stay recognisable around it.
//!
//! - [`parts`]: convex parts and splitting them (section 3.1);
//! - [`splitters`]: the axis, depth and line splitters' planes in the current view;
//! - [`forces`]: the return, explosion, viewing and spacing forces (section 3.2,
//!   equations 1–5).
//!
//! All three are pure (glam only) and unit-tested against values worked out by hand.

pub mod forces;
pub mod parts;
pub mod splitters;
