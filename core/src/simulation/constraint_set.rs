//! The constraints of one family as a simulation keeps them: flat arrays, one entry per
//! constraint in the binding's order (the particles, `arity` of them each; the rest value; what
//! it stores; the size of its element; the compliance of a body's own material), built once from
//! the family's binding to the mesh, and the order a sweep projects them in (the binding's, or a
//! permutation drawn from an order seed). Their multipliers λ are the state's
//! ([`super::State::lambdas`]).
//!
//! In a scene of several bodies each constraint belongs to the body of its first particle
//! ([`SceneBody::owner`]): it is laid only where that body takes the family
//! ([`SceneBody::constraints`]), and a body of its own material ([`SceneBody::material`]) gives
//! it that material's rest value and compliance ([`ConstraintSet::own_compliance`]).

use crate::constraint_file::ConstraintFile;
use crate::constraints::differentiable::of_constraint;
use crate::constraints::material::Material;
use crate::constraints::{Families, Family};
use crate::scene::SceneBody;
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
    /// The place each constraint has in the binding's list, where some were left out (the
    /// bodies that do not take the family); empty where none was.
    placed: Vec<u32>,
    /// Each constraint's compliance α from its body's own material, NaN where it takes the
    /// family's ([`ConstraintSet::own_compliance`]); empty where none has one.
    own: Vec<f64>,
    /// Σ C(x⁰)² over the constraints at the rest shape that take the family's compliance (not 0
    /// for a pre-stressed family such as the neo-Hookean pair), and Σ C(x⁰)² / α over those of
    /// their own; the C that are not finite left out.
    rest_squared: (f64, f64),
}

impl ConstraintSet {
    /// The constraints of `family` on `mesh` ([`crate::constraints::Binding::particles`]) of
    /// the bodies among `bodies` that take it (every one where `bodies` is empty), each with its
    /// rest value measured on the mesh's rest positions ([`Constraint::rest_value`]) with its
    /// body's material, `material` where the body has none of its own.
    pub(crate) fn new(
        families: &Families,
        family: Family,
        mesh: &TetMesh,
        (material, bodies): (&Material, &[SceneBody]),
    ) -> ConstraintSet {
        let arity = families.arity(family);
        let mut particles = families.particles_on(family, mesh);
        let taken = |first: u32| {
            SceneBody::owner(bodies, first).is_none_or(|b| bodies[b].takes(families, family))
        };
        let mut placed = Vec::new();
        if arity > 0 && bodies.iter().any(|b| !b.takes(families, family)) {
            for c in 0..particles.len() / arity {
                if taken(particles[c * arity]) {
                    let kept = placed.len();
                    particles.copy_within(c * arity..(c + 1) * arity, kept * arity);
                    placed.push(c as u32);
                }
            }
            particles.truncate(placed.len() * arity);
        }
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
            placed,
            own: Vec::new(),
            rest_squared: (0.0, 0.0),
        };
        set.measure_rest(families, family, &mesh.positions, (material, bodies));
        set
    }

    /// Measures the rest values again on `rest_positions`, each with its body's material among
    /// `bodies`, `material` where it has none of its own (for a family whose rest values depend
    /// on it, when the material changes), and the compliances the bodies' own materials give.
    pub(crate) fn measure_rest(
        &mut self,
        families: &Families,
        family: Family,
        rest_positions: &[DVec3],
        (material, bodies): (&Material, &[SceneBody]),
    ) {
        if !self.built {
            return;
        }
        let constraint = families.constraint(family);
        let from_material = families.row(family).compliance_from_material;
        let own_material = |c: usize| {
            let first = self.particles[c * self.arity];
            SceneBody::owner(bodies, first).and_then(|b| bodies[b].material.as_ref())
        };
        let count = self.particles.len() / self.arity.max(1);
        let mut shape = Vec::with_capacity(self.arity);
        let mut rest = Vec::with_capacity(count);
        let stored_len = families.row(family).stored_len;
        let mut stored = Vec::with_capacity(count * stored_len);
        let mut own = Vec::new();
        if let Some(compliance) = from_material
            && (0..count).any(|c| own_material(c).is_some())
        {
            own = (0..count)
                .map(|c| own_material(c).map_or(f64::NAN, compliance))
                .collect();
        }
        for c in 0..count {
            let material = own_material(c).unwrap_or(material);
            let idx = &self.particles[c * self.arity..(c + 1) * self.arity];
            shape.clear();
            shape.extend(idx.iter().map(|&i| rest_positions[i as usize]));
            rest.push(constraint.rest_value(&shape, material));
            if stored_len > 0 {
                stored.extend(constraint.store(&shape, material));
            }
        }
        (self.rest, self.stored, self.stored_len, self.own) = (rest, stored, stored_len, own);
        self.rest_squared = (0.0, 0.0);
        for c in 0..self.len() {
            let rest = (self.rest[c], self.stored(c));
            let particles = self.particles(c);
            let at = rest_positions;
            let value = of_constraint(families, family, particles, rest, at, at).0;
            if value.is_finite() {
                match self.own_compliance(c) {
                    Some(alpha) => self.rest_squared.1 += value * value / alpha,
                    None => self.rest_squared.0 += value * value,
                }
            }
        }
    }

    /// At the rest shape, as last measured: Σ C(x⁰)² over the constraints that take the
    /// family's compliance (0 for a family whose constraints all hold there; not for a
    /// pre-stressed one such as the neo-Hookean pair), and Σ C(x⁰)² / α over those with one of
    /// their own ([`ConstraintSet::own_compliance`]).
    pub fn rest_squared(&self) -> (f64, f64) {
        self.rest_squared
    }

    /// The compliance α constraint `c` takes from its body's own material
    /// ([`SceneBody::material`]), for a family whose compliance a material gives; `None` where
    /// it takes the family's ([`super::Resolved::compliance`]).
    #[inline]
    pub fn own_compliance(&self, c: usize) -> Option<f64> {
        self.own.get(c).copied().filter(|a| !a.is_nan())
    }

    /// The constraint that has place `k` in the binding's list
    /// ([`crate::constraints::Binding::particles`]), `None` where that one was left out (its body
    /// does not take the family) or there is none.
    pub fn of_binding(&self, k: usize) -> Option<usize> {
        if self.placed.is_empty() {
            return (k < self.len()).then_some(k);
        }
        self.placed.binary_search(&(k as u32)).ok()
    }

    /// Whether it holds the binding's whole list (every body takes the family).
    pub fn is_whole(&self) -> bool {
        self.placed.is_empty()
    }

    /// Each constraint's own compliance, NaN where it takes the family's; empty where none has
    /// one of its own.
    pub fn own_compliances(&self) -> &[f64] {
        &self.own
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
        (self.particles.capacity() + self.order.capacity() + self.placed.capacity())
            * size_of::<u32>()
            + (self.rest.capacity()
                + self.stored.capacity()
                + self.size.capacity()
                + self.own.capacity())
                * size_of::<f64>()
    }
}
