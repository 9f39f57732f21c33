//! The traits through which code reaches a family's [`Constraint`] type with it known at compile
//! time, so that the formula is inlined into the loop (and into SIMD lanes, and dual numbers):
//! [`Visit`] for one family, [`VisitProjected`] for what one projection moves ([`Unit`]: a
//! family alone, or the two of a pair as one constraint of two values, [`Projected`], [`Pair`]).
//! The dispatch itself is [`super::Families::visit`] and [`super::Families::visit_unit`].

use super::{Constraint, Evaluation, Family, GROUP, SubstepStart};
use crate::numbers::lanes::{F32x8, Vec3x8};
use crate::numbers::vector::Vector3;

/// Code that works on one family's constraints with the family's [`Constraint`] type known at
/// compile time: the solvers' per-family loops, metrics over every constraint, and automatic
/// differentiation (which runs the formula on dual numbers).
pub trait Visit {
    /// What the visit gives.
    type Output;
    /// Works on `family`, whose constraints `constraint` evaluates, `N` particles each.
    fn visit<const N: usize, C: Constraint<N>>(
        self,
        family: Family,
        constraint: &C,
    ) -> Self::Output;
}

/// What one projection evaluates: `K` constraints on the same `N` particles, projected together
/// (one correction from all `K` multipliers, [`crate::simulation::projection::correct`]). A
/// family on its own is `K = 1` (every [`Constraint`] is one); two families projected together
/// ([`super::Row::projected_with`]: the neo-Hookean pair, a file's `pair`) are `K = 2`
/// ([`Pair`]). The solvers have one code path for both.
pub trait Projected<const N: usize, const K: usize>: Sync {
    /// Whether [`Projected::evaluate_stored`] reads the rest shape (the solvers gather it only
    /// then; otherwise they pass the current positions).
    const READS_REST_SHAPE: bool;

    /// Whether the fast engine evaluates [`GROUP`] batches at a time
    /// ([`Projected::evaluate_batches`]).
    const GROUPED: bool;

    /// Whether any of the `K` reads where the particles were at the start of the substep or its
    /// h ([`Constraint::reads_motion`]): the solvers gather the start positions only then.
    fn reads_motion(&self) -> bool;

    /// C and ∇C of each of the `K` constraints at `p`, each with its rest value and what its
    /// element stores.
    fn evaluate_stored<V: Vector3>(
        &self,
        p: &[V; N],
        rest: [V::Real; K],
        rest_shape: &[V; N],
        stored: [&[V::Real]; K],
        motion: SubstepStart<'_, V, N>,
    ) -> [Evaluation<V, N>; K];

    /// [`Projected::evaluate_stored`] of [`GROUP`] batches of lanes at once: value k of batch j
    /// is `[k][j]`, to the bit what batch j gives alone.
    fn evaluate_batches(
        &self,
        p: &[[Vec3x8; N]; GROUP],
        rest: [[F32x8; GROUP]; K],
        rest_shape: &[[Vec3x8; N]; GROUP],
        stored: [[&[F32x8]; GROUP]; K],
        motion: (&[[Vec3x8; N]; GROUP], F32x8),
    ) -> [[Evaluation<Vec3x8, N>; GROUP]; K];
}

impl<const N: usize, C: Constraint<N>> Projected<N, 1> for C {
    const READS_REST_SHAPE: bool = C::STORED_USES_REST_SHAPE;
    const GROUPED: bool = C::GROUPED;

    fn reads_motion(&self) -> bool {
        Constraint::reads_motion(self)
    }

    #[inline(always)]
    fn evaluate_stored<V: Vector3>(
        &self,
        p: &[V; N],
        [rest]: [V::Real; 1],
        rest_shape: &[V; N],
        [stored]: [&[V::Real]; 1],
        motion: SubstepStart<'_, V, N>,
    ) -> [Evaluation<V, N>; 1] {
        [Constraint::evaluate_stored(
            self, p, rest, rest_shape, stored, motion,
        )]
    }

    #[inline(always)]
    fn evaluate_batches(
        &self,
        p: &[[Vec3x8; N]; GROUP],
        [rest]: [[F32x8; GROUP]; 1],
        rest_shape: &[[Vec3x8; N]; GROUP],
        [stored]: [[&[F32x8]; GROUP]; 1],
        motion: (&[[Vec3x8; N]; GROUP], F32x8),
    ) -> [[Evaluation<Vec3x8, N>; GROUP]; 1] {
        [Constraint::evaluate_batches(
            self, p, rest, rest_shape, stored, motion,
        )]
    }
}

/// Two constraints on the same particles, projected as one of two values.
pub struct Pair<'a, A, B>(pub &'a A, pub &'a B);

impl<const N: usize, A: Constraint<N>, B: Constraint<N>> Projected<N, 2> for Pair<'_, A, B> {
    const READS_REST_SHAPE: bool = A::STORED_USES_REST_SHAPE || B::STORED_USES_REST_SHAPE;
    const GROUPED: bool = A::GROUPED && B::GROUPED;

    fn reads_motion(&self) -> bool {
        self.0.reads_motion() || self.1.reads_motion()
    }

    #[inline(always)]
    fn evaluate_stored<V: Vector3>(
        &self,
        p: &[V; N],
        [rest_a, rest_b]: [V::Real; 2],
        rest_shape: &[V; N],
        [stored_a, stored_b]: [&[V::Real]; 2],
        motion: SubstepStart<'_, V, N>,
    ) -> [Evaluation<V, N>; 2] {
        [
            self.0
                .evaluate_stored(p, rest_a, rest_shape, stored_a, motion),
            self.1
                .evaluate_stored(p, rest_b, rest_shape, stored_b, motion),
        ]
    }

    #[inline(always)]
    fn evaluate_batches(
        &self,
        p: &[[Vec3x8; N]; GROUP],
        [rest_a, rest_b]: [[F32x8; GROUP]; 2],
        rest_shape: &[[Vec3x8; N]; GROUP],
        [stored_a, stored_b]: [[&[F32x8]; GROUP]; 2],
        motion: (&[[Vec3x8; N]; GROUP], F32x8),
    ) -> [[Evaluation<Vec3x8, N>; GROUP]; 2] {
        [
            self.0
                .evaluate_batches(p, rest_a, rest_shape, stored_a, motion),
            self.1
                .evaluate_batches(p, rest_b, rest_shape, stored_b, motion),
        ]
    }
}

/// Code that works on what one projection moves with its [`Projected`] type known at compile
/// time: the solvers' sweeps and the description of one projection.
pub trait VisitProjected {
    /// What the visit gives.
    type Output;
    /// Works on the `K` families `families` (the lead first), whose constraints `constraint`
    /// evaluates together, `N` particles each.
    fn visit<const N: usize, const K: usize, P: Projected<N, K>>(
        self,
        families: [Family; K],
        constraint: &P,
    ) -> Self::Output;
}

/// The families one projection moves: a family alone, or the two of a pair (the lead, which comes
/// first in the table, and its partner).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Unit {
    /// The family that leads (the only one, when alone).
    pub lead: Family,
    /// The family projected with it, if any.
    pub partner: Option<Family>,
}

impl Unit {
    /// Its families, the lead first.
    pub fn families(self) -> impl Iterator<Item = Family> {
        std::iter::once(self.lead).chain(self.partner)
    }
}
