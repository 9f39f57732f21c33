//! The fast solver: the substep of [`crate::simulation`] in f32, on flat arrays laid out for speed, on
//! one thread or several. For big meshes, headless runs and `tetlab bench`; the interactive f64
//! solver stays the reference and the teaching path.
//!
//! What is the same: the constraint formulas (the [`crate::constraints::Constraint`] types of
//! the family table), the projection rule ([`crate::simulation::projection`]), the integration
//! (`integrate`), rest values, masses and pins (taken from a simulation, [`Start`]); grabs and settling edits too
//! ([`FrameInputs`]).
//!
//! What differs, for speed:
//! - particles are renumbered along a Morton (Z-order) curve ([`morton`]), so that particles close
//!   in space are close in memory; [`FastSimulation::positions`] gives them back in the scene's
//!   numbering;
//! - each family's constraints are coloured so that no two of one colour share a particle, and
//!   projected colour by colour (Gauss–Seidel across colours) ([`batches`]). Within a colour the
//!   order does not matter, so several threads can share a colour and the result is the same bits
//!   whatever the thread count. A large body is first cut into regions of space, each projected
//!   through all its colours before the elements across the cuts ([`batches`], "Regions";
//!   `schedule`), so that threads take whole regions and meet at the cuts only;
//! - within a colour, [`crate::numbers::lanes::LANES`] constraints are projected at once ([`kernel`]): the formulas run
//!   on [`crate::numbers::lanes::Vec3x8`], eight x, eight y and eight z in SIMD registers; a batch's
//!   particles are loaded as padded 3-vectors and transposed, its inverse masses, rest values and
//!   multipliers are stored lane by lane beside it; the loads skip their bounds checks
//!   ([`particles`], one of the two `unsafe` modules, with [`team`]);
//! - f32 instead of f64;
//! - optionally the [`Order::Jacobi`] order, for comparison;
//! - regions, large colours and the per-particle passes of a large body shared by a [`Team`] of
//!   threads kept for the simulation's life.

pub mod batches;
mod kernel;
mod morton;
mod particles;
mod schedule;
mod share_timers;
mod team;

pub use batches::{Batches, Colour, Layout, PARALLEL_MIN};
pub use team::Team;

use super::constraint_set::ConstraintSet;
use super::settings::Settings;
use crate::constraints::{Binding, Constraint, Families, Family, PerFamily, Visit, VisitPair};
use crate::input::limits::SOUND_LIMIT;
use crate::simulation::divergence::Divergence;
use crate::simulation::integrate;
use crate::simulation::projection::{Rule, SkipCounts};
use glam::{DVec3, Vec3A};
use std::time::Duration;
use web_time::Instant;

/// The largest coordinate (m) the f32 engine holds: an edge of twice this, raised to the fourth
/// power (the squared gradient of a volume), stays below f32's 3.4·10³⁸. Velocities are held up
/// to [`SOUND_LIMIT`], as in f64 (they are only ever multiplied by a substep).
pub const POSITION_LIMIT: f64 = 1e9;

/// A body whose centre is further than this many times its own size from the origin of the
/// fast engine's coordinates is moved back to it ([`FastSimulation::recentre`]).
const RECENTRE_FROM: f32 = 1.0;

/// Time spent projecting each family, and how many projections, since the last reset.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timings {
    /// Per family: time spent in its sweeps.
    pub time: PerFamily<Duration>,
    /// Per family: constraints projected.
    pub projections: PerFamily<u64>,
}

/// The f32 position of `p` and what its rounding left out, as f32: `p ≈ x + r` to f32's
/// precision squared ([`integrate::Residuals`]).
fn residual(p: DVec3) -> Vec3A {
    (p - p.as_vec3a().as_dvec3()).as_vec3a()
}

/// The soft body, fast. See the module documentation.
pub struct FastSimulation {
    /// The table of families it projects.
    families: Families,
    settings: Settings,
    /// Where the positions are measured from, in the scene's frame: a particle is at
    /// `origin + positions[i]`. It follows a body that travels far (thrown, falling), so that
    /// its f32 coordinates stay about its own size, and their precision its size's
    /// ([`FastSimulation::recentre`]).
    origin: DVec3,
    positions: Vec<Vec3A>,
    previous: Vec<Vec3A>,
    /// What each position's f32 rounding left out: the particle is at `origin + positions[i] +
    /// residuals[i]`, and velocities come from that sum ([`integrate::Residuals`]).
    residuals: Vec<Vec3A>,
    /// [`FastSimulation::residuals`] at the start of the substep.
    previous_residuals: Vec<Vec3A>,
    velocities: Vec<Vec3A>,
    /// The rest positions, for families whose formula reads the rest shape.
    rest_positions: Vec<Vec3A>,
    inverse_masses: Vec<f32>,
    /// The scene's number of each particle, by new number.
    original: Vec<u32>,
    /// The new number of each particle, by the scene's number.
    renumber: Vec<u32>,
    /// The edges, the tets and the (tet, vertex) pairs of the body, coloured and in batches;
    /// every family of a binding shares that binding's (each is empty when no active family
    /// uses it).
    layouts: Layouts,
    /// The rest values and multipliers of each active family (the others are left empty).
    sets: PerFamily<Batches>,
    /// The order each family's colours are projected in: empty for the layout's order,
    /// otherwise a permutation drawn from [`Settings::order_seed`].
    colour_orders: PerFamily<Vec<u32>>,
    tets: usize,
    jacobi: Option<Jacobi>,
    /// The threads large colours are shared with, kept for the simulation's life (none: one).
    team: Option<Team>,
    timings: Timings,
    /// Projections skipped for a counted reason since the last [`FastSimulation::take_skipped`].
    skipped: PerFamily<SkipCounts>,
    frame: u64,
    /// Δp of the last substep and its sum over the frame, when a frame asks for them
    /// ([`FrameInputs`]); the predicted positions they are measured from. Empty until then.
    corrections: Corrections,
    /// The external forces in N by new number ([`crate::simulation::Simulation::set_forces`]); empty: none.
    forces: Vec<Vec3A>,
    /// Whether every particle keeps its z ([`crate::simulation::Simulation::set_plane_strain`]).
    plane_strain: bool,
}

/// What a frame of the fast solver is asked to do beyond the settings: hold a grabbed particle,
/// settle an edit, keep Δp. The reference solver ([`crate::simulation::Simulation`]) passes them when it steps
/// on the fast engine.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameInputs {
    /// A particle held by the user: its number in the scene, where it is held, and the grab's
    /// compliance (0: it follows the target exactly, and its inverse mass must be 0).
    pub grab: Option<(usize, DVec3, f64)>,
    /// Whether an edit settles: corrections may move particles but not speed them up, and Δp is
    /// summed over the frame.
    pub settling: bool,
    /// Whether to keep Δp of the frame's last substep ([`FastSimulation::store`]).
    pub corrections: bool,
}

/// Δp per particle (new numbering), kept on request.
#[derive(Clone, Debug, Default)]
struct Corrections {
    predicted: Vec<Vec3A>,
    last: Vec<Vec3A>,
    frame: Vec<Vec3A>,
}

/// The layouts of the elements families bind to: edges, tets, and (tet, vertex) pairs.
#[derive(Default)]
struct Layouts {
    edges: Layout,
    tets: Layout,
    tet_vertices: Layout,
    triangles: Layout,
    hinges: Layout,
}

impl Layouts {
    /// The layout a family of `binding` uses.
    fn of(&self, binding: Binding) -> &Layout {
        match binding {
            Binding::Edges => &self.edges,
            Binding::Tets => &self.tets,
            Binding::TetVertices => &self.tet_vertices,
            Binding::Triangles => &self.triangles,
            Binding::Hinges => &self.hinges,
        }
    }

    /// Every one, for the families' weights and the memory.
    fn all_mut(&mut self) -> [&mut Layout; 5] {
        [
            &mut self.edges,
            &mut self.tets,
            &mut self.tet_vertices,
            &mut self.triangles,
            &mut self.hinges,
        ]
    }
}

/// One family's constraints as the fast solver holds them: on its layout, one per element.
#[derive(Clone, Copy)]
pub struct FamilyBatches<'a> {
    layout: &'a Layout,
    batches: &'a Batches,
}

impl<'a> FamilyBatches<'a> {
    /// The entries of the family's layout: its colours, segment by segment (the regions, then
    /// the border: [`Layout::colours`]; none for a family that is not active).
    pub fn colours(&self) -> &'a [Colour] {
        if self.batches.is_empty() {
            &[]
        } else {
            &self.layout.colours
        }
    }

    /// How many colours each segment of the layout has (none for a family that is not active):
    /// what [`FastSimulation::colour_order`] permutes ([`Layout::colour_count`]).
    pub fn colour_count(&self) -> usize {
        if self.batches.is_empty() {
            0
        } else {
            self.layout.colour_count()
        }
    }

    /// The layout's regions ([`Layout::regions`]).
    pub fn regions(&self) -> usize {
        self.layout.regions()
    }

    /// The number of constraints, padding not counted.
    pub fn len(&self) -> usize {
        self.colours().iter().map(|c| c.elements).sum::<usize>()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The particles (the first arity of four, in the constraint's order) and rest value of each
    /// constraint, colour by colour, padding left out.
    pub fn constraints(&self) -> impl Iterator<Item = ([u32; 4], f32)> + 'a {
        self.constraints_storing()
            .map(|(particles, rest, _)| (particles, rest))
    }

    /// [`FamilyBatches::constraints`] with what each stores.
    pub fn constraints_storing(&self) -> impl Iterator<Item = ([u32; 4], f32, Vec<f32>)> + 'a {
        let batches = self.batches;
        let elements = (!batches.is_empty()).then(|| self.layout.elements());
        elements
            .into_iter()
            .flatten()
            .map(move |(_, particles, at)| (particles, batches.rest_at(at), batches.stored_at(at)))
    }

    /// Whether every colour of its layout really shares no particle.
    pub fn colouring_is_valid(&self, particle_count: usize) -> bool {
        self.layout.colouring_is_valid(particle_count)
    }

    /// How many of its constraints each particle is in.
    fn constraints_per_particle(&self, particle_count: usize) -> Vec<u32> {
        let mut count = vec![0; particle_count];
        for (particles, _) in self.constraints() {
            for &i in &particles[..self.layout.arity()] {
                count[i as usize] += 1;
            }
        }
        count
    }
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
    factors: PerFamily<Vec<f32>>,
}

/// What a fast solver starts from: a simulation's state and constraints, in the scene's
/// numbering ([`crate::simulation::Simulation::fast_start`]).
#[derive(Clone, Copy)]
pub struct Start<'a> {
    /// The settings it runs with; the active families and the material are fixed for its life.
    pub settings: &'a Settings,
    /// Positions, velocities and inverse masses (0 where pinned or rigidly grabbed).
    pub positions: &'a [DVec3],
    /// See [`Start::positions`].
    pub velocities: &'a [DVec3],
    /// See [`Start::positions`].
    pub inverse_masses: &'a [f64],
    /// The rest positions, which the batches' weights and rest values come from.
    pub rest_positions: &'a [DVec3],
    /// External forces in N per particle; empty: none.
    pub forces: &'a [DVec3],
    /// The mesh's tets.
    pub tets: &'a [[u32; 4]],
    /// The table of families the constraints are of.
    pub families: &'a Families,
    /// The constraints of each family, as the binding makes them (with their rest values).
    pub constraints: &'a PerFamily<ConstraintSet>,
    /// Whether every particle keeps its z.
    pub plane_strain: bool,
}

impl FastSimulation {
    /// The fast solver for a simulation's state and constraints (`start`, in the scene's
    /// numbering: [`crate::simulation::Simulation::fast_start`]), on `threads` threads (1 without
    /// the `parallel` feature).
    pub fn new(start: Start<'_>, threads: usize) -> FastSimulation {
        let simulation = start;
        let n = simulation.positions.len();
        let original = morton::morton_order(simulation.positions);
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
        let residuals: Vec<Vec3A> = original
            .iter()
            .map(|&i| residual(simulation.positions[i as usize]))
            .collect();
        let inverse_masses: Vec<f32> = original
            .iter()
            .map(|&i| simulation.inverse_masses[i as usize] as f32)
            .collect();
        let rest_positions = take(simulation.rest_positions);
        let forces = if simulation.forces.is_empty() {
            Vec::new()
        } else {
            take(simulation.forces)
        };
        // Only the families in use are built: the settings do not change after this.
        let active = simulation.settings.active;
        let uses = |binding: &dyn Fn(Binding) -> bool| {
            active
                .families()
                .any(|f| binding(simulation.families.binding(f)))
        };
        let mut layouts = Layouts::default();
        if uses(&|b| b == Binding::Edges) {
            // In the order of the edge binding ([`Binding::particles`]), whose rest values they
            // are: the built-in edge family's, always built.
            let (pairs, _) = simulation.constraints[Family::EDGES]
                .all_particles()
                .as_chunks::<2>();
            let edges: Vec<[u32; 2]> = pairs
                .iter()
                .map(|edge| edge.map(|i| renumber[i as usize]))
                .collect();
            layouts.edges = Layout::new(&edges, &inverse_masses, &rest_positions);
        }
        let renumbered = |tets: &[[u32; 4]]| -> Vec<[u32; 4]> {
            tets.iter()
                .map(|tet| tet.map(|i| renumber[i as usize]))
                .collect()
        };
        if uses(&|b| b == Binding::Tets) {
            let tets = renumbered(simulation.tets);
            layouts.tets = Layout::new(&tets, &inverse_masses, &rest_positions);
        }
        if uses(&|b| b == Binding::TetVertices) {
            // Each (tet, vertex) constraint is an element of its own, its particles in the
            // constraint's order ([`Binding::particles`]), coloured apart from its tet's others.
            let mesh = crate::scene::mesh::TetMesh {
                positions: Vec::new(),
                tets: simulation.tets.to_vec(),
            };
            let flat = Binding::TetVertices.particles(&mesh);
            let (constraints, _) = flat.as_chunks::<4>();
            let constraints = renumbered(constraints);
            // Role by role: every tet's first height, then every tet's second, …, so that a
            // tet's four heights take colours far apart (see `batches`).
            let n = constraints.len();
            let visit: Vec<usize> = (0..4).flat_map(|k| (k..n).step_by(4)).collect();
            layouts.tet_vertices =
                Layout::new_visiting(&constraints, visit, &inverse_masses, &rest_positions);
        }
        // The surface's triangles and hinges, in the order of their binding, as the sets of the
        // active families that bind to them hold them (whose rest values they are).
        let of_binding = |binding: Binding| {
            active
                .families()
                .find(|&f| simulation.families.binding(f) == binding)
                .map(|f| simulation.constraints[f].all_particles())
        };
        if let Some(flat) = of_binding(Binding::Triangles) {
            let (triangles, _) = flat.as_chunks::<3>();
            let triangles: Vec<[u32; 3]> = triangles
                .iter()
                .map(|t| t.map(|i| renumber[i as usize]))
                .collect();
            layouts.triangles = Layout::new(&triangles, &inverse_masses, &rest_positions);
        }
        if let Some(flat) = of_binding(Binding::Hinges) {
            let (hinges, _) = flat.as_chunks::<4>();
            layouts.hinges = Layout::new(&renumbered(hinges), &inverse_masses, &rest_positions);
        }
        let sets = simulation.families.per_family(|family| {
            if !active[family] {
                return Batches::default();
            }
            let set = &simulation.constraints[family];
            let rest = set.rest();
            Batches::new(
                layouts.of(simulation.families.binding(family)),
                |element| rest[element as usize] as f32,
                set.stored_len(),
                |element| {
                    set.stored(element as usize)
                        .iter()
                        .map(|&x| x as f32)
                        .collect()
                },
            )
        });
        debug_assert!(
            layouts.edges.colouring_is_valid(n)
                && layouts.tets.colouring_is_valid(n)
                && layouts.tet_vertices.colouring_is_valid(n)
        );
        let positions = take(simulation.positions);
        // Without the feature (the page), one thread.
        #[cfg(not(feature = "parallel"))]
        let threads = threads.min(1);
        let colour_orders = colour_orders(simulation.families, simulation.settings, &layouts);
        FastSimulation {
            families: simulation.families.clone(),
            colour_orders,
            origin: DVec3::ZERO,
            settings: *simulation.settings,
            previous: positions.clone(),
            positions,
            previous_residuals: residuals.clone(),
            residuals,
            velocities: take(simulation.velocities),
            rest_positions,
            inverse_masses,
            original,
            renumber,
            layouts,
            sets,
            tets: simulation.tets.len(),
            jacobi: None,
            team: (threads > 1).then(|| Team::new(threads)),
            timings: Timings::default(),
            skipped: PerFamily::default(),
            frame: 0,
            corrections: Corrections::default(),
            forces,
            plane_strain: simulation.plane_strain,
        }
    }

    /// The scene's number of each particle, in the fast engine's (Morton) order.
    pub fn original(&self) -> &[u32] {
        &self.original
    }

    /// Takes up a state given in the scene's numbering: positions, velocities and inverse
    /// masses (pins and a rigid grab give 0). Allocates nothing; the inverse masses are written
    /// into every batch lane that holds the particle.
    ///
    /// # Panics
    /// If the slices are not one per particle.
    pub fn load(&mut self, positions: &[DVec3], velocities: &[DVec3], inverse_masses: &[f64]) {
        self.origin = DVec3::ZERO;
        for (new, &old) in self.original.iter().enumerate() {
            let old = old as usize;
            self.positions[new] = positions[old].as_vec3a();
            self.residuals[new] = residual(positions[old]);
            self.velocities[new] = velocities[old].as_vec3a();
            self.inverse_masses[new] = inverse_masses[old] as f32;
        }
        self.previous.copy_from_slice(&self.positions);
        self.previous_residuals.copy_from_slice(&self.residuals);
        for layout in self.layouts.all_mut() {
            layout.set_weights(&self.inverse_masses);
        }
    }

    /// Writes the state back in the scene's numbering: positions and velocities, and with
    /// `corrections`, Δp of the last substep and its sum over the frame (zero where the frame
    /// did not keep them, [`FrameInputs`]). Allocates nothing.
    ///
    /// # Panics
    /// If the slices are not one per particle.
    pub fn store(
        &self,
        positions: &mut [DVec3],
        velocities: &mut [DVec3],
        corrections: Option<(&mut [DVec3], &mut [DVec3])>,
    ) {
        for (new, &old) in self.original.iter().enumerate() {
            positions[old as usize] =
                self.origin + self.positions[new].as_dvec3() + self.residuals[new].as_dvec3();
            velocities[old as usize] = self.velocities[new].as_dvec3();
        }
        if let Some((last, frame)) = corrections {
            let kept = &self.corrections;
            for (new, &old) in self.original.iter().enumerate() {
                let at = |values: &[Vec3A]| values.get(new).map_or(DVec3::ZERO, |v| v.as_dvec3());
                last[old as usize] = at(&kept.last);
                frame[old as usize] = at(&kept.frame);
            }
        }
    }

    /// Replaces the settings; the active families and the material must stay as they were (a
    /// change of either needs a new [`FastSimulation`], whose constraints are built for them).
    pub fn set_settings(&mut self, settings: Settings) {
        debug_assert!(settings.active == self.settings.active);
        if settings.order_seed != self.settings.order_seed {
            self.colour_orders = colour_orders(&self.families, &settings, &self.layouts);
        }
        self.settings = settings;
    }

    /// The order `family`'s colours are projected in, in each segment of its layout: colour
    /// numbers, below [`FamilyBatches::colour_count`].
    pub fn colour_order(&self, family: Family) -> Vec<usize> {
        let colours = self.batches(family).colour_count();
        let order = &self.colour_orders[family];
        (0..colours)
            .map(|k| order.get(k).map_or(k, |&c| c as usize))
            .collect()
    }

    /// The threads the projections run on.
    pub fn threads(&self) -> usize {
        self.team.as_ref().map_or(1, Team::threads)
    }

    /// The constraints of `family`, coloured and in batches (empty when it is not active).
    pub fn batches(&self, family: Family) -> FamilyBatches<'_> {
        FamilyBatches {
            layout: self.layouts.of(self.families.binding(family)),
            batches: &self.sets[family],
        }
    }

    /// How far `threads` threads would keep to their own particles on `family`'s colours:
    /// (lines from another thread, lines) over one sweep ([`Layout::lines_from_other_threads`]).
    pub fn lines_from_other_threads(&self, family: Family, threads: usize) -> (usize, usize) {
        self.layouts
            .of(self.families.binding(family))
            .lines_from_other_threads(&self.colour_orders[family], threads)
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
                    factors: self.families.per_family(|family| {
                        let n = self.positions.len();
                        factors(self.batches(family).constraints_per_particle(n))
                    }),
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

    /// Per active family, how far its constraints are from holding now: √(mean (C / rest)²) (a
    /// rest value of zero counts as one).
    pub fn relative_error(&self) -> PerFamily<Option<f64>> {
        struct RelativeError<'a> {
            batches: FamilyBatches<'a>,
            positions: &'a [Vec3A],
            rest_positions: &'a [Vec3A],
        }
        impl Visit for RelativeError<'_> {
            type Output = f64;
            fn visit<const N: usize, C: Constraint<N>>(self, _: Family, c: &C) -> f64 {
                let mut sum = 0.0;
                for (particles, rest, stored) in self.batches.constraints_storing() {
                    let at = |positions: &[Vec3A]| -> [Vec3A; N] {
                        std::array::from_fn(|k| positions[particles[k] as usize])
                    };
                    let value = c
                        .evaluate_stored(
                            &at(self.positions),
                            rest,
                            &at(self.rest_positions),
                            &stored,
                        )
                        .value;
                    let scale = if rest == 0.0 { 1.0 } else { rest.abs() };
                    sum += (f64::from(value) / f64::from(scale)).powi(2);
                }
                (sum / self.batches.len().max(1) as f64).sqrt()
            }
        }
        let active = self.settings.active;
        self.families.per_family(|family| {
            active[family].then(|| {
                self.families.visit(
                    family,
                    RelativeError {
                        batches: self.batches(family),
                        positions: &self.positions,
                        rest_positions: &self.rest_positions,
                    },
                )
            })
        })
    }

    /// The settings in force.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Positions in the scene's particle numbering.
    pub fn positions(&self) -> Vec<DVec3> {
        let mut positions = self.in_scene_order(&self.positions);
        for (new, &old) in self.original.iter().enumerate() {
            positions[old as usize] += self.origin + self.residuals[new].as_dvec3();
        }
        positions
    }

    /// Moves the origin of the f32 coordinates to the body when the body has travelled from it
    /// by more than its own size ([`RECENTRE_FROM`]), axis by axis: a body thrown 1 km up keeps
    /// coordinates of its own size, and their 2⁻²⁴ relative precision. (Unmoved, a bunny 2 km
    /// up computed its sliver tets' volumes from coordinates of 2000 m, each good to 10⁻⁴ m,
    /// and ended with tets squashed to 44 % and inverted that the f64 engine kept whole.)
    ///
    /// The shift is a multiple of 2⁻¹⁰ of the body's size, so that the origin is one too: the
    /// ground, at y = −origin.y in these coordinates, stays exact in f32 up to 2¹⁴ body sizes
    /// away. A body within its own size of the origin (every body at rest near the scene's
    /// origin) is never moved, and its bits never change.
    fn recentre(&mut self) {
        let (low, high) = self.positions.iter().fold(
            (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY)),
            |(low, high), p| (low.min(*p), high.max(*p)),
        );
        let size = (high - low).max_element();
        if !(size.is_finite() && size > 0.0) {
            return;
        }
        let centre = (low + high) * 0.5;
        let grid = 2f32.powi(size.log2().floor() as i32 - 10);
        let shift = Vec3A::select(
            centre.abs().cmpgt(Vec3A::splat(RECENTRE_FROM * size)),
            (centre / grid).round() * grid,
            Vec3A::ZERO,
        );
        if shift == Vec3A::ZERO {
            return;
        }
        for p in self.positions.iter_mut().chain(&mut self.previous) {
            *p -= shift;
        }
        self.origin += shift.as_dvec3();
    }

    /// Where the ground (y = 0) is in the f32 coordinates.
    fn ground(&self) -> Option<f64> {
        self.settings.ground.then_some(-self.origin.y)
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

    /// Ok while every f32 coordinate (measured from the engine's origin, which follows the
    /// body) is finite and below [`POSITION_LIMIT`] in size, every position below
    /// [`SOUND_LIMIT`], and every velocity component below that too; otherwise
    /// the first that is not (particles in the scene's numbering).
    pub fn check(&self) -> Result<(), Divergence> {
        let f64s = |v: &Vec3A| v.as_dvec3().to_array();
        let original = |i: usize| self.original[i] as usize;
        Divergence::find(
            self.frame,
            (POSITION_LIMIT, SOUND_LIMIT),
            self.positions.iter().map(f64s),
            self.velocities.iter().map(f64s),
            original,
        )?;
        let global = |v: &Vec3A| (self.origin + v.as_dvec3()).to_array();
        Divergence::find(
            self.frame,
            (SOUND_LIMIT, SOUND_LIMIT),
            self.positions.iter().map(global),
            std::iter::empty(),
            original,
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
        self.settings
            .projections_per_frame(self.families.per_family(|f| self.batches(f).len()))
    }

    /// The bytes of memory the solver's arrays take.
    pub fn heap_bytes(&self) -> usize {
        (self.positions.capacity()
            + self.previous.capacity()
            + self.residuals.capacity()
            + self.previous_residuals.capacity()
            + self.velocities.capacity()
            + self.rest_positions.capacity())
            * size_of::<Vec3A>()
            + self.inverse_masses.capacity() * size_of::<f32>()
            + (self.original.capacity() + self.renumber.capacity()) * size_of::<u32>()
            + self.layouts.edges.heap_bytes()
            + self.layouts.tets.heap_bytes()
            + self.layouts.tet_vertices.heap_bytes()
            + self
                .sets
                .every_place()
                .map(Batches::heap_bytes)
                .sum::<usize>()
            + (self.corrections.predicted.capacity()
                + self.corrections.last.capacity()
                + self.corrections.frame.capacity())
                * size_of::<Vec3A>()
            + self.jacobi.as_ref().map_or(0, |j| {
                j.sums.capacity() * size_of::<Vec3A>()
                    + j.factors.every_place().map(Vec::capacity).sum::<usize>() * size_of::<f32>()
            })
    }

    /// Time and projections per family since the last [`FastSimulation::reset_timings`].
    pub fn timings(&self) -> Timings {
        self.timings
    }

    /// The projections skipped for a counted reason (∇C undefined, or a step beyond
    /// [`crate::simulation::projection::DEFAULT_REACH`]) since the last call, per family; the count starts again.
    pub fn take_skipped(&mut self) -> PerFamily<SkipCounts> {
        std::mem::take(&mut self.skipped)
    }

    /// Starts the timings afresh.
    pub fn reset_timings(&mut self) {
        self.timings = Timings::default();
        share_timers::reset();
    }

    /// With the feature `share-timers`, the mean time of a colour large enough to share and of
    /// each thread's share of one, since [`FastSimulation::reset_timings`] (process-wide: one
    /// simulation at a time); `None` without it.
    pub fn share_timings(&self) -> Option<String> {
        share_timers::report()
    }

    /// Advances one frame: `substeps` substeps of predict, sweeps, velocities. With several
    /// threads, large colours are shared with the simulation's [`Team`], whose threads wait for
    /// the next colour spinning, not asleep, while a frame is under way.
    pub fn step(&mut self) {
        self.step_frame(&FrameInputs::default());
    }

    /// [`FastSimulation::step`], holding a grabbed particle, settling an edit or keeping Δp as
    /// `inputs` ask. Allocates nothing once Δp has been kept once.
    pub fn step_frame(&mut self, inputs: &FrameInputs) {
        let team = self.team.take();
        self.step_on(team.as_ref(), inputs);
        self.team = team;
        self.frame += 1;
    }

    /// One frame; large colours are shared with `team`'s threads, when there is one.
    fn step_on(&mut self, team: Option<&Team>, inputs: &FrameInputs) {
        self.recentre();
        let settings = self.settings;
        let h = settings.dt / settings.substeps.max(1) as f64;
        let substeps = settings.substeps.max(1);
        let ground = self.ground();
        let grab = inputs.grab.map(|(particle, target, compliance)| {
            (
                self.renumber[particle] as usize,
                (target - self.origin).as_vec3a(),
                compliance,
            )
        });
        let keep = inputs.settling || inputs.corrections;
        if keep && self.corrections.predicted.len() != self.positions.len() {
            let n = self.positions.len();
            self.corrections = Corrections {
                predicted: vec![Vec3A::ZERO; n],
                last: vec![Vec3A::ZERO; n],
                frame: vec![Vec3A::ZERO; n],
            };
        }
        if keep {
            self.corrections.frame.fill(Vec3A::ZERO);
        }
        let motion = integrate::Substep {
            gravity: settings.gravity,
            h,
            ground,
            plane_strain: self.plane_strain,
        };
        for substep in 0..substeps {
            let (arrays, inverse_masses, forces) = self.particle_arrays();
            schedule::by_particles(
                team,
                arrays,
                |range, [positions, previous, velocities, now, before]| {
                    let forces = forces.get(range.clone()).unwrap_or_default();
                    integrate::predict(
                        positions,
                        previous,
                        velocities,
                        &inverse_masses[range],
                        forces,
                        motion,
                        Some(integrate::Residuals {
                            now,
                            previous: before,
                        }),
                    );
                },
            );
            if let Some((i, target, compliance)) = grab
                && compliance <= 0.0
            {
                self.positions[i] = target;
                self.residuals[i] = Vec3A::ZERO;
            }
            let track = inputs.settling || (inputs.corrections && substep + 1 == substeps);
            if track {
                self.corrections.predicted.copy_from_slice(&self.positions);
            }
            for family in settings.active.families() {
                self.sets[family].reset_lambda();
            }
            let mut grab_lambda = 0.0;
            for _ in 0..settings.iterations.max(1) {
                self.sweep(h, team, grab, &mut grab_lambda);
            }
            if track {
                let c = &mut self.corrections;
                for (((last, sum), p), predicted) in c
                    .last
                    .iter_mut()
                    .zip(&mut c.frame)
                    .zip(&self.positions)
                    .zip(&c.predicted)
                {
                    *last = *p - *predicted;
                    *sum += *last;
                }
            }
            schedule::by_particles(
                team,
                self.particle_arrays().0,
                |_, [positions, previous, velocities, now, before]| {
                    integrate::update_velocities(
                        positions,
                        previous,
                        velocities,
                        h,
                        settings.damping,
                        inputs.settling,
                        Some(&integrate::Residuals {
                            now,
                            previous: before,
                        }),
                    );
                },
            );
        }
    }

    /// What the per-particle passes write (positions, their values at the start of the substep,
    /// velocities, residuals and theirs at the start of the substep) and read (inverse masses,
    /// forces).
    #[allow(clippy::type_complexity)]
    fn particle_arrays(&mut self) -> ([&mut [Vec3A]; 5], &[f32], &[Vec3A]) {
        (
            [
                &mut self.positions,
                &mut self.previous,
                &mut self.velocities,
                &mut self.residuals,
                &mut self.previous_residuals,
            ],
            &self.inverse_masses,
            &self.forces,
        )
    }

    /// In Jacobi order, moves each particle by its share of the corrections `family`'s
    /// projections summed, and clears the sums.
    fn apply_jacobi(&mut self, family: Family) {
        if let Some(jacobi) = &mut self.jacobi {
            let factors = &jacobi.factors[family];
            for ((p, sum), &factor) in self.positions.iter_mut().zip(&mut jacobi.sums).zip(factors)
            {
                *p += *sum * factor;
                *sum = Vec3A::ZERO;
            }
        }
    }

    /// One sweep over the active families, then the grab (when it is compliant: a rigid one
    /// holds its particle at the target with inverse mass 0), then the ground.
    fn sweep(
        &mut self,
        h: f64,
        team: Option<&Team>,
        grab: Option<(usize, Vec3A, f64)>,
        grab_lambda: &mut f32,
    ) {
        let active = self.settings.active;
        for family in active.families() {
            if self.families.projected_by_partner(family, &active) {
                continue;
            }
            let rule = Rule::for_settings(&self.settings, family, h);
            let started = Instant::now();
            let sums = self.jacobi.as_mut().map(|j| &mut j.sums[..]);
            if let Some(partner) = self.families.partner_in(family, &active) {
                struct ProjectPair<'a> {
                    layout: &'a Layout,
                    order: &'a [u32],
                    batches: (&'a mut Batches, &'a mut Batches),
                    positions: (&'a mut [Vec3A], &'a mut [Vec3A]),
                    rest_positions: &'a mut [Vec3A],
                    sums: Option<&'a mut [Vec3A]>,
                    rules: [Rule<f64>; 2],
                    reach: f64,
                    team: Option<&'a Team>,
                }
                impl VisitPair for ProjectPair<'_> {
                    type Output = (usize, [SkipCounts; 2]);
                    #[inline]
                    fn visit_pair<
                        const N: usize,
                        A: Constraint<N>,
                        const M: usize,
                        B: Constraint<M>,
                    >(
                        self,
                        first: &A,
                        second: &B,
                    ) -> (usize, [SkipCounts; 2]) {
                        kernel::project_pair::<N, A, M, B>(
                            (first, second),
                            self.layout,
                            self.order,
                            self.batches,
                            self.positions,
                            self.rest_positions,
                            self.sums,
                            (self.rules, self.reach),
                            self.team,
                        )
                    }
                }
                let rules = [rule, Rule::for_settings(&self.settings, partner, h)];
                let (count, skipped) = self.families.visit_pair(
                    family,
                    partner,
                    ProjectPair {
                        layout: self.layouts.of(self.families.binding(family)),
                        order: &self.colour_orders[family],
                        batches: self.sets.pair_mut(family, partner),
                        positions: (&mut self.positions, &mut self.residuals),
                        rest_positions: &mut self.rest_positions,
                        sums,
                        rules,
                        reach: self.settings.reach,
                        team,
                    },
                );
                self.apply_jacobi(family);
                // One pair projection is a projection of each: each family gets half the time.
                let half = started.elapsed() / 2;
                for (f, skipped) in [family, partner].into_iter().zip(skipped) {
                    self.timings.time[f] += half;
                    self.timings.projections[f] += count as u64;
                    self.skipped[f] = self.skipped[f] + skipped;
                }
                continue;
            }
            struct Project<'a> {
                layout: &'a Layout,
                order: &'a [u32],
                batches: &'a mut Batches,
                positions: (&'a mut [Vec3A], &'a mut [Vec3A]),
                rest_positions: &'a mut [Vec3A],
                sums: Option<&'a mut [Vec3A]>,
                rule: Rule<f64>,
                reach: f64,
                team: Option<&'a Team>,
            }
            impl Visit for Project<'_> {
                type Output = (usize, SkipCounts);
                #[inline]
                fn visit<const N: usize, C: Constraint<N>>(
                    self,
                    _: Family,
                    c: &C,
                ) -> (usize, SkipCounts) {
                    kernel::project_family::<N, C>(
                        c,
                        self.layout,
                        self.order,
                        self.batches,
                        self.positions,
                        self.rest_positions,
                        self.sums,
                        (self.rule, self.reach),
                        self.team,
                    )
                }
            }
            let (count, skipped) = self.families.visit(
                family,
                Project {
                    layout: self.layouts.of(self.families.binding(family)),
                    order: &self.colour_orders[family],
                    batches: &mut self.sets[family],
                    positions: (&mut self.positions, &mut self.residuals),
                    rest_positions: &mut self.rest_positions,
                    sums,
                    rule,
                    reach: self.settings.reach,
                    team,
                },
            );
            self.apply_jacobi(family);
            self.timings.time[family] += started.elapsed();
            self.timings.projections[family] += count as u64;
            self.skipped[family] = self.skipped[family] + skipped;
        }
        if let Some((i, target, compliance)) = grab
            && compliance > 0.0
        {
            let evaluation =
                crate::constraints::distance::evaluate(&[self.positions[i], target], 0.0);
            let rule = Rule::Xpbd {
                alpha_tilde: (compliance / (h * h)) as f32,
            };
            let weights = [self.inverse_masses[i], 0.0];
            let unbounded = f32::INFINITY;
            let correction = crate::simulation::projection::correction;
            if let Some(c) = correction(evaluation, weights, *grab_lambda, rule, unbounded) {
                *grab_lambda += c.delta_lambda;
                self.positions[i] += c.delta_x[0];
            }
        }
        let (ground, plane_strain) = (self.ground(), self.plane_strain);
        if ground.is_some() || plane_strain {
            let (inverse_masses, previous) = (&self.inverse_masses[..], &self.previous[..]);
            schedule::by_particles(team, [&mut self.positions], |range, [positions]| {
                if let Some(ground) = ground {
                    integrate::project_ground(positions, &inverse_masses[range.clone()], ground);
                }
                if plane_strain {
                    integrate::hold_plane(positions, &previous[range]);
                }
            });
        }
    }
}

/// The order of each active family's colours that `settings` ask for ([`Settings::order_seed`]):
/// empty (the layout's order) without a seed.
fn colour_orders(
    families: &Families,
    settings: &Settings,
    layouts: &Layouts,
) -> PerFamily<Vec<u32>> {
    families.per_family(|family| {
        if !settings.active[family] {
            return Vec::new();
        }
        let colours = layouts.of(families.binding(family)).colour_count();
        settings
            .projection_order(family, colours)
            .unwrap_or_default()
    })
}
