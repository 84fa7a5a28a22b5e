//! The camera of a scene file: a standard view, an orbit (azimuth and elevation around
//! the visible data) or an explicit pose. `scene::load::camera` turns it into a camera
//! for the data's bounds.

use serde::{Deserialize, Serialize};

use crate::region::View;

/// The camera.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum CameraSpec {
    /// A standard view framing the visible data.
    View {
        view: View,
        #[serde(default)]
        orthographic: bool,
        /// > 1 moves closer.
        #[serde(default = "one")]
        zoom: f32,
    },
    /// Azimuth and elevation around the visible data (see [`crate::region::Orbit`]).
    Orbit {
        azimuth_deg: f32,
        elevation_deg: f32,
        #[serde(default)]
        orthographic: bool,
        #[serde(default = "one")]
        zoom: f32,
    },
    /// An explicit pose.
    LookAt {
        eye: (f32, f32, f32),
        target: (f32, f32, f32),
        #[serde(default = "z_up")]
        up: (f32, f32, f32),
        #[serde(default)]
        orthographic_height: Option<f32>,
        #[serde(default = "fov")]
        fov_deg: f32,
    },
}

fn one() -> f32 {
    1.0
}

fn z_up() -> (f32, f32, f32) {
    (0.0, 0.0, 1.0)
}

fn fov() -> f32 {
    30.0
}

impl Default for CameraSpec {
    fn default() -> Self {
        CameraSpec::View { view: View::Oblique, orthographic: false, zoom: 1.0 }
    }
}
