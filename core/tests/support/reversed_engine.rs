//! A third engine, written outside the library against its engine interface alone: the
//! reference engine's stages ([`OnState`]), except that each sweep projects every family's
//! constraints in the reverse of the order the reference engine uses. It touches no edit, no
//! inspection, no metric: the simulation owns the state and hands it over a frame at a time,
//! which is what the engine matrix and the seam's tests show by running it beside the two
//! engines tetlab ships.

use tetlab_core::constraints::{PerFamily, Unit};
use tetlab_core::simulation::projection::SkipCounts;
use tetlab_core::simulation::substep::{self, Plan, Substeps};
use tetlab_core::simulation::{Body, Engine, Frame, OnState, Start};

/// The reference engine's substep with every sweep's order reversed.
#[derive(Default)]
pub struct Reversed {
    /// Frames it stepped, and the revisions of the body and state it saw at each.
    pub seen: Vec<(u64, u64)>,
}

impl Reversed {
    /// What [`tetlab_core::simulation::Simulation::use_engine`] takes.
    pub fn build(_: Start<'_>) -> Box<dyn Engine> {
        Box::new(Reversed::default())
    }
}

impl Engine for Reversed {
    fn step(&mut self, frame: Frame<'_>) -> PerFamily<SkipCounts> {
        self.seen.push((frame.revision.body, frame.revision.state));
        let grab = frame.state.grab.map(|g| (g.particle, g.target));
        let plane_strain = frame.body.plane_strain;
        let plan = Plan::new(
            frame.families,
            frame.resolved,
            plane_strain,
            grab,
            frame.settling,
        );
        let mut stages = Backwards {
            on: OnState::new(frame.families, frame.body, frame.state),
            body: frame.body,
        };
        substep::frame(&mut stages, &plan);
        stages.on.skipped()
    }

    fn describe(&self) -> String {
        "reversed (f64, a test's)".to_owned()
    }

    fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
        self
    }
}

/// The reference engine's stages, every sweep walked backwards.
struct Backwards<'a> {
    on: OnState<'a>,
    body: &'a Body,
}

impl Substeps for Backwards<'_> {
    tetlab_core::forward_stages!(on:
        predict, hold, keep_predicted, reset_multipliers, contacts, soft_grab, ground_and_plane,
        keep_corrections, update_velocities);

    fn project(&mut self, unit: Unit, plan: &Plan) {
        let set = &self.body.sets[unit.lead];
        for k in (0..set.len()).rev() {
            self.on.project_one(unit, set.in_order(k), plan);
        }
    }
}
