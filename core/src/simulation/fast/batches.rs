//! The fast solver's constraints, laid out for eight lanes.
//!
//! A [`Layout`] holds the elements constraints bind to, one constraint per element: edges, tets,
//! or the four (tet, vertex) pairs of each tet ([`crate::constraints::Binding::TetVertices`], each with its
//! particles in the constraint's order). Its elements are coloured so that no two of a colour
//! share a particle, and packed [`LANES`] to a batch, each batch stored lane by lane. The
//! particles of batch b are rows b·N..b·N + N of `particles` (row i: particle i of the element in
//! each lane), their inverse masses the same rows of `weights`: a batch is loaded with one vector
//! load per row. Every family bound the same way shares one layout (the built-in volume, the
//! neo-Hookean pair, a constraint file's tet family all share the tets'), and keeps only its own
//! rest values and multipliers ([`Batches`]).
//!
//! The four heights of a tet are four elements, coloured apart (they share their particles), not
//! one element projected four times in a row: projected back to back, they snap each inverted tet
//! to its own rest shape before its neighbours move, and a mirrored cube recovered in a third of
//! the orders (docs/performance.md, "Engines"). For the same reason the colouring visits them
//! role by role ([`Layout::new_visiting`]): visited tet by tet, a tet's four heights took four
//! colours in a row, and the colour order projected them back to back after all.

use crate::numbers::lanes::{F32x8, LANES};
use crate::numbers::vector::Real;
use std::ops::Range;

/// One colour of a layout: the batches `batches`, holding `elements` elements. The lanes after
/// them in the last batch are padding: copies of an element of the batch with zero weights,
/// which move nothing.
#[derive(Clone, Debug, PartialEq)]
pub struct Colour {
    /// The batches of this colour.
    pub batches: Range<usize>,
    /// The elements in them, padding not counted.
    pub elements: usize,
}

/// The edges or the tets of a body, coloured and in batches (see the module).
#[derive(Clone, Debug, Default)]
pub struct Layout {
    arity: usize,
    particles: Vec<[u32; LANES]>,
    weights: Vec<F32x8>,
    /// Per batch, the element (edge or tet number) in each lane.
    elements: Vec<[u32; LANES]>,
    /// Per batch, the size of each lane's element (its longest rest edge), what the reach of
    /// its projections is measured in ([`crate::simulation::Settings::reach`]).
    size: Vec<F32x8>,
    /// Elements of one colour share no particle; colours are projected in order.
    pub colours: Vec<Colour>,
    /// Every particle index above is below this.
    particle_count: usize,
}

/// One family's constraints on a [`Layout`]: each element's rest value and multiplier, a row per
/// batch.
#[derive(Clone, Debug, Default)]
pub struct Batches {
    rest: Vec<F32x8>,
    lambda: Vec<F32x8>,
    /// What each element stores ([`crate::constraints::Constraint::store`]), `stored_len` rows
    /// per batch.
    stored: Vec<F32x8>,
    stored_len: usize,
}

/// The rest values of a family's batches, a row each, and what their elements store,
/// `len` rows per batch: what the kernels read.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RestRows<'a> {
    values: &'a [F32x8],
    stored: &'a [F32x8],
    len: usize,
}

impl<'a> RestRows<'a> {
    /// The rows of batches `range`.
    #[inline]
    pub(crate) fn batches(self, range: std::ops::Range<usize>) -> RestRows<'a> {
        RestRows {
            values: &self.values[range.clone()],
            stored: &self.stored[range.start * self.len..range.end * self.len],
            len: self.len,
        }
    }

    /// Batch `b`'s rest values and what its elements store.
    #[inline(always)]
    pub(crate) fn of(self, b: usize) -> (F32x8, &'a [F32x8]) {
        (
            self.values[b],
            &self.stored[b * self.len..(b + 1) * self.len],
        )
    }
}

/// A layout with its arity N known: what the kernels read.
pub(crate) struct Typed<'a, const N: usize> {
    pub particles: &'a [[[u32; LANES]; N]],
    pub weights: &'a [[F32x8; N]],
    pub size: &'a [F32x8],
    pub colours: &'a [Colour],
    pub particle_count: usize,
}

impl Layout {
    /// Colours `elements` (each its particles, in the new numbering) greedily: each takes the first
    /// colour none of its particles has yet; within a colour they are sorted by first particle,
    /// for locality, and packed into batches. `rest_positions` (the new numbering) give each
    /// element's size.
    pub(crate) fn new<const N: usize>(
        elements: &[[u32; N]],
        inverse_masses: &[f32],
        rest_positions: &[glam::Vec3A],
    ) -> Layout {
        Self::new_visiting(
            elements,
            (0..elements.len()).collect(),
            inverse_masses,
            rest_positions,
        )
    }

    /// [`Layout::new`], the greedy colouring visiting the elements in the order `visit`.
    pub(crate) fn new_visiting<const N: usize>(
        elements: &[[u32; N]],
        visit: Vec<usize>,
        inverse_masses: &[f32],
        rest_positions: &[glam::Vec3A],
    ) -> Layout {
        let mut colour_of = vec![usize::MAX; elements.len()];
        let mut remaining: Vec<usize> = visit;
        let mut base = 0;
        // 64 colours per pass, one bit each per particle; elements that find none wait for the
        // next pass.
        while !remaining.is_empty() {
            let mut used = vec![0u64; inverse_masses.len()];
            let mut waiting = Vec::new();
            for e in remaining {
                let taken = elements[e]
                    .iter()
                    .fold(0u64, |mask, &i| mask | used[i as usize]);
                if taken == u64::MAX {
                    waiting.push(e);
                    continue;
                }
                let colour = taken.trailing_ones() as usize;
                for &i in &elements[e] {
                    used[i as usize] |= 1 << colour;
                }
                colour_of[e] = base + colour;
            }
            remaining = waiting;
            base += 64;
        }
        let mut order: Vec<usize> = (0..elements.len()).collect();
        order.sort_by_key(|&e| (colour_of[e], elements[e].iter().min().copied()));
        let mut layout = Layout {
            arity: N,
            particle_count: inverse_masses.len(),
            ..Layout::default()
        };
        for colour in order.chunk_by(|&a, &b| colour_of[a] == colour_of[b]) {
            let start = layout.elements.len();
            for lanes in colour.chunks(LANES) {
                let element = |k: usize| lanes[k.min(lanes.len() - 1)];
                // Corner i of every lane's element (so not a loop over one element's corners).
                #[allow(clippy::needless_range_loop)]
                for i in 0..N {
                    // Indexing checks the invariant the kernels rely on (see `particles`).
                    let row = std::array::from_fn(|k| elements[element(k)][i]);
                    let weights = std::array::from_fn(|k| {
                        let w = inverse_masses[row[k] as usize];
                        if k < lanes.len() { w } else { 0.0 }
                    });
                    layout.particles.push(row);
                    layout.weights.push(F32x8::new(weights));
                }
                layout
                    .elements
                    .push(std::array::from_fn(|k| element(k) as u32));
                layout.size.push(F32x8::new(std::array::from_fn(|k| {
                    let corners = elements[element(k)].map(|i| rest_positions[i as usize]);
                    crate::scene::mesh::longest_edge(corners.iter().map(|p| p.as_dvec3())) as f32
                })));
            }
            layout.colours.push(Colour {
                batches: start..layout.elements.len(),
                elements: colour.len(),
            });
        }
        layout
    }

    /// The layout with its arity `N` known.
    ///
    /// # Panics
    /// If `N` is not its arity.
    pub(crate) fn typed<const N: usize>(&self) -> Typed<'_, N> {
        assert_eq!(N, self.arity, "a layout of another arity");
        Typed {
            particles: self.particles.as_chunks::<N>().0,
            weights: self.weights.as_chunks::<N>().0,
            size: &self.size,
            colours: &self.colours,
            particle_count: self.particle_count,
        }
    }

    /// How far `threads` threads sharing the large colours (of [`super::PARALLEL_MIN`] elements
    /// or more, each thread a contiguous share of the batches) keep to their own particles, over
    /// one sweep of the colours in `order` (empty: the layout's) after another: of the cache
    /// lines of particles (four 16-byte particles to a 64-byte line) that each share touches,
    /// how many another thread wrote since. Small colours are projected by thread 0. Returns
    /// (lines from another thread, lines), over the second sweep; (0, 0) for one thread.
    ///
    /// A line another core wrote is loaded from that core's cache, which costs tens of
    /// nanoseconds more than one from this core's own (docs/performance.md, "Two threads").
    pub fn lines_from_other_threads(&self, order: &[u32], threads: usize) -> (usize, usize) {
        const NONE: u8 = u8::MAX;
        if threads < 2 {
            return (0, 0);
        }
        let threads = threads.min(super::team::MAX_THREADS);
        let mut last_writer = vec![NONE; self.particle_count.div_ceil(4)];
        let mut touched = Vec::new();
        let (mut other, mut lines) = (0, 0);
        for sweep in 0..2 {
            for k in 0..self.colours.len() {
                let colour = &self.colours[super::kernel::in_order(order, k)];
                let batches = colour.batches.clone();
                let shared = colour.elements >= super::PARALLEL_MIN;
                for thread in 0..if shared { threads } else { 1 } {
                    let share = if shared {
                        super::team::share(batches.len(), thread, threads)
                    } else {
                        0..batches.len()
                    };
                    touched.clear();
                    for b in share.start + batches.start..share.end + batches.start {
                        let rows = &self.particles[b * self.arity..(b + 1) * self.arity];
                        touched.extend(rows.iter().flatten().map(|&i| i as usize / 4));
                    }
                    touched.sort_unstable();
                    touched.dedup();
                    for &line in &touched {
                        let writer = last_writer[line];
                        if sweep == 1 {
                            lines += 1;
                            other += usize::from(writer != NONE && usize::from(writer) != thread);
                        }
                        last_writer[line] = thread as u8;
                    }
                }
            }
        }
        (other, lines)
    }

    /// Writes each particle's inverse mass into every lane that holds it (padding lanes keep
    /// 0): after a pin, a grab or a release. Allocates nothing.
    pub(crate) fn set_weights(&mut self, inverse_masses: &[f32]) {
        let arity = self.arity;
        for colour in &self.colours {
            for (k, b) in colour.batches.clone().enumerate() {
                let real = colour.elements.saturating_sub(k * LANES).min(LANES);
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

    /// How many particles an element has: 2 for an edge, 4 for a tet.
    pub fn arity(&self) -> usize {
        self.arity
    }

    /// The number of batches.
    pub fn batch_count(&self) -> usize {
        self.elements.len()
    }

    /// The elements, colour by colour, padding left out: each element's number and its
    /// particles (the first `arity` of four), with where it is (batch, lane).
    pub fn elements(&self) -> impl Iterator<Item = (u32, [u32; 4], (usize, usize))> + '_ {
        self.colours.iter().flat_map(|colour| {
            colour
                .batches
                .clone()
                .flat_map(|b| (0..LANES).map(move |k| (b, k)))
                .take(colour.elements)
                .map(|(b, k)| {
                    let mut particles = [0; 4];
                    for (i, slot) in particles.iter_mut().enumerate().take(self.arity) {
                        *slot = self.particles[b * self.arity + i][k];
                    }
                    (self.elements[b][k], particles, (b, k))
                })
        })
    }

    /// Whether every colour really shares no particle (padding, which moves nothing, aside).
    pub fn colouring_is_valid(&self, particle_count: usize) -> bool {
        let mut seen = vec![usize::MAX; particle_count];
        let mut colour_at = vec![0; self.elements.len()];
        for (k, colour) in self.colours.iter().enumerate() {
            for b in colour.batches.clone() {
                colour_at[b] = k;
            }
        }
        self.elements().all(|(_, particles, (b, _))| {
            let k = colour_at[b];
            particles[..self.arity].iter().all(|&i| {
                let fresh = seen[i as usize] != k;
                seen[i as usize] = k;
                fresh
            })
        })
    }

    /// The bytes its arrays take (their capacities).
    pub(crate) fn heap_bytes(&self) -> usize {
        (self.particles.capacity() + self.elements.capacity()) * size_of::<[u32; LANES]>()
            + (self.weights.capacity() + self.size.capacity()) * size_of::<F32x8>()
            + self.colours.capacity() * size_of::<Colour>()
    }
}

impl Batches {
    /// A family's batches on `layout`: the constraint of element e has rest value `rest(e)`
    /// and stores `stored(e)` (`stored_len` numbers).
    pub(crate) fn new(
        layout: &Layout,
        rest: impl Fn(u32) -> f32,
        stored_len: usize,
        stored: impl Fn(u32) -> Vec<f32>,
    ) -> Self {
        let mut rows = Vec::with_capacity(layout.elements.len() * stored_len);
        if stored_len > 0 {
            for lanes in &layout.elements {
                let values = lanes.map(&stored);
                rows.extend(
                    (0..stored_len)
                        .map(|k| F32x8::new(std::array::from_fn(|lane| values[lane][k]))),
                );
            }
        }
        Batches {
            rest: layout
                .elements
                .iter()
                .map(|lanes| F32x8::new(lanes.map(&rest)))
                .collect(),
            lambda: vec![F32x8::ZERO; layout.batch_count()],
            stored: rows,
            stored_len,
        }
    }

    /// Whether it holds no constraints (a family that is not active has none, though its
    /// binding's layout may have elements for others).
    pub(crate) fn is_empty(&self) -> bool {
        self.rest.is_empty()
    }

    /// The rest values and stored numbers, and the multipliers, for the kernels.
    pub(crate) fn rows(&mut self) -> (RestRows<'_>, &mut [F32x8]) {
        (
            RestRows {
                values: &self.rest,
                stored: &self.stored,
                len: self.stored_len,
            },
            &mut self.lambda,
        )
    }

    /// What the element at (batch, lane) stores.
    pub(crate) fn stored_at(&self, (batch, lane): (usize, usize)) -> Vec<f32> {
        let rows = &self.stored[batch * self.stored_len..(batch + 1) * self.stored_len];
        rows.iter().map(|row| row.to_array()[lane]).collect()
    }

    /// The rest value of the constraint of the element at (batch, lane).
    pub(crate) fn rest_at(&self, (batch, lane): (usize, usize)) -> f32 {
        self.rest[batch].to_array()[lane]
    }

    /// λ = 0 for every constraint (a new substep).
    pub(crate) fn reset_lambda(&mut self) {
        self.lambda.fill(F32x8::ZERO);
    }

    /// The bytes its arrays take (their capacities).
    pub(crate) fn heap_bytes(&self) -> usize {
        (self.rest.capacity() + self.lambda.capacity() + self.stored.capacity())
            * size_of::<F32x8>()
    }
}
