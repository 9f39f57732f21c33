//! What a reader sees of one family's constraints in the fast engine ([`FamilyBatches`]: its
//! colours, regions and constraints, in the engine's numbering), and the order a sweep applies
//! corrections in ([`Order`]: Gauss–Seidel, or Jacobi for comparison).

use super::batches::{Batches, Colour, Layout};
use glam::Vec3A;

/// One family's constraints as the fast solver holds them: on its layout, one per element.
#[derive(Clone, Copy)]
pub struct FamilyBatches<'a> {
    pub(super) layout: &'a Layout,
    pub(super) batches: &'a Batches,
}

impl<'a> FamilyBatches<'a> {
    /// The entries of the family's layout: its colours, segment by segment (the regions, then
    /// the border: [`Layout::colours`]; none for a family that is not active).
    pub fn colours(&self) -> &'a [Colour] {
        if self.batches.is_empty() {
            &[]
        } else {
            &self.layout.colours
        }
    }

    /// How many colours each segment of the layout has (none for a family that is not active):
    /// what [`super::FastSimulation::colour_order`] permutes ([`Layout::colour_count`]).
    pub fn colour_count(&self) -> usize {
        if self.batches.is_empty() {
            0
        } else {
            self.layout.colour_count()
        }
    }

    /// The layout's regions ([`Layout::regions`]).
    pub fn regions(&self) -> usize {
        self.layout.regions()
    }

    /// The number of constraints, padding not counted.
    pub fn len(&self) -> usize {
        self.colours().iter().map(|c| c.elements).sum::<usize>()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The particles (the first arity of four, in the constraint's order) and rest value of each
    /// constraint, colour by colour, padding left out.
    pub fn constraints(&self) -> impl Iterator<Item = ([u32; 4], f32)> + 'a {
        self.constraints_storing()
            .map(|(particles, rest, _)| (particles, rest))
    }

    /// [`FamilyBatches::constraints`] with what each stores.
    pub(crate) fn constraints_storing(
        &self,
    ) -> impl Iterator<Item = ([u32; 4], f32, Vec<f32>)> + 'a {
        let batches = self.batches;
        let elements = (!batches.is_empty()).then(|| self.layout.elements());
        elements
            .into_iter()
            .flatten()
            .map(move |(_, particles, at)| (particles, batches.rest_at(at), batches.stored_at(at)))
    }

    /// Whether every colour of its layout really shares no particle.
    pub fn colouring_is_valid(&self, particle_count: usize) -> bool {
        self.layout.colouring_is_valid(particle_count)
    }

    /// How many of its constraints each particle is in.
    pub(super) fn constraints_per_particle(&self, particle_count: usize) -> Vec<u32> {
        let mut count = vec![0; particle_count];
        for (particles, _) in self.constraints() {
            for &i in &particles[..self.layout.arity()] {
                count[i as usize] += 1;
            }
        }
        count
    }
}

/// How a sweep applies the corrections of a family's constraints.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Order {
    /// Gauss–Seidel: each colour starts from the positions the colours before it left.
    GaussSeidel,
    /// Jacobi: every constraint of a family is projected from the same positions, and then each
    /// particle moves by `relaxation` × the mean of the corrections it got (ω/nᵢ Σ Δxᵢ).
    Jacobi {
        /// ω: 1 moves by the mean; larger values overrelax.
        relaxation: f32,
    },
}

/// What the Jacobi order needs: the corrections summed per particle, and per family the factor
/// ω/nᵢ each particle's sum is applied with (nᵢ: the family's constraints on particle i).
pub(super) struct Jacobi {
    pub(super) relaxation: f32,
    pub(super) sums: Vec<Vec3A>,
    pub(super) factors: crate::constraints::PerFamily<Vec<f32>>,
}
