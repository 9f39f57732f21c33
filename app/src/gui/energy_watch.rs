//! The workbench's watch on the energy account: the warning `tetlab run` prints when a body's
//! energy grows ([`EnergyWatch`]), kept frame by frame while the workbench plays, and started
//! afresh wherever energy is given legitimately: an edit of the state or the body, a change of
//! the settings, a particle held by the pointer (its pull does work).
//!
//! Only for bodies of up to [`WATCHED_TETS`] tets: the watch measures how far every rigid
//! constraint is from holding each frame (a C and a ∇C each), which the 100,000-tet block would
//! pay 35 ms a frame for.

use tetlab_core::measures::energy_account::EnergyWatch;
use tetlab_core::simulation::{Revision, Settings, Simulation};

/// The largest body, in tets, whose energy the workbench watches.
pub const WATCHED_TETS: usize = 5_000;

/// A watch, and what it was started under: it holds while these stay as they were.
#[derive(Default)]
pub struct WorkbenchWatch {
    watch: Option<(EnergyWatch, Revision, Settings)>,
}

impl WorkbenchWatch {
    /// Before a frame of `simulation`: (re)starts the watch from the state now where none is
    /// running or what it was started under changed; stops it while a particle is held, and for
    /// a body over [`WATCHED_TETS`].
    pub fn before_frame(&mut self, simulation: &Simulation) {
        let watched = simulation.tets().len() <= WATCHED_TETS && simulation.grabbed().is_none();
        if !watched {
            self.watch = None;
            return;
        }
        let current = |(_, revision, settings): &(EnergyWatch, Revision, Settings)| {
            *revision == simulation.revision() && settings == simulation.settings()
        };
        if !self.watch.as_ref().is_some_and(current) {
            self.watch = Some((
                EnergyWatch::start(simulation),
                simulation.revision(),
                *simulation.settings(),
            ));
        }
    }

    /// After that frame: observed, and the warning where the energy grew past its bound since
    /// the watch started (`None` otherwise, and with no watch).
    pub fn after_frame(&mut self, simulation: &Simulation) -> Option<String> {
        let (watch, revision, _) = self.watch.as_mut()?;
        if *revision != simulation.revision() {
            // The frame edited something (a divergence put the body back at rest).
            self.watch = None;
            return None;
        }
        watch.observe(simulation, simulation.frame());
        watch
            .lines()
            .into_iter()
            .find(|line| line.starts_with("warning: the energy grew"))
    }

    /// Forgets the watch (the scene was loaded again or reset).
    pub fn stop(&mut self) {
        self.watch = None;
    }
}
