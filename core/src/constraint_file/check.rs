//! Checking a constraint file's own gradient against automatic differentiation (AD), and AD against
//! central finite differences, on random configurations and on near-degenerate ones; and what C
//! does under a translation, a rotation and a reflection. `tetlab check-gradients
//! --constraint-file` prints this report.

use super::ConstraintFile;
use crate::numbers::finite_difference::central_difference;
use crate::numbers::random::SplitMix64;
use crate::teaching::verify::{CONDITIONING, relative_error};
use glam::DVec3;

/// The largest relative error (against AD) at which a gradient agrees.
pub const AGREEMENT: f64 = 1e-6;

/// The largest |Σᵢ ∇ᵢC| (and |Σᵢ pᵢ × ∇ᵢC|), relative to the gradient's size (times the
/// configuration's), at which C counts as translation (rotation) invariant.
pub const INVARIANCE: f64 = 1e-9;

/// The configuration where the file's gradient is furthest from AD.
#[derive(Clone, Debug, PartialEq)]
pub struct Worst {
    /// The particle whose gradient is furthest off.
    pub particle: usize,
    /// The configuration.
    pub points: Vec<DVec3>,
    /// Its rest value.
    pub rest: f64,
    /// That particle's error: |yours − AD|∞ / maxⱼ |∇ⱼC|.
    pub relative_error: f64,
}

/// What C does when the configuration is mirrored (x → −x).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reflection {
    /// C is the same (a length, an unsigned area).
    Unchanged,
    /// C changes sign (a signed volume, a signed height).
    Negated,
    /// Neither.
    Changed,
    /// Not known: C is undefined with rest 0 everywhere tried (C = V / rest − 1).
    Untried,
}

impl Reflection {
    /// One word for it.
    pub fn describe(self) -> &'static str {
        match self {
            Reflection::Unchanged => "unchanged",
            Reflection::Negated => "negated",
            Reflection::Changed => "changed",
            Reflection::Untried => "untried (C is undefined with rest 0)",
        }
    }
}

/// The outcome of [`check`].
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// Well-conditioned configurations compared.
    pub compared: usize,
    /// Drawn but skipped as near-degenerate (an edge or a face angle below
    /// [`CONDITIONING`]).
    pub skipped: usize,
    /// Per particle, the largest relative error of the file's gradient against AD; `None` for a
    /// particle the file gives no gradient for.
    pub max_relative_error: Vec<Option<f64>>,
    /// Where the largest of those is.
    pub worst: Option<Worst>,
    /// The largest relative error of AD against central differences.
    pub automatic_vs_finite_difference: f64,
    /// The largest |Σᵢ ∇ᵢC| / maxᵢ |∇ᵢC| (AD).
    pub translation: f64,
    /// The largest |Σᵢ (pᵢ − centre) × ∇ᵢC| / (maxᵢ |∇ᵢC| · size) (AD).
    pub rotation: f64,
    /// What a reflection does to C (with rest 0).
    pub reflection: Reflection,
    /// Near-degenerate configurations evaluated (points coincident or coplanar).
    pub near_degenerate: usize,
    /// Of those, how many have C or ∇C undefined there (flagged, never NaN in the results).
    pub undefined: usize,
}

impl Report {
    /// Whether every gradient the file gives agrees with AD within [`AGREEMENT`].
    pub fn agrees(&self) -> bool {
        self.max_relative_error
            .iter()
            .flatten()
            .all(|&e| e <= AGREEMENT)
    }

    /// Whether Σᵢ ∇ᵢC = 0 within [`INVARIANCE`].
    pub fn translation_invariant(&self) -> bool {
        self.translation <= INVARIANCE
    }

    /// Whether Σᵢ pᵢ × ∇ᵢC = 0 within [`INVARIANCE`].
    pub fn rotation_invariant(&self) -> bool {
        self.rotation <= INVARIANCE
    }
}

/// Whether `points` are far from degenerate: no two closer than [`CONDITIONING`] times the
/// largest distance, and no face of three of them with an angle's sine below it.
pub fn well_conditioned(points: &[DVec3]) -> bool {
    let n = points.len();
    let mut longest: f64 = 0.0;
    for i in 0..n {
        for j in i + 1..n {
            longest = longest.max(points[i].distance(points[j]));
        }
    }
    if longest == 0.0 {
        return false;
    }
    for i in 0..n {
        for j in i + 1..n {
            if points[i].distance(points[j]) < CONDITIONING * longest {
                return false;
            }
            for k in j + 1..n {
                let (a, b) = (points[j] - points[i], points[k] - points[i]);
                for (u, v) in [(a, b), (points[i] - points[j], points[k] - points[j])] {
                    if u.cross(v).length() < CONDITIONING * u.length() * v.length() {
                        return false;
                    }
                }
            }
        }
    }
    true
}

/// Compares on `configs` well-conditioned random configurations (points in a cube of random size
/// 10^U(−2, 2) around a random centre; rest value C × U(−1.5, 1.5)), then on near-degenerate ones.
pub fn check(file: &ConstraintFile, configs: usize, seed: u64) -> Report {
    let arity = file.arity();
    let mut rng = SplitMix64::new(seed);
    let mut report = Report {
        compared: 0,
        skipped: 0,
        max_relative_error: (0..arity)
            .map(|k| file.gives_gradient(k).then_some(0.0))
            .collect(),
        worst: None,
        automatic_vs_finite_difference: 0.0,
        translation: 0.0,
        rotation: 0.0,
        reflection: Reflection::Unchanged,
        near_degenerate: 0,
        undefined: 0,
    };
    let (mut unchanged, mut negated, mut reflected_any) = (true, true, false);
    let mut attempts = 0usize;
    while report.compared < configs && attempts < configs.saturating_mul(100).max(1000) {
        attempts += 1;
        let size = 10f64.powf(rng.range(-2.0, 2.0));
        let centre = rng.in_cube(size);
        let points: Vec<DVec3> = (0..arity).map(|_| centre + rng.in_cube(size)).collect();
        if !well_conditioned(&points) {
            report.skipped += 1;
            continue;
        }
        // A rest value of the size C's own would have: the file's rest expression where it
        // gives one (C = V / rest − 1 is undefined with rest 0), else C with rest 0.
        let rest = file.rest_value(&points) * rng.range(-1.5, 1.5);
        let evaluation = file.evaluate(&points, rest);
        let Some(automatic) = evaluation.automatic else {
            report.skipped += 1;
            continue;
        };
        report.compared += 1;
        let scale = automatic.iter().map(|g| g.length()).fold(0.0, f64::max);
        let numeric = central_difference(&points, |p| file.value(p, rest));
        report.automatic_vs_finite_difference = report
            .automatic_vs_finite_difference
            .max(relative_error(&automatic, &numeric));
        for (k, yours) in evaluation.yours.iter().enumerate() {
            let Some(yours) = yours else { continue };
            let difference = (*yours - automatic[k]).abs().max_element();
            let error = if scale > 0.0 {
                difference / scale
            } else {
                difference
            };
            // A non-finite gradient of yours where AD's is finite is as wrong as it gets.
            let error = if error.is_finite() {
                error
            } else {
                f64::INFINITY
            };
            let slot = report.max_relative_error[k].get_or_insert(0.0);
            *slot = slot.max(error);
            if report
                .worst
                .as_ref()
                .is_none_or(|w| error > w.relative_error)
            {
                report.worst = Some(Worst {
                    particle: k,
                    points: points.clone(),
                    rest,
                    relative_error: error,
                });
            }
        }
        if scale > 0.0 {
            let sum: DVec3 = automatic.iter().sum();
            report.translation = report.translation.max(sum.length() / scale);
            let mean = points.iter().sum::<DVec3>() / arity as f64;
            let torque: DVec3 = points
                .iter()
                .zip(&automatic)
                .map(|(p, g)| (*p - mean).cross(*g))
                .sum();
            report.rotation = report.rotation.max(torque.length() / (scale * size));
        }
        // Reflection, and a rotation's effect on C itself, with rest 0.
        let raw = file.value(&points, 0.0);
        let mirrored: Vec<DVec3> = points.iter().map(|p| DVec3::new(-p.x, p.y, p.z)).collect();
        let reflected = file.value(&mirrored, 0.0);
        if raw.is_finite() && reflected.is_finite() {
            reflected_any = true;
            let tolerance = 1e-9 * raw.abs().max(1e-300);
            unchanged &= (reflected - raw).abs() <= tolerance;
            negated &= (reflected + raw).abs() <= tolerance;
        }
    }
    report.reflection = match (unchanged, negated) {
        _ if !reflected_any => Reflection::Untried,
        (true, _) => Reflection::Unchanged,
        (false, true) => Reflection::Negated,
        _ => Reflection::Changed,
    };
    for shape in near_degenerate(arity, &mut rng, 200) {
        report.near_degenerate += 1;
        let evaluation = file.evaluate(&shape, 0.0);
        if !evaluation.value.is_finite() || evaluation.automatic.is_none() {
            report.undefined += 1;
        }
    }
    report
}

/// Configurations at or near degeneracy: two points coincident, all coincident, all on a line,
/// p3 on the plane of p0, p1, p2 (for four), and the same moved by 10⁻⁹ of their size.
fn near_degenerate(arity: usize, rng: &mut SplitMix64, count: usize) -> Vec<Vec<DVec3>> {
    let mut shapes = Vec::with_capacity(count);
    while shapes.len() < count {
        let size = 10f64.powf(rng.range(-2.0, 2.0));
        let mut points: Vec<DVec3> = (0..arity).map(|_| rng.in_cube(size)).collect();
        match shapes.len() % 4 {
            0 => points[arity - 1] = points[0],
            1 => {
                let p = points[0];
                points.iter_mut().for_each(|q| *q = p);
            }
            2 => {
                let (a, b) = (points[0], points[1]);
                for (i, q) in points.iter_mut().enumerate() {
                    *q = a + (b - a) * i as f64;
                }
            }
            _ => {
                if arity == 4 {
                    let (u, v) = (rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
                    points[3] =
                        points[0] + (points[1] - points[0]) * u + (points[2] - points[0]) * v;
                } else {
                    points[1] = points[0] + DVec3::splat(size * 1e-12);
                }
            }
        }
        if shapes.len() % 8 >= 4 {
            let rotation = rng.rotation();
            for q in &mut points {
                *q = rotation * *q + DVec3::splat(1e-9 * size);
            }
        }
        shapes.push(points);
    }
    shapes
}
