//! A lens as the user sets it up: the `Lens` component of a lens entity, also the form
//! scene files store.

use bevy::prelude::Component;
use glam::Vec2;
use serde::{Deserialize, Serialize};

use super::profile::Profile;
use super::sampling::Sampling;
use super::shape::Shape;

/// What a lens does to the rays under it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum LensKind {
    /// Rays bend through a virtual focal point (§3.1).
    Magnifier {
        /// Magnification at the focus depth.
        magnification: f32,
        #[serde(default)]
        profile: Profile,
        /// Distance from the camera where the magnification holds (default: the centre
        /// of the scene along the lens's central ray).
        #[serde(default)]
        focus_depth: Option<f32>,
        /// Distance from the camera to the lens plane (default: close to the eye, so the
        /// magnification barely changes with depth; see `lens::magnifier`).
        #[serde(default)]
        plane_depth: Option<f32>,
    },
    /// Ray starts re-spaced by a sampling-rate function (§3.3).
    Sampling(Sampling),
    /// Angular fisheye (§3.4).
    Angular {
        /// Field of view across the lens, degrees (up to 360).
        field_of_view: f32,
        /// The whole view is the fisheye (a circle touching the top and bottom).
        #[serde(default)]
        whole_view: bool,
    },
}

/// A lens on a camera's image plane.
#[derive(Component, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lens {
    pub kind: LensKind,
    #[serde(default = "default_shape")]
    pub shape: Shape,
    /// Centre in lens units (normalised device coordinates with x scaled by the aspect
    /// ratio: one unit is half the image height).
    #[serde(default)]
    pub center: Vec2,
    /// Radius of the focus region (half side for a square), lens units.
    #[serde(default = "default_radius")]
    pub radius: f32,
    /// Width of the transition border, lens units.
    #[serde(default = "default_border")]
    pub border: f32,
    #[serde(default = "default_true")]
    pub enabled: bool,
}

fn default_shape() -> Shape {
    Shape::Circle
}
fn default_radius() -> f32 {
    0.3
}
fn default_border() -> f32 {
    0.15
}
fn default_true() -> bool {
    true
}

impl Lens {
    /// A circular magnifier with a cubic border.
    pub fn magnifier(center: Vec2, radius: f32, border: f32, magnification: f32) -> Lens {
        Lens {
            kind: LensKind::Magnifier { magnification, profile: Profile::Cubic, focus_depth: None, plane_depth: None },
            shape: Shape::Circle,
            center,
            radius,
            border,
            enabled: true,
        }
    }

    /// Short name of the kind.
    pub fn kind_name(&self) -> &'static str {
        match self.kind {
            LensKind::Magnifier { .. } => "magnifier",
            LensKind::Sampling(_) => "sampling",
            LensKind::Angular { .. } => "angular",
        }
    }

    /// Checks the parameters; the message names the problem.
    pub fn validate(&self) -> Result<(), String> {
        let finite = self.center.is_finite() && self.radius.is_finite() && self.border.is_finite();
        if !finite || self.radius <= 0.0 || self.border < 0.0 {
            return Err(format!(
                "a lens needs a finite centre, a positive radius and a border ≥ 0 (radius {}, border {})",
                self.radius, self.border
            ));
        }
        self.shape.validate()?;
        match &self.kind {
            LensKind::Magnifier { magnification, focus_depth, plane_depth, .. } => {
                if !(magnification.is_finite() && (1.0..=64.0).contains(magnification)) {
                    return Err(format!("magnification must lie in [1, 64], not {magnification}"));
                }
                if focus_depth.is_some_and(|d| !(d.is_finite() && d > 0.0)) || plane_depth.is_some_and(|d| !d.is_finite()) {
                    return Err("focus and plane depths must be finite (and the focus depth positive)".into());
                }
                if let (Some(f), Some(p)) = (focus_depth, plane_depth)
                    && p >= f
                {
                    return Err(format!("the lens plane ({p}) must lie before the focus depth ({f})"));
                }
                Ok(())
            }
            LensKind::Sampling(s) => {
                if matches!(self.shape, Shape::Polygon(_) | Shape::Feature(_)) {
                    return Err("a sampling lens is a circle or a square".into());
                }
                s.validate()
            }
            LensKind::Angular { field_of_view, .. } => {
                if matches!(self.shape, Shape::Polygon(_) | Shape::Square | Shape::Feature(_)) {
                    return Err("an angular lens is a circle".into());
                }
                if !(field_of_view.is_finite() && *field_of_view > 0.0 && *field_of_view <= 360.0) {
                    return Err(format!("the angular field of view must lie in (0, 360] degrees, not {field_of_view}"));
                }
                Ok(())
            }
        }
    }
}
