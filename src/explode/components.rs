//! The components of an exploded view.
//!
//! An [`Exploded`] dataset owns parts: each [`Part`] is an entity with a rapier dynamic
//! rigid body and a convex-hull collider whose `Transform` is the part's motion in the
//! dataset's own frame (identity = in place before the explosion). The simulation runs
//! in that frame, so moving the dataset moves its exploded parts with it; the viewer is
//! carried into it for the viewing force.

use std::sync::Arc;

use bevy::prelude::*;

use super::forces::{Coefficients, ExplosionPoint};
use super::parts::Polyhedron;
use crate::region::Appearance;
use crate::volume::{SelectionVolume, Volume};

/// Explodes the dataset entity it is on.
#[derive(Component, Clone)]
pub struct Exploded {
    /// The degree of explosion and the δ of equation 5.
    pub coefficients: Coefficients,
    /// Whether the viewing force acts (figure 5 of the paper: off and on).
    pub viewing: bool,
    /// Parts fade by the viewing force on them (figure 9: a part in the way of the
    /// selection turns transparent; [`super::forces::fade`]).
    pub fade: bool,
    /// The selection: a degree-of-interest volume ([`SelectionVolume::volume`]) placed
    /// by its grid in the dataset's frame; `None`: nothing selected, no explosion points.
    /// The parts draw the data less the selection, the selection its own region (not
    /// moved) with [`Self::selection_look`].
    pub selection: Option<Arc<Volume>>,
    /// How the selection is drawn (`None`: as the dataset).
    pub selection_look: Option<Appearance>,
    /// Most explosion points ([`super::points`]).
    pub max_points: usize,
}

impl Default for Exploded {
    fn default() -> Self {
        Exploded {
            coefficients: Coefficients::default(),
            viewing: false,
            fade: false,
            selection: None,
            selection_look: None,
            max_points: 64,
        }
    }
}

impl Exploded {
    /// Exploded around `selection`.
    pub fn around(selection: &SelectionVolume) -> Exploded {
        Exploded { selection: Some(Arc::new(selection.volume.clone())), ..Default::default() }
    }
}

/// The explosion points of an exploded dataset, in its own frame (recomputed when the
/// selection or the appearance changes).
#[derive(Component, Clone, Debug, Default, PartialEq)]
pub struct ExplosionPoints {
    pub points: Vec<ExplosionPoint>,
}

/// A part's opacity factor by the viewing force (1 unless its dataset fades parts).
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct PartFade(pub f32);

impl Default for PartFade {
    fn default() -> Self {
        PartFade(1.0)
    }
}

/// One part of an exploded dataset.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct Part {
    /// The exploded dataset.
    pub dataset: Entity,
    /// The part at rest, in the dataset's own frame.
    pub rest: Polyhedron,
    /// Hidden parts draw nothing (they still move).
    pub hidden: bool,
    /// Fixed in place (infinite mass: a rapier fixed body).
    pub fixed: bool,
    /// Density relative to the default (mass = volume × density).
    pub density: f32,
    /// Parts with the same group move as one (`None`: on its own).
    pub group: Option<u32>,
}

impl Part {
    pub fn new(dataset: Entity, rest: Polyhedron) -> Part {
        Part { dataset, rest, hidden: false, fixed: false, density: 1.0, group: None }
    }
}

/// The rapier steps per second of exploded views, and how many the app runs at most per
/// frame.
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct ExplodeTiming {
    pub steps_per_second: f32,
    pub max_steps_per_frame: u32,
}

impl Default for ExplodeTiming {
    fn default() -> Self {
        ExplodeTiming { steps_per_second: 120.0, max_steps_per_frame: 4 }
    }
}
