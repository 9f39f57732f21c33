//! Contact (the `contact` family): a particle p0 kept at least a thickness d above the plane of a
//! surface triangle (p1, p2, p3) of another body, or of its own body away from it.
//!
//! It is the height constraint ([`super::height`]) with its particles renamed: the height of a
//! corner above its tet's opposite face, and the height of a particle above a triangle it is
//! about to go through, are one formula. With e₀ = p0 − p1, e₂ = p2 − p1, e₃ = p3 − p1,
//! c = e₂×e₃ and n = c/|c| (the triangle wound so that n points out of its body):
//!
//! C = e₀·n − d ≥ 0
//!
//! ∇ₚ₀C = n
//! ∇ₚ₂C = (e₃×e₀ + (n×e₃)(n·e₀)) / |c|
//! ∇ₚ₃C = −(e₂×e₀ + (n×e₂)(n·e₀)) / |c|
//! ∇ₚ₁C = −(∇ₚ₀C + ∇ₚ₂C + ∇ₚ₃C)
//!
//! Unlike the other families it is an inequality: a contact is projected only while C < 0, and
//! only while p0 lies over the triangle (its foot on the plane inside it). Its constraints are
//! not bound to the mesh once for all but found every frame ([`super::Binding::Contacts`],
//! `crate::simulation::contact`), and d is the contact's thickness, a setting, not a rest value.
//! An inverted tet is a corner that went through its own opposite face; a penetration is a
//! particle that went through another body's surface: the same C and ∇C push both back.

use super::{Constraint, Evaluation, height};
use crate::numbers::vector::Vector3;

/// The constraint and its gradients as lines of math, for display (the inspector, lessons).
pub const FORMULA: &[&str] = &[
    "e₀ = p₀ − p₁,  e₂ = p₂ − p₁,  e₃ = p₃ − p₁,  c = e₂ × e₃,  n = c / |c|",
    "C = e₀ · n − d ≥ 0   (d: the thickness)",
    "∇ₚ₀C = n",
    "∇ₚ₂C = (e₃ × e₀ + (n × e₃)(n · e₀)) / |c|",
    "∇ₚ₃C = −(e₂ × e₀ + (n × e₂)(n · e₀)) / |c|",
    "∇ₚ₁C = −(∇ₚ₀C + ∇ₚ₂C + ∇ₚ₃C)",
];

/// C = (p0 − p1)·n − d, n the unit normal of the triangle (p1, p2, p3), and its gradients: the
/// height of p0 above the triangle, less the thickness.
///
/// ```
/// use glam::DVec3;
/// use tetlab_core::constraints::{contact, height};
/// // A particle 0.3 above the triangle z = 0, with a thickness of 0.1.
/// let p = [DVec3::new(0.2, 0.2, 0.3), DVec3::ZERO, DVec3::X, DVec3::Y];
/// let e = contact::evaluate(&p, 0.1);
/// assert!((e.value - 0.2).abs() < 1e-15);
/// assert_eq!(e.gradients[0], DVec3::Z); // the particle is pushed along the normal
/// // It is the height constraint with p0 and p1 swapped, gradients and all.
/// let h = height::evaluate(&[p[1], p[0], p[2], p[3]], 0.1);
/// assert_eq!(h.value, e.value);
/// assert_eq!([h.gradients[1], h.gradients[0]], [e.gradients[0], e.gradients[1]]);
/// ```
#[inline(always)]
pub fn evaluate<V: Vector3>(p: &[V; 4], thickness: V::Real) -> Evaluation<V, 4> {
    let mut e = height::evaluate(&[p[1], p[0], p[2], p[3]], thickness);
    e.gradients.swap(0, 1);
    e
}

/// The contact constraint, as the family table evaluates it ([`evaluate`]).
pub struct Contact;

impl Constraint<4> for Contact {
    #[inline(always)]
    fn evaluate<V: Vector3>(&self, p: &[V; 4], rest: V::Real, _: &[V; 4]) -> Evaluation<V, 4> {
        evaluate(p, rest)
    }
}
