//! The fast solver: the substep of [`crate::solver`] in f32, on flat arrays laid out for speed, on
//! one thread or several. For big meshes, headless runs and `tetlab bench`; the interactive f64
//! solver stays the reference and the teaching path.
//!
//! What is the same: the constraint formulas (the generic code of [`crate::constraints`]), the
//! projection rule ([`crate::solver`]'s `correction_lanes`), the integration (`integrate`), rest
//! values, masses and pins (taken from a [`Simulation`]).
//!
//! What differs, for speed:
//! - particles are renumbered along a Morton (Z-order) curve, so that particles close in space are
//!   close in memory; [`FastSimulation::positions`] gives them back in the scene's numbering;
//! - each family's constraints are coloured so that no two of one colour share a particle, and
//!   projected colour by colour (Gauss–Seidel across colours). Within a colour the order does not
//!   matter, so several threads can share a colour and the result is the same bits whatever the
//!   thread count;
//! - within a colour, [`LANES`] constraints are projected at once: the formulas run on
//!   [`Vec3x8`], eight x, eight y and eight z in SIMD registers; a batch's particles are loaded
//!   as padded 3-vectors and transposed, its inverse masses, rest values and multipliers are
//!   stored lane by lane beside it;
//! - f32 instead of f64, and no grab or settling (nobody drags a benchmark);
//! - optionally the [`Order::Jacobi`] order, for comparison.

use crate::constraints::{Evaluation, Family, distance, plane, volume};
use crate::divergence::Divergence;
use crate::integrate;
use crate::lanes::{F32x8, LANES, Vec3x8};
use crate::solver::{PerFamily, Rule, Settings, Simulation, correction_lanes};
use crate::vector::{Real, Vector3};
use glam::{DVec3, Vec3A};
use particles::Particles;
use std::ops::Range;
use std::time::{Duration, Instant};

/// The largest coordinate (m) the f32 engine holds: an edge of twice this, raised to the fourth
/// power (the squared gradient of a volume), stays below f32's 3.4·10³⁸. Velocities are held up
/// to [`crate::solver::SOUND_LIMIT`], as in f64 (they are only ever multiplied by a substep).
pub const POSITION_LIMIT: f64 = 1e9;

/// Colours with fewer constraints than this are projected on one thread even when several are
/// available: below it, handing out the work costs more than it saves.
pub const PARALLEL_MIN: usize = 1024;

/// Batches per task when threads share a colour. Which thread projects a batch does not change
/// what it computes, so the result is the same bits for any thread count.
#[cfg(feature = "parallel")]
const CHUNK: usize = 64;

/// One colour of a family: the batches `batches`, holding `constraints` constraints. The lanes
/// after them in the last batch are padding: copies of a constraint of the batch with zero
/// weights, which move nothing.
#[derive(Clone, Debug, PartialEq)]
pub struct Colour {
    /// The batches of this colour.
    pub batches: Range<usize>,
    /// The constraints in them, padding not counted.
    pub constraints: usize,
}

/// One family's constraints, coloured and packed [`LANES`] to a batch, each batch laid out as
/// its lanes: `particles[b][i][k]` is particle `i` of the constraint in lane `k` of batch `b`, and
/// the inverse masses, rest values and multipliers beside it, so that a batch is loaded with one
/// vector load per quantity.
#[derive(Clone, Debug, Default)]
pub struct Batches<const N: usize> {
    particles: Vec<[[u32; LANES]; N]>,
    weights: Vec<[F32x8; N]>,
    rest: Vec<F32x8>,
    lambda: Vec<F32x8>,
    /// Constraints of one colour share no particle; colours are projected in order.
    pub colours: Vec<Colour>,
    /// Every particle index above is below this.
    particle_count: usize,
}

impl<const N: usize> Batches<N> {
    /// Colours constraints given as (particles, rest) in the new particle numbering: greedy, each
    /// constraint takes the first colour none of its particles has yet; within a colour, sorted by
    /// first particle for locality, then packed into batches.
    fn new(constraints: Vec<([u32; N], f32)>, inverse_masses: &[f32]) -> Self {
        let mut colour_of = vec![usize::MAX; constraints.len()];
        let mut remaining: Vec<usize> = (0..constraints.len()).collect();
        let mut base = 0;
        // 64 colours per pass, one bit each per particle; constraints that find none wait for the
        // next pass.
        while !remaining.is_empty() {
            let mut used = vec![0u64; inverse_masses.len()];
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
        let mut batches = Batches {
            particle_count: inverse_masses.len(),
            ..Batches::default()
        };
        for colour in order.chunk_by(|&a, &b| colour_of[a] == colour_of[b]) {
            let start = batches.rest.len();
            for lanes in colour.chunks(LANES) {
                batches.push(std::array::from_fn(|k| {
                    let (particles, rest) = constraints[lanes[k.min(lanes.len() - 1)]];
                    // Indexing checks the invariant the kernels rely on (see `particles`).
                    let weights = particles.map(|i| inverse_masses[i as usize]);
                    let padding = k >= lanes.len();
                    (
                        particles,
                        rest,
                        weights.map(|w| if padding { 0.0 } else { w }),
                    )
                }));
            }
            batches.colours.push(Colour {
                batches: start..batches.rest.len(),
                constraints: colour.len(),
            });
        }
        batches
    }

    /// Appends a batch of (particles, rest, weights), one per lane.
    fn push(&mut self, lanes: [([u32; N], f32, [f32; N]); LANES]) {
        self.particles
            .push(std::array::from_fn(|i| lanes.map(|lane| lane.0[i])));
        self.rest.push(F32x8::new(lanes.map(|lane| lane.1)));
        self.weights.push(std::array::from_fn(|i| {
            F32x8::new(lanes.map(|lane| lane.2[i]))
        }));
        self.lambda.push(F32x8::ZERO);
    }

    /// The number of constraints, padding not counted.
    pub fn len(&self) -> usize {
        self.colours.iter().map(|c| c.constraints).sum()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The particles and rest value of each constraint, colour by colour, padding left out.
    pub fn constraints(&self) -> impl Iterator<Item = ([u32; N], f32)> + '_ {
        self.colours
            .iter()
            .flat_map(|colour| self.constraints_of(colour))
    }

    /// The particles and rest value of each constraint of `colour`, padding left out.
    fn constraints_of<'a>(
        &'a self,
        colour: &'a Colour,
    ) -> impl Iterator<Item = ([u32; N], f32)> + 'a {
        colour
            .batches
            .clone()
            .flat_map(|b| (0..LANES).map(move |k| (b, k)))
            .take(colour.constraints)
            .map(|(b, k)| {
                let particles = self.particles[b].map(|lanes| lanes[k]);
                (particles, self.rest[b].to_array()[k])
            })
    }

    /// How many constraints each particle is in.
    fn constraints_per_particle(&self) -> Vec<u32> {
        let mut count = vec![0; self.particle_count];
        for (particles, _) in self.constraints() {
            for i in particles {
                count[i as usize] += 1;
            }
        }
        count
    }

    /// √(mean of (C / rest value)²) over the constraints at `positions`: how far they are from
    /// holding, relative to their size (a rest value of zero counts as one).
    fn relative_error<F: Formula<N>>(&self, positions: &[Vec3A]) -> f64 {
        let mut sum = 0.0;
        for (particles, rest) in self.constraints() {
            let value = F::evaluate(&particles.map(|i| positions[i as usize]), rest).value;
            let scale = if rest == 0.0 { 1.0 } else { rest.abs() };
            sum += (f64::from(value) / f64::from(scale)).powi(2);
        }
        (sum / self.len().max(1) as f64).sqrt()
    }

    /// Whether every colour really shares no particle (padding, which moves nothing, aside).
    pub fn colouring_is_valid(&self, particle_count: usize) -> bool {
        let mut seen = vec![usize::MAX; particle_count];
        self.colours.iter().enumerate().all(|(k, colour)| {
            self.constraints_of(colour).all(|(particles, _)| {
                particles.iter().all(|&i| {
                    let fresh = seen[i as usize] != k;
                    seen[i as usize] = k;
                    fresh
                })
            })
        })
    }

    fn heap_bytes(&self) -> usize {
        self.particles.capacity() * size_of::<[[u32; LANES]; N]>()
            + self.weights.capacity() * size_of::<[F32x8; N]>()
            + (self.rest.capacity() + self.lambda.capacity()) * size_of::<F32x8>()
            + self.colours.capacity() * size_of::<Colour>()
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
    jacobi: Option<Jacobi>,
    #[cfg(feature = "parallel")]
    pool: Option<rayon::ThreadPool>,
    timings: Timings,
    frame: u64,
}

/// How a sweep applies the corrections of a family's constraints.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Order {
    /// Gauss–Seidel: each colour starts from the positions the colours before it left.
    GaussSeidel,
    /// Jacobi: every constraint of a family is projected from the same positions, and then each
    /// particle moves by `relaxation` × the mean of the corrections it got (ω/nᵢ Σ Δxᵢ).
    Jacobi {
        /// ω: 1 moves by the mean; larger values overrelax.
        relaxation: f32,
    },
}

/// What the Jacobi order needs: the corrections summed per particle, and per family the factor
/// ω/nᵢ each particle's sum is applied with (nᵢ: the family's constraints on particle i).
struct Jacobi {
    relaxation: f32,
    sums: Vec<Vec3A>,
    factors: [Vec<f32>; 3],
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
        let inverse_masses: Vec<f32> = original
            .iter()
            .map(|&i| simulation.inverse_masses()[i as usize] as f32)
            .collect();
        let active = simulation.settings().active;
        // Only the families in use are built: the settings do not change after this.
        fn batches<const N: usize>(
            on: bool,
            particles: &[[u32; N]],
            rest: &[f64],
            renumber: &[u32],
            inverse_masses: &[f32],
        ) -> Batches<N> {
            if !on {
                return Batches::default();
            }
            let constraints = particles
                .iter()
                .zip(rest)
                .map(|(p, &r)| (p.map(|i| renumber[i as usize]), r as f32))
                .collect();
            Batches::new(constraints, inverse_masses)
        }
        let edges = batches(
            active.edges,
            &simulation.edges.particles,
            &simulation.edges.rest,
            &renumber,
            &inverse_masses,
        );
        let planes = batches(
            active.plane,
            &simulation.planes.particles,
            &simulation.planes.rest,
            &renumber,
            &inverse_masses,
        );
        let volumes = batches(
            active.volume,
            &simulation.volumes.particles,
            &simulation.volumes.rest,
            &renumber,
            &inverse_masses,
        );
        debug_assert!(
            edges.colouring_is_valid(n)
                && planes.colouring_is_valid(n)
                && volumes.colouring_is_valid(n)
        );
        let positions = take(simulation.positions());
        #[cfg(not(feature = "parallel"))]
        let _ = threads;
        FastSimulation {
            settings: *simulation.settings(),
            previous: positions.clone(),
            positions,
            velocities: take(simulation.velocities()),
            inverse_masses,
            original,
            edges,
            planes,
            volumes,
            tets: simulation.tets().len(),
            jacobi: None,
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

    /// Projects in `order` from now on (Gauss–Seidel unless set).
    pub fn set_order(&mut self, order: Order) {
        self.jacobi = match order {
            Order::GaussSeidel => None,
            Order::Jacobi { relaxation } => {
                let factors = |count: Vec<u32>| -> Vec<f32> {
                    count
                        .into_iter()
                        .map(|n| if n == 0 { 0.0 } else { relaxation / n as f32 })
                        .collect()
                };
                Some(Jacobi {
                    relaxation,
                    sums: vec![Vec3A::ZERO; self.positions.len()],
                    factors: [
                        factors(self.edges.constraints_per_particle()),
                        factors(self.planes.constraints_per_particle()),
                        factors(self.volumes.constraints_per_particle()),
                    ],
                })
            }
        }
    }

    /// The order the sweeps project in.
    pub fn order(&self) -> Order {
        match &self.jacobi {
            None => Order::GaussSeidel,
            Some(jacobi) => Order::Jacobi {
                relaxation: jacobi.relaxation,
            },
        }
    }

    /// Per active family, how far its constraints are from holding now: √(mean (C / rest)²).
    pub fn relative_error(&self) -> PerFamily<Option<f64>> {
        let active = self.settings.active;
        PerFamily {
            edges: active
                .edges
                .then(|| self.edges.relative_error::<EdgeFormula>(&self.positions)),
            plane: active
                .plane
                .then(|| self.planes.relative_error::<PlaneFormula>(&self.positions)),
            volume: active.volume.then(|| {
                self.volumes
                    .relative_error::<VolumeFormula>(&self.positions)
            }),
        }
    }

    /// The settings in force.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Positions in the scene's particle numbering.
    pub fn positions(&self) -> Vec<DVec3> {
        self.in_scene_order(&self.positions)
    }

    /// Velocities in the scene's particle numbering.
    pub fn velocities(&self) -> Vec<DVec3> {
        self.in_scene_order(&self.velocities)
    }

    fn in_scene_order(&self, values: &[Vec3A]) -> Vec<DVec3> {
        let mut out = vec![DVec3::ZERO; values.len()];
        for (v, &i) in values.iter().zip(&self.original) {
            out[i as usize] = v.as_dvec3();
        }
        out
    }

    /// Ok while every coordinate is finite and below [`POSITION_LIMIT`] in size and every
    /// velocity component below [`crate::solver::SOUND_LIMIT`]; otherwise the first that is not
    /// (particles in the scene's numbering).
    pub fn check(&self) -> Result<(), Divergence> {
        let f64s = |v: &Vec3A| v.as_dvec3().to_array();
        Divergence::find(
            self.frame,
            (POSITION_LIMIT, crate::solver::SOUND_LIMIT),
            self.positions.iter().map(f64s),
            self.velocities.iter().map(f64s),
            |i| self.original[i] as usize,
        )
    }

    /// Whether [`FastSimulation::check`] finds nothing.
    pub fn is_sound(&self) -> bool {
        self.check().is_ok()
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
            + self.jacobi.as_ref().map_or(0, |j| {
                j.sums.capacity() * size_of::<Vec3A>()
                    + j.factors.iter().map(Vec::capacity).sum::<usize>() * size_of::<f32>()
            })
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
                    lambda.fill(F32x8::ZERO);
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
            let positions = &mut self.positions;
            let sums = self.jacobi.as_mut().map(|j| &mut j.sums[..]);
            let count = match family {
                Family::Distance => project_family::<2, EdgeFormula>(
                    &mut self.edges,
                    positions,
                    sums,
                    rule,
                    parallel,
                ),
                Family::Plane => project_family::<4, PlaneFormula>(
                    &mut self.planes,
                    positions,
                    sums,
                    rule,
                    parallel,
                ),
                Family::Volume => project_family::<4, VolumeFormula>(
                    &mut self.volumes,
                    positions,
                    sums,
                    rule,
                    parallel,
                ),
            };
            if let Some(jacobi) = &mut self.jacobi {
                let factors = &jacobi.factors[k];
                for ((p, sum), &factor) in
                    self.positions.iter_mut().zip(&mut jacobi.sums).zip(factors)
                {
                    *p += *sum * factor;
                    *sum = Vec3A::ZERO;
                }
            }
            self.timings.time[k] += started.elapsed();
            self.timings.projections[k] += count as u64;
        }
        if self.settings.ground {
            integrate::project_ground(&mut self.positions, &self.inverse_masses);
        }
    }
}

/// A constraint family's formula, for any vector type: one f32 constraint or eight in lanes.
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

/// The positions the kernels read and move, without a bounds check per access: the one place
/// tetlab uses `unsafe`.
///
/// Sound because of one invariant of this module: every particle index in a [`Batches`] is below
/// its `particle_count` (checked when it is built, and its fields are private), and a
/// [`Particles`] is only made for a family whose `particle_count` is the positions' length
/// (checked in [`Particles::new`]). Threads sharing a colour never write the same particle, nor
/// read one another writes: the constraints of a colour share none
/// ([`Batches::colouring_is_valid`]), and a padding lane repeats a particle of its own batch, which
/// one thread projects. (With the Jacobi order, the threads only read the positions and write
/// the sums.)
#[allow(unsafe_code)]
mod particles {
    use crate::lanes::{padded, unpadded};
    use glam::Vec3A;
    use std::marker::PhantomData;
    use wide::f32x4;

    /// Positions borrowed for the projection of one family.
    #[derive(Clone, Copy)]
    pub(super) struct Particles<'a> {
        ptr: *mut Vec3A,
        len: usize,
        borrow: PhantomData<&'a mut [Vec3A]>,
    }

    // SAFETY: the threads share the pointer but never an element (see the module).
    unsafe impl Send for Particles<'_> {}
    unsafe impl Sync for Particles<'_> {}

    impl<'a> Particles<'a> {
        /// `positions`, for batches built for `particle_count` particles.
        pub(super) fn new(positions: &'a mut [Vec3A], particle_count: usize) -> Self {
            assert_eq!(positions.len(), particle_count, "batches of another body");
            Particles {
                ptr: positions.as_mut_ptr(),
                len: positions.len(),
                borrow: PhantomData,
            }
        }

        /// Particle `i` as four lanes: x, y, z and a fourth the kernels ignore.
        #[inline(always)]
        pub(super) fn get(self, i: u32) -> f32x4 {
            debug_assert!((i as usize) < self.len);
            // SAFETY: i is an index of the batches, below `len` (see the module).
            padded(unsafe { self.ptr.add(i as usize).read() })
        }

        /// Moves particle `i` by the first three lanes of `delta` (its fourth is zero).
        #[inline(always)]
        pub(super) fn add(self, i: u32, delta: f32x4) {
            debug_assert!((i as usize) < self.len);
            // SAFETY: as for `get`; and no other thread reads or writes particle i meanwhile.
            unsafe {
                let p = self.ptr.add(i as usize);
                p.write(p.read() + unpadded(delta));
            }
        }
    }
}

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

/// Projects batches of constraints that share no particle, [`LANES`] constraints at a time (the
/// generic formula and projection rule on [`Vec3x8`]): reads the particles from `read` and adds
/// the corrections to `write` (the same positions for Gauss–Seidel, the sums for Jacobi).
#[inline]
fn project_batches<const N: usize, F: Formula<N>>(
    particles: &[[[u32; LANES]; N]],
    weights: &[[F32x8; N]],
    rest: &[F32x8],
    lambda: &mut [F32x8],
    read: Particles,
    write: Particles,
    rule: Rule<F32x8>,
) {
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
        let (_, d) = correction_lanes(F::evaluate(&p, rest), *weights, *lambda, rule);
        *lambda += d.delta_lambda;
        for (&indices, delta) in indices.iter().zip(d.delta_x) {
            scatter_add(write, indices, delta);
        }
    }
}

/// Projects every constraint of `batches`, colour by colour, and adds the corrections to
/// `positions` (Gauss–Seidel) or, given `sums`, to `sums` (Jacobi: `positions` stay as they are);
/// with `parallel`, large colours are shared by the threads of the current pool. Returns how many
/// constraints it projected.
#[inline]
fn project_family<const N: usize, F: Formula<N>>(
    batches: &mut Batches<N>,
    positions: &mut [Vec3A],
    sums: Option<&mut [Vec3A]>,
    rule: Rule<f64>,
    parallel: bool,
) -> usize {
    let rule: Rule<F32x8> = rule.to();
    let Batches {
        particles,
        weights,
        rest,
        lambda,
        colours,
        particle_count,
    } = batches;
    let read = Particles::new(positions, *particle_count);
    let write = sums.map_or(read, |sums| Particles::new(sums, *particle_count));
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
                        project_batches::<N, F>(
                            particles, weights, rest, lambda, read, write, rule,
                        );
                    })
            }
            _ => project_batches::<N, F>(particles, weights, rest, lambda, read, write, rule),
        }
        count += colour.constraints;
    }
    count
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
        assert_eq!(fast.volumes.len(), simulation.volumes.len());
        let mut before: Vec<[u32; 4]> = simulation.volumes.particles.clone();
        let mut after: Vec<[u32; 4]> = fast
            .volumes
            .constraints()
            .map(|(p, _)| p.map(|i| fast.original[i as usize]))
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
        for order in [Order::GaussSeidel, Order::Jacobi { relaxation: 1.5 }] {
            let mut one = FastSimulation::new(&reference, 1);
            let mut two = FastSimulation::new(&reference, 2);
            one.set_order(order);
            two.set_order(order);
            assert_eq!(two.threads(), 2);
            assert!(
                two.volumes
                    .colours
                    .iter()
                    .any(|c| c.constraints >= PARALLEL_MIN),
                "some colour is large enough to be shared"
            );
            for _ in 0..5 {
                one.step();
                two.step();
            }
            assert_eq!(one.positions(), two.positions(), "{order:?}");
        }
    }

    #[test]
    fn a_mirrored_cube_recovers_in_jacobi_order_too() {
        let mut reference = cube(3, PerFamily::splat(true));
        reference.perturb(Perturbation::Mirror);
        let mut fast = FastSimulation::new(&reference, 1);
        fast.set_order(Order::Jacobi { relaxation: 1.0 });
        assert_eq!(fast.order(), Order::Jacobi { relaxation: 1.0 });
        for _ in 0..60 {
            fast.step();
        }
        let mut check = reference.clone();
        check.set_positions(&fast.positions());
        assert!(fast.is_sound());
        assert_eq!(Metrics::measure(&check).inverted_tets, 0);
    }

    /// Jacobi averages where Gauss–Seidel chains: with the same projections per frame, a body
    /// resting under gravity holds its edges and volumes less tightly.
    #[test]
    fn the_jacobi_order_holds_the_constraints_less_tightly_than_gauss_seidel() {
        let simulation = cube(4, PerFamily::parse_list("edges,volume").unwrap());
        let error = |order| {
            let mut fast = FastSimulation::new(&simulation, 1);
            fast.set_order(order);
            for _ in 0..60 {
                fast.step();
            }
            fast.relative_error()
        };
        let gauss_seidel = error(Order::GaussSeidel);
        let jacobi = error(Order::Jacobi { relaxation: 1.0 });
        assert_eq!(gauss_seidel.plane, None, "heights not active");
        for (gs, j) in [
            (gauss_seidel.edges, jacobi.edges),
            (gauss_seidel.volume, jacobi.volume),
        ] {
            let (gs, j) = (gs.unwrap(), j.unwrap());
            assert!(gs > 0.0 && j > 2.0 * gs, "Gauss–Seidel {gs}, Jacobi {j}");
        }
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
