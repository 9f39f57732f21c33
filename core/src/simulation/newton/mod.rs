//! The Newton reference: the exact solution of the discrete problem XPBD approximates, as an
//! engine of its own ([`NewtonEngine`], `--engine newton`) and as a static equilibrium
//! ([`equilibrium`]).
//!
//! XPBD's substep is an approximation of one implicit Euler step: from the predicted positions x̃
//! (the same prediction, the ground's sticking included, [`super::substep`]), the positions that
//! minimise Φ(x) = ½ |x − x̃|²_M / h² + Σ ½ C² / α subject to the rigid constraints (α = 0) and
//! the ground y ≥ 0 (`objective.rs`). Its Gauss–Seidel sweeps stop after `iterations`; this engine
//! solves the same problem to a stated tolerance ([`Options::tolerance`]): Newton's method on the
//! projected Hessian, a line search, and an augmented Lagrangian for what is rigid
//! (`minimize.rs`). Everything else of the substep (prediction, velocities, damping, settling, Δp)
//! is the reference engine's, through the substep every CPU engine shares, so the two differ by
//! the solve alone: XPBD's distance from this engine's state is the solver's error.
//!
//! Rigid families have no energy: for them the reference is the constrained step, C = 0 held by
//! the augmented Lagrangian's multipliers to the tolerance, relative to each element's size. The
//! ground holds y ≥ 0 the same way, frictionless within the step; its sticking is the prediction's,
//! as in XPBD. PBD has no energy either: under PBD this engine solves XPBD's problem with the
//! families' compliances.

mod minimize;
mod objective;

use super::engine::{Engine, Frame, Start};
use super::reference::OnState;
use super::state::Body;
use super::substep::{self, Plan, Substeps};
use crate::constraints::{Families, Family, PerFamily, Unit};
use crate::simulation::Resolved;
use crate::simulation::projection::SkipCounts;
use glam::DVec3;
use minimize::{Factoriser, Scales, minimize};
use objective::{Dofs, Inertia, Load, Objective, Term};

/// How exactly the Newton reference solves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// At a solution ‖∇Φ‖∞ is at most this times the forces of the problem (or 2·10⁻¹⁰ of the
    /// magnitudes of the terms it sums, where rounding allows no less), and every rigid
    /// constraint's |C| at most this times its element's size (and the ground's depth times the
    /// body's): 10⁻¹⁰.
    pub tolerance: f64,
    /// Newton steps allowed for one minimisation.
    pub max_iterations: u32,
    /// Augmented Lagrangian updates allowed.
    pub max_outer_iterations: u32,
    /// The smallest force scale the residual is measured against (N): a problem at rest at its
    /// start has no force of its own to measure against.
    pub force_scale: f64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            tolerance: 1e-10,
            max_iterations: 60,
            max_outer_iterations: 40,
            force_scale: 1e-9,
        }
    }
}

/// How a solve went.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Report {
    /// Newton steps taken (all minimisations together).
    pub newton_iterations: u32,
    /// Minimisations (1 without rigid constraints or a ground).
    pub outer_iterations: u32,
    /// ‖∇Φ‖∞ at the end, relative to the problem's forces.
    pub residual: f64,
    /// The largest violation of a rigid constraint or of the ground at the end, relative.
    pub violation: f64,
    /// Whether both are within the tolerance.
    pub converged: bool,
}

/// The Newton reference as an engine: every substep's implicit Euler step solved to
/// [`Options::tolerance`].
#[derive(Default)]
pub struct NewtonEngine {
    options: Options,
    factoriser: Factoriser,
    /// The last substep's solve.
    last: Report,
    /// Substeps whose solve did not converge, since the engine was built.
    unconverged: u64,
    /// The force the ground holds each particle up with at the end of the last solve, N.
    ground_forces: Vec<f64>,
}

impl NewtonEngine {
    /// The engine solving each substep with `options` rather than [`Options::default`].
    pub fn with_options(options: Options) -> NewtonEngine {
        NewtonEngine {
            options,
            ..NewtonEngine::default()
        }
    }

    /// The last substep's solve.
    pub fn last_report(&self) -> Report {
        self.last
    }

    /// How many substeps' solves have not converged to the tolerance.
    pub fn unconverged(&self) -> u64 {
        self.unconverged
    }

    /// What a front end says when some substep's solve has not converged (`None` when every
    /// one has): how many, the last one's residual and violation, and what follows.
    pub fn warning(&self) -> Option<String> {
        let last = self.last;
        (self.unconverged > 0).then(|| {
            format!(
                "the Newton reference did not solve {} substeps to its tolerance (the last: \
                 residual {:.1e}, violation {:.1e}); its answer there is a local one",
                self.unconverged, last.residual, last.violation
            )
        })
    }
}

impl Engine for NewtonEngine {
    fn step(&mut self, frame: Frame<'_>) -> PerFamily<SkipCounts> {
        let plan = Plan::of(&frame);
        let (families, resolved, body) = (frame.families, frame.resolved, frame.body);
        let mut stages = Implicit {
            on: OnState::new(families, body, frame.state),
            families,
            resolved,
            body,
            engine: self,
        };
        substep::frame(&mut stages, &plan);
        PerFamily::default()
    }

    fn describe(&self) -> String {
        format!(
            "newton (f64, implicit Euler to {:.0e})",
            self.options.tolerance
        )
    }

    fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
        self
    }
}

/// The Newton reference during a frame: the reference engine's stages, and the substep's system
/// solved where XPBD sweeps.
struct Implicit<'a> {
    on: OnState<'a>,
    families: &'a Families,
    resolved: &'a Resolved,
    body: &'a Body,
    engine: &'a mut NewtonEngine,
}

/// How each active family enters the problem: with its stiffness 1/α, or rigid.
fn terms(families: &Families, resolved: &Resolved) -> PerFamily<Term> {
    families.per_family(|f| {
        if !resolved.active[f] {
            Term::Off
        } else if resolved.compliance[f] > 0.0 {
            Term::Compliant(1.0 / resolved.compliance[f])
        } else {
            Term::Rigid
        }
    })
}

/// The masses, 0 where a particle is held (its inverse mass 0).
fn masses(body: &Body, inverse_masses: &[f64]) -> Vec<f64> {
    (body.lumped_inverse_masses.iter().zip(inverse_masses))
        .map(|(&lumped, &w)| if w > 0.0 { 1.0 / lumped } else { 0.0 })
        .collect()
}

/// The largest force a problem's particles feel from outside: a weight or an external force.
fn force_scale(heaviest: f64, gravity: f64, forces: &[DVec3]) -> f64 {
    forces
        .iter()
        .map(|f| f.abs().max_element())
        .fold(heaviest * gravity.abs(), f64::max)
}

impl Substeps for Implicit<'_> {
    crate::forward_stages!(on:
        predict, hold, keep_predicted, reset_multipliers, contacts, soft_grab, ground_and_plane,
        keep_corrections, update_velocities);

    /// Never called: [`Implicit::sweeps`] solves the whole substep.
    fn project(&mut self, _: Unit, _: &Plan) {
        unreachable!("the Newton reference solves the substep at once, not unit by unit")
    }

    fn sweeps(&mut self, plan: &Plan) {
        let state = self.on.state();
        let masses = masses(self.body, &state.inverse_masses);
        let dofs = Dofs::new(
            state.inverse_masses.iter().map(|&w| w <= 0.0),
            plan.motion.plane_strain,
        );
        let predicted = state.positions.clone();
        let over_h2 = 1.0 / (plan.h * plan.h);
        let objective = Objective {
            families: self.families,
            body: self.body,
            terms: terms(self.families, self.resolved),
            inertia: Some(Inertia {
                masses: &masses,
                predicted: &predicted,
                over_h2,
            }),
            load: None,
            grab: (plan.soft_grab)
                .map(|(particle, target, compliance)| (particle, target, 1.0 / compliance)),
            ground: plan.motion.ground,
            dofs: &dofs,
            start: Some((&state.previous, plan.h)),
        };
        let heaviest = masses.iter().fold(0.0f64, |a, &m| a.max(m));
        let scales = Scales {
            stiffness: heaviest * over_h2,
            size: self.body.rest_diagonal().max(f64::MIN_POSITIVE),
            force: force_scale(heaviest, self.resolved.settings.gravity, &self.body.forces),
        };
        let engine = &mut *self.engine;
        let solved = minimize(
            &objective,
            &mut state.positions,
            &mut engine.factoriser,
            scales,
            &engine.options,
            &mut engine.ground_forces,
        );
        // The ground's share of the move from x̃: x = x̃ + h² W (f_ground − ∇E), so its push is
        // h² w f_ground along +y (what it took is booked from it, as on every engine).
        let h2 = plan.h * plan.h;
        for ((push, &w), &force) in (state.pushes.iter_mut())
            .zip(&state.inverse_masses)
            .zip(&engine.ground_forces)
        {
            push.y += h2 * w * force;
        }
        engine.last = solved.unwrap_or_default();
        if !engine.last.converged {
            engine.unconverged += 1;
        }
    }
}

/// The static equilibrium of a simulation's body under its load (gravity on the lumped masses,
/// the external forces), from its current positions: the positions where ∇Φ = 0 for
/// Φ = Σ ½ C² / α − Σ (mᵢ g + fᵢ)·xᵢ, held particles and (in plane strain) every z fixed, rigid
/// constraints and the ground held. The exact solution of the discrete problem a static run of
/// XPBD approaches at rest.
pub fn equilibrium(start: Start<'_>, options: &Options) -> Result<(Vec<DVec3>, Report), String> {
    let (families, resolved, body, state) =
        (start.families, start.resolved, start.body, start.state);
    let masses: Vec<f64> = body
        .lumped_inverse_masses
        .iter()
        .map(|&w| 1.0 / w)
        .collect();
    let dofs = Dofs::new(
        state.inverse_masses.iter().map(|&w| w <= 0.0),
        body.plane_strain,
    );
    let terms = terms(families, resolved);
    let objective = Objective {
        families,
        body,
        terms,
        inertia: None,
        load: Some(Load {
            masses: &masses,
            gravity: resolved.settings.gravity,
            forces: &body.forces,
        }),
        grab: None,
        ground: resolved.settings.ground.then_some(0.0),
        dofs: &dofs,
        start: None,
    };
    let own_stiffest = |f: Family| {
        let own = body.sets[f].own_compliances().iter();
        own.filter(|a| !a.is_nan())
            .fold(0.0f64, |k, a| k.max(1.0 / a))
    };
    let stiffness = families
        .all()
        .filter_map(|f| match terms[f] {
            Term::Compliant(k) => Some(k.max(own_stiffest(f))),
            _ => None,
        })
        .fold(1.0f64, f64::max);
    let heaviest = masses.iter().fold(0.0f64, |a, &m| a.max(m));
    let scales = Scales {
        stiffness,
        size: body.rest_diagonal().max(f64::MIN_POSITIVE),
        force: force_scale(heaviest, resolved.settings.gravity, &body.forces),
    };
    let mut x = state.positions.clone();
    let report = minimize(
        &objective,
        &mut x,
        &mut Factoriser::default(),
        scales,
        options,
        &mut Vec::new(),
    )?;
    Ok((x, report))
}
