//! Signed volume: keeps the oriented volume of a tet at its rest value V.
//!
//! With e₁ = p1 − p0, e₂ = p2 − p0, e₃ = p3 − p0:
//!
//! C = ⅙ e₁·(e₂×e₃) − V
//!
//! ∇ₚ₁C = ⅙ e₂×e₃
//! ∇ₚ₂C = ⅙ e₃×e₁
//! ∇ₚ₃C = ⅙ e₁×e₂
//! ∇ₚ₀C = −(∇ₚ₁C + ∇ₚ₂C + ∇ₚ₃C)
//!
//! Each ∇ₚᵢC is the outward-or-inward area normal of the face opposite pᵢ, a third of its area
//! long. V is signed, so an inverted tet (negative volume) is driven back to positive.
//!
//! Invariants checked by the tests: the gradients sum to zero; C is unchanged under translation
//! and rotation and the gradients rotate with the body; swapping two vertices flips the sign of
//! the volume. When all four particles lie on one line every gradient vanishes: the evaluation is
//! flagged degenerate.

use super::{Constraint, Evaluation, first_from_rest};
use crate::numbers::vector::{Mask, Real, Vector3, spans_no_plane};

/// The constraint and its gradients as lines of math, for display (the inspector, lessons).
pub const FORMULA: &[&str] = &[
    "e₁ = p₁ − p₀,  e₂ = p₂ − p₀,  e₃ = p₃ − p₀",
    "C = ⅙ e₁ · (e₂ × e₃) − V",
    "∇ₚ₁C = ⅙ e₂ × e₃",
    "∇ₚ₂C = ⅙ e₃ × e₁",
    "∇ₚ₃C = ⅙ e₁ × e₂",
    "∇ₚ₀C = −(∇ₚ₁C + ∇ₚ₂C + ∇ₚ₃C)",
];

/// V = ⅙ (p1 − p0)·((p2 − p0)×(p3 − p0)) of a rest configuration: positive when
/// (p1 − p0, p2 − p0, p3 − p0) is a right-handed frame.
#[inline(always)]
pub fn rest_value<V: Vector3>(p: &[V; 4]) -> V::Real {
    signed_volume(p)
}

/// ⅙ (p1 − p0)·((p2 − p0)×(p3 − p0)), the signed volume of a tet.
///
/// ```
/// use glam::DVec3;
/// use tetlab_core::constraints::volume::signed_volume;
/// let p = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
/// assert_eq!(signed_volume(&p), 1.0 / 6.0);
/// // Swapping two vertices mirrors the tet: the signed volume flips.
/// assert_eq!(signed_volume(&[p[1], p[0], p[2], p[3]]), -1.0 / 6.0);
/// ```
#[inline(always)]
pub fn signed_volume<V: Vector3>(p: &[V; 4]) -> V::Real {
    let e1 = p[1] - p[0];
    let e2 = p[2] - p[0];
    let e3 = p[3] - p[0];
    e1.dot(e2.cross(e3)) * sixth::<V::Real>()
}

/// C = ⅙ (p1 − p0)·((p2 − p0)×(p3 − p0)) − V and its gradients.
///
/// ```
/// use glam::DVec3;
/// use tetlab_core::constraints::volume;
/// let p = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
/// let e = volume::evaluate(&p, 1.0 / 6.0);
/// assert_eq!(e.value, 0.0);
/// assert_eq!(e.gradients[1], DVec3::X / 6.0); // ⅙ area normal of the face opposite p1
/// ```
#[inline(always)]
pub fn evaluate<V: Vector3>(p: &[V; 4], rest: V::Real) -> Evaluation<V, 4> {
    let e1 = p[1] - p[0];
    let e2 = p[2] - p[0];
    let e3 = p[3] - p[0];
    let c23 = e2.cross(e3);
    let c31 = e3.cross(e1);
    let c12 = e1.cross(e2);
    let sixth = sixth::<V::Real>();
    let value = e1.dot(c23) * sixth - rest;
    // All four points on one line: no two edges span a plane (rarely the case, so the later
    // checks only run when the earlier hold).
    let degenerate = spans_no_plane(e2, e3, c23)
        .and_then(|| spans_no_plane(e3, e1, c31))
        .and_then(|| spans_no_plane(e1, e2, c12));
    let gradients = first_from_rest(c23 * sixth, c31 * sixth, c12 * sixth);
    Evaluation::unless_degenerate(degenerate, value, value, gradients)
}

#[inline(always)]
fn sixth<R: Real>() -> R {
    R::ONE / R::from_f64(6.0)
}

/// The signed volume constraint, as the family table evaluates it ([`evaluate`]).
pub struct Volume;

impl Constraint<4> for Volume {
    #[inline(always)]
    fn evaluate<V: Vector3>(&self, p: &[V; 4], rest: V::Real, _: &[V; 4]) -> Evaluation<V, 4> {
        evaluate(p, rest)
    }
}
