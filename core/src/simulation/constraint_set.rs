//! The constraints of one family as a simulation keeps them: flat arrays, one entry per
//! constraint in the binding's order (the particles, `arity` of them each; the rest value; what
//! it stores; the size of its element), built once from the family's binding to the mesh, and
//! the order a sweep projects them in (the binding's, or a permutation drawn from an order seed).
//! Their multipliers λ are the state's ([`super::State::lambdas`]).

use crate::constraint_file::ConstraintFile;
use crate::constraints::differentiable::of_constraint;
use crate::constraints::material::Material;
use crate::constraints::{Families, Family};
use crate::scene::mesh::TetMesh;
use glam::DVec3;
use std::sync::Arc;

/// One family's constraints.
#[derive(Clone, Debug, Default)]
pub struct ConstraintSet {
    /// Whether it was built (the sets of families a simulation does not use stay empty).
    built: bool,
    /// The file it was built from, for a file's family: a redefined family has another
    /// ([`Families::same_definition`]).
    file: Option<Arc<ConstraintFile>>,
    arity: usize,
    particles: Vec<u32>,
    rest: Vec<f64>,
    /// What each constraint stores ([`Constraint::store`]), `stored_len` numbers each.
    stored: Vec<f64>,
    stored_len: usize,
    /// The size of each constraint's element: the longest rest edge among its particles, what
    /// its reach is measured in ([`crate::simulation::Settings::reach`]).
    size: Vec<f64>,
    /// The order a sweep projects the constraints in; empty for 0, 1, 2, …
    /// ([`crate::simulation::Settings::order_seed`]).
    order: Vec<u32>,
    /// Σ C(x⁰)² over the constraints at the rest shape (not 0 for a pre-stressed family such as
    /// the neo-Hookean pair); the C that are not finite left out.
    rest_squared: f64,
}

impl ConstraintSet {
    /// The constraints of `family` on `mesh` ([`crate::constraints::Binding::particles`]), each
    /// with its rest value measured on the mesh's rest positions ([`Constraint::rest_value`]).
    pub(crate) fn new(
        families: &Families,
        family: Family,
        mesh: &TetMesh,
        material: &Material,
    ) -> ConstraintSet {
        let arity = families.arity(family);
        let particles = families.particles_on(family, mesh);
        let size = match arity {
            // A particle alone has no size of its own: the longest rest edge at it.
            1 => {
                let longest = mesh.longest_edge_at();
                particles.iter().map(|&i| longest[i as usize]).collect()
            }
            _ => particles
                .chunks_exact(arity)
                .map(|idx| {
                    crate::scene::mesh::longest_edge(
                        idx.iter().map(|&i| mesh.positions[i as usize]),
                    )
                })
                .collect(),
        };
        let mut set = ConstraintSet {
            built: true,
            file: families.file(family).cloned(),
            arity,
            particles,
            rest: Vec::new(),
            stored: Vec::new(),
            stored_len: 0,
            size,
            order: Vec::new(),
            rest_squared: 0.0,
        };
        set.measure_rest(families, family, &mesh.positions, material);
        set
    }

    /// Measures the rest values again on `rest_positions`, with `material` (for a family whose
    /// rest values depend on it, when the material changes).
    pub(crate) fn measure_rest(
        &mut self,
        families: &Families,
        family: Family,
        rest_positions: &[DVec3],
        material: &Material,
    ) {
        if !self.built {
            return;
        }
        let constraint = families.constraint(family);
        let shapes = || {
            self.particles
                .chunks_exact(self.arity)
                .map(|idx| idx.iter().map(|&i| rest_positions[i as usize]))
        };
        let mut shape = Vec::with_capacity(self.arity);
        let mut rest = Vec::with_capacity(self.particles.len() / self.arity);
        let stored_len = families.row(family).stored_len;
        let mut stored = Vec::with_capacity(rest.capacity() * stored_len);
        for points in shapes() {
            shape.clear();
            shape.extend(points);
            rest.push(constraint.rest_value(&shape, material));
            if stored_len > 0 {
                stored.extend(constraint.store(&shape, material));
            }
        }
        (self.rest, self.stored, self.stored_len) = (rest, stored, stored_len);
        self.rest_squared = (0..self.len())
            .map(|c| {
                let rest = (self.rest[c], self.stored(c));
                let particles = self.particles(c);
                let at = rest_positions;
                of_constraint(families, family, particles, rest, at, at).0
            })
            .filter(|c| c.is_finite())
            .map(|c| c * c)
            .sum();
    }

    /// Σ C(x⁰)² over the constraints at the rest shape, as last measured (0 for a family whose
    /// constraints all hold there; not for a pre-stressed one such as the neo-Hookean pair).
    pub fn rest_squared(&self) -> f64 {
        self.rest_squared
    }

    /// Whether it was built from the definition of `family` in `families`.
    pub(crate) fn is_current(&self, families: &Families, family: Family) -> bool {
        self.built
            && match (&self.file, families.file(family)) {
                (None, None) => true,
                (Some(built), Some(now)) => Arc::ptr_eq(built, now),
                _ => false,
            }
    }

    /// Whether it was built at all (the sets of families that joined the table after the
    /// simulation was made are built when they are switched on).
    pub(crate) fn is_built(&self) -> bool {
        self.built
    }

    /// The number of constraints.
    pub fn len(&self) -> usize {
        self.rest.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.rest.is_empty()
    }

    /// How many particles each constraint touches.
    pub fn arity(&self) -> usize {
        self.arity
    }

    /// The particles of constraint `c`, in the constraint's own order.
    pub fn particles(&self, c: usize) -> &[u32] {
        &self.particles[c * self.arity..(c + 1) * self.arity]
    }

    /// The particles of every constraint, flat (`arity` per constraint).
    pub fn all_particles(&self) -> &[u32] {
        &self.particles
    }

    /// The particles of constraint `c` as an array of the family's arity `N`.
    #[inline]
    pub(crate) fn indices<const N: usize>(&self, c: usize) -> [u32; N] {
        debug_assert_eq!(N, self.arity);
        let (groups, _) = self.particles.as_chunks::<N>();
        groups[c]
    }

    /// What constraint `c` stores ([`crate::constraints::Constraint::store`]; empty for a built-in family).
    pub fn stored(&self, c: usize) -> &[f64] {
        &self.stored[c * self.stored_len..(c + 1) * self.stored_len]
    }

    /// How many numbers each constraint stores.
    pub fn stored_len(&self) -> usize {
        self.stored_len
    }

    /// The rest values.
    pub fn rest(&self) -> &[f64] {
        &self.rest
    }

    /// The size of each constraint's element: the longest rest edge among its particles.
    pub fn size(&self) -> &[f64] {
        &self.size
    }

    /// Sets the order a sweep projects the constraints in: a permutation of 0..len, or `None`
    /// for the binding's order.
    pub(crate) fn set_order(&mut self, order: Option<Vec<u32>>) {
        self.order = order.unwrap_or_default();
        debug_assert!(self.order.is_empty() || self.order.len() == self.len());
    }

    /// The constraint a sweep projects `k`-th.
    #[inline]
    pub fn in_order(&self, k: usize) -> usize {
        self.order.get(k).map_or(k, |&c| c as usize)
    }

    /// The bytes its arrays take (their capacities).
    pub(crate) fn heap_bytes(&self) -> usize {
        (self.particles.capacity() + self.order.capacity()) * size_of::<u32>()
            + (self.rest.capacity() + self.stored.capacity() + self.size.capacity())
                * size_of::<f64>()
    }
}
