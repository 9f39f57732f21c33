//! A constraint file as a [`GradientSource`] for the one gradient check
//! ([`crate::constraints::verify`]): its own gradient against automatic differentiation (AD), AD
//! against central finite differences, on random configurations and on near-degenerate ones, and
//! what C does under a translation, a rotation and a reflection. `tetlab check-gradients
//! --constraint-file` prints the report.

use super::ConstraintFile;
use crate::constraints::material::Material;
use crate::constraints::verify::{Around, GradientSource};
use glam::DVec3;

pub use crate::constraints::verify::{
    AGREEMENT, INVARIANCE, Reflection, Report, Worst, well_conditioned,
};

/// What the element stores is worked out from the rest shape drawn with the configuration and
/// the default material ([`Material::default`]); a file that reads no rest shape is drawn
/// without one.
impl GradientSource for ConstraintFile {
    fn arity(&self) -> usize {
        ConstraintFile::arity(self)
    }

    fn uses_rest_shape(&self) -> bool {
        self.reads_rest_shape()
    }

    fn uses_motion(&self) -> bool {
        self.reads_motion()
    }

    fn value(&self, points: &[DVec3], rest: f64, around: &Around) -> f64 {
        let stored = self.store(&around.rest_shape, &Material::default());
        self.value_moving(points, around.moving(), rest, &stored)
    }

    fn given(&self, points: &[DVec3], rest: f64, around: &Around) -> Vec<Option<DVec3>> {
        let stored = self.store(&around.rest_shape, &Material::default());
        self.yours_moving(points, around.moving(), rest, &stored)[..ConstraintFile::arity(self)]
            .to_vec()
    }

    fn automatic(&self, points: &[DVec3], rest: f64, around: &Around) -> Option<Vec<DVec3>> {
        let stored = self.store(&around.rest_shape, &Material::default());
        self.evaluate_moving(points, around.moving(), rest, &stored)
            .automatic
    }

    fn natural_rest(&self, _: &[DVec3], around: &Around) -> f64 {
        self.rest_value(&around.rest_shape, &Material::default())
    }
}

/// The check of `file` on `configs` well-conditioned random configurations
/// ([`crate::constraints::verify::check`]).
pub fn check(file: &ConstraintFile, configs: usize, seed: u64) -> Report {
    crate::constraints::verify::check(file, configs, seed)
}

/// A place where C has a kink or a jump ([`kinks`]): an `abs`, `sign`, `min`, `max`, `clamp` or
/// `if` on C's path.
#[derive(Clone, Debug, PartialEq)]
pub struct Kink {
    /// Its line and column in the file.
    pub at: (usize, usize),
    /// What it is: `abs`, `min`, `if`…
    pub what: &'static str,
    /// Of the lines through random configurations tried, how many cross it.
    pub crossed: usize,
    /// How many lines were tried.
    pub tried: usize,
    /// The largest jump of ∇C (AD) across it, |∇C⁺ − ∇C⁻|∞ relative to |∇C|: 0 for a kink
    /// that C's gradient does not feel, about 2 for `abs` at its zero.
    pub jump: f64,
    /// Of the random configurations, how many lie within 10⁻⁹ of their size of it: the check
    /// compares gradients away from kinks, since random configurations almost never land on one.
    pub landed: usize,
}

/// The kink set of C, found by sampling near it: through each of `lines` random configurations
/// ([`crate::constraints::verify::draw`]) a random line, along which the value that decides each
/// switch (the argument of `abs`, the difference of `min`'s two…) is bisected to its zero where
/// it changes sign; there ∇C is taken by AD just before and just after.
///
/// ```
/// use std::path::Path;
/// use tetlab_core::constraint_file::ConstraintFile;
/// use tetlab_core::constraint_file::check::kinks;
/// let text = "name = \"k\"\napplies_to = \"edges\"\nvalue = \"abs(p0.x - p1.x)\"\n";
/// let file = ConstraintFile::parse(Path::new("k.toml"), text).unwrap();
/// let found = kinks(&file, 50, 1);
/// assert_eq!(found[0].what, "abs");
/// assert!(found[0].crossed > 0 && (found[0].jump - 2.0).abs() < 1e-6);
/// assert_eq!(found[0].landed, 0);
/// ```
pub fn kinks(file: &ConstraintFile, lines: usize, seed: u64) -> Vec<Kink> {
    use crate::numbers::random::SplitMix64;
    let mut rng = SplitMix64::new(seed);
    let material = Material::default();
    let mut found: Vec<Kink> = Vec::new();
    for _ in 0..lines {
        // At rest: where the particles were at the start of the substep is not drawn here.
        let (points, around, size) = crate::constraints::verify::draw(&mut rng, file);
        let stored = file.store(&around.rest_shape, &material);
        let rest = file.rest_value(&around.rest_shape, &material) * rng.range(-1.5, 1.5);
        let direction: Vec<DVec3> = points.iter().map(|_| rng.in_cube(size)).collect();
        let along = |t: f64| -> Vec<DVec3> {
            points
                .iter()
                .zip(&direction)
                .map(|(p, d)| *p + *d * t)
                .collect()
        };
        let here = file.switches_at(&points, rest, &stored);
        for (k, &(at, what, decides)) in here.iter().enumerate() {
            let kink = match found.iter_mut().position(|f| f.at == at && f.what == what) {
                Some(i) => &mut found[i],
                None => {
                    found.push(Kink {
                        at,
                        what,
                        crossed: 0,
                        tried: 0,
                        jump: 0.0,
                        landed: 0,
                    });
                    found.last_mut().expect("just pushed")
                }
            };
            kink.tried += 1;
            if decides.abs() <= 1e-9 * size {
                kink.landed += 1;
            }
            let decides_at = |t: f64| {
                file.switches_at(&along(t), rest, &stored)
                    .get(k)
                    .map_or(f64::NAN, |s| s.2)
            };
            // A sign change on a grid of t in −1…1, then bisection to the zero.
            let grid: Vec<f64> = (0..=16).map(|i| -1.0 + i as f64 / 8.0).collect();
            let Some(window) = grid
                .windows(2)
                .find(|w| decides_at(w[0]).signum() * decides_at(w[1]).signum() < 0.0)
            else {
                continue;
            };
            let (mut low, mut high) = (window[0], window[1]);
            for _ in 0..60 {
                let middle = 0.5 * (low + high);
                if decides_at(middle).signum() == decides_at(low).signum() {
                    low = middle;
                } else {
                    high = middle;
                }
            }
            let side = |t: f64| file.evaluate(&along(t), rest, &stored).automatic;
            let step = 1e-6;
            if let (Some(before), Some(after)) = (side(low - step), side(high + step)) {
                let scale = before
                    .iter()
                    .chain(&after)
                    .map(|g| g.length())
                    .fold(0.0, f64::max);
                if scale > 0.0 {
                    kink.crossed += 1;
                    let jump = before
                        .iter()
                        .zip(&after)
                        .map(|(a, b)| (*a - *b).abs().max_element())
                        .fold(0.0, f64::max)
                        / scale;
                    kink.jump = kink.jump.max(jump);
                }
            }
        }
    }
    found
}
