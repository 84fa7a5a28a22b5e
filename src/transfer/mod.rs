//! Transfer functions: piecewise-linear colour and opacity over real values, presets
//! from `assets/transfer/`, baked lookup tables, opacity correction for the step size,
//! and per-label styles for label volumes. Colours are display (sRGB) values, baked to
//! linear light for compositing ([`color`]).

pub mod color;
pub mod function;
pub mod labels;
pub mod lut;
pub mod opacity;
pub mod presets;
pub mod visible;

pub use function::{ColorPoint, OpacityPoint, TransferFunction, ValueSpace};
pub use labels::{LabelStyle, LabelTransfer};
pub use lut::Lut;
