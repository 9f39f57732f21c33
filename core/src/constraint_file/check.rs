//! A constraint file as a [`GradientSource`] for the one gradient check
//! ([`crate::constraints::verify`]): its own gradient against automatic differentiation (AD), AD
//! against central finite differences, on random configurations and on near-degenerate ones, and
//! what C does under a translation, a rotation and a reflection. `tetlab check-gradients
//! --constraint-file` prints the report.

use super::ConstraintFile;
use crate::constraints::verify::GradientSource;
use glam::DVec3;

pub use crate::constraints::verify::{
    AGREEMENT, INVARIANCE, Reflection, Report, Worst, well_conditioned,
};

/// A file reads no rest shape: the configuration's own points stand in for it.
impl GradientSource for ConstraintFile {
    fn arity(&self) -> usize {
        ConstraintFile::arity(self)
    }

    fn uses_rest_shape(&self) -> bool {
        false
    }

    fn value(&self, points: &[DVec3], rest: f64, _: &[DVec3]) -> f64 {
        ConstraintFile::value(self, points, rest)
    }

    fn given(&self, points: &[DVec3], rest: f64, _: &[DVec3]) -> Vec<Option<DVec3>> {
        self.yours(points, rest)[..ConstraintFile::arity(self)].to_vec()
    }

    fn automatic(&self, points: &[DVec3], rest: f64, _: &[DVec3]) -> Option<Vec<DVec3>> {
        self.evaluate(points, rest).automatic
    }

    fn natural_rest(&self, points: &[DVec3], _: &[DVec3]) -> f64 {
        self.rest_value(points)
    }
}

/// The check of `file` on `configs` well-conditioned random configurations
/// ([`crate::constraints::verify::check`]).
pub fn check(file: &ConstraintFile, configs: usize, seed: u64) -> Report {
    crate::constraints::verify::check(file, configs, seed)
}
