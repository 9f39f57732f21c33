//! How far XPBD's frame is from the exact one ([`ExactStepGap`]): the same frame, from the same
//! state, stepped by the Newton reference ([`crate::simulation::newton`]), which solves every
//! substep's implicit Euler step that XPBD's sweeps approximate. The difference is the solver's
//! error of that frame alone: why a body looks softer with fewer iterations or longer substeps,
//! as a number.

use crate::simulation::newton::NewtonEngine;
use crate::simulation::{EngineChoice, Simulation};

/// XPBD's frame against the exact one from the same start.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ExactStepGap {
    /// max over particles of |x_XPBD − x_exact| at the end of the frame, m.
    pub largest: f64,
    /// [`ExactStepGap::largest`] over the exact frame's largest motion of a particle (0 where
    /// nothing moved).
    pub relative: f64,
    /// Whether the Newton reference solved every substep of the frame to its tolerance (where
    /// it did not, its answer is a local one).
    pub converged: bool,
}

impl ExactStepGap {
    /// The gap between `after`, the state a position-based engine reached from `before` in one
    /// frame, and the state the Newton reference reaches from `before` in the same frame.
    ///
    /// ```
    /// use tetlab_core::measures::exact_step::ExactStepGap;
    /// use tetlab_core::scene::{Builtin, Scene};
    /// use tetlab_core::simulation::{Settings, Simulation};
    /// // A tet at rest on the ground, its rigid edges and volume held: the exact frame keeps it
    /// // where it is; XPBD's, one sweep a substep, lets gravity sag it by its solver's error,
    /// // a fraction of a micrometre.
    /// let scene = Scene::builtin(Builtin::Tet, 1).unwrap();
    /// let mut simulation = Simulation::new(&scene, Settings::default());
    /// let before = simulation.clone();
    /// simulation.step();
    /// let gap = ExactStepGap::measure(&before, &simulation);
    /// assert!(gap.converged && gap.largest > 0.0 && gap.largest < 1e-6, "{gap:?}");
    /// ```
    pub fn measure(before: &Simulation, after: &Simulation) -> ExactStepGap {
        let mut exact = before.clone();
        let mut settings = *exact.settings();
        settings.engine = EngineChoice::Newton;
        exact.set_settings(settings);
        exact.step();
        let converged = exact
            .engine_as::<NewtonEngine>()
            .is_some_and(|newton| newton.unconverged() == 0);
        let largest = (after.positions().iter())
            .zip(exact.positions())
            .map(|(a, b)| a.distance(*b))
            .fold(0.0, f64::max);
        let moved = (before.positions().iter())
            .zip(exact.positions())
            .map(|(a, b)| a.distance(*b))
            .fold(0.0, f64::max);
        ExactStepGap {
            largest,
            relative: if moved > 0.0 { largest / moved } else { 0.0 },
            converged,
        }
    }
}
