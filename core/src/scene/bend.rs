//! A bend: a body laid along x folded upwards about the z axis, over the middle of its length,
//! so that a bar becomes a hook or a hairpin (a scene file's `bend`, [`Bend`]).
//!
//! # The map
//! The bar spans x ∈ [x₀, x₁] and y ∈ [y₀, y₁]. The fold turns about the line through
//! c = (a, y₁ + r) parallel to z, r the inner radius: a point at height y is ρ = c_y − y from
//! it, and the middle of the bar's height, y_m = (y₀ + y₁)/2, is R = c_y − y_m from it. Along
//! the bend the angle grows as φ = (x − a)/R, so the middle line keeps its length; up to φ = θ,
//! the bend's angle, the point goes to c + ρ (sin φ, −cos φ); past it, it goes on straight
//! along (cos θ, sin θ). The bend starts at a = x_m − θR/2, so the two legs are as long.
//! The map turns and stretches but never folds a tet over: along the bend its Jacobian is
//! the rotation by φ times diag(ρ/R, 1), and ρ ≥ r > 0.

use glam::DVec3;

/// A fold by `degrees` about z with the inner radius `radius` (m), over the middle of a body's
/// length along x.
///
/// ```
/// use glam::DVec3;
/// use tetlab_core::scene::Bend;
/// // A bar 2 long and 0.1 high folded by 180° with an inner radius 0.05 is a hairpin: its two
/// // ends lie one above the other, twice the radius apart, and the middle line keeps its length.
/// let bar = [DVec3::new(-1.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0),
///            DVec3::new(-1.0, 0.1, 0.0), DVec3::new(1.0, 0.1, 0.0)];
/// let mut folded = bar;
/// Bend { degrees: 180.0, radius: 0.05 }.apply(&mut folded);
/// assert!((folded[0] - bar[0]).length() < 1e-12, "the first leg stays");
/// let [lower_top, upper_bottom] = [folded[2], folded[3]];
/// assert!((upper_bottom.y - lower_top.y - 0.1).abs() < 1e-12, "a gap of twice the radius");
/// assert!((upper_bottom.x - lower_top.x).abs() < 1e-12, "one end above the other");
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bend {
    /// The angle the bar turns through, in degrees (0, 180].
    pub degrees: f64,
    /// The inner radius, m (> 0).
    pub radius: f64,
}

impl Bend {
    /// Folds `points` (a body along x, y up) in place as the module says.
    pub fn apply(&self, points: &mut [DVec3]) {
        let (lo, hi) = super::mesh::bounds(points);
        let theta = self.degrees.to_radians();
        let centre_y = hi.y + self.radius;
        let middle = centre_y - 0.5 * (lo.y + hi.y);
        let start = 0.5 * (lo.x + hi.x) - 0.5 * theta * middle;
        for p in points {
            let rho = centre_y - p.y;
            let along = p.x - start;
            if along <= 0.0 {
                continue;
            }
            let phi = (along / middle).min(theta);
            let beyond = along - phi * middle;
            let (sin, cos) = phi.sin_cos();
            p.x = start + rho * sin + beyond * cos;
            p.y = centre_y - rho * cos + beyond * sin;
        }
    }
}
