//! The fast engine's stages of the substep ([`crate::simulation::substep::Substeps`]) on its own
//! f32 arrays: the per-particle passes shared out among the team's threads for a large body,
//! each unit of families projected by the kernel ([`super::kernel::project`]), and the
//! compensated positions (each position x + its residual r, [`integrate::Residuals`]).

use super::kernel;
use super::{Corrections, FastSimulation, Team, schedule};
use crate::constraints::{Family, PerFamily, Projected, Unit, VisitProjected};
use crate::simulation::integrate;
use crate::simulation::projection::{Rule, SkipCounts};
use crate::simulation::substep::{Plan, Substeps};
use glam::{DVec3, Vec3A};
use web_time::Instant;

/// A fast simulation during a frame, with the team it shares its work with and the compliant
/// grab's multiplier.
pub(super) struct OnArrays<'a> {
    pub(super) simulation: &'a mut FastSimulation,
    pub(super) team: Option<&'a Team>,
    pub(super) grab_lambda: f32,
}

impl Substeps for OnArrays<'_> {
    fn begin_frame(&mut self, plan: &Plan) {
        let s = &mut *self.simulation;
        s.recentre();
        let keep = plan.settling || plan.keep_corrections;
        let n = s.positions.len();
        if keep && s.corrections.predicted.len() != n {
            s.corrections = Corrections {
                predicted: vec![Vec3A::ZERO; n],
                last: vec![Vec3A::ZERO; n],
                frame: vec![Vec3A::ZERO; n],
            };
        }
        if keep {
            s.corrections.frame.fill(Vec3A::ZERO);
        }
        // The frame's contact pairs, renumbered once.
        let (found, _) = &mut s.contacts;
        found.clear();
        if let Some(contact) = &plan.contact {
            let renumber = &s.renumber;
            crate::simulation::contact::keep_room(found, contact.room());
            found.extend((contact.found.iter()).map(|pair| pair.map(|i| renumber[i as usize])));
        }
    }

    fn predict(&mut self, plan: &Plan) {
        let s = &mut *self.simulation;
        let mut motion = plan.motion;
        // The ground at y = 0 in the scene is at −origin.y in the engine's coordinates.
        motion.ground = motion.ground.map(|ground| -(s.origin.y - ground));
        let (arrays, inverse_masses, forces) = s.particle_arrays();
        schedule::by_particles(
            self.team,
            arrays,
            |range, [positions, previous, velocities, now, before, pushes, _]| {
                let forces = forces.get(range.clone()).unwrap_or_default();
                integrate::predict(
                    positions,
                    previous,
                    velocities,
                    &inverse_masses[range],
                    forces,
                    motion,
                    Some(integrate::Residuals {
                        now,
                        previous: before,
                    }),
                    pushes,
                );
            },
        );
    }

    fn hold(&mut self, particle: usize, target: DVec3) {
        let s = &mut *self.simulation;
        let i = s.renumber[particle] as usize;
        s.positions[i] = (target - s.origin).as_vec3a();
        s.residuals[i] = Vec3A::ZERO;
    }

    fn keep_predicted(&mut self) {
        let s = &mut *self.simulation;
        s.corrections.predicted.copy_from_slice(&s.positions);
    }

    fn reset_multipliers(&mut self, plan: &Plan) {
        let s = &mut *self.simulation;
        for family in s.resolved.active.families() {
            s.sets[family].reset_lambda();
        }
        self.grab_lambda = 0.0;
        if let Some(contact) = &plan.contact {
            let (found, lambdas) = &mut s.contacts;
            let wanted = found.len() * contact.families.len();
            let room = contact.room() * contact.families.len();
            crate::simulation::contact::keep_room(lambdas, room);
            lambdas.resize(wanted, 0.0);
            lambdas.fill(0.0);
        }
    }

    fn contacts(&mut self, plan: &Plan) {
        let Some(contact) = &plan.contact else {
            return;
        };
        let s = &mut *self.simulation;
        let (found, lambdas) = &mut s.contacts;
        crate::simulation::contact::project_pairs(
            &s.families,
            &plan.rules,
            contact,
            (found, None),
            (&mut s.positions, &mut s.previous, &s.inverse_masses),
            lambdas,
            &mut s.skipped,
        );
    }

    fn project(&mut self, unit: Unit, plan: &Plan) {
        let s = &mut *self.simulation;
        let started = Instant::now();
        let lead = unit.lead;
        let sums = s.jacobi.as_mut().map(|j| &mut j.sums[..]);
        let count = s.families.visit_unit(
            unit,
            ProjectUnit {
                layout: s.layouts.of(&s.families, lead),
                order: &s.colour_orders[lead],
                sets: &mut s.sets,
                positions: (&mut s.positions, &mut s.residuals),
                rest_positions: &mut s.rest_positions,
                previous: (&mut s.previous, plan.h),
                sums,
                rules: &plan.rules,
                reach: plan.reach,
                team: self.team,
                skipped: &mut s.skipped,
            },
        );
        s.apply_jacobi(lead);
        // One projection of a pair is a projection of each: each family gets its share of the
        // time.
        let share = started.elapsed() / unit.families().count() as u32;
        for family in unit.families() {
            s.timings.time[family] += share;
            s.timings.projections[family] += count as u64;
        }
    }

    fn soft_grab(&mut self, particle: usize, target: DVec3, compliance: f64, h: f64) {
        let target = (target - self.simulation.origin).as_vec3a();
        let alpha = (compliance / (h * h)) as f32;
        let s = &mut *self.simulation;
        let i = s.renumber[particle] as usize;
        let (w, lambda) = (s.inverse_masses[i], &mut self.grab_lambda);
        crate::simulation::substep::pull(&mut s.positions[i], w, lambda, target, alpha);
    }

    fn ground_and_plane(&mut self, plan: &Plan) {
        let s = &mut *self.simulation;
        let ground = plan.motion.ground.map(|ground| -(s.origin.y - ground));
        let plane_strain = plan.motion.plane_strain;
        if ground.is_none() && !plane_strain {
            return;
        }
        let (inverse_masses, previous) = (&s.inverse_masses[..], &s.previous[..]);
        let arrays = [&mut s.positions[..], &mut s.pushes[..]];
        schedule::by_particles(self.team, arrays, |range, [positions, pushes]| {
            if let Some(ground) = ground {
                let inverse_masses = &inverse_masses[range.clone()];
                integrate::project_ground(positions, inverse_masses, ground, pushes);
            }
            if plane_strain {
                integrate::hold_plane(positions, &previous[range]);
            }
        });
    }

    fn keep_corrections(&mut self) {
        let s = &mut *self.simulation;
        let c = &mut s.corrections;
        for (((last, sum), p), predicted) in c
            .last
            .iter_mut()
            .zip(&mut c.frame)
            .zip(&s.positions)
            .zip(&c.predicted)
        {
            *last = *p - *predicted;
            *sum += *last;
        }
    }

    fn update_velocities(&mut self, plan: &Plan) {
        let (h, damping, settling) = (plan.h, plan.damping, plan.settling);
        let gravity = plan.motion.gravity;
        let (arrays, inverse_masses, forces) = self.simulation.particle_arrays();
        schedule::by_particles(
            self.team,
            arrays,
            |range, [positions, previous, velocities, now, before, pushes, taken]| {
                integrate::update_velocities(
                    positions,
                    previous,
                    velocities,
                    h,
                    damping,
                    settling,
                    Some(&integrate::Residuals {
                        now,
                        previous: before,
                    }),
                    integrate::Book {
                        inverse_masses: &inverse_masses[range.clone()],
                        forces: forces.get(range).unwrap_or_default(),
                        gravity,
                        pushes,
                        taken,
                    },
                );
            },
        );
    }
}

/// Projects every constraint of a unit on the fast engine's arrays ([`kernel::project`]);
/// returns how many elements it projected, and counts each family's skipped projections.
struct ProjectUnit<'a> {
    layout: &'a super::Layout,
    order: &'a [u32],
    sets: &'a mut PerFamily<super::Batches>,
    positions: (&'a mut [Vec3A], &'a mut [Vec3A]),
    rest_positions: &'a mut [Vec3A],
    /// Where the particles were at the start of the substep, and h.
    previous: (&'a mut [Vec3A], f64),
    sums: Option<&'a mut [Vec3A]>,
    rules: &'a PerFamily<Rule<f64>>,
    reach: f64,
    team: Option<&'a Team>,
    skipped: &'a mut PerFamily<SkipCounts>,
}

impl VisitProjected for ProjectUnit<'_> {
    type Output = usize;

    #[inline]
    fn visit<const N: usize, const K: usize, P: Projected<N, K>>(
        self,
        families: [Family; K],
        constraint: &P,
    ) -> usize {
        let rules = families.map(|f| self.rules[f]);
        let mut batches = self.sets.get_disjoint_mut(families);
        for set in batches.iter_mut() {
            // An own compliance's α̃ follows h (nothing to do where none has one, or h is as
            // it was).
            set.set_substep(self.previous.1);
        }
        let (count, skipped) = kernel::project::<N, K, P>(
            constraint,
            self.layout,
            self.order,
            batches,
            self.positions,
            (self.rest_positions, self.previous),
            self.sums,
            (rules, self.reach),
            self.team,
        );
        for (family, skipped) in families.into_iter().zip(skipped) {
            self.skipped[family] = self.skipped[family] + skipped;
        }
        count
    }
}
