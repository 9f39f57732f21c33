//! Which solver steps a [`Simulation`]: the reference one (f64, one constraint at a time, the
//! teaching path) or the fast one ([`crate::fast`]: f32, coloured, eight constraints per SIMD
//! register, on threads), chosen per simulation ([`Settings::engine`]).
//!
//! The simulation's own arrays (f64, the scene's numbering) stay the state every front end
//! reads: after each frame on the fast engine its positions, velocities and Δp are written back
//! (one pass over the particles, no allocation). An edit (a perturbation, a particle placed or
//! pinned, a grab, a step made one projection at a time) changes those arrays; the fast engine
//! takes them up before its next frame. So step-by-step mode and the inspector, which need the
//! reference path's per-constraint detail, work on either engine: entering them carries the
//! state across, leaving carries it back.

use super::{Settings, Simulation};
use crate::fast::{FastSimulation, FrameInputs};

/// Which solver steps a simulation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Engine {
    /// The reference solver for scenes of fewer than [`FAST_FROM_TETS`] tets, the fast one
    /// from there.
    #[default]
    Auto,
    /// The f64 solver, one constraint at a time: exact to f64, and the one step-by-step mode
    /// walks through.
    Reference,
    /// The f32 solver in SIMD lanes and on threads: several times faster on a real mesh.
    Fast,
}

/// The size from which [`Engine::Auto`] picks the fast engine. The reference solver's frame
/// grows with the tets, about 19 µs a tet at the default 100 substeps with edges + volume (the
/// 384-tet cube: 7.3 ms a frame; the 1351-tet bunny: 24 ms, where the fast engine takes 4.1;
/// docs/performance.md): from about 900 tets it no longer holds 60 frames a second. The built-in
/// teaching scenes and every lesson's scene but the bunny stay below it, on the exact path.
pub const FAST_FROM_TETS: usize = 1000;

impl Engine {
    /// `auto`, `reference` or `fast`.
    ///
    /// ```
    /// use tetlab_core::solver::Engine;
    /// assert_eq!(Engine::parse("fast"), Ok(Engine::Fast));
    /// assert!(Engine::parse("gpu").unwrap_err().contains("auto, reference or fast"));
    /// ```
    pub fn parse(text: &str) -> Result<Engine, String> {
        match text.trim() {
            "auto" => Ok(Engine::Auto),
            "reference" => Ok(Engine::Reference),
            "fast" => Ok(Engine::Fast),
            other => Err(format!(
                "'{other}' is not an engine: expected auto, reference or fast"
            )),
        }
    }

    /// The name [`Engine::parse`] reads.
    pub fn name(self) -> &'static str {
        match self {
            Engine::Auto => "auto",
            Engine::Reference => "reference",
            Engine::Fast => "fast",
        }
    }

    /// The engine this choice runs a scene of `tets` tets on: [`Engine::Reference`] or
    /// [`Engine::Fast`].
    ///
    /// ```
    /// use tetlab_core::solver::{Engine, FAST_FROM_TETS};
    /// assert_eq!(Engine::Auto.resolve(162), Engine::Reference);
    /// assert_eq!(Engine::Auto.resolve(FAST_FROM_TETS), Engine::Fast);
    /// assert_eq!(Engine::Reference.resolve(100_000), Engine::Reference);
    /// ```
    pub fn resolve(self, tets: usize) -> Engine {
        match self {
            Engine::Auto if tets >= FAST_FROM_TETS => Engine::Fast,
            Engine::Auto => Engine::Reference,
            chosen => chosen,
        }
    }
}

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
        self.refresh_families();
        self.ready_fast();
        self.fast.solver.as_mut().expect("made ready above")
    }

    /// Builds the fast engine if there is none, and gives it the current state if it lacks it.
    fn ready_fast(&mut self) {
        if self.fast.solver.is_none() {
            self.fast.solver = Some(Box::new(FastSimulation::new(self, self.threads)));
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
        self.refresh_families();
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
        for (family, counts) in solver.take_skipped().iter() {
            self.skipped[family] = self.skipped[family] + counts;
        }
        solver.store(
            &mut self.positions,
            &mut self.velocities,
            Some((&mut self.corrections, &mut self.frame_corrections)),
        );
    }
}
