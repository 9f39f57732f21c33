//! Stable neo-Hookean tets (the `neohookean` family: Macklin & Müller 2021, on the energy of
//! Smith et al. 2018): two constraints per tet, deviatoric and hydrostatic, whose compliances
//! come from a [`Material`].
//!
//! # Formula
//! With eᵢ = pᵢ − p₀ and rᵢ the same edges at rest, Ds = [e₁ e₂ e₃], Dm = [r₁ r₂ r₃],
//! F = Ds Dm⁻¹ and the rest volume V₀ = det Dm / 6. The rows of Dm⁻¹ are
//! bᵢ = (rⱼ × rₖ) / det Dm for (i, j, k) = (1, 2, 3), (2, 3, 1), (3, 1, 2), so F = Σᵢ eᵢ bᵢᵀ.
//!
//! - Deviatoric: C_D = s ‖F‖_F, with s = √|V₀| and ‖F‖² = Σᵢₖ (eᵢ·eₖ)(bᵢ·bₖ);
//!   ∇ₚₖC_D = s F bₖ / ‖F‖ = s Σᵢ eᵢ (bᵢ·bₖ) / ‖F‖ for k = 1, 2, 3.
//! - Hydrostatic: C_H = s (det F − γ), det F = e₁·(e₂×e₃) / det Dm;
//!   ∇ₚ₁C_H = s (e₂×e₃) / det Dm, ∇ₚ₂C_H = s (e₃×e₁) / det Dm, ∇ₚ₃C_H = s (e₁×e₂) / det Dm,
//!   the columns of s cof(F) Dm⁻ᵀ.
//! - ∇ₚ₀C = −(∇ₚ₁C + ∇ₚ₂C + ∇ₚ₃C) for both.
//!
//! Scaling C by s = √|V₀| makes the paper's per-tet compliances 1/(μ V₀) and 1/(λ V₀) the same
//! for every tet of a family, 1/μ and 1/λ: XPBD with C and α/V₀ takes exactly the steps of XPBD
//! with √V₀ C and α (docs/gradients.md). The rest value of the deviatoric constraint is 0 and
//! of the hydrostatic one s γ, γ = 1 + μ/λ: at rest the two pull against each other and
//! balance.
//!
//! cof F is not zero when det F ≤ 0 (only when the tet collapses onto a line), so the
//! hydrostatic constraint pushes an inverted tet back through itself. A tet whose rest shape has
//! no volume, or whose deformed shape is a point (‖F‖ = 0), has no gradient: the evaluation is
//! flagged degenerate with C finite.
//!
//! ```
//! use glam::{DMat3, DVec3};
//! use tetlab_core::constraints::neohookean::{deviatoric, hydrostatic};
//! let rest = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
//! // At rest F = I: ‖F‖ = √3, det F = 1, each scaled by √V₀ = √(1/6).
//! let s = (1.0f64 / 6.0).sqrt();
//! assert!((deviatoric(&rest, 0.0, &rest).value - s * 3f64.sqrt()).abs() < 1e-15);
//! assert!((hydrostatic(&rest, 0.0, &rest).value - s).abs() < 1e-15);
//! // Mirrored (p1 through the face p0 p2 p3): det F = −1, and the gradient still points back.
//! let mirrored = [DVec3::ZERO, -DVec3::X, DVec3::Y, DVec3::Z];
//! let h = hydrostatic(&mirrored, 0.0, &rest);
//! assert!((h.value + s).abs() < 1e-15);
//! // C < 0 and ∇ₚ₁C points along +x: the step −C ∇C / |∇C|² moves p1 back through the face.
//! assert!(h.value < 0.0 && h.gradients[1].x > 0.0);
//! ```

use super::{Constraint, Evaluation, first_from_rest};
use crate::constraints::material::Material;
use crate::numbers::vector::{Real, Vector3};
use glam::{DMat3, DVec3};

/// The deviatoric constraint and its gradients as lines of math (the inspector, lessons).
pub const DEVIATORIC_FORMULA: &[&str] = &[
    "eᵢ = pᵢ − p₀,  F = Ds Dm⁻¹ = Σᵢ eᵢ bᵢᵀ,  bᵢ the rows of Dm⁻¹,  s = √V₀",
    "C = s ‖F‖_F",
    "∇ₚₖC = s F bₖ / ‖F‖_F   (k = 1, 2, 3)",
    "∇ₚ₀C = −(∇ₚ₁C + ∇ₚ₂C + ∇ₚ₃C)",
    "compliance 1/μ",
];

/// The hydrostatic constraint and its gradients as lines of math.
pub const HYDROSTATIC_FORMULA: &[&str] = &[
    "eᵢ = pᵢ − p₀,  det F = e₁ · (e₂ × e₃) / det Dm,  s = √V₀,  γ = 1 + μ/λ",
    "C = s (det F − γ)",
    "∇ₚ₁C = s e₂ × e₃ / det Dm,  ∇ₚ₂C = s e₃ × e₁ / det Dm,  ∇ₚ₃C = s e₁ × e₂ / det Dm",
    "∇ₚ₀C = −(∇ₚ₁C + ∇ₚ₂C + ∇ₚ₃C)",
    "compliance 1/λ",
];

/// What the rest shape gives both constraints: the rows bᵢ of Dm⁻¹, det Dm, s = √|V₀|, and
/// whether the rest shape has no volume (then b and s are zero).
struct RestFrame<V: Vector3> {
    b: [V; 3],
    det: V::Real,
    scale: V::Real,
    degenerate: <V::Real as Real>::Mask,
}

#[inline(always)]
fn rest_frame<V: Vector3>(r: &[V; 4]) -> RestFrame<V> {
    let r1 = r[1] - r[0];
    let r2 = r[2] - r[0];
    let r3 = r[3] - r[0];
    let c23 = r2.cross(r3);
    let det = r1.dot(c23);
    // No volume at working precision: |det Dm| ≤ ε |r₁| |r₂| |r₃| (compared squared).
    let eps = V::Real::EPSILON;
    let bound = eps * eps * r1.length_squared() * r2.length_squared() * r3.length_squared();
    let degenerate = !(det * det).gt(bound);
    let safe_det = V::Real::select(degenerate, V::Real::ONE, det);
    let abs_det = V::Real::select(det.gt(V::Real::ZERO), det, -det);
    let scale = V::Real::select(
        degenerate,
        V::Real::ZERO,
        (abs_det / V::Real::from_f64(6.0)).sqrt(),
    );
    RestFrame {
        b: [
            c23 / safe_det,
            r3.cross(r1) / safe_det,
            r1.cross(r2) / safe_det,
        ],
        det: safe_det,
        scale,
        degenerate,
    }
}

/// C_D = √|V₀| ‖F‖_F − `rest` and its gradients, F from the rest shape `rest_shape`.
#[inline]
pub fn deviatoric<V: Vector3>(p: &[V; 4], rest: V::Real, rest_shape: &[V; 4]) -> Evaluation<V, 4> {
    let frame = rest_frame(rest_shape);
    let e = [p[1] - p[0], p[2] - p[0], p[3] - p[0]];
    let b = frame.b;
    let (g00, g11, g22) = (b[0].dot(b[0]), b[1].dot(b[1]), b[2].dot(b[2]));
    let (g01, g02, g12) = (b[0].dot(b[1]), b[0].dot(b[2]), b[1].dot(b[2]));
    // F bₖ = Σᵢ eᵢ (bᵢ·bₖ).
    let fb = [
        e[0] * g00 + e[1] * g01 + e[2] * g02,
        e[0] * g01 + e[1] * g11 + e[2] * g12,
        e[0] * g02 + e[1] * g12 + e[2] * g22,
    ];
    let norm_squared = e[0].dot(fb[0]) + e[1].dot(fb[1]) + e[2].dot(fb[2]);
    // ‖F‖ = 0 at working precision (against ‖I‖² = 3): the tet is squashed to a point.
    let eps = V::Real::EPSILON;
    let collapsed = !norm_squared.gt(eps * eps * V::Real::from_f64(3.0));
    let degenerate = frame.degenerate | collapsed;
    let norm = V::Real::select(collapsed, V::Real::ONE, norm_squared.sqrt());
    let factor = frame.scale / norm;
    let gradients = first_from_rest(fb[0] * factor, fb[1] * factor, fb[2] * factor);
    let value = frame.scale * norm - rest;
    let at_zero = V::Real::select(collapsed, -rest, value);
    Evaluation::unless_degenerate(degenerate, value, at_zero, gradients)
}

/// C_H = √|V₀| det F − `rest` (the rest value holds √|V₀| γ) and its gradients: det F =
/// 6V / det Dm, so this is the signed volume constraint ([`super::volume::evaluate`]) scaled by
/// 6 √|V₀| / det Dm, degenerate where that one is (all four points on one line) or where the
/// rest shape has no volume.
#[inline]
pub fn hydrostatic<V: Vector3>(p: &[V; 4], rest: V::Real, rest_shape: &[V; 4]) -> Evaluation<V, 4> {
    let frame = rest_frame(rest_shape);
    let volume = super::volume::evaluate(p, V::Real::ZERO);
    let factor = frame.scale * V::Real::from_f64(6.0) / frame.det;
    let value = volume.value * factor - rest;
    let gradients = volume.gradients.map(|g| g * factor);
    let degenerate = frame.degenerate | volume.degenerate;
    Evaluation::unless_degenerate(degenerate, value, value, gradients)
}

/// F = Ds Dm⁻¹ of a tet at `p` with rest shape `rest_shape`; `None` when the rest shape has no
/// volume.
pub(crate) fn deformation_gradient(p: &[DVec3; 4], rest_shape: &[DVec3; 4]) -> Option<DMat3> {
    let columns = |q: &[DVec3; 4]| DMat3::from_cols(q[1] - q[0], q[2] - q[0], q[3] - q[0]);
    let dm = columns(rest_shape);
    (!rest_frame(rest_shape).degenerate).then(|| columns(p) * dm.inverse())
}

/// F, det F and ‖F‖, for the inspector.
fn describe(p: &[DVec3; 4], rest_shape: &[DVec3; 4]) -> Vec<String> {
    let Some(f) = deformation_gradient(p, rest_shape) else {
        return vec!["the rest tet has no volume: F = Ds Dm⁻¹ is undefined".to_owned()];
    };
    let row = |i: usize| {
        let r = f.row(i);
        format!("{:+.4} {:+.4} {:+.4}", r.x, r.y, r.z)
    };
    let norm =
        (f.x_axis.length_squared() + f.y_axis.length_squared() + f.z_axis.length_squared()).sqrt();
    vec![
        format!("F = [{}; {}; {}]", row(0), row(1), row(2)),
        format!("J = det F = {:+.4}   ‖F‖ = {norm:.4}", f.determinant()),
    ]
}

/// √|V₀| of a rest tet (0 when it has no volume).
fn scale(rest_shape: &[DVec3; 4]) -> f64 {
    rest_frame(rest_shape).scale
}

/// The deviatoric constraint, as the family table evaluates it ([`deviatoric`]).
pub struct Deviatoric;

impl Constraint<4> for Deviatoric {
    const STORED_USES_REST_SHAPE: bool = true;

    #[inline(always)]
    fn evaluate<V: Vector3>(&self, p: &[V; 4], rest: V::Real, shape: &[V; 4]) -> Evaluation<V, 4> {
        deviatoric(p, rest, shape)
    }

    /// 0: the deviatoric constraint pulls towards F = 0; the hydrostatic one holds it off.
    fn rest_value(&self, _: &[DVec3; 4], _: &Material) -> f64 {
        0.0
    }

    fn describe_state(&self, p: &[DVec3; 4], rest_shape: &[DVec3; 4]) -> Vec<String> {
        describe(p, rest_shape)
    }
}

/// The hydrostatic constraint, as the family table evaluates it ([`hydrostatic`]).
pub struct Hydrostatic;

impl Constraint<4> for Hydrostatic {
    const STORED_USES_REST_SHAPE: bool = true;

    #[inline(always)]
    fn evaluate<V: Vector3>(&self, p: &[V; 4], rest: V::Real, shape: &[V; 4]) -> Evaluation<V, 4> {
        hydrostatic(p, rest, shape)
    }

    /// √|V₀| γ, γ = 1 + μ/λ: det F at rest is 1, and the constraint aims a little above it.
    fn rest_value(&self, rest_shape: &[DVec3; 4], material: &Material) -> f64 {
        scale(rest_shape) * material.gamma()
    }

    fn describe_state(&self, p: &[DVec3; 4], rest_shape: &[DVec3; 4]) -> Vec<String> {
        describe(p, rest_shape)
    }
}
