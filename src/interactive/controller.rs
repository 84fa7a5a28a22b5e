//! The resolution a moving view draws at, as pure functions of the frames measured.
//!
//! A frame's cost is about `a + b·s²` at a fraction `s` of the pixels per axis (the rays
//! dominate, and there are `s²` as many). Holding a target frame time `T` after a frame
//! of `m` milliseconds at `s` asks for `s·√(T/m)` when the fixed part `a` is small; the
//! frame that shows a new scale is measured a frame or two later (Bevy renders the
//! previous frame while the next one is updated), so the controller takes only half of
//! that step in the logarithm, `s' = s·(T/m)^¼`, at most a factor 2 either way, which
//! converges without overshooting on that lag ([`tests`] runs it on a model of such
//! frames). Scales are quantised to 1/32 so the reduced texture keeps its size while
//! the measured time only scatters. When the view comes to rest the scale doubles
//! every frame up to 1: the picture refines progressively, each step a quarter of the
//! time of the one after it.

/// The fraction of the pixels drawn per axis is a multiple of this.
pub const QUANTUM: f32 = 1.0 / 32.0;

/// Quantises `scale` to [`QUANTUM`] within `min … 1`.
pub fn quantise(scale: f32, min: f32) -> f32 {
    let s = if scale.is_finite() { scale } else { 1.0 };
    ((s / QUANTUM).round() * QUANTUM).clamp(min.clamp(QUANTUM, 1.0), 1.0)
}

/// The scale after a frame of `frame_ms` drawn at `scale` while moving, holding
/// `target_ms`, at least `min`.
pub fn while_moving(scale: f32, frame_ms: f32, target_ms: f32, min: f32) -> f32 {
    let measured = frame_ms.is_finite() && frame_ms > 0.0 && target_ms.is_finite() && target_ms > 0.0;
    if !measured {
        return quantise(scale, min);
    }
    let step = (target_ms / frame_ms).powf(0.25).clamp(0.5, 2.0);
    quantise(scale * step, min)
}

/// The scale of the next frame of a view at rest: twice this one's, up to 1.
pub fn at_rest(scale: f32) -> f32 {
    quantise(scale * 2.0, QUANTUM)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame of a software renderer: 8 ms of fixed cost, 400 ms of rays at full
    /// resolution.
    fn frame(scale: f32) -> f32 {
        8.0 + 400.0 * scale * scale
    }

    #[test]
    fn a_moving_view_settles_at_the_target_frame_time() {
        // 8 + 400 s² = 50 at s = √(42/400) = 0.324; frames are measured two frames late.
        let (mut drawn, mut s) = (vec![1.0f32, 1.0], 1.0f32);
        for _ in 0..40 {
            let measured = frame(drawn[drawn.len() - 2]);
            s = while_moving(s, measured, 50.0, 0.125);
            drawn.push(s);
        }
        let tail: Vec<f32> = drawn[drawn.len() - 10..].to_vec();
        for s in &tail {
            assert!((frame(*s) - 50.0).abs() < 8.0, "{s} → {} ms; {drawn:?}", frame(*s));
        }
        // Within a quantum of the exact scale, and no swings once there.
        assert!((tail[9] - 0.324).abs() <= QUANTUM, "{tail:?}");
        assert!(tail.windows(2).all(|w| (w[0] - w[1]).abs() <= QUANTUM), "{tail:?}");
    }

    #[test]
    fn fast_frames_draw_every_pixel_and_slow_ones_stop_at_the_floor() {
        let mut s = 0.25;
        for _ in 0..20 {
            s = while_moving(s, frame(s) / 20.0, 50.0, 0.125);
        }
        assert_eq!(s, 1.0);
        for _ in 0..20 {
            s = while_moving(s, 10_000.0, 50.0, 0.125);
        }
        assert_eq!(s, 0.125);
        // A step is at most a factor 2, and nonsense measurements keep the scale.
        assert_eq!(while_moving(0.5, 1e9, 50.0, QUANTUM), 0.25);
        assert_eq!(while_moving(0.5, f32::NAN, 50.0, QUANTUM), 0.5);
        assert_eq!(while_moving(0.5, 0.0, 50.0, QUANTUM), 0.5);
    }

    #[test]
    fn a_view_at_rest_refines_by_doubling() {
        let mut steps = vec![0.15f32];
        while *steps.last().unwrap_or(&1.0) < 1.0 && steps.len() < 10 {
            steps.push(at_rest(*steps.last().unwrap_or(&1.0)));
        }
        assert_eq!(steps, vec![0.15, 0.3125, 0.625, 1.0]);
        assert_eq!(quantise(0.49, 0.125), 0.5);
        assert_eq!(quantise(0.01, 0.125), 0.125);
        assert_eq!(quantise(f32::INFINITY, 0.125), 1.0);
    }
}
