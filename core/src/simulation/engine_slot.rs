//! How a simulation holds its engine ([`EngineSlot`]): built on the first frame from the settings'
//! choice (or from an engine given by code), built again when the choice changes, and not copied
//! with the simulation. [`build`] is the one place a choice becomes an engine, and
//! [`EngineChoice::available`] the one place that asks whether it can run here.

use super::EngineChoice;
use super::engine::{Build, Engine, Start};
use super::fast::FastSimulation;
use super::newton::NewtonEngine;
use super::reference::ReferenceEngine;

/// Whether a choice can run here: asked of the engines themselves, so that the list of
/// choices (`engine_choice.rs`, which the settings hold) depends on none of them.
impl EngineChoice {
    /// Whether this choice can run here: every engine but the GPU's always can; that one needs
    /// the feature `gpu` and an adapter (a software one, such as Mesa's lavapipe, will do).
    /// The error says why not, in a line.
    pub fn available(self) -> Result<(), String> {
        match self {
            #[cfg(feature = "gpu")]
            EngineChoice::Gpu => super::gpu::gpu().map(|_| ()),
            #[cfg(not(feature = "gpu"))]
            EngineChoice::Gpu => Err("this build of tetlab has no GPU engine".to_owned()),
            _ => Ok(()),
        }
    }

    /// Whether a test of this engine can run here ([`EngineChoice::available`]); where it
    /// cannot, the test returns early, and this says why on stderr (past the test harness's
    /// capture).
    ///
    /// # Panics
    /// Under CI (`CI=true`), which installs Mesa's software Vulkan, when it cannot.
    pub fn for_test(self) -> bool {
        use std::io::Write;
        let Err(why) = self.available() else {
            return true;
        };
        assert!(
            !crate::input::shared_meshes::in_ci(),
            "CI=true, and the {} engine's tests must run, but it cannot here: {why}",
            self.name()
        );
        let _ = writeln!(
            std::io::stderr(),
            "skipped: the {} engine cannot run here ({why})",
            self.name()
        );
        false
    }
}

/// What the front ends show of `choice`'s engine on `threads` threads before it is built
/// ([`EngineChoice::describe`]), the GPU engine's with its adapter.
pub(super) fn describe(choice: EngineChoice, threads: usize) -> String {
    match choice {
        #[cfg(feature = "gpu")]
        EngineChoice::Gpu => match super::gpu::gpu() {
            Ok(gpu) => format!("gpu (f32, {})", gpu.describe()),
            Err(_) => "gpu (f32, no GPU here)".to_owned(),
        },
        _ => choice.describe(threads),
    }
}

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
