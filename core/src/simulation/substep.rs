//! The reference solver's frame, top to bottom: a frame is `substeps` substeps; a substep
//! predicts, sweeps the active families `iterations` times (then the grab, the ground and the
//! plane-strain hold), and takes Δp and the velocities from where the particles ended up.

use super::*;

impl Simulation {
    /// Advances one frame: `substeps` substeps of Δt / substeps, on the engine of
    /// [`Simulation::engine`].
    pub fn step(&mut self) {
        self.update_inverse_masses();
        self.frame_corrections.fill(DVec3::ZERO);
        match self.engine() {
            Engine::Fast => self.step_fast(),
            _ => {
                for _ in 0..self.settings.substeps.max(1) {
                    self.substep();
                }
            }
        }
        if let Some(grab) = &mut self.grab {
            grab.target_velocity = (grab.target - grab.target_at_last_step) / self.settings.dt;
            grab.target_at_last_step = grab.target;
        }
        if let Some(frames) = self.settling {
            let largest = self.largest_frame_correction();
            self.settling = (self.settings.edits_settle() && largest > self.settle_tolerance())
                .then_some(frames + 1);
        }
        self.frame += 1;
        self.time += self.settings.dt;
    }

    /// One substep: predict, project every active family `iterations` times, update velocities.
    /// The same as [`Simulation::begin_substep`], then for each iteration every constraint of
    /// [`Simulation::projection_order`] through [`Simulation::project`] and
    /// [`Simulation::end_sweep`], then [`Simulation::end_substep`] — done here in tight loops.
    pub fn substep(&mut self) {
        let h = self.substep_length();
        self.begin_substep();
        for _ in 0..self.settings.iterations.max(1) {
            self.sweep(h);
        }
        self.end_substep();
    }

    /// h = Δt / substeps.
    pub fn substep_length(&self) -> f64 {
        self.settings.dt / self.settings.substeps.max(1) as f64
    }

    /// The first part of a substep: predict positions, and (XPBD) λ = 0 for every constraint.
    pub fn begin_substep(&mut self) {
        self.fast.edited();
        let h = self.substep_length();
        self.predict(h);
        for family in self.families.all() {
            self.sets[family].reset_lambda();
        }
        if let Some(grab) = &mut self.grab {
            grab.lambda = 0.0;
        }
    }

    pub(super) fn predict(&mut self, h: f64) {
        integrate::predict(
            &mut self.positions,
            &mut self.previous,
            &mut self.velocities,
            &self.inverse_masses,
            &self.forces,
            integrate::Substep {
                gravity: self.settings.gravity,
                h,
                ground: self.settings.ground.then_some(0.0),
                plane_strain: self.plane_strain,
            },
            None,
        );
        if let Some(grab) = self.rigid_grab() {
            self.positions[grab.particle] = grab.target;
        }
        self.corrections.copy_from_slice(&self.positions);
    }

    /// One Gauss–Seidel sweep over the active families, then the grab, the ground and the
    /// plane-strain hold.
    pub(super) fn sweep(&mut self, h: f64) {
        let active = self.settings.active;
        for family in self.families.all() {
            if !active[family] || self.families.projected_by_partner(family, &active) {
                continue;
            }
            self.project_range(family, Projected::All, h);
        }
        self.end_sweep();
    }

    /// Projects the constraints `which` of `family` in turn, alone or with its partner.
    pub(super) fn project_range(&mut self, family: Family, which: Projected, h: f64) {
        let rule = self.rule(family, h);
        if let Some(partner) = self.families.partner_in(family, &self.settings.active) {
            let rules = [rule, self.rule(partner, h)];
            let (first, second) = self.sets.pair_mut(family, partner);
            let (skipped_first, skipped_second) = self.skipped.pair_mut(family, partner);
            let sweep = pair::PairSweep {
                first,
                second,
                skipped: [skipped_first, skipped_second],
                positions: &mut self.positions,
                rest_positions: &self.rest_positions,
                inverse_masses: &self.inverse_masses,
                rules,
                which,
                reach: self.settings.reach,
            };
            self.families.visit_pair(family, partner, sweep);
            return;
        }
        self.families.visit(
            family,
            Sweep {
                set: &mut self.sets[family],
                positions: &mut self.positions,
                rest_positions: &self.rest_positions,
                inverse_masses: &self.inverse_masses,
                rule,
                which,
                skipped: &mut self.skipped[family],
                reach: self.settings.reach,
            },
        );
    }

    /// The end of one sweep, after the constraint families: the grab, then the ground y ≥ 0.
    pub fn end_sweep(&mut self) {
        self.fast.edited();
        let h = self.substep_length();
        self.project_soft_grab(h);
        if self.settings.ground {
            integrate::project_ground(&mut self.positions, &self.inverse_masses, 0.0);
        }
        if self.plane_strain {
            integrate::hold_plane(&mut self.positions, &self.previous);
        }
    }

    pub(super) fn project_soft_grab(&mut self, h: f64) {
        let compliance = self.settings.grab_compliance;
        let Some(grab) = self.grab.as_mut().filter(|_| compliance > 0.0) else {
            return;
        };
        let i = grab.particle;
        let evaluation = distance::evaluate(&[self.positions[i], grab.target], 0.0);
        let rule = Rule::Xpbd {
            alpha_tilde: compliance / (h * h),
        };
        let unbounded = f64::INFINITY;
        let weights = [self.inverse_masses[i], 0.0];
        if let Some(c) = correction(evaluation, weights, grab.lambda, rule, unbounded) {
            grab.lambda += c.delta_lambda;
            self.positions[i] += c.delta_x[0];
        }
    }

    /// The last part of a substep: Δp = x − predicted x, then velocities from the positions.
    pub fn end_substep(&mut self) {
        self.fast.edited();
        let h = self.substep_length();
        for ((correction, sum), p) in self
            .corrections
            .iter_mut()
            .zip(&mut self.frame_corrections)
            .zip(&self.positions)
        {
            *correction = *p - *correction;
            *sum += *correction;
        }
        self.update_velocities(h, self.settings.edits_settle() && self.settling.is_some());
    }

    /// v = (x − x_prev) / h, damped; when `settling`, no faster than the predicted velocity.
    pub(super) fn update_velocities(&mut self, h: f64, settling: bool) {
        integrate::update_velocities(
            &self.positions,
            &self.previous,
            &mut self.velocities,
            h,
            self.settings.damping,
            settling,
            None,
        );
    }

    pub(crate) fn rule(&self, family: Family, h: f64) -> Rule<f64> {
        Rule::for_settings(&self.settings, family, h)
    }

    /// The longest Δp of the last substep among particles that can move.
    pub(super) fn largest_frame_correction(&self) -> f64 {
        self.frame_corrections
            .iter()
            .zip(&self.inverse_masses)
            .filter(|(_, w)| **w > 0.0)
            .map(|(c, _)| c.length())
            .fold(0.0, f64::max)
    }

    pub(super) fn update_inverse_masses(&mut self) {
        for i in 0..self.positions.len() {
            self.inverse_masses[i] = if self.pinned[i] {
                0.0
            } else {
                self.lumped_inverse_masses[i]
            };
        }
        if let Some(grab) = self.rigid_grab() {
            self.inverse_masses[grab.particle] = 0.0;
        }
    }
}

/// Which constraints of a family a projection call makes.
#[derive(Clone, Copy)]
pub(super) enum Projected {
    /// Every one, in the set's order (a sweep).
    All,
    /// Constraint c alone (step-by-step mode).
    One(usize),
}

impl Projected {
    /// The positions in the set's order to go through.
    pub(super) fn range(self, set: &ConstraintSet) -> std::ops::Range<usize> {
        match self {
            Projected::All => 0..set.len(),
            Projected::One(c) => c..c + 1,
        }
    }

    /// The constraint at position `k` of [`Projected::range`].
    #[inline]
    pub(super) fn at(self, set: &ConstraintSet, k: usize) -> usize {
        match self {
            Projected::All => set.in_order(k),
            Projected::One(c) => c,
        }
    }
}

/// Projects the constraints of one family's `set` (every one in the set's order, Gauss–Seidel,
/// or one): λ += Δλ, xᵢ += Δxᵢ.
struct Sweep<'a> {
    set: &'a mut ConstraintSet,
    positions: &'a mut [DVec3],
    rest_positions: &'a [DVec3],
    inverse_masses: &'a [f64],
    rule: Rule<f64>,
    which: Projected,
    skipped: &'a mut SkipCounts,
    /// [`Settings::reach`].
    reach: f64,
}

impl Visit for Sweep<'_> {
    type Output = ();

    #[inline]
    fn visit<const N: usize, C: Constraint<N>>(self, _: Family, constraint: &C) {
        for k in self.which.range(self.set) {
            let c = self.which.at(self.set, k);
            let idx = self.set.indices::<N>(c);
            let p = idx.map(|i| self.positions[i as usize]);
            let shape = if C::STORED_USES_REST_SHAPE {
                idx.map(|i| self.rest_positions[i as usize])
            } else {
                p
            };
            let evaluation =
                constraint.evaluate_stored(&p, self.set.rest()[c], &shape, self.set.stored(c));
            let weights = idx.map(|i| self.inverse_masses[i as usize]);
            let (lambda, reach) = (self.set.lambda()[c], self.reach * self.set.size()[c]);
            let (skipped, correction) =
                correction_lanes(evaluation, weights, lambda, self.rule, reach);
            if skipped.any() {
                self.skipped.add(skipped);
            } else {
                self.set.add_lambda(c, correction.delta_lambda);
                for (&i, dx) in idx.iter().zip(correction.delta_x) {
                    self.positions[i as usize] += dx;
                }
            }
        }
    }
}
