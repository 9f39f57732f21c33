//! The fast solver's kernels: a family's constraints projected colour by colour, eight elements
//! (edges, tets or a tet's vertices) at a time in SIMD lanes, through the generic formula
//! ([`Constraint`]) and projection rule ([`correction_lanes`]); threads share large colours.
//!
//! A batch's particles are gathered into registers, its constraints projected there, and the
//! corrections added to the positions (Gauss–Seidel) or to the Jacobi sums.

use super::batches::{Batches, Layout, RestRows, Typed};
use super::particles::Particles;
use super::schedule::sweep;
use super::team::Team;
use crate::constraints::{Constraint, Evaluation, GROUP};
use crate::numbers::lanes::{F32x8, LANES, Vec3x8};
use crate::numbers::vector::{Real, Vector3};
use crate::simulation::projection::{Rule, SkipCounts, correction_lanes, pair_correction_lanes};
use glam::Vec3A;

/// The particles `indices` (one per lane) as eight x, eight y and eight z.
#[inline(always)]
fn gather(positions: Particles, indices: [u32; LANES]) -> Vec3x8 {
    let [i0, i1, i2, i3, i4, i5, i6, i7] = indices;
    Vec3x8::from_rows([
        positions.get(i0),
        positions.get(i1),
        positions.get(i2),
        positions.get(i3),
        positions.get(i4),
        positions.get(i5),
        positions.get(i6),
        positions.get(i7),
    ])
}

/// Every particle of a batch, gathered.
#[inline(always)]
fn gather_batch<const N: usize>(positions: Particles, indices: &[[u32; LANES]; N]) -> [Vec3x8; N] {
    let mut p = [Vec3x8::ZERO; N];
    for (p, &indices) in p.iter_mut().zip(indices) {
        *p = gather(positions, indices);
    }
    p
}

/// Adds lane k of `delta` to particle `indices[k]`.
#[inline(always)]
fn scatter_add(positions: Particles, indices: [u32; LANES], delta: Vec3x8) {
    for (&i, row) in indices.iter().zip(delta.rows()) {
        positions.add(i, row);
    }
}

/// Where the kernels read and write: the positions (or their rest shape, for a family that reads
/// it), and where corrections go: the same positions for Gauss–Seidel, the sums for Jacobi.
#[derive(Clone, Copy)]
struct Access<'a> {
    read: Particles<'a>,
    rest_shape: Particles<'a>,
    /// The Jacobi sums, when projecting in Jacobi order.
    sums: Option<Particles<'a>>,
}

/// Projects batches of elements that share no particle, one constraint per element: the
/// corrections are added to the positions (Gauss–Seidel) or, in Jacobi order, to the sums.
/// Returns the projections skipped for a counted reason.
#[inline]
#[allow(clippy::too_many_arguments)]
fn project_batches<const N: usize, C: Constraint<N>>(
    constraint: &C,
    particles: &[[[u32; LANES]; N]],
    weights: &[[F32x8; N]],
    (size, reach): (&[F32x8], F32x8),
    rest: RestRows,
    lambda: &mut [F32x8],
    access: Access,
    rule: Rule<F32x8>,
) -> SkipCounts {
    let mut skips = SkipCounts::default();
    let read = access.read;
    let write = access.sums.unwrap_or(read);
    // A macro rather than a closure, so that the correction is inlined at both of its places
    // (as a closure called twice, it was not, and its evaluation went through memory).
    macro_rules! project {
        ($b:expr, $evaluation:expr) => {{
            let b = $b;
            let (skipped, d) =
                correction_lanes($evaluation, weights[b], lambda[b], rule, size[b] * reach);
            skips.add(skipped);
            lambda[b] += d.delta_lambda;
            for (&indices, delta) in particles[b].iter().zip(d.delta_x) {
                scatter_add(write, indices, delta);
            }
        }};
    }
    let mut b = 0;
    if C::GROUPED {
        // GROUP batches at a time: they share no particle, so that gathering them all before
        // writing any changes nothing.
        while b + GROUP <= particles.len() {
            let (p, shape, rows) =
                gather_group((access, C::STORED_USES_REST_SHAPE), particles, rest, b);
            let evaluations = constraint.evaluate_batches(&p, rows.0, &shape, rows.1);
            for (j, evaluation) in evaluations.iter().enumerate() {
                project!(b + j, *evaluation);
            }
            b += GROUP;
        }
    }
    // The next batch is gathered before this one is written (they share no particle), so that
    // its loads overlap this one's arithmetic.
    let mut next = particles.get(b).map(|indices| gather_batch(read, indices));
    while let Some(p) = next {
        let (rest, stored) = rest.of(b);
        next = particles
            .get(b + 1)
            .map(|indices| gather_batch(read, indices));
        let shape = if C::STORED_USES_REST_SHAPE {
            gather_batch(access.rest_shape, &particles[b])
        } else {
            p
        };
        project!(b, constraint.evaluate_stored(&p, rest, &shape, stored));
        b += 1;
    }
    skips
}

/// Batches `b..b + GROUP`, gathered: their particles, their rest shapes (the particles again
/// unless `uses_rest_shape`) and their rows of rest values and stored numbers.
#[inline(always)]
#[allow(clippy::type_complexity)]
fn gather_group<'a, const N: usize>(
    (access, uses_rest_shape): (Access, bool),
    particles: &[[[u32; LANES]; N]],
    rest: RestRows<'a>,
    b: usize,
) -> (
    [[Vec3x8; N]; GROUP],
    [[Vec3x8; N]; GROUP],
    ([F32x8; GROUP], [&'a [F32x8]; GROUP]),
) {
    let mut p = [[Vec3x8::ZERO; N]; GROUP];
    let mut shape = [[Vec3x8::ZERO; N]; GROUP];
    let mut rows = [F32x8::ZERO; GROUP];
    let mut stored: [&[F32x8]; GROUP] = [&[]; GROUP];
    for j in 0..GROUP {
        p[j] = gather_batch(access.read, &particles[b + j]);
        shape[j] = if uses_rest_shape {
            gather_batch(access.rest_shape, &particles[b + j])
        } else {
            p[j]
        };
        (rows[j], stored[j]) = rest.of(b + j);
    }
    (p, shape, (rows, stored))
}

/// Projects every constraint of a family (`batches`, on `layout`), colour by colour in `order`
/// (empty: the layout's), moving `positions` (Gauss–Seidel) or, given `sums`, adding the
/// corrections to `sums` (Jacobi: `positions` stay as they are); with a `team`, large colours
/// are shared by its threads, each projecting a contiguous share of the colour's batches. Returns how many constraints it projected, and
/// how many of them were skipped for a counted reason.
#[inline]
#[allow(clippy::too_many_arguments)]
pub(crate) fn project_family<const N: usize, C: Constraint<N>>(
    constraint: &C,
    layout: &Layout,
    order: &[u32],
    batches: &mut Batches,
    (positions, residuals): (&mut [Vec3A], &mut [Vec3A]),
    rest_positions: &mut [Vec3A],
    sums: Option<&mut [Vec3A]>,
    (rule, reach): (Rule<f64>, f64),
    team: Option<&Team>,
) -> (usize, SkipCounts) {
    let rule: Rule<F32x8> = rule.to();
    let reach = F32x8::from_f64(reach);
    let Typed {
        particles,
        weights,
        size,
        colours,
        particle_count,
    } = layout.typed::<N>();
    let (rest, lambda) = batches.rows();
    let access = Access {
        read: Particles::compensated(positions, residuals, particle_count),
        rest_shape: Particles::new(rest_positions, particle_count),
        sums: sums.map(|sums| Particles::new(sums, particle_count)),
    };
    let [skips] = sweep(layout, order, team, [lambda], |range, [lambda]| {
        [project_batches::<N, C>(
            constraint,
            &particles[range.clone()],
            &weights[range.clone()],
            (&size[range.clone()], reach),
            rest.batches(range),
            lambda,
            access,
            rule,
        )]
    });
    (colours.iter().map(|c| c.elements).sum(), skips)
}

/// [`project_batches`] for two families projected together ([`pair_correction_lanes`]): one
/// constraint of each per element, on the same layout; each has its own rest values and
/// multipliers.
#[inline]
#[allow(clippy::too_many_arguments)]
fn project_pair_batches<const N: usize, A: Constraint<N>, const M: usize, B: Constraint<M>>(
    (first, second): (&A, &B),
    particles: &[[[u32; LANES]; N]],
    (weights, size, reach): (&[[F32x8; N]], &[F32x8], F32x8),
    (rest_a, rest_b): (RestRows, RestRows),
    (lambda_a, lambda_b): (&mut [F32x8], &mut [F32x8]),
    access: Access,
    rules: [Rule<F32x8>; 2],
) -> [SkipCounts; 2] {
    assert_eq!(N, M, "a pair shares its particles");
    let mut skips = [SkipCounts::default(); 2];
    // A macro rather than a closure, as in project_batches: inlined at both of its places.
    macro_rules! project {
        ($b:expr, $first:expr, $second:expr) => {{
            let (b, e) = ($b, $second);
            let mut gradients = [Vec3x8::ZERO; N];
            for (k, g) in gradients.iter_mut().enumerate() {
                *g = e.gradients[k];
            }
            let second_evaluation = Evaluation {
                value: e.value,
                gradients,
                degenerate: e.degenerate,
            };
            let d = pair_correction_lanes(
                $first,
                second_evaluation,
                weights[b],
                [lambda_a[b], lambda_b[b]],
                rules,
                size[b] * reach,
            );
            for (counts, skipped) in skips.iter_mut().zip(d.skipped) {
                counts.add(skipped);
            }
            lambda_a[b] += d.delta_lambda[0];
            lambda_b[b] += d.delta_lambda[1];
            let write = access.sums.unwrap_or(access.read);
            for (i, &indices) in particles[b].iter().enumerate() {
                scatter_add(write, indices, d.delta_x[i]);
            }
        }};
    }
    let uses_rest_shape = A::STORED_USES_REST_SHAPE || B::STORED_USES_REST_SHAPE;
    let mut b = 0;
    if A::GROUPED && B::GROUPED {
        // GROUP batches at a time, as in project_batches.
        while b + GROUP <= particles.len() {
            let (p, shape, (rest_a_rows, stored_a)) =
                gather_group((access, uses_rest_shape), particles, rest_a, b);
            let first = first.evaluate_batches(&p, rest_a_rows, &shape, stored_a);
            let mut rest_b_rows = [F32x8::ZERO; GROUP];
            let mut stored_b: [&[F32x8]; GROUP] = [&[]; GROUP];
            for j in 0..GROUP {
                (rest_b_rows[j], stored_b[j]) = rest_b.of(b + j);
            }
            let (mut p2, mut shape2) = ([[Vec3x8::ZERO; M]; GROUP], [[Vec3x8::ZERO; M]; GROUP]);
            for j in 0..GROUP {
                for k in 0..M {
                    (p2[j][k], shape2[j][k]) = (p[j][k], shape[j][k]);
                }
            }
            let second = second.evaluate_batches(&p2, rest_b_rows, &shape2, stored_b);
            for j in 0..GROUP {
                project!(b + j, first[j], second[j]);
            }
            b += GROUP;
        }
    }
    for (b, indices) in particles.iter().enumerate().skip(b) {
        let p = gather_batch(access.read, indices);
        let shape = if uses_rest_shape {
            gather_batch(access.rest_shape, indices)
        } else {
            p
        };
        let ((rest_first, stored_a), (rest_second, stored_b)) = (rest_a.of(b), rest_b.of(b));
        let first_evaluation = first.evaluate_stored(&p, rest_first, &shape, stored_a);
        let p2: [Vec3x8; M] = std::array::from_fn(|k| p[k]);
        let shape2: [Vec3x8; M] = std::array::from_fn(|k| shape[k]);
        let e = second.evaluate_stored(&p2, rest_second, &shape2, stored_b);
        project!(b, first_evaluation, e);
    }
    skips
}

/// [`project_family`] for two families projected together, element by element (the neo-Hookean
/// pair: one constraint of each per tet, on the same layout). Returns how many constraints of
/// each it projected, and how many of each were skipped for a counted reason.
#[inline]
#[allow(clippy::too_many_arguments)]
pub(crate) fn project_pair<const N: usize, A: Constraint<N>, const M: usize, B: Constraint<M>>(
    constraints: (&A, &B),
    layout: &Layout,
    order: &[u32],
    (first, second): (&mut Batches, &mut Batches),
    (positions, residuals): (&mut [Vec3A], &mut [Vec3A]),
    rest_positions: &mut [Vec3A],
    sums: Option<&mut [Vec3A]>,
    (rules, reach): ([Rule<f64>; 2], f64),
    team: Option<&Team>,
) -> (usize, [SkipCounts; 2]) {
    let rules: [Rule<F32x8>; 2] = rules.map(Rule::to);
    let reach = F32x8::from_f64(reach);
    let Typed {
        particles,
        weights,
        size,
        colours,
        particle_count,
    } = layout.typed::<N>();
    let (rest_a, lambda_a) = first.rows();
    let (rest_b, lambda_b) = second.rows();
    let access = Access {
        read: Particles::compensated(positions, residuals, particle_count),
        rest_shape: Particles::new(rest_positions, particle_count),
        sums: sums.map(|sums| Particles::new(sums, particle_count)),
    };
    let skips = sweep(
        layout,
        order,
        team,
        [lambda_a, lambda_b],
        |range, [lambda_a, lambda_b]| {
            project_pair_batches::<N, A, M, B>(
                constraints,
                &particles[range.clone()],
                (&weights[range.clone()], &size[range.clone()], reach),
                (rest_a.batches(range.clone()), rest_b.batches(range)),
                (lambda_a, lambda_b),
                access,
                rules,
            )
        },
    );
    (colours.iter().map(|c| c.elements).sum(), skips)
}
