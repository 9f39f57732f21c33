//! What a user (or a lesson, or a test) does to a running simulation: pins, perturbations,
//! particles placed, reset, a grab, external forces and plane strain. Each goes through
//! [`Simulation::state_mut`] or [`Simulation::body_mut`], so that an engine sees it by the
//! revision; an edit of the positions starts the settling of [`super::Settings::settle_edits`].

use super::{Grab, Simulation, State};
use crate::scene::mesh::TetMesh;
use glam::DVec3;

impl Simulation {
    /// Whether particle `i` is pinned.
    pub fn is_pinned(&self, i: usize) -> bool {
        self.state.pinned[i]
    }

    /// Pins or frees particle `i`.
    pub fn set_pinned(&mut self, i: usize, pinned: bool) {
        self.state_mut().pinned[i] = pinned;
        self.refresh_inverse_masses();
    }

    /// Applies a perturbation to the current positions and stops all motion.
    pub fn perturb(&mut self, perturbation: crate::scene::Perturbation) {
        let mesh = TetMesh {
            positions: self.body.rest_positions.clone(),
            tets: self.body.tets.clone(),
        };
        let state = self.state_mut();
        perturbation.apply(&mut state.positions, &mesh);
        stop(state);
        self.settling = Some(0);
    }

    /// Puts every particle at the given positions, at rest (e.g. a state computed elsewhere).
    pub fn set_positions(&mut self, positions: &[DVec3]) {
        let state = self.state_mut();
        state.positions.copy_from_slice(positions);
        stop(state);
    }

    /// Puts particle `i` at `position` at rest (a kinematic move, e.g. a drag while paused).
    pub fn place(&mut self, i: usize, position: DVec3) {
        let state = self.state_mut();
        state.positions[i] = position;
        state.previous[i] = position;
        state.velocities[i] = DVec3::ZERO;
        state.corrections[i] = DVec3::ZERO;
        state.frame_corrections[i] = DVec3::ZERO;
        self.settling = Some(0);
    }

    /// Back to the rest shape, at frame 0: at rest, or as a scene file's bodies were launched
    /// (each with its velocity).
    pub fn reset(&mut self) {
        let (_, body, state) = self.edit();
        state.positions.copy_from_slice(&body.rest_positions);
        stop(state);
        if !body.start_velocities.is_empty() {
            state.velocities.copy_from_slice(&body.start_velocities);
        }
        state.taken = super::Taken::default();
        self.skipped = Default::default();
        self.settling = None;
        self.frame = 0;
        self.time = 0.0;
    }

    /// Starts holding particle `i` at `target`. With zero grab compliance the particle follows the
    /// target exactly (its inverse mass is 0 meanwhile); otherwise a compliant zero-length
    /// constraint pulls it.
    pub fn grab(&mut self, i: usize, target: DVec3) {
        self.release();
        self.state_mut().grab = Some(Grab {
            particle: i,
            target,
            target_at_last_step: target,
            target_velocity: DVec3::ZERO,
            lambda: 0.0,
        });
        self.refresh_inverse_masses();
    }

    /// Moves the held target. Not an edit of the state: every engine reads the grab afresh each
    /// frame.
    pub fn move_grab(&mut self, target: DVec3) {
        if let Some(grab) = &mut self.state.grab {
            grab.target = target;
        }
    }

    /// The current grab, if any.
    pub fn grabbed(&self) -> Option<&Grab> {
        self.state.grab.as_ref()
    }

    /// Lets go: the particle's mass comes back, and it keeps the target's velocity over the last
    /// step so it can be thrown.
    pub fn release(&mut self) {
        if let Some(grab) = self.state.grab {
            let state = self.state_mut();
            state.grab = None;
            state.velocities[grab.particle] = grab.target_velocity;
            self.refresh_inverse_masses();
        }
    }

    /// Sets the external forces, one per particle in N (a traction lumped onto the nodes it
    /// acts on), or none with an empty vector. Each substep adds w fᵢ h to a free particle's
    /// velocity, on either engine; pinned particles feel nothing.
    ///
    /// # Panics
    /// If `forces` is neither empty nor one per particle.
    pub fn set_forces(&mut self, forces: Vec<DVec3>) {
        assert!(
            forces.is_empty() || forces.len() == self.state.positions.len(),
            "one force per particle, or none"
        );
        self.body_mut().forces = forces;
    }

    /// Holds every particle at its current z (on) or frees z again (off): a plane problem
    /// extruded into one layer of tets, held in z, is in plane strain (ε_zz = 0).
    pub fn set_plane_strain(&mut self, on: bool) {
        self.body_mut().plane_strain = on;
    }
}

/// Zeroes every velocity and multiplier, and Δp.
fn stop(state: &mut State) {
    state.previous.copy_from_slice(&state.positions);
    state.velocities.fill(DVec3::ZERO);
    state.corrections.fill(DVec3::ZERO);
    state.frame_corrections.fill(DVec3::ZERO);
    for lambda in state.lambdas.every_place_mut() {
        lambda.fill(0.0);
    }
}
