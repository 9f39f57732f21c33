//! The fast solver's kernel: what one projection moves (a family alone, or a pair as one
//! constraint of two values, [`Projected`]) projected colour by colour, eight elements (edges,
//! tets or a tet's vertices) at a time in SIMD lanes, through the generic formula and the
//! projection rule every engine shares ([`correct_in_reach`]); threads share large colours.
//!
//! A batch's particles are gathered into registers, its constraints projected there, and the
//! corrections added to the positions (Gauss–Seidel) or to the Jacobi sums.

use super::batches::{Batches, Layout, RestRows, Typed};
use super::particles::Particles;
use super::schedule::sweep;
use super::team::Team;
use crate::constraints::{GROUP, Projected, SubstepStart};
use crate::numbers::lanes::{F32x8, LANES, Vec3x8};
use crate::numbers::vector::{Real, Vector3};
use crate::simulation::projection::{Rule, SkipCounts, correct_in_reach};
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
    /// Where the particles were at the start of the substep, and h: gathered only for a family
    /// that reads them ([`Projected::reads_motion`]).
    start: (Particles<'a>, F32x8),
    /// The Jacobi sums, when projecting in Jacobi order.
    sums: Option<Particles<'a>>,
}

/// Projects batches of elements that share no particle, one projection of `K` values per
/// element: the corrections are added to the positions (Gauss–Seidel) or, in Jacobi order, to
/// the sums. Returns the projections of each value skipped for a counted reason.
#[inline]
#[allow(clippy::too_many_arguments)]
fn project_batches<const N: usize, const K: usize, const OWN: bool, P: Projected<N, K>>(
    constraint: &P,
    particles: &[[[u32; LANES]; N]],
    weights: &[[F32x8; N]],
    (size, reach): (&[F32x8], F32x8),
    rest: [RestRows; K],
    lambda: [&mut [F32x8]; K],
    access: Access,
    rules: [Rule<F32x8>; K],
) -> [SkipCounts; K] {
    let mut skips = [SkipCounts::default(); K];
    let moving = constraint.reads_motion();
    let read = access.read;
    let write = access.sums.unwrap_or(read);
    // A macro rather than a closure, so that the correction is inlined at both of its places
    // (as a closure called twice, it was not, and its evaluation went through memory).
    macro_rules! project {
        ($b:expr, $evaluations:expr) => {{
            let b = $b;
            let lambdas = std::array::from_fn(|k| lambda[k][b]);
            // A family's own compliances, where some body has them (`OWN`, a separate
            // instantiation, so that the loop without them is as it was).
            let rules: [Rule<F32x8>; K] = if OWN {
                std::array::from_fn(|k| match rest[k].own(b) {
                    Some(own) => rules[k].with_own(own),
                    None => rules[k],
                })
            } else {
                rules
            };
            let d = correct_in_reach(
                $evaluations,
                weights[b],
                lambdas,
                rules,
                (reach, size[b]),
                || gather_batch(read, &particles[b]),
            );
            for k in 0..K {
                skips[k].add(d.skipped[k]);
                lambda[k][b] += d.delta_lambda[k];
            }
            for (&indices, delta) in particles[b].iter().zip(d.delta_x) {
                scatter_add(write, indices, delta);
            }
        }};
    }
    let mut b = 0;
    if P::GROUPED {
        // GROUP batches at a time: they share no particle, so that gathering them all before
        // writing any changes nothing.
        while b + GROUP <= particles.len() {
            let (p, shape) = gather_group((access, P::READS_REST_SHAPE), particles, b);
            let start = if moving {
                std::array::from_fn(|j| gather_batch(access.start.0, &particles[b + j]))
            } else {
                p
            };
            let rows = rest.map(|rest| rest.group(b));
            let evaluations = constraint.evaluate_batches(
                &p,
                rows.map(|(rest, _)| rest),
                &shape,
                rows.map(|(_, stored)| stored),
                (&start, access.start.1),
            );
            // Batch j's values are column j of the K rows.
            #[allow(clippy::needless_range_loop)]
            for j in 0..GROUP {
                project!(b + j, std::array::from_fn(|k| evaluations[k][j]));
            }
            b += GROUP;
        }
    }
    // The next batch is gathered before this one is written (they share no particle), so that
    // its loads overlap this one's arithmetic.
    let mut next = particles.get(b).map(|indices| gather_batch(read, indices));
    while let Some(p) = next {
        let rows = rest.map(|rest| rest.of(b));
        next = particles
            .get(b + 1)
            .map(|indices| gather_batch(read, indices));
        let shape = if P::READS_REST_SHAPE {
            gather_batch(access.rest_shape, &particles[b])
        } else {
            p
        };
        let start = if moving {
            gather_batch(access.start.0, &particles[b])
        } else {
            p
        };
        let evaluations = constraint.evaluate_stored(
            &p,
            rows.map(|(rest, _)| rest),
            &shape,
            rows.map(|(_, stored)| stored),
            SubstepStart {
                start: &start,
                h: access.start.1,
            },
        );
        project!(b, evaluations);
        b += 1;
    }
    skips
}

/// Batches `b..b + GROUP`, gathered: their particles and their rest shapes (the particles again
/// unless `uses_rest_shape`).
#[inline(always)]
fn gather_group<const N: usize>(
    (access, uses_rest_shape): (Access, bool),
    particles: &[[[u32; LANES]; N]],
    b: usize,
) -> ([[Vec3x8; N]; GROUP], [[Vec3x8; N]; GROUP]) {
    let mut p = [[Vec3x8::ZERO; N]; GROUP];
    let mut shape = [[Vec3x8::ZERO; N]; GROUP];
    for j in 0..GROUP {
        p[j] = gather_batch(access.read, &particles[b + j]);
        shape[j] = if uses_rest_shape {
            gather_batch(access.rest_shape, &particles[b + j])
        } else {
            p[j]
        };
    }
    (p, shape)
}

/// Projects every constraint of a unit of `K` families (`batches`, one per family, on `layout`),
/// colour by colour in `order` (empty: the layout's), moving `positions` (Gauss–Seidel) or, given
/// `sums`, adding the corrections to `sums` (Jacobi: `positions` stay as they are); with a
/// `team`, large colours are shared by its threads, each projecting a contiguous share of the
/// colour's batches. Returns how many elements it projected, and how many projections of each
/// family were skipped for a counted reason.
#[inline]
#[allow(clippy::too_many_arguments)]
pub(crate) fn project<const N: usize, const K: usize, P: Projected<N, K>>(
    constraint: &P,
    layout: &Layout,
    order: &[u32],
    batches: [&mut Batches; K],
    (positions, residuals): (&mut [Vec3A], &mut [Vec3A]),
    (rest_positions, (previous, h)): (&mut [Vec3A], (&mut [Vec3A], f64)),
    sums: Option<&mut [Vec3A]>,
    (rules, reach): ([Rule<f64>; K], f64),
    team: Option<&Team>,
) -> (usize, [SkipCounts; K]) {
    let rules: [Rule<F32x8>; K] = rules.map(Rule::to);
    let reach = F32x8::from_f64(reach);
    let Typed {
        particles,
        weights,
        size,
        colours,
        particle_count,
    } = layout.typed::<N>();
    let rows = batches.map(Batches::rows);
    let rest = rows.each_ref().map(|(rest, _)| *rest);
    let lambdas = rows.map(|(_, lambda)| lambda);
    let access = Access {
        read: Particles::compensated(positions, residuals, particle_count),
        rest_shape: Particles::new(rest_positions, particle_count),
        start: (Particles::new(previous, particle_count), F32x8::from_f64(h)),
        sums: sums.map(|sums| Particles::new(sums, particle_count)),
    };
    let skips = sweep(layout, order, team, lambdas, |range, lambdas| {
        let rest = rest.map(|rest| rest.batches(range.clone()));
        let batches = (&particles[range.clone()], &weights[range.clone()]);
        let size = (&size[range.clone()], reach);
        if rest.iter().any(|rest| rest.has_own()) {
            let (particles, weights) = batches;
            project_batches::<N, K, true, P>(
                constraint, particles, weights, size, rest, lambdas, access, rules,
            )
        } else {
            let (particles, weights) = batches;
            project_batches::<N, K, false, P>(
                constraint, particles, weights, size, rest, lambdas, access, rules,
            )
        }
    });
    (colours.iter().map(|c| c.elements).sum(), skips)
}
