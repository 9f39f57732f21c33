//! The simulation every front end drives: XPBD (default) or PBD on the constraint families of a
//! table ([`crate::constraints::Families`]), with substeps, gravity, a ground plane, pins, a grab
//! and external forces.
//!
//! A [`Simulation`] owns what it simulates: the settings as the user set them ([`Settings`]; what
//! follows from them is [`Resolved`]), the table of families, the [`Body`] and the [`State`]. An
//! [`Engine`] steps the state a frame at a time (`engine.rs`): the reference engine (f64, one
//! constraint at a time, `reference.rs`) or the fast one (f32, SIMD lanes, threads, [`fast`]);
//! both run the substep written once in `substep.rs`, and both project by the one rule of
//! [`projection`]. Edits (`edits.rs`) change the state through `Simulation::state_mut` (or the
//! body through `Simulation::body_mut`), which bump the [`Revision`] that engines compare; what
//! a reader asks between steps is `inspection.rs`.
//!
//! Reading map, for one volume projection: [`Simulation::step`] → [`Engine::step`] of
//! [`reference::ReferenceEngine`] → `substep::frame` → `OnState::project` →
//! [`crate::constraints::Families::visit_unit`] → the `Sweep` visitor → `project_unit` →
//! [`crate::constraints::volume::evaluate`] and [`projection::correct`].

mod constraint_set;
pub mod contact;
pub mod divergence;
mod edits;
mod engine;
mod engine_choice;
mod engine_slot;
pub mod fast;
#[cfg(feature = "gpu")]
pub mod gpu;
mod inspection;
mod integrate;
mod masses;
pub mod newton;
pub mod projection;
mod reference;
mod resolved;
pub(crate) mod settings;
mod settling;
mod state;
mod stepping;
pub mod substep;

pub use crate::input::limits::SOUND_LIMIT;
pub use constraint_set::ConstraintSet;
pub use engine::{Build, Engine, Frame, Start};
pub use engine_choice::{EngineChoice, FAST_FROM_TETS};
pub use inspection::Projection;
pub use masses::DENSITY;
pub use reference::{OnState, ReferenceEngine};
pub use resolved::Resolved;
pub use settings::{DEFAULT_SUBSTEPS, Method, Settings, settable_family};
pub use settling::VIOLATED;
pub use state::{Body, Grab, Revision, State, Taken};

use crate::constraints::{Families, Family, PerFamily};
use crate::scene::mesh::TetMesh;
use crate::scene::{Scene, SceneBody};
use crate::simulation::divergence::Divergence;
use crate::simulation::projection::SkipCounts;
use engine_slot::EngineSlot;
use glam::DVec3;
use std::ops::Range;

/// An edit has settled when the speed the corrections of a frame would give a particle, ΣΔp / h
/// over its substeps, is at most this many mean rest edge lengths per second (plus what gravity
/// alone causes; see [`Simulation::settle_tolerance`]). docs/experiments.md says how it was
/// chosen.
pub const SETTLE_SPEED: f64 = 6.0;

/// The soft body in motion.
#[derive(Clone, Debug)]
pub struct Simulation {
    /// The settings as they were set.
    settings: Settings,
    /// The table of families it simulates: the built-in ones and the files it was given.
    families: Families,
    /// The settings resolved against the table (kept with them: [`Simulation::resolve`]).
    resolved: Resolved,
    /// The material the rest values were measured with.
    measured_with: crate::constraints::material::Material,
    body: Body,
    state: State,
    /// How often the body and the state have been edited.
    revision: Revision,
    /// Frames an edit has been settling, `None` when none is; see [`Settings::settle_edits`].
    settling: Option<u32>,
    /// Whether the speed cap of a settling edit is held off for the coming frame (see
    /// `Simulation::hold_off_settling`).
    settling_held_off: bool,
    /// Whether the settling edit left tets inverted under a material, as its first frame found.
    edit_inverted: bool,
    frame: u64,
    time: f64,
    /// The engine that steps it.
    engine: EngineSlot,
    /// Threads an engine may use.
    threads: usize,
    /// Projections skipped for a counted reason since the start (or the last reset), per family.
    skipped: PerFamily<SkipCounts>,
    /// The broad phase of contact, its arrays kept between frames.
    contact_finder: contact::ContactFinder,
}

impl Simulation {
    /// A simulation of `scene` at rest on the built-in families, with masses lumped from
    /// density × rest volume / 4 per tet.
    pub fn new(scene: &Scene, settings: Settings) -> Simulation {
        Simulation::with_families(scene, settings, Families::builtin())
    }

    /// [`Simulation::new`] on the families of `families`: the built-in ones and those of the
    /// constraint files in it. Only families of the table are active ([`Resolved::active`]).
    pub fn with_families(scene: &Scene, settings: Settings, families: Families) -> Simulation {
        let mesh = &scene.mesh;
        let resolved = Resolved::new(&settings, &families);
        let material = settings.material;
        let made_of = (&material, scene.bodies.as_slice());
        let sets = families.per_family(|f| ConstraintSet::new(&families, f, mesh, made_of));
        let edges = mesh.edges();
        let positions = &mesh.positions;
        let mean_edge = if edges.is_empty() {
            1.0
        } else {
            let length = |&[i, j]: &[u32; 2]| positions[i as usize].distance(positions[j as usize]);
            edges.iter().map(length).sum::<f64>() / edges.len() as f64
        };
        let body = Body {
            rest_positions: mesh.positions.clone(),
            tets: mesh.tets.clone(),
            lumped_inverse_masses: masses::lumped_inverse_masses(mesh, &scene.bodies),
            forces: Vec::new(),
            plane_strain: false,
            mean_edge,
            edges,
            sets,
            start_velocities: start_velocities(scene),
            bodies: scene.bodies.clone(),
            contact_surface: std::sync::OnceLock::new(),
        };
        let mut state = State::at_rest(&body);
        for &i in &scene.pinned {
            state.pinned[i as usize] = true;
            state.inverse_masses[i as usize] = 0.0;
        }
        let mut simulation = Simulation {
            settings,
            families,
            resolved,
            measured_with: material,
            body,
            state,
            revision: Revision::default(),
            settling: None,
            settling_held_off: false,
            edit_inverted: false,
            frame: 0,
            time: 0.0,
            engine: EngineSlot::default(),
            threads: 1,
            skipped: PerFamily::default(),
            contact_finder: contact::ContactFinder::default(),
        };
        simulation.apply_orders();
        simulation
    }

    /// The settings as they were set ([`Simulation::set_settings`]).
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// The settings resolved against the table: the compliances the material gives, the
    /// active families of the table, the rules.
    pub fn resolved(&self) -> &Resolved {
        &self.resolved
    }

    /// The active families of the table ([`Resolved::active`]).
    pub fn active(&self) -> &PerFamily<bool> {
        &self.resolved.active
    }

    /// The contact pairs found at the start of the last frame, [particle, a, b, c]
    /// ([`contact`]); empty when no active family binds to contacts.
    pub fn contact_pairs(&self) -> &[[u32; 4]] {
        &self.state.contacts
    }

    /// The table of families it simulates.
    pub fn families(&self) -> &Families {
        &self.families
    }

    /// Changes the settings; they apply from the next substep. The constraints of a family they
    /// switch on that the simulation has not built yet (one a file added to the table since) are
    /// built, rest values that depend on the material are measured again when it changed, and
    /// the constraints are put in the order a new order seed asks for.
    pub fn set_settings(&mut self, settings: Settings) {
        let reorder = settings.order_seed != self.settings.order_seed;
        self.settings = settings;
        self.resolve();
        if reorder {
            self.apply_orders();
        }
    }

    /// Simulates the families of `families` from now on (the workbench's editor redefines a
    /// constraint file's family as you type): the constraints of a family whose definition
    /// changed are rebuilt, those of an active family new to the table are built, and nothing
    /// else is touched.
    pub fn set_families(&mut self, families: Families) {
        self.families = families;
        self.resolve();
    }

    /// Works out what follows from the settings and the table ([`Resolved`]), and brings the
    /// body's constraints in line with them: built for every active family, rebuilt where the
    /// definition changed, rest values measured again when the material changed.
    fn resolve(&mut self) {
        self.resolved = Resolved::new(&self.settings, &self.families);
        let material = self.settings.material;
        if material != self.measured_with {
            self.measured_with = material;
            let families = self.families.clone();
            let body = self.body_mut();
            for family in families.all() {
                if families.row(family).rest_uses_material {
                    let (rest, bodies) = (&body.rest_positions, &body.bodies);
                    let made_of = (&material, bodies.as_slice());
                    body.sets[family].measure_rest(&families, family, rest, made_of);
                }
            }
        }
        self.rebuild_stale_sets();
    }

    /// Rebuilds the constraints of each family that were built from another definition, and
    /// builds those of an active family that joined the table since the simulation was made.
    /// Allocates only what it builds.
    fn rebuild_stale_sets(&mut self) {
        let stale = self.families.per_family(|family| {
            let set = &self.body.sets[family];
            !set.is_current(&self.families, family) && (set.is_built() || self.active()[family])
        });
        if stale.families().next().is_none() {
            return;
        }
        let mesh = TetMesh {
            positions: self.body.rest_positions.clone(),
            tets: self.body.tets.clone(),
        };
        let (families, settings) = (self.families.clone(), self.settings);
        for family in stale.families() {
            let made_of = (&settings.material, self.body.bodies.as_slice());
            let set = ConstraintSet::new(&families, family, &mesh, made_of);
            let len = set.len();
            self.body_mut().sets[family] = set;
            self.state_mut().lambdas[family] = vec![0.0; len];
        }
        self.apply_orders();
    }

    /// Gives every family's constraints the order [`Settings::order_seed`] asks for. Not an
    /// edit of the body: the order follows from the settings, which every engine reads afresh
    /// each frame.
    fn apply_orders(&mut self) {
        let (families, settings) = (&self.families, &self.settings);
        let sets = &mut self.body.sets;
        for family in families.all() {
            let order = settings.projection_order(family, sets[family].len());
            sets[family].set_order(order);
        }
    }

    /// The state to edit, beside the table and the body it is read with: the one place the
    /// state changes outside an engine's step, so that the [`Revision`] every engine compares
    /// is bumped.
    pub(crate) fn edit(&mut self) -> (&Families, &Body, &mut State) {
        self.revision.state += 1;
        (&self.families, &self.body, &mut self.state)
    }

    /// The state, to edit ([`Simulation::edit`]).
    pub(crate) fn state_mut(&mut self) -> &mut State {
        self.edit().2
    }

    /// The body, to edit ([`Simulation::state_mut`], for the body).
    pub(crate) fn body_mut(&mut self) -> &mut Body {
        self.revision.body += 1;
        &mut self.body
    }

    /// The state: positions, velocities, multipliers, the grab.
    pub fn state(&self) -> &State {
        &self.state
    }

    /// The body: rest positions, tets, masses, constraints, loads.
    pub fn body(&self) -> &Body {
        &self.body
    }

    /// How often the body and the state have been edited.
    pub fn revision(&self) -> Revision {
        self.revision
    }

    /// What an engine would be built from now.
    pub fn start(&self) -> Start<'_> {
        Start {
            families: &self.families,
            resolved: &self.resolved,
            body: &self.body,
            state: &self.state,
            revision: self.revision,
            threads: self.threads,
        }
    }

    /// Current particle positions.
    pub fn positions(&self) -> &[DVec3] {
        &self.state.positions
    }

    /// Rest positions (the scene as made).
    pub fn rest_positions(&self) -> &[DVec3] {
        &self.body.rest_positions
    }

    /// Current particle velocities.
    pub fn velocities(&self) -> &[DVec3] {
        &self.state.velocities
    }

    /// Δp of the last substep, per particle: the position after the constraint projections minus
    /// the predicted position. Zero after a perturbation or a reset, and for a particle placed by
    /// hand, until the next substep.
    pub fn corrections(&self) -> &[DVec3] {
        &self.state.corrections
    }

    /// Inverse masses in use (0 for pinned or grabbed-rigidly particles).
    pub fn inverse_masses(&self) -> &[f64] {
        &self.state.inverse_masses
    }

    /// The bodies of a scene file, which particles and tets are each's; empty for a scene of one
    /// body.
    pub fn bodies(&self) -> &[SceneBody] {
        &self.body.bodies
    }

    /// The tets, as indices into the positions.
    pub fn tets(&self) -> &[[u32; 4]] {
        &self.body.tets
    }

    /// The signed volume of tet `t` at rest, m³ (whether or not a volume constraint is laid on
    /// it).
    pub fn rest_volume(&self, t: usize) -> f64 {
        let rest = &self.body.rest_positions;
        crate::constraints::volume::signed_volume(&self.body.tets[t].map(|i| rest[i as usize]))
    }

    /// The external forces on the particles in N, besides gravity: empty when there are none.
    pub fn forces(&self) -> &[DVec3] {
        &self.body.forces
    }

    /// Whether every particle keeps its z coordinate ([`Simulation::set_plane_strain`]).
    pub fn plane_strain(&self) -> bool {
        self.body.plane_strain
    }

    /// Whether an edit is settling (see [`Settings::settle_edits`]).
    pub fn is_settling(&self) -> bool {
        self.settling.is_some()
    }

    /// Frames stepped since the start.
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// Simulated time in seconds.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Per family, the projections skipped since the start (or the last reset) because ∇C was
    /// undefined or not finite, or because the step would have moved a particle further than
    /// [`crate::simulation::projection::DEFAULT_REACH`] rest edges of its element. Zero for every
    /// built-in family on every scene tetlab ships; a constraint file whose ∇C vanishes where C
    /// does not counts here instead of flinging particles away.
    pub fn skipped(&self) -> &PerFamily<SkipCounts> {
        &self.skipped
    }

    /// h = Δt / substeps.
    pub fn substep_length(&self) -> f64 {
        self.resolved.substep_length()
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
        (SETTLE_SPEED * self.body.mean_edge + self.settings.gravity.abs() * self.settings.dt) * h
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
        self.centre_of_mass_of(positions, 0..positions.len())
    }

    /// [`Simulation::centre_of_mass`] of the particles `particles` alone (one body's).
    pub fn centre_of_mass_of(&self, positions: &[DVec3], particles: Range<usize>) -> DVec3 {
        let mut weighted = DVec3::ZERO;
        let mut mass = 0.0;
        let masses = &self.body.lumped_inverse_masses[particles.clone()];
        for (p, w) in positions[particles].iter().zip(masses) {
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
        self.body.rest_diagonal()
    }

    /// Ok while every coordinate and velocity component is finite and below [`SOUND_LIMIT`] in
    /// size, and what the engine holds of its own is sound ([`Engine::check`]); otherwise the
    /// first that is not. Within the input [`crate::input::limits`] only an instability leaves
    /// that range; front ends check after every frame and stop.
    pub fn check(&self) -> Result<(), Divergence> {
        if let Some((_, engine)) = &self.engine.built {
            engine.check()?;
        }
        Divergence::find(
            self.frame,
            (SOUND_LIMIT, SOUND_LIMIT),
            self.state.positions.iter().map(|p| p.to_array()),
            self.state.velocities.iter().map(|v| v.to_array()),
            |i| i,
        )
    }

    /// Whether [`Simulation::check`] finds nothing.
    pub fn is_sound(&self) -> bool {
        self.check().is_ok()
    }

    /// The bytes of memory the simulation's arrays take (their capacities), its engine's
    /// included.
    pub fn heap_bytes(&self) -> usize {
        self.body.heap_bytes()
            + self.state.heap_bytes()
            + (self.engine.built.as_ref()).map_or(0, |(_, engine)| engine.heap_bytes())
    }

    /// The constraints of `family`: their particles, rest values and order.
    pub fn constraints(&self, family: Family) -> &ConstraintSet {
        &self.body.sets[family]
    }
}

/// Each particle's velocity at the start: its body's in a scene file ([`Scene::bodies`]), 0 for
/// a pinned one; empty for a scene that starts at rest.
fn start_velocities(scene: &Scene) -> Vec<DVec3> {
    if scene.bodies.iter().all(|b| b.velocity == DVec3::ZERO) {
        return Vec::new();
    }
    let mut velocities = vec![DVec3::ZERO; scene.mesh.positions.len()];
    for body in &scene.bodies {
        for i in body.particles.clone() {
            velocities[i as usize] = body.velocity;
        }
    }
    // A pinned particle stays where it is.
    for &i in &scene.pinned {
        velocities[i as usize] = DVec3::ZERO;
    }
    velocities
}
