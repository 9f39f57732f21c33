//! The substep of XPBD/PBD, written once for every CPU engine ([`frame`]): each engine says how it
//! predicts, projects and integrates its own arrays ([`Substeps`]); the order of the stages is
//! here, and only here.
//!
//! One substep of length h = Δt / substeps:
//! 1. predict: v += g h, x_prev = x, x += v h; a particle predicted below the ground is put back
//!    at its previous position, on the ground (sticking friction); a rigidly held particle is
//!    put at its target;
//! 2. XPBD only: λ = 0 for every constraint;
//! 3. `iterations` Gauss–Seidel sweeps over what the active families project ([`Plan::units`]:
//!    each family alone, or a pair together), in the table's order, then the compliant grab, the
//!    ground y ≥ 0 and the plane-strain hold;
//! 4. Δp = x − predicted x (kept when asked), then v = (x − x_prev) / h, damped; while an edit
//!    settles, |v| is also capped at the predicted speed.
//!
//! Step-by-step mode walks the same stages ([`begin_substep`], one projection at a time,
//! [`end_sweep`], [`end_substep`]) on the reference engine, so a substep taken one projection at
//! a time gives the bits of one taken at once. An engine written outside the library may run
//! the same skeleton: implement [`Substeps`], or wrap the reference engine's
//! ([`super::OnState`]) and change what it does at one stage.

use super::contact::ContactPlan;
use super::engine::Frame;
pub use super::integrate::Substep as Motion;
use super::projection::{Rule, correct};
use super::resolved::Resolved;
use crate::constraints::{Families, MAX_FAMILIES, PerFamily, Unit, distance};
use crate::numbers::vector::{Mask, Real, Vector3};
use arrayvec::ArrayVec;
use glam::DVec3;

/// What a frame's substeps are to do, worked out once a frame from the settings and the inputs.
#[derive(Clone, Debug)]
pub struct Plan {
    /// Substeps in the frame, ≥ 1.
    pub substeps: u32,
    /// Sweeps per substep, ≥ 1.
    pub iterations: u32,
    /// The substep's length h.
    pub h: f64,
    /// Gravity, the ground and plane strain, for the prediction.
    pub motion: Motion,
    /// Velocity damping per second.
    pub damping: f64,
    /// What one sweep projects, in order.
    pub units: ArrayVec<Unit, MAX_FAMILIES>,
    /// The rule each family is projected by.
    pub rules: PerFamily<Rule<f64>>,
    /// How far one projection may move a particle, in rest edges of its element.
    pub reach: f64,
    /// A particle held rigidly at a target (it moves with the target; its inverse mass is 0).
    pub rigid_grab: Option<(usize, DVec3)>,
    /// A particle pulled towards a target by a compliant constraint: the particle, the target,
    /// the compliance.
    pub soft_grab: Option<(usize, DVec3, f64)>,
    /// Whether an edit settles: velocities are capped and Δp summed over every substep.
    pub settling: bool,
    /// Whether to keep Δp of the frame's last substep.
    pub keep_corrections: bool,
    /// What the sweeps project of contact, when a family that binds to contacts is active.
    pub contact: Option<ContactPlan>,
}

impl Plan {
    /// The plan of a frame under `resolved`, for a body held in plane strain or not, with a
    /// particle held at a target, if one is (`grab`: the particle and where it is held), and
    /// `settling` when an edit settles.
    pub fn new(
        families: &Families,
        resolved: &Resolved,
        plane_strain: bool,
        grab: Option<(usize, DVec3)>,
        settling: bool,
    ) -> Plan {
        let settings = &resolved.settings;
        let h = resolved.substep_length();
        let compliance = settings.grab_compliance;
        Plan {
            substeps: settings.substeps.max(1),
            iterations: settings.iterations.max(1),
            h,
            motion: Motion {
                gravity: settings.gravity,
                h,
                ground: settings.ground.then_some(0.0),
                plane_strain,
            },
            damping: settings.damping,
            units: families.units(&resolved.active).collect(),
            rules: families.per_family(|f| resolved.rule(f, h)),
            reach: settings.reach,
            rigid_grab: grab.filter(|_| compliance <= 0.0),
            soft_grab: grab
                .filter(|_| compliance > 0.0)
                .map(|(particle, target)| (particle, target, compliance)),
            settling,
            keep_corrections: true,
            contact: None,
        }
    }

    /// The plan of `frame`: its settings, the grab the state holds, the body's plane strain,
    /// whether an edit settles; Δp of the last substep kept.
    pub fn of(frame: &Frame<'_>) -> Plan {
        let grab = frame.state.grab.map(|g| (g.particle, g.target));
        let (families, resolved) = (frame.families, frame.resolved);
        let mut plan = Plan::new(
            families,
            resolved,
            frame.body.plane_strain,
            grab,
            frame.settling,
        );
        plan.contact = ContactPlan::new(families, resolved, &frame.state.contacts);
        plan
    }

    /// Whether substep `substep` (from 0) keeps its Δp: every one while an edit settles (their
    /// sum is the measure of "settled"), otherwise the frame's last, when asked.
    pub fn tracks(&self, substep: u32) -> bool {
        self.settling || (self.keep_corrections && substep + 1 == self.substeps)
    }
}

/// The stages of [`Substeps`] an engine that wraps the reference engine's ([`super::OnState`],
/// in the field named first) leaves to it, each forwarded as is: write the stages it changes
/// by hand and list the others here.
///
/// ```text
/// impl Substeps for Backwards<'_> {
///     tetlab_core::forward_stages!(on: predict, hold, keep_predicted, reset_multipliers,
///         soft_grab, ground_and_plane, keep_corrections, update_velocities);
///     fn project(&mut self, unit: Unit, plan: &Plan) { /* its own order */ }
/// }
/// ```
#[macro_export]
macro_rules! forward_stages {
    ($on:ident: $($stage:ident),+ $(,)?) => {
        $($crate::forward_stages!(@stage $on $stage);)+
    };
    (@stage $on:ident predict) => {
        fn predict(&mut self, plan: &$crate::simulation::substep::Plan) {
            self.$on.predict(plan);
        }
    };
    (@stage $on:ident hold) => {
        fn hold(&mut self, particle: usize, target: ::glam::DVec3) {
            self.$on.hold(particle, target);
        }
    };
    (@stage $on:ident keep_predicted) => {
        fn keep_predicted(&mut self) {
            self.$on.keep_predicted();
        }
    };
    (@stage $on:ident reset_multipliers) => {
        fn reset_multipliers(&mut self, plan: &$crate::simulation::substep::Plan) {
            self.$on.reset_multipliers(plan);
        }
    };
    (@stage $on:ident project) => {
        fn project(
            &mut self,
            unit: $crate::constraints::Unit,
            plan: &$crate::simulation::substep::Plan,
        ) {
            self.$on.project(unit, plan);
        }
    };
    (@stage $on:ident contacts) => {
        fn contacts(&mut self, plan: &$crate::simulation::substep::Plan) {
            self.$on.contacts(plan);
        }
    };
    (@stage $on:ident soft_grab) => {
        fn soft_grab(&mut self, particle: usize, target: ::glam::DVec3, compliance: f64, h: f64) {
            self.$on.soft_grab(particle, target, compliance, h);
        }
    };
    (@stage $on:ident ground_and_plane) => {
        fn ground_and_plane(&mut self, plan: &$crate::simulation::substep::Plan) {
            self.$on.ground_and_plane(plan);
        }
    };
    (@stage $on:ident keep_corrections) => {
        fn keep_corrections(&mut self) {
            self.$on.keep_corrections();
        }
    };
    (@stage $on:ident update_velocities) => {
        fn update_velocities(&mut self, plan: &$crate::simulation::substep::Plan) {
            self.$on.update_velocities(plan);
        }
    };
}

/// What a CPU engine does at each stage of a substep, on its own arrays.
pub trait Substeps {
    /// Before the frame's first substep (the fast engine moves its origin to the body).
    fn begin_frame(&mut self, plan: &Plan) {
        let _ = plan;
    }
    /// x_prev = x, then v += (g + w f) h and x += v h for every free particle, the ground's
    /// sticking friction and the plane-strain hold on v (`integrate::predict`).
    fn predict(&mut self, plan: &Plan);
    /// Puts `particle` at `target` (a rigid grab, after the prediction).
    fn hold(&mut self, particle: usize, target: DVec3);
    /// Keeps the predicted positions, which Δp is measured from.
    fn keep_predicted(&mut self);
    /// λ = 0 for every constraint of the active families, and for the compliant grab.
    fn reset_multipliers(&mut self, plan: &Plan);
    /// Projects every constraint of `unit`, in the engine's order.
    fn project(&mut self, unit: Unit, plan: &Plan);
    /// What a substep does between its start and its end: `iterations` Gauss–Seidel [`sweep`]s.
    /// An engine that solves the substep's system another way (the Newton reference) does it
    /// here instead.
    fn sweeps(&mut self, plan: &Plan)
    where
        Self: Sized,
    {
        for _ in 0..plan.iterations {
            sweep(self, plan);
        }
    }
    /// Projects every pair of [`Plan::contact`] by each family that binds to contacts, with
    /// friction (`contact::project`); called only when there is a contact plan.
    fn contacts(&mut self, plan: &Plan);
    /// The compliant grab: `particle` pulled towards `target` (in the scene's frame) by a
    /// zero-length XPBD constraint of compliance `compliance`, in a substep of length `h`
    /// (`pull`, in the engine's precision and coordinates; the GPU engine records it).
    fn soft_grab(&mut self, particle: usize, target: DVec3, compliance: f64, h: f64);
    /// y ≥ 0 for every free particle, then the plane-strain hold on x.
    fn ground_and_plane(&mut self, plan: &Plan);
    /// Δp = x − predicted x, and its sum over the frame.
    fn keep_corrections(&mut self);
    /// v = (x − x_prev) / h, damped, and capped while an edit settles.
    fn update_velocities(&mut self, plan: &Plan);
}

/// One frame: `substeps` substeps, each [`begin_substep`], the sweeps ([`Substeps::sweeps`]:
/// `iterations` × [`sweep`]), [`end_substep`].
pub fn frame(engine: &mut impl Substeps, plan: &Plan) {
    engine.begin_frame(plan);
    for substep in 0..plan.substeps {
        let tracks = plan.tracks(substep);
        begin_substep(engine, plan, tracks);
        engine.sweeps(plan);
        end_substep(engine, plan, tracks);
    }
}

/// The start of a substep: predict, hold the rigidly grabbed particle, keep the predicted
/// positions when Δp is `tracked`, and (XPBD) λ = 0.
pub fn begin_substep(engine: &mut impl Substeps, plan: &Plan, tracked: bool) {
    engine.predict(plan);
    if let Some((particle, target)) = plan.rigid_grab {
        engine.hold(particle, target);
    }
    if tracked {
        engine.keep_predicted();
    }
    engine.reset_multipliers(plan);
}

/// One Gauss–Seidel sweep: what each active family projects, in order, then [`end_sweep`].
pub fn sweep(engine: &mut impl Substeps, plan: &Plan) {
    for &unit in &plan.units {
        engine.project(unit, plan);
    }
    end_sweep(engine, plan);
}

/// The end of a sweep, after the families: contact, the compliant grab, then the ground and
/// the plane.
pub fn end_sweep(engine: &mut impl Substeps, plan: &Plan) {
    if plan.contact.is_some() {
        engine.contacts(plan);
    }
    close_sweep(engine, plan);
}

/// The end of a sweep after its contacts: the compliant grab, then the ground and the plane
/// (step-by-step mode projects the contacts one at a time before it).
pub fn close_sweep(engine: &mut impl Substeps, plan: &Plan) {
    if let Some((particle, target, compliance)) = plan.soft_grab {
        engine.soft_grab(particle, target, compliance, plan.h);
    }
    engine.ground_and_plane(plan);
}

/// The end of a substep: Δp when it is `tracked`, then the velocities.
pub fn end_substep(engine: &mut impl Substeps, plan: &Plan, tracked: bool) {
    if tracked {
        engine.keep_corrections();
    }
    engine.update_velocities(plan);
}

/// One XPBD projection of |p − target| = 0 moving p alone (the target is fixed), without a
/// branch on a value (the GPU engine runs it too): a skipped projection moves nothing.
pub(crate) fn pull<V: Vector3>(
    position: &mut V,
    w: V::Real,
    lambda: &mut V::Real,
    target: V,
    alpha: V::Real,
) {
    let evaluation = distance::evaluate(&[*position, target], V::Real::ZERO);
    let rule = Rule::Xpbd { alpha_tilde: alpha };
    let unbounded = V::Real::from_f64(f64::INFINITY);
    let c = correct(
        [evaluation],
        [w, V::Real::ZERO],
        [*lambda],
        [rule],
        unbounded,
    );
    let made = !c.skipped[0].all;
    if made.any() {
        *lambda = V::Real::select(made, *lambda + c.delta_lambda[0], *lambda);
        *position = V::select(made, *position + c.delta_x[0], *position);
    }
}
