//! Focal: a focus+context volume explorer.
//!
//! The crate is organised by technique (see `../shared/DESIGN.md` and the README):
//! [`volume`] holds the data model, readers and phantoms; [`transfer`] the transfer
//! functions; [`region`] the geometry every renderer shares; [`reference`] the CPU
//! reference renderer. Techniques and the GPU renderer build on these.

pub mod reference;
pub mod region;
pub mod transfer;
pub mod volume;
