//! An experiment on XPBD's static bias, written outside the library against its engine
//! interface: the reference engine's stages ([`OnState`]), and after each sweep the positions
//! rebuilt from the multipliers, x = x̃ + W Σ_c ∇C_c(x) λ_c with every gradient taken at the
//! end of the sweep (`passes` fixed-point passes), where XPBD added each correction along the
//! gradient of the moment it was made. At a converged solve the rebuilt positions satisfy the
//! implicit step's stationarity, x − x̃ = W Σ ∇C(x) λ, exactly; XPBD's satisfy it only to first
//! order in how far the gradients turned during the substep.

use glam::DVec3;
use tetlab_core::constraints::differentiable::of_constraint;
use tetlab_core::constraints::{Families, PerFamily};
use tetlab_core::simulation::projection::SkipCounts;
use tetlab_core::simulation::substep::{self, Plan, Substeps};
use tetlab_core::simulation::{Body, Engine, Frame, OnState, Resolved, Start};

/// The reference engine with its positions rebuilt after every sweep.
pub struct Rebuilt {
    /// Fixed-point passes of the rebuild.
    pub passes: usize,
}

impl Rebuilt {
    /// What [`tetlab_core::simulation::Simulation::use_engine`] takes: three passes.
    pub fn build(_: Start<'_>) -> Box<dyn Engine> {
        Box::new(Rebuilt { passes: 3 })
    }
}

impl Engine for Rebuilt {
    fn step(&mut self, frame: Frame<'_>) -> PerFamily<SkipCounts> {
        let plan = Plan::of(&frame);
        let mut stages = Rebuilding {
            on: OnState::new(frame.families, frame.body, frame.state),
            body: frame.body,
            families: frame.families,
            resolved: frame.resolved,
            predicted: Vec::new(),
            passes: self.passes,
        };
        substep::frame(&mut stages, &plan);
        stages.on.skipped()
    }

    fn describe(&self) -> String {
        "rebuilt (f64, a test's)".to_owned()
    }

    fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
        self
    }
}

struct Rebuilding<'a> {
    on: OnState<'a>,
    body: &'a Body,
    families: &'a Families,
    resolved: &'a Resolved,
    predicted: Vec<DVec3>,
    passes: usize,
}

impl Rebuilding<'_> {
    /// x = x̃ + W Σ ∇C(x) λ over every active family, `passes` times.
    fn rebuild(&mut self) {
        let (body, families, active) = (self.body, self.families, self.resolved.active);
        for _ in 0..self.passes {
            let state = self.on.state();
            let mut moved = self.predicted.clone();
            for family in families.all().filter(|&f| active[f]) {
                let set = &body.sets[family];
                for c in 0..set.len() {
                    let lambda = state.lambdas[family][c];
                    if lambda == 0.0 {
                        continue;
                    }
                    let idx = set.particles(c);
                    let rest = (set.rest()[c], set.stored(c));
                    let (value, gradients) = of_constraint(
                        families,
                        family,
                        idx,
                        rest,
                        &state.positions,
                        &body.rest_positions,
                    );
                    if !value.is_finite() || gradients.iter().flatten().any(|g| !g.is_finite()) {
                        continue;
                    }
                    for (&i, g) in idx.iter().zip(&gradients) {
                        let (i, w) = (i as usize, state.inverse_masses[i as usize]);
                        moved[i] += w * lambda * DVec3::from_array(*g);
                    }
                }
            }
            for (i, p) in moved.into_iter().enumerate() {
                if state.inverse_masses[i] > 0.0 {
                    state.positions[i] = p;
                }
            }
        }
    }
}

impl Substeps for Rebuilding<'_> {
    tetlab_core::forward_stages!(on:
        keep_predicted, reset_multipliers, contacts, project, soft_grab, ground_and_plane, keep_corrections,
        update_velocities);

    fn predict(&mut self, plan: &Plan) {
        self.on.predict(plan);
        self.predicted.clone_from(&self.on.state().positions);
    }

    fn hold(&mut self, particle: usize, target: DVec3) {
        self.on.hold(particle, target);
        self.predicted[particle] = target;
    }

    fn sweeps(&mut self, plan: &Plan) {
        for _ in 0..plan.iterations {
            substep::sweep(self, plan);
            self.rebuild();
            self.on.ground_and_plane(plan);
        }
    }
}
