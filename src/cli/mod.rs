//! Subcommands of the `focal` binary.

pub mod bench;
pub mod convert;
pub mod info;
pub mod render;
pub mod slice;
