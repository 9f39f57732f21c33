//! The gradient check, one for every constraint: a built-in family or a compiled constraint
//! file ([`GradientSource`]). One sampling recipe ([`draw`]), one test of near-degeneracy
//! ([`well_conditioned`]) and one forward-mode seeding ([`crate::numbers::dual::gradient`]) serve
//! both. [`check`] compares the gradient a source gives against automatic differentiation (AD),
//! AD against central finite differences, and reports what C does under a translation, a rotation
//! and a reflection and at near-degenerate configurations; [`random_check`] gives the figures of
//! `tetlab check-gradients` for the built-in families (the analytic gradient against central
//! differences and against AD).
//!
//! The same routines back the test suite (which asserts every figure) and `tetlab
//! check-gradients` (which prints the figures quoted in `docs/gradients.md`).

use crate::constraints::{Constraint, Families, Family, Visit};
use crate::numbers::dual::{Dual64, DualVec3};
use crate::numbers::finite_difference::central_difference;
use crate::numbers::random::SplitMix64;
use crate::numbers::vector::Real;
use glam::DVec3;

/// Below this sine of an angle of any triangle of the points, or this fraction of the largest
/// distance between two of them, a random configuration counts as near-degenerate and is not
/// compared.
pub const CONDITIONING: f64 = 0.05;

/// The largest relative error (against AD) at which a gradient agrees.
pub const AGREEMENT: f64 = 1e-6;

/// The largest |Σᵢ ∇ᵢC| (and |Σᵢ pᵢ × ∇ᵢC|), relative to the gradient's size (times the
/// configuration's), at which C counts as translation (rotation) invariant, where rounding
/// allows no less; where it allows more, what it allows at that configuration
/// (`rounding_floor`).
pub const INVARIANCE: f64 = 1e-9;

/// The configuration where the file's gradient is furthest from AD.
#[derive(Clone, Debug, PartialEq)]
pub struct Worst {
    /// The particle whose gradient is furthest off.
    pub particle: usize,
    /// The configuration.
    pub points: Vec<DVec3>,
    /// Its rest shape, for a constraint that reads one (Dm, F, V0); `None` otherwise.
    pub rest_shape: Option<Vec<DVec3>>,
    /// Where the particles were at the start of the substep, and h, for a constraint that reads
    /// them (`start0`…, `h`); `None` otherwise.
    pub moving: Option<(Vec<DVec3>, f64)>,
    /// Its rest value.
    pub rest: f64,
    /// That particle's error: |yours − AD|∞ / maxⱼ |∇ⱼC|; where AD's gradient is zero, the
    /// absolute |yours − AD|∞ ([`Worst::absolute`]).
    pub relative_error: f64,
    /// Whether AD's gradient is zero there, so that the error is absolute, not relative.
    pub absolute: bool,
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
    /// The same of the gradient the source gives, when it gives every particle's.
    pub translation_given: Option<f64>,
    /// The largest |Σᵢ (pᵢ − centre) × ∇ᵢC| / (maxᵢ |∇ᵢC| · size) (AD).
    pub rotation: f64,
    /// The largest of [`Report::translation`]'s ratios to what rounding allows at its own
    /// configuration (`rounding_floor`): at most 1 for a translation-invariant C.
    pub translation_excess: f64,
    /// The same of [`Report::translation_given`].
    pub translation_given_excess: Option<f64>,
    /// The same of [`Report::rotation`].
    pub rotation_excess: f64,
    /// The largest that rounding allowed at any configuration, relative (`rounding_floor`).
    pub rounding: f64,
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

    /// Whether Σᵢ ∇ᵢC = 0 (AD's) at every configuration, within [`INVARIANCE`] or what rounding
    /// allows there (`rounding_floor`).
    pub fn translation_invariant(&self) -> bool {
        self.translation_excess <= 1.0
    }

    /// The same of the gradient the source gives, when it gives every particle's.
    pub fn given_translation_invariant(&self) -> Option<bool> {
        self.translation_given_excess.map(|excess| excess <= 1.0)
    }

    /// Whether Σᵢ pᵢ × ∇ᵢC = 0 at every configuration, within [`INVARIANCE`] or what rounding
    /// allows there.
    pub fn rotation_invariant(&self) -> bool {
        self.rotation_excess <= 1.0
    }
}

/// The error of an analytic gradient against central differences, relative to the gradient's size:
/// maxᵢ |∇ₚᵢC − ∇ₚᵢC_fd|∞ / maxᵢ |∇ₚᵢC|.
pub fn relative_error(analytic: &[DVec3], numeric: &[DVec3]) -> f64 {
    let scale = analytic.iter().map(|g| g.length()).fold(0.0, f64::max);
    let error = max_abs_error(analytic, numeric);
    if scale > 0.0 { error / scale } else { error }
}

/// maxᵢ |∇ₚᵢC − ∇ₚᵢC_fd|∞, the largest difference of any one component.
pub fn max_abs_error(analytic: &[DVec3], numeric: &[DVec3]) -> f64 {
    analytic
        .iter()
        .zip(numeric)
        .map(|(a, n)| (*a - *n).abs().max_element())
        .fold(0.0, f64::max)
}

/// The analytic gradient of `family` at `points` (with rest value `rest` and rest shape
/// `rest_shape`) and the central-difference one, in f64.
pub fn analytic_and_numeric(
    families: &Families,
    family: Family,
    points: &[DVec3],
    rest: f64,
    rest_shape: &[DVec3],
) -> (Vec<DVec3>, Vec<DVec3>) {
    let evaluate = |p: &[DVec3]| families.constraint(family).evaluate(p, rest, rest_shape);
    let analytic = evaluate(points).gradients[..points.len()].to_vec();
    let numeric = central_difference(points, |p| evaluate(p).value);
    (analytic, numeric)
}

/// ∇C of `family` by forward-mode automatic differentiation ([`crate::numbers::dual`]): the family's own
/// formula evaluated on dual numbers, once per coordinate; the rest shape is held fixed. `None`
/// where a derivative is not finite.
pub fn automatic_gradient(
    families: &Families,
    family: Family,
    points: &[DVec3],
    rest: f64,
    rest_shape: &[DVec3],
) -> Option<Vec<DVec3>> {
    struct Value<'a>(&'a [DualVec3], f64, &'a [DVec3]);
    impl Visit for Value<'_> {
        type Output = Dual64;
        fn visit<const N: usize, C: Constraint<N>>(self, _: Family, c: &C) -> Dual64 {
            let p: [DualVec3; N] = std::array::from_fn(|k| self.0[k]);
            let shape: [DualVec3; N] =
                std::array::from_fn(|k| DualVec3::seeded(self.2[k], DVec3::ZERO));
            c.evaluate(&p, Dual64::from_f64(self.1), &shape).value
        }
    }
    crate::numbers::dual::gradient(points, |p| {
        families.visit(family, Value(p, rest, rest_shape))
    })
}

/// Whether `points` are far from degenerate: no two closer than [`CONDITIONING`] times the
/// largest distance, and no face of three of them with an angle's sine below it. A point
/// alone always is.
pub fn well_conditioned(points: &[DVec3]) -> bool {
    let n = points.len();
    if n == 1 {
        return true;
    }
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

/// What a check evaluates C with besides the points: the rest shape, and where the particles were
/// at the start of the substep and its length h.
#[derive(Clone, Debug, PartialEq)]
pub struct Around {
    /// The rest shape (the points themselves for a constraint that reads none).
    pub rest_shape: Vec<DVec3>,
    /// Where the particles were at the start of the substep (the points for a constraint that
    /// does not read them).
    pub start: Vec<DVec3>,
    /// The substep's length.
    pub h: f64,
}

impl Around {
    /// At rest shape `rest_shape`, with no motion: the particles were at `points`, h the default
    /// substep.
    pub fn at_rest(points: &[DVec3], rest_shape: &[DVec3]) -> Around {
        Around {
            rest_shape: rest_shape.to_vec(),
            start: points.to_vec(),
            h: crate::constraint_file::RESTING_H,
        }
    }

    /// The motion, as a constraint file reads it.
    pub fn moving(&self) -> crate::constraint_file::Moving<'_> {
        crate::constraint_file::Moving {
            start: &self.start,
            h: self.h,
        }
    }
}

/// A random configuration of `source`'s particles: uniform in a cube of random size
/// 10^U(−2, 2) around a random centre; for a source that reads a rest shape (the neo-Hookean
/// pair's Dm), a rest shape drawn the same way around the same centre, otherwise the points
/// themselves; for one that reads where the particles were at the start of the substep, each
/// moved from there by up to 0.3 of the size, and h = 10^U(−4, −2). Gives the points, what C
/// reads besides them, and the size.
pub fn draw(rng: &mut SplitMix64, source: &impl GradientSource) -> (Vec<DVec3>, Around, f64) {
    let size = 10f64.powf(rng.range(-2.0, 2.0));
    let centre = rng.in_cube(size);
    let mut points = || -> Vec<DVec3> {
        (0..source.arity())
            .map(|_| centre + rng.in_cube(size))
            .collect()
    };
    let current = points();
    let rest_shape = if source.uses_rest_shape() {
        points()
    } else {
        current.clone()
    };
    let mut around = Around::at_rest(&current, &rest_shape);
    if source.uses_motion() {
        around.start = current
            .iter()
            .map(|p| *p - rng.in_cube(0.3 * size))
            .collect();
        around.h = 10f64.powf(rng.range(-4.0, -2.0));
    }
    (current, around, size)
}

/// What the check needs of a constraint: C, the gradient it gives, and ∇C by forward-mode AD.
/// A family of a table ([`TableFamily`]) gives its analytic gradient for every particle; a constraint file
/// gives the gradients it writes (its `[gradient]` table), and none for the others.
pub trait GradientSource {
    /// How many particles one constraint touches.
    fn arity(&self) -> usize;
    /// Whether C reads a rest shape (then one is drawn beside the points).
    fn uses_rest_shape(&self) -> bool;
    /// Whether C reads where the particles were at the start of the substep or h (then they are
    /// drawn beside the points).
    fn uses_motion(&self) -> bool {
        false
    }
    /// C at `points` with rest value `rest` and the rest shape and motion `around` (NaN where
    /// undefined).
    fn value(&self, points: &[DVec3], rest: f64, around: &Around) -> f64;
    /// The gradient the source gives, per particle; `None` for a particle it gives none for.
    fn given(&self, points: &[DVec3], rest: f64, around: &Around) -> Vec<Option<DVec3>>;
    /// ∇C by forward-mode AD; `None` where it is undefined.
    fn automatic(&self, points: &[DVec3], rest: f64, around: &Around) -> Option<Vec<DVec3>>;
    /// A rest value of the size C's own would have at `points` (a file's rest expression where
    /// it gives one, otherwise C with rest value 0).
    fn natural_rest(&self, points: &[DVec3], around: &Around) -> f64;
}

/// A family of a table, as the check sees it: C by the family's formula, its analytic gradient,
/// and AD over the same formula.
#[derive(Clone, Copy)]
pub struct TableFamily<'a> {
    /// The table.
    pub families: &'a Families,
    /// The family.
    pub family: Family,
}

impl GradientSource for TableFamily<'_> {
    fn arity(&self) -> usize {
        self.families.arity(self.family)
    }

    fn uses_rest_shape(&self) -> bool {
        self.families.row(self.family).reads_rest_shape
    }

    fn value(&self, points: &[DVec3], rest: f64, around: &Around) -> f64 {
        let constraint = self.families.constraint(self.family);
        constraint.evaluate(points, rest, &around.rest_shape).value
    }

    fn given(&self, points: &[DVec3], rest: f64, around: &Around) -> Vec<Option<DVec3>> {
        let constraint = self.families.constraint(self.family);
        let evaluation = constraint.evaluate(points, rest, &around.rest_shape);
        evaluation.gradients[..points.len()]
            .iter()
            .map(|&g| Some(g))
            .collect()
    }

    fn automatic(&self, points: &[DVec3], rest: f64, around: &Around) -> Option<Vec<DVec3>> {
        automatic_gradient(self.families, self.family, points, rest, &around.rest_shape)
    }

    fn natural_rest(&self, points: &[DVec3], around: &Around) -> f64 {
        self.value(points, 0.0, around)
    }
}

/// The outcome of [`random_check`].
#[derive(Clone, Debug, PartialEq)]
pub struct FamilyReport {
    /// The family checked.
    pub family: Family,
    /// Configurations compared.
    pub compared: usize,
    /// Configurations drawn but skipped as near-degenerate.
    pub skipped: usize,
    /// The largest [`relative_error`] seen.
    pub max_relative_error: f64,
    /// The mean [`relative_error`].
    pub mean_relative_error: f64,
    /// The largest [`relative_error`] of the analytic gradient against automatic differentiation
    /// ([`automatic_gradient`]), on the same configurations.
    pub max_automatic_error: f64,
}

/// Draws configurations until `samples` well-conditioned ones have been compared: points uniform
/// in a cube of random size 10^U(−2, 2) around a random centre, rest value random in the range of
/// the constraint's own values, and (for a family that reads one) a rest shape drawn the same
/// way. Returns the error statistics.
pub fn random_check(
    families: &Families,
    family: Family,
    samples: usize,
    seed: u64,
) -> FamilyReport {
    let source = TableFamily { families, family };
    let mut rng = SplitMix64::new(seed);
    let (mut compared, mut skipped) = (0, 0);
    let (mut max_error, mut sum_error, mut max_automatic) = (0.0_f64, 0.0, 0.0_f64);
    while compared < samples {
        let (points, around, _) = draw(&mut rng, &source);
        let rest_shape = around.rest_shape.clone();
        if !well_conditioned(&points) || !well_conditioned(&rest_shape) {
            skipped += 1;
            continue;
        }
        let rest = source.natural_rest(&points, &around) * rng.range(-1.5, 1.5);
        let (analytic, numeric) =
            analytic_and_numeric(families, family, &points, rest, &rest_shape);
        let error = relative_error(&analytic, &numeric);
        max_error = max_error.max(error);
        if let Some(automatic) = automatic_gradient(families, family, &points, rest, &rest_shape) {
            max_automatic = max_automatic.max(relative_error(&analytic, &automatic));
        }
        sum_error += error;
        compared += 1;
    }
    FamilyReport {
        family,
        compared,
        skipped,
        max_relative_error: max_error,
        mean_relative_error: if compared > 0 {
            sum_error / compared as f64
        } else {
            0.0
        },
        max_automatic_error: max_automatic,
    }
}

/// What rounding can make of Σᵢ ∇ᵢC at one configuration, relative to the gradient's size
/// `scale`, never below [`INVARIANCE`]: how far AD's gradient (`automatic`) moves when every
/// point moves by the same 10⁻⁹ of the configuration's size, times the particles (a sum of that
/// many terms) and a margin of 10.
///
/// Why: such a move leaves the exact gradient of a translation-invariant C as it is, and changes
/// the rounding of every operation, so the change is the rounding's size there. An exactly
/// invariant C on an ill-conditioned rest shape (det F − 1, a normalised shear: Dm⁻¹ large) has
/// Σ ∇C of 10⁻⁸ of |∇C| from rounding alone, which a fixed bound of 10⁻⁹ read as "not
/// invariant". A C that is not invariant changes by H t there, 10⁻⁹ of it, and its Σ ∇C (a
/// property of C, the size of ∇C itself) stays far above the floor.
fn rounding_floor<S: GradientSource>(
    source: &S,
    (points, rest, around): (&[DVec3], f64, &Around),
    automatic: &[DVec3],
    scale: f64,
) -> f64 {
    let size = points
        .iter()
        .flat_map(|p| points.iter().map(move |q| p.distance(*q)))
        .fold(0.0, f64::max);
    let shift = DVec3::new(0.48, -0.62, 0.62) * (1e-9 * size);
    let moved: Vec<DVec3> = points.iter().map(|p| *p + shift).collect();
    // The rest shape too (by another shift): the rounding of what is worked out from it (Dm⁻¹)
    // is as much the configuration's as that of the points.
    let reshaped = Around {
        rest_shape: around
            .rest_shape
            .iter()
            .map(|p| *p + DVec3::new(shift.z, shift.x, shift.y))
            .collect(),
        start: around.start.iter().map(|p| *p + shift).collect(),
        h: around.h,
    };
    let noise = match source.automatic(&moved, rest, &reshaped) {
        Some(again) => max_abs_error(&again, automatic) / scale,
        None => 0.0,
    };
    let floor = 10.0 * points.len() as f64 * noise;
    if floor.is_finite() {
        floor.max(INVARIANCE)
    } else {
        INVARIANCE
    }
}

/// Compares on `configs` well-conditioned random configurations ([`draw`]; rest value the natural
/// one × U(−1.5, 1.5)), then on near-degenerate ones.
pub fn check<S: GradientSource>(source: &S, configs: usize, seed: u64) -> Report {
    let arity = source.arity();
    let mut rng = SplitMix64::new(seed);
    let mut report = Report {
        compared: 0,
        skipped: 0,
        max_relative_error: vec![None; arity],
        worst: None,
        automatic_vs_finite_difference: 0.0,
        translation: 0.0,
        translation_given: None,
        rotation: 0.0,
        translation_excess: 0.0,
        translation_given_excess: None,
        rotation_excess: 0.0,
        rounding: INVARIANCE,
        reflection: Reflection::Unchanged,
        near_degenerate: 0,
        undefined: 0,
    };
    let (mut unchanged, mut negated, mut reflected_any) = (true, true, false);
    let mut attempts = 0usize;
    while report.compared < configs && attempts < configs.saturating_mul(100).max(1000) {
        attempts += 1;
        let (points, shape, size) = draw(&mut rng, source);
        if !well_conditioned(&points) || !well_conditioned(&shape.rest_shape) {
            report.skipped += 1;
            continue;
        }
        // A rest value of the size C's own would have: the file's rest expression where it
        // gives one (C = V / rest − 1 is undefined with rest 0), else C with rest 0.
        let rest = source.natural_rest(&points, &shape) * rng.range(-1.5, 1.5);
        let value = source.value(&points, rest, &shape);
        let automatic = source
            .automatic(&points, rest, &shape)
            .filter(|_| value.is_finite());
        let Some(automatic) = automatic else {
            report.skipped += 1;
            continue;
        };
        report.compared += 1;
        let scale = automatic.iter().map(|g| g.length()).fold(0.0, f64::max);
        let numeric = central_difference(&points, |p| source.value(p, rest, &shape));
        report.automatic_vs_finite_difference = report
            .automatic_vs_finite_difference
            .max(relative_error(&automatic, &numeric));
        let given = source.given(&points, rest, &shape);
        let floor = if scale > 0.0 {
            rounding_floor(source, (&points, rest, &shape), &automatic, scale)
        } else {
            INVARIANCE
        };
        report.rounding = report.rounding.max(floor);
        if scale > 0.0 && given.iter().all(Option::is_some) {
            let sum: DVec3 = given.iter().flatten().sum();
            let off = sum.length() / scale;
            let off = if off.is_finite() { off } else { f64::INFINITY };
            let slot = report.translation_given.get_or_insert(0.0);
            *slot = slot.max(off);
            let slot = report.translation_given_excess.get_or_insert(0.0);
            *slot = slot.max(off / floor);
        }
        for (k, yours) in given.iter().enumerate() {
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
                    rest_shape: source.uses_rest_shape().then(|| shape.rest_shape.clone()),
                    moving: source.uses_motion().then(|| (shape.start.clone(), shape.h)),
                    rest,
                    relative_error: error,
                    absolute: scale == 0.0,
                });
            }
        }
        if scale > 0.0 {
            let sum: DVec3 = automatic.iter().sum();
            let translation = sum.length() / scale;
            report.translation = report.translation.max(translation);
            report.translation_excess = report.translation_excess.max(translation / floor);
            let mean = points.iter().sum::<DVec3>() / arity as f64;
            let torque: DVec3 = points
                .iter()
                .zip(&automatic)
                .map(|(p, g)| (*p - mean).cross(*g))
                .sum();
            let rotation = torque.length() / (scale * size);
            report.rotation = report.rotation.max(rotation);
            report.rotation_excess = report.rotation_excess.max(rotation / floor);
        }
        // Reflection, and a rotation's effect on C itself, with rest 0.
        let raw = source.value(&points, 0.0, &shape);
        let mirrored: Vec<DVec3> = points.iter().map(|p| DVec3::new(-p.x, p.y, p.z)).collect();
        let reflected = source.value(&mirrored, 0.0, &shape);
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
    for points in near_degenerate(arity, &mut rng, 200) {
        report.near_degenerate += 1;
        let around = Around::at_rest(&points, &points);
        let value = source.value(&points, 0.0, &around);
        if !value.is_finite() || source.automatic(&points, 0.0, &around).is_none() {
            report.undefined += 1;
        }
    }
    report
}

/// Configurations at or near degeneracy: two points coincident, all coincident, all on a line,
/// p3 on the plane of p0, p1, p2 (for four), and the same moved by 10⁻⁹ of their size. One
/// particle alone is checked at rest, where the caller puts it (p0 = q0: a pin at its place).
fn near_degenerate(arity: usize, rng: &mut SplitMix64, count: usize) -> Vec<Vec<DVec3>> {
    let mut shapes = Vec::with_capacity(count);
    while shapes.len() < count {
        let size = 10f64.powf(rng.range(-2.0, 2.0));
        let mut points: Vec<DVec3> = (0..arity).map(|_| rng.in_cube(size)).collect();
        if arity == 1 {
            shapes.push(points);
            continue;
        }
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
