//! The lens-distorted lattice: a regular grid on the focus plane, drawn as the lenses
//! show it, so the magnification field can be read off the image (the overlay Wang et
//! al. propose as future work, §6).
//!
//! The grid lies in the plane perpendicular to the view at view depth `D` (the focus
//! depth), its lines `spacing` world units apart along the camera's right and up axes.
//! The image is sampled every few pixels: each sample's ray, bent by the lenses, meets
//! the plane at a point with lattice coordinates `(u, v)` (position over spacing). The
//! drawn lines are the level sets `u = k` and `v = k` of these two fields, traced by
//! marching squares over the sample grid; where a lens magnifies by `m` the lines lie
//! `m` times further apart.

use glam::Vec2;

use super::screen::Screen;
use super::stack::{ResolvedLens, lens_ray};
use crate::region::Camera;

/// Most lines one sample cell may hold per field (more means the lattice is too fine).
const MAX_LINES_PER_CELL: i32 = 4;

/// Lattice coordinates `(u, v)` at every sample, `step` pixels apart (`NaN` where a pixel
/// has no ray or its ray misses the plane).
fn sample_fields(
    camera: &Camera,
    screen: Screen,
    lenses: &[ResolvedLens],
    depth: f32,
    spacing: f32,
    step: f32,
) -> (usize, usize, Vec<Vec2>) {
    let nx = (screen.width / step).ceil() as usize + 1;
    let ny = (screen.height / step).ceil() as usize + 1;
    let (fwd, right, up) = (camera.forward(), camera.right(), camera.up());
    let mut field = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            let (px, py) = ((i as f32 * step).min(screen.width), (j as f32 * step).min(screen.height));
            let uv = lens_ray(camera, screen, lenses, px, py).and_then(|ray| {
                let along = ray.dir.dot(fwd);
                let t = (depth - (ray.origin - camera.position).dot(fwd)) / along;
                (along > 1e-6 && t >= 0.0).then(|| {
                    let p = ray.at(t) - camera.position;
                    Vec2::new(p.dot(right), p.dot(up)) / spacing
                })
            });
            field.push(uv.unwrap_or(Vec2::NAN));
        }
    }
    (nx, ny, field)
}

/// Line segments (pixel coordinates, top-left origin) of the lattice seen through
/// `lenses`, sampled every `step` pixels.
pub fn lattice(camera: &Camera, screen: Screen, lenses: &[ResolvedLens], depth: f32, spacing: f32, step: f32) -> Vec<[Vec2; 2]> {
    let step = step.max(1.0);
    let (nx, ny, field) = sample_fields(camera, screen, lenses, depth, spacing, step);
    let pixel = |i: usize, j: usize| Vec2::new((i as f32 * step).min(screen.width), (j as f32 * step).min(screen.height));
    let mut segments = Vec::new();
    for j in 0..ny.saturating_sub(1) {
        for i in 0..nx.saturating_sub(1) {
            // Corners in order around the cell.
            let corners = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
            let values = corners.map(|(a, b)| field[b * nx + a]);
            if values.iter().any(|v| !v.is_finite()) {
                continue;
            }
            for axis in 0..2 {
                let f = values.map(|v| v[axis]);
                let lo = f.iter().copied().fold(f32::INFINITY, f32::min);
                let hi = f.iter().copied().fold(f32::NEG_INFINITY, f32::max);
                let (first, last) = (lo.ceil() as i32, hi.floor() as i32);
                if last - first >= MAX_LINES_PER_CELL {
                    continue;
                }
                for k in first..=last {
                    let k = k as f32;
                    let mut crossings = Vec::with_capacity(4);
                    for e in 0..4 {
                        let (a, b) = (f[e], f[(e + 1) % 4]);
                        if (a >= k) != (b >= k) {
                            let t = (k - a) / (b - a);
                            let (pa, pb) = (pixel(corners[e].0, corners[e].1), pixel(corners[(e + 1) % 4].0, corners[(e + 1) % 4].1));
                            crossings.push(pa.lerp(pb, t));
                        }
                    }
                    for pair in crossings.chunks_exact(2) {
                        segments.push([pair[0], pair[1]]);
                    }
                }
            }
        }
    }
    segments
}

/// A lattice spacing for a view `view_height` world units tall: a round number
/// (1, 2 or 5 times a power of ten) giving about `lines` lines across the height.
pub fn round_spacing(view_height: f32, lines: f32) -> f32 {
    let raw = (view_height / lines.max(1.0)).max(1e-6);
    let decade = 10f32.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0].into_iter().map(|k| k * decade).find(|s| *s >= raw).unwrap_or(10.0 * decade)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lens::{Lens, stack::resolve};
    use crate::region::Projection;
    use glam::Vec3;

    fn ortho() -> Camera {
        Camera::look_at(Vec3::new(0.0, 0.0, 500.0), Vec3::ZERO, Vec3::Y, Projection::Orthographic { height: 200.0 })
    }

    /// x positions where vertical lattice lines cross the row `y`.
    fn crossings_of_row(segments: &[[Vec2; 2]], y: f32) -> Vec<f32> {
        let mut xs: Vec<f32> = segments
            .iter()
            .filter(|[a, b]| (a.y - y) * (b.y - y) < 0.0 && (b.x - a.x).abs() < (b.y - a.y).abs())
            .map(|[a, b]| a.x + (b.x - a.x) * (y - a.y) / (b.y - a.y))
            .collect();
        xs.sort_by(f32::total_cmp);
        xs
    }

    #[test]
    fn without_lenses_the_lattice_is_regular() {
        let screen = Screen::new(200, 200);
        let segments = lattice(&ortho(), screen, &[], 500.0, 10.0, 4.0);
        let xs = crossings_of_row(&segments, 101.0);
        // Lines at x = 10, 20, …, 200 (the one at x = 0 lies on the image's edge).
        assert_eq!(xs.len(), 20, "{xs:?}");
        for w in xs.windows(2) {
            assert!((w[1] - w[0] - 10.0).abs() < 1e-3, "{xs:?}");
        }
        // Vertical lines are vertical.
        for [a, b] in &segments {
            assert!((a.x - b.x).abs() < 1e-3 || (a.y - b.y).abs() < 1e-3);
        }
    }

    #[test]
    fn a_magnifier_spreads_the_lines_by_its_magnification() {
        let screen = Screen::new(200, 200);
        let cam = ortho();
        let lens = Lens::magnifier(Vec2::ZERO, 0.4, 0.3, 3.0);
        let resolved = [resolve(&lens, &cam, screen, (Vec3::ZERO, 100.0))];
        let segments = lattice(&cam, screen, &resolved, 500.0, 10.0, 2.0);
        let xs = crossings_of_row(&segments, 101.0);
        let gap_at = |x: f32| xs.windows(2).find(|w| w[0] <= x && w[1] > x).map(|w| w[1] - w[0]).unwrap_or_else(|| panic!("{x}: {xs:?}"));
        // The centre line through x = 100 and its neighbours 30 pixels away; far outside
        // the lens 10 pixels apart.
        assert!((gap_at(105.0) - 30.0).abs() < 0.5, "{xs:?}");
        assert!((gap_at(15.0) - 10.0).abs() < 0.1, "{xs:?}");
        // The border compresses: lines closer than outside.
        assert!(gap_at(45.0) < 6.0, "{xs:?}");
    }

    #[test]
    fn spacings_are_round() {
        assert_eq!(round_spacing(200.0, 10.0), 20.0);
        assert_eq!(round_spacing(230.0, 10.0), 50.0);
        assert!((round_spacing(0.7, 10.0) - 0.1).abs() < 1e-6);
    }
}
