//! What a user (or a lesson, or a test) does to a running simulation: pins, perturbations,
//! particles placed, reset, a grab, external forces and plane strain. Each edit tells the fast
//! engine to take the state up again, and starts the settling of [`Settings::settle_edits`].

use super::*;

impl Simulation {
    /// Whether particle `i` is pinned.
    pub fn is_pinned(&self, i: usize) -> bool {
        self.pinned[i]
    }

    /// Pins or frees particle `i`.
    pub fn set_pinned(&mut self, i: usize, pinned: bool) {
        self.pinned[i] = pinned;
        self.update_inverse_masses();
        self.fast.edited();
    }

    /// Applies a perturbation to the current positions and stops all motion.
    pub fn perturb(&mut self, perturbation: crate::scene::Perturbation) {
        let mesh = TetMesh {
            positions: self.rest_positions.clone(),
            tets: self.tets.clone(),
        };
        perturbation.apply(&mut self.positions, &mesh);
        self.stop();
        self.settling = Some(0);
    }

    /// Puts every particle at the given positions, at rest (e.g. a state computed elsewhere).
    pub fn set_positions(&mut self, positions: &[DVec3]) {
        self.positions.copy_from_slice(positions);
        self.stop();
    }

    /// Puts particle `i` at `position` at rest (a kinematic move, e.g. a drag while paused).
    pub fn place(&mut self, i: usize, position: DVec3) {
        self.fast.edited();
        self.positions[i] = position;
        self.previous[i] = position;
        self.velocities[i] = DVec3::ZERO;
        self.corrections[i] = DVec3::ZERO;
        self.frame_corrections[i] = DVec3::ZERO;
        self.settling = Some(0);
    }

    /// Back to the rest shape, at rest, at frame 0.
    pub fn reset(&mut self) {
        self.positions.copy_from_slice(&self.rest_positions);
        self.skipped = PerFamily::default();
        self.stop();
        self.settling = None;
        self.frame = 0;
        self.time = 0.0;
    }

    /// Zeroes every velocity and multiplier.
    pub(super) fn stop(&mut self) {
        self.fast.edited();
        self.previous.copy_from_slice(&self.positions);
        self.velocities.fill(DVec3::ZERO);
        self.corrections.fill(DVec3::ZERO);
        self.frame_corrections.fill(DVec3::ZERO);
        for family in self.families.all() {
            self.sets[family].reset_lambda();
        }
    }

    /// Starts holding particle `i` at `target`. With zero grab compliance the particle follows the
    /// target exactly (its inverse mass is 0 meanwhile); otherwise a compliant zero-length
    /// constraint pulls it.
    pub fn grab(&mut self, i: usize, target: DVec3) {
        self.release();
        self.grab = Some(Grab {
            particle: i,
            target,
            target_at_last_step: target,
            target_velocity: DVec3::ZERO,
            lambda: 0.0,
        });
        self.update_inverse_masses();
        self.fast.edited();
    }

    /// Moves the held target.
    pub fn move_grab(&mut self, target: DVec3) {
        if let Some(grab) = &mut self.grab {
            grab.target = target;
        }
    }

    /// The current grab, if any.
    pub fn grabbed(&self) -> Option<&Grab> {
        self.grab.as_ref()
    }

    /// Lets go: the particle's mass comes back, and it keeps the target's velocity over the last
    /// step so it can be thrown.
    pub fn release(&mut self) {
        if let Some(grab) = self.grab.take() {
            self.velocities[grab.particle] = grab.target_velocity;
            self.update_inverse_masses();
            self.fast.edited();
        }
    }

    pub(super) fn rigid_grab(&self) -> Option<Grab> {
        self.grab.filter(|_| self.settings.grab_compliance <= 0.0)
    }

    /// Sets the external forces, one per particle in N (a traction lumped onto the nodes it
    /// acts on), or none with an empty vector. Each substep adds w fᵢ h to a free particle's
    /// velocity, on either engine; pinned particles feel nothing.
    ///
    /// # Panics
    /// If `forces` is neither empty nor one per particle.
    pub fn set_forces(&mut self, forces: Vec<DVec3>) {
        assert!(
            forces.is_empty() || forces.len() == self.positions.len(),
            "one force per particle, or none"
        );
        self.forces = forces;
        self.fast.solver = None;
    }

    /// Holds every particle at its current z (on) or frees z again (off): a plane problem
    /// extruded into one layer of tets, held in z, is in plane strain (ε_zz = 0).
    pub fn set_plane_strain(&mut self, on: bool) {
        self.plane_strain = on;
        self.fast.solver = None;
    }
}
