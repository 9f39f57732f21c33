//! Height above the opposite face (the `height` family): keeps p1 at signed height d above the
//! plane of p0, p2, p3.
//!
//! With e₁ = p1 − p0, e₂ = p2 − p0, e₃ = p3 − p0, c = e₂×e₃ and n = c/|c|:
//!
//! C = e₁·n − d
//!
//! ∇ₚ₁C = n
//! ∇ₚ₂C = (e₃×e₁ + (n×e₃)(n·e₁)) / |c|
//! ∇ₚ₃C = −(e₂×e₁ + (n×e₂)(n·e₁)) / |c|
//! ∇ₚ₀C = −(∇ₚ₁C + ∇ₚ₂C + ∇ₚ₃C)
//!
//! d is signed: it carries the orientation of the rest tet, so an inverted tet (p1 on the wrong
//! side of the face) has a large C and is pushed back through the face. A tet has four of these
//! constraints, one per vertex; [`tet_vertex_order`] lists them.
//!
//! Invariants checked by the tests: the gradients sum to zero; C is unchanged under translation
//! and rotation and the gradients rotate with the body; swapping p2 and p3 flips the sign of
//! the height; the height equals 3V / area(p0, p2, p3). A face of zero area has no normal: the
//! evaluation is flagged degenerate, with C = −d.

use super::{Constraint, Evaluation, first_from_rest};
use crate::numbers::vector::{Vector3, spans_no_plane};

/// The constraint and its gradients as lines of math, for display (the inspector, lessons).
pub const FORMULA: &[&str] = &[
    "e₁ = p₁ − p₀,  e₂ = p₂ − p₀,  e₃ = p₃ − p₀,  c = e₂ × e₃,  n = c / |c|",
    "C = e₁ · n − d",
    "∇ₚ₁C = n",
    "∇ₚ₂C = (e₃ × e₁ + (n × e₃)(n · e₁)) / |c|",
    "∇ₚ₃C = −(e₂ × e₁ + (n × e₂)(n · e₁)) / |c|",
    "∇ₚ₀C = −(∇ₚ₁C + ∇ₚ₂C + ∇ₚ₃C)",
];

/// The four height constraints of a tet (a, b, c, d), as index orders into it.
///
/// Entry k keeps vertex k off the plane of the other three, written in the constraint's own order
/// (p0, p1, p2, p3) with p1 = vertex k. Each order is an even permutation of (0, 1, 2, 3) with
/// vertex k moved to position 1, so all four rest heights of a positively oriented tet
/// are positive.
pub const fn tet_vertex_order() -> [[usize; 4]; 4] {
    [[1, 0, 3, 2], [0, 1, 2, 3], [0, 2, 3, 1], [0, 3, 1, 2]]
}

/// e₁·n, the signed height of p1 above the plane of (p0, p2, p3); zero for a degenerate face.
#[inline(always)]
pub fn rest_value<V: Vector3>(p: &[V; 4]) -> V::Real {
    let e = evaluate(p, <V::Real as crate::numbers::vector::Real>::ZERO);
    e.value
}

/// C = (p1 − p0)·n − d and its gradients.
///
/// ```
/// use glam::DVec3;
/// use tetlab_core::constraints::height;
/// let p = [DVec3::ZERO, DVec3::new(0.2, 0.3, 2.0), DVec3::X, DVec3::Y];
/// let e = height::evaluate(&p, 0.0);
/// assert_eq!(e.value, 2.0);                      // p1 is 2 above the z = 0 face
/// assert_eq!(e.gradients[1], DVec3::Z);          // moving p1 along n raises it fastest
/// // Swapping p2 and p3 turns the face over: the height changes sign.
/// let swapped = height::evaluate(&[p[0], p[1], p[3], p[2]], 0.0);
/// assert_eq!(swapped.value, -2.0);
/// ```
#[inline(always)]
pub fn evaluate<V: Vector3>(p: &[V; 4], rest: V::Real) -> Evaluation<V, 4> {
    let e1 = p[1] - p[0];
    let e2 = p[2] - p[0];
    let e3 = p[3] - p[0];
    let c = e2.cross(e3);
    let degenerate = spans_no_plane(e2, e3, c);
    let area2 = c.length();
    let n = c / area2;
    let height = e1.dot(n);
    let g1 = n;
    let g2 = (e3.cross(e1) + n.cross(e3) * height) / area2;
    let g3 = -(e2.cross(e1) + n.cross(e2) * height) / area2;
    let gradients = first_from_rest(g1, g2, g3);
    // A face of zero area has no normal: the height counts as 0.
    Evaluation::unless_degenerate(degenerate, height - rest, -rest, gradients)
}

/// The height above the opposite face constraint, as the family table evaluates it ([`evaluate`]).
pub struct Height;

impl Constraint<4> for Height {
    #[inline(always)]
    fn evaluate<V: Vector3>(&self, p: &[V; 4], rest: V::Real, _: &[V; 4]) -> Evaluation<V, 4> {
        evaluate(p, rest)
    }
}
