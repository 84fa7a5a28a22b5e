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

/// A camera that moved less than this (world millimetres; its axes' entries a hundredth
/// of it) is at rest.
pub const AT_REST: f32 = 1e-3;

/// A region whose data moved less than this, in its voxels (a hundredth: invisible), is
/// at rest; its map's linear entries and its planes' normals within [`AT_REST`] / 10.
/// (Rigid bodies settle into motions that never quite stop; what is compared is the
/// state when the view last moved, so a slow drift still adds up to a movement. The
/// log at debug level, `RUST_LOG=focal::interactive=debug`, says what moved and by how
/// much: the exploded head of `tests/app.rs` at degree 6 swings its parts by 2–3.5
/// voxels every few frames for the whole of a 25 s run, so its view stays moving.)
pub const REGION_AT_REST: f32 = 1e-2;

fn near_vec(a: Vec3, b: Vec3, tolerance: f32) -> bool {
    (a - b).abs().max_element() <= tolerance
}

fn near_affine(a: &glam::Affine3A, b: &glam::Affine3A) -> bool {
    let (m, n) = (a.matrix3, b.matrix3);
    near_vec(m.x_axis.into(), n.x_axis.into(), AT_REST * 0.1)
        && near_vec(m.y_axis.into(), n.y_axis.into(), AT_REST * 0.1)
        && near_vec(m.z_axis.into(), n.z_axis.into(), AT_REST * 0.1)
        && near_vec(a.translation.into(), b.translation.into(), REGION_AT_REST)
}

/// Planes within [`REGION_AT_REST`] voxels of a map of `voxels_per_mm`.
fn near_plane(a: &crate::region::Plane, b: &crate::region::Plane, voxels_per_mm: f32) -> bool {
    near_vec(a.normal, b.normal, AT_REST * 0.1) && (a.offset - b.offset).abs() * voxels_per_mm <= REGION_AT_REST
}

/// Two camera transforms within [`AT_REST`] (their axes' entries within a hundredth of it).
fn near_matrix(a: &Mat4, b: &Mat4) -> bool {
    let axes = |m: &Mat4| [m.x_axis, m.y_axis, m.z_axis];
    axes(a).iter().zip(axes(b)).all(|(p, q)| p.abs_diff_eq(q, AT_REST * 1e-2)) && (a.w_axis - b.w_axis).abs().max_element() <= AT_REST
}

/// What differs between two scenes (`None`: the same, their regions' geometry within
/// [`REGION_AT_REST`]).
fn scene_change(a: &RenderScene, b: &RenderScene) -> Option<&'static str> {
    let near_region = |r: &crate::region::Region, s: &crate::region::Region| {
        let m = r.world_to_voxel.matrix3;
        let per_mm = m.x_axis.length().max(m.y_axis.length()).max(m.z_axis.length());
        let near_plane = |p, q| near_plane(p, q, per_mm);
        r.volume == s.volume
            && r.appearance == s.appearance
            && r.planes.len() == s.planes.len()
            && r.holes.len() == s.holes.len()
            && near_affine(&r.world_to_voxel, &s.world_to_voxel)
            && r.planes.iter().zip(&s.planes).all(|(p, q)| near_plane(p, q))
            && r.holes.iter().zip(&s.holes).all(|(h, k)| h.iter().zip(k).all(|(p, q)| near_plane(p, q)))
    };
    if a.regions.len() != b.regions.len() {
        Some("the number of regions")
    } else if !a.regions.iter().zip(&b.regions).all(|(r, s)| near_region(r, s)) {
        let shift = |r: &crate::region::Region, s: &crate::region::Region| {
            (r.world_to_voxel.translation - s.world_to_voxel.translation).abs().max_element()
        };
        let most = a.regions.iter().zip(&b.regions).map(|(r, s)| shift(r, s)).fold(0.0f32, f32::max);
        debug!("regions moved by up to {most} voxels");
        Some("the regions")
    } else if a.appearances != b.appearances {
        Some("the looks")
    } else if !a.equal_but_regions(b) {
        Some("the scene")
    } else {
        None
    }
}

impl Shown {
    /// Whether the view shows something else than `before`: its camera moved or turned
    /// by more than [`AT_REST`], a region by more than [`REGION_AT_REST`], or anything
    /// else changed.
    pub fn moved_from(&self, before: &Shown) -> bool {
        self.what_moved(before).is_some()
    }

    /// What moved since `before` (the first difference found), for the log.
    pub fn what_moved(&self, before: &Shown) -> Option<&'static str> {
        if !near_matrix(&self.camera, &before.camera) {
            Some("the camera")
        } else if self.projection != before.projection || self.pixels != before.pixels {
            Some("the projection")
        } else if self.switches != before.switches {
            Some("the view's switches")
        } else if self.lenses != before.lenses {
            Some("the lenses")
        } else {
            scene_change(&self.scene, &before.scene)
        }
    }
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

    #[test]
    fn motions_below_the_rest_tolerance_are_no_movement() {
        use crate::region::Region;
        use crate::volume::Grid;
        let grid = Grid::centered(glam::UVec3::splat(8), Vec3::ONE);
        let at = |dx: f32| {
            let region = Region::volume_box_at(&grid, glam::Affine3A::from_translation(Vec3::new(dx, 0.0, 0.0)), 0, 0);
            Shown {
                camera: Mat4::from_translation(Vec3::new(0.0, -100.0 + dx, 0.0)),
                projection: Mat4::IDENTITY,
                pixels: Some(UVec2::new(64, 64)),
                switches: crate::dataset::VolumeView::default(),
                lenses: None,
                scene: RenderScene { regions: vec![region], ..Default::default() },
            }
        };
        let rest = at(0.0);
        // A part (and the camera) settling by 10⁻⁵ mm: at rest; by a tenth of a
        // millimetre: moving.
        assert!(!at(1e-5).moved_from(&rest));
        assert!(at(0.1).moved_from(&rest));
        // Anything else that changes is movement.
        let mut switched = at(0.0);
        switched.switches.skip_empty = false;
        assert!(switched.moved_from(&rest));
        let mut resized = at(0.0);
        resized.pixels = Some(UVec2::new(65, 64));
        assert!(resized.moved_from(&rest));
    }
}
