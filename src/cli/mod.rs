//! Subcommands of the `focal` binary.

pub mod info;
pub mod render;
