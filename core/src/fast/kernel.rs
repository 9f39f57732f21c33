//! The fast solver's kernels: a family's batches projected colour by colour, eight constraints
//! at a time in SIMD lanes, through the generic formula ([`Constraint`]) and projection rule
//! ([`correction_lanes`]); threads share large colours.

use super::batches::{Batches, Typed};
use super::particles::Particles;
use crate::constraints::Constraint;
use crate::lanes::{F32x8, LANES, Vec3x8};
use crate::projection::{Rule, correction_lanes, pair_correction_lanes};
use crate::vector::Vector3;
use glam::Vec3A;

/// Colours with fewer constraints than this are projected on one thread even when several are
/// available: below it, handing out the work costs more than it saves.
pub const PARALLEL_MIN: usize = 1024;

/// Batches per task when threads share a colour. Which thread projects a batch does not change
/// what it computes, so the result is the same bits for any thread count.
#[cfg(feature = "parallel")]
const CHUNK: usize = 64;

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
/// it), and where corrections go (the same positions for Gauss–Seidel, the sums for Jacobi).
#[derive(Clone, Copy)]
struct Access<'a> {
    read: Particles<'a>,
    rest_shape: Particles<'a>,
    write: Particles<'a>,
}

/// Projects batches of constraints that share no particle, [`LANES`] constraints at a time (the
/// generic formula and projection rule on [`Vec3x8`]): reads the particles from `access.read`
/// and adds the corrections to `access.write`.
#[inline]
#[allow(clippy::too_many_arguments)]
fn project_batches<const N: usize, C: Constraint<N>>(
    constraint: &C,
    particles: &[[[u32; LANES]; N]],
    weights: &[[F32x8; N]],
    rest: &[F32x8],
    lambda: &mut [F32x8],
    access: Access,
    rule: Rule<F32x8>,
) {
    let read = access.read;
    // The next batch is gathered before this one is corrected (they share no particle), so that
    // its loads overlap this one's arithmetic.
    let mut next = particles.first().map(|indices| gather_batch(read, indices));
    for (b, (((indices, weights), &rest), lambda)) in particles
        .iter()
        .zip(weights)
        .zip(rest)
        .zip(lambda)
        .enumerate()
    {
        let Some(p) = next else { break };
        next = particles
            .get(b + 1)
            .map(|indices| gather_batch(read, indices));
        let shape = if C::USES_REST_SHAPE {
            gather_batch(access.rest_shape, indices)
        } else {
            p
        };
        let (_, d) = correction_lanes(
            constraint.evaluate(&p, rest, &shape),
            *weights,
            *lambda,
            rule,
        );
        *lambda += d.delta_lambda;
        for (&indices, delta) in indices.iter().zip(d.delta_x) {
            scatter_add(access.write, indices, delta);
        }
    }
}

/// Projects every constraint of `batches`, colour by colour, and adds the corrections to
/// `positions` (Gauss–Seidel) or, given `sums`, to `sums` (Jacobi: `positions` stay as they are);
/// with `parallel`, large colours are shared by the threads of the current pool. Returns how many
/// constraints it projected.
#[inline]
#[allow(clippy::too_many_arguments)]
pub(crate) fn project_family<const N: usize, C: Constraint<N>>(
    constraint: &C,
    batches: &mut Batches,
    positions: &mut [Vec3A],
    rest_positions: &mut [Vec3A],
    sums: Option<&mut [Vec3A]>,
    rule: Rule<f64>,
    parallel: bool,
) -> usize {
    let rule: Rule<F32x8> = rule.to();
    let Typed {
        particles,
        weights,
        rest,
        lambda,
        colours,
        particle_count,
    } = batches.typed::<N>();
    let read = Particles::new(positions, particle_count);
    let access = Access {
        read,
        rest_shape: Particles::new(rest_positions, particle_count),
        write: sums.map_or(read, |sums| Particles::new(sums, particle_count)),
    };
    let mut count = 0;
    for colour in colours.iter() {
        let range = colour.batches.clone();
        let (particles, weights, rest, lambda) = (
            &particles[range.clone()],
            &weights[range.clone()],
            &rest[range.clone()],
            &mut lambda[range],
        );
        match parallel && colour.constraints >= PARALLEL_MIN {
            #[cfg(feature = "parallel")]
            true => {
                use rayon::prelude::*;
                lambda
                    .par_chunks_mut(CHUNK)
                    .zip(particles.par_chunks(CHUNK))
                    .zip(weights.par_chunks(CHUNK))
                    .zip(rest.par_chunks(CHUNK))
                    .for_each(|(((lambda, particles), weights), rest)| {
                        project_batches::<N, C>(
                            constraint, particles, weights, rest, lambda, access, rule,
                        );
                    })
            }
            _ => {
                project_batches::<N, C>(constraint, particles, weights, rest, lambda, access, rule)
            }
        }
        count += colour.constraints;
    }
    count
}

/// [`project_batches`] for two families projected together ([`pair_correction_lanes`]): the
/// batches of both have the same particles, in the same order; each has its own rest values and
/// multipliers.
#[inline]
#[allow(clippy::too_many_arguments)]
fn project_pair_batches<const N: usize, A: Constraint<N>, const M: usize, B: Constraint<M>>(
    (first, second): (&A, &B),
    particles: &[[[u32; LANES]; N]],
    weights: &[[F32x8; N]],
    (rest_a, rest_b): (&[F32x8], &[F32x8]),
    (lambda_a, lambda_b): (&mut [F32x8], &mut [F32x8]),
    access: Access,
    rules: [Rule<F32x8>; 2],
) {
    assert_eq!(N, M, "a pair shares its particles");
    for (b, (indices, weights)) in particles.iter().zip(weights).enumerate() {
        let p = gather_batch(access.read, indices);
        let shape = if A::USES_REST_SHAPE || B::USES_REST_SHAPE {
            gather_batch(access.rest_shape, indices)
        } else {
            p
        };
        let first_evaluation = first.evaluate(&p, rest_a[b], &shape);
        let p2: [Vec3x8; M] = std::array::from_fn(|k| p[k]);
        let shape2: [Vec3x8; M] = std::array::from_fn(|k| shape[k]);
        let e = second.evaluate(&p2, rest_b[b], &shape2);
        let second_evaluation = crate::constraints::Evaluation {
            value: e.value,
            gradients: std::array::from_fn(|k| e.gradients[k]),
            degenerate: e.degenerate,
        };
        let d = pair_correction_lanes(
            first_evaluation,
            second_evaluation,
            *weights,
            [lambda_a[b], lambda_b[b]],
            rules,
        );
        lambda_a[b] += d.delta_lambda[0];
        lambda_b[b] += d.delta_lambda[1];
        for (&indices, delta) in indices.iter().zip(d.delta_x) {
            scatter_add(access.write, indices, delta);
        }
    }
}

/// [`project_family`] for two families projected together, constraint by constraint: their
/// batches (`pair`) were built from the same particles, so they have the same colours and
/// batches. Returns how many constraints of each it projected.
#[inline]
#[allow(clippy::too_many_arguments)]
pub(crate) fn project_pair<const N: usize, A: Constraint<N>, const M: usize, B: Constraint<M>>(
    constraints: (&A, &B),
    (first, second): (&mut Batches, &mut Batches),
    positions: &mut [Vec3A],
    rest_positions: &mut [Vec3A],
    sums: Option<&mut [Vec3A]>,
    rules: [Rule<f64>; 2],
    parallel: bool,
) -> usize {
    let rules: [Rule<F32x8>; 2] = rules.map(Rule::to);
    let Typed {
        particles,
        weights,
        rest: rest_a,
        lambda: lambda_a,
        colours,
        particle_count,
    } = first.typed::<N>();
    let Typed {
        particles: particles_b,
        rest: rest_b,
        lambda: lambda_b,
        ..
    } = second.typed::<M>();
    assert_eq!(
        particles.len(),
        particles_b.len(),
        "a pair has the same batches"
    );
    let read = Particles::new(positions, particle_count);
    let access = Access {
        read,
        rest_shape: Particles::new(rest_positions, particle_count),
        write: sums.map_or(read, |sums| Particles::new(sums, particle_count)),
    };
    let mut count = 0;
    for colour in colours.iter() {
        let range = colour.batches.clone();
        let (particles, weights) = (&particles[range.clone()], &weights[range.clone()]);
        let rest = (&rest_a[range.clone()], &rest_b[range.clone()]);
        let (lambda_a, lambda_b) = (&mut lambda_a[range.clone()], &mut lambda_b[range]);
        match parallel && colour.constraints >= PARALLEL_MIN {
            #[cfg(feature = "parallel")]
            true => {
                use rayon::prelude::*;
                lambda_a
                    .par_chunks_mut(CHUNK)
                    .zip(lambda_b.par_chunks_mut(CHUNK))
                    .zip(particles.par_chunks(CHUNK))
                    .zip(weights.par_chunks(CHUNK))
                    .zip(rest.0.par_chunks(CHUNK).zip(rest.1.par_chunks(CHUNK)))
                    .for_each(|((((lambda_a, lambda_b), particles), weights), rest)| {
                        project_pair_batches::<N, A, M, B>(
                            constraints,
                            particles,
                            weights,
                            rest,
                            (lambda_a, lambda_b),
                            access,
                            rules,
                        );
                    })
            }
            _ => project_pair_batches::<N, A, M, B>(
                constraints,
                particles,
                weights,
                rest,
                (lambda_a, lambda_b),
                access,
                rules,
            ),
        }
        count += colour.constraints;
    }
    count
}
