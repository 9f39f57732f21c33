//! Step-by-step projection: a substep taken one constraint at a time, so that a reader sees which
//! constraint is projected next, its ∇C, and the Δx it is about to apply.
//!
//! A substep is [`Simulation::begin_substep`] (predict), then `iterations` sweeps, each projecting
//! every constraint of [`Simulation::projection_order`] with [`Simulation::project`] and closing
//! with `Simulation::end_sweep`, then `Simulation::end_substep`. [`StepByStep`] walks the same
//! calls in the same order, so stepping through a whole substep gives the same bits as
//! [`Simulation::substep`]. Like [`Simulation::substep`], it does not count frames.

use crate::constraints::Family;
use crate::simulation::{Projection, Simulation};

/// Where a substep taken one projection at a time stands: between substeps, or inside one.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum StepByStep {
    /// No substep under way; the next advance begins one (the prediction).
    #[default]
    BetweenSubsteps,
    /// Inside a substep.
    Sweeping {
        /// The sweep under way, from 0.
        iteration: u32,
        /// How many constraints of this sweep have been projected.
        done: usize,
    },
}

/// What the next [`StepByStep::advance`] does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Next {
    /// Begin a substep: predict positions from the velocities and gravity.
    BeginSubstep,
    /// Project constraint (family, index).
    Project(Family, usize),
    /// Close the sweep (grab, ground); `last` when that also ends the substep (velocities).
    EndSweep {
        /// Whether this is the substep's last sweep.
        last: bool,
    },
}

/// What [`StepByStep::advance`] did.
// One value per key press: its size does not matter, and a Copy value is simpler to show.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Advanced {
    /// Began a substep.
    BeganSubstep,
    /// Projected one constraint, as described just before.
    Projected(Projection),
    /// Closed a sweep, and ended the substep if it was the last sweep.
    EndedSweep {
        /// Whether the substep ended.
        ended_substep: bool,
    },
}

impl StepByStep {
    /// The sweep under way (from 0) and the number of sweeps per substep; `None` between substeps.
    pub fn iteration(&self, simulation: &Simulation) -> Option<(u32, u32)> {
        match *self {
            StepByStep::BetweenSubsteps => None,
            StepByStep::Sweeping { iteration, .. } => {
                Some((iteration, simulation.settings().iterations.max(1)))
            }
        }
    }

    /// How many of this sweep's constraints are projected, and how many it has.
    pub fn progress(&self, simulation: &Simulation) -> (usize, usize) {
        let total = sweep_length(simulation);
        match *self {
            StepByStep::BetweenSubsteps => (0, total),
            StepByStep::Sweeping { done, .. } => (done.min(total), total),
        }
    }

    /// What the next [`StepByStep::advance`] does.
    pub fn next(&self, simulation: &Simulation) -> Next {
        match *self {
            StepByStep::BetweenSubsteps => Next::BeginSubstep,
            StepByStep::Sweeping { iteration, done } => {
                match simulation.projection_order().nth(done) {
                    Some((family, c)) => Next::Project(family, c),
                    None => Next::EndSweep {
                        last: iteration + 1 >= simulation.settings().iterations.max(1),
                    },
                }
            }
        }
    }

    /// What the next projection will do, when the next advance is a projection.
    pub fn pending(&self, simulation: &Simulation) -> Option<Projection> {
        match self.next(simulation) {
            Next::Project(family, c) => Some(simulation.projection(family, c)),
            _ => None,
        }
    }

    /// Does [`StepByStep::next`]: begins a substep, projects one constraint, or closes a sweep (and
    /// after the last sweep ends the substep).
    pub fn advance(&mut self, simulation: &mut Simulation) -> Advanced {
        match (self.next(simulation), *self) {
            (Next::BeginSubstep, _) => {
                simulation.begin_substep();
                *self = StepByStep::Sweeping {
                    iteration: 0,
                    done: 0,
                };
                Advanced::BeganSubstep
            }
            (Next::Project(family, c), StepByStep::Sweeping { iteration, done }) => {
                let projection = simulation.projection(family, c);
                simulation.project(family, c);
                *self = StepByStep::Sweeping {
                    iteration,
                    done: done + 1,
                };
                Advanced::Projected(projection)
            }
            (Next::EndSweep { last }, StepByStep::Sweeping { iteration, .. }) => {
                simulation.end_sweep();
                if last {
                    simulation.end_substep();
                    *self = StepByStep::BetweenSubsteps;
                } else {
                    *self = StepByStep::Sweeping {
                        iteration: iteration + 1,
                        done: 0,
                    };
                }
                Advanced::EndedSweep {
                    ended_substep: last,
                }
            }
            (_, StepByStep::BetweenSubsteps) => unreachable!("between substeps, next begins one"),
        }
    }

    /// Makes every remaining projection of the substep under way and ends it; nothing between
    /// substeps. Afterwards the stepper stands between substeps.
    pub fn finish(&mut self, simulation: &mut Simulation) {
        while *self != StepByStep::BetweenSubsteps {
            self.advance(simulation);
        }
    }
}

/// How many constraints one sweep projects.
fn sweep_length(simulation: &Simulation) -> usize {
    let families = simulation.families();
    let contact = crate::simulation::contact::contact_families(families, simulation.active());
    let pairs = contact.count() * simulation.contact_pairs().len();
    let constraints: usize = (simulation.settings().active.families())
        .map(|f| simulation.constraint_count(f))
        .sum();
    constraints + pairs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraints::PerFamily;
    use crate::scene::{Builtin, Perturbation, Scene};
    use crate::simulation::{Method, Settings};

    fn scrambled(method: Method) -> Simulation {
        scrambled_in(method, None)
    }

    fn scrambled_in(method: Method, order_seed: Option<u64>) -> Simulation {
        let scene = Scene::builtin(Builtin::Cube, 1).unwrap();
        let settings = Settings {
            method,
            order_seed,
            active: PerFamily::splat(true),
            iterations: 2,
            stiffness: PerFamily::splat(0.7),
            compliance: PerFamily::splat(1e-6),
            ..Settings::default()
        };
        let mut simulation = Simulation::new(&scene, settings);
        simulation.perturb(Perturbation::Scramble(5));
        simulation.step();
        simulation
    }

    /// In the table's order and in an order drawn from a seed alike: step-by-step mode walks
    /// the order a sweep projects in.
    #[test]
    fn a_substep_taken_one_projection_at_a_time_gives_the_same_bits() {
        for (method, seed) in [
            (Method::Xpbd, None),
            (Method::Pbd, None),
            (Method::Xpbd, Some(4)),
        ] {
            let mut whole = scrambled_in(method, seed);
            let mut stepped = whole.clone();
            whole.substep();
            let mut stepper = StepByStep::default();
            let mut projections = 0;
            let mut sweeps = 0;
            assert_eq!(stepper.advance(&mut stepped), Advanced::BeganSubstep);
            loop {
                match stepper.advance(&mut stepped) {
                    Advanced::Projected(_) => projections += 1,
                    Advanced::EndedSweep { ended_substep } => {
                        sweeps += 1;
                        if ended_substep {
                            break;
                        }
                    }
                    Advanced::BeganSubstep => panic!("one substep only"),
                }
            }
            let per_sweep = whole.projection_order().count();
            assert_eq!((sweeps, projections), (2, 2 * per_sweep), "{method:?}");
            assert_eq!(stepper, StepByStep::BetweenSubsteps);
            assert_eq!(whole.positions(), stepped.positions(), "{method:?}");
            assert_eq!(whole.velocities(), stepped.velocities(), "{method:?}");
        }
    }

    /// Two cubes, one resting on the other, with contact: a sweep steps through the contact
    /// pairs one at a time after the families, each pending projection is what its advance
    /// applies, and the whole substep gives the same bits as [`Simulation::substep`].
    #[test]
    fn contact_pairs_are_stepped_one_at_a_time() {
        let settings = Settings {
            substeps: 4,
            ..Settings::default()
        };
        let at = [0.3, 1.002, 0.0];
        let mut simulation = crate::simulation::contact::cube_on_cube(1, at, settings, 3);
        let contact = simulation.families().parse("contact").unwrap();
        let mut whole = simulation.clone();
        whole.substep();
        let mut stepper = StepByStep::default();
        let (mut pairs, mut moved) = (0, 0);
        loop {
            let pending = stepper.pending(&simulation);
            let before = simulation.positions().to_vec();
            match (pending, stepper.advance(&mut simulation)) {
                (Some(expected), Advanced::Projected(done)) => {
                    assert_eq!(expected, done);
                    if done.family == contact {
                        pairs += 1;
                        for (k, &i) in done.particles().iter().enumerate() {
                            let step = simulation.positions()[i as usize] - before[i as usize];
                            assert_eq!(step, done.delta_x[k], "pair {}", done.constraint);
                            moved += usize::from(step != glam::DVec3::ZERO);
                        }
                    }
                }
                (
                    None,
                    Advanced::EndedSweep {
                        ended_substep: true,
                    },
                ) => break,
                (None, _) => {}
                other => panic!("pending and advance disagree: {other:?}"),
            }
        }
        assert_eq!(pairs, simulation.contact_pairs().len());
        assert!(pairs > 0 && moved > 0, "{pairs} pairs, {moved} moved");
        assert_eq!(whole.positions(), simulation.positions());
        assert_eq!(whole.velocities(), simulation.velocities());
    }

    #[test]
    fn the_pending_projection_is_what_the_next_advance_applies() {
        let mut simulation = scrambled(Method::Xpbd);
        let mut stepper = StepByStep::default();
        for _ in 0..40 {
            let pending = stepper.pending(&simulation);
            let before = simulation.positions().to_vec();
            match (pending, stepper.advance(&mut simulation)) {
                (Some(expected), Advanced::Projected(done)) => {
                    assert_eq!(expected, done);
                    for (k, &i) in done.particles().iter().enumerate() {
                        let moved = simulation.positions()[i as usize] - before[i as usize];
                        assert!((moved - done.delta_x[k]).length() < 1e-15);
                    }
                }
                (None, Advanced::EndedSweep { .. } | Advanced::BeganSubstep) => {}
                other => panic!("pending and advance disagree: {other:?}"),
            }
        }
    }

    #[test]
    fn finishing_a_substep_part_way_equals_a_whole_substep() {
        let mut whole = scrambled(Method::Pbd);
        let mut stepped = whole.clone();
        whole.substep();
        let mut stepper = StepByStep::default();
        for _ in 0..7 {
            stepper.advance(&mut stepped);
        }
        stepper.finish(&mut stepped);
        assert_eq!(stepper, StepByStep::BetweenSubsteps);
        assert_eq!(whole.positions(), stepped.positions());
        assert_eq!(whole.corrections(), stepped.corrections());
        stepper.finish(&mut stepped);
        assert_eq!(
            whole.positions(),
            stepped.positions(),
            "between substeps, nothing to finish"
        );
    }
}
