//! How a simulation holds its engine ([`EngineSlot`]): built on the first frame from the settings'
//! choice (or from an engine given by code), built again when the choice changes, and not copied
//! with the simulation. [`build`] is the one place a choice becomes an engine.

use super::EngineChoice;
use super::engine::{Build, Engine, Start};
use super::fast::FastSimulation;
use super::newton::NewtonEngine;
use super::reference::ReferenceEngine;

/// How the engine of `choice` is made; [`EngineChoice::Auto`] is resolved by the size of the
/// scene first ([`EngineChoice::resolve`]).
pub(super) fn build(choice: EngineChoice) -> Build {
    match choice {
        EngineChoice::Auto | EngineChoice::Reference => |_| Box::new(ReferenceEngine),
        EngineChoice::Fast => |start| Box::new(FastSimulation::new(start)),
        EngineChoice::Newton => |_| Box::new(NewtonEngine::default()),
        #[cfg(feature = "gpu")]
        EngineChoice::Gpu => |start| Box::new(super::gpu::GpuEngine::new(start)),
        // A build without the GPU engine (the page) runs the fast one, whose model it is; the
        // front ends offer the choice only where it is available.
        #[cfg(not(feature = "gpu"))]
        EngineChoice::Gpu => |start| Box::new(FastSimulation::new(start)),
    }
}

/// A simulation's engine: which one, and the engine itself once built. A copy of a simulation
/// starts without one: it is built again from the copy's state on its first frame.
#[derive(Default)]
pub(super) struct EngineSlot {
    /// An engine given by code ([`super::Simulation::use_engine`]) instead of the settings'
    /// choice.
    pub(super) given: Option<(Build, &'static str)>,
    /// The engine, and the choice it was built for (`None` for a given one).
    pub(super) built: Option<(Option<EngineChoice>, Box<dyn Engine>)>,
}

impl Clone for EngineSlot {
    fn clone(&self) -> Self {
        EngineSlot {
            given: self.given,
            built: None,
        }
    }
}

impl std::fmt::Debug for EngineSlot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EngineSlot")
            .field("given", &self.given.map(|(_, name)| name))
            .field("built", &self.built.as_ref().map(|(_, e)| e.describe()))
            .finish()
    }
}

impl EngineSlot {
    /// The engine for `choice` (or the given one), built from `start` if it is not yet.
    pub(super) fn ready(&mut self, choice: EngineChoice, start: Start<'_>) -> &mut dyn Engine {
        let wanted = match self.given {
            Some(_) => None,
            None => Some(choice),
        };
        if self
            .built
            .as_ref()
            .is_none_or(|(built, _)| *built != wanted)
        {
            let build = self.given.map_or(build(choice), |(build, _)| build);
            self.built = Some((wanted, build(start)));
        }
        &mut *self.built.as_mut().expect("built above").1
    }
}
