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
//! # Regions
//!
//! A large body's particles are cut into [`Layout::regions`] regions R (a power of two),
//! contiguous runs of the Morton order, so parts of space. Regions pair up into groups level by
//! level: at level l a group is 2^l regions in a row, and the last level's one group is the whole
//! body. An element belongs to the smallest group that holds all its particles: most to their own
//! region (level 0), those across a cut to the level of that cut. A family is projected level
//! by level, each group through all its colours:
//!
//! ```text
//! level 0:  (region 0, every colour) (region 1, every colour) …   ← groups at once, one thread each
//! level 1:  (regions 0–1, every colour) (regions 2–3, …) …
//! …
//! last:     (the whole body, colour 0) (…, colour 1) …           ← a large colour shared by the threads
//! ```
//!
//! The groups of a level share no particle, so threads project them at once with no barrier
//! between colours, and a thread that projected regions 0–3 at level 0 projects their groups at
//! the levels after: no cache line of particles passes between cores but at the levels where
//! groups are fewer than threads (docs/performance.md, "Two threads"). The order depends on the
//! body alone, never on the number of threads: the bits are the same for any. A body of fewer
//! than 2 × [`PARTICLES_PER_REGION`] particles has one region and one level: colour after colour,
//! as a Gauss–Seidel sweep by colours is.
//!
//! The four heights of a tet are four elements, coloured apart (they share their particles), not
//! one element projected four times in a row: projected back to back, they snap each inverted tet
//! to its own rest shape before its neighbours move, and a mirrored cube recovered in a third of
//! the orders (docs/performance.md, "Engines"). For the same reason the colouring visits them
//! role by role ([`Layout::new_visiting`]): visited tet by tet, a tet's four heights took four
//! colours in a row, and the colour order projected them back to back after all.

use crate::constraints::GROUP;
use crate::numbers::lanes::{F32x8, LANES};
use crate::numbers::vector::Real;
use std::ops::Range;

/// The fewest particles a region has: a body is cut into as many regions as this allows, a power
/// of two up to [`MAX_REGIONS`].
pub(super) const PARTICLES_PER_REGION: usize = 2048;

/// Colours with fewer elements than this are projected on one thread even when several are
/// available: below it, handing out the work costs more than it saves.
pub const PARALLEL_MIN: usize = 256;

/// The most regions a body is cut into.
pub(super) const MAX_REGIONS: usize = 8;

/// Particles a region boundary is a multiple of: four 16-byte particles fill a 64-byte cache line,
/// so that no line holds particles of two regions. (16 for lines of 128 bytes, or 256 elsewhere.)
const REGION_ALIGN: usize = 16;

/// How many regions a body of `particles` particles is cut into (see the module).
pub(super) fn regions_for(particles: usize) -> usize {
    let most = (particles / PARTICLES_PER_REGION).clamp(1, MAX_REGIONS);
    1 << most.ilog2()
}

/// The region of particle `i` of `particles`, among `regions` (see the module): runs of the
/// particle numbers as even as [`REGION_ALIGN`] allows.
#[inline]
fn region_of(i: usize, particles: usize, regions: usize) -> usize {
    let blocks = particles.div_ceil(REGION_ALIGN).max(1);
    (i / REGION_ALIGN) * regions / blocks
}

/// The level and group (see the module) of an element whose particles lie in regions `lo` to
/// `hi`: the level is the highest bit in which the two differ, plus one (0 when they are the
/// same region), and the group the regions' number above it.
pub(super) fn level_and_group(lo: usize, hi: usize) -> (usize, usize) {
    let level = (usize::BITS - (lo ^ hi).leading_zeros()) as usize;
    (level, lo >> level)
}

/// Where group `group` of level `level` is among the groups of a body of `regions` regions:
/// the R regions first, then level 1's R / 2 groups, and so on.
pub(in crate::simulation) fn group_index(regions: usize, level: usize, group: usize) -> usize {
    2 * regions - 2 * (regions >> level) + group
}

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
    /// Elements of one entry share no particle. Entry s·C + c (C = [`Layout::colour_count`]) is
    /// colour c of group s: the R regions (level 0), the R / 2 groups of level 1, …, the one group
    /// of the last level ([`Layout::groups`] per level). An entry may be empty.
    pub colours: Vec<Colour>,
    /// How many regions: R, a power of two (see the module).
    regions: usize,
    /// How many colours each segment has: C.
    colour_count: usize,
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
    /// Each lane's compliance α from its body's own material (NaN: the family's), a row per
    /// batch; empty where no element has one ([`crate::simulation::ConstraintSet::own_compliance`]).
    own: Vec<[f64; LANES]>,
    /// `own` as α / h² in f32, for the substep length `own_h`: what the kernels read.
    own_tilde: Vec<F32x8>,
    own_h: f64,
}

/// The rest values of a family's batches, a row each, and what their elements store,
/// `len` rows per batch: what the kernels read.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RestRows<'a> {
    values: &'a [F32x8],
    stored: &'a [F32x8],
    len: usize,
    /// Each batch's own α̃ per lane (NaN: the family's); empty where none has one.
    own: &'a [F32x8],
}

impl<'a> RestRows<'a> {
    /// The rows of batches `range`.
    #[inline]
    pub(crate) fn batches(self, range: std::ops::Range<usize>) -> RestRows<'a> {
        RestRows {
            values: &self.values[range.clone()],
            stored: &self.stored[range.start * self.len..range.end * self.len],
            len: self.len,
            own: self.own.get(range).unwrap_or_default(),
        }
    }

    /// Whether some element has a compliance of its own.
    #[inline(always)]
    pub(crate) fn has_own(self) -> bool {
        !self.own.is_empty()
    }

    /// Batch `b`'s own α̃ per lane, NaN where a lane takes the family's; `None` where no
    /// element of the family has one.
    #[inline(always)]
    pub(crate) fn own(self, b: usize) -> Option<F32x8> {
        self.own.get(b).copied()
    }

    /// Batch `b`'s rest values and what its elements store.
    #[inline(always)]
    pub(crate) fn of(self, b: usize) -> (F32x8, &'a [F32x8]) {
        (
            self.values[b],
            &self.stored[b * self.len..(b + 1) * self.len],
        )
    }

    /// [`RestRows::of`] batches `b..b + GROUP`.
    #[inline(always)]
    pub(crate) fn group(self, b: usize) -> ([F32x8; GROUP], [&'a [F32x8]; GROUP]) {
        let mut rest = [F32x8::ZERO; GROUP];
        let mut stored: [&[F32x8]; GROUP] = [&[]; GROUP];
        for j in 0..GROUP {
            (rest[j], stored[j]) = self.of(b + j);
        }
        (rest, stored)
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
        let particle_count = inverse_masses.len();
        let regions = regions_for(particle_count);
        let segment_of = |e: usize| {
            let region = |&i: &u32| region_of(i as usize, particle_count, regions);
            let lo = elements[e].iter().map(region).min().unwrap_or(0);
            let hi = elements[e].iter().map(region).max().unwrap_or(0);
            let (level, group) = level_and_group(lo, hi);
            group_index(regions, level, group)
        };
        let segments = 2 * regions - 1;
        let colour_count = colour_of.iter().map(|&c| c + 1).max().unwrap_or(0);
        let key = |e: usize| (segment_of(e), colour_of[e]);
        let mut order: Vec<usize> = (0..elements.len()).collect();
        order.sort_by_key(|&e| (key(e), elements[e].iter().min().copied()));
        let mut layout = Layout {
            arity: N,
            particle_count,
            regions,
            colour_count,
            ..Layout::default()
        };
        let mut rest = &order[..];
        for entry in (0..segments).flat_map(|s| (0..colour_count).map(move |c| (s, c))) {
            let len = rest.iter().take_while(|&&e| key(e) == entry).count();
            let colour;
            (colour, rest) = rest.split_at(len);
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
                // A particle alone is no element whose size a step could grow (see
                // `correct_in_reach`): its steps are never limited.
                layout.size.push(F32x8::new(std::array::from_fn(|k| {
                    let corners = elements[element(k)].map(|i| rest_positions[i as usize]);
                    match N {
                        1 => f32::INFINITY,
                        _ => crate::scene::mesh::longest_edge(corners.iter().map(|p| p.as_dvec3()))
                            as f32,
                    }
                })));
            }
            layout.colours.push(Colour {
                batches: start..layout.elements.len(),
                elements: colour.len(),
            });
        }
        debug_assert!(rest.is_empty(), "every element has its entry");
        layout
    }

    /// How many regions the particles are cut into: R (see the module).
    pub fn regions(&self) -> usize {
        // An empty layout (`Layout::default`) is one region.
        self.regions.max(1)
    }

    /// How many levels of groups: log₂ R + 1 (see the module).
    pub(crate) fn levels(&self) -> usize {
        self.regions().ilog2() as usize + 1
    }

    /// How many groups level `level` has: R / 2^level.
    pub fn groups(&self, level: usize) -> usize {
        self.regions() >> level
    }

    /// How many colours: C, the same in every group (some entries may be empty).
    pub fn colour_count(&self) -> usize {
        self.colour_count
    }

    /// The entry of group `group` projected `k`-th ([`group_index`]), the colours in `order`
    /// (empty: the layout's).
    #[inline]
    pub(crate) fn entry(&self, group: usize, k: usize, order: &[u32]) -> &Colour {
        &self.colours[group * self.colour_count + in_order(order, k)]
    }

    /// The batches of groups `groups` of level `level`, which lie together: a group's entries
    /// are stored one after the other, before the next group's, and a level's groups before the
    /// next level's.
    pub(crate) fn group_batches(&self, level: usize, groups: Range<usize>) -> Range<usize> {
        let c = self.colour_count;
        let first = group_index(self.regions(), level, groups.start);
        let start = self
            .colours
            .get(first * c)
            .map_or(self.elements.len(), |e| e.batches.start);
        if groups.is_empty() || c == 0 {
            return start..start;
        }
        let last = group_index(self.regions(), level, groups.end - 1);
        start..self.colours[last * c + c - 1].batches.end
    }

    /// Its rows as the GPU engine uploads them: each batch's particles and their inverse masses
    /// (rows b·N + i, lane by lane, N its arity) and each batch's sizes (row b).
    #[cfg(feature = "gpu")]
    pub(in crate::simulation) fn rows(&self) -> (&[[u32; LANES]], &[F32x8], &[F32x8]) {
        (&self.particles, &self.weights, &self.size)
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

    /// How far `threads` threads keep to their own particles over one sweep (as
    /// `schedule::sweep` shares it out: level by level, a contiguous run of the level's groups
    /// per thread, then the last level's colours in `order` (empty: the layout's), a large one (of
    /// [`super::PARALLEL_MIN`] elements or more) shared in contiguous parts of its batches and a
    /// small one projected by thread 0), after another: of the cache lines of particles (four
    /// 16-byte particles to a 64-byte line) that each thread touches in each step, how many
    /// another thread wrote since. Returns (lines from another thread, lines), over the second
    /// sweep; (0, 0) for one thread.
    ///
    /// A line another core wrote is loaded from that core's cache, which costs tens of
    /// nanoseconds more than one from this core's own (docs/performance.md, "Two threads").
    pub fn lines_from_other_threads(&self, order: &[u32], threads: usize) -> (usize, usize) {
        use super::team::share;
        const NONE: u8 = u8::MAX;
        if threads < 2 {
            return (0, 0);
        }
        let threads = threads.min(super::team::MAX_THREADS);
        let mut last_writer = vec![NONE; self.particle_count.div_ceil(4)];
        let mut touched = Vec::new();
        let (mut other, mut lines) = (0, 0);
        // Thread `thread` projects `batches` (in the second sweep, `count` says so).
        let mut step = |thread: usize, batches: Range<usize>, count: bool| {
            touched.clear();
            for b in batches {
                let rows = &self.particles[b * self.arity..(b + 1) * self.arity];
                touched.extend(rows.iter().flatten().map(|&i| i as usize / 4));
            }
            touched.sort_unstable();
            touched.dedup();
            for &line in &touched {
                let writer = last_writer[line];
                if count {
                    lines += 1;
                    other += usize::from(writer != NONE && usize::from(writer) != thread);
                }
                last_writer[line] = thread as u8;
            }
        };
        for sweep in 0..2 {
            let count = sweep == 1;
            let last = self.levels() - 1;
            for level in 0..last {
                for thread in 0..threads {
                    let groups = share(self.groups(level), thread, threads);
                    step(thread, self.group_batches(level, groups), count);
                }
            }
            for k in 0..self.colour_count {
                let colour = self.entry(group_index(self.regions(), last, 0), k, order);
                let batches = colour.batches.clone();
                if colour.elements >= PARALLEL_MIN {
                    for thread in 0..threads {
                        let part = share(batches.len(), thread, threads);
                        step(
                            thread,
                            batches.start + part.start..batches.start + part.end,
                            count,
                        );
                    }
                } else {
                    step(0, batches, count);
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
    pub(crate) fn batch_count(&self) -> usize {
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

    /// Whether every colour really shares no particle (padding, which moves nothing, aside), and
    /// every group's elements have their particles in the group's regions only (see the module),
    /// which is what lets threads project a level's groups at once.
    pub fn colouring_is_valid(&self, particle_count: usize) -> bool {
        let mut seen = vec![usize::MAX; particle_count];
        let mut colour_at = vec![0; self.elements.len()];
        for (k, colour) in self.colours.iter().enumerate() {
            for b in colour.batches.clone() {
                colour_at[b] = k;
            }
        }
        // The regions each group holds, by group index.
        let mut regions = vec![0..0; 2 * self.regions() - 1];
        for level in 0..self.levels() {
            for group in 0..self.groups(level) {
                regions[group_index(self.regions(), level, group)] =
                    group << level..(group + 1) << level;
            }
        }
        let c = self.colour_count.max(1);
        self.elements().all(|(_, particles, (b, _))| {
            let k = colour_at[b];
            particles[..self.arity].iter().all(|&i| {
                let fresh = seen[i as usize] != k;
                seen[i as usize] = k;
                let region = region_of(i as usize, self.particle_count, self.regions());
                fresh && regions[k / c].contains(&region)
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
    /// A family's batches on `layout`: the constraint of element e has rest value `rest(e)`,
    /// stores `stored(e)` (`stored_len` numbers) and has the compliance `own[e]` of its own
    /// (NaN: the family's; `own` empty: none has one).
    pub(crate) fn new(
        layout: &Layout,
        rest: impl Fn(u32) -> f32,
        (stored_len, stored): (usize, impl Fn(u32) -> Vec<f32>),
        own: &[f64],
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
            own: if own.is_empty() {
                Vec::new()
            } else {
                (layout.elements.iter())
                    .map(|lanes| lanes.map(|e| own[e as usize]))
                    .collect()
            },
            own_tilde: vec![
                F32x8::from_f64(f64::NAN);
                if own.is_empty() {
                    0
                } else {
                    layout.batch_count()
                }
            ],
            own_h: f64::NAN,
        }
    }

    /// Works out the own α̃ = α / h² for substeps of length `h`, when `h` changed (nothing to
    /// do where no element has an own compliance): rounded to f32 from the f64 quotient, as the
    /// family's α̃ is ([`crate::simulation::projection::Rule::to`]).
    pub(crate) fn set_substep(&mut self, h: f64) {
        if self.own.is_empty() || self.own_h == h {
            return;
        }
        self.own_h = h;
        for (tilde, alpha) in self.own_tilde.iter_mut().zip(&self.own) {
            *tilde = F32x8::new(alpha.map(|a| (a / (h * h)) as f32));
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
                own: &self.own_tilde,
            },
            &mut self.lambda,
        )
    }

    /// Its rows as the GPU engine uploads them: the rest values (a row per batch), what the
    /// elements store (`stored_len` rows per batch), that length, and the own α̃ (a row per
    /// batch, NaN: the family's; empty where none has one).
    #[cfg(feature = "gpu")]
    pub(in crate::simulation) fn uploaded(&self) -> (&[F32x8], &[F32x8], usize, &[F32x8]) {
        (&self.rest, &self.stored, self.stored_len, &self.own_tilde)
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
        (self.rest.capacity()
            + self.lambda.capacity()
            + self.stored.capacity()
            + self.own_tilde.capacity())
            * size_of::<F32x8>()
            + self.own.capacity() * size_of::<[f64; LANES]>()
    }
}

/// The colour projected `k`-th: `order[k]`, or `k` when `order` is empty (the layout's order).
#[inline]
fn in_order(order: &[u32], k: usize) -> usize {
    order.get(k).map_or(k, |&c| c as usize)
}

#[cfg(test)]
mod examples {
    #[allow(unused_imports)]
    use super::*;

    /// The example of `level_and_group`'s documentation (a unit test: the item is not exported).
    #[test]
    fn level_and_group_example() {
        use crate::simulation::fast::batches::level_and_group;
        assert_eq!(level_and_group(5, 5), (0, 5)); // inside region 5
        assert_eq!(level_and_group(4, 5), (1, 2)); // across the cut of regions 4–5
        assert_eq!(level_and_group(1, 2), (2, 0)); // regions 0–3 hold it
    }

    /// The example of `regions_for`'s documentation (a unit test: the item is not exported).
    #[test]
    fn regions_for_example() {
        use crate::simulation::fast::batches::regions_for;
        assert_eq!(regions_for(333), 1); // the bunny: one region, colour after colour
        assert_eq!(regions_for(4096), 2);
        assert_eq!(regions_for(1_000_000), 8);
    }
}
