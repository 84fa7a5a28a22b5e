//! The orbit camera of the viewport: the conventions of medical and scientific viewers.
//!
//! Left-drag orbits around the target (azimuth around the superior axis, elevation
//! clamped short of the poles), right- or middle-drag pans in the view plane, the wheel
//! zooms (perspective: distance; orthographic: view height), double-click centres on
//! the picked point. The pure state ([`OrbitCamera`]) is separate from the systems so it
//! can be tested without a window.

use bevy::camera::ScalingMode;
use bevy::input::mouse::{AccumulatedMouseMotion, AccumulatedMouseScroll, MouseScrollUnit};
use bevy::prelude::*;
use bevy::window::PrimaryWindow;

use crate::region::{Camera as FocalCamera, Orbit, Projection as FocalProjection, View};

/// Orbit state of a camera.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct OrbitCamera {
    pub target: Vec3,
    pub azimuth_deg: f32,
    pub elevation_deg: f32,
    pub distance: f32,
    pub orthographic: bool,
    /// Vertical field of view (perspective).
    pub fov_deg: f32,
    /// Fly-through: drags turn the view about the eye, the wheel and the arrow keys move
    /// the eye (it may enter the volume).
    pub fly: bool,
    /// Fly-through speed, world units per second (a quarter of the scene's diagonal).
    pub fly_speed: f32,
}

impl Default for OrbitCamera {
    fn default() -> Self {
        Self {
            target: Vec3::ZERO,
            azimuth_deg: 35.0,
            elevation_deg: 20.0,
            distance: 600.0,
            orthographic: false,
            fov_deg: 30.0,
            fly: false,
            fly_speed: 100.0,
        }
    }
}

/// Degrees of orbit per pixel of drag.
const ORBIT_SPEED: f32 = 0.35;
/// Zoom factor per wheel line.
const ZOOM_STEP: f32 = 1.12;

impl OrbitCamera {
    /// The height of the view at the target (the orthographic view height).
    pub fn view_height(&self) -> f32 {
        2.0 * self.distance * (self.fov_deg.to_radians() * 0.5).tan()
    }

    pub fn camera(&self) -> FocalCamera {
        let projection = if self.orthographic {
            FocalProjection::Orthographic { height: self.view_height() }
        } else {
            FocalProjection::Perspective { fov_y: self.fov_deg.to_radians() }
        };
        Orbit { target: self.target, azimuth_deg: self.azimuth_deg, elevation_deg: self.elevation_deg, distance: self.distance, projection }
            .camera()
    }

    /// Rotates by a drag of `delta` pixels.
    pub fn orbit(&mut self, delta: Vec2) {
        self.azimuth_deg = (self.azimuth_deg - delta.x * ORBIT_SPEED).rem_euclid(360.0);
        self.elevation_deg = (self.elevation_deg + delta.y * ORBIT_SPEED).clamp(-89.0, 89.0);
    }

    /// Fly-through: turns the view about the eye by a drag of `delta` pixels (the
    /// view follows the pointer, as when turning one's head).
    pub fn look(&mut self, delta: Vec2) {
        let eye = self.camera().position;
        self.orbit(delta);
        let back = (self.camera().position - self.target).normalize_or(Vec3::Y);
        self.target = eye - back * self.distance;
    }

    /// Fly-through: moves the eye (and the target) by `right`, `up` and `forward` world
    /// units along the camera's axes.
    pub fn fly_by(&mut self, right: f32, up: f32, forward: f32) {
        let cam = self.camera();
        self.target += cam.right() * right + cam.up() * up + cam.forward() * forward;
    }

    /// Moves the target so the scene follows a drag of `delta` pixels in a viewport
    /// `height` pixels tall.
    pub fn pan(&mut self, delta: Vec2, height: f32) {
        let cam = self.camera();
        let per_pixel = self.view_height() / height.max(1.0);
        self.target += (-cam.right() * delta.x + cam.up() * delta.y) * per_pixel;
    }

    /// Zooms by `lines` wheel lines (positive: closer).
    pub fn zoom(&mut self, lines: f32) {
        self.distance = (self.distance / ZOOM_STEP.powf(lines)).clamp(1.0, 1.0e6);
    }

    /// Looks from a standard side at a box, framing it.
    pub fn frame(&mut self, view: View, lo: Vec3, hi: Vec3, aspect: f32) {
        let framed = view.frame_box(lo, hi, aspect, false);
        self.target = (lo + hi) * 0.5;
        self.distance = (framed.position - self.target).length();
        let dir = (framed.position - self.target).normalize_or(Vec3::Y);
        self.elevation_deg = dir.z.clamp(-1.0, 1.0).asin().to_degrees().clamp(-89.0, 89.0);
        self.azimuth_deg = (-dir.x).atan2(dir.y).to_degrees().rem_euclid(360.0);
    }

    /// Takes the pose and projection of `cam` (a scene's camera), orbiting about the
    /// point of its view axis nearest to `centre`. The orbit keeps +z up: a rolled
    /// camera loses its roll.
    pub fn set_from(&mut self, cam: &FocalCamera, centre: Vec3) {
        let forward = cam.forward();
        let along = (centre - cam.position).dot(forward);
        let distance = if along > 1e-3 { along } else { (centre - cam.position).length().max(1.0) };
        self.target = cam.position + forward * distance;
        self.distance = distance;
        let dir = -forward;
        self.elevation_deg = dir.z.clamp(-1.0, 1.0).asin().to_degrees().clamp(-89.0, 89.0);
        self.azimuth_deg = (-dir.x).atan2(dir.y).to_degrees().rem_euclid(360.0);
        match cam.projection {
            FocalProjection::Perspective { fov_y } => {
                self.orthographic = false;
                self.fov_deg = fov_y.to_degrees();
            }
            FocalProjection::Orthographic { height } => {
                self.orthographic = true;
                self.fov_deg = (2.0 * (height * 0.5 / distance).atan()).to_degrees();
            }
        }
    }

    /// The Bevy transform and projection of this camera.
    pub fn bevy(&self) -> (Transform, Projection) {
        let cam = self.camera();
        let projection = match cam.projection {
            FocalProjection::Perspective { fov_y } => Projection::Perspective(PerspectiveProjection { fov: fov_y, near: 0.5, ..default() }),
            FocalProjection::Orthographic { height } => Projection::Orthographic(OrthographicProjection {
                near: -1.0e5,
                far: 1.0e5,
                scaling_mode: ScalingMode::FixedVertical { viewport_height: height },
                ..OrthographicProjection::default_3d()
            }),
        };
        (Transform { translation: cam.position, rotation: cam.rotation, scale: Vec3::ONE }, projection)
    }
}

/// Whether the pointer belongs to the 3D viewport (not to a panel), and the viewport's
/// height in pixels; written by the UI each frame.
#[derive(Resource, Clone, Copy, Debug, Default)]
pub struct PointerInViewport {
    pub inside: bool,
    pub height: f32,
    /// A lens took the button press (the drag is the lens's, not the camera's).
    pub press_taken: bool,
    /// A lens took the wheel this frame.
    pub wheel_taken: bool,
}

/// Applies mouse input to the orbit camera.
pub fn orbit_input(
    buttons: Res<ButtonInput<MouseButton>>,
    motion: Res<AccumulatedMouseMotion>,
    scroll: Res<AccumulatedMouseScroll>,
    pointer: Res<PointerInViewport>,
    mut dragging: Local<Option<MouseButton>>,
    mut cams: Query<&mut OrbitCamera>,
) {
    let pressed = [MouseButton::Left, MouseButton::Right, MouseButton::Middle].into_iter().find(|b| buttons.just_pressed(*b));
    if let Some(b) = pressed
        && pointer.inside
        && !pointer.press_taken
    {
        *dragging = Some(b);
    }
    if dragging.is_some_and(|b| !buttons.pressed(b)) {
        *dragging = None;
    }
    let Ok(mut orbit) = cams.single_mut() else { return };
    match *dragging {
        Some(MouseButton::Left) if motion.delta != Vec2::ZERO && orbit.fly => orbit.look(motion.delta),
        Some(MouseButton::Left) if motion.delta != Vec2::ZERO => orbit.orbit(motion.delta),
        Some(MouseButton::Right | MouseButton::Middle) if motion.delta != Vec2::ZERO => orbit.pan(motion.delta, pointer.height),
        _ => {}
    }
    if pointer.inside && !pointer.wheel_taken && scroll.delta.y != 0.0 {
        let lines = wheel_lines(&scroll);
        if orbit.fly {
            let step = orbit.fly_speed * 0.1 * lines;
            orbit.fly_by(0.0, 0.0, step);
        } else {
            orbit.zoom(lines);
        }
    }
}

/// Wheel turns in lines.
pub fn wheel_lines(scroll: &AccumulatedMouseScroll) -> f32 {
    match scroll.unit {
        MouseScrollUnit::Line => scroll.delta.y,
        MouseScrollUnit::Pixel => scroll.delta.y / MouseScrollUnit::SCROLL_UNIT_CONVERSION_FACTOR,
    }
}

/// Fly-through keys: arrows move forward, back and sideways, Page Up / Down up and down,
/// Shift four times faster.
pub fn fly_keys(
    keys: Res<ButtonInput<KeyCode>>,
    time: Res<Time<Real>>,
    mut contexts: bevy_egui::EguiContexts,
    mut cams: Query<&mut OrbitCamera>,
) {
    if contexts.ctx_mut().is_ok_and(|c| c.egui_wants_keyboard_input()) {
        return;
    }
    let Ok(mut orbit) = cams.single_mut() else { return };
    if !orbit.fly {
        return;
    }
    let axis = |plus: KeyCode, minus: KeyCode| keys.pressed(plus) as i32 as f32 - keys.pressed(minus) as i32 as f32;
    let (right, up, forward) = (
        axis(KeyCode::ArrowRight, KeyCode::ArrowLeft),
        axis(KeyCode::PageUp, KeyCode::PageDown),
        axis(KeyCode::ArrowUp, KeyCode::ArrowDown),
    );
    if right == 0.0 && up == 0.0 && forward == 0.0 {
        return;
    }
    let boost = if keys.any_pressed([KeyCode::ShiftLeft, KeyCode::ShiftRight]) { 4.0 } else { 1.0 };
    let step = orbit.fly_speed * boost * time.delta_secs().min(0.1);
    orbit.fly_by(right * step, up * step, forward * step);
}

/// Writes the orbit state into the camera's transform and projection.
pub fn apply_orbit(mut cams: Query<(&OrbitCamera, &mut Transform, &mut Projection), Changed<OrbitCamera>>) {
    for (orbit, mut transform, mut projection) in &mut cams {
        let (t, p) = orbit.bevy();
        *transform = t;
        *projection = p;
    }
}

/// Detects a double click in the viewport: the cursor position, in window pixels.
pub fn double_click(buttons: &ButtonInput<MouseButton>, window: &Window, now: f64, last: &mut (f64, Vec2)) -> Option<Vec2> {
    if !buttons.just_pressed(MouseButton::Left) {
        return None;
    }
    let p = window.cursor_position()?;
    let hit = now - last.0 < 0.4 && p.distance(last.1) < 6.0;
    *last = if hit { (-1.0, p) } else { (now, p) };
    hit.then_some(p)
}

/// The primary window (for cursor positions).
pub type PrimaryWindowQuery<'w, 's> = Query<'w, 's, &'static Window, With<PrimaryWindow>>;

/// Turns fly-through on or off; its speed follows the scene's size.
pub fn toggle_fly(orbit: &mut OrbitCamera, bounds: (Vec3, Vec3)) {
    orbit.fly = !orbit.fly;
    orbit.fly_speed = ((bounds.1 - bounds.0).length() * 0.25).max(1e-3);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orbit_pan_zoom_behave() {
        let mut o = OrbitCamera { azimuth_deg: 0.0, elevation_deg: 0.0, distance: 100.0, ..Default::default() };
        // Azimuth 0 looks at the face from +y.
        assert!((o.camera().position - Vec3::new(0.0, 100.0, 0.0)).length() < 1e-3);
        // Dragging right turns the camera towards the patient's right (+x side).
        o.orbit(Vec2::new(100.0 / ORBIT_SPEED * 90.0 / 100.0, 0.0));
        assert!((o.camera().position - Vec3::new(100.0, 0.0, 0.0)).length() < 1e-2, "{}", o.camera().position);
        // Elevation is clamped short of the pole.
        o.orbit(Vec2::new(0.0, 10_000.0));
        assert_eq!(o.elevation_deg, 89.0);
        // Panning by a whole viewport height moves the target by the view height.
        let mut p = OrbitCamera { azimuth_deg: 0.0, elevation_deg: 0.0, distance: 100.0, ..Default::default() };
        let h = p.view_height();
        p.pan(Vec2::new(0.0, 500.0), 500.0);
        assert!((p.target - Vec3::new(0.0, 0.0, h)).length() < 1e-3, "{}", p.target);
        p.zoom(1.0);
        assert!((p.distance - 100.0 / ZOOM_STEP).abs() < 1e-4);
        // Framing: the box centre becomes the target, seen from the side asked.
        p.frame(View::Left, Vec3::splat(-10.0), Vec3::splat(10.0), 1.0);
        assert!(p.target.length() < 1e-5);
        assert!((p.azimuth_deg - 90.0).abs() < 1e-3 && p.elevation_deg.abs() < 1e-3, "{} {}", p.azimuth_deg, p.elevation_deg);
    }

    #[test]
    fn a_scene_camera_becomes_the_orbit() {
        // An orbit's own camera round-trips, perspective and orthographic.
        for orthographic in [false, true] {
            let o = OrbitCamera {
                target: Vec3::new(5.0, -3.0, 2.0),
                azimuth_deg: 70.0,
                elevation_deg: 25.0,
                distance: 240.0,
                orthographic,
                ..Default::default()
            };
            let mut p = OrbitCamera::default();
            p.set_from(&o.camera(), o.target + Vec3::new(0.0, 0.0, 0.0));
            let (a, b) = (o.camera(), p.camera());
            assert!((a.position - b.position).length() < 1e-2, "{} vs {}", a.position, b.position);
            assert!(a.rotation.angle_between(b.rotation) < 1e-3);
            assert_eq!(a.projection, b.projection);
        }
        // A scene's look-at camera from the front, at 300 from a centre it looks past:
        // the orbit pivots on the view axis at the centre's depth, same eye and view.
        let cam = FocalCamera::look_at(
            Vec3::new(0.0, 300.0, 0.0),
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::Z,
            FocalProjection::Perspective { fov_y: 0.5 },
        );
        let mut p = OrbitCamera::default();
        p.set_from(&cam, Vec3::ZERO);
        assert!((p.camera().position - cam.position).length() < 1e-2);
        assert!(p.camera().forward().dot(cam.forward()) > 0.99999);
        assert!((p.fov_deg - 0.5f32.to_degrees()).abs() < 1e-4 && !p.orthographic);
    }

    #[test]
    fn flying_turns_about_the_eye_and_enters_the_volume() {
        let mut o = OrbitCamera { azimuth_deg: 0.0, elevation_deg: 0.0, distance: 100.0, fly: true, ..Default::default() };
        let eye = o.camera().position;
        let right = o.camera().right();
        // Dragging right turns the view to the right; the eye stays.
        o.look(Vec2::new(50.0, 0.0));
        assert!((o.camera().position - eye).length() < 1e-3, "{}", o.camera().position);
        assert!(o.camera().forward().dot(right) > 0.1);
        // Flying forward 150 units passes the old target (inside the volume).
        let mut f = OrbitCamera { azimuth_deg: 0.0, elevation_deg: 0.0, distance: 100.0, ..Default::default() };
        f.fly_by(0.0, 0.0, 150.0);
        assert!((f.camera().position - Vec3::new(0.0, -50.0, 0.0)).length() < 1e-3, "{}", f.camera().position);
        f.fly_by(10.0, 5.0, 0.0);
        assert!((f.camera().position - Vec3::new(-10.0, -50.0, 5.0)).length() < 1e-3, "{}", f.camera().position);
    }
}
