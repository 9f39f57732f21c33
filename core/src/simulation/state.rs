//! What a simulation owns and every engine steps: the [`Body`] (the rest shape, its masses, its
//! constraints, the loads and holds it is simulated under) and the [`State`] (where the particles
//! are and how they move, the constraints' multipliers, the grab), in f64 and in the scene's
//! numbering: the state every front end reads, whichever engine stepped it.
//!
//! A [`Revision`] counts the edits of each. Code that changes the state or the body does it
//! through [`super::Simulation::state_mut`] or [`super::Simulation::body_mut`], which bump it; an
//! engine that keeps a copy of its own (the fast engine's f32 arrays) compares the revision it
//! last saw with the simulation's and takes up the change before its next frame. No edit has to
//! tell an engine anything.

use super::ConstraintSet;
use crate::constraints::PerFamily;
use glam::DVec3;

/// A particle held by the user.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grab {
    /// The particle.
    pub particle: usize,
    /// Where the user holds it.
    pub target: DVec3,
    pub(super) target_at_last_step: DVec3,
    /// How fast the target moved over the last step.
    pub target_velocity: DVec3,
    /// The multiplier of the compliant grab, accumulated within a substep.
    pub(super) lambda: f64,
}

/// The body a simulation moves: its rest shape, its constraints and what it is simulated under.
/// It changes only by an edit of the body ([`Revision::body`]): forces set, plane strain
/// switched, constraints built, rebuilt, measured again or put in another order.
#[derive(Clone, Debug)]
pub struct Body {
    /// Rest positions (the scene as made).
    pub rest_positions: Vec<DVec3>,
    /// The tets, as indices into the positions.
    pub tets: Vec<[u32; 4]>,
    /// Inverse masses lumped from density × rest volume / 4 per tet, pins not counted.
    pub lumped_inverse_masses: Vec<f64>,
    /// External forces per particle in N, besides gravity (empty: none).
    pub forces: Vec<DVec3>,
    /// Whether every particle keeps its z (plane strain).
    pub plane_strain: bool,
    /// The mean rest edge length, the scale of "settled".
    pub mean_edge: f64,
    /// The mesh's edges, sorted pairs in order, whichever families are laid on them (the edge
    /// family's constraints are those of the bodies that take it,
    /// [`crate::scene::SceneBody::constraints`]).
    pub edges: Vec<[u32; 2]>,
    /// The constraints of each family, as its binding makes them (those of a family the
    /// simulation has not used are not built).
    pub sets: PerFamily<ConstraintSet>,
    /// Each particle's velocity at the start (the scene file's bodies'); empty: at rest.
    pub start_velocities: Vec<DVec3>,
    /// The bodies of a scene file; empty for a scene of one body.
    pub bodies: Vec<crate::scene::SceneBody>,
    /// The surface contact is found on, made when first asked for ([`Body::contact_surface`]).
    pub(crate) contact_surface: std::sync::OnceLock<super::contact::surface::ContactSurface>,
}

/// Where the particles are and how they move, in f64 and in the scene's numbering.
#[derive(Clone, Debug)]
pub struct State {
    /// Current positions.
    pub positions: Vec<DVec3>,
    /// Positions at the start of the substep.
    pub previous: Vec<DVec3>,
    /// Current velocities.
    pub velocities: Vec<DVec3>,
    /// Inverse masses in use: the lumped ones, 0 where pinned or rigidly grabbed.
    pub inverse_masses: Vec<f64>,
    /// Whether each particle is pinned.
    pub pinned: Vec<bool>,
    /// Δp of the last substep; during a substep, the predicted positions.
    pub corrections: Vec<DVec3>,
    /// The sum of Δp over the substeps of the frame so far, the measure of "settled".
    pub frame_corrections: Vec<DVec3>,
    /// The XPBD multiplier λ of each constraint of each family ([`Body::sets`]), accumulated
    /// within the current substep.
    pub lambdas: PerFamily<Vec<f64>>,
    /// The particle the user holds, if any. Read afresh every frame: moving its target is not an
    /// edit ([`super::Simulation::move_grab`]).
    pub grab: Option<Grab>,
    /// The ground's moves of each particle within the current substep (what it took is worked
    /// out from them at the substep's end: `integrate::Book`).
    pub pushes: Vec<DVec3>,
    /// Per particle, what the ground, damping and the settling cap took within the current
    /// substep (J), before it is added to [`State::taken`].
    pub taken_by_particle: Vec<DVec3>,
    /// What the ground, damping and the settling cap took from the body so far, J.
    pub taken: Taken,
    /// The contact pairs found at the start of the last frame, [particle, a, b, c]
    /// ([`super::contact`]); empty when no family binds to contacts.
    pub contacts: std::sync::Arc<Vec<[u32; 4]>>,
    /// The XPBD multiplier of each contact pair of each contact family (family by family, in
    /// the order of the contact plan), within the current substep.
    pub contact_lambdas: Vec<f64>,
}

/// The energy taken from a body by what is not a family (J): the ground (its impulses against
/// the particles' motion: landings, and its sticking friction), velocity damping, and the cap
/// on speed while an edit settles. What XPBD's own projections dissipate is not among them: it
/// is what the energy account's total lost beyond these.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Taken {
    /// By the ground, J.
    pub ground: f64,
    /// By velocity damping, J.
    pub damping: f64,
    /// By the speed cap of settling edits, J.
    pub settling: f64,
}

impl Taken {
    /// Adds per-particle tallies (x the ground's, y damping's, z the cap's, J) in order, and
    /// zeroes them.
    pub(crate) fn add_and_clear<V: crate::numbers::vector::Vector3>(&mut self, tallies: &mut [V])
    where
        V::Real: Into<f64>,
    {
        let zero = V::from_f64s(0.0, 0.0, 0.0);
        for tally in tallies {
            let [ground, damping, settling] = tally.to_array();
            self.ground += ground.into();
            self.damping += damping.into();
            self.settling += settling.into();
            *tally = zero;
        }
    }

    /// The sum of the three, J.
    pub fn total(&self) -> f64 {
        self.ground + self.damping + self.settling
    }
}

impl std::ops::Sub for Taken {
    type Output = Taken;
    fn sub(self, other: Taken) -> Taken {
        Taken {
            ground: self.ground - other.ground,
            damping: self.damping - other.damping,
            settling: self.settling - other.settling,
        }
    }
}

/// How many times the body and the state have been edited: what an engine compares with what
/// it last saw ([`super::engine::Frame::revision`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Revision {
    /// Edits of the [`Body`]: an engine built from it builds again.
    pub body: u64,
    /// Edits of the [`State`] from outside the engines (perturbations, particles placed or
    /// pinned, a grab, a step taken one projection at a time): an engine that copies the state
    /// takes it up again.
    pub state: u64,
}

impl State {
    /// A body at rest at its rest positions, with nothing pinned.
    pub(super) fn at_rest(body: &Body) -> State {
        let n = body.rest_positions.len();
        State {
            positions: body.rest_positions.clone(),
            previous: body.rest_positions.clone(),
            velocities: match body.start_velocities.len() {
                0 => vec![DVec3::ZERO; n],
                _ => body.start_velocities.clone(),
            },
            inverse_masses: body.lumped_inverse_masses.clone(),
            pinned: vec![false; n],
            corrections: vec![DVec3::ZERO; n],
            frame_corrections: vec![DVec3::ZERO; n],
            lambdas: body.sets.map(|set| vec![0.0; set.len()]),
            grab: None,
            pushes: vec![DVec3::ZERO; n],
            taken_by_particle: vec![DVec3::ZERO; n],
            taken: Taken::default(),
            contacts: std::sync::Arc::default(),
            contact_lambdas: Vec::new(),
        }
    }

    /// The inverse masses the state should have: the lumped ones, 0 where pinned or held by
    /// `rigid_grab`.
    pub(super) fn wanted_inverse_mass(&self, body: &Body, i: usize, rigid_grab: bool) -> f64 {
        let held = rigid_grab && self.grab.is_some_and(|g| g.particle == i);
        if self.pinned[i] || held {
            0.0
        } else {
            body.lumped_inverse_masses[i]
        }
    }

    /// The bytes of memory its arrays take (their capacities).
    pub(super) fn heap_bytes(&self) -> usize {
        fn bytes<T>(v: &Vec<T>) -> usize {
            v.capacity() * size_of::<T>()
        }
        bytes(&self.positions)
            + bytes(&self.previous)
            + bytes(&self.velocities)
            + bytes(&self.inverse_masses)
            + bytes(&self.pinned)
            + bytes(&self.corrections)
            + bytes(&self.frame_corrections)
            + bytes(&self.pushes)
            + bytes(&self.taken_by_particle)
            + (self.lambdas.every_place())
                .map(|l| l.capacity() * size_of::<f64>())
                .sum::<usize>()
    }
}

impl Body {
    /// The surface contact is found on: its triangles, particles and neighbours.
    pub fn contact_surface(&self) -> &super::contact::surface::ContactSurface {
        self.contact_surface.get_or_init(|| {
            super::contact::surface::ContactSurface::of(&self.tets, self.rest_positions.len())
        })
    }

    /// The diagonal of the rest shape's bounding box, in metres: the size of the body (0 for
    /// none).
    pub fn rest_diagonal(&self) -> f64 {
        let rest = &self.rest_positions;
        let (low, high) = rest.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(low, high), p| (low.min(*p), high.max(*p)),
        );
        if rest.is_empty() {
            0.0
        } else {
            low.distance(high)
        }
    }

    /// The bytes of memory its arrays take (their capacities).
    pub(super) fn heap_bytes(&self) -> usize {
        self.rest_positions.capacity() * size_of::<DVec3>()
            + self.tets.capacity() * size_of::<[u32; 4]>()
            + self.lumped_inverse_masses.capacity() * size_of::<f64>()
            + self.forces.capacity() * size_of::<DVec3>()
            + (self.sets.every_place())
                .map(ConstraintSet::heap_bytes)
                .sum::<usize>()
    }
}
