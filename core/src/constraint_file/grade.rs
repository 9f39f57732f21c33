//! Grading a student's gradient: a lesson step that is an exercise ("write ∇C", "this ∇C is
//! wrong: fix it") is graded by the check of `tetlab check-gradients --constraint-file`
//! ([`super::check::check`]) on [`GRADED_CONFIGS`] random configurations. The grade says, per
//! particle, whether the student's ∇ₚᵢC held against automatic differentiation (AD), was not
//! written, or is wrong, and for a wrong one the configuration that shows it, but never AD's
//! gradient itself: that would give the answer away.

use super::ConstraintFile;
use super::check::{self, AGREEMENT, Worst};
use crate::constraints::{Families, Family};
use std::sync::Arc;

/// The configurations a grade compares on (seed 1, as `gradient_error.NAME` in a lesson).
pub const GRADED_CONFIGS: usize = 100;

/// What became of one particle's gradient.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Verdict {
    /// The file gives no gradient for it.
    Missing,
    /// It agrees with AD: its largest relative error is at most [`AGREEMENT`].
    Held(f64),
    /// It does not: its largest relative error.
    Wrong(f64),
}

/// A student's gradient, graded.
#[derive(Clone, Debug, PartialEq)]
pub struct Grade {
    /// The family graded.
    pub name: String,
    /// Configurations compared.
    pub compared: usize,
    /// Per particle, from p0.
    pub particles: Vec<Verdict>,
    /// Where the gradient is furthest from AD, when it is wrong somewhere.
    pub shown_wrong: Option<Worst>,
}

impl Grade {
    /// Grades the gradient `file` gives.
    ///
    /// ```
    /// use std::path::Path;
    /// use tetlab_core::constraint_file::{ConstraintFile, grade::{Grade, Verdict}};
    /// let text = "name = \"e\"\napplies_to = \"edges\"\nvalue = \"length(p0 - p1) - rest\"\n";
    /// let with = |gradient: &str| {
    ///     let text = format!("{text}[gradient]\n{gradient}\n");
    ///     Grade::of(&ConstraintFile::parse(Path::new("e.toml"), &text).unwrap())
    /// };
    /// // Right at both ends: passed.
    /// let right = with("p0 = \"normalize(p0 - p1)\"\np1 = \"normalize(p1 - p0)\"");
    /// assert!(right.passed() && right.error() < 1e-12);
    /// // p1 not written: not passed, though what is written holds.
    /// let half = with("p0 = \"normalize(p0 - p1)\"");
    /// assert_eq!(half.particles[1], Verdict::Missing);
    /// assert!(!half.passed() && half.error().is_infinite());
    /// // p1 with its sign lost: p1 is named, on a configuration that shows it.
    /// let wrong = with("p0 = \"normalize(p0 - p1)\"\np1 = \"normalize(p0 - p1)\"");
    /// assert!(matches!(wrong.particles[1], Verdict::Wrong(e) if e > 1.0));
    /// assert_eq!(wrong.shown_wrong.as_ref().map(|w| w.particle), Some(1));
    /// ```
    pub fn of(file: &ConstraintFile) -> Grade {
        let report = check::check(file, GRADED_CONFIGS, 1);
        let particles: Vec<Verdict> = report
            .max_relative_error
            .iter()
            .map(|error| match *error {
                None => Verdict::Missing,
                Some(e) if e <= AGREEMENT => Verdict::Held(e),
                Some(e) => Verdict::Wrong(e),
            })
            .collect();
        let wrong = particles.iter().any(|v| matches!(v, Verdict::Wrong(_)));
        Grade {
            name: file.name.clone(),
            compared: report.compared,
            particles,
            shown_wrong: report.worst.filter(|_| wrong),
        }
    }

    /// The largest relative error of any particle's gradient against AD: what a lesson's
    /// `gradient_error.NAME` measures. Infinite when a particle's gradient is not written, or
    /// when no configuration could be compared.
    pub fn error(&self) -> f64 {
        if self.compared == 0 {
            return f64::INFINITY;
        }
        self.particles
            .iter()
            .map(|v| match *v {
                Verdict::Missing => f64::INFINITY,
                Verdict::Held(e) | Verdict::Wrong(e) => e,
            })
            .fold(0.0, f64::max)
    }

    /// Whether every particle's gradient is written and agrees with AD.
    pub fn passed(&self) -> bool {
        self.error() <= AGREEMENT
    }

    /// What the student is told, a line each with whether it is good news: the verdict, each
    /// particle's, and for a wrong gradient the configuration where it is furthest off. AD's
    /// gradient is not shown.
    pub fn lines(&self) -> Vec<(String, bool)> {
        let passed = self.passed();
        let mut lines = vec![(
            if passed {
                format!(
                    "passed: your gradient of {} agrees with automatic differentiation at every \
                     particle, on {} random configurations",
                    self.name, self.compared
                )
            } else {
                format!(
                    "not yet: your gradient of {} does not agree with automatic differentiation",
                    self.name
                )
            },
            passed,
        )];
        for (k, verdict) in self.particles.iter().enumerate() {
            lines.push(match *verdict {
                Verdict::Held(e) => (format!("p{k}: held (largest relative error {e:.0e})"), true),
                Verdict::Missing => (
                    format!("p{k}: not written yet ([gradient] p{k} = \"...\")"),
                    false,
                ),
                Verdict::Wrong(e) => (
                    format!("p{k}: wrong (off by {e:.2} of the largest |grad C| somewhere)"),
                    false,
                ),
            });
        }
        if let Some(worst) = &self.shown_wrong {
            let points: Vec<String> = worst
                .points
                .iter()
                .enumerate()
                .map(|(k, p)| format!("p{k} = ({:.3}, {:.3}, {:.3})", p.x, p.y, p.z))
                .collect();
            lines.push((
                format!(
                    "p{} is furthest off at {}, rest {:.3}: work out your p{0} there by hand",
                    worst.particle,
                    points.join(", "),
                    worst.rest
                ),
                false,
            ));
        }
        lines
    }
}

/// The grade of `family`'s file ([`ConstraintFile::grade`], worked out once per definition of
/// the family: the student redefines it as they type); `None` for a built-in family.
pub fn of_family(families: &Families, family: Family) -> Option<Arc<Grade>> {
    Some(families.file(family)?.grade())
}
