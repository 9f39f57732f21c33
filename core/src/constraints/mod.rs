//! The tetrahedron constraints of tetlab and their analytic gradients.
//!
//! Each constraint is a scalar function C of a few particle positions that is zero when the
//! constraint holds. A projection moves every particle along −∇C, so each module here gives the
//! value C, the gradient ∇C with respect to every particle it touches, and the rest value (d or
//! V) measured on a rest configuration. The derivations are in `docs/gradients.md`.
//!
//! | family | particles | C |
//! | --- | --- | --- |
//! | [`distance`] (`edges`) | p0, p1 | \|p0 − p1\| − d |
//! | [`height`] | p0, p1, p2, p3 | (p1 − p0)·n − d, n the unit normal of (p0, p2, p3) |
//! | [`volume`] | p0, p1, p2, p3 | ⅙ (p1 − p0)·((p2 − p0)×(p3 − p0)) − V |
//! | [`neohookean`] deviatoric | p0, p1, p2, p3 | √V₀ ‖F‖_F, F = Ds Dm⁻¹ |
//! | [`neohookean`] hydrostatic | p0, p1, p2, p3 | √V₀ (det F − γ), γ = 1 + μ/λ |
//!
//! Each is a [`Constraint`] type, one formula generic over the number type. What a family is
//! besides its formula (names, colour, binding, material, what it reads and stores) is data, its
//! [`Row`] (`row`); the built-in rows are `builtin`, one entry each. A [`Families`] value
//! (`family_table`) is the table of families that everything else reads: the built-in ones, and
//! those of constraint files ([`mod@file`]). The solvers reach a family's type through `dispatch`;
//! tools ask any family in f64 through `any`. [`material`] turns Young's modulus and Poisson's
//! ratio into the compliances of the families that take them.
//!
//! When a gradient is undefined (coincident points, a face of zero area) the evaluation is
//! flagged ([`Evaluation::degenerate`]), its gradients are zero and its value stays finite.

mod any;
mod binding;
mod builtin;
pub mod contact;
pub mod differentiable;
mod dispatch;
pub mod distance;
mod family_table;
pub mod file;
pub mod height;
pub mod material;
pub mod neohookean;
mod per_family;
mod row;
pub mod verify;
mod visit;
pub mod volume;

pub use any::{AnyConstraint, Typed};
pub use binding::Binding;
pub(crate) use binding::for_arity;
pub use builtin::TABLE;
pub use family_table::{COLOURS, Families, MAX_FILE_FAMILIES, Named};
pub use per_family::PerFamily;
pub use row::{Family, Formula, MAX_FAMILIES, Row};
pub use visit::{Pair, Projected, Unit, Visit, VisitProjected};

use crate::constraints::material::Material;
use crate::numbers::lanes::{F32x8, Vec3x8};
use crate::numbers::vector::{Real, Vector3};
use glam::DVec3;

/// How many batches of lanes the fast engine hands at once to a family that asks for it
/// ([`Constraint::GROUPED`], [`Constraint::evaluate_batches`]).
pub const GROUP: usize = 2;

/// The most numbers a constraint may store beyond its rest value ([`Constraint::store`]): what
/// depends only on its rest shape and the material, worked out once per element.
pub const MAX_STORED: usize = 48;

/// What an element stores ([`Constraint::store`]).
pub type Stored = arrayvec::ArrayVec<f64, MAX_STORED>;

/// Where a constraint's particles were at the start of the substep, and the substep's length h:
/// what a constraint on velocities reads besides the particles (a constraint file's `start0`…
/// and `h`, [`Constraint::reads_motion`]). The solvers gather it only for a family that reads
/// it; elsewhere (and outside a substep: the metrics, the readers) it is [`SubstepStart::at_rest`].
#[derive(Clone, Copy, Debug)]
pub struct SubstepStart<'a, V: Vector3, const N: usize> {
    /// Each particle at the start of the substep.
    pub start: &'a [V; N],
    /// The substep's length in seconds.
    pub h: V::Real,
}

impl<'a, V: Vector3, const N: usize> SubstepStart<'a, V, N> {
    /// No motion: the particles were at `p`, and h is the default substep
    /// ([`crate::constraint_file::RESTING_H`]).
    #[inline(always)]
    pub fn at_rest(p: &'a [V; N]) -> Self {
        SubstepStart {
            start: p,
            h: V::Real::from_f64(crate::constraint_file::RESTING_H),
        }
    }
}

/// A constraint on N particles: C and ∇C at any configuration, in any precision (f64, f32, or
/// eight constraints at once in SIMD lanes).
pub trait Constraint<const N: usize>: Sync {
    /// Whether [`Constraint::evaluate_stored`], what the solvers call, reads `rest_shape`: a
    /// family that stores what it needs of its rest shape ([`Constraint::store`]) does not, and
    /// the solvers then gather no rest positions for it. A constant of the type, since the
    /// solvers' loops are compiled with it.
    const STORED_USES_REST_SHAPE: bool = false;

    /// Whether the fast engine should evaluate this family [`GROUP`] batches at a time
    /// ([`Constraint::evaluate_batches`]) rather than one: for a family whose evaluation costs
    /// something per call whatever the lanes (a constraint file's tape pays its dispatch on each
    /// instruction once per call).
    const GROUPED: bool = false;

    /// Whether [`Constraint::evaluate_stored`] reads where the particles were at the start of
    /// the substep or its h ([`SubstepStart`]): a constraint file that names `start0`… or `h`. The
    /// solvers gather the start positions only then.
    fn reads_motion(&self) -> bool {
        false
    }

    /// C and ∇C at `p`, with rest value `rest` (d, V) and the particles' rest positions
    /// `rest_shape`: the one formula a family must write.
    fn evaluate<V: Vector3>(
        &self,
        p: &[V; N],
        rest: V::Real,
        rest_shape: &[V; N],
    ) -> Evaluation<V, N>;

    /// The rest value of a constraint whose particles are at rest at `rest_shape`: unless the
    /// family says otherwise, C there with rest value 0 (the rest length d, the rest volume V),
    /// so that C = 0 at rest.
    fn rest_value(&self, rest_shape: &[DVec3; N], material: &Material) -> f64 {
        let _ = material;
        self.evaluate(rest_shape, 0.0, rest_shape).value
    }

    /// What a constraint at rest at `rest_shape` stores, with `material`: what depends only on
    /// its rest shape and the material, worked out once per element ([`Row::stored_len`]
    /// numbers). The built-in families store none (they work everything out at each
    /// projection); a constraint file's stores what its prelude computes
    /// (the file's compiled prelude).
    fn store(&self, rest_shape: &[DVec3; N], material: &Material) -> Stored {
        let _ = (rest_shape, material);
        Stored::new()
    }

    /// C and ∇C at `p` given what the element stores ([`Constraint::store`], in the precision of
    /// `V`) and the substep's [`SubstepStart`]: what the solvers call. Unless the family stores
    /// something or reads the motion, [`Constraint::evaluate`].
    #[inline(always)]
    fn evaluate_stored<V: Vector3>(
        &self,
        p: &[V; N],
        rest: V::Real,
        rest_shape: &[V; N],
        stored: &[V::Real],
        motion: SubstepStart<'_, V, N>,
    ) -> Evaluation<V, N> {
        let _ = (stored, motion);
        self.evaluate(p, rest, rest_shape)
    }

    /// C and ∇C of [`GROUP`] batches of lanes of one colour at once, batch j at `p[j]` with
    /// `rest[j]`, `rest_shape[j]` and `stored[j]`. Each batch's evaluation is, to the bit, what
    /// [`Constraint::evaluate_stored`] gives it alone, which is what this does unless the family
    /// has a faster way.
    #[inline(always)]
    fn evaluate_batches(
        &self,
        p: &[[Vec3x8; N]; GROUP],
        rest: [F32x8; GROUP],
        rest_shape: &[[Vec3x8; N]; GROUP],
        stored: [&[F32x8]; GROUP],
        (start, h): (&[[Vec3x8; N]; GROUP], F32x8),
    ) -> [Evaluation<Vec3x8, N>; GROUP] {
        std::array::from_fn(|j| {
            let motion = SubstepStart {
                start: &start[j],
                h,
            };
            self.evaluate_stored(&p[j], rest[j], &rest_shape[j], stored[j], motion)
        })
    }

    /// What else a reader should see of the constraint's particles at `p` (rest shape
    /// `rest_shape`), one line each, beside C and ∇C: the neo-Hookean pair shows F and det F.
    fn describe_state(&self, p: &[DVec3; N], rest_shape: &[DVec3; N]) -> Vec<String> {
        let _ = (p, rest_shape);
        Vec::new()
    }
}

/// A constraint evaluated at one configuration: C and ∇C for each of its N particles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Evaluation<V: Vector3, const N: usize> {
    /// C, the constraint value; zero when the constraint is satisfied.
    pub value: V::Real,
    /// ∇ₚᵢC for each particle pᵢ, in the constraint's particle order.
    pub gradients: [V; N],
    /// Set when ∇C is undefined here (per lane, for lanes); the gradients are then zero.
    pub degenerate: <V::Real as Real>::Mask,
}

impl<V: Vector3, const N: usize> Evaluation<V, N> {
    /// C and ∇C, except where `degenerate` is set: there the value is `degenerate_value` and the
    /// gradients zero.
    #[inline(always)]
    pub fn unless_degenerate(
        degenerate: <V::Real as Real>::Mask,
        value: V::Real,
        degenerate_value: V::Real,
        gradients: [V; N],
    ) -> Self {
        let mut kept = [V::ZERO; N];
        for (k, g) in gradients.iter().enumerate() {
            kept[k] = V::select(degenerate, V::ZERO, *g);
        }
        Self {
            value: V::Real::select(degenerate, degenerate_value, value),
            gradients: kept,
            degenerate,
        }
    }

    /// Σᵢ |∇ₚᵢC|², unweighted.
    #[inline]
    pub fn gradient_norm_squared(&self) -> V::Real {
        let mut sum = V::Real::ZERO;
        for g in &self.gradients {
            sum += g.length_squared();
        }
        sum
    }
}

/// The gradient of the first particle of a translation-invariant constraint:
/// ∇ₚ₀C = −(∇ₚ₁C + ∇ₚ₂C + ∇ₚ₃C), since moving all four particles together leaves C unchanged.
#[inline]
pub(crate) fn first_from_rest<V: Vector3>(g1: V, g2: V, g3: V) -> [V; 4] {
    [-(g1 + g2 + g3), g1, g2, g3]
}
