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
//! Each constraint is projected by the rule of [`crate::projection`] (XPBD or PBD), which the
//! fast solver shares. All state lives in flat arrays, one [`ConstraintSet`] per family,
//! allocated once: a step allocates nothing, and the same inputs give the same bits.
//!
//! Reading map, for one volume projection: [`Simulation::step`] → [`Simulation::substep`] →
//! `sweep` (each active family, through [`Family::visit`]) → `project_one` →
//! [`crate::constraints::volume::evaluate`] → `correction` ([`crate::projection`]).

mod constraint_set;
mod engine;
mod masses;
mod pair;
mod settings;

pub use constraint_set::ConstraintSet;
pub use engine::{Engine, FAST_FROM_TETS};
pub use masses::DENSITY;
pub use settings::{DEFAULT_SUBSTEPS, Method, Settings};

use crate::constraints::{Constraint, Family, PerFamily, Visit, distance};
use crate::divergence::Divergence;
use crate::integrate;
use crate::mesh::TetMesh;
use crate::projection::{Rule, SkipCounts, correction, correction_lanes};
use crate::scene::Scene;
use glam::DVec3;

/// The largest coordinate or velocity component (in m or m/s) a sound simulation in f64 has:
/// below it, volumes (cubes), squared residuals and their sums over any mesh stay finite.
pub const SOUND_LIMIT: f64 = 1e30;

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
    /// [`crate::constraints::file::definitions`] when the sets were last brought up to date.
    definitions: u64,
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
    /// A simulation of `scene` at rest, with masses lumped from density × rest volume / 4 per tet.
    pub fn new(scene: &Scene, settings: Settings) -> Simulation {
        let mesh = &scene.mesh;
        let positions = mesh.positions.clone();
        let sets = PerFamily::build(|family| ConstraintSet::new(family, mesh, &settings.material));
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
            definitions: crate::constraints::file::definitions(),
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
        for family in Family::all() {
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

    /// Brings the constraints up to date with the table when a family was defined since the
    /// last look ([`Family::define`]: the workbench's editor redefines a constraint file's
    /// family as you type): those of a redefined family are rebuilt. Nothing to do, and nothing
    /// allocated, when no family was defined; every substep calls it.
    pub fn refresh_families(&mut self) {
        if crate::constraints::file::definitions() != self.definitions {
            self.rebuild_stale_sets();
        }
    }

    /// Rebuilds the constraints of each family that were built from an older definition, and
    /// builds those of an active family registered since the simulation was made. Allocates
    /// only what it builds.
    fn rebuild_stale_sets(&mut self) {
        self.definitions = crate::constraints::file::definitions();
        let mut mesh = None;
        for family in Family::all() {
            let set = &self.sets[family];
            if set.is_current(family) || !(set.is_built() || self.settings.active[family]) {
                continue;
            }
            let mesh = mesh.get_or_insert_with(|| TetMesh {
                positions: self.rest_positions.clone(),
                tets: self.tets.clone(),
            });
            self.sets[family] = ConstraintSet::new(family, mesh, &self.settings.material);
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
        if settings.material != self.settings.material {
            for family in Family::all().filter(|f| f.rest_uses_material()) {
                self.sets[family].measure_rest(family, &self.rest_positions, &settings.material);
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
    /// use tetlab_core::solver::{Settings, Simulation};
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
    /// use tetlab_core::solver::{Settings, Simulation};
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
    /// [`crate::projection::DEFAULT_REACH`] rest edges of its element. Zero for every built-in family on
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
    /// follows the body) below [`crate::fast::POSITION_LIMIT`]; otherwise the first that is not.
    /// Within the input [`crate::limits`] only an instability leaves that range; front ends
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
                .iter_ref()
                .map(|(_, set)| set.heap_bytes())
                .sum::<usize>()
            + self.fast.solver.as_ref().map_or(0, |f| f.heap_bytes())
    }

    /// The external forces on the particles in N, besides gravity: empty when there are none.
    pub fn forces(&self) -> &[DVec3] {
        &self.forces
    }

    /// Sets the external forces, one per particle in N (a traction lumped onto the nodes it
    /// acts on), or none with an empty vector. Each substep adds w fᵢ h to a free particle's
    /// velocity, on either engine; pinned particles feel nothing.
    ///
    /// # Panics
    /// If `forces` is neither empty nor one per particle.
    pub fn set_forces(&mut self, forces: Vec<DVec3>) {
        assert!(
            forces.is_empty() || forces.len() == self.positions.len(),
            "one force per particle, or none"
        );
        self.forces = forces;
        self.fast.solver = None;
    }

    /// Whether every particle keeps its z coordinate ([`Simulation::set_plane_strain`]).
    pub fn plane_strain(&self) -> bool {
        self.plane_strain
    }

    /// Holds every particle at its current z (on) or frees z again (off): a plane problem
    /// extruded into one layer of tets, held in z, is in plane strain (ε_zz = 0).
    pub fn set_plane_strain(&mut self, on: bool) {
        self.plane_strain = on;
        self.fast.solver = None;
    }

    /// Whether particle `i` is pinned.
    pub fn is_pinned(&self, i: usize) -> bool {
        self.pinned[i]
    }

    /// Pins or frees particle `i`.
    pub fn set_pinned(&mut self, i: usize, pinned: bool) {
        self.pinned[i] = pinned;
        self.update_inverse_masses();
        self.fast.edited();
    }

    /// Applies a perturbation to the current positions and stops all motion.
    pub fn perturb(&mut self, perturbation: crate::scene::Perturbation) {
        let mesh = TetMesh {
            positions: self.rest_positions.clone(),
            tets: self.tets.clone(),
        };
        perturbation.apply(&mut self.positions, &mesh);
        self.stop();
        self.settling = Some(0);
    }

    /// Puts every particle at the given positions, at rest (e.g. a state computed elsewhere).
    pub fn set_positions(&mut self, positions: &[DVec3]) {
        self.positions.copy_from_slice(positions);
        self.stop();
    }

    /// Puts particle `i` at `position` at rest (a kinematic move, e.g. a drag while paused).
    pub fn place(&mut self, i: usize, position: DVec3) {
        self.fast.edited();
        self.positions[i] = position;
        self.previous[i] = position;
        self.velocities[i] = DVec3::ZERO;
        self.corrections[i] = DVec3::ZERO;
        self.frame_corrections[i] = DVec3::ZERO;
        self.settling = Some(0);
    }

    /// Back to the rest shape, at rest, at frame 0.
    pub fn reset(&mut self) {
        self.positions.copy_from_slice(&self.rest_positions);
        self.skipped = PerFamily::default();
        self.stop();
        self.settling = None;
        self.frame = 0;
        self.time = 0.0;
    }

    /// Zeroes every velocity and multiplier.
    fn stop(&mut self) {
        self.fast.edited();
        self.previous.copy_from_slice(&self.positions);
        self.velocities.fill(DVec3::ZERO);
        self.corrections.fill(DVec3::ZERO);
        self.frame_corrections.fill(DVec3::ZERO);
        for family in Family::all() {
            self.sets[family].reset_lambda();
        }
    }

    /// Starts holding particle `i` at `target`. With zero grab compliance the particle follows the
    /// target exactly (its inverse mass is 0 meanwhile); otherwise a compliant zero-length
    /// constraint pulls it.
    pub fn grab(&mut self, i: usize, target: DVec3) {
        self.release();
        self.grab = Some(Grab {
            particle: i,
            target,
            target_at_last_step: target,
            target_velocity: DVec3::ZERO,
            lambda: 0.0,
        });
        self.update_inverse_masses();
        self.fast.edited();
    }

    /// Moves the held target.
    pub fn move_grab(&mut self, target: DVec3) {
        if let Some(grab) = &mut self.grab {
            grab.target = target;
        }
    }

    /// The current grab, if any.
    pub fn grabbed(&self) -> Option<&Grab> {
        self.grab.as_ref()
    }

    /// Lets go: the particle's mass comes back, and it keeps the target's velocity over the last
    /// step so it can be thrown.
    pub fn release(&mut self) {
        if let Some(grab) = self.grab.take() {
            self.velocities[grab.particle] = grab.target_velocity;
            self.update_inverse_masses();
            self.fast.edited();
        }
    }

    fn rigid_grab(&self) -> Option<Grab> {
        self.grab.filter(|_| self.settings.grab_compliance <= 0.0)
    }

    fn update_inverse_masses(&mut self) {
        for i in 0..self.positions.len() {
            self.inverse_masses[i] = if self.pinned[i] {
                0.0
            } else {
                self.lumped_inverse_masses[i]
            };
        }
        if let Some(grab) = self.rigid_grab() {
            self.inverse_masses[grab.particle] = 0.0;
        }
    }

    /// Advances one frame: `substeps` substeps of Δt / substeps, on the engine of
    /// [`Simulation::engine`].
    pub fn step(&mut self) {
        self.update_inverse_masses();
        self.frame_corrections.fill(DVec3::ZERO);
        match self.engine() {
            Engine::Fast => self.step_fast(),
            _ => {
                for _ in 0..self.settings.substeps.max(1) {
                    self.substep();
                }
            }
        }
        if let Some(grab) = &mut self.grab {
            grab.target_velocity = (grab.target - grab.target_at_last_step) / self.settings.dt;
            grab.target_at_last_step = grab.target;
        }
        if let Some(frames) = self.settling {
            let largest = self.largest_frame_correction();
            self.settling = (self.settings.edits_settle() && largest > self.settle_tolerance())
                .then_some(frames + 1);
        }
        self.frame += 1;
        self.time += self.settings.dt;
    }

    /// One substep: predict, project every active family `iterations` times, update velocities.
    /// The same as [`Simulation::begin_substep`], then for each iteration every constraint of
    /// [`Simulation::projection_order`] through [`Simulation::project`] and
    /// [`Simulation::end_sweep`], then [`Simulation::end_substep`] — done here in tight loops.
    pub fn substep(&mut self) {
        let h = self.substep_length();
        self.begin_substep();
        for _ in 0..self.settings.iterations.max(1) {
            self.sweep(h);
        }
        self.end_substep();
    }

    /// h = Δt / substeps.
    pub fn substep_length(&self) -> f64 {
        self.settings.dt / self.settings.substeps.max(1) as f64
    }

    /// The first part of a substep: predict positions, and (XPBD) λ = 0 for every constraint.
    pub fn begin_substep(&mut self) {
        self.fast.edited();
        self.refresh_families();
        let h = self.substep_length();
        self.predict(h);
        for family in Family::all() {
            self.sets[family].reset_lambda();
        }
        if let Some(grab) = &mut self.grab {
            grab.lambda = 0.0;
        }
    }

    /// The end of one sweep, after the constraint families: the grab, then the ground y ≥ 0.
    pub fn end_sweep(&mut self) {
        self.fast.edited();
        let h = self.substep_length();
        self.project_soft_grab(h);
        if self.settings.ground {
            integrate::project_ground(&mut self.positions, &self.inverse_masses, 0.0);
        }
        if self.plane_strain {
            integrate::hold_plane(&mut self.positions, &self.previous);
        }
    }

    /// The last part of a substep: Δp = x − predicted x, then velocities from the positions.
    pub fn end_substep(&mut self) {
        self.fast.edited();
        let h = self.substep_length();
        for ((correction, sum), p) in self
            .corrections
            .iter_mut()
            .zip(&mut self.frame_corrections)
            .zip(&self.positions)
        {
            *correction = *p - *correction;
            *sum += *correction;
        }
        self.update_velocities(h, self.settings.edits_settle() && self.settling.is_some());
    }

    /// The constraints one sweep projects, in order: every constraint of each active family
    /// (edges, then heights, then volumes), each family's in the order of
    /// [`Settings::order_seed`], as (family, index in the family).
    pub fn projection_order(&self) -> impl Iterator<Item = (Family, usize)> + '_ {
        let active = self.settings.active;
        Family::all()
            .filter(move |&f| active[f] && !f.projected_by_partner(&active))
            .flat_map(move |f| {
                let set = &self.sets[f];
                (0..set.len()).map(move |k| (f, set.in_order(k)))
            })
    }

    /// The constraints of `family` on tet `tet`, as indices in the family: its edges (six), its
    /// four heights, or its volume ([`crate::constraints::Binding::of_tet`]).
    pub fn tet_constraints(&self, tet: usize, family: Family) -> impl Iterator<Item = usize> + '_ {
        let edges = self.sets[Family::EDGES].all_particles();
        family.row().binding.of_tet(tet, self.tets[tet], edges)
    }

    /// The constraints of `family`: their particles, rest values and multipliers.
    pub fn constraints(&self, family: Family) -> &ConstraintSet {
        &self.sets[family]
    }

    /// The shortest edge of the rest shape (0 without edges).
    pub fn shortest_edge(&self) -> f64 {
        let lengths = self.sets[Family::EDGES].rest().iter().copied();
        lengths.filter(|&l| l > 0.0).reduce(f64::min).unwrap_or(0.0)
    }

    /// Why the settings may blow up, when an active family takes its compliance from the
    /// material and the substeps are too long for it
    /// ([`crate::material::Material::substeps_needed`]): a warning
    /// every front end shows.
    pub fn stability_warning(&self) -> Option<String> {
        let settings = &self.settings;
        let material_family = settings
            .active
            .families()
            .find(|f| f.row().compliance_from_material.is_some())?;
        let shortest = self.shortest_edge();
        let material = settings.material;
        let needed = material.substeps_needed(settings.dt, shortest, DENSITY);
        (needed > u64::from(settings.substeps)).then(|| {
            format!(
                "{} with material {} needs at least {needed} substeps per frame of {:.4} s on this \
                 mesh (pressure waves {:.3e} m/s, shortest edge {:.3e} m); with {} it may blow \
                 up",
                material_family.row().group,
                material.describe(),
                settings.dt,
                material.wave_speed(DENSITY),
                shortest,
                settings.substeps
            )
        })
    }

    /// Constraint projections one frame makes with the current settings: the active families'
    /// constraints × substeps × iterations.
    pub fn projections_per_frame(&self) -> u64 {
        self.settings
            .projections_per_frame(PerFamily::from_fn(|f| self.constraint_count(f)))
    }

    /// How many constraints `family` has.
    pub fn constraint_count(&self, family: Family) -> usize {
        self.sets[family].len()
    }

    /// What projecting constraint `c` of `family` now would do, with the current λ and the rule
    /// (XPBD or PBD) of the current settings: C, ∇C, the inverse masses, Δλ and Δx.
    ///
    /// A family projected together with another ([`Family::partner_in`]) shows its own C and
    /// ∇C, and the Δλ and Δx of the pair's projection.
    pub fn projection(&self, family: Family, c: usize) -> Projection {
        let h = self.substep_length();
        let rule = self.rule(family, h);
        let mut projection = family.visit(Describe {
            set: &self.sets[family],
            positions: &self.positions,
            rest_positions: &self.rest_positions,
            inverse_masses: &self.inverse_masses,
            rule,
            c,
            reach: self.settings.reach,
        });
        if let Some(partner) = family.partner_in(&self.settings.active) {
            let pair = pair::Pair {
                first: &self.sets[family],
                second: &self.sets[partner],
                positions: &self.positions,
                rest_positions: &self.rest_positions,
                inverse_masses: &self.inverse_masses,
                rules: [rule, self.rule(partner, h)],
                reach: self.settings.reach,
            };
            let correction = family.visit_pair(partner, pair::PairAt { pair, c });
            let skipped = projection.delta_lambda.is_none();
            projection.delta_lambda = (!skipped).then_some(correction.delta_lambda[0]);
            projection.delta_x = correction.delta_x;
        }
        projection
    }

    /// Projects constraint `c` of `family` once, exactly as a sweep does (with its partner, if
    /// it leads a pair).
    pub fn project(&mut self, family: Family, c: usize) {
        self.fast.edited();
        self.project_range(family, Projected::One(c), self.substep_length());
    }

    /// Projects the constraints `which` of `family` in turn, alone or with its partner.
    fn project_range(&mut self, family: Family, which: Projected, h: f64) {
        let rule = self.rule(family, h);
        if let Some(partner) = family.partner_in(&self.settings.active) {
            let rules = [rule, self.rule(partner, h)];
            let (first, second) = self.sets.pair_mut(family, partner);
            let (skipped_first, skipped_second) = self.skipped.pair_mut(family, partner);
            let sweep = pair::PairSweep {
                first,
                second,
                skipped: [skipped_first, skipped_second],
                positions: &mut self.positions,
                rest_positions: &self.rest_positions,
                inverse_masses: &self.inverse_masses,
                rules,
                which,
                reach: self.settings.reach,
            };
            family.visit_pair(partner, sweep);
            return;
        }
        family.visit(Sweep {
            set: &mut self.sets[family],
            positions: &mut self.positions,
            rest_positions: &self.rest_positions,
            inverse_masses: &self.inverse_masses,
            rule,
            which,
            skipped: &mut self.skipped[family],
            reach: self.settings.reach,
        });
    }

    /// The longest Δp of the last substep among particles that can move.
    fn largest_frame_correction(&self) -> f64 {
        self.frame_corrections
            .iter()
            .zip(&self.inverse_masses)
            .filter(|(_, w)| **w > 0.0)
            .map(|(c, _)| c.length())
            .fold(0.0, f64::max)
    }

    fn predict(&mut self, h: f64) {
        integrate::predict(
            &mut self.positions,
            &mut self.previous,
            &mut self.velocities,
            &self.inverse_masses,
            &self.forces,
            integrate::Substep {
                gravity: self.settings.gravity,
                h,
                ground: self.settings.ground.then_some(0.0),
                plane_strain: self.plane_strain,
            },
            None,
        );
        if let Some(grab) = self.rigid_grab() {
            self.positions[grab.particle] = grab.target;
        }
        self.corrections.copy_from_slice(&self.positions);
    }

    pub(crate) fn rule(&self, family: Family, h: f64) -> Rule<f64> {
        Rule::for_settings(&self.settings, family, h)
    }

    /// One Gauss–Seidel sweep over the active families, then the grab, the ground and the
    /// plane-strain hold.
    fn sweep(&mut self, h: f64) {
        let active = self.settings.active;
        for family in Family::all() {
            if !active[family] || family.projected_by_partner(&active) {
                continue;
            }
            self.project_range(family, Projected::All, h);
        }
        self.end_sweep();
    }

    fn project_soft_grab(&mut self, h: f64) {
        let compliance = self.settings.grab_compliance;
        let Some(grab) = self.grab.as_mut().filter(|_| compliance > 0.0) else {
            return;
        };
        let i = grab.particle;
        let evaluation = distance::evaluate(&[self.positions[i], grab.target], 0.0);
        let rule = Rule::Xpbd {
            alpha_tilde: compliance / (h * h),
        };
        let unbounded = f64::INFINITY;
        let weights = [self.inverse_masses[i], 0.0];
        if let Some(c) = correction(evaluation, weights, grab.lambda, rule, unbounded) {
            grab.lambda += c.delta_lambda;
            self.positions[i] += c.delta_x[0];
        }
    }

    /// v = (x − x_prev) / h, damped; when `settling`, no faster than the predicted velocity.
    fn update_velocities(&mut self, h: f64, settling: bool) {
        integrate::update_velocities(
            &self.positions,
            &self.previous,
            &mut self.velocities,
            h,
            self.settings.damping,
            settling,
            None,
        );
    }
}

/// Which constraints of a family a projection call makes.
#[derive(Clone, Copy)]
pub(super) enum Projected {
    /// Every one, in the set's order (a sweep).
    All,
    /// Constraint c alone (step-by-step mode).
    One(usize),
}

impl Projected {
    /// The positions in the set's order to go through.
    pub(super) fn range(self, set: &ConstraintSet) -> std::ops::Range<usize> {
        match self {
            Projected::All => 0..set.len(),
            Projected::One(c) => c..c + 1,
        }
    }

    /// The constraint at position `k` of [`Projected::range`].
    #[inline]
    pub(super) fn at(self, set: &ConstraintSet, k: usize) -> usize {
        match self {
            Projected::All => set.in_order(k),
            Projected::One(c) => c,
        }
    }
}

/// Projects the constraints of one family's `set` (every one in the set's order, Gauss–Seidel,
/// or one): λ += Δλ, xᵢ += Δxᵢ.
struct Sweep<'a> {
    set: &'a mut ConstraintSet,
    positions: &'a mut [DVec3],
    rest_positions: &'a [DVec3],
    inverse_masses: &'a [f64],
    rule: Rule<f64>,
    which: Projected,
    skipped: &'a mut SkipCounts,
    /// [`Settings::reach`].
    reach: f64,
}

impl Visit for Sweep<'_> {
    type Output = ();

    #[inline]
    fn visit<const N: usize, C: Constraint<N>>(self, _: Family, constraint: &C) {
        for k in self.which.range(self.set) {
            let c = self.which.at(self.set, k);
            let idx = self.set.indices::<N>(c);
            let p = idx.map(|i| self.positions[i as usize]);
            let shape = if C::USES_REST_SHAPE {
                idx.map(|i| self.rest_positions[i as usize])
            } else {
                p
            };
            let evaluation = constraint.evaluate(&p, self.set.rest()[c], &shape);
            let weights = idx.map(|i| self.inverse_masses[i as usize]);
            let (lambda, reach) = (self.set.lambda()[c], self.reach * self.set.size()[c]);
            let (skipped, correction) =
                correction_lanes(evaluation, weights, lambda, self.rule, reach);
            if skipped.any() {
                self.skipped.add(skipped);
            } else {
                self.set.add_lambda(c, correction.delta_lambda);
                for (&i, dx) in idx.iter().zip(correction.delta_x) {
                    self.positions[i as usize] += dx;
                }
            }
        }
    }
}

/// One constraint, described for a reader: see [`Simulation::projection`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    /// The constraint's family.
    pub family: Family,
    /// Its index within the family.
    pub constraint: usize,
    /// Its particles; the first [`Projection::len`] are used (2 for an edge, 4 otherwise).
    pub particles: [u32; 4],
    /// How many particles it has.
    pub len: usize,
    /// C now.
    pub value: f64,
    /// The rest value, d or V.
    pub rest: f64,
    /// ∇ₚC for each particle.
    pub gradients: [DVec3; 4],
    /// The inverse mass w of each particle (0 if pinned or held).
    pub inverse_masses: [f64; 4],
    /// Σ wᵢ |∇ₚᵢC|².
    pub weighted_norm: f64,
    /// λ accumulated so far in this substep (XPBD).
    pub lambda: f64,
    /// XPBD: Δλ; PBD: k′ s. `None` when the projection is skipped (degenerate, every particle
    /// fixed, or [`LOCKED`]).
    pub delta_lambda: Option<f64>,
    /// Δx the projection would give each particle (zero when skipped).
    pub delta_x: [DVec3; 4],
    /// Whether ∇C is undefined here.
    pub degenerate: bool,
}

impl Projection {
    /// The particles it uses.
    pub fn particles(&self) -> &[u32] {
        &self.particles[..self.len]
    }
}

/// [`Projection`] of constraint `c` of `set`.
struct Describe<'a> {
    set: &'a ConstraintSet,
    positions: &'a [DVec3],
    rest_positions: &'a [DVec3],
    inverse_masses: &'a [f64],
    rule: Rule<f64>,
    c: usize,
    reach: f64,
}

impl Visit for Describe<'_> {
    type Output = Projection;

    fn visit<const N: usize, C: Constraint<N>>(self, family: Family, constraint: &C) -> Projection {
        let c = self.c;
        let idx = self.set.indices::<N>(c);
        let p = idx.map(|i| self.positions[i as usize]);
        let shape = idx.map(|i| self.rest_positions[i as usize]);
        let evaluation = constraint.evaluate(&p, self.set.rest()[c], &shape);
        let weights = idx.map(|i| self.inverse_masses[i as usize]);
        let lambda = self.set.lambda()[c];
        let reach = self.reach * self.set.size()[c];
        let correction = correction(evaluation, weights, lambda, self.rule, reach);
        let mut projection = Projection {
            family,
            constraint: c,
            particles: [0; 4],
            len: N,
            value: evaluation.value,
            rest: self.set.rest()[c],
            gradients: [DVec3::ZERO; 4],
            inverse_masses: [0.0; 4],
            weighted_norm: crate::projection::weighted_norm(&weights, &evaluation.gradients),
            lambda,
            delta_lambda: correction.map(|c| c.delta_lambda),
            delta_x: [DVec3::ZERO; 4],
            degenerate: evaluation.degenerate,
        };
        for k in 0..N {
            projection.particles[k] = idx[k];
            projection.gradients[k] = evaluation.gradients[k];
            projection.inverse_masses[k] = weights[k];
            if let Some(correction) = &correction {
                projection.delta_x[k] = correction.delta_x[k];
            }
        }
        projection
    }
}
