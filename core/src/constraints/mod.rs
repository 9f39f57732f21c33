//! The three tetrahedron constraints of tetlab and their analytic gradients.
//!
//! Each constraint is a scalar function C of a few particle positions that is zero when the
//! constraint holds. A projection moves every particle along −∇C, so each module here gives the
//! value C, the gradient ∇C with respect to every particle it touches, and the rest value (d or
//! V) measured on a rest configuration. The derivations are in `docs/gradients.md`.
//!
//! | family | particles | C |
//! | --- | --- | --- |
//! | [`distance`] | p0, p1 | \|p0 − p1\| − d |
//! | [`plane`] | p0, p1, p2, p3 | (p1 − p0)·n − d, n the unit normal of (p0, p2, p3) |
//! | [`volume`] | p0, p1, p2, p3 | ⅙ (p1 − p0)·((p2 − p0)×(p3 − p0)) − V |
//!
//! When a gradient is undefined (coincident points, a face of zero area) the evaluation is
//! flagged ([`Evaluation::degenerate`]), its gradients are zero and its value stays finite.

pub mod distance;
pub mod plane;
pub mod volume;

use crate::vector::{Real, Vector3};
use glam::DVec3;

/// A constraint evaluated at one configuration: C and ∇C for each of its N particles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Evaluation<V: Vector3, const N: usize> {
    /// C, the constraint value; zero when the constraint is satisfied.
    pub value: V::Real,
    /// ∇ₚᵢC for each particle pᵢ, in the constraint's particle order.
    pub gradients: [V; N],
    /// Set when ∇C is undefined here (per lane, for lanes); the gradients are then zero.
    pub degenerate: <V::Real as Real>::Mask,
}

impl<V: Vector3, const N: usize> Evaluation<V, N> {
    /// C and ∇C, except where `degenerate` is set: there the value is `degenerate_value` and the
    /// gradients zero.
    #[inline(always)]
    pub fn unless_degenerate(
        degenerate: <V::Real as Real>::Mask,
        value: V::Real,
        degenerate_value: V::Real,
        gradients: [V; N],
    ) -> Self {
        let mut kept = [V::ZERO; N];
        for (k, g) in gradients.iter().enumerate() {
            kept[k] = V::select(degenerate, V::ZERO, *g);
        }
        Self {
            value: V::Real::select(degenerate, degenerate_value, value),
            gradients: kept,
            degenerate,
        }
    }

    /// Σᵢ |∇ₚᵢC|², unweighted.
    #[inline]
    pub fn gradient_norm_squared(&self) -> V::Real {
        let mut sum = V::Real::ZERO;
        for g in &self.gradients {
            sum += g.length_squared();
        }
        sum
    }
}

/// The gradient of the first particle of a translation-invariant constraint:
/// ∇ₚ₀C = −(∇ₚ₁C + ∇ₚ₂C + ∇ₚ₃C), since moving all four particles together leaves C unchanged.
#[inline]
pub(crate) fn first_from_rest<V: Vector3>(g1: V, g2: V, g3: V) -> [V; 4] {
    [-(g1 + g2 + g3), g1, g2, g3]
}

/// One of the three constraint families, for code that picks a family at run time.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Family {
    /// Edge distance, [`distance`].
    Distance,
    /// Height of a vertex above the opposite face, [`plane`].
    Plane,
    /// Signed volume, [`volume`].
    Volume,
}

impl Family {
    /// Every family, in a fixed order.
    pub const ALL: [Family; 3] = [Family::Distance, Family::Plane, Family::Volume];

    /// The name used on the command line and in files.
    pub fn name(self) -> &'static str {
        match self {
            Family::Distance => "distance",
            Family::Plane => "plane",
            Family::Volume => "volume",
        }
    }

    /// The family with this command-line name.
    pub fn from_name(name: &str) -> Option<Family> {
        Family::ALL.into_iter().find(|f| f.name() == name)
    }

    /// The family a user means: `edges` (or `edge`, `distance`), `plane` (or `height`,
    /// `heights`) or `volume`, as written on the command line and in lesson files.
    ///
    /// ```
    /// use tetlab_core::constraints::Family;
    /// assert_eq!(Family::parse(" edges"), Ok(Family::Distance));
    /// assert!(Family::parse("edgy").unwrap_err().contains("'edgy'"));
    /// ```
    pub fn parse(name: &str) -> Result<Family, String> {
        match name.trim() {
            "edges" | "edge" | "distance" => Ok(Family::Distance),
            "plane" | "height" | "heights" => Ok(Family::Plane),
            "volume" => Ok(Family::Volume),
            other => Err(format!(
                "'{other}' is not a constraint family: expected edges, plane or volume"
            )),
        }
    }

    /// The name used for the family in `--constraints` and lesson files: edges, plane or volume.
    pub fn short_name(self) -> &'static str {
        match self {
            Family::Distance => "edges",
            Family::Plane => "plane",
            Family::Volume => "volume",
        }
    }

    /// The constraint and its gradients as lines of math: [`distance::FORMULA`],
    /// [`plane::FORMULA`] or [`volume::FORMULA`].
    pub fn formula(self) -> &'static [&'static str] {
        match self {
            Family::Distance => distance::FORMULA,
            Family::Plane => plane::FORMULA,
            Family::Volume => volume::FORMULA,
        }
    }

    /// How many particles one constraint of this family touches.
    pub fn arity(self) -> usize {
        match self {
            Family::Distance => 2,
            Family::Plane | Family::Volume => 4,
        }
    }

    /// C and ∇C in f64 for `points.len() == self.arity()` particles.
    ///
    /// # Panics
    /// If the number of points is not the family's arity; callers check it first.
    pub fn evaluate(self, points: &[DVec3], rest: f64) -> Evaluation<DVec3, 4> {
        assert_eq!(
            points.len(),
            self.arity(),
            "wrong number of points for {self:?}"
        );
        match self {
            Family::Distance => {
                let e = distance::evaluate(&[points[0], points[1]], rest);
                Evaluation {
                    value: e.value,
                    gradients: [e.gradients[0], e.gradients[1], DVec3::ZERO, DVec3::ZERO],
                    degenerate: e.degenerate,
                }
            }
            Family::Plane => plane::evaluate(&four(points), rest),
            Family::Volume => volume::evaluate(&four(points), rest),
        }
    }

    /// The rest value (d or V) of a rest configuration of `self.arity()` particles.
    ///
    /// # Panics
    /// If the number of points is not the family's arity.
    pub fn rest_value(self, points: &[DVec3]) -> f64 {
        assert_eq!(
            points.len(),
            self.arity(),
            "wrong number of points for {self:?}"
        );
        match self {
            Family::Distance => distance::rest_value(&[points[0], points[1]]),
            Family::Plane => plane::rest_value(&four(points)),
            Family::Volume => volume::rest_value(&four(points)),
        }
    }
}

fn four(points: &[DVec3]) -> [DVec3; 4] {
    [points[0], points[1], points[2], points[3]]
}
