//! The fast solver: the substep of [`crate::solver`] in f32, on flat arrays laid out for speed, on
//! one thread or several. For big meshes, headless runs and `tetlab bench`; the interactive f64
//! solver stays the reference and the teaching path.
//!
//! What is the same: the constraint formulas (the generic code of [`crate::constraints`] for
//! [`Vec3A`]), the projection rule ([`crate::solver`]'s `correction`), the integration
//! (`integrate`), rest values, masses and pins (taken from a [`Simulation`]).
//!
//! What differs, for speed:
//! - particles are renumbered along a Morton (Z-order) curve, so that particles close in space are
//!   close in memory; [`FastSimulation::positions`] gives them back in the scene's numbering;
//! - each family's constraints are coloured so that no two of one colour share a particle, and
//!   projected colour by colour (Gauss–Seidel across colours). Within a colour the order does not
//!   matter, so several threads can share a colour and the result is the same bits whatever the
//!   thread count;
//! - f32 instead of f64, and no grab or settling (nobody drags a benchmark).

use crate::constraints::{Evaluation, Family, distance, plane, volume};
use crate::integrate;
use crate::lanes::{F32x4, LANES, Vec3x4};
use crate::solver::{PerFamily, Rule, Settings, Simulation, correction, correction_lanes};
use crate::vector::Vector3;
use glam::{DVec3, Vec3A};
use std::ops::Range;
use std::time::{Duration, Instant};

/// Colours with fewer constraints than this are projected on one thread even when several are
/// available: below it, handing out the work costs more than it saves.
pub const PARALLEL_MIN: usize = 1024;

/// One family's constraints, coloured: particle indices (renumbered), rest values, multipliers,
/// and the ranges of constraints that share no particle.
#[derive(Clone, Debug, Default)]
pub struct Batches<const N: usize> {
    /// The particles of each constraint.
    pub particles: Vec<[u32; N]>,
    rest: Vec<f32>,
    lambda: Vec<f32>,
    /// Constraints `colours[k]` share no particle; colours are projected in order.
    pub colours: Vec<Range<usize>>,
}

impl<const N: usize> Batches<N> {
    /// Colours constraints given as (particles, rest) in the new particle numbering: greedy, each
    /// constraint takes the first colour none of its particles has yet; within a colour, sorted by
    /// first particle for locality.
    fn new(constraints: Vec<([u32; N], f32)>, particle_count: usize) -> Self {
        let mut colour_of = vec![usize::MAX; constraints.len()];
        let mut remaining: Vec<usize> = (0..constraints.len()).collect();
        let mut base = 0;
        // 64 colours per pass, one bit each per particle; constraints that find none wait for the
        // next pass.
        while !remaining.is_empty() {
            let mut used = vec![0u64; particle_count];
            let mut waiting = Vec::new();
            for c in remaining {
                let particles = constraints[c].0;
                let taken = particles
                    .iter()
                    .fold(0u64, |mask, &i| mask | used[i as usize]);
                if taken == u64::MAX {
                    waiting.push(c);
                    continue;
                }
                let colour = taken.trailing_ones() as usize;
                for &i in &particles {
                    used[i as usize] |= 1 << colour;
                }
                colour_of[c] = base + colour;
            }
            remaining = waiting;
            base += 64;
        }
        let mut order: Vec<usize> = (0..constraints.len()).collect();
        order.sort_by_key(|&c| (colour_of[c], constraints[c].0.iter().min().copied()));
        let mut colours: Vec<Range<usize>> = Vec::new();
        for (at, &c) in order.iter().enumerate() {
            match colours.last_mut() {
                Some(range) if colour_of[order[range.start]] == colour_of[c] => range.end = at + 1,
                _ => colours.push(at..at + 1),
            }
        }
        Batches {
            particles: order.iter().map(|&c| constraints[c].0).collect(),
            rest: order.iter().map(|&c| constraints[c].1).collect(),
            lambda: vec![0.0; constraints.len()],
            colours,
        }
    }

    /// The number of constraints.
    pub fn len(&self) -> usize {
        self.particles.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.particles.is_empty()
    }

    /// Whether every colour really shares no particle.
    pub fn colouring_is_valid(&self, particle_count: usize) -> bool {
        let mut seen = vec![usize::MAX; particle_count];
        self.colours.iter().enumerate().all(|(k, range)| {
            self.particles[range.clone()].iter().all(|particles| {
                particles.iter().all(|&i| {
                    let fresh = seen[i as usize] != k;
                    seen[i as usize] = k;
                    fresh
                })
            })
        })
    }

    fn heap_bytes(&self) -> usize {
        self.particles.capacity() * size_of::<[u32; N]>()
            + (self.rest.capacity() + self.lambda.capacity()) * size_of::<f32>()
            + self.colours.capacity() * size_of::<Range<usize>>()
    }
}

/// Time spent projecting each family, and how many projections, since the last reset.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timings {
    /// Per family (edges, heights, volume): time spent in its sweeps.
    pub time: [Duration; 3],
    /// Per family: constraints projected.
    pub projections: [u64; 3],
}

/// The soft body, fast. See the module documentation.
pub struct FastSimulation {
    settings: Settings,
    positions: Vec<Vec3A>,
    previous: Vec<Vec3A>,
    velocities: Vec<Vec3A>,
    inverse_masses: Vec<f32>,
    /// The scene's number of each particle, by new number.
    original: Vec<u32>,
    /// Edge distance constraints.
    pub edges: Batches<2>,
    /// Height constraints.
    pub planes: Batches<4>,
    /// Signed volume constraints.
    pub volumes: Batches<4>,
    tets: usize,
    #[cfg(feature = "parallel")]
    pool: Option<rayon::ThreadPool>,
    timings: Timings,
    frame: u64,
}

impl FastSimulation {
    /// The fast solver for the current state of `simulation` (positions, velocities, pins,
    /// settings), on `threads` threads (1 without the `parallel` feature).
    pub fn new(simulation: &Simulation, threads: usize) -> FastSimulation {
        let n = simulation.positions().len();
        let original = morton_order(simulation.positions());
        let mut renumber = vec![0u32; n];
        for (new, &old) in original.iter().enumerate() {
            renumber[old as usize] = new as u32;
        }
        let take = |values: &[DVec3]| -> Vec<Vec3A> {
            original
                .iter()
                .map(|&i| values[i as usize].as_vec3a())
                .collect()
        };
        fn batches<const N: usize>(
            particles: &[[u32; N]],
            rest: &[f64],
            renumber: &[u32],
        ) -> Batches<N> {
            let constraints = particles
                .iter()
                .zip(rest)
                .map(|(p, &r)| (p.map(|i| renumber[i as usize]), r as f32))
                .collect();
            Batches::new(constraints, renumber.len())
        }
        let edges = batches(
            &simulation.edges.particles,
            &simulation.edges.rest,
            &renumber,
        );
        let planes = batches(
            &simulation.planes.particles,
            &simulation.planes.rest,
            &renumber,
        );
        let volumes = batches(
            &simulation.volumes.particles,
            &simulation.volumes.rest,
            &renumber,
        );
        debug_assert!(edges.colouring_is_valid(n) && volumes.colouring_is_valid(n));
        let positions = take(simulation.positions());
        #[cfg(not(feature = "parallel"))]
        let _ = threads;
        FastSimulation {
            settings: *simulation.settings(),
            previous: positions.clone(),
            positions,
            velocities: take(simulation.velocities()),
            inverse_masses: original
                .iter()
                .map(|&i| simulation.inverse_masses()[i as usize] as f32)
                .collect(),
            original,
            edges,
            planes,
            volumes,
            tets: simulation.tets().len(),
            #[cfg(feature = "parallel")]
            pool: (threads > 1)
                .then(|| {
                    rayon::ThreadPoolBuilder::new()
                        .num_threads(threads)
                        .build()
                        .ok()
                })
                .flatten(),
            timings: Timings::default(),
            frame: 0,
        }
    }

    /// The threads the projections run on.
    pub fn threads(&self) -> usize {
        #[cfg(feature = "parallel")]
        if let Some(pool) = &self.pool {
            return pool.current_num_threads();
        }
        1
    }

    /// The settings in force.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Positions in the scene's particle numbering.
    pub fn positions(&self) -> Vec<DVec3> {
        let mut out = vec![DVec3::ZERO; self.positions.len()];
        for (p, &i) in self.positions.iter().zip(&self.original) {
            out[i as usize] = p.as_dvec3();
        }
        out
    }

    /// Whether every coordinate and velocity component is finite and below
    /// [`crate::solver::SOUND_LIMIT`] in size.
    pub fn is_sound(&self) -> bool {
        let limit = crate::solver::SOUND_LIMIT as f32;
        self.positions
            .iter()
            .chain(&self.velocities)
            .all(|v| v.abs().max_element() < limit)
    }

    /// Frames stepped.
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// The tets in the scene.
    pub fn tet_count(&self) -> usize {
        self.tets
    }

    /// Constraint projections one frame makes with the current settings.
    pub fn projections_per_frame(&self) -> u64 {
        self.settings.projections_per_frame(PerFamily {
            edges: self.edges.len(),
            plane: self.planes.len(),
            volume: self.volumes.len(),
        })
    }

    /// The bytes of memory the solver's arrays take.
    pub fn heap_bytes(&self) -> usize {
        (self.positions.capacity() + self.previous.capacity() + self.velocities.capacity())
            * size_of::<Vec3A>()
            + self.inverse_masses.capacity() * size_of::<f32>()
            + self.original.capacity() * size_of::<u32>()
            + self.edges.heap_bytes()
            + self.planes.heap_bytes()
            + self.volumes.heap_bytes()
    }

    /// Time and projections per family since the last [`FastSimulation::reset_timings`].
    pub fn timings(&self) -> Timings {
        self.timings
    }

    /// Starts the timings afresh.
    pub fn reset_timings(&mut self) {
        self.timings = Timings::default();
    }

    /// Advances one frame: `substeps` substeps of predict, sweeps, velocities. With several
    /// threads, the whole frame runs inside the thread pool (entering it once per frame, not once
    /// per colour).
    pub fn step(&mut self) {
        #[cfg(feature = "parallel")]
        if let Some(pool) = self.pool.take() {
            pool.install(|| self.step_on(true));
            self.pool = Some(pool);
            self.frame += 1;
            return;
        }
        self.step_on(false);
        self.frame += 1;
    }

    /// One frame; `parallel`: large colours are shared by the threads of the current pool.
    fn step_on(&mut self, parallel: bool) {
        let settings = self.settings;
        let h = settings.dt / settings.substeps.max(1) as f64;
        for _ in 0..settings.substeps.max(1) {
            integrate::predict(
                &mut self.positions,
                &mut self.previous,
                &mut self.velocities,
                &self.inverse_masses,
                settings.gravity,
                h,
                settings.ground,
            );
            let active = settings.active;
            for (on, lambda) in [
                (active.edges, &mut self.edges.lambda),
                (active.plane, &mut self.planes.lambda),
                (active.volume, &mut self.volumes.lambda),
            ] {
                if on {
                    lambda.fill(0.0);
                }
            }
            for _ in 0..settings.iterations.max(1) {
                self.sweep(h, parallel);
            }
            integrate::update_velocities(
                &self.positions,
                &self.previous,
                &mut self.velocities,
                h,
                settings.damping,
                false,
            );
        }
    }

    fn sweep(&mut self, h: f64, parallel: bool) {
        let active = self.settings.active;
        for (k, family) in Family::ALL.into_iter().enumerate() {
            if !active.get(family) {
                continue;
            }
            let rule = Rule::for_settings(&self.settings, family, h);
            let started = Instant::now();
            let count = match family {
                Family::Distance => project_family::<2, EdgeFormula>(
                    &mut self.edges,
                    &mut self.positions,
                    &self.inverse_masses,
                    rule,
                    parallel,
                ),
                Family::Plane => project_family::<4, PlaneFormula>(
                    &mut self.planes,
                    &mut self.positions,
                    &self.inverse_masses,
                    rule,
                    parallel,
                ),
                Family::Volume => project_family::<4, VolumeFormula>(
                    &mut self.volumes,
                    &mut self.positions,
                    &self.inverse_masses,
                    rule,
                    parallel,
                ),
            };
            self.timings.time[k] += started.elapsed();
            self.timings.projections[k] += count as u64;
        }
        if self.settings.ground {
            integrate::project_ground(&mut self.positions, &self.inverse_masses);
        }
    }
}

/// A constraint family's formula, for any vector type: one f32 constraint or four in lanes.
trait Formula<const N: usize> {
    fn evaluate<V: Vector3>(p: &[V; N], rest: V::Real) -> Evaluation<V, N>;
}

struct EdgeFormula;
struct PlaneFormula;
struct VolumeFormula;

impl Formula<2> for EdgeFormula {
    #[inline(always)]
    fn evaluate<V: Vector3>(p: &[V; 2], rest: V::Real) -> Evaluation<V, 2> {
        distance::evaluate(p, rest)
    }
}

impl Formula<4> for PlaneFormula {
    #[inline(always)]
    fn evaluate<V: Vector3>(p: &[V; 4], rest: V::Real) -> Evaluation<V, 4> {
        plane::evaluate(p, rest)
    }
}

impl Formula<4> for VolumeFormula {
    #[inline(always)]
    fn evaluate<V: Vector3>(p: &[V; 4], rest: V::Real) -> Evaluation<V, 4> {
        volume::evaluate(p, rest)
    }
}

/// Where the kernels read and move particles.
trait Positions {
    fn get(&self, i: u32) -> Vec3A;
    fn add(&mut self, i: u32, delta: Vec3A);
}

impl Positions for &mut [Vec3A] {
    #[inline(always)]
    fn get(&self, i: u32) -> Vec3A {
        self[i as usize]
    }
    #[inline(always)]
    fn add(&mut self, i: u32, delta: Vec3A) {
        self[i as usize] += delta;
    }
}

/// Projects a run of constraints that share no particle: four at a time in SIMD lanes, the last
/// few one by one. Lanes and single constraints compute the same formula and rule.
#[inline]
fn project_run<const N: usize, F: Formula<N>>(
    particles: &[[u32; N]],
    rest: &[f32],
    lambda: &mut [f32],
    positions: &mut impl Positions,
    inverse_masses: &[f32],
    rule: Rule<f64>,
) {
    let in_lanes = particles.len() / LANES * LANES;
    let lane_rule: Rule<F32x4> = rule.to();
    for base in (0..in_lanes).step_by(LANES) {
        let idx: [[u32; N]; LANES] = std::array::from_fn(|k| particles[base + k]);
        let p: [Vec3x4; N] = std::array::from_fn(|i| {
            Vec3x4::gather(std::array::from_fn(|k| positions.get(idx[k][i])))
        });
        let w: [F32x4; N] = std::array::from_fn(|i| {
            F32x4::new(std::array::from_fn(|k| inverse_masses[idx[k][i] as usize]))
        });
        let r = F32x4::new(std::array::from_fn(|k| rest[base + k]));
        let l = F32x4::new(std::array::from_fn(|k| lambda[base + k]));
        let (_, d) = correction_lanes(F::evaluate(&p, r), w, l, lane_rule);
        let delta_lambda = d.delta_lambda.to_array();
        let delta_x = d.delta_x.map(Vec3x4::scatter);
        for (k, particles) in idx.iter().enumerate() {
            lambda[base + k] += delta_lambda[k];
            for (i, &particle) in particles.iter().enumerate() {
                positions.add(particle, delta_x[i][k]);
            }
        }
    }
    let one_rule: Rule<f32> = rule.to();
    for c in in_lanes..particles.len() {
        let idx = particles[c];
        let p = idx.map(|i| positions.get(i));
        let w = idx.map(|i| inverse_masses[i as usize]);
        if let Some(d) = correction(F::evaluate(&p, rest[c]), w, lambda[c], one_rule) {
            lambda[c] += d.delta_lambda;
            for (&i, &delta) in idx.iter().zip(&d.delta_x) {
                positions.add(i, delta);
            }
        }
    }
}

/// Projects every constraint of `batches`, colour by colour; with `parallel`, large colours are
/// shared by the threads of the current pool. Returns how many constraints it projected.
#[inline]
fn project_family<const N: usize, F: Formula<N>>(
    batches: &mut Batches<N>,
    mut positions: &mut [Vec3A],
    inverse_masses: &[f32],
    rule: Rule<f64>,
    parallel: bool,
) -> usize {
    let Batches {
        particles,
        rest,
        lambda,
        colours,
    } = batches;
    for range in colours.iter() {
        let (particles, rest, lambda) = (
            &particles[range.clone()],
            &rest[range.clone()],
            &mut lambda[range.clone()],
        );
        match parallel && range.len() >= PARALLEL_MIN {
            #[cfg(feature = "parallel")]
            true => parallel::project_colour::<N, F>(
                particles,
                rest,
                lambda,
                positions,
                inverse_masses,
                rule,
            ),
            _ => project_run::<N, F>(
                particles,
                rest,
                lambda,
                &mut positions,
                inverse_masses,
                rule,
            ),
        }
    }
    particles.len()
}

/// Several threads projecting one colour. The constraints of a colour share no particle
/// ([`Batches::colouring_is_valid`]), so each particle is read and written by one thread only:
/// the positions are handed to the threads through a raw pointer, which is the one place tetlab
/// uses `unsafe`.
#[cfg(feature = "parallel")]
#[allow(unsafe_code)]
mod parallel {
    use super::*;
    use rayon::prelude::*;

    /// Constraints per task: a multiple of the lane count, so that the quadruples are the same as
    /// on one thread and the result the same bits.
    const CHUNK: usize = 64 * LANES;

    /// Positions written by several threads at once, each at particles no other thread touches.
    /// Made only by `project_colour`, for the constraints of one colour.
    #[derive(Clone, Copy)]
    struct Disjoint {
        ptr: *mut Vec3A,
        len: usize,
    }

    // SAFETY: the threads share the pointer but never an element (see `project_colour`).
    unsafe impl Send for Disjoint {}
    unsafe impl Sync for Disjoint {}

    impl Positions for Disjoint {
        #[inline(always)]
        fn get(&self, i: u32) -> Vec3A {
            let i = i as usize;
            assert!(i < self.len);
            // SAFETY: in bounds (checked); the constraints of one colour share no particle, so no
            // other task of this colour reads or writes particle i, and `positions` is borrowed
            // mutably for the whole of `project_colour`, so nothing else does either.
            unsafe { self.ptr.add(i).read() }
        }

        #[inline(always)]
        fn add(&mut self, i: u32, delta: Vec3A) {
            let i = i as usize;
            assert!(i < self.len);
            // SAFETY: as for `get`.
            unsafe {
                let p = self.ptr.add(i);
                p.write(p.read() + delta);
            }
        }
    }

    pub(super) fn project_colour<const N: usize, F: Formula<N>>(
        particles: &[[u32; N]],
        rest: &[f32],
        lambda: &mut [f32],
        positions: &mut [Vec3A],
        inverse_masses: &[f32],
        rule: Rule<f64>,
    ) {
        let shared = Disjoint {
            ptr: positions.as_mut_ptr(),
            len: positions.len(),
        };
        lambda
            .par_chunks_mut(CHUNK)
            .zip(particles.par_chunks(CHUNK))
            .zip(rest.par_chunks(CHUNK))
            .for_each(|((lambda, particles), rest)| {
                let mut positions = shared;
                project_run::<N, F>(
                    particles,
                    rest,
                    lambda,
                    &mut positions,
                    inverse_masses,
                    rule,
                );
            });
    }
}

/// The particles sorted along a Morton (Z-order) curve through their bounding box: new number →
/// old number. Deterministic; ties keep the old order.
fn morton_order(positions: &[DVec3]) -> Vec<u32> {
    let (lo, hi) = crate::visual::bounds(positions);
    let extent = (hi - lo).max_element().max(f64::MIN_POSITIVE);
    let code = |p: DVec3| -> u64 {
        let cell = ((p - lo) / extent * 1023.0).clamp(DVec3::ZERO, DVec3::splat(1023.0));
        let spread = |v: f64| -> u64 {
            let mut x = v as u64 & 0x3ff;
            x = (x | (x << 16)) & 0x0300_00ff;
            x = (x | (x << 8)) & 0x0300_f00f;
            x = (x | (x << 4)) & 0x030c_30c3;
            (x | (x << 2)) & 0x0924_9249
        };
        spread(cell.x) | (spread(cell.y) << 1) | (spread(cell.z) << 2)
    };
    let mut order: Vec<u32> = (0..positions.len() as u32).collect();
    order.sort_by_key(|&i| code(positions[i as usize]));
    order
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::Metrics;
    use crate::scene::{Builtin, Perturbation, Scene};
    use crate::solver::PerFamily;

    fn cube(resolution: u32, active: PerFamily<bool>) -> Simulation {
        let scene = Scene::builtin(Builtin::Cube, resolution).unwrap();
        Simulation::new(
            &scene,
            Settings {
                active,
                ..Settings::default()
            },
        )
    }

    #[test]
    fn colours_share_no_particle_and_cover_every_constraint_once() {
        let simulation = cube(4, PerFamily::splat(true));
        let fast = FastSimulation::new(&simulation, 1);
        let n = simulation.positions().len();
        assert!(fast.edges.colouring_is_valid(n));
        assert!(fast.planes.colouring_is_valid(n));
        assert!(fast.volumes.colouring_is_valid(n));
        assert_eq!(fast.edges.len(), simulation.edges.len());
        let covered: usize = fast.volumes.colours.iter().map(|r| r.len()).sum();
        assert_eq!(covered, simulation.volumes.len());
        let mut before: Vec<[u32; 4]> = simulation.volumes.particles.clone();
        let mut after: Vec<[u32; 4]> = fast
            .volumes
            .particles
            .iter()
            .map(|p| p.map(|i| fast.original[i as usize]))
            .collect();
        before.sort_unstable();
        after.sort_unstable();
        assert_eq!(before, after, "the same constraints, renumbered");
    }

    #[test]
    fn a_mirrored_cube_recovers_on_the_fast_path_as_on_the_reference() {
        let mut reference = cube(3, PerFamily::splat(true));
        reference.set_settings(Settings {
            settle_edits: false,
            ..*reference.settings()
        });
        reference.perturb(Perturbation::Mirror);
        let mut fast = FastSimulation::new(&reference, 1);
        for _ in 0..60 {
            reference.step();
            fast.step();
        }
        let mut check = reference.clone();
        check.set_positions(&fast.positions());
        assert_eq!(Metrics::measure(&reference).inverted_tets, 0);
        assert_eq!(Metrics::measure(&check).inverted_tets, 0);
    }

    #[test]
    fn edges_alone_leave_a_mirrored_cube_inverted_on_the_fast_path_too() {
        let mut reference = cube(3, PerFamily::parse_list("edges").unwrap());
        reference.perturb(Perturbation::Mirror);
        let mut fast = FastSimulation::new(&reference, 1);
        for _ in 0..60 {
            fast.step();
        }
        let mut check = reference.clone();
        check.set_positions(&fast.positions());
        assert_eq!(
            Metrics::measure(&check).inverted_tets,
            reference.tets().len()
        );
    }

    #[cfg(feature = "parallel")]
    #[test]
    fn two_threads_give_the_same_bits_as_one() {
        let mut reference = cube(16, PerFamily::parse_list("edges,volume").unwrap());
        reference.perturb(Perturbation::Scramble(4));
        let mut one = FastSimulation::new(&reference, 1);
        let mut two = FastSimulation::new(&reference, 2);
        assert_eq!(two.threads(), 2);
        assert!(
            two.volumes.colours.iter().any(|r| r.len() >= PARALLEL_MIN),
            "some colour is large enough to be shared"
        );
        for _ in 0..5 {
            one.step();
            two.step();
        }
        assert_eq!(one.positions(), two.positions());
    }

    #[test]
    fn projections_and_memory_are_counted() {
        let simulation = cube(4, PerFamily::parse_list("edges,volume").unwrap());
        let mut fast = FastSimulation::new(&simulation, 1);
        let per_frame = (simulation.edges.len() + simulation.volumes.len()) as u64 * 10;
        assert_eq!(fast.projections_per_frame(), per_frame);
        fast.step();
        let t = fast.timings();
        assert_eq!(t.projections[0] + t.projections[2], per_frame);
        assert_eq!(t.projections[1], 0);
        let per_tet = fast.heap_bytes() / fast.tet_count();
        assert!((100..300).contains(&per_tet), "{per_tet} bytes per tet");
    }
}
