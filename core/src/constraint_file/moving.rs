//! A constraint file evaluated in f64 at a configuration, as the check, `tetlab gradient` and the
//! workbench's readers see it: C, ∇C by forward-mode AD and the file's own gradient, with the
//! particles where they were at the start of the substep and its h ([`Moving`]), or at rest.

use super::program::RESTING_H;
use super::{ConstraintFile, Evaluation, sound};
use crate::constraints::MAX_STORED;
use crate::numbers::dual::Tangent;
use crate::numbers::vector::Vector3;
use arrayvec::ArrayVec;
use glam::DVec3;

/// Where the particles were at the start of the substep (`start0`, `start1`, … of a file) and
/// the substep's length (`h`): what a constraint on velocities reads besides the particles.
#[derive(Clone, Copy, Debug)]
pub struct Moving<'a> {
    /// Each particle at the start of the substep, in the constraint's order.
    pub start: &'a [DVec3],
    /// The substep's length in seconds.
    pub h: f64,
}

impl<'a> Moving<'a> {
    /// No motion: the particles were where they are, and h is [`RESTING_H`] (the default
    /// substep): how a file is evaluated outside a substep.
    pub fn at_rest(points: &'a [DVec3]) -> Moving<'a> {
        Moving {
            start: points,
            h: RESTING_H,
        }
    }
}

impl ConstraintFile {
    /// C at `points` with rest value `rest` and what the element stores (NaN where it is
    /// undefined), at rest ([`Moving::at_rest`]).
    pub fn value(&self, points: &[DVec3], rest: f64, stored: &[f64]) -> f64 {
        self.value_moving(points, Moving::at_rest(points), rest, stored)
    }

    /// [`ConstraintFile::value`] with the particles where `moving` says they were at the start
    /// of the substep, and its h.
    pub fn value_moving(
        &self,
        points: &[DVec3],
        moving: Moving<'_>,
        rest: f64,
        stored: &[f64],
    ) -> f64 {
        let points = self.coordinates(points);
        let start = self.coordinates(moving.start);
        self.value.run(
            &self.inputs(&points, (&start, moving.h), rest, stored),
            |r| r.scalar(0),
        )
    }

    /// C, its gradient by forward-mode AD and the file's own, at `points` with rest value `rest`
    /// and what the element stores: what `tetlab check-gradients` and `tetlab gradient`
    /// compare. At rest ([`Moving::at_rest`]).
    pub fn evaluate(&self, points: &[DVec3], rest: f64, stored: &[f64]) -> Evaluation {
        self.evaluate_moving(points, Moving::at_rest(points), rest, stored)
    }

    /// [`ConstraintFile::evaluate`] with the particles where `moving` says they were at the
    /// start of the substep, and its h (the gradient is C's with respect to the particles now).
    pub fn evaluate_moving(
        &self,
        points: &[DVec3],
        moving: Moving<'_>,
        rest: f64,
        stored: &[f64],
    ) -> Evaluation {
        let value = self.value_moving(points, moving, rest, stored);
        let automatic = crate::constraints::for_arity!(self.arity(), |N| self
            .forward_mode::<N>(points, moving, rest, stored));
        Evaluation {
            value,
            automatic: automatic.filter(|_| value.is_finite()),
            yours: self.yours_moving(points, moving, rest, stored)[..self.arity()].to_vec(),
        }
    }

    /// The file's own gradient for each particle it gives one for, at `points` with rest value
    /// `rest` and what the element stores, at rest.
    pub fn yours(&self, points: &[DVec3], rest: f64, stored: &[f64]) -> [Option<DVec3>; 4] {
        self.yours_moving(points, Moving::at_rest(points), rest, stored)
    }

    /// [`ConstraintFile::yours`] with the particles where `moving` says they were at the start
    /// of the substep, and its h.
    pub fn yours_moving(
        &self,
        points: &[DVec3],
        moving: Moving<'_>,
        rest: f64,
        stored: &[f64],
    ) -> [Option<DVec3>; 4] {
        let points = self.coordinates(points);
        let start = self.coordinates(moving.start);
        let inputs = self.inputs(&points, (&start, moving.h), rest, stored);
        self.yours.run(&inputs, |r| {
            std::array::from_fn(|k| self.gives[k].then(|| DVec3::from_array(r.vector(1 + k))))
        })
    }

    /// ∇C by forward-mode AD in f64 over [`Tangent`] numbers, one pass per coordinate; `None`
    /// where it is undefined.
    fn forward_mode<const N: usize>(
        &self,
        points: &[DVec3],
        moving: Moving<'_>,
        rest: f64,
        stored: &[f64],
    ) -> Option<Vec<DVec3>> {
        let tangent_rest = Tangent::new(rest, 0.0);
        let tangents: ArrayVec<Tangent<f64>, MAX_STORED> =
            stored.iter().map(|&x| Tangent::new(x, 0.0)).collect();
        // Where the particles were is given, not differentiated by.
        let start: Vec<[Tangent<f64>; 3]> = moving
            .start
            .iter()
            .map(|q| q.to_array().map(|x| Tangent::new(x, 0.0)))
            .collect();
        let h = Tangent::new(moving.h, 0.0);
        let gradients = crate::numbers::dual::gradient(points, |p| {
            let p: [[Tangent<f64>; 3]; N] = std::array::from_fn(|k| p[k].to_array());
            let inputs = self.inputs(&p, (&start, h), tangent_rest, &tangents);
            self.value.run(&inputs, |r| r.scalar(0))
        })?;
        let gradients: [[f64; 3]; N] = std::array::from_fn(|k| gradients[k].to_array());
        let e = sound::<DVec3, N>(self.value_moving(points, moving, rest, stored), gradients);
        (!e.degenerate).then(|| e.gradients.to_vec())
    }
}
