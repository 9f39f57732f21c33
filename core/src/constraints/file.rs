//! A constraint file's family as a [`Constraint`]: its compiled tape gives C and ∇C. The file
//! joins the table of families in [`super::Families`].

use super::{Constraint, Evaluation};
use super::{MAX_STORED, Stored};
use crate::constraint_file::ConstraintFile;
use crate::constraints::material::Material;
use crate::numbers::vector::Vector3;
use arrayvec::ArrayVec;
use glam::DVec3;

/// A constraint file's family as a [`Constraint`] on N particles: C and ∇C from the file's
/// compiled tape ([`ConstraintFile::evaluate_vectors`]), the rest value as the file defines it.
/// `SHAPE` says whether it reads the rest shape ([`ConstraintFile::reads_rest_shape`]), so that
/// the solvers gather the rest positions only for one that does.
pub struct FileConstraint<'a, const N: usize, const SHAPE: bool>(pub &'a ConstraintFile);

impl<const N: usize, const SHAPE: bool> Constraint<N> for FileConstraint<'_, N, SHAPE> {
    const USES_REST_SHAPE: bool = SHAPE;
    // μ and λ may appear in what an element stores and in its rest value.
    const REST_USES_MATERIAL: bool = true;

    /// C and ∇C with what the element stores worked out here from `rest_shape` and the default
    /// material: for the checkers and readers that hold no stored values (the solvers call
    /// [`Constraint::evaluate_stored`]).
    #[inline]
    fn evaluate<V: Vector3>(&self, p: &[V; N], rest: V::Real, shape: &[V; N]) -> Evaluation<V, N> {
        if self.0.stored_len() == 0 {
            return self.0.evaluate_vectors(p, rest, &[]);
        }
        let mut stored: ArrayVec<V::Real, MAX_STORED> = ArrayVec::new();
        let shape: [[V::Real; 3]; N] = std::array::from_fn(|k| shape[k].to_array());
        for x in self.0.store_in(&shape, &Material::default()) {
            stored.push(x);
        }
        self.0.evaluate_vectors(p, rest, &stored)
    }

    #[inline(always)]
    fn evaluate_stored<V: Vector3>(
        &self,
        p: &[V; N],
        rest: V::Real,
        _: &[V; N],
        stored: &[V::Real],
    ) -> Evaluation<V, N> {
        self.0.evaluate_vectors(p, rest, stored)
    }

    fn stored_len(&self) -> usize {
        self.0.stored_len()
    }

    fn store(&self, rest_shape: &[DVec3; N], material: &Material) -> Stored {
        self.0.store(rest_shape, material)
    }

    fn rest_value(&self, rest_shape: &[DVec3; N], material: &Material) -> f64 {
        self.0.rest_value(rest_shape, material)
    }
}
