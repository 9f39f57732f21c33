//! A constraint file's family as a [`Constraint`]: its compiled tape gives C and ∇C. The file
//! joins the table of families in [`super::Families`].

use super::{Constraint, Evaluation};
use crate::constraint_file::ConstraintFile;
use crate::constraints::material::Material;
use crate::numbers::vector::Vector3;
use glam::DVec3;

/// A constraint file's family as a [`Constraint`] on N particles: C and ∇C from the file's
/// compiled tape ([`ConstraintFile::evaluate_vectors`]), the rest value as the file defines it.
pub struct FileConstraint<'a, const N: usize>(pub &'a ConstraintFile);

impl<const N: usize> Constraint<N> for FileConstraint<'_, N> {
    #[inline]
    fn evaluate<V: Vector3>(&self, p: &[V; N], rest: V::Real, _: &[V; N]) -> Evaluation<V, N> {
        self.0.evaluate_vectors(p, rest)
    }

    fn rest_value(&self, rest_shape: &[DVec3; N], _: &Material) -> f64 {
        self.0.rest_value(rest_shape)
    }
}
