//! The seam every engine plugs into: an [`Engine`] is built from a simulation's table, settings,
//! body and state ([`Start`]) and steps a frame of its state ([`Frame`]); the simulation owns the
//! state, and every front end reads it there, whichever engine stepped it.
//!
//! An engine never hears of an edit by a call: each frame brings the simulation's [`Revision`],
//! and an engine that keeps a copy of the state (the fast engine's f32 arrays, in its own
//! numbering) compares it with the one it last saw and takes the state up again, or builds
//! itself again when the body changed. Edits, inspection, metrics, the GUI, the recorder and
//! lessons never name an engine: adding one is its module, its entry among the choices
//! ([`super::EngineChoice`], `engine_choice.rs`) and how it is built (`engine_slot.rs`;
//! docs/architecture.md, "Adding an engine").
//!
//! The CPU engines share the substep's skeleton ([`super::substep`]); an engine that runs the
//! whole frame elsewhere implements [`Engine::step`] itself.

use super::Resolved;
use super::state::{Body, Revision, State};
use crate::constraints::{Families, PerFamily};
use crate::simulation::divergence::Divergence;
use crate::simulation::projection::SkipCounts;

/// A solver that steps a simulation's state a frame at a time.
pub trait Engine: Send {
    /// Advances `frame.state` by one frame (`substeps` substeps of Δt / substeps), and returns
    /// per family the projections it skipped for a counted reason
    /// ([`crate::simulation::projection::Skipped`]).
    fn step(&mut self, frame: Frame<'_>) -> PerFamily<SkipCounts>;

    /// Whether the frame the last [`Engine::step`] began is still under way. An engine that
    /// cannot wait for its results (the GPU engine in a page: a browser hands a GPU's results
    /// over only between two of the page's frames) returns from `step` once the frame is
    /// started, with the state as it was, and finishes it in a later `step` of the same frame;
    /// [`super::Simulation::step`] counts the frame only then. Every other engine finishes a
    /// frame in the call that began it.
    fn pending(&self) -> bool {
        false
    }

    /// What the front ends show: "reference (f64)", "fast (f32, 2 threads)".
    fn describe(&self) -> String;

    /// Ok while what the engine holds of its own is sound (the fast engine's f32 coordinates
    /// within [`crate::simulation::fast::POSITION_LIMIT`]); the simulation checks its f64 state
    /// itself.
    fn check(&self) -> Result<(), Divergence> {
        Ok(())
    }

    /// The bytes of memory its own arrays take.
    fn heap_bytes(&self) -> usize {
        0
    }

    /// The engine as [`std::any::Any`], for a tool that knows which engine it asks
    /// (`tetlab bench` reads the fast engine's timings: [`super::Simulation::engine_as`]).
    fn as_any_mut(&mut self) -> &mut dyn std::any::Any;
}

/// What an engine is built from: the simulation's table, settings, body and state, read-only.
#[derive(Clone, Copy)]
pub struct Start<'a> {
    /// The table of families.
    pub families: &'a Families,
    /// The settings, resolved against the table.
    pub resolved: &'a Resolved,
    /// The body.
    pub body: &'a Body,
    /// The state now.
    pub state: &'a State,
    /// How often the body and state have been edited so far.
    pub revision: Revision,
    /// The threads an engine may use (1 without the `parallel` feature).
    pub threads: usize,
}

/// One frame for an engine to step.
pub struct Frame<'a> {
    /// The table of families.
    pub families: &'a Families,
    /// The settings, resolved against the table.
    pub resolved: &'a Resolved,
    /// The body.
    pub body: &'a Body,
    /// The state, to advance.
    pub state: &'a mut State,
    /// How often the body and state have been edited, up to this frame.
    pub revision: Revision,
    /// The threads an engine may use.
    pub threads: usize,
    /// Whether an edit settles this frame ([`super::Settings::settle_edits`]): corrections may
    /// move particles but not speed them up, and Δp is summed over the frame.
    pub settling: bool,
}

impl Frame<'_> {
    /// What the engine would be built from now.
    pub fn start(&self) -> Start<'_> {
        Start {
            families: self.families,
            resolved: self.resolved,
            body: self.body,
            state: self.state,
            revision: self.revision,
            threads: self.threads,
        }
    }
}

/// How an engine is made from a simulation.
pub type Build = fn(Start<'_>) -> Box<dyn Engine>;
