//! The projection rule every engine shares ([`correct`]): how one projection moves its
//! particles, in any precision and for one element or eight in SIMD lanes, for a family alone
//! (K = 1 value) or two projected together (K = 2).
//!
//! Projecting one constraint C with particles i, gradients ∇ᵢC and inverse masses wᵢ:
//! - XPBD: α̃ = α / h², Δλ = (−C − α̃ λ) / (Σ wᵢ|∇ᵢC|² + α̃), λ += Δλ, Δxᵢ = wᵢ ∇ᵢC Δλ;
//! - PBD: s = −C / Σ wᵢ|∇ᵢC|², Δxᵢ = k′ s wᵢ ∇ᵢC with k′ = 1 − (1 − k)^(1/iterations), so that
//!   `iterations` sweeps of stiffness k′ compound to k;
//! - PBD on a family whose compliance a material gives (the neo-Hookean pair, which has no
//!   stiffness k): Δλ = −C / (Σ wᵢ|∇ᵢC|² + α̃) in every sweep, XPBD without the multiplier's
//!   memory, so that more sweeps make the material stiffer, as in PBD.
//!
//! A constraint is skipped (no correction) where its evaluation is degenerate (undefined ∇C),
//! where every particle is fixed, where it is [`LOCKED`], and where its step would be longer
//! than [`DEFAULT_REACH`] times the longest rest edge of its element and would lengthen the
//! element ([`correct_in_reach`]): such a step is not a correction but a singularity of ∇C (see
//! [`DEFAULT_REACH`]). The degenerate and the too long are counted ([`SkipCounts`]).

pub use super::settings::DEFAULT_REACH;
use crate::constraints::Evaluation;
use crate::numbers::vector::{Mask, Real, Vector3};
use glam::DVec3;

/// The change one projection of `K` values makes: Δλ of each (XPBD; the scaled step s for PBD),
/// Δx per particle, and why each value was skipped, among the counted reasons.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Correction<const N: usize, const K: usize, V: Vector3 = DVec3> {
    /// XPBD: Δλ. PBD: k′ s. Zero for a value that is skipped.
    pub delta_lambda: [V::Real; K],
    /// Δx for each particle (zero when every value is skipped).
    pub delta_x: [V; N],
    /// Whether each value was skipped, and why ([`Skipped`]).
    pub skipped: [Skipped<<V::Real as Real>::Mask>; K],
}

/// The correction of a projection of `K` values at once, the rule every engine runs: for
/// K = 1 the rule of the module's documentation, for K = 2 the 2 × 2 solve of two constraints on
/// the same particles (`pair_correction_lanes`). In any precision, for one element or eight in
/// SIMD lanes; branch-free within each.
///
/// ```
/// use glam::DVec3;
/// use tetlab_core::constraints::distance;
/// use tetlab_core::simulation::projection::{Rule, correct};
/// // A rigid edge stretched from 1 to 2 between equal masses: each end moves half the way.
/// let (a, b) = (DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0));
/// let e = distance::evaluate(&[a, b], 1.0);
/// let rule = Rule::Xpbd { alpha_tilde: 0.0 };
/// let c = correct([e], [1.0, 1.0], [0.0], [rule], f64::INFINITY);
/// assert!((c.delta_x[0] - DVec3::new(0.5, 0.0, 0.0)).length() < 1e-15);
/// assert!((c.delta_x[1] + DVec3::new(0.5, 0.0, 0.0)).length() < 1e-15);
/// ```
#[inline(always)]
pub fn correct<V: Vector3, const N: usize, const K: usize>(
    evaluations: [Evaluation<V, N>; K],
    weights: [V::Real; N],
    lambda: [V::Real; K],
    rules: [Rule<V::Real>; K],
    reach: V::Real,
) -> Correction<N, K, V> {
    match K {
        1 => {
            let (skipped, (delta_lambda, delta_x)) =
                correction_lanes(evaluations[0], weights, lambda[0], rules[0], reach);
            Correction {
                delta_lambda: [delta_lambda; K],
                delta_x,
                skipped: [skipped; K],
            }
        }
        2 => {
            let pair = pair_correction_lanes(
                evaluations[0],
                evaluations[1],
                weights,
                [lambda[0], lambda[1]],
                [rules[0], rules[1]],
                reach,
            );
            Correction {
                delta_lambda: std::array::from_fn(|k| pair.delta_lambda[k]),
                delta_x: pair.delta_x,
                skipped: std::array::from_fn(|k| pair.skipped[k]),
            }
        }
        _ => unreachable!("a projection has one value or two"),
    }
}

/// [`correct`] with the reach of an element: a step longer than `reach` times `size` (the
/// element's longest rest edge) is skipped, unless it leaves the element no larger than it is
/// now (its `extent`, the longest distance between two of its particles at `positions`): a
/// correction that pulls a stretched element together is the one that undoes the damage, and
/// it is never a singularity's throw, which flings a particle away from the others.
///
/// Why: a body stretched far beyond its rest shape (1,200-fold in one frame by a dihedral-angle
/// file on a mirrored cube) needs steps of its stretched size to come back; measured against the
/// rest size alone, every one of them, the rigid edges' included, was skipped and the body could
/// never return. Measured against the current size instead, each step could grow the element
/// by the reach and the next step allow a longer one: a singular ∇C would throw the body without
/// bound. A step that does not lengthen the element cannot do that.
///
/// The positions are read only where a step was too long (`positions` is called then), and a
/// lane's correction is the same whether its neighbours' were or not.
///
/// ```
/// use glam::DVec3;
/// use tetlab_core::constraints::distance;
/// use tetlab_core::simulation::projection::{Rule, correct_in_reach};
/// // An edge of rest length 1 stretched to 1000: its correction, 999, is far beyond a reach of
/// // 100 rest lengths, but it pulls the edge together, so it is made.
/// let p = [DVec3::ZERO, DVec3::new(1000.0, 0.0, 0.0)];
/// let rule = Rule::Xpbd { alpha_tilde: 0.0 };
/// let pull = |p: [DVec3; 2]| {
///     let e = distance::evaluate(&p, 1.0);
///     correct_in_reach([e], [1.0, 1.0], [0.0], [rule], (100.0, 1.0), || p)
/// };
/// let c = pull(p);
/// assert!(!c.skipped[0].too_long);
/// assert!(((p[1] + c.delta_x[1] - p[0] - c.delta_x[0]).length() - 1.0).abs() < 1e-9);
/// // Pushed apart instead (rest length 10⁶ from 1000), the same length of step is skipped.
/// let e = distance::evaluate(&p, 1e6);
/// let c = correct_in_reach([e], [1.0, 1.0], [0.0], [rule], (100.0, 1.0), || p);
/// assert!(c.skipped[0].too_long);
/// ```
#[inline(always)]
pub fn correct_in_reach<V: Vector3, const N: usize, const K: usize>(
    evaluations: [Evaluation<V, N>; K],
    weights: [V::Real; N],
    lambda: [V::Real; K],
    rules: [Rule<V::Real>; K],
    (reach, size): (V::Real, V::Real),
    positions: impl FnOnce() -> [V; N],
) -> Correction<N, K, V> {
    let limited = reach * size;
    let first = correct(evaluations, weights, lambda, rules, limited);
    if !first.skipped.iter().any(|s| s.too_long.any()) {
        return first;
    }
    let p = positions();
    let unlimited = V::Real::from_f64(f64::INFINITY);
    let free = correct(evaluations, weights, lambda, rules, unlimited);
    let mut after = p;
    for (x, dx) in after.iter_mut().zip(free.delta_x) {
        *x += dx;
    }
    let shrinks = extent(&after).le(extent(&p));
    correct(
        evaluations,
        weights,
        lambda,
        rules,
        V::Real::select(shrinks, unlimited, limited),
    )
}

/// The longest squared distance between two of `p`: the size of an element now, squared.
#[inline(always)]
fn extent<V: Vector3, const N: usize>(p: &[V; N]) -> V::Real {
    let mut largest = V::Real::ZERO;
    for i in 0..N {
        for j in i + 1..N {
            let d = (p[i] - p[j]).length_squared();
            largest = V::Real::select(d.gt(largest), d, largest);
        }
    }
    largest
}

/// How a correction is scaled: XPBD with α̃ = α / h², or PBD with the per-iteration stiffness k′.
#[derive(Clone, Copy, Debug)]
pub enum Rule<R> {
    /// XPBD with α̃ = α / h².
    Xpbd {
        /// α̃ = α / h².
        alpha_tilde: R,
    },
    /// PBD with the per-sweep stiffness k′.
    Pbd {
        /// k′ = 1 − (1 − k)^(1/iterations).
        k: R,
    },
    /// PBD with a compliance: each sweep starts from λ = 0.
    CompliantPbd {
        /// α̃ = α / h².
        alpha_tilde: R,
    },
}

/// Rigid XPBD (α̃ = 0).
impl<R: Real> Default for Rule<R> {
    fn default() -> Self {
        Rule::Xpbd {
            alpha_tilde: R::ZERO,
        }
    }
}

impl<R: Real> Rule<R> {
    /// The rule for a constraint of its own compliance: α̃ = `own` (its α / h²) in each lane
    /// where `own` is a number, the family's where it is NaN. PBD's stiffness k is the
    /// family's for every constraint (own compliances come from a body's material, and a family
    /// a material gives is never projected by k).
    ///
    /// ```
    /// use tetlab_core::simulation::projection::Rule;
    /// let family = Rule::Xpbd { alpha_tilde: 2.0 };
    /// assert!(matches!(family.with_own(5.0), Rule::Xpbd { alpha_tilde } if alpha_tilde == 5.0));
    /// assert!(matches!(family.with_own(f64::NAN), Rule::Xpbd { alpha_tilde } if alpha_tilde == 2.0));
    /// ```
    #[inline(always)]
    pub fn with_own(self, own: R) -> Rule<R> {
        let pick = |alpha_tilde: R| R::select(own.finite(), own, alpha_tilde);
        match self {
            Rule::Xpbd { alpha_tilde } => Rule::Xpbd {
                alpha_tilde: pick(alpha_tilde),
            },
            Rule::CompliantPbd { alpha_tilde } => Rule::CompliantPbd {
                alpha_tilde: pick(alpha_tilde),
            },
            Rule::Pbd { k } => Rule::Pbd { k },
        }
    }
}

impl Rule<f64> {
    /// The rule of constraint `c` of `set`, whose family's rule is this one, in a substep of
    /// length `h`: α̃ = α_c / h² where the constraint has a compliance of its own
    /// ([`crate::simulation::ConstraintSet::own_compliance`]).
    #[inline]
    pub fn of_constraint(self, set: &crate::simulation::ConstraintSet, c: usize, h: f64) -> Self {
        match set.own_compliance(c) {
            Some(alpha) => self.with_own(alpha / (h * h)),
            None => self,
        }
    }

    /// The same rule in another precision.
    pub fn to<R: Real>(self) -> Rule<R> {
        match self {
            Rule::Xpbd { alpha_tilde } => Rule::Xpbd {
                alpha_tilde: R::from_f64(alpha_tilde),
            },
            Rule::Pbd { k } => Rule::Pbd { k: R::from_f64(k) },
            Rule::CompliantPbd { alpha_tilde } => Rule::CompliantPbd {
                alpha_tilde: R::from_f64(alpha_tilde),
            },
        }
    }
}

/// The correction that projecting one constraint would make, or `None` when it is skipped
/// (degenerate, every particle pinned, or a step longer than `reach`, [`DEFAULT_REACH`]), for one
/// constraint in f64 or f32 ([`correct`] with K = 1).
#[inline]
pub(crate) fn correction<V: Vector3, const N: usize>(
    evaluation: Evaluation<V, N>,
    weights: [V::Real; N],
    lambda: V::Real,
    rule: Rule<V::Real>,
    reach: V::Real,
) -> Option<Correction<N, 1, V>>
where
    V::Real: Real<Mask = bool>,
{
    let correction = correct([evaluation], weights, [lambda], [rule], reach);
    (!correction.skipped[0].any()).then_some(correction)
}

/// Whether a projection (or each lane of one) was skipped (`all`), and the reasons that are
/// counted: its ∇C undefined or not finite where some particle could move (`degenerate`), or its
/// step longer than its reach (`too_long`). A constraint whose particles are all fixed (or
/// [`LOCKED`]) is skipped without being counted: that is a pin, not a fault.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Skipped<M> {
    /// Skipped, for any reason.
    pub all: M,
    /// ∇C undefined (degenerate, or not finite).
    pub degenerate: M,
    /// The step, max |Δxᵢ|, longer than the reach.
    pub too_long: M,
}

impl<M: crate::numbers::vector::Mask> Skipped<M> {
    /// Whether it (some lane of it) was skipped.
    #[inline(always)]
    pub fn any(self) -> bool {
        self.all.any()
    }
}

/// Projections skipped for a counted reason ([`Skipped`]), summed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SkipCounts {
    /// With ∇C undefined or not finite.
    pub degenerate: u64,
    /// With a step longer than the reach ([`DEFAULT_REACH`]).
    pub too_long: u64,
}

impl SkipCounts {
    /// Adds the lanes `skipped` flags.
    #[inline(always)]
    pub(crate) fn add<M: crate::numbers::vector::Mask>(&mut self, skipped: Skipped<M>) {
        self.degenerate += u64::from(skipped.degenerate.count());
        self.too_long += u64::from(skipped.too_long.count());
    }

    /// Whether none was skipped.
    pub fn is_zero(&self) -> bool {
        *self == SkipCounts::default()
    }
}

impl std::ops::Add for SkipCounts {
    type Output = SkipCounts;
    fn add(self, other: SkipCounts) -> SkipCounts {
        SkipCounts {
            degenerate: self.degenerate + other.degenerate,
            too_long: self.too_long + other.too_long,
        }
    }
}

/// The projection rule without a branch, for one constraint or several in lanes:
/// Σ wᵢ|∇ᵢC|²; XPBD Δλ = (−C − α̃λ) / (Σ wᵢ|∇ᵢC|² + α̃), PBD Δλ = −k′C / Σ wᵢ|∇ᵢC|²; Δxᵢ = wᵢ ∇ᵢC Δλ.
/// The correction is zero where the evaluation is degenerate, where Σ wᵢ|∇ᵢC|² is not positive
/// and finite (every particle fixed), where the constraint is [`LOCKED`] (its free particles
/// can barely change it), and where the step max |Δxᵢ| is longer than `reach` (or not a number);
/// the counted reasons are returned ([`Skipped`]).
#[inline(always)]
fn correction_lanes<V: Vector3, const N: usize>(
    evaluation: Evaluation<V, N>,
    weights: [V::Real; N],
    lambda: V::Real,
    rule: Rule<V::Real>,
    reach: V::Real,
) -> (Skipped<<V::Real as Real>::Mask>, Step<V, N>) {
    let (skipped, degenerate, weighted_norm, largest) = skipped_lanes(&evaluation, &weights);
    let delta_lambda = match rule {
        Rule::Xpbd { alpha_tilde } => {
            (-evaluation.value - alpha_tilde * lambda) / (weighted_norm + alpha_tilde)
        }
        Rule::Pbd { k } => k * -evaluation.value / weighted_norm,
        Rule::CompliantPbd { alpha_tilde } => -evaluation.value / (weighted_norm + alpha_tilde),
    };
    // The longest step, max |Δxᵢ|² = Δλ² max wᵢ²|∇ᵢC|², from the norms already taken. A step
    // that is not a number is not "too long": it reaches the positions, and the divergence check
    // names it.
    let too_long = !skipped & (delta_lambda * delta_lambda * largest).gt(reach * reach);
    let skipped = skipped | too_long;
    let mut delta_x = [V::ZERO; N];
    for ((dx, g), w) in delta_x.iter_mut().zip(&evaluation.gradients).zip(weights) {
        *dx = V::select(skipped, V::ZERO, *g * (w * delta_lambda));
    }
    (
        Skipped {
            all: skipped,
            degenerate,
            too_long,
        },
        (
            V::Real::select(skipped, V::Real::ZERO, delta_lambda),
            delta_x,
        ),
    )
}

/// What one value's projection changes: Δλ, and Δx per particle.
type Step<V, const N: usize> = (<V as Vector3>::Real, [V; N]);

/// What [`skipped_lanes`] finds: whether each lane is skipped, which of those are counted as
/// degenerate, Σ wᵢ|∇ᵢC|², and max wᵢ²|∇ᵢC|².
type Norms<R> = (<R as Real>::Mask, <R as Real>::Mask, R, R);

/// Whether a projection skips the constraint (degenerate, every particle fixed, or [`LOCKED`]);
/// of those, the degenerate ones where some particle is free (the ones counted);
/// Σ wᵢ|∇ᵢC|²; and max wᵢ²|∇ᵢC|², the longest step per unit Δλ, squared.
#[inline(always)]
fn skipped_lanes<V: Vector3, const N: usize>(
    evaluation: &Evaluation<V, N>,
    weights: &[V::Real; N],
) -> Norms<V::Real> {
    // Σ wᵢ|∇ᵢC|², max wᵢ²|∇ᵢC|², and for LOCKED max wᵢ and Σ|∇ᵢC|², in one pass.
    let mut weighted_norm = V::Real::ZERO;
    let mut norm = V::Real::ZERO;
    let mut heaviest = V::Real::ZERO;
    let mut largest = V::Real::ZERO;
    for (w, g) in weights.iter().zip(&evaluation.gradients) {
        let squared = g.length_squared();
        let weighted = *w * squared;
        weighted_norm += weighted;
        norm += squared;
        heaviest = V::Real::select(w.gt(heaviest), *w, heaviest);
        let reach = *w * weighted;
        largest = V::Real::select(reach.gt(largest), reach, largest);
    }
    let locked = weighted_norm.le(V::Real::from_f64(LOCKED) * heaviest * norm);
    let undefined = evaluation.degenerate | !weighted_norm.finite();
    let skipped = undefined | !weighted_norm.gt(V::Real::ZERO) | locked;
    (
        skipped,
        undefined & heaviest.gt(V::Real::ZERO),
        weighted_norm,
        largest,
    )
}

/// Two constraints on the same particles projected together (the neo-Hookean pair, whose two
/// constraints pull against each other at rest): with gᵃ, gᵇ their gradients, W the inverse
/// masses and α̃ each one's compliance / h², Δλ solves the 2 × 2 system
///
/// ⎡gᵃ·W gᵃ + α̃ᵃ   gᵃ·W gᵇ     ⎤ ⎡Δλᵃ⎤   ⎡−Cᵃ − α̃ᵃ λᵃ⎤
/// ⎣gᵇ·W gᵃ        gᵇ·W gᵇ + α̃ᵇ⎦ ⎣Δλᵇ⎦ = ⎣−Cᵇ − α̃ᵇ λᵇ⎦,   Δxᵢ = wᵢ (gᵃᵢ Δλᵃ + gᵇᵢ Δλᵇ),
///
/// where projecting them one after the other would let the first undo itself fully before the
/// second answers (a stiff material's deviatoric constraint then squashes each tet). A
/// constraint that [`correction_lanes`] would skip takes no part; under PBD (no multiplier's
/// memory) λ counts as 0. The diagonal gains ε (a + b) so that the system stays solvable when
/// the gradients are parallel and the compliances nearly 0 (a tet at rest). A step longer than
/// `reach` skips both ([`DEFAULT_REACH`]).
#[inline(always)]
fn pair_correction_lanes<V: Vector3, const N: usize>(
    first: Evaluation<V, N>,
    second: Evaluation<V, N>,
    weights: [V::Real; N],
    lambda: [V::Real; 2],
    rules: [Rule<V::Real>; 2],
    reach: V::Real,
) -> Correction<N, 2, V> {
    let zero = V::Real::ZERO;
    let one = V::Real::ONE;
    let part = |e: &Evaluation<V, N>, lambda: V::Real, rule: Rule<V::Real>| {
        let (skipped, degenerate, weighted_norm, _) = skipped_lanes(e, &weights);
        let (alpha, rhs) = match rule {
            Rule::Xpbd { alpha_tilde } => (alpha_tilde, -e.value - alpha_tilde * lambda),
            Rule::CompliantPbd { alpha_tilde } => (alpha_tilde, -e.value),
            Rule::Pbd { k } => (zero, -(k * e.value)),
        };
        let mut gradients = [V::ZERO; N];
        for (g, &kept) in gradients.iter_mut().zip(&e.gradients) {
            *g = V::select(skipped, V::ZERO, kept);
        }
        let diagonal = V::Real::select(skipped, one, weighted_norm + alpha);
        (
            skipped,
            degenerate,
            gradients,
            diagonal,
            V::Real::select(skipped, zero, rhs),
        )
    };
    let (skip_a, degenerate_a, ga, mut a, rhs_a) = part(&first, lambda[0], rules[0]);
    let (skip_b, degenerate_b, gb, mut b, rhs_b) = part(&second, lambda[1], rules[1]);
    let mut ab = zero;
    for k in 0..N {
        ab += weights[k] * ga[k].dot(gb[k]);
    }
    let ridge = V::Real::EPSILON * (a + b);
    a += ridge;
    b += ridge;
    let det = a * b - ab * ab;
    let delta_a = V::Real::select(skip_a, zero, (b * rhs_a - ab * rhs_b) / det);
    let delta_b = V::Real::select(skip_b, zero, (a * rhs_b - ab * rhs_a) / det);
    let mut delta_x = [V::ZERO; N];
    let mut step = zero;
    for k in 0..N {
        delta_x[k] = (ga[k] * delta_a + gb[k] * delta_b) * weights[k];
        let squared = delta_x[k].length_squared();
        step = V::Real::select(squared.gt(step), squared, step);
    }
    let too_long = !(skip_a & skip_b) & !step.le(reach * reach);
    for dx in &mut delta_x {
        *dx = V::select(too_long, V::ZERO, *dx);
    }
    let skipped = |all, degenerate| Skipped {
        all: all | too_long,
        degenerate,
        too_long,
    };
    Correction {
        delta_lambda: [
            V::Real::select(too_long, zero, delta_a),
            V::Real::select(too_long, zero, delta_b),
        ],
        delta_x,
        skipped: [skipped(skip_a, degenerate_a), skipped(skip_b, degenerate_b)],
    }
}

/// One rigid XPBD projection of a constraint at `points` with rest value `rest` and inverse
/// masses `weights`, starting from λ = 0, with a reach of `reach`: Δx per particle (zero when
/// skipped). The kernel the solvers run per constraint, for benchmarks (`core/benches/kernels.rs`).
pub fn project_kernel<V: Vector3, const N: usize>(
    evaluate: impl Fn(&[V; N], V::Real) -> Evaluation<V, N>,
    points: &[V; N],
    rest: V::Real,
    weights: [V::Real; N],
    reach: V::Real,
) -> [V; N] {
    let rule = Rule::Xpbd {
        alpha_tilde: V::Real::ZERO,
    };
    correct(
        [evaluate(points, rest)],
        weights,
        [V::Real::ZERO],
        [rule],
        reach,
    )
    .delta_x
}

/// Below this fraction of max wᵢ · Σ|∇ᵢC|², Σ wᵢ|∇ᵢC|² says that the particles free to move
/// (w > 0) can barely change the constraint: those that could are pinned or held, and the free
/// ones' gradients nearly vanish. Projecting it would move a free particle by about |C| / |∇ᵢC|,
/// unboundedly far as ∇ᵢC → 0 (a face vertex of a height constraint whose other corners are
/// held flings out by millions of metres, and the next projections feed on it). At this
/// threshold a projection moves no particle more than 1/√LOCKED = 100 times as far as it would
/// with every particle free; at or below it the constraint is skipped, like a degenerate one:
/// Σ wᵢ|∇ᵢC|² ≤ LOCKED · max wᵢ · Σ|∇ᵢC|².
pub const LOCKED: f64 = 1e-4;

/// Σ wᵢ |∇ₚᵢC|², the denominator of every projection.
#[inline]
pub(crate) fn weighted_norm<V: Vector3, const N: usize>(
    weights: &[V::Real; N],
    gradients: &[V; N],
) -> V::Real {
    let mut sum = V::Real::ZERO;
    for (w, g) in weights.iter().zip(gradients) {
        sum += *w * g.length_squared();
    }
    sum
}
