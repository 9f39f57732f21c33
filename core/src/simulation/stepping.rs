//! How a simulation moves: a frame on its engine ([`Simulation::step`]), which engine that is
//! and on how many threads, and a substep taken stage by stage on the reference engine
//! (step-by-step mode: [`Simulation::begin_substep`], [`Simulation::project`],
//! [`Simulation::end_sweep`], [`Simulation::end_substep`]), the same stages
//! [`super::substep::frame`] runs.

use super::engine::{Build, Engine, Frame};
use super::reference::OnState;
use super::substep::{self, Plan, Substeps};
use super::{EngineChoice, Simulation};
use crate::constraints::Family;
use glam::DVec3;

impl Simulation {
    /// Advances one frame: `substeps` substeps of Δt / substeps, on the engine of
    /// [`Simulation::engine`].
    ///
    /// On an engine that does not wait for the GPU (the GPU engine in a page), a call may only
    /// start the frame: then [`Simulation::pending`] is true, nothing has changed, and a later
    /// call finishes it ([`Engine::pending`]).
    pub fn step(&mut self) {
        self.refresh_inverse_masses();
        // A frame under way keeps the last Δp on show until it lands (and writes its own).
        if !self.pending() {
            self.state.frame_corrections.fill(DVec3::ZERO);
        }
        self.find_contacts();
        if self.frame == 0 && self.settling.is_none() && self.starts_inside_the_layer() {
            // Set down with a particle inside the thickness of a surface: contact moves it out
            // of the layer, bending its body, whose constraints would undo the bend with speed
            // (contact's `project` module docs). The start settles as an edit does.
            self.settling = Some(0);
        }
        self.hold_off_settling();
        let settling = self.edits_settle_now();
        // The slot is taken out while its engine steps the rest of the simulation.
        let mut slot = std::mem::take(&mut self.engine);
        let engine = slot.ready(self.engine(), self.start());
        let skipped = engine.step(Frame {
            families: &self.families,
            resolved: &self.resolved,
            body: &self.body,
            state: &mut self.state,
            revision: self.revision,
            threads: self.threads,
            settling,
        });
        let pending = engine.pending();
        self.engine = slot;
        if pending {
            return;
        }
        for family in self.families.all() {
            self.skipped[family] = self.skipped[family] + skipped[family];
        }
        if let Some(grab) = &mut self.state.grab {
            grab.target_velocity = (grab.target - grab.target_at_last_step) / self.settings.dt;
            grab.target_at_last_step = grab.target;
        }
        if let Some(frames) = self.settling {
            let largest = self.largest_frame_correction();
            let settles = self.resolved.edits_settle();
            // Held off, the edit is still to settle, whatever the frame's Δp.
            let unsettled = self.settling_held_off || largest > self.settle_tolerance();
            self.settling = (settles && unsettled).then_some(frames + 1);
        }
        self.frame += 1;
        self.time += self.settings.dt;
    }

    /// Whether a frame [`Simulation::step`] started is still under way (the GPU engine in a
    /// page): the state is the one before it until a later `step` finishes it.
    pub fn pending(&self) -> bool {
        (self.engine.built.as_ref()).is_some_and(|(_, engine)| engine.pending())
    }

    /// The contact pairs of the coming frame, from where the particles are and how fast they
    /// move ([`super::contact::ContactFinder`]), into the state; none when no active family
    /// binds to contacts. Not an edit: the pairs are read afresh every frame.
    fn find_contacts(&mut self) {
        use super::contact::{Reach, contact_families};
        if contact_families(&self.families, &self.resolved.active)
            .next()
            .is_none()
        {
            if !self.state.contacts.is_empty() {
                self.state.contacts = std::sync::Arc::default();
            }
            return;
        }
        let reach = Reach {
            thickness: self.settings.contact.thickness,
            dt: self.settings.dt,
            gravity: self.settings.gravity,
        };
        let surface = self.body.contact_surface();
        let state = &mut self.state;
        let found = (self.contact_finder).find(surface, &state.positions, &state.velocities, reach);
        let contacts = std::sync::Arc::make_mut(&mut state.contacts);
        contacts.clear();
        super::contact::keep_room(contacts, found.len().max(surface.particles.len()));
        contacts.extend_from_slice(found);
    }

    /// Whether some contact pair found for the coming frame has its particle over its triangle
    /// and closer to it than the thickness d (C < 0 by the built-in contact's formula).
    fn starts_inside_the_layer(&self) -> bool {
        let thickness = self.settings.contact.thickness;
        let positions = &self.state.positions;
        (self.state.contacts.iter()).any(|&pair| {
            super::contact::over_and_closing(positions, pair, thickness).is_some_and(|c| c < 0.0)
        })
    }

    /// Gives each particle its inverse mass (the lumped one, 0 where pinned or rigidly held):
    /// an edit of the state where one changed (a pin, a grab, the grab's compliance set to 0).
    pub(super) fn refresh_inverse_masses(&mut self) {
        let rigid = self.settings.grab_compliance <= 0.0;
        let wanted = |s: &Simulation, i: usize| s.state.wanted_inverse_mass(&s.body, i, rigid);
        let n = self.state.inverse_masses.len();
        if (0..n).any(|i| wanted(self, i) != self.state.inverse_masses[i]) {
            let (_, body, state) = self.edit();
            for i in 0..n {
                state.inverse_masses[i] = state.wanted_inverse_mass(body, i, rigid);
            }
        }
    }

    /// The engine the settings choose for this simulation: [`Settings::engine`](super::Settings::engine),
    /// with [`EngineChoice::Auto`] resolved by the size of the scene. An engine given by code
    /// ([`Simulation::use_engine`]) steps it instead; [`Simulation::describe_engine`] names
    /// the one that does.
    pub fn engine(&self) -> EngineChoice {
        self.settings.engine.resolve(self.body.tets.len())
    }

    /// "reference (f64)" or "fast (f32, 2 threads)": what the front ends show.
    pub fn describe_engine(&self) -> String {
        match (&self.engine.built, self.engine.given) {
            (Some((_, engine)), Some(_)) => engine.describe(),
            // The GPU engine says what it found: its adapter, or why a frame ran on the CPU.
            (Some((Some(super::EngineChoice::Gpu), engine)), None)
                if self.settings.engine == super::EngineChoice::Gpu =>
            {
                engine.describe()
            }
            (None, Some((_, name))) => name.to_owned(),
            _ => super::engine_slot::describe(self.engine(), self.threads),
        }
    }

    /// Steps this simulation on the engine `build` makes (named `name` until it is built)
    /// rather than the settings' choice: an engine that is not one of tetlab's own (a test's).
    pub fn use_engine(&mut self, build: Build, name: &'static str) {
        self.engine.given = Some((build, name));
        self.engine.built = None;
    }

    /// The engine, built (and ready for the next frame) if it was not, as an `E` when it is one:
    /// for `tetlab bench`, which times the fast engine and reads its per-family timings.
    pub fn engine_as<E: Engine + 'static>(&mut self) -> Option<&mut E> {
        let mut slot = std::mem::take(&mut self.engine);
        slot.ready(self.engine(), self.start());
        self.engine = slot;
        let (_, engine) = self.engine.built.as_mut()?;
        engine.as_any_mut().downcast_mut::<E>()
    }

    /// The threads an engine uses.
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Sets the threads an engine may use (1 without the `parallel` feature, where every count
    /// is 1); the results are the same bits for any count.
    pub fn set_threads(&mut self, threads: usize) {
        self.threads = if cfg!(feature = "parallel") {
            threads.max(1)
        } else {
            1
        };
    }

    /// The plan of a substep taken stage by stage: a frame's (every stage tracks Δp).
    fn stage_plan(&self) -> Plan {
        let grab = self.state.grab.map(|g| (g.particle, g.target));
        let plane_strain = self.body.plane_strain;
        let settling = self.edits_settle_now();
        let mut plan = Plan::new(&self.families, &self.resolved, plane_strain, grab, settling);
        plan.contact =
            super::contact::ContactPlan::new(&self.families, &self.resolved, &self.state.contacts);
        plan
    }

    /// Runs `stage` on the reference engine's view of the state: an edit of the state, as far as
    /// another engine is concerned.
    fn on_state<T>(&mut self, stage: impl FnOnce(&mut OnState<'_>, &Plan) -> T) -> T {
        let plan = self.stage_plan();
        let (families, body, state) = self.edit();
        let mut on = OnState::new(families, body, state);
        let out = stage(&mut on, &plan);
        let skipped = on.skipped;
        for family in self.families.all() {
            self.skipped[family] = self.skipped[family] + skipped[family];
        }
        out
    }

    /// One substep on the reference engine: [`Simulation::begin_substep`], `iterations` sweeps
    /// ([`Simulation::project`] of every constraint of [`Simulation::projection_order`], then
    /// `Simulation::end_sweep`), `Simulation::end_substep`: done here in tight loops. Like
    /// [`Simulation::begin_substep`], it finds the contact pairs afresh first.
    pub fn substep(&mut self) {
        self.hold_off_settling();
        self.find_contacts();
        self.on_state(|on, plan| {
            substep::begin_substep(on, plan, true);
            on.sweeps(plan);
            substep::end_substep(on, plan, true);
        });
    }

    /// The first stage of a substep: predict positions, and (XPBD) λ = 0 for every constraint.
    pub fn begin_substep(&mut self) {
        self.hold_off_settling();
        self.find_contacts();
        self.on_state(|on, plan| substep::begin_substep(on, plan, true));
    }

    /// Projects constraint `c` of `family` once, exactly as a sweep does (with its partner, if it
    /// leads a pair).
    ///
    /// For a family that binds to contacts, `c` is a pair of [`Simulation::contact_pairs`],
    /// projected as the sweep's contact pass projects it.
    pub fn project(&mut self, family: Family, c: usize) {
        if self.families.binding(family) == crate::constraints::Binding::Contacts {
            self.on_state(|on, plan| on.project_contact(family, c, plan));
            return;
        }
        let unit = self.families.unit_of(family, self.active());
        self.on_state(|on, plan| on.project_one(unit, c, plan));
    }

    /// The end of one sweep, after the constraint families and the contacts, which step-by-step
    /// mode projects one at a time: the grab, then the ground y ≥ 0.
    pub(crate) fn end_sweep(&mut self) {
        self.on_state(|on, plan| substep::close_sweep(on, plan));
    }

    /// The last stage of a substep: Δp = x − predicted x, then velocities from the positions.
    pub(crate) fn end_substep(&mut self) {
        self.on_state(|on, plan| substep::end_substep(on, plan, true));
    }
}
