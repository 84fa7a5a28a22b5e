//! The state of a view whose resolution adapts: the movement it detects and the scale
//! it draws at ([`super::controller`] chooses the scales).

use bevy::prelude::*;

use super::controller::{at_rest, quantise, while_moving};
use crate::lens::systems::ViewLenses;
use crate::region::RenderScene;

/// Holds a camera's frame time while it moves by drawing fewer pixels.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct InteractiveResolution {
    /// Off: every frame draws every pixel.
    pub enabled: bool,
    /// The frame time to hold while the view moves, in milliseconds.
    pub target_ms: f32,
    /// The lowest fraction of the pixels per axis.
    pub min: f32,
    /// Milliseconds without change after which the view counts as at rest.
    pub rest_ms: f32,
    /// The fraction drawn now.
    pub scale: f32,
    /// The fraction the last movement ended at, where the next one starts.
    pub moving_scale: f32,
    /// Whether the view moved in the last `rest_ms`.
    pub moving: bool,
    /// Milliseconds since what the view shows last changed.
    pub since_change_ms: f32,
    /// Frames of different ray jitter averaged into the picture at rest (at every
    /// pixel; 1: none), [`crate::dataset::view::Accumulate`].
    pub accumulate: u32,
    /// Frames drawn at rest at every pixel since the view last moved (or streamed
    /// bricks changed the picture).
    pub still_frames: u32,
    /// The streaming counts of the last frame: when they change, the average starts anew.
    pub last_stream: Option<crate::streaming::bricked::StreamCounts>,
    /// What the view showed last frame.
    pub last: Option<Shown>,
}

impl Default for InteractiveResolution {
    fn default() -> Self {
        Self {
            enabled: true,
            target_ms: 50.0,
            min: crate::dataset::view::MIN_RESOLUTION,
            rest_ms: 150.0,
            scale: 1.0,
            moving_scale: 0.5,
            moving: false,
            since_change_ms: f32::INFINITY,
            accumulate: 16,
            still_frames: 0,
            last_stream: None,
            last: None,
        }
    }
}

impl InteractiveResolution {
    /// The frame of the average over jittered frames this one is, once the view rests at
    /// every pixel (counting the frames there), else `None` (and the count starts anew).
    pub fn accumulation(&mut self, jitter: bool) -> Option<crate::dataset::view::Accumulate> {
        if !self.enabled || self.moving || self.scale < 1.0 || self.accumulate < 2 || !jitter {
            self.still_frames = 0;
            return None;
        }
        let index = self.still_frames;
        self.still_frames = self.still_frames.saturating_add(1);
        Some(crate::dataset::view::Accumulate { index, frames: self.accumulate })
    }

    /// One frame of the state machine: the scale to draw and whether the view moves.
    pub fn step(&mut self, changed: bool, frame_ms: f32) -> (f32, bool) {
        if !self.enabled {
            self.since_change_ms = f32::INFINITY;
            return (1.0, false);
        }
        self.since_change_ms = if changed { 0.0 } else { self.since_change_ms + frame_ms.max(0.0) };
        let moving = self.since_change_ms < self.rest_ms;
        if moving {
            // (The first frame of a movement measured a frame at rest: start where the last
            // movement ended instead.)
            if self.moving {
                self.moving_scale = while_moving(self.scale, frame_ms, self.target_ms, self.min);
            }
            (quantise(self.moving_scale, self.min), true)
        } else {
            (at_rest(self.scale), false)
        }
    }
}

/// What a view shows: when any of it changes, the view moves.
#[derive(Clone, Debug, PartialEq)]
pub struct Shown {
    pub camera: Mat4,
    pub projection: Mat4,
    /// The view's pixels (a resized viewport of the same aspect keeps its projection).
    pub pixels: Option<UVec2>,
    /// The view's switches (with the resolution and jitter seed this system sets left
    /// out): a switch turned at rest starts a new picture.
    pub switches: crate::dataset::VolumeView,
    pub lenses: Option<ViewLenses>,
    pub scene: RenderScene,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn movement_lowers_the_scale_and_rest_refines_it() {
        let mut s = InteractiveResolution::default();
        // At rest from the start: every pixel.
        assert_eq!(s.step(false, 400.0), (1.0, false));
        s.scale = 1.0;
        // A drag starts: the last movement's scale at once, then the controller.
        let first = s.step(true, 400.0);
        assert_eq!(first, (0.5, true));
        (s.scale, s.moving) = first;
        let second = s.step(true, 400.0);
        assert!(second.1 && second.0 < 0.5, "{second:?}");
        (s.scale, s.moving) = second;
        // The drag pauses for less than rest_ms: still moving, the scale kept low.
        let paused = s.step(false, 100.0);
        assert!(paused.1 && paused.0 <= second.0, "{paused:?}");
        (s.scale, s.moving) = paused;
        // At rest: doubling every frame to 1.
        let mut scales = Vec::new();
        for _ in 0..6 {
            let next = s.step(false, 100.0);
            (s.scale, s.moving) = next;
            scales.push(next.0);
        }
        assert!(!s.moving && scales.last() == Some(&1.0), "{scales:?}");
        assert!(scales.windows(2).all(|w| w[1] >= w[0]), "{scales:?}");
        // The next movement starts where this one ended.
        assert_eq!(s.step(true, 100.0).0, quantise(paused.0, s.min));
        // Switched off: every pixel, whatever moves.
        s.enabled = false;
        assert_eq!(s.step(true, 400.0), (1.0, false));
    }
}
