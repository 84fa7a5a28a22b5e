//! The forces of an exploded view (Bruckner and Gröller 2006, section 3.2, equations
//! 1–5), as pure functions: each returns a force and the point it acts at, and
//! [`Wrench::about`] turns a sum of them into the force and torque a rigid body takes.
//!
//! Distances are measured in units of a length `ℓ` ([`Scale::length`], a quarter of the
//! dataset's diagonal by default: a degree of 1 then pushes parts about a sixth of the
//! diagonal out, 3 about a third): the paper's formulas are written in such normalised
//! units, and in millimetres `e^‖r‖` would vanish a few millimetres from a point. Forces
//! come out in units of [`Scale::force`]. With `r' = r/ℓ`:
//!
//! - **Return** (eq. 1): a logarithmic spring from each vertex of a part to its place
//!   before the explosion, `F_r = c_r · ln(1 + ‖r'‖) · r̂`, `r` from the vertex to its
//!   original position, each divided by the part's vertex count and applied at the
//!   vertex (so it also turns parts back). The paper writes `ln ‖r‖`, which is negative
//!   below one unit and would push a part off its place; `ln(1 + ‖r'‖)` is 0 at rest and
//!   grows as slowly. Near half a turn the vertex springs' torque vanishes (a part
//!   flipped by the explosion crept back over minutes), so a torque towards the rest
//!   orientation joins them: `τ = −c_r · ρ · θ · â` for a turn by `θ` about `â`, `ρ` the
//!   part's radius (in force units × millimetres), as strong as the springs for small
//!   turns.
//! - **Explosion** (eq. 2): each explosion point `p` pushes every part at the part's
//!   point `x` closest to it, `F_e = c_e / e^‖r'‖ · r̂`, `r = x − p`; the points carry
//!   weights (their octree node's size) and the sum is divided by the weights' total.
//! - **Viewing** (eq. 3): each explosion point's viewing ray (from the eye through it)
//!   pushes parts off itself, `F_v = c_v / ‖r'‖ · r̂`, `r` from the ray to the part's
//!   point closest to it, perpendicular to the ray, divided by the weights' total; a part
//!   the ray passes through is pushed along the direction from the ray to its centre.
//! - **Spacing** (eq. 4): parts repel each other's centres, `F_s = c_s / ‖r'‖² · r̂`,
//!   divided by the number of parts.
//! - (eq. 5) `c_e, c_v, c_s` are the degree of explosion times `δ_e, δ_v, δ_s` (1/2,
//!   1/3, 1/6 by default), [`Coefficients`].
//!
//! `‖r'‖` is kept above [`MIN_DISTANCE`] where it divides, so no force is infinite.

use glam::Vec3;

use super::parts::Polyhedron;

/// Smallest normalised distance the viewing and spacing forces divide by.
pub const MIN_DISTANCE: f32 = 0.05;

/// The coefficients of equation 5 and the return force's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coefficients {
    /// Degree of explosion: the user's main control (0: every part in place).
    pub degree: f32,
    pub delta_explosion: f32,
    pub delta_viewing: f32,
    pub delta_spacing: f32,
    /// `c_r` of the return force.
    pub returning: f32,
}

impl Default for Coefficients {
    fn default() -> Self {
        Coefficients { degree: 0.0, delta_explosion: 0.5, delta_viewing: 1.0 / 3.0, delta_spacing: 1.0 / 6.0, returning: 1.0 }
    }
}

impl Coefficients {
    pub fn explosion(&self) -> f32 {
        self.degree * self.delta_explosion
    }
    pub fn viewing(&self) -> f32 {
        self.degree * self.delta_viewing
    }
    pub fn spacing(&self) -> f32 {
        self.degree * self.delta_spacing
    }
}

/// The units forces are computed in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scale {
    /// `ℓ`: the unit of distance in the formulas (world millimetres).
    pub length: f32,
    /// The force one unit of the formulas stands for.
    pub force: f32,
}

/// A force acting at a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Push {
    pub force: Vec3,
    pub at: Vec3,
}

/// A force and torque about a body's centre of mass.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Wrench {
    pub force: Vec3,
    pub torque: Vec3,
    /// How much the part is in the way of the view, 0..1: the weighted mean over the
    /// explosion points of `1 / (1 + d)`, `d` the part's distance from the sight line to
    /// the point in length units (1: every sight line crosses it; 0 without the viewing
    /// force).
    pub in_view: f32,
}

impl Wrench {
    /// The sum of `pushes` as a force and a torque about `center`.
    pub fn about(center: Vec3, pushes: impl IntoIterator<Item = Push>) -> Wrench {
        let mut w = Wrench::default();
        for p in pushes {
            w.add(center, p);
        }
        w
    }

    /// Adds `p` to the force and its moment about `center` to the torque.
    pub fn add(&mut self, center: Vec3, p: Push) {
        self.force += p.force;
        self.torque += (p.at - center).cross(p.force);
    }
}

/// Equation 1 at one vertex now at `current`, first at `original` (before the division
/// by the vertex count).
pub fn return_force(current: Vec3, original: Vec3, c_r: f32, scale: Scale) -> Vec3 {
    let r = original - current;
    let d = r.length() / scale.length;
    if d <= 0.0 {
        return Vec3::ZERO;
    }
    r.normalize() * c_r * (1.0 + d).ln() * scale.force
}

/// The torque turning a part back to its rest orientation from `rotation` (see the
/// module doc); `radius` is the part's farthest vertex from its centre.
pub fn return_torque(rotation: glam::Quat, radius: f32, c_r: f32, scale: Scale) -> Vec3 {
    let (axis, angle) = rotation.to_axis_angle();
    // The shorter way round.
    let angle = if angle > std::f32::consts::PI { angle - std::f32::consts::TAU } else { angle };
    if !angle.is_finite() || angle == 0.0 {
        return Vec3::ZERO;
    }
    -axis * angle * c_r * radius / scale.length * scale.force * radius
}

/// Equation 2: explosion point `point` on a part whose closest point to it is `closest`.
pub fn explosion_force(point: Vec3, closest: Vec3, c_e: f32, scale: Scale) -> Vec3 {
    let r = closest - point;
    let d = r.length() / scale.length;
    r.normalize_or_zero() * c_e * (-d).exp() * scale.force
}

/// Equation 3's direction and distance: from the viewing ray (the segment from `eye` to
/// the explosion point `eye + dir`) to the part's point closest to it, perpendicular to the ray; through the part,
/// from the ray to `center`. Returns the push's direction, its normalised length and the
/// point it acts at.
pub fn off_ray(eye: Vec3, dir: Vec3, part: &Polyhedron, center: Vec3, scale: Scale) -> (Vec3, f32, Vec3) {
    // The sight line ends at the explosion point (`eye + dir`): parts behind it do not
    // hide it.
    let length = dir.length();
    let dir = dir.normalize_or(Vec3::NEG_Z);
    let foot = |p: Vec3| eye + dir * (p - eye).dot(dir).clamp(0.0, length);
    // The ray's point nearest the centre, then the part's point nearest that, twice
    // (close enough to the nearest pair for a convex part and a line).
    let mut on_ray = foot(center);
    let mut x = part.closest_point(on_ray);
    on_ray = foot(x);
    x = part.closest_point(on_ray);
    let r = x - on_ray;
    // Beside the sight line: perpendicular to it; beyond its end: from the point.
    let beyond = (x - eye).dot(dir) > length;
    let perpendicular = if beyond { r } else { r - dir * r.dot(dir) };
    if perpendicular.length() > 1e-6 * scale.length {
        return (perpendicular.normalize(), perpendicular.length() / scale.length, x);
    }
    // The ray passes through the part: away from it towards the centre (any
    // perpendicular when the centre is on the ray too).
    let c = center - foot(center);
    let away = c - dir * c.dot(dir);
    let away = if away.length() > 1e-6 * scale.length { away.normalize() } else { dir.any_orthonormal_vector() };
    (away, 0.0, x)
}

/// Equation 3: the push of one viewing ray (from [`off_ray`]).
pub fn viewing_force(direction: Vec3, distance: f32, c_v: f32, scale: Scale) -> Vec3 {
    direction * c_v / distance.max(MIN_DISTANCE) * scale.force
}

/// Equation 4: the push on a part centred at `center` by a part centred at `other`.
pub fn spacing_force(center: Vec3, other: Vec3, c_s: f32, scale: Scale) -> Vec3 {
    let r = center - other;
    let d = (r.length() / scale.length).max(MIN_DISTANCE);
    let dir = r.normalize_or(Vec3::X);
    dir * c_s / (d * d) * scale.force
}

/// An explosion point: where the selection is, weighted by its octree node's size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExplosionPoint {
    pub position: Vec3,
    pub weight: f32,
}

/// What one part knows of the others and of the view when its forces are summed.
pub struct Surroundings<'a> {
    pub points: &'a [ExplosionPoint],
    /// Every part's centre (this one's included, it is skipped by index).
    pub centers: &'a [Vec3],
    /// The eye (`None`: no viewing force).
    pub eye: Option<Vec3>,
}

/// A part as it is now: its rest polyhedron and the rigid motion placing it.
pub struct PartNow<'a> {
    pub index: usize,
    pub rest: &'a Polyhedron,
    pub to_world: glam::Affine3A,
    pub center_of_mass: Vec3,
}

/// Every force on one part (equations 1–5) as a force and a torque about its centre of
/// mass.
pub fn part_wrench(part: &PartNow, around: &Surroundings, c: &Coefficients, scale: Scale) -> Wrench {
    let mut w = Wrench::default();
    let mut add = |p: Push| w.add(part.center_of_mass, p);
    let n = part.rest.vertices.len().max(1) as f32;
    for v in &part.rest.vertices {
        let now = part.to_world.transform_point3(*v);
        add(Push { force: return_force(now, *v, c.returning, scale) / n, at: now });
    }
    let mut in_view = 0.0;
    let total: f32 = around.points.iter().map(|p| p.weight).sum();
    let rest_center = part.rest.centroid();
    if total > 0.0 && c.degree != 0.0 {
        // Closest points in the part's rest frame (the motion is rigid: distances keep).
        let (m, back) = (part.to_world, part.to_world.inverse());
        let center = m.transform_point3(rest_center);
        let eye_rest = around.eye.map(|eye| back.transform_point3(eye));
        for p in around.points {
            let share = p.weight / total;
            let point_rest = back.transform_point3(p.position);
            let x = m.transform_point3(part.rest.closest_point(point_rest));
            add(Push { force: explosion_force(p.position, x, c.explosion(), scale) * share, at: x });
            if let Some(eye_rest) = eye_rest {
                let (dir, d, at) = off_ray(eye_rest, point_rest - eye_rest, part.rest, rest_center, scale);
                let (dir, at) = (m.transform_vector3(dir), m.transform_point3(at));
                in_view += share / (1.0 + d);
                add(Push { force: viewing_force(dir, d, c.viewing(), scale) * share, at });
            }
        }
        let parts = around.centers.len().max(1) as f32;
        for (j, other) in around.centers.iter().enumerate() {
            if j != part.index {
                add(Push { force: spacing_force(center, *other, c.spacing(), scale) / parts, at: center });
            }
        }
    }
    let (_, rotation, _) = part.to_world.to_scale_rotation_translation();
    w.torque += return_torque(rotation, part.rest.radius(), c.returning, scale);
    w.in_view = in_view;
    w
}

/// The opacity of a part that fades by the viewing force (figure 9 of the paper): from 1
/// for a part out of the view (`in_view` = 0) down to `floor` for one every sight line
/// crosses (`in_view` = 1), linearly; quantised to twentieths so the looks change only in
/// steps.
pub fn fade(in_view: f32, floor: f32) -> f32 {
    let o = 1.0 - (1.0 - floor) * in_view.clamp(0.0, 1.0);
    ((o * 20.0).round() / 20.0).clamp(floor, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Affine3A, Quat};

    const UNIT: Scale = Scale { length: 2.0, force: 10.0 };

    #[test]
    fn each_force_by_hand() {
        // Return: a vertex 2ℓ = 4 mm from its place, c_r = 1.5: 1.5·ln 3·10 towards it.
        let f = return_force(Vec3::new(4.0, 0.0, 0.0), Vec3::ZERO, 1.5, UNIT);
        assert!((f - Vec3::new(-1.5 * 3f32.ln() * 10.0, 0.0, 0.0)).length() < 1e-4, "{f}");
        assert_eq!(return_force(Vec3::ONE, Vec3::ONE, 1.5, UNIT), Vec3::ZERO);
        // Explosion: the closest point 1 ℓ above the point, c_e = 0.5: 0.5·e⁻¹·10 up.
        let f = explosion_force(Vec3::ZERO, Vec3::new(0.0, 0.0, 2.0), 0.5, UNIT);
        assert!((f - Vec3::Z * 0.5 * (-1f32).exp() * 10.0).length() < 1e-5, "{f}");
        // Viewing: 0.5 ℓ off the ray, c_v = 1/3: (1/3)/0.5·10 = 6.67 sideways; at the
        // ray itself no more than 1/MIN_DISTANCE.
        let f = viewing_force(Vec3::X, 0.5, 1.0 / 3.0, UNIT);
        assert!((f.x - 20.0 / 3.0).abs() < 1e-4);
        assert!((viewing_force(Vec3::X, 0.0, 1.0, UNIT).x - 10.0 / MIN_DISTANCE).abs() < 1e-3);
        // Spacing: centres 2ℓ apart, c_s = 1/6: (1/6)/4·10 away from the other.
        let f = spacing_force(Vec3::new(0.0, 4.0, 0.0), Vec3::ZERO, 1.0 / 6.0, UNIT);
        assert!((f - Vec3::Y * (10.0 / 24.0)).length() < 1e-5, "{f}");
        // The turning-back torque: a quarter turn about z, radius 4 mm = 2ℓ, c_r = 1:
        // −(π/2)·1·(4/2)·10·4 about z.
        let t = return_torque(glam::Quat::from_rotation_z(std::f32::consts::FRAC_PI_2), 4.0, 1.0, UNIT);
        assert!((t - Vec3::NEG_Z * std::f32::consts::FRAC_PI_2 * 80.0).length() < 1e-3, "{t}");
        // Three quarters of a turn is a quarter back the other way.
        let t = return_torque(glam::Quat::from_rotation_z(1.5 * std::f32::consts::PI), 4.0, 1.0, UNIT);
        assert!((t - Vec3::Z * std::f32::consts::FRAC_PI_2 * 80.0).length() < 1e-2, "{t}");
        // Equation 5.
        let c = Coefficients { degree: 3.0, ..Default::default() };
        assert_eq!((c.explosion(), c.viewing(), c.spacing()), (1.5, 1.0, 0.5));
    }

    #[test]
    fn fading_by_the_viewing_force() {
        assert_eq!(fade(0.0, 0.1), 1.0);
        assert_eq!(fade(0.5, 0.1), 0.55);
        assert_eq!(fade(1.0, 0.1), 0.1, "the floor keeps some context");
        assert_eq!(fade(7.0, 0.1), 0.1);
        assert_eq!(fade(0.04, 0.1), 0.95, "in twentieths: 1 − 0.9·0.04 = 0.964");
        // A part a ray crosses (distance 0: the push at MIN_DISTANCE) is in the view far
        // more than a part beside the ray.
        let cube = Polyhedron::cuboid(Vec3::new(-1.0, -1.0, -6.0), Vec3::new(1.0, 1.0, -4.0));
        let beside = Polyhedron::cuboid(Vec3::new(6.0, -1.0, -6.0), Vec3::new(8.0, 1.0, -4.0));
        let points = [ExplosionPoint { position: Vec3::new(0.0, 0.0, -10.0), weight: 1.0 }];
        let centers = [cube.centroid(), beside.centroid()];
        let around = Surroundings { points: &points, centers: &centers, eye: Some(Vec3::ZERO) };
        let c = Coefficients { degree: 1.0, ..Default::default() };
        let w = |index: usize, rest: &Polyhedron| {
            part_wrench(&PartNow { index, rest, to_world: Affine3A::IDENTITY, center_of_mass: rest.centroid() }, &around, &c, UNIT).in_view
        };
        let (front, side) = (w(0, &cube), w(1, &beside));
        // Beside: 6 mm = 3ℓ off the sight line: 1/(1 + 3); crossed: 1.
        assert!((side - 0.25).abs() < 1e-3, "{side}");
        assert!((front - 1.0).abs() < 1e-5, "{front}");
        assert!(fade(front, 0.1) < fade(side, 0.1));
    }

    #[test]
    fn wrenches_and_viewing_rays() {
        // A unit push along y at (1, 0, 0) about the origin: torque x̂ × ŷ = ẑ.
        let w = Wrench::about(Vec3::ZERO, [Push { force: Vec3::Y, at: Vec3::X }, Push { force: Vec3::Y, at: -Vec3::X }]);
        assert_eq!((w.force, w.torque), (Vec3::Y * 2.0, Vec3::ZERO));
        assert_eq!(Wrench::about(Vec3::ZERO, [Push { force: Vec3::Y, at: Vec3::X }]).torque, Vec3::Z);
        // A cube 3 mm to the side of a ray along −z: pushed along +x, its near face 2 mm
        // = 1ℓ off the ray.
        let cube = Polyhedron::cuboid(Vec3::new(2.0, -1.0, -6.0), Vec3::new(4.0, 1.0, -4.0));
        let (dir, d, at) = off_ray(Vec3::ZERO, Vec3::NEG_Z * 10.0, &cube, cube.centroid(), UNIT);
        assert!((dir - Vec3::X).length() < 1e-5 && (d - 1.0).abs() < 1e-4 && (at.x - 2.0).abs() < 1e-4, "{dir} {d} {at}");
        // The ray through the cube: pushed from the ray towards its centre, at distance 0.
        let (dir, d, _) = off_ray(Vec3::new(2.5, 0.0, 0.0), Vec3::NEG_Z * 10.0, &cube, cube.centroid(), UNIT);
        assert!((dir - Vec3::X).length() < 1e-5 && d == 0.0);
        // A part behind the point is not in its way: its distance is from the point.
        let (_, d, _) = off_ray(Vec3::new(2.5, 0.0, 0.0), Vec3::NEG_Z * 2.0, &cube, cube.centroid(), UNIT);
        assert!((d - 1.0).abs() < 1e-4, "2 mm behind the point: {d}");
    }

    #[test]
    fn at_rest_with_degree_zero_nothing_moves_a_part() {
        let cube = Polyhedron::cuboid(Vec3::splat(-1.0), Vec3::splat(1.0));
        let points = [ExplosionPoint { position: Vec3::new(0.0, 0.0, 5.0), weight: 1.0 }];
        let centers = [Vec3::ZERO, Vec3::new(3.0, 0.0, 0.0)];
        let around = Surroundings { points: &points, centers: &centers, eye: Some(Vec3::new(0.0, 0.0, 20.0)) };
        let part = PartNow { index: 0, rest: &cube, to_world: Affine3A::IDENTITY, center_of_mass: Vec3::ZERO };
        let still = part_wrench(&part, &around, &Coefficients::default(), UNIT);
        assert_eq!(still, Wrench::default());
        // Raised, the explosion point above pushes it down (away), the other part to the
        // left (−x).
        let pushed = part_wrench(&part, &around, &Coefficients { degree: 1.0, ..Default::default() }, UNIT);
        assert!(pushed.force.z < 0.0 && pushed.force.x < 0.0, "{:?}", pushed.force);
        // Turned and moved away, the return force pulls it back and turns it back.
        let turned =
            PartNow { to_world: Affine3A::from_rotation_translation(Quat::from_rotation_z(0.3), Vec3::X), center_of_mass: Vec3::X, ..part };
        let back = part_wrench(&turned, &around, &Coefficients::default(), UNIT);
        assert!(back.force.x < 0.0 && back.torque.z < 0.0, "{back:?}");
    }
}
