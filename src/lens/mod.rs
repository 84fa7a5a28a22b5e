//! Magic volume lenses: "The Magic Volume Lens" (Wang, Zhao, Mueller, Kaufman, IEEE Vis
//! 2005) with the border profiles of LaMar, Hamann and Joy (2001).
//!
//! A lens is an entity with a [`Lens`] component: its kind, shape and place on the
//! image plane of the views. Each frame [`systems::resolve_view_lenses`] resolves the
//! lenses for every volume camera into a [`ViewLenses`] component (pure math in
//! [`stack`]); the renderer packs it into the view uniform and the shader bends, re-spaces
//! or turns the rays in its ray-generation stage, as the CPU reference does with
//! [`stack::lens_ray`].
//!
//! - [`magnifier`]: rays through a virtual focal point (§3.1, eq. 1–3);
//! - [`profile`]: simple, linear and cubic borders (LaMar et al.);
//! - [`shape`]: circle, square and drawn outlines with their distance fields;
//! - [`sampling`]: the sampling-rate lens (§3.3, eq. 5–7);
//! - [`angular`]: the angular fisheye (§3.4);
//! - [`antialias`]: mip levels where a lens compresses (eq. 4);
//! - [`feature`]: the feature lens, shaped by a segmented feature's silhouette (§3.2);
//! - [`handles`]: grabbing, dragging and drawing lenses in the viewport;
//! - [`lattice`]: the lens-distorted lattice overlay;
//! - [`screen`]: the image plane in lens coordinates.

pub mod angular;
pub mod antialias;
pub mod feature;
pub mod handles;
pub mod lattice;
pub mod magnifier;
pub mod profile;
pub mod sampling;
pub mod screen;
pub mod shape;
pub mod spec;
pub mod stack;
pub mod systems;

pub use profile::Profile;
pub use sampling::Sampling;
pub use screen::Screen;
pub use shape::Shape;
pub use spec::{Lens, LensKind};
pub use stack::{MAX_LENSES, ResolvedLens, lens_ray, local_magnification};
pub use systems::{LensPlugin, ViewLenses};
