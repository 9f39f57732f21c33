//! The reference engine: the substep of [`super::substep`] on the simulation's own f64 state, one
//! constraint at a time in each family's order. Exact to f64, and the path step-by-step mode and
//! the inspector walk: [`project_unit`] is the one projection that a sweep applies, a step takes
//! and the inspector describes ([`super::Simulation::projection`]).

use super::constraint_set::ConstraintSet;
use super::engine::{Engine, Frame};
use super::integrate;
use super::projection::{Correction, Rule, SkipCounts, correct_in_reach};
use super::state::{Body, State};
use super::substep::{self, Plan, Substeps};
use crate::constraints::{
    Evaluation, Families, Family, PerFamily, Projected, SubstepStart, Unit, VisitProjected,
};
use glam::DVec3;

/// The reference engine: f64, one constraint at a time, in the simulation's own arrays. It keeps
/// nothing of its own, so an edit needs nothing of it.
#[derive(Clone, Copy, Debug, Default)]
pub struct ReferenceEngine;

impl Engine for ReferenceEngine {
    fn step(&mut self, frame: Frame<'_>) -> PerFamily<SkipCounts> {
        let plan = Plan::of(&frame);
        let mut on = OnState::new(frame.families, frame.body, frame.state);
        substep::frame(&mut on, &plan);
        on.skipped
    }

    fn describe(&self) -> String {
        "reference (f64)".to_owned()
    }

    fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
        self
    }
}

/// The reference engine's stages of a substep ([`Substeps`]), on a simulation's f64 state: what
/// the reference engine runs, step-by-step mode walks, and an engine of one's own may wrap.
pub struct OnState<'a> {
    families: &'a Families,
    body: &'a Body,
    state: &'a mut State,
    /// Projections skipped for a counted reason, per family.
    pub(super) skipped: PerFamily<SkipCounts>,
}

impl<'a> OnState<'a> {
    /// The stages on `state`, of `body`, with the families of `families`.
    pub fn new(families: &'a Families, body: &'a Body, state: &'a mut State) -> Self {
        OnState {
            families,
            body,
            state,
            skipped: PerFamily::default(),
        }
    }

    /// The state the stages work on: what an engine that wraps these stages reads and changes
    /// between them (the Newton reference solves the substep on it).
    pub fn state(&mut self) -> &mut State {
        self.state
    }

    /// Projections skipped for a counted reason so far, per family.
    pub fn skipped(&self) -> PerFamily<SkipCounts> {
        self.skipped
    }

    /// Projects constraint `c` of `unit` alone, exactly as a sweep does (step-by-step mode).
    pub fn project_one(&mut self, unit: Unit, c: usize, plan: &Plan) {
        self.project_which(unit, Which::One(c), plan);
    }

    /// Projects pair `c` of the frame's contacts by the contact family `family` alone, exactly
    /// as a sweep's contact pass does (step-by-step mode).
    pub fn project_contact(&mut self, family: Family, c: usize, plan: &Plan) {
        self.contacts_which(plan, Some((family, c)));
    }

    fn contacts_which(&mut self, plan: &Plan, only: Option<(Family, usize)>) {
        let Some(contact) = &plan.contact else {
            return;
        };
        let s = &mut *self.state;
        crate::simulation::contact::project_pairs(
            self.families,
            &plan.rules,
            contact,
            (&contact.found, only),
            (&mut s.positions, &mut s.previous, &s.inverse_masses),
            &mut s.contact_lambdas,
            &mut self.skipped,
        );
    }

    fn project_which(&mut self, unit: Unit, which: Which, plan: &Plan) {
        let sweep = Sweep {
            sets: &self.body.sets,
            lambdas: &mut self.state.lambdas,
            positions: &mut self.state.positions,
            rest_positions: &self.body.rest_positions,
            inverse_masses: &self.state.inverse_masses,
            previous: (&self.state.previous, plan.h),
            rules: &plan.rules,
            which,
            skipped: &mut self.skipped,
            reach: plan.reach,
        };
        self.families.visit_unit(unit, sweep);
    }
}

impl Substeps for OnState<'_> {
    fn predict(&mut self, plan: &Plan) {
        let s = &mut *self.state;
        integrate::predict(
            &mut s.positions,
            &mut s.previous,
            &mut s.velocities,
            &s.inverse_masses,
            &self.body.forces,
            plan.motion,
            None,
            &mut s.pushes,
        );
    }

    fn hold(&mut self, particle: usize, target: DVec3) {
        self.state.positions[particle] = target;
    }

    fn keep_predicted(&mut self) {
        self.state
            .corrections
            .copy_from_slice(&self.state.positions);
    }

    fn reset_multipliers(&mut self, plan: &Plan) {
        for family in self.families.all() {
            self.state.lambdas[family].fill(0.0);
        }
        if let Some(grab) = &mut self.state.grab {
            grab.lambda = 0.0;
        }
        if let Some(contact) = &plan.contact {
            let wanted = contact.found.len() * contact.families.len();
            let room = contact.room() * contact.families.len();
            super::contact::keep_room(&mut self.state.contact_lambdas, room);
            self.state.contact_lambdas.resize(wanted, 0.0);
            self.state.contact_lambdas.fill(0.0);
        }
    }

    fn contacts(&mut self, plan: &Plan) {
        self.contacts_which(plan, None);
    }

    fn project(&mut self, unit: Unit, plan: &Plan) {
        self.project_which(unit, Which::All, plan);
    }

    fn soft_grab(&mut self, particle: usize, target: DVec3, compliance: f64, h: f64) {
        let s = &mut *self.state;
        let grab = s.grab.as_mut().expect("a grab is held");
        let w = s.inverse_masses[particle];
        let alpha = compliance / (h * h);
        substep::pull(
            &mut s.positions[particle],
            w,
            &mut grab.lambda,
            target,
            alpha,
        );
    }

    fn ground_and_plane(&mut self, plan: &Plan) {
        let s = &mut *self.state;
        if let Some(ground) = plan.motion.ground {
            integrate::project_ground(&mut s.positions, &s.inverse_masses, ground, &mut s.pushes);
        }
        if plan.motion.plane_strain {
            integrate::hold_plane(&mut s.positions, &s.previous);
        }
    }

    fn keep_corrections(&mut self) {
        let s = &mut *self.state;
        for ((correction, sum), p) in s
            .corrections
            .iter_mut()
            .zip(&mut s.frame_corrections)
            .zip(&s.positions)
        {
            *correction = *p - *correction;
            *sum += *correction;
        }
    }

    fn update_velocities(&mut self, plan: &Plan) {
        let s = &mut *self.state;
        integrate::update_velocities(
            &s.positions,
            &s.previous,
            &mut s.velocities,
            plan.h,
            plan.damping,
            plan.settling,
            None,
            integrate::Book {
                inverse_masses: &s.inverse_masses,
                forces: &self.body.forces,
                gravity: plan.motion.gravity,
                pushes: &s.pushes,
                taken: &mut s.taken_by_particle,
            },
        );
        s.taken.add_and_clear(&mut s.taken_by_particle);
    }
}

/// Which constraints of a unit a projection call makes.
#[derive(Clone, Copy)]
enum Which {
    /// Every one, in the lead family's order (a sweep).
    All,
    /// Constraint c alone (step-by-step mode).
    One(usize),
}

impl Which {
    /// The positions in the set's order to go through.
    fn range(self, set: &ConstraintSet) -> std::ops::Range<usize> {
        match self {
            Which::All => 0..set.len(),
            Which::One(c) => c..c + 1,
        }
    }

    /// The constraint at position `k` of [`Which::range`].
    #[inline]
    fn at(self, set: &ConstraintSet, k: usize) -> usize {
        match self {
            Which::All => set.in_order(k),
            Which::One(c) => c,
        }
    }
}

/// What one projection of a unit's constraint `c` sees and would do, in f64.
pub(super) struct UnitProjection<const N: usize, const K: usize> {
    /// The constraint's particles.
    pub particles: [u32; N],
    /// C and ∇C of each value.
    pub evaluations: [Evaluation<DVec3, N>; K],
    /// The particles' inverse masses.
    pub weights: [f64; N],
    /// Each value's multiplier before the projection.
    pub lambda: [f64; K],
    /// What the projection changes.
    pub correction: Correction<N, K>,
}

/// Constraint `c` of the unit whose constraints `constraint` evaluates (families `families`, the
/// lead first), projected with the current positions and multipliers: evaluated, and its
/// correction worked out, not applied.
#[inline]
#[allow(clippy::too_many_arguments)]
pub(super) fn project_unit<const N: usize, const K: usize, P: Projected<N, K>>(
    constraint: &P,
    families: [Family; K],
    sets: &PerFamily<ConstraintSet>,
    lambdas: &PerFamily<Vec<f64>>,
    (positions, rest_positions, inverse_masses): (&[DVec3], &[DVec3], &[f64]),
    (previous, h): (&[DVec3], f64),
    rules: [Rule<f64>; K],
    reach: f64,
    c: usize,
) -> UnitProjection<N, K> {
    let lead = &sets[families[0]];
    let particles = lead.indices::<N>(c);
    let p = particles.map(|i| positions[i as usize]);
    let shape = if P::READS_REST_SHAPE {
        particles.map(|i| rest_positions[i as usize])
    } else {
        p
    };
    let rest = families.map(|f| sets[f].rest()[c]);
    let stored = families.map(|f| sets[f].stored(c));
    // Where the particles were at the start of the substep, for a family that reads it.
    let start = if constraint.reads_motion() {
        particles.map(|i| previous[i as usize])
    } else {
        p
    };
    let motion = SubstepStart { start: &start, h };
    let evaluations = constraint.evaluate_stored(&p, rest, &shape, stored, motion);
    let weights = particles.map(|i| inverse_masses[i as usize]);
    let lambda = families.map(|f| lambdas[f][c]);
    let size = (reach, lead.size()[c]);
    let rules = std::array::from_fn(|k| rules[k].of_constraint(&sets[families[k]], c, h));
    let correction = correct_in_reach(evaluations, weights, lambda, rules, size, || p);
    UnitProjection {
        particles,
        evaluations,
        weights,
        lambda,
        correction,
    }
}

/// Projects the constraints `which` of a unit in turn (Gauss–Seidel): each correction moves the
/// particles and adds to each value's multiplier.
struct Sweep<'a> {
    sets: &'a PerFamily<ConstraintSet>,
    lambdas: &'a mut PerFamily<Vec<f64>>,
    positions: &'a mut [DVec3],
    rest_positions: &'a [DVec3],
    inverse_masses: &'a [f64],
    /// Where the particles were at the start of the substep, and h.
    previous: (&'a [DVec3], f64),
    rules: &'a PerFamily<Rule<f64>>,
    which: Which,
    skipped: &'a mut PerFamily<SkipCounts>,
    reach: f64,
}

impl VisitProjected for Sweep<'_> {
    type Output = ();

    #[inline]
    fn visit<const N: usize, const K: usize, P: Projected<N, K>>(
        self,
        families: [Family; K],
        constraint: &P,
    ) {
        let lead = &self.sets[families[0]];
        let rules = families.map(|f| self.rules[f]);
        for k in self.which.range(lead) {
            let c = self.which.at(lead, k);
            let arrays = (&*self.positions, self.rest_positions, self.inverse_masses);
            let unit = project_unit(
                constraint,
                families,
                self.sets,
                self.lambdas,
                arrays,
                self.previous,
                rules,
                self.reach,
                c,
            );
            let correction = unit.correction;
            for (&family, skipped) in families.iter().zip(correction.skipped) {
                self.skipped[family].add(skipped);
            }
            // A family alone that is skipped moves nothing, not even by a zero (which would turn
            // a coordinate of −0 into +0).
            if K == 1 && correction.skipped[0].any() {
                continue;
            }
            for (&family, delta) in families.iter().zip(correction.delta_lambda) {
                self.lambdas[family][c] += delta;
            }
            for (&i, dx) in unit.particles.iter().zip(correction.delta_x) {
                self.positions[i as usize] += dx;
            }
        }
    }
}
