//! Exploded views of volume data (Bruckner and Gröller, "Exploded Views for Volume
//! Data", IEEE TVCG 12(5), 2006): the parts of a dataset around a selection (the
//! focus) are pushed aside by forces in a rigid-body simulation, so the selection shows
//! while the parts stay recognisable around it.
//!
//! - [`parts`]: convex parts and splitting them (section 3.1);
//! - [`paint`]: painting the selection with a volumetric brush;
//! - [`splitters`]: the axis, depth and line splitters' planes in the current view;
//! - [`forces`]: the return, explosion, viewing and spacing forces (section 3.2,
//!   equations 1–5).
//!
//! - [`points`]: explosion points from the data's and the selection's min-max octrees;
//! - [`regions`]: parts as regions of the ray caster;
//! - [`components`], [`systems`]: parts as rapier rigid bodies, the forces of each step;
//! - [`plugin`]: the schedule that runs them;
//! - [`joints`]: slider, hinge, ball, universal and fixed joints (section 3.3), groups;
//! - [`spec`]: exploded views in scene files;
//! - [`edit`]: exploding, the splitters applied to the parts, undo (the app's edits).
//!
//! The math modules are pure (glam only) and unit-tested against values worked out by
//! hand.

pub mod components;
pub mod edit;
pub mod forces;
pub mod joints;
pub mod paint;
pub mod parts;
pub mod plugin;
pub mod points;
pub mod regions;
pub mod spec;
pub mod splitters;
pub mod systems;

pub use components::{ExplodeTiming, Exploded, ExplosionPoints, Part};
pub use joints::{JointKind, PartJoint};
pub use plugin::ExplodePlugin;
pub use systems::{ExplodeStep, step};
