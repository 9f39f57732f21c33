//! The fast engine: the substep of [`crate::simulation::substep`] in f32, on flat arrays laid out
//! for speed, on one thread or several. For big meshes, headless runs and `tetlab bench`; the
//! reference engine stays the exact path and the one step-by-step mode walks.
//!
//! What is the same: the substep's stages and their order ([`crate::simulation::substep`]), the
//! constraint formulas (the [`crate::constraints::Constraint`] types of the family table), the
//! projection rule ([`crate::simulation::projection`]), the integration (`integrate`), rest
//! values, masses, pins, grabs and settling edits (from the simulation's body and state,
//! [`crate::simulation::Start`]).
//!
//! What differs, for speed:
//! - particles are renumbered along a Morton (Z-order) curve (`morton`), so that particles close
//!   in space are close in memory; [`FastSimulation::positions`] gives them back in the scene's
//!   numbering;
//! - each family's constraints are coloured so that no two of one colour share a particle, and
//!   projected colour by colour (Gauss–Seidel across colours) (`batches`). Within a colour the
//!   order does not matter, so several threads can share a colour and the result is the same bits
//!   whatever the thread count. A large body is first cut into regions of space, each projected
//!   through all its colours before the elements across the cuts (`batches`, "Regions";
//!   `schedule`), so that threads take whole regions and meet at the cuts only;
//! - within a colour, [`crate::numbers::lanes::LANES`] constraints are projected at once
//!   (`kernel`): the formulas run on [`crate::numbers::lanes::Vec3x8`], eight x, eight y and
//!   eight z in SIMD registers; a batch's particles are loaded as padded 3-vectors and
//!   transposed, its inverse masses, rest values and multipliers are stored lane by lane beside
//!   it; the loads skip their bounds checks (`particles`, one of the two `unsafe` modules, with
//!   `team`);
//! - f32 instead of f64, each position kept with the residual its rounding left out;
//! - optionally the [`Order::Jacobi`] order, for comparison;
//! - regions, large colours and the per-particle passes of a large body shared by a [`Team`] of
//!   threads kept for the simulation's life.
//!
//! As an [`Engine`], it keeps its own copy of the state: each frame it compares the simulation's
//! [`crate::simulation::Revision`] with the one it last saw, takes the state up again after an
//! edit ([`FastSimulation::load`]) and builds itself again after an edit of the body or a change
//! of what it was built for (the active families, the material, the threads), then writes
//! positions, velocities and Δp back ([`FastSimulation::store`]).

pub(in crate::simulation) mod batches;
mod family_batches;
mod kernel;
pub(in crate::simulation) mod layouts;
mod morton;
mod particles;
mod readers;
mod schedule;
mod share_timers;
mod substeps;
mod team;

pub use batches::{Batches, Colour, Layout, PARALLEL_MIN};
pub use family_batches::{FamilyBatches, Order};
pub use team::Team;

use crate::constraints::material::Material;
use crate::constraints::{Families, Family, PerFamily};
use crate::simulation::engine::{Engine, Frame, Start};
use crate::simulation::projection::SkipCounts;
use crate::simulation::substep::{self, Plan};
use crate::simulation::{Divergence, Resolved, Taken};
use family_batches::Jacobi;
use glam::{DVec3, Vec3A};
use layouts::Layouts;
use std::time::Duration;

/// The largest coordinate (m) the f32 engine holds: an edge of twice this, raised to the fourth
/// power (the squared gradient of a volume), stays below f32's 3.4·10³⁸. Velocities are held up
/// to [`crate::simulation::SOUND_LIMIT`], as in f64 (they are only ever multiplied by a substep).
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

/// What the engine was built for: when one of these changes, it builds itself again.
#[derive(Clone, Copy, Debug, PartialEq)]
struct BuiltFor {
    /// The body's revision.
    body: u64,
    /// The active families, whose layouts and batches it built.
    active: PerFamily<bool>,
    /// The material the batches' rest values were measured with.
    material: Material,
    /// Its threads.
    threads: usize,
}

/// The soft body, fast. See the module documentation.
pub struct FastSimulation {
    /// The table of families it projects.
    families: Families,
    /// The settings in force, resolved against the table.
    resolved: Resolved,
    /// What it was built for.
    built_for: BuiltFor,
    /// The revision of the simulation's state it holds.
    synced: u64,
    /// Where the positions are measured from, in the scene's frame: a particle is at
    /// `origin + positions[i]`. It follows a body that travels far (thrown, falling), so that
    /// its f32 coordinates stay about its own size, and their precision its size's
    /// ([`FastSimulation::recentre`]).
    pub(in crate::simulation) origin: DVec3,
    pub(in crate::simulation) positions: Vec<Vec3A>,
    pub(in crate::simulation) previous: Vec<Vec3A>,
    /// What each position's f32 rounding left out: the particle is at `origin + positions[i] +
    /// residuals[i]`, and velocities come from that sum ([`integrate::Residuals`]).
    pub(in crate::simulation) residuals: Vec<Vec3A>,
    /// [`FastSimulation::residuals`] at the start of the substep.
    pub(in crate::simulation) previous_residuals: Vec<Vec3A>,
    pub(in crate::simulation) velocities: Vec<Vec3A>,
    /// The rest positions, for families whose formula reads the rest shape.
    pub(in crate::simulation) rest_positions: Vec<Vec3A>,
    pub(in crate::simulation) inverse_masses: Vec<f32>,
    /// The scene's number of each particle, by new number.
    original: Vec<u32>,
    /// The new number of each particle, by the scene's number.
    pub(in crate::simulation) renumber: Vec<u32>,
    /// The elements the active families bind to, coloured and in batches.
    pub(in crate::simulation) layouts: Layouts,
    /// The rest values and multipliers of each active family (the others are left empty).
    pub(in crate::simulation) sets: PerFamily<Batches>,
    /// The order each family's colours are projected in: empty for the layout's order,
    /// otherwise a permutation drawn from [`crate::simulation::Settings::order_seed`].
    pub(in crate::simulation) colour_orders: PerFamily<Vec<u32>>,
    tets: usize,
    jacobi: Option<Jacobi>,
    /// The threads large colours are shared with, kept for the simulation's life (none: one).
    team: Option<Team>,
    timings: Timings,
    /// Projections skipped for a counted reason since the last [`Engine::step`].
    pub(in crate::simulation) skipped: PerFamily<SkipCounts>,
    pub(in crate::simulation) frame: u64,
    /// Δp of the last substep and its sum over the frame, when a frame asks for them; the
    /// predicted positions they are measured from. Empty until then.
    pub(in crate::simulation) corrections: Corrections,
    /// The external forces in N by new number ([`crate::simulation::Simulation::set_forces`]);
    /// empty: none.
    pub(in crate::simulation) forces: Vec<Vec3A>,
    /// Whether every particle keeps its z ([`crate::simulation::Simulation::set_plane_strain`]).
    pub(in crate::simulation) plane_strain: bool,
    /// The ground's moves of each particle within the substep (`integrate::Book`).
    pushes: Vec<Vec3A>,
    /// Per particle, what the ground, damping and the settling cap took within the frame (J),
    /// summed in order once a frame ([`crate::simulation::Taken`]), so for any thread count.
    pub(in crate::simulation) taken: Vec<Vec3A>,
    /// The frame's contact pairs in the new numbering, and their multipliers.
    contacts: (Vec<[u32; 4]>, Vec<f32>),
}

/// Δp per particle (new numbering), kept on request.
#[derive(Clone, Debug, Default)]
pub(in crate::simulation) struct Corrections {
    pub(in crate::simulation) predicted: Vec<Vec3A>,
    pub(in crate::simulation) last: Vec<Vec3A>,
    pub(in crate::simulation) frame: Vec<Vec3A>,
}

impl FastSimulation {
    /// The fast engine for a simulation's body and state (`start`, in the scene's numbering:
    /// [`crate::simulation::Simulation::start`]), on `start.threads` threads (1 without the
    /// `parallel` feature).
    pub fn new(start: Start<'_>) -> FastSimulation {
        let (body, state) = (start.body, start.state);
        let n = state.positions.len();
        let original = morton::morton_order(&state.positions);
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
            .map(|&i| residual(state.positions[i as usize]))
            .collect();
        let inverse_masses: Vec<f32> = original
            .iter()
            .map(|&i| state.inverse_masses[i as usize] as f32)
            .collect();
        let rest_positions = take(&body.rest_positions);
        let forces = if body.forces.is_empty() {
            Vec::new()
        } else {
            take(&body.forces)
        };
        // Only the families in use are built: a change of them builds the engine again.
        let (families, resolved) = (start.families, start.resolved);
        let active = resolved.active;
        let masses = (&inverse_masses[..], &rest_positions[..]);
        let layouts = Layouts::new(families, &active, body, &renumber, masses);
        let sets = families.per_family(|family| {
            if !active[family] {
                return Batches::default();
            }
            let set = &body.sets[family];
            let rest = set.rest();
            let stored = |element: u32| {
                let stored = set.stored(element as usize).iter();
                stored.map(|&x| x as f32).collect()
            };
            Batches::new(
                layouts.of(families, family),
                |element| rest[element as usize] as f32,
                (set.stored_len(), stored),
                set.own_compliances(),
            )
        });
        debug_assert!(layouts.all().all(|l| l.colouring_is_valid(n)));
        let positions = take(&state.positions);
        // Without the feature (the page), one thread.
        #[cfg(not(feature = "parallel"))]
        let threads = start.threads.min(1);
        #[cfg(feature = "parallel")]
        let threads = start.threads;
        let colour_orders = layouts.colour_orders(families, resolved);
        FastSimulation {
            families: families.clone(),
            resolved: *resolved,
            built_for: BuiltFor {
                body: start.revision.body,
                active,
                material: resolved.settings.material,
                threads: start.threads,
            },
            synced: start.revision.state,
            colour_orders,
            origin: DVec3::ZERO,
            previous: positions.clone(),
            positions,
            previous_residuals: residuals.clone(),
            residuals,
            velocities: take(&state.velocities),
            rest_positions,
            inverse_masses,
            original,
            renumber,
            layouts,
            sets,
            tets: body.tets.len(),
            jacobi: None,
            team: (threads > 1).then(|| Team::new(threads)),
            timings: Timings::default(),
            skipped: PerFamily::default(),
            frame: 0,
            corrections: Corrections::default(),
            forces,
            plane_strain: body.plane_strain,
            pushes: vec![Vec3A::ZERO; n],
            taken: vec![Vec3A::ZERO; n],
            contacts: (Vec::new(), Vec::new()),
        }
    }

    /// Brings the engine up to `frame`: built again when the body or what it was built for
    /// changed, the state taken up again when it was edited, and the settings of the frame in
    /// force (a new order seed puts the colours in its order).
    pub(in crate::simulation) fn prepare(&mut self, frame: &Frame<'_>) {
        let wanted = BuiltFor {
            body: frame.revision.body,
            active: frame.resolved.active,
            material: frame.resolved.settings.material,
            threads: frame.threads,
        };
        if wanted != self.built_for {
            let jacobi = self.order();
            *self = FastSimulation::new(frame.start());
            self.set_order(jacobi);
            return;
        }
        if frame.revision.state != self.synced {
            let state = &*frame.state;
            self.load(&state.positions, &state.velocities, &state.inverse_masses);
            self.synced = frame.revision.state;
        }
        if frame.resolved.settings.order_seed != self.resolved.settings.order_seed {
            self.colour_orders = self.layouts.colour_orders(&self.families, frame.resolved);
        }
        self.resolved = *frame.resolved;
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
    /// did not keep them). Allocates nothing.
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

    /// Advances one frame on its own arrays, with no grab, no edit settling and no Δp kept: the
    /// engine alone, as `tetlab bench` and the tests time and compare it.
    pub fn step(&mut self) {
        let mut plan = Plan::new(
            &self.families,
            &self.resolved,
            self.plane_strain,
            None,
            false,
        );
        plan.keep_corrections = false;
        self.run(&plan);
    }

    /// One frame of `plan` on its own arrays; large colours are shared with its team's threads,
    /// which wait for the next colour spinning, not asleep, while a frame is under way. Returns
    /// what the ground, damping and the settling cap took over the frame.
    fn run(&mut self, plan: &Plan) -> Taken {
        let team = self.team.take();
        let mut on = substeps::OnArrays {
            simulation: self,
            team: team.as_ref(),
            grab_lambda: 0.0,
        };
        substep::frame(&mut on, plan);
        self.team = team;
        self.frame += 1;
        let mut taken = Taken::default();
        taken.add_and_clear(&mut self.taken);
        taken
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
    pub(in crate::simulation) fn recentre(&mut self) {
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

    /// What the per-particle passes write (positions, their values at the start of the substep,
    /// velocities, residuals and theirs at the start of the substep) and read (inverse masses,
    /// forces).
    #[allow(clippy::type_complexity)]
    fn particle_arrays(&mut self) -> ([&mut [Vec3A]; 7], &[f32], &[Vec3A]) {
        (
            [
                &mut self.positions,
                &mut self.previous,
                &mut self.velocities,
                &mut self.residuals,
                &mut self.previous_residuals,
                &mut self.pushes,
                &mut self.taken,
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
}

impl Engine for FastSimulation {
    fn step(&mut self, frame: Frame<'_>) -> PerFamily<SkipCounts> {
        self.prepare(&frame);
        let plan = Plan::of(&frame);
        let taken = self.run(&plan);
        let state = frame.state;
        state.taken.ground += taken.ground;
        state.taken.damping += taken.damping;
        state.taken.settling += taken.settling;
        let corrections = (&mut state.corrections[..], &mut state.frame_corrections[..]);
        self.store(
            &mut state.positions,
            &mut state.velocities,
            Some(corrections),
        );
        self.take_skipped()
    }

    fn describe(&self) -> String {
        crate::simulation::EngineChoice::Fast.describe(self.threads())
    }

    fn check(&self) -> Result<(), Divergence> {
        FastSimulation::check(self)
    }

    fn heap_bytes(&self) -> usize {
        FastSimulation::heap_bytes(self)
    }

    fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
        self
    }
}
