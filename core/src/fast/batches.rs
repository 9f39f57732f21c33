//! One family's constraints as the fast solver keeps them: coloured so that no two of a colour
//! share a particle, and packed [`LANES`] to a batch, each batch laid out as its lanes. The
//! particles of batch b are rows b·N..b·N + N of `particles` (row i: particle i of the
//! constraint in each lane), its inverse masses rows b·N..b·N + N of `weights`, its rest values
//! and multipliers entry b of `rest` and `lambda`: a batch is loaded with one vector load per
//! quantity. The same shape for every family, whatever its arity N.

use crate::lanes::{F32x8, LANES};
use crate::vector::Real;
use std::ops::Range;

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

/// One family's constraints, coloured and in batches.
#[derive(Clone, Debug, Default)]
pub struct Batches {
    arity: usize,
    particles: Vec<[u32; LANES]>,
    weights: Vec<F32x8>,
    rest: Vec<F32x8>,
    lambda: Vec<F32x8>,
    /// Constraints of one colour share no particle; colours are projected in order.
    pub colours: Vec<Colour>,
    /// Every particle index above is below this.
    particle_count: usize,
}

/// A family's batches with their arity N known: what the kernels read.
pub(crate) struct Typed<'a, const N: usize> {
    pub particles: &'a [[[u32; LANES]; N]],
    pub weights: &'a [[F32x8; N]],
    pub rest: &'a [F32x8],
    pub lambda: &'a mut [F32x8],
    pub colours: &'a [Colour],
    pub particle_count: usize,
}

impl Batches {
    /// Colours constraints given as (particles, rest) in the new particle numbering: greedy, each
    /// constraint takes the first colour none of its particles has yet; within a colour, sorted by
    /// first particle for locality, then packed into batches.
    pub(crate) fn new<const N: usize>(
        constraints: Vec<([u32; N], f32)>,
        inverse_masses: &[f32],
    ) -> Self {
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
            arity: N,
            particle_count: inverse_masses.len(),
            ..Batches::default()
        };
        for colour in order.chunk_by(|&a, &b| colour_of[a] == colour_of[b]) {
            let start = batches.rest.len();
            for lanes in colour.chunks(LANES) {
                batches.push::<N>(std::array::from_fn(|k| {
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
    fn push<const N: usize>(&mut self, lanes: [([u32; N], f32, [f32; N]); LANES]) {
        for i in 0..N {
            self.particles.push(lanes.map(|lane| lane.0[i]));
            self.weights.push(F32x8::new(lanes.map(|lane| lane.2[i])));
        }
        self.rest.push(F32x8::new(lanes.map(|lane| lane.1)));
        self.lambda.push(F32x8::ZERO);
    }

    /// The batches with their arity `N` known.
    ///
    /// # Panics
    /// If `N` is not their arity.
    pub(crate) fn typed<const N: usize>(&mut self) -> Typed<'_, N> {
        assert_eq!(N, self.arity, "batches of another arity");
        Typed {
            particles: self.particles.as_chunks::<N>().0,
            weights: self.weights.as_chunks::<N>().0,
            rest: &self.rest,
            lambda: &mut self.lambda,
            colours: &self.colours,
            particle_count: self.particle_count,
        }
    }

    /// Writes each particle's inverse mass into every lane that holds it (padding lanes keep
    /// 0): after a pin, a grab or a release. Allocates nothing.
    pub(crate) fn set_weights(&mut self, inverse_masses: &[f32]) {
        let arity = self.arity;
        for colour in &self.colours {
            for (k, b) in colour.batches.clone().enumerate() {
                let real = colour.constraints.saturating_sub(k * LANES).min(LANES);
                for i in 0..arity {
                    let row = self.particles[b * arity + i];
                    let mut lanes = [0.0f32; LANES];
                    for (lane, weight) in lanes.iter_mut().enumerate().take(real) {
                        *weight = inverse_masses[row[lane] as usize];
                    }
                    self.weights[b * arity + i] = F32x8::new(lanes);
                }
            }
        }
    }

    /// λ = 0 for every constraint (a new substep).
    pub(crate) fn reset_lambda(&mut self) {
        self.lambda.fill(F32x8::ZERO);
    }

    /// How many particles each constraint touches.
    pub fn arity(&self) -> usize {
        self.arity
    }

    /// The number of constraints, padding not counted.
    pub fn len(&self) -> usize {
        self.colours.iter().map(|c| c.constraints).sum()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The particles (the first `arity` of four) and rest value of each constraint, colour by
    /// colour, padding left out.
    pub fn constraints(&self) -> impl Iterator<Item = ([u32; 4], f32)> + '_ {
        self.colours
            .iter()
            .flat_map(|colour| self.constraints_of(colour))
    }

    /// The particles and rest value of each constraint of `colour`, padding left out.
    fn constraints_of<'a>(
        &'a self,
        colour: &'a Colour,
    ) -> impl Iterator<Item = ([u32; 4], f32)> + 'a {
        colour
            .batches
            .clone()
            .flat_map(|b| (0..LANES).map(move |k| (b, k)))
            .take(colour.constraints)
            .map(|(b, k)| {
                let mut particles = [0; 4];
                for (i, slot) in particles.iter_mut().enumerate().take(self.arity) {
                    *slot = self.particles[b * self.arity + i][k];
                }
                (particles, self.rest[b].to_array()[k])
            })
    }

    /// How many constraints each particle is in.
    pub(crate) fn constraints_per_particle(&self) -> Vec<u32> {
        let mut count = vec![0; self.particle_count];
        for (particles, _) in self.constraints() {
            for &i in &particles[..self.arity] {
                count[i as usize] += 1;
            }
        }
        count
    }

    /// Whether every colour really shares no particle (padding, which moves nothing, aside).
    pub fn colouring_is_valid(&self, particle_count: usize) -> bool {
        let mut seen = vec![usize::MAX; particle_count];
        self.colours.iter().enumerate().all(|(k, colour)| {
            self.constraints_of(colour).all(|(particles, _)| {
                particles[..self.arity].iter().all(|&i| {
                    let fresh = seen[i as usize] != k;
                    seen[i as usize] = k;
                    fresh
                })
            })
        })
    }

    /// The bytes its arrays take (their capacities).
    pub(crate) fn heap_bytes(&self) -> usize {
        self.particles.capacity() * size_of::<[u32; LANES]>()
            + (self.weights.capacity() + self.rest.capacity() + self.lambda.capacity())
                * size_of::<F32x8>()
            + self.colours.capacity() * size_of::<Colour>()
    }
}
