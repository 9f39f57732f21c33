//! A family's C and ∇C in any number type that compares to a `bool` (f64, and the dual numbers of
//! forward-mode automatic differentiation), and from it ∇²C: what the energy's Hessian and its
//! checks ([`crate::energy`]) and the Newton reference ([`crate::simulation::newton`])
//! differentiate. For a constraint file, ∇C is its compiled AD, never the file's own gradient: the
//! derivative of the energy is the derivative of C.

use super::{Constraint, Families, Family, SubstepStart, Visit};
use crate::numbers::dual::{DualVec3, Tangent};
use crate::numbers::vector::{Real, Vector3};
use glam::DVec3;
use nalgebra::SMatrix;

/// A 12 × 12 matrix: the second derivatives of one constraint in its particles' coordinates
/// (particle by particle, x y z), the first 3N rows and columns used.
pub type Matrix12 = SMatrix<f64, 12, 12>;

/// C and ∇C of one constraint of `family` at `x`, with its rest value and stored numbers `rest`
/// and rest shape `rest_shape`, in any number type `T` that compares to a bool: ∇C by the
/// family's formula, or for a file by its compiled AD (never the file's own gradient).
pub fn value_and_gradient<T: Real<Mask = bool>, const N: usize>(
    families: &Families,
    family: Family,
    x: &[[T; 3]; N],
    rest: (f64, &[f64]),
    rest_shape: &[DVec3; N],
) -> (T, [[T; 3]; N]) {
    value_and_gradient_moving(families, family, x, rest, rest_shape, None)
}

/// [`value_and_gradient`] with the particles at `start` at the start of the substep of length h:
/// for a family that reads them ([`Constraint::reads_motion`]), the Newton reference's substep.
/// `None` is at rest: the particles were where they are (`x`'s values, held, not differentiated
/// with it), h the default substep.
pub fn value_and_gradient_moving<T: Real<Mask = bool>, const N: usize>(
    families: &Families,
    family: Family,
    x: &[[T; 3]; N],
    (rest, stored): (f64, &[f64]),
    rest_shape: &[DVec3; N],
    moving: Option<(&[DVec3; N], f64)>,
) -> (T, [[T; 3]; N]) {
    let stored: arrayvec::ArrayVec<T, { super::MAX_STORED }> =
        stored.iter().map(|&s| T::from_f64(s)).collect();
    let start: [[T; 3]; N] = match moving {
        Some((start, _)) => std::array::from_fn(|k| start[k].to_array().map(T::from_f64)),
        // Where the particles are, held: not differentiated with them.
        None => x.map(|c| c.map(T::constant)),
    };
    let h = T::from_f64(moving.map_or(crate::constraint_file::RESTING_H, |(_, h)| h));
    if let Some(file) = families.file(family) {
        let (value, gradients) =
            file.value_and_gradient(x, (&start, h), T::from_f64(rest), &stored, false);
        let sound = crate::constraint_file::sound::<DualVec3<T>, N>(value, gradients);
        return (sound.value, sound.gradients.map(|g| g.0));
    }
    families.visit(
        family,
        At {
            x,
            rest: T::from_f64(rest),
            stored: &stored,
            rest_shape,
            start: (&start, h),
        },
    )
}

/// C and ∇C (one row per particle, the unused rows 0) of the constraint on `particles` of
/// `family`, with its rest value and stored numbers `rest`, at positions `x` (every particle's),
/// its rest shape from `rest_positions`: [`value_and_gradient`] in f64 for a constraint of any
/// arity, read from the simulation's flat arrays.
///
/// ```
/// use glam::DVec3;
/// use tetlab_core::constraints::differentiable::of_constraint;
/// use tetlab_core::constraints::{Families, Family};
/// let x = [DVec3::ZERO, DVec3::new(3.0, 0.0, 4.0)];
/// let (c, g) = of_constraint(&Families::builtin(), Family::EDGES, &[0, 1], (4.0, &[]), &x, &x);
/// assert_eq!(c, 1.0);
/// assert_eq!((g[1], g[2]), ([0.6, 0.0, 0.8], [0.0; 3]));
/// ```
pub fn of_constraint(
    families: &Families,
    family: Family,
    particles: &[u32],
    rest: (f64, &[f64]),
    x: &[DVec3],
    rest_positions: &[DVec3],
) -> (f64, [[f64; 3]; 4]) {
    of_constraint_moving(families, family, particles, rest, (x, rest_positions), None)
}

/// [`of_constraint`] with every particle at `start` at the start of the substep of length h
/// (`None`: at rest): the Newton reference's constraint values in its substep.
pub fn of_constraint_moving(
    families: &Families,
    family: Family,
    particles: &[u32],
    rest: (f64, &[f64]),
    (x, rest_positions): (&[DVec3], &[DVec3]),
    moving: Option<(&[DVec3], f64)>,
) -> (f64, [[f64; 3]; 4]) {
    fn at<const N: usize>(
        (families, family, particles, rest): (&Families, Family, &[u32], (f64, &[f64])),
        x: &[DVec3],
        rest_positions: &[DVec3],
        moving: Option<(&[DVec3], f64)>,
    ) -> (f64, [[f64; 3]; 4]) {
        let p: [[f64; 3]; N] = std::array::from_fn(|k| x[particles[k] as usize].to_array());
        let shape: [DVec3; N] = std::array::from_fn(|k| rest_positions[particles[k] as usize]);
        let start = moving.map(|(start, h)| {
            let at: [DVec3; N] = std::array::from_fn(|k| start[particles[k] as usize]);
            (at, h)
        });
        let (value, gradients) = value_and_gradient_moving(
            families,
            family,
            &p,
            rest,
            &shape,
            start.as_ref().map(|(at, h)| (at, *h)),
        );
        let mut padded = [[0.0; 3]; 4];
        padded[..N].copy_from_slice(&gradients);
        (value, padded)
    }
    let constraint = (families, family, particles, rest);
    super::for_arity!(particles.len(), |N| at::<N>(
        constraint,
        x,
        rest_positions,
        moving
    ))
}

/// One constraint of a built-in family evaluated at `x`, in the number type of `x`.
struct At<'a, T, const M: usize> {
    x: &'a [[T; 3]; M],
    rest: T,
    stored: &'a [T],
    rest_shape: &'a [DVec3; M],
    start: (&'a [[T; 3]; M], T),
}

impl<T: Real<Mask = bool>, const M: usize> Visit for At<'_, T, M> {
    type Output = (T, [[T; 3]; M]);

    fn visit<const N: usize, C: Constraint<N>>(self, _: Family, c: &C) -> Self::Output {
        assert_eq!(N, M, "the family's arity");
        let p: [DualVec3<T>; N] = std::array::from_fn(|k| DualVec3(self.x[k]));
        let shape: [DualVec3<T>; N] = std::array::from_fn(|k| {
            let q = self.rest_shape[k];
            DualVec3::<T>::from_f64s(q.x, q.y, q.z)
        });
        let start: [DualVec3<T>; N] = std::array::from_fn(|k| DualVec3(self.start.0[k]));
        let moving = SubstepStart {
            start: &start,
            h: self.start.1,
        };
        let e = c.evaluate_stored(&p, self.rest, &shape, self.stored, moving);
        (e.value, std::array::from_fn(|k| e.gradients[k].to_array()))
    }
}

/// C, ∇C and ∇²C of one constraint of `family` at `x` (its N particles), by forward mode over
/// ∇C: coordinate j seeded with a dual number, column j of ∇²C is the slopes of ∇C (3N passes).
/// ∇C is padded to 12 numbers and ∇²C to 12 × 12, symmetrised ((∇²C + ∇²Cᵀ) / 2: symmetric to
/// rounding anyway).
///
/// ```
/// use glam::DVec3;
/// use tetlab_core::constraints::differentiable::second_order;
/// use tetlab_core::constraints::{Families, Family};
/// // C = |p0 − p1| − d: along the edge C is linear, across it ∇²C = (I − n nᵀ) / ℓ.
/// let families = Families::builtin();
/// let (a, b) = (DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0));
/// let (c, g, h) = second_order::<2>(&families, Family::EDGES, &[a, b], (1.0, &[]), &[a, b]);
/// assert_eq!(c, 1.0);
/// assert_eq!((g[0], g[3]), (-1.0, 1.0));
/// assert!(h[(0, 0)].abs() < 1e-15 && (h[(1, 1)] - 0.5).abs() < 1e-15 && (h[(1, 4)] + 0.5).abs() < 1e-15);
/// ```
pub fn second_order<const N: usize>(
    families: &Families,
    family: Family,
    x: &[DVec3; N],
    rest: (f64, &[f64]),
    rest_shape: &[DVec3; N],
) -> (f64, [f64; 12], Matrix12) {
    let at_rest = Some((x, crate::constraint_file::RESTING_H));
    second_order_moving(families, family, x, rest, rest_shape, at_rest)
}

/// [`second_order`] with the particles at `start` at the start of the substep of length h
/// ([`value_and_gradient_moving`]).
pub fn second_order_moving<const N: usize>(
    families: &Families,
    family: Family,
    x: &[DVec3; N],
    (rest, stored): (f64, &[f64]),
    rest_shape: &[DVec3; N],
    moving: Option<(&[DVec3; N], f64)>,
) -> (f64, [f64; 12], Matrix12) {
    let mut value = 0.0;
    let mut gradient = [0.0; 12];
    let mut hessian = Matrix12::zeros();
    for j in 0..3 * N {
        let seeded: [[Tangent<f64>; 3]; N] = std::array::from_fn(|k| {
            std::array::from_fn(|a| Tangent::new(x[k][a], if 3 * k + a == j { 1.0 } else { 0.0 }))
        });
        let (c, g) = value_and_gradient_moving(
            families,
            family,
            &seeded,
            (rest, stored),
            rest_shape,
            moving,
        );
        value = c.value;
        for (i, gi) in g.iter().flatten().enumerate() {
            gradient[i] = gi.value;
            hessian[(i, j)] = gi.slope;
        }
    }
    let symmetric = (hessian + hessian.transpose()) * 0.5;
    (value, gradient, symmetric)
}
