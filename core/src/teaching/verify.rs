//! Checks of the analytic gradients against central finite differences on random configurations.
//!
//! The same routine backs the test suite (which asserts the bound) and `tetlab check-gradients`
//! (which prints the figures quoted in `docs/gradients.md`).

use crate::constraints::{Constraint, Family, Visit};
use crate::numbers::dual::{Dual64, DualVec3};
use crate::numbers::finite_difference::central_difference;
use crate::numbers::random::SplitMix64;
use crate::numbers::vector::Real;
use glam::DVec3;

/// Below this sine of the angle between two edges, or this fraction of the configuration's size
/// for an edge length, a random configuration counts as near-degenerate and is not compared.
pub const CONDITIONING: f64 = 0.05;

/// The error of an analytic gradient against central differences, relative to the gradient's size:
/// maxᵢ |∇ₚᵢC − ∇ₚᵢC_fd|∞ / maxᵢ |∇ₚᵢC|.
pub fn relative_error(analytic: &[DVec3], numeric: &[DVec3]) -> f64 {
    let scale = analytic.iter().map(|g| g.length()).fold(0.0, f64::max);
    let error = max_abs_error(analytic, numeric);
    if scale > 0.0 { error / scale } else { error }
}

/// maxᵢ |∇ₚᵢC − ∇ₚᵢC_fd|∞, the largest difference of any one component.
pub fn max_abs_error(analytic: &[DVec3], numeric: &[DVec3]) -> f64 {
    analytic
        .iter()
        .zip(numeric)
        .map(|(a, n)| (*a - *n).abs().max_element())
        .fold(0.0, f64::max)
}

/// The analytic gradient of `family` at `points` (with rest value `rest` and rest shape
/// `rest_shape`) and the central-difference one, in f64.
pub fn analytic_and_numeric(
    family: Family,
    points: &[DVec3],
    rest: f64,
    rest_shape: &[DVec3],
) -> (Vec<DVec3>, Vec<DVec3>) {
    let analytic = family.evaluate(points, rest, rest_shape).gradients[..points.len()].to_vec();
    let numeric = central_difference(points, |p| family.evaluate(p, rest, rest_shape).value);
    (analytic, numeric)
}

/// ∇C of `family` by forward-mode automatic differentiation ([`crate::numbers::dual`]): the family's own
/// formula evaluated on dual numbers, once per coordinate; the rest shape is held fixed. `None`
/// where a derivative is not finite.
pub fn automatic_gradient(
    family: Family,
    points: &[DVec3],
    rest: f64,
    rest_shape: &[DVec3],
) -> Option<Vec<DVec3>> {
    struct Value<'a>(&'a [DualVec3], f64, &'a [DVec3]);
    impl Visit for Value<'_> {
        type Output = Dual64;
        fn visit<const N: usize, C: Constraint<N>>(self, _: Family, c: &C) -> Dual64 {
            let p: [DualVec3; N] = std::array::from_fn(|k| self.0[k]);
            let shape: [DualVec3; N] =
                std::array::from_fn(|k| DualVec3::seeded(self.2[k], DVec3::ZERO));
            c.evaluate(&p, Dual64::from_f64(self.1), &shape).value
        }
    }
    crate::numbers::dual::gradient(points, |p| family.visit(Value(p, rest, rest_shape)))
}

/// Whether a configuration is far enough from degeneracy for a finite-difference comparison:
/// no edge shorter than [`CONDITIONING`] times the longest, and for the height constraint a face
/// (p0, p2, p3) whose edges meet at a sine of at least [`CONDITIONING`].
pub fn well_conditioned(family: Family, points: &[DVec3]) -> bool {
    let mut lengths = Vec::new();
    for i in 0..points.len() {
        for j in i + 1..points.len() {
            lengths.push(points[i].distance(points[j]));
        }
    }
    let longest = lengths.iter().copied().fold(0.0, f64::max);
    if lengths.iter().any(|&l| l < CONDITIONING * longest) || longest == 0.0 {
        return false;
    }
    if family.row().needs_face_p0_p2_p3 {
        let (e2, e3) = (points[2] - points[0], points[3] - points[0]);
        e2.cross(e3).length() >= CONDITIONING * e2.length() * e3.length()
    } else {
        true
    }
}

/// The outcome of [`random_check`].
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// The family checked.
    pub family: Family,
    /// Configurations compared.
    pub compared: usize,
    /// Configurations drawn but skipped as near-degenerate.
    pub skipped: usize,
    /// The largest [`relative_error`] seen.
    pub max_relative_error: f64,
    /// The mean [`relative_error`].
    pub mean_relative_error: f64,
    /// The largest [`relative_error`] of the analytic gradient against automatic differentiation
    /// ([`automatic_gradient`]), on the same configurations.
    pub max_automatic_error: f64,
}

/// Draws configurations until `samples` well-conditioned ones have been compared: points uniform
/// in a cube of random size 10^U(−2, 2) around a random centre, rest value random in the range of
/// the constraint's own values, and (for a family that reads one) a rest shape drawn the same
/// way. Returns the error statistics.
pub fn random_check(family: Family, samples: usize, seed: u64) -> Report {
    let mut rng = SplitMix64::new(seed);
    let (mut compared, mut skipped) = (0, 0);
    let (mut max_error, mut sum_error, mut max_automatic) = (0.0_f64, 0.0, 0.0_f64);
    while compared < samples {
        let size = 10f64.powf(rng.range(-2.0, 2.0));
        let centre = rng.in_cube(size);
        let mut draw = || -> Vec<DVec3> {
            (0..family.arity())
                .map(|_| centre + rng.in_cube(size))
                .collect()
        };
        let points = draw();
        let rest_shape = if family.uses_rest_shape() {
            draw()
        } else {
            points.clone()
        };
        if !well_conditioned(family, &points) || !well_conditioned(family, &rest_shape) {
            skipped += 1;
            continue;
        }
        let rest = family.evaluate(&points, 0.0, &rest_shape).value * rng.range(-1.5, 1.5);
        let (analytic, numeric) = analytic_and_numeric(family, &points, rest, &rest_shape);
        let error = relative_error(&analytic, &numeric);
        max_error = max_error.max(error);
        if let Some(automatic) = automatic_gradient(family, &points, rest, &rest_shape) {
            max_automatic = max_automatic.max(relative_error(&analytic, &automatic));
        }
        sum_error += error;
        compared += 1;
    }
    Report {
        family,
        compared,
        skipped,
        max_relative_error: max_error,
        mean_relative_error: if compared > 0 {
            sum_error / compared as f64
        } else {
            0.0
        },
        max_automatic_error: max_automatic,
    }
}
