//! The simulation that every front end drives: XPBD (default) or PBD on the constraint families
//! of [`crate::constraints::TABLE`], with substeps, gravity, a ground plane, pins and a grab
//! constraint.
//!
//! One substep of length h = Δt / substeps:
//! 1. predict: v += g h, x_prev = x, x += v h; a particle predicted below the ground (y < 0) is put
//!    back at its previous position, on the ground (sticking friction);
//! 2. XPBD only: λ = 0 for every constraint;
//! 3. `iterations` Gauss–Seidel sweeps over the active families in the table's order (edges,
//!    heights, volume), then the grab, then the ground y ≥ 0, each constraint projected at once;
//! 4. v = (x − x_prev) / h, then damped: v *= max(0, 1 − damping · h) — except, with
//!    [`Settings::settle_edits`], while an edit settles: there |v| is also capped at the predicted
//!    speed, so the projections may turn the motion but never speed it up.
//!
//! The correction Δp of a substep is, per particle, the position after the sweeps minus the
//! predicted one ([`Simulation::corrections`]). An edit (a perturbation, a particle placed by hand)
//! settles until no particle's Δp, summed over a frame's substeps, exceeds
//! [`Simulation::settle_tolerance`]: until its violation is undone, however long that takes. (It
//! once ended after at most a second as well; a body still tangled then, its rigid constraints
//! still fighting, was launched at hundreds of m/s when the cap came off.)
//!
//! Each constraint is projected by the rule of [`crate::simulation::projection`] (XPBD or PBD), which the
//! fast solver shares. All state lives in flat arrays, one [`ConstraintSet`] per family,
//! allocated once: a step allocates nothing, and the same inputs give the same bits.
//!
//! Reading map, for one volume projection: [`Simulation::step`] → [`Simulation::substep`]
//! (`substep.rs`: predict, then `sweep` over each active family, through [`Family::visit`], then
//! `end_substep`) → `project_range` → the `Sweep` visitor → [`crate::constraints::volume::evaluate`]
//! → `correction_lanes` ([`crate::simulation::projection`]). Edits (`edits.rs`) and what a reader
//! asks between steps (`inspection.rs`) stand beside it; `engine.rs` hands a frame to the fast
//! solver instead.

mod constraint_set;
pub mod divergence;
mod edits;
mod engine;
pub mod fast;
mod inspection;
mod integrate;
mod masses;
mod pair;
pub mod projection;
mod settings;
mod substep;

pub use crate::input::limits::SOUND_LIMIT;
pub use constraint_set::ConstraintSet;
pub use inspection::Projection;
pub use masses::DENSITY;
pub use settings::{
    DEFAULT_SUBSTEPS, Engine, FAST_FROM_TETS, Method, Settings, family_value, settable_family,
};
use substep::Projected;

use crate::constraints::{Constraint, Families, Family, PerFamily, Visit, distance};
use crate::scene::Scene;
use crate::scene::mesh::TetMesh;
use crate::simulation::divergence::Divergence;
use crate::simulation::projection::{Rule, SkipCounts, correction, correction_lanes};
use glam::DVec3;

/// An edit has settled when the speed the corrections of a frame would give a particle, ΣΔp / h
/// over its substeps, is at most this many mean rest edge lengths per second (plus what gravity
/// alone causes; see [`Simulation::settle_tolerance`]).
///
/// Why a frame's sum, as a speed: each substep's Δp adds Δp / h to the velocity once settling
/// ends, so what is released is the sum, divided by h. The first rule, the largest Δp of the last
/// substep below 10⁻³ of an edge, held at 10 substeps (where it is about this bound); at 100 a
/// cube still being unmirrored at capped speed passed it (4 × 10⁻⁵ m a substep, a hundred
/// substeps a frame) and took off at 2.6 m/s.
pub const SETTLE_SPEED: f64 = 6.0;

/// A particle held by the user.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grab {
    /// The particle.
    pub particle: usize,
    /// Where the user holds it.
    pub target: DVec3,
    target_at_last_step: DVec3,
    /// How fast the target moved over the last step.
    pub target_velocity: DVec3,
    lambda: f64,
}

/// The soft body in motion.
#[derive(Clone, Debug)]
pub struct Simulation {
    settings: Settings,
    rest_positions: Vec<DVec3>,
    positions: Vec<DVec3>,
    previous: Vec<DVec3>,
    velocities: Vec<DVec3>,
    /// Inverse masses from the lumped masses, 0 where pinned.
    inverse_masses: Vec<f64>,
    pinned: Vec<bool>,
    lumped_inverse_masses: Vec<f64>,
    tets: Vec<[u32; 4]>,
    /// The constraints of each family, as its binding makes them.
    sets: PerFamily<ConstraintSet>,
    grab: Option<Grab>,
    /// Δp of the last substep; during a substep, the predicted positions.
    corrections: Vec<DVec3>,
    /// The sum of Δp over the substeps of the frame so far, the measure of "settled".
    frame_corrections: Vec<DVec3>,
    /// The mean rest edge length, the scale of "settled".
    mean_edge: f64,
    /// Frames an edit has been settling, `None` when none is; see [`Settings::settle_edits`].
    settling: Option<u32>,
    frame: u64,
    time: f64,
    /// The table of families it simulates: the built-in ones and the files it was given.
    families: Families,
    /// The fast engine, when [`Simulation::engine`] is [`Engine::Fast`] ([`engine`]).
    fast: engine::FastEngine,
    /// Threads for the fast engine.
    threads: usize,
    /// Projections skipped for a counted reason since the start (or the last reset), per family.
    skipped: PerFamily<SkipCounts>,
    /// External forces per particle in N, besides gravity (empty: none).
    forces: Vec<DVec3>,
    /// Whether every particle keeps its z (plane strain).
    plane_strain: bool,
}

impl Simulation {
    /// A simulation of `scene` at rest on the built-in families, with masses lumped from
    /// density × rest volume / 4 per tet.
    pub fn new(scene: &Scene, settings: Settings) -> Simulation {
        Simulation::with_families(scene, settings, Families::builtin())
    }

    /// [`Simulation::new`] on the families of `families`: the built-in ones and those of the
    /// constraint files in it.
    ///
    /// Only families of the table are active: `settings.active` is kept to them (a
    /// [`PerFamily::splat`] of `true` means every family the table has).
    pub fn with_families(scene: &Scene, settings: Settings, families: Families) -> Simulation {
        let settings = Settings {
            active: families.per_family(|f| settings.active[f]),
            compliance: families.with_file_stiffness(settings.compliance, &settings.material),
            from_material: families.from_material(),
            ..settings
        };
        let mesh = &scene.mesh;
        let positions = mesh.positions.clone();
        let sets = families
            .per_family(|family| ConstraintSet::new(&families, family, mesh, &settings.material));
        let lumped_inverse_masses = masses::lumped_inverse_masses(mesh);
        let edges = mesh.edges();
        let mean_edge = if edges.is_empty() {
            1.0
        } else {
            let length = |&[i, j]: &[u32; 2]| positions[i as usize].distance(positions[j as usize]);
            edges.iter().map(length).sum::<f64>() / edges.len() as f64
        };
        let mut pinned = vec![false; positions.len()];
        for &i in &scene.pinned {
            pinned[i as usize] = true;
        }
        let n = positions.len();
        let mut simulation = Simulation {
            settings,
            rest_positions: positions.clone(),
            previous: positions.clone(),
            positions,
            velocities: vec![DVec3::ZERO; n],
            inverse_masses: vec![0.0; n],
            pinned,
            lumped_inverse_masses,
            tets: mesh.tets.clone(),
            sets,
            grab: None,
            corrections: vec![DVec3::ZERO; n],
            frame_corrections: vec![DVec3::ZERO; n],
            mean_edge,
            settling: None,
            frame: 0,
            time: 0.0,
            families,
            fast: engine::FastEngine::default(),
            threads: 1,
            skipped: PerFamily::default(),
            forces: Vec::new(),
            plane_strain: false,
        };
        simulation.update_inverse_masses();
        simulation.apply_orders();
        simulation
    }

    #[doc(hidden)]
    pub fn scratch_set_order(&mut self, family: Family, order: Vec<u32>) {
        self.sets[family].set_order(Some(order));
    }

    /// Gives every family's constraints the order [`Settings::order_seed`] asks for.
    fn apply_orders(&mut self) {
        for family in self.families.all() {
            let order = self
                .settings
                .projection_order(family, self.sets[family].len());
            self.sets[family].set_order(order);
        }
    }

    /// The settings in force.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// The table of families it simulates.
    pub fn families(&self) -> &Families {
        &self.families
    }

    /// Simulates the families of `families` from now on (the workbench's editor redefines a
    /// constraint file's family as you type): the constraints of a family whose definition
    /// changed are rebuilt, those of an active family new to the table are built, and nothing
    /// else is touched.
    pub fn set_families(&mut self, families: Families) {
        let active = families.per_family(|f| self.settings.active[f]);
        if active != self.settings.active {
            self.fast.solver = None;
        }
        self.settings.active = active;
        self.settings.compliance =
            families.with_file_stiffness(self.settings.compliance, &self.settings.material);
        self.settings.from_material = families.from_material();
        self.families = families;
        self.rebuild_stale_sets();
    }

    /// Rebuilds the constraints of each family that were built from another definition, and
    /// builds those of an active family that joined the table since the simulation was made.
    /// Allocates only what it builds.
    fn rebuild_stale_sets(&mut self) {
        let mut mesh = None;
        for family in self.families.all() {
            let set = &self.sets[family];
            if set.is_current(&self.families, family)
                || !(set.is_built() || self.settings.active[family])
            {
                continue;
            }
            let mesh = mesh.get_or_insert_with(|| TetMesh {
                positions: self.rest_positions.clone(),
                tets: self.tets.clone(),
            });
            self.sets[family] =
                ConstraintSet::new(&self.families, family, mesh, &self.settings.material);
            let order = self
                .settings
                .projection_order(family, self.sets[family].len());
            self.sets[family].set_order(order);
            // The fast engine's constraints were built from the old ones.
            self.fast.solver = None;
        }
    }

    /// Changes the settings; they apply from the next substep. The constraints of a family
    /// they switch on that the simulation has not built yet (one a file added to the table
    /// since) are built.
    pub fn set_settings(&mut self, settings: Settings) {
        let settings = Settings {
            active: self.families.per_family(|f| settings.active[f]),
            compliance: self
                .families
                .with_file_stiffness(settings.compliance, &settings.material),
            from_material: self.families.from_material(),
            ..settings
        };
        if settings.material != self.settings.material {
            for family in self.families.all() {
                if self.families.rest_uses_material(family) {
                    let rest = &self.rest_positions;
                    self.sets[family].measure_rest(
                        &self.families,
                        family,
                        rest,
                        &settings.material,
                    );
                }
            }
        }
        self.fast.set_settings(&self.settings, &settings);
        let reorder = settings.order_seed != self.settings.order_seed;
        self.settings = settings;
        if reorder {
            self.apply_orders();
        }
        self.rebuild_stale_sets();
    }

    /// Current particle positions.
    pub fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    /// Rest positions (the scene as made).
    pub fn rest_positions(&self) -> &[DVec3] {
        &self.rest_positions
    }

    /// Current particle velocities.
    pub fn velocities(&self) -> &[DVec3] {
        &self.velocities
    }

    /// Δp of the last substep, per particle: the position after the constraint projections minus
    /// the predicted position. Zero after a perturbation or a reset, and for a particle placed by
    /// hand, until the next substep.
    pub fn corrections(&self) -> &[DVec3] {
        &self.corrections
    }

    /// Whether an edit is settling (see [`Settings::settle_edits`]).
    pub fn is_settling(&self) -> bool {
        self.settling.is_some()
    }

    /// For how many frames the edit being settled has been settling, `None` when none is.
    pub fn settling_frames(&self) -> Option<u32> {
        self.settling
    }

    /// The largest sum of Δp over a frame's substeps, in metres, at which an edit counts as
    /// settled: [`SETTLE_SPEED`] × the mean rest edge length × h, plus g h Δt, the sum of the
    /// g h² a substep that gravity alone causes in a body at rest on the ground.
    ///
    /// ```
    /// use tetlab_core::scene::{Builtin, Scene};
    /// use tetlab_core::simulation::{Settings, Simulation};
    /// let scene = Scene::builtin(Builtin::Cube, 2).unwrap();
    /// let at = |substeps| {
    ///     let settings = Settings { substeps, gravity: 0.0, ..Settings::default() };
    ///     Simulation::new(&scene, settings).settle_tolerance()
    /// };
    /// // The same speed at any substep count: ten times the substeps, a tenth of the length.
    /// assert!((at(10) / at(100) - 10.0).abs() < 1e-9);
    /// ```
    pub fn settle_tolerance(&self) -> f64 {
        let h = self.substep_length();
        (SETTLE_SPEED * self.mean_edge + self.settings.gravity.abs() * self.settings.dt) * h
    }

    /// The centre of mass of the particles at `positions` (one per particle, e.g.
    /// [`Simulation::positions`] or [`Simulation::rest_positions`]), weighted by the lumped
    /// masses, pinned particles included.
    ///
    /// ```
    /// use tetlab_core::scene::{Builtin, Scene};
    /// use tetlab_core::simulation::{Settings, Simulation};
    /// let cube = Simulation::new(&Scene::builtin(Builtin::Cube, 2).unwrap(), Settings::default());
    /// // The unit cube on the ground, centred on the y axis: its centre is half a metre up.
    /// let centre = cube.centre_of_mass(cube.rest_positions());
    /// assert!((centre - glam::DVec3::new(0.0, 0.5, 0.0)).length() < 1e-12);
    /// ```
    pub fn centre_of_mass(&self, positions: &[DVec3]) -> DVec3 {
        let mut weighted = DVec3::ZERO;
        let mut mass = 0.0;
        for (p, w) in positions.iter().zip(&self.lumped_inverse_masses) {
            weighted += *p / *w;
            mass += 1.0 / *w;
        }
        if mass > 0.0 {
            weighted / mass
        } else {
            DVec3::ZERO
        }
    }

    /// The diagonal of the rest shape's bounding box, in metres: the size of the body.
    pub fn rest_diagonal(&self) -> f64 {
        let (low, high) = self.rest_positions.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(low, high), p| (low.min(*p), high.max(*p)),
        );
        if self.rest_positions.is_empty() {
            0.0
        } else {
            low.distance(high)
        }
    }

    /// Inverse masses in use (0 for pinned or grabbed-rigidly particles).
    pub fn inverse_masses(&self) -> &[f64] {
        &self.inverse_masses
    }

    /// Per family, the projections skipped since the start (or the last reset) because ∇C was
    /// undefined or not finite, or because the step would have moved a particle further than
    /// [`crate::simulation::projection::DEFAULT_REACH`] rest edges of its element. Zero for every built-in family on
    /// every scene tetlab ships; a constraint file whose ∇C vanishes where C does not counts
    /// here instead of flinging particles away.
    pub fn skipped(&self) -> &PerFamily<SkipCounts> {
        &self.skipped
    }

    /// The tets, as indices into the positions.
    pub fn tets(&self) -> &[[u32; 4]] {
        &self.tets
    }

    /// Frames stepped since the start.
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// Simulated time in seconds.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Ok while every coordinate and velocity component is finite and below [`SOUND_LIMIT`] in
    /// size, and on the fast engine every f32 coordinate (measured from its origin, which
    /// follows the body) below [`crate::simulation::fast::POSITION_LIMIT`]; otherwise the first that is not.
    /// Within the input [`crate::input::limits`] only an instability leaves that range; front ends
    /// check after every frame and stop.
    pub fn check(&self) -> Result<(), Divergence> {
        if let (Engine::Fast, Some(fast)) = (self.engine(), &self.fast.solver) {
            fast.check()?;
        }
        Divergence::find(
            self.frame,
            (SOUND_LIMIT, SOUND_LIMIT),
            self.positions.iter().map(|p| p.to_array()),
            self.velocities.iter().map(|v| v.to_array()),
            |i| i,
        )
    }

    /// Whether [`Simulation::check`] finds nothing.
    pub fn is_sound(&self) -> bool {
        self.check().is_ok()
    }

    /// The bytes of memory the simulation's arrays take (their capacities).
    pub fn heap_bytes(&self) -> usize {
        fn bytes<T>(v: &Vec<T>) -> usize {
            v.capacity() * size_of::<T>()
        }
        bytes(&self.rest_positions)
            + bytes(&self.positions)
            + bytes(&self.previous)
            + bytes(&self.velocities)
            + bytes(&self.inverse_masses)
            + bytes(&self.pinned)
            + bytes(&self.lumped_inverse_masses)
            + bytes(&self.tets)
            + bytes(&self.corrections)
            + bytes(&self.frame_corrections)
            + self
                .sets
                .every_place()
                .map(ConstraintSet::heap_bytes)
                .sum::<usize>()
            + self.fast.solver.as_ref().map_or(0, |f| f.heap_bytes())
    }

    /// The external forces on the particles in N, besides gravity: empty when there are none.
    pub fn forces(&self) -> &[DVec3] {
        &self.forces
    }

    /// Whether every particle keeps its z coordinate ([`Simulation::set_plane_strain`]).
    pub fn plane_strain(&self) -> bool {
        self.plane_strain
    }
}
