//! Keyframed animation in scene files: a camera path, a lens's position, size and power,
//! κt of the context-preserving model and the degree of explosion, each a track of keys
//! `(t: seconds, value: …)` interpolated over time. `focal render scene.ron` renders it
//! as a movie (a PNG sequence, a GIF and, where ffmpeg is, an MP4), so that a paper's
//! figure can become a video.
//!
//! **Interpolation.** Between keys (tᵢ, pᵢ) and (tᵢ₊₁, pᵢ₊₁) every animated component is
//! a cubic Hermite segment, with s = (t − tᵢ)/Δ, Δ = tᵢ₊₁ − tᵢ:
//!
//! p(t) = h₀₀(s)·pᵢ + h₁₀(s)·Δ·mᵢ + h₀₁(s)·pᵢ₊₁ + h₁₁(s)·Δ·mᵢ₊₁,
//! h₀₀ = 2s³ − 3s² + 1, h₁₀ = s³ − 2s² + s, h₀₁ = −2s³ + 3s², h₁₁ = s³ − s².
//!
//! - `Linear`: p = (1 − s)·pᵢ + s·pᵢ₊₁ (constant speed, corners at the keys);
//! - `Smooth`: mᵢ = 0, so p = pᵢ + (3s² − 2s³)(pᵢ₊₁ − pᵢ): ease in and out of every key;
//! - `Spline`: Catmull–Rom tangents mᵢ = (pᵢ₊₁ − pᵢ₋₁)/(tᵢ₊₁ − tᵢ₋₁) (one-sided at the
//!   ends), through the keys without stopping.
//!
//! Before the first key a track holds its first value, after the last its last.
//! Cameras interpolate in their own terms: orbits by azimuth, elevation and zoom (so 0°
//! to 360° is one turn), look-at poses by eye, target, up and field of view; the two
//! keys of a segment must be of one kind.

use serde::{Deserialize, Serialize};

use super::camera::CameraSpec;
use crate::context::ContextParams;
use crate::lens::{Lens, LensKind};

/// Frames a second unless the scene says otherwise.
pub const DEFAULT_FPS: u32 = 25;
/// The most frames one animation may have (a minute at 60 frames a second).
pub const MAX_FRAMES: u32 = 3600;

/// What an animation's tracks may refer to in their scene: its lenses, and for each
/// dataset whether it is exploded and its context-preserving parameters.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Refers {
    pub lenses: usize,
    pub exploded: Vec<bool>,
    pub contexts: Vec<ContextParams>,
}

/// A scene's animation: tracks of keys over `duration_s` seconds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Animation {
    pub duration_s: f32,
    #[serde(default = "default_fps")]
    pub fps: u32,
    pub tracks: Vec<Track>,
}

fn default_fps() -> u32 {
    DEFAULT_FPS
}

/// How a track moves between its keys (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Ease {
    Linear,
    #[default]
    Smooth,
    Spline,
}

/// A value at a time (seconds from the start).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Key<T> {
    pub t: f32,
    pub value: T,
}

/// One animated parameter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Track {
    /// The camera (orbit or look-at keys).
    Camera {
        keys: Vec<Key<CameraSpec>>,
        #[serde(default)]
        ease: Ease,
    },
    /// Lens `lens` of the scene's `lenses`: its centre, radius, border and power
    /// (magnification, field of view) move; its kind and shape stay those of the keys.
    Lens {
        lens: usize,
        keys: Vec<Key<Lens>>,
        #[serde(default)]
        ease: Ease,
    },
    /// κt of a dataset's context-preserving model (its other parameters stay).
    KappaT {
        dataset: usize,
        keys: Vec<Key<f32>>,
        #[serde(default)]
        ease: Ease,
    },
    /// The degree of explosion of an exploded dataset; the parts move under the
    /// simulation between frames (1/fps seconds of it per frame).
    Explosion {
        dataset: usize,
        keys: Vec<Key<f32>>,
        #[serde(default)]
        ease: Ease,
    },
}

/// A value that can be animated: the numbers that move, and the value with them set.
trait Animated: Clone {
    fn components(&self) -> Vec<f32>;
    /// `self` with its moving numbers replaced by `c`.
    fn with(&self, c: &[f32]) -> Self;
    /// Whether `self` and `next` can be the two ends of one segment.
    fn check_pair(&self, next: &Self) -> Result<(), String>;
}

impl Animated for f32 {
    fn components(&self) -> Vec<f32> {
        vec![*self]
    }
    fn with(&self, c: &[f32]) -> Self {
        c[0]
    }
    fn check_pair(&self, _: &Self) -> Result<(), String> {
        Ok(())
    }
}

impl Animated for CameraSpec {
    fn components(&self) -> Vec<f32> {
        match *self {
            CameraSpec::View { zoom, .. } => vec![zoom],
            CameraSpec::Orbit { azimuth_deg, elevation_deg, zoom, .. } => vec![azimuth_deg, elevation_deg, zoom],
            CameraSpec::LookAt { eye, target, up, orthographic_height, fov_deg } => {
                vec![eye.0, eye.1, eye.2, target.0, target.1, target.2, up.0, up.1, up.2, fov_deg, orthographic_height.unwrap_or(0.0)]
            }
        }
    }
    fn with(&self, c: &[f32]) -> Self {
        match self.clone() {
            CameraSpec::View { view, orthographic, .. } => CameraSpec::View { view, orthographic, zoom: c[0] },
            CameraSpec::Orbit { orthographic, .. } => {
                CameraSpec::Orbit { azimuth_deg: c[0], elevation_deg: c[1], zoom: c[2], orthographic }
            }
            CameraSpec::LookAt { orthographic_height, .. } => CameraSpec::LookAt {
                eye: (c[0], c[1], c[2]),
                target: (c[3], c[4], c[5]),
                up: (c[6], c[7], c[8]),
                fov_deg: c[9],
                orthographic_height: orthographic_height.map(|_| c[10]),
            },
        }
    }
    fn check_pair(&self, next: &Self) -> Result<(), String> {
        match (self, next) {
            (CameraSpec::View { view: a, orthographic: p, .. }, CameraSpec::View { view: b, orthographic: q, .. }) if a == b && p == q => {
                Ok(())
            }
            (CameraSpec::View { .. }, CameraSpec::View { .. }) => {
                Err("two View keys of different views or projections: turn between views with Orbit keys".into())
            }
            (CameraSpec::Orbit { orthographic: p, .. }, CameraSpec::Orbit { orthographic: q, .. }) if p != q => {
                Err("one Orbit key is orthographic and the next is not".into())
            }
            (CameraSpec::LookAt { orthographic_height: p, .. }, CameraSpec::LookAt { orthographic_height: q, .. })
                if p.is_some() != q.is_some() =>
            {
                Err("one LookAt key is orthographic and the next is not".into())
            }
            (CameraSpec::Orbit { .. }, CameraSpec::Orbit { .. }) | (CameraSpec::LookAt { .. }, CameraSpec::LookAt { .. }) => Ok(()),
            _ => Err("neighbouring camera keys are of different kinds (View, Orbit, LookAt): use one kind along a path".into()),
        }
    }
}

/// The lens's power: a magnifier's magnification, a fisheye's field of view.
fn lens_power(kind: &LensKind) -> f32 {
    match kind {
        LensKind::Magnifier { magnification, .. } => *magnification,
        LensKind::Angular { field_of_view, .. } => *field_of_view,
        LensKind::Sampling(_) => 0.0,
    }
}

impl Animated for Lens {
    fn components(&self) -> Vec<f32> {
        vec![self.center.x, self.center.y, self.radius, self.border, lens_power(&self.kind)]
    }
    fn with(&self, c: &[f32]) -> Self {
        let mut lens = self.clone();
        lens.center = glam::Vec2::new(c[0], c[1]);
        (lens.radius, lens.border) = (c[2], c[3]);
        match &mut lens.kind {
            LensKind::Magnifier { magnification, .. } => *magnification = c[4],
            LensKind::Angular { field_of_view, .. } => *field_of_view = c[4],
            LensKind::Sampling(_) => {}
        }
        lens
    }
    fn check_pair(&self, next: &Self) -> Result<(), String> {
        if std::mem::discriminant(&self.kind) != std::mem::discriminant(&next.kind) || self.shape != next.shape {
            return Err("neighbouring lens keys are of different kinds or shapes".into());
        }
        Ok(())
    }
}

/// The cubic Hermite basis at s ∈ [0, 1]: (h₀₀, h₁₀, h₀₁, h₁₁).
pub fn hermite_basis(s: f32) -> [f32; 4] {
    let (s2, s3) = (s * s, s * s * s);
    [2.0 * s3 - 3.0 * s2 + 1.0, s3 - 2.0 * s2 + s, -2.0 * s3 + 3.0 * s2, s3 - s2]
}

/// The tangent of component `j` at key `i` under Catmull–Rom (one-sided at the ends).
fn catmull_rom(times: &[f32], values: &[Vec<f32>], i: usize, j: usize) -> f32 {
    let (a, b) = (i.saturating_sub(1), (i + 1).min(times.len() - 1));
    if a == b { 0.0 } else { (values[b][j] - values[a][j]) / (times[b] - times[a]) }
}

/// The value of a track's keys at time `t` (keys checked: non-empty, increasing times).
fn value_at<T: Animated>(keys: &[Key<T>], ease: Ease, t: f32) -> T {
    let first = &keys[0];
    if t <= first.t || keys.len() == 1 {
        return first.value.clone();
    }
    let last = &keys[keys.len() - 1];
    if t >= last.t {
        return last.value.clone();
    }
    let i = keys.windows(2).position(|w| t < w[1].t).unwrap_or(keys.len() - 2);
    let (k0, k1) = (&keys[i], &keys[i + 1]);
    let delta = k1.t - k0.t;
    let s = (t - k0.t) / delta;
    let (p0, p1) = (k0.value.components(), k1.value.components());
    let c: Vec<f32> = match ease {
        Ease::Linear => p0.iter().zip(&p1).map(|(a, b)| a + s * (b - a)).collect(),
        Ease::Smooth | Ease::Spline => {
            let [h00, h10, h01, h11] = hermite_basis(s);
            let (times, values): (Vec<f32>, Vec<Vec<f32>>) =
                if ease == Ease::Spline { keys.iter().map(|k| (k.t, k.value.components())).unzip() } else { (Vec::new(), Vec::new()) };
            let tangent = |k: usize, j: usize| if ease == Ease::Spline { catmull_rom(&times, &values, k, j) } else { 0.0 };
            (0..p0.len()).map(|j| h00 * p0[j] + h10 * delta * tangent(i, j) + h01 * p1[j] + h11 * delta * tangent(i + 1, j)).collect()
        }
    };
    k0.value.with(&c)
}

/// Checks a track's keys: some, at increasing times within the animation, and each
/// neighbouring pair of one kind.
fn check_keys<T: Animated>(keys: &[Key<T>], duration: f32) -> Result<(), String> {
    if keys.is_empty() {
        return Err("no keys".into());
    }
    for (i, k) in keys.iter().enumerate() {
        if !k.t.is_finite() || k.t < 0.0 || k.t > duration {
            return Err(format!("key {i}: t = {} is not within 0..{duration} s", k.t));
        }
        if k.value.components().iter().any(|c| !c.is_finite()) {
            return Err(format!("key {i}: a value is not finite"));
        }
    }
    for (i, w) in keys.windows(2).enumerate() {
        if w[1].t <= w[0].t {
            return Err(format!("keys {i} and {}: times must increase ({} then {})", i + 1, w[0].t, w[1].t));
        }
        w[0].value.check_pair(&w[1].value).map_err(|e| format!("keys {i} and {}: {e}", i + 1))?;
    }
    Ok(())
}

impl Track {
    fn name(&self) -> &'static str {
        match self {
            Track::Camera { .. } => "Camera",
            Track::Lens { .. } => "Lens",
            Track::KappaT { .. } => "KappaT",
            Track::Explosion { .. } => "Explosion",
        }
    }

    /// Checks the track's value at time `t` (its keys checked already).
    fn check_value_at(&self, t: f32) -> Result<(), String> {
        let at_least_zero = |v: f32, what: &str| if v >= 0.0 { Ok(()) } else { Err(format!("{what} {v} is negative")) };
        match self {
            Track::Camera { keys, ease } => match value_at(keys, *ease, t) {
                CameraSpec::View { zoom, .. } | CameraSpec::Orbit { zoom, .. } if zoom <= 0.0 => {
                    Err(format!("zoom {zoom} is not positive"))
                }
                _ => Ok(()),
            },
            Track::Lens { keys, ease, .. } => value_at(keys, *ease, t).validate(),
            Track::KappaT { keys, ease, .. } => at_least_zero(value_at(keys, *ease, t), "κt"),
            Track::Explosion { keys, ease, .. } => at_least_zero(value_at(keys, *ease, t), "the degree of explosion"),
        }
    }

    fn check(&self, scene: &Refers, duration: f32) -> Result<(), String> {
        let n = scene.exploded.len();
        let dataset = |d: usize| if d < n { Ok(()) } else { Err(format!("dataset {d}: the scene has {n}")) };
        match self {
            Track::Camera { keys, .. } => {
                check_keys(keys, duration)?;
                let zooms = keys.iter().filter_map(|k| match k.value {
                    CameraSpec::View { zoom, .. } | CameraSpec::Orbit { zoom, .. } => Some(zoom),
                    CameraSpec::LookAt { .. } => None,
                });
                if zooms.into_iter().any(|z| z <= 0.0) {
                    return Err("a zoom is not positive".into());
                }
                Ok(())
            }
            Track::Lens { lens, keys, .. } => {
                if *lens >= scene.lenses {
                    return Err(format!("lens {lens}: the scene has {} (an animated lens must be in `lenses`)", scene.lenses));
                }
                check_keys(keys, duration)?;
                keys.iter().enumerate().try_for_each(|(i, k)| k.value.validate().map_err(|e| format!("key {i}: {e}")))
            }
            Track::KappaT { dataset: d, keys, .. } => {
                dataset(*d)?;
                check_keys(keys, duration)?;
                if keys.iter().any(|k| k.value < 0.0) {
                    return Err("κt must not be negative".into());
                }
                Ok(())
            }
            Track::Explosion { dataset: d, keys, .. } => {
                dataset(*d)?;
                if !scene.exploded[*d] {
                    return Err(format!("dataset {d} is not exploded (it has no explode)"));
                }
                check_keys(keys, duration)?;
                if keys.iter().any(|k| k.value < 0.0) {
                    return Err("the degree of explosion must not be negative".into());
                }
                Ok(())
            }
        }
    }
}

impl Animation {
    /// The number of frames: one at t = 0 and one every 1/fps s up to the duration.
    pub fn frame_count(&self) -> u32 {
        (self.duration_s * self.fps as f32).round() as u32 + 1
    }

    /// Checks the animation against its scene: a duration, a frame rate, frames within
    /// [`MAX_FRAMES`], and every track's keys and references.
    pub fn validate(&self, scene: &Refers) -> Result<(), String> {
        let fail = |e: String| format!("animation: {e}");
        if !self.duration_s.is_finite() || self.duration_s <= 0.0 {
            return Err(fail(format!("duration_s {} is not a positive number of seconds", self.duration_s)));
        }
        if !(1..=120).contains(&self.fps) {
            return Err(fail(format!("fps {} is not 1..120", self.fps)));
        }
        if self.duration_s * self.fps as f32 >= MAX_FRAMES as f32 {
            return Err(fail(format!("{} s at {} fps is more than {MAX_FRAMES} frames", self.duration_s, self.fps)));
        }
        for (i, track) in self.tracks.iter().enumerate() {
            track.check(scene, self.duration_s).map_err(|e| fail(format!("track {i} ({}): {e}", track.name())))?;
        }
        // Every frame's values: a spline may overshoot its keys (a negative κt, a
        // magnification below 1).
        for k in 0..self.frame_count() {
            let t = self.time_of(k);
            for (i, track) in self.tracks.iter().enumerate() {
                track.check_value_at(t).map_err(|e| {
                    fail(format!(
                        "track {i} ({}) at t = {t:.3} s, between keys: {e} (the spline overshoots: ease smooth, or add keys)",
                        track.name()
                    ))
                })?;
            }
        }
        Ok(())
    }

    /// The time of frame `k`, seconds.
    pub fn time_of(&self, k: u32) -> f32 {
        k as f32 / self.fps as f32
    }

    /// Every track's value at time `t` (the scene's `refers` gives what stays: the
    /// lenses not animated, each dataset's other context parameters).
    pub fn values_at(&self, t: f32, lenses: &[Lens], refers: &Refers) -> Values {
        let mut values = Values::default();
        for track in &self.tracks {
            match track {
                Track::Camera { keys, ease } => values.camera = Some(value_at(keys, *ease, t)),
                Track::Lens { lens, keys, ease } => {
                    let all = values.lenses.get_or_insert_with(|| lenses.to_vec());
                    all[*lens] = value_at(keys, *ease, t);
                }
                Track::KappaT { dataset, keys, ease } => {
                    let context = ContextParams { kappa_t: value_at(keys, *ease, t), ..refers.contexts[*dataset] };
                    values.contexts.push((*dataset, context));
                }
                Track::Explosion { dataset, keys, ease } => values.degrees.push((*dataset, value_at(keys, *ease, t))),
            }
        }
        values
    }
}

/// The animated values at one time.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Values {
    pub camera: Option<CameraSpec>,
    /// The scene's lenses with the animated ones moved (`None`: no lens moves).
    pub lenses: Option<Vec<Lens>>,
    /// (dataset, its context-preserving parameters with κt animated).
    pub contexts: Vec<(usize, ContextParams)>,
    /// (dataset, its degree of explosion).
    pub degrees: Vec<(usize, f32)>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn keys(pairs: &[(f32, f32)]) -> Vec<Key<f32>> {
        pairs.iter().map(|&(t, value)| Key { t, value }).collect()
    }

    #[test]
    fn linear_keys_move_at_constant_speed() {
        let k = keys(&[(0.0, 2.0), (2.0, 6.0), (4.0, 6.0)]);
        assert_eq!(value_at(&k, Ease::Linear, -1.0), 2.0);
        assert_eq!(value_at(&k, Ease::Linear, 0.5), 3.0);
        assert_eq!(value_at(&k, Ease::Linear, 1.0), 4.0);
        assert_eq!(value_at(&k, Ease::Linear, 3.0), 6.0);
        assert_eq!(value_at(&k, Ease::Linear, 9.0), 6.0);
    }

    #[test]
    fn smooth_keys_ease_in_and_out() {
        // From 0 to 10 over 1 s: p(s) = 10·(3s² − 2s³): at s = ¼, 10·(3/16 − 2/64) = 1.5625.
        let k = keys(&[(0.0, 0.0), (1.0, 10.0)]);
        assert!((value_at(&k, Ease::Smooth, 0.25) - 1.5625).abs() < 1e-5);
        assert!((value_at(&k, Ease::Smooth, 0.5) - 5.0).abs() < 1e-5);
        assert!((value_at(&k, Ease::Smooth, 0.75) - 8.4375).abs() < 1e-5);
    }

    #[test]
    fn spline_keys_pass_through_without_stopping() {
        // Keys 0, 10, 30 at t = 0, 1, 2. Catmull–Rom tangents: m₀ = (10 − 0)/1 = 10 (one-sided),
        // m₁ = (30 − 0)/2 = 15. At s = ½ of the first segment (Δ = 1):
        // h = (½, ⅛, ½, −⅛): 0·½ + ⅛·10 + 10·½ − ⅛·15 = 1.25 + 5 − 1.875 = 4.375.
        let k = keys(&[(0.0, 0.0), (1.0, 10.0), (2.0, 30.0)]);
        assert!((value_at(&k, Ease::Spline, 0.5) - 4.375).abs() < 1e-5);
        assert_eq!(value_at(&k, Ease::Spline, 1.0), 10.0);
        // It does not stop at the middle key: the speed there is m₁ = 15, against 0 for Smooth.
        let speed = |ease| (value_at(&k, ease, 1.001) - value_at(&k, ease, 0.999)) / 0.002;
        assert!((speed(Ease::Spline) - 15.0).abs() < 0.1, "{}", speed(Ease::Spline));
        assert!(speed(Ease::Smooth).abs() < 0.1);
    }

    #[test]
    fn the_hermite_basis_sums_to_one_and_matches_its_definition() {
        for s in [0.0, 0.3, 0.5, 1.0] {
            let [h00, h10, h01, h11] = hermite_basis(s);
            assert!((h00 + h01 - 1.0).abs() < 1e-6);
            assert!((h10 - s * (1.0 - s) * (1.0 - s)).abs() < 1e-6);
            assert!((h11 + s * s * (1.0 - s)).abs() < 1e-6);
        }
    }

    fn animation(text: &str) -> Animation {
        ron::from_str(text).unwrap()
    }

    /// One dataset (context-preserving, not exploded), one lens.
    fn refers() -> Refers {
        Refers { lenses: 1, exploded: vec![false], contexts: vec![ContextParams { kappa_t: 0.0, kappa_s: 0.7, ..Default::default() }] }
    }

    const ORBIT: &str = r#"(duration_s: 2.0, fps: 4, tracks: [
        Camera(keys: [(t: 0, value: Orbit(azimuth_deg: 0, elevation_deg: 10)),
                      (t: 2, value: Orbit(azimuth_deg: 360, elevation_deg: 30, zoom: 2))], ease: linear),
        Lens(lens: 0, keys: [(t: 0, value: (kind: magnifier(magnification: 2.0), center: (-0.5, 0.0))),
                             (t: 1, value: (kind: magnifier(magnification: 4.0), center: (0.5, 0.2), radius: 0.4))]),
        KappaT(dataset: 0, keys: [(t: 0, value: 0), (t: 2, value: 6)], ease: linear),
    ])"#;

    #[test]
    fn every_tracks_value_at_a_time() {
        let a = animation(ORBIT);
        a.validate(&refers()).unwrap();
        assert_eq!(a.frame_count(), 9, "0, 0.25 … 2 s");
        assert_eq!(a.time_of(2), 0.5);
        let lens = Lens::magnifier(glam::Vec2::ZERO, 0.3, 0.15, 1.0);
        let v = a.values_at(0.5, std::slice::from_ref(&lens), &refers());
        // t = 0.5 s: a quarter of the orbit, linear.
        match v.camera {
            Some(CameraSpec::Orbit { azimuth_deg, elevation_deg, zoom, .. }) => {
                assert_eq!((azimuth_deg, elevation_deg, zoom), (90.0, 15.0, 1.25));
            }
            other => panic!("{other:?}"),
        }
        // The lens half-way (smooth: s = ½ gives ½), its radius 0.3 → 0.4.
        let moved = &v.lenses.unwrap()[0];
        assert!((moved.center - glam::Vec2::new(0.0, 0.1)).length() < 1e-6);
        assert!((moved.radius - 0.35).abs() < 1e-6);
        assert_eq!(
            moved.kind,
            LensKind::Magnifier { magnification: 3.0, profile: Default::default(), focus_depth: None, plane_depth: None }
        );
        // κt 0 → 6 linear: 1.5 at 0.5 s, the dataset's κs kept.
        assert_eq!(v.contexts, vec![(0, ContextParams { kappa_t: 1.5, ..refers().contexts[0] })]);
        assert!(v.degrees.is_empty());
    }

    #[test]
    fn bad_animations_are_refused_with_the_track_and_the_keys() {
        let err = |tracks: &str| animation(&ORBIT.replace(ORBIT_TRACKS, tracks)).validate(&refers()).unwrap_err();
        assert!(
            err("KappaT(dataset: 0, keys: [(t: 1, value: 0), (t: 0.5, value: 6)])").contains("(KappaT): keys 0 and 1: times must increase")
        );
        assert!(err("KappaT(dataset: 3, keys: [(t: 0, value: 0)])").contains("dataset 3"));
        assert!(err("KappaT(dataset: 0, keys: [(t: 5, value: 0)])").contains("not within 0..2 s"));
        assert!(err("KappaT(dataset: 0, keys: [])").contains("no keys"));
        assert!(err("Lens(lens: 4, keys: [])").contains("lens 4"));
        assert!(err("Explosion(dataset: 0, keys: [(t: 0, value: 1)])").contains("not exploded"));
        let mixed = "Camera(keys: [(t: 0, value: Orbit(azimuth_deg: 0, elevation_deg: 0)), (t: 1, value: View(view: left))])";
        assert!(err(mixed).contains("different kinds"));
        // Five lens keys are one lens's path, not five lenses.
        let key = |t: f32| format!("(t: {t}, value: (kind: magnifier(magnification: 2.0)))");
        let five = format!("Lens(lens: 0, keys: [{}])", (0..5).map(|k| key(k as f32 * 0.5)).collect::<Vec<_>>().join(", "));
        animation(&ORBIT.replace(ORBIT_TRACKS, &five)).validate(&refers()).unwrap();
        // A spline through 0, 0, 6 dips below 0 between the first two keys (−0.375 at
        // 0.5 s: m₁ = 3, h₁₁(½)·Δ·m₁ = −⅛·1·3).
        assert!((value_at(&keys(&[(0.0, 0.0), (1.0, 0.0), (2.0, 6.0)]), Ease::Spline, 0.5) + 0.375).abs() < 1e-6);
        let dip = err("KappaT(dataset: 0, keys: [(t: 0, value: 0), (t: 1, value: 0), (t: 2, value: 6)], ease: spline),");
        assert!(dip.contains("track 2 (KappaT) at t = 0.250 s, between keys: κt") && dip.contains("overshoots"), "{dip}");
        let long = animation(&ORBIT.replace("duration_s: 2.0, fps: 4", "duration_s: 100.0, fps: 60"));
        assert!(long.validate(&refers()).unwrap_err().contains("more than 3600 frames"));
    }

    const ORBIT_TRACKS: &str = "KappaT(dataset: 0, keys: [(t: 0, value: 0), (t: 2, value: 6)], ease: linear),";
}
