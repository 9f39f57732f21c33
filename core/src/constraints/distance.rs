//! Edge distance: keeps two particles a rest distance d apart.
//!
//! C(p0, p1) = |p0 − p1| − d
//!
//! ∇ₚ₀C = (p0 − p1)/|p0 − p1|, ∇ₚ₁C = −∇ₚ₀C: a unit vector along the edge, pushing the ends
//! apart when the edge is short and together when it is long.
//!
//! Invariants checked by the tests: the gradients sum to zero and have unit length; C does not
//! change under translation or rotation and the gradients rotate with the body. Coincident
//! particles have no edge direction: the evaluation is flagged degenerate.

use super::{Constraint, Evaluation};
use crate::numbers::vector::{Real, Vector3};

/// The constraint and its gradients as lines of math, for display (the inspector, lessons).
pub const FORMULA: &[&str] = &[
    "C = |p₀ − p₁| − d",
    "∇ₚ₀C = (p₀ − p₁) / |p₀ − p₁|",
    "∇ₚ₁C = −∇ₚ₀C",
];

/// d = |p0 − p1| of a rest configuration.
#[inline(always)]
pub fn rest_value<V: Vector3>(p: &[V; 2]) -> V::Real {
    (p[0] - p[1]).length()
}

/// C = |p0 − p1| − d and its gradient.
///
/// ```
/// use glam::DVec3;
/// use tetlab_core::constraints::distance;
/// let e = distance::evaluate(&[DVec3::new(3.0, 4.0, 0.0), DVec3::ZERO], 4.0);
/// assert_eq!(e.value, 1.0);
/// assert_eq!(e.gradients[0], DVec3::new(0.6, 0.8, 0.0));
/// assert_eq!(e.gradients[0] + e.gradients[1], DVec3::ZERO);
/// ```
#[inline(always)]
pub fn evaluate<V: Vector3>(p: &[V; 2], rest: V::Real) -> Evaluation<V, 2> {
    let delta = p[0] - p[1];
    let length = delta.length();
    let value = length - rest;
    let degenerate = !length.finite() | length.le(V::Real::MIN_POSITIVE);
    let direction = delta / length;
    Evaluation::unless_degenerate(degenerate, value, value, [direction, -direction])
}

/// The edge distance constraint, as the family table evaluates it ([`evaluate`]).
pub struct Distance;

impl Constraint<2> for Distance {
    #[inline(always)]
    fn evaluate<V: Vector3>(&self, p: &[V; 2], rest: V::Real, _: &[V; 2]) -> Evaluation<V, 2> {
        evaluate(p, rest)
    }
}
