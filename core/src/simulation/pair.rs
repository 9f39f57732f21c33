//! Two families projected together in the reference solver, constraint by constraint
//! ([`crate::constraints::Row::projected_with`]: the neo-Hookean pair): constraint c of each has
//! the same particles, and one 2 × 2 solve ([`pair_correction_lanes`]) moves them.

use super::{ConstraintSet, Projected};
use crate::constraints::{Constraint, Evaluation, VisitPair};
use crate::simulation::projection::{PairCorrection, Rule, SkipCounts, pair_correction_lanes};
use glam::DVec3;

/// What the pair is projected with: the two families' constraints, the particles and the rules.
pub(super) struct Pair<'a> {
    pub first: &'a ConstraintSet,
    pub second: &'a ConstraintSet,
    pub positions: &'a [DVec3],
    pub rest_positions: &'a [DVec3],
    pub inverse_masses: &'a [f64],
    pub rules: [Rule<f64>; 2],
    /// [`crate::simulation::Settings::reach`].
    pub reach: f64,
}

impl Pair<'_> {
    /// The particles of constraint `c` and the correction projecting it with its partner makes.
    #[inline]
    pub fn correction_at<const N: usize, A: Constraint<N>, const M: usize, B: Constraint<M>>(
        &self,
        first: &A,
        second: &B,
        c: usize,
    ) -> ([u32; N], PairCorrection<N>) {
        assert_eq!(N, M, "a pair shares its particles");
        let idx = self.first.indices::<N>(c);
        let p = idx.map(|i| self.positions[i as usize]);
        let shape = idx.map(|i| self.rest_positions[i as usize]);
        let a = first.evaluate_stored(&p, self.first.rest()[c], &shape, self.first.stored(c));
        let p2: [DVec3; M] = std::array::from_fn(|k| p[k]);
        let shape2: [DVec3; M] = std::array::from_fn(|k| shape[k]);
        let b = second.evaluate_stored(&p2, self.second.rest()[c], &shape2, self.second.stored(c));
        let b = Evaluation {
            value: b.value,
            gradients: std::array::from_fn(|k| b.gradients[k]),
            degenerate: b.degenerate,
        };
        let weights = idx.map(|i| self.inverse_masses[i as usize]);
        let lambda = [self.first.lambda()[c], self.second.lambda()[c]];
        let reach = self.reach * self.first.size()[c];
        (
            idx,
            pair_correction_lanes(a, b, weights, lambda, self.rules, reach),
        )
    }
}

/// The pair's constraints in `range` projected in turn (Gauss–Seidel): each correction moves the
/// particles and adds to both multipliers.
pub(super) struct PairSweep<'a> {
    pub first: &'a mut ConstraintSet,
    pub second: &'a mut ConstraintSet,
    /// Where each family's skipped projections are counted.
    pub skipped: [&'a mut SkipCounts; 2],
    pub positions: &'a mut [DVec3],
    pub rest_positions: &'a [DVec3],
    pub inverse_masses: &'a [f64],
    pub rules: [Rule<f64>; 2],
    /// Which constraints, in the first family's order.
    pub which: Projected,
    /// [`crate::simulation::Settings::reach`].
    pub reach: f64,
}

impl VisitPair for PairSweep<'_> {
    type Output = ();

    #[inline]
    fn visit_pair<const N: usize, A: Constraint<N>, const M: usize, B: Constraint<M>>(
        mut self,
        first: &A,
        second: &B,
    ) {
        for k in self.which.range(self.first) {
            let c = self.which.at(self.first, k);
            let pair = Pair {
                first: &*self.first,
                second: &*self.second,
                positions: &*self.positions,
                rest_positions: self.rest_positions,
                inverse_masses: self.inverse_masses,
                rules: self.rules,
                reach: self.reach,
            };
            let (idx, correction) = pair.correction_at::<N, A, M, B>(first, second, c);
            for (counts, skipped) in self.skipped.iter_mut().zip(correction.skipped) {
                counts.add(skipped);
            }
            self.first.add_lambda(c, correction.delta_lambda[0]);
            self.second.add_lambda(c, correction.delta_lambda[1]);
            for (&i, dx) in idx.iter().zip(correction.delta_x) {
                self.positions[i as usize] += dx;
            }
        }
    }
}

/// The correction of one constraint of the pair, padded to four particles, without applying it.
pub(super) struct PairAt<'a> {
    pub pair: Pair<'a>,
    pub c: usize,
}

impl VisitPair for PairAt<'_> {
    type Output = PairCorrection<4>;

    fn visit_pair<const N: usize, A: Constraint<N>, const M: usize, B: Constraint<M>>(
        self,
        first: &A,
        second: &B,
    ) -> PairCorrection<4> {
        let (_, correction) = self.pair.correction_at::<N, A, M, B>(first, second, self.c);
        let mut delta_x = [DVec3::ZERO; 4];
        delta_x[..N].copy_from_slice(&correction.delta_x);
        PairCorrection {
            delta_lambda: correction.delta_lambda,
            delta_x,
            skipped: correction.skipped,
        }
    }
}
