//! Which solver steps a [`Simulation`]: the reference one (f64, one constraint at a time, the
//! teaching path) or the fast one ([`crate::simulation::fast`]: f32, coloured, eight constraints per SIMD
//! register, on threads), chosen per simulation ([`Settings::engine`]).
//!
//! The simulation's own arrays (f64, the scene's numbering) stay the state every front end
//! reads: after each frame on the fast engine its positions, velocities and Δp are written back
//! (one pass over the particles, no allocation). An edit (a perturbation, a particle placed or
//! pinned, a grab, a step made one projection at a time) changes those arrays; the fast engine
//! takes them up before its next frame. So step-by-step mode and the inspector, which need the
//! reference path's per-constraint detail, work on either engine: entering them carries the
//! state across, leaving carries it back.

use super::{Engine, Settings, Simulation};
use crate::simulation::fast::{FastSimulation, FrameInputs, Start};

/// The fast engine of a simulation, built when it is first needed. A copy of a simulation
/// starts without one (it is rebuilt from the copy's state on its first fast frame).
#[derive(Default)]
pub(super) struct FastEngine {
    pub(super) solver: Option<Box<FastSimulation>>,
    /// Whether the solver holds the simulation's current state (no edit since its last frame).
    pub(super) current: bool,
}

impl Clone for FastEngine {
    fn clone(&self) -> Self {
        FastEngine::default()
    }
}

impl std::fmt::Debug for FastEngine {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FastEngine")
            .field("built", &self.solver.is_some())
            .field("current", &self.current)
            .finish()
    }
}

impl FastEngine {
    /// Something changed the simulation's state: the solver takes it up before its next frame.
    pub(super) fn edited(&mut self) {
        self.current = false;
    }

    /// The settings changed: a new solver when the active families or the material changed
    /// (its constraints are built for them), the same one with the new settings otherwise.
    pub(super) fn set_settings(&mut self, old: &Settings, new: &Settings) {
        if old.active != new.active || old.material != new.material {
            self.solver = None;
        } else if let Some(solver) = &mut self.solver {
            solver.set_settings(*new);
        }
    }
}

impl Simulation {
    /// The engine that steps this simulation: [`Settings::engine`], with [`Engine::Auto`]
    /// resolved by the size of the scene.
    pub fn engine(&self) -> Engine {
        self.settings.engine.resolve(self.tets.len())
    }

    /// "reference (f64)" or "fast (f32, 2 threads)": what the front ends show.
    pub fn describe_engine(&self) -> String {
        match self.engine() {
            Engine::Fast => {
                let threads = self.threads;
                let s = if threads == 1 { "" } else { "s" };
                format!("fast (f32, {threads} thread{s})")
            }
            _ => "reference (f64)".to_owned(),
        }
    }

    /// The threads the fast engine uses.
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Sets the threads the fast engine uses (1 without the `parallel` feature, where every
    /// count is 1); the results are the same bits for any count.
    pub fn set_threads(&mut self, threads: usize) {
        let threads = if cfg!(feature = "parallel") {
            threads.max(1)
        } else {
            1
        };
        if threads != self.threads {
            self.threads = threads;
            self.fast.solver = None;
        }
    }

    /// The fast engine, built (and brought up to the current state) if it was not: for
    /// `tetlab bench`, which times it and reads its per-family timings.
    pub fn fast_solver(&mut self) -> &mut FastSimulation {
        self.ready_fast();
        self.fast.solver.as_mut().expect("made ready above")
    }

    /// What a fast solver starts from: this simulation's state, settings and constraints.
    pub fn fast_start(&self) -> Start<'_> {
        Start {
            settings: &self.settings,
            positions: &self.positions,
            velocities: &self.velocities,
            inverse_masses: &self.inverse_masses,
            rest_positions: &self.rest_positions,
            forces: &self.forces,
            tets: &self.tets,
            families: &self.families,
            constraints: &self.sets,
            plane_strain: self.plane_strain,
        }
    }

    /// Builds the fast engine if there is none, and gives it the current state if it lacks it.
    fn ready_fast(&mut self) {
        if self.fast.solver.is_none() {
            self.fast.solver = Some(Box::new(FastSimulation::new(
                self.fast_start(),
                self.threads,
            )));
            self.fast.current = true;
        }
        if !self.fast.current {
            let solver = self.fast.solver.as_mut().expect("built above");
            solver.load(&self.positions, &self.velocities, &self.inverse_masses);
            self.fast.current = true;
        }
    }

    /// One frame on the fast engine: it takes up the state if an edit changed it, steps with
    /// the grab and the settling of an edit, and writes positions, velocities and Δp back.
    pub(super) fn step_fast(&mut self) {
        self.ready_fast();
        let inputs = FrameInputs {
            grab: self
                .grab
                .map(|g| (g.particle, g.target, self.settings.grab_compliance)),
            settling: self.settings.edits_settle() && self.settling.is_some(),
            corrections: true,
        };
        let solver = self.fast.solver.as_mut().expect("made ready above");
        solver.step_frame(&inputs);
        let skipped = solver.take_skipped();
        for family in self.families.all() {
            let counts = skipped[family];
            self.skipped[family] = self.skipped[family] + counts;
        }
        solver.store(
            &mut self.positions,
            &mut self.velocities,
            Some((&mut self.corrections, &mut self.frame_corrections)),
        );
    }
}
