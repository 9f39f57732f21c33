//! Any family's constraint in f64 behind one object-safe interface ([`AnyConstraint`]), for
//! everything that is not a solver's loop: the gradient check and `tetlab gradient`, the rest
//! values and stored numbers a simulation builds once, the inspector's extra lines. The solvers,
//! which run the formula in f32 lanes, and automatic differentiation, which runs it on dual
//! numbers, reach the type itself through [`super::Families::visit`].

use super::material::Material;
use super::{Constraint, Evaluation, Stored, SubstepStart};
use glam::DVec3;

/// What every family's constraint answers in f64, whatever its arity: points and rest shapes are
/// slices of the family's arity ([`super::Row::arity`]), gradients are padded to four.
pub trait AnyConstraint: Send + Sync {
    /// C and ∇C at `points` with rest value `rest` and the particles at rest at `rest_shape`
    /// ([`Constraint::evaluate`]); for a family that stores numbers, what it would store is
    /// worked out from `rest_shape` and the default material.
    fn evaluate(&self, points: &[DVec3], rest: f64, rest_shape: &[DVec3]) -> Evaluation<DVec3, 4>;

    /// C and ∇C given what the element stores, as the solvers evaluate it
    /// ([`Constraint::evaluate_stored`]).
    fn evaluate_stored(
        &self,
        points: &[DVec3],
        rest: f64,
        rest_shape: &[DVec3],
        stored: &[f64],
    ) -> Evaluation<DVec3, 4>;

    /// The rest value of a constraint at rest at `rest_shape` ([`Constraint::rest_value`]).
    fn rest_value(&self, rest_shape: &[DVec3], material: &Material) -> f64;

    /// What a constraint at rest at `rest_shape` stores ([`Constraint::store`]).
    fn store(&self, rest_shape: &[DVec3], material: &Material) -> Stored;

    /// What else a reader should see of the particles ([`Constraint::describe_state`]).
    fn describe_state(&self, points: &[DVec3], rest_shape: &[DVec3]) -> Vec<String>;
}

/// A [`Constraint`] on `N` particles as an [`AnyConstraint`].
///
/// ```
/// use glam::DVec3;
/// use tetlab_core::constraints::{AnyConstraint, Typed};
/// use tetlab_core::constraints::distance::Distance;
/// let edge: &dyn AnyConstraint = &Typed::<2, _>(Distance);
/// let (a, b) = (DVec3::ZERO, DVec3::new(3.0, 4.0, 0.0));
/// // C = |p0 − p1| − d, and the gradients of a length are opposite unit vectors.
/// let e = edge.evaluate(&[a, b], 5.0, &[a, b]);
/// assert_eq!(e.value, 0.0);
/// assert!((e.gradients[0] + e.gradients[1]).length() < 1e-15);
/// ```
pub struct Typed<const N: usize, C>(pub C);

/// The first `N` points as an array.
///
/// # Panics
/// If there are fewer than `N`.
fn points<const N: usize>(points: &[DVec3]) -> [DVec3; N] {
    assert!(
        points.len() >= N,
        "{} points for a constraint of {N}",
        points.len()
    );
    std::array::from_fn(|k| points[k])
}

/// An evaluation's gradients padded to four particles.
fn padded<const N: usize>(e: Evaluation<DVec3, N>) -> Evaluation<DVec3, 4> {
    let mut gradients = [DVec3::ZERO; 4];
    gradients[..N].copy_from_slice(&e.gradients);
    Evaluation {
        value: e.value,
        gradients,
        degenerate: e.degenerate,
    }
}

impl<const N: usize, C: Constraint<N> + Send> AnyConstraint for Typed<N, C> {
    fn evaluate(&self, p: &[DVec3], rest: f64, rest_shape: &[DVec3]) -> Evaluation<DVec3, 4> {
        padded(self.0.evaluate(&points(p), rest, &points(rest_shape)))
    }

    fn evaluate_stored(
        &self,
        p: &[DVec3],
        rest: f64,
        rest_shape: &[DVec3],
        stored: &[f64],
    ) -> Evaluation<DVec3, 4> {
        let (shape, p) = (points(rest_shape), points(p));
        padded(
            self.0
                .evaluate_stored(&p, rest, &shape, stored, SubstepStart::at_rest(&p)),
        )
    }

    fn rest_value(&self, rest_shape: &[DVec3], material: &Material) -> f64 {
        self.0.rest_value(&points(rest_shape), material)
    }

    fn store(&self, rest_shape: &[DVec3], material: &Material) -> Stored {
        self.0.store(&points(rest_shape), material)
    }

    fn describe_state(&self, p: &[DVec3], rest_shape: &[DVec3]) -> Vec<String> {
        self.0.describe_state(&points(p), &points(rest_shape))
    }
}
