//! What a reader asks of a simulation between steps: the order of a sweep, the constraints of
//! one tet, one projection described ([`Projection`], by the projection a sweep makes,
//! [`super::reference::project_unit`]), and the counts and warnings the front ends show.

use super::reference::project_unit;
use super::{ConstraintSet, DENSITY, Simulation};
use crate::constraints::material::Material;
use crate::constraints::{Family, Projected, VisitProjected};
use crate::simulation::projection::Rule;
use glam::DVec3;

impl Simulation {
    /// The constraints one sweep projects, in order: every constraint of each active family
    /// (edges, then heights, then volumes), each family's in the order of
    /// [`super::Settings::order_seed`], as (family, index in the family); then each active
    /// family that binds to contacts over the pairs of [`Simulation::contact_pairs`], in the
    /// order the seed gives them, as (family, index of the pair).
    pub fn projection_order(&self) -> impl Iterator<Item = (Family, usize)> + '_ {
        let families = self.families.units(self.active()).flat_map(move |unit| {
            let set = &self.body.sets[unit.lead];
            (0..set.len()).map(move |k| (unit.lead, set.in_order(k)))
        });
        let contact =
            super::contact::ContactPlan::new(&self.families, &self.resolved, &self.state.contacts);
        let contacts = contact.into_iter().flat_map(|plan| {
            let n = plan.found.len();
            let order = plan.order.clone();
            plan.families.clone().into_iter().flat_map(move |family| {
                let order = order.clone();
                (0..n).map(move |k| (family, order.as_ref().map_or(k, |o| o[k] as usize)))
            })
        });
        families.chain(contacts)
    }

    /// The constraints of `family` on tet `tet`, as indices in the family: its edges (six), its
    /// four heights, or its volume ([`crate::constraints::Binding::of_tet`]); none where the
    /// tet's body does not take the family ([`crate::scene::SceneBody::constraints`]).
    pub(crate) fn tet_constraints(
        &self,
        tet: usize,
        family: Family,
    ) -> impl Iterator<Item = usize> + '_ {
        let set = &self.body.sets[family];
        let binding = self.families.binding(family);
        // An edge family's constraints are found by their particles among its own; a tet's
        // by their place in the binding.
        let looked_up = binding == crate::constraints::Binding::Edges;
        (binding.of_tet(tet, self.body.tets[tet], set.all_particles())).filter_map(move |k| {
            if looked_up {
                Some(k)
            } else {
                set.of_binding(k)
            }
        })
    }

    /// The shortest edge of the rest shape (0 without edges).
    pub fn shortest_edge(&self) -> f64 {
        let rest = &self.body.rest_positions;
        let length = |&[a, b]: &[u32; 2]| rest[a as usize].distance(rest[b as usize]);
        let lengths = self.body.edges.iter().map(length);
        lengths.filter(|&l| l > 0.0).reduce(f64::min).unwrap_or(0.0)
    }

    /// Why the settings may blow up, when an active family takes its compliance from the
    /// material and the substeps are too long for it
    /// ([`crate::constraints::material::Material::substeps_needed`]): a warning
    /// every front end shows. In a scene of several bodies, each body's material and density
    /// count ([`crate::scene::SceneBody::material`]), and the warning names the body that needs
    /// the most.
    pub fn stability_warning(&self) -> Option<String> {
        let settings = &self.settings;
        let material_family = self.resolved.material_family()?;
        let shortest = self.shortest_edge();
        let whole = (None, settings.material, DENSITY);
        let bodies = (self.body.bodies.iter())
            .filter(|b| b.takes(&self.families, material_family))
            .map(|b| {
                (
                    Some(b.name.as_str()),
                    b.material.unwrap_or(settings.material),
                    b.density,
                )
            });
        let needs = |&(_, material, density): &(Option<&str>, Material, f64)| {
            material.substeps_needed(settings.dt, shortest, density)
        };
        let worst = if self.body.bodies.is_empty() {
            whole
        } else {
            bodies.max_by_key(needs)?
        };
        let needed = needs(&worst);
        let (body, material, density) = worst;
        (needed > u64::from(settings.substeps)).then(|| {
            format!(
                "{}{} with material {} needs at least {needed} substeps per frame of {:.4} s on \
                 this mesh (pressure waves {:.3e} m/s, shortest edge {:.3e} m); with {} it may \
                 blow up",
                self.families.row(material_family).group,
                body.map_or(String::new(), |name| format!(" on body \"{name}\"")),
                material.describe(),
                settings.dt,
                material.wave_speed(density),
                shortest,
                settings.substeps
            )
        })
    }

    /// Constraint projections one frame makes with the current settings: the active families'
    /// constraints × substeps × iterations.
    pub fn projections_per_frame(&self) -> u64 {
        let counts = self.families.per_family(|f| self.constraint_count(f));
        self.settings.projections_per_frame(counts)
    }

    /// How many constraints `family` has.
    pub fn constraint_count(&self, family: Family) -> usize {
        self.body.sets[family].len()
    }

    /// The particles of every constraint of `family`, flat, its arity per constraint (of a
    /// family on single particles: the particles it holds).
    pub fn constraint_particles(&self, family: Family) -> &[u32] {
        self.body.sets[family].all_particles()
    }

    /// What projecting constraint `c` of `family` now would do, with the current λ and the rule
    /// (XPBD or PBD) of the current settings: C, ∇C, the inverse masses, Δλ and Δx.
    ///
    /// A family projected together with another ([`crate::constraints::Row::projected_with`])
    /// shows its own C and ∇C, and its Δλ and the Δx of the pair's projection: what a sweep does.
    ///
    /// For a family that binds to contacts, `c` is a pair of [`Simulation::contact_pairs`].
    pub fn projection(&self, family: Family, c: usize) -> Projection {
        if self.families.binding(family) == crate::constraints::Binding::Contacts {
            return self.contact_projection(family, c);
        }
        let unit = self.families.unit_of(family, self.active());
        let h = self.substep_length();
        let describe = Describe {
            simulation: self,
            family,
            c,
            rule: |f| self.resolved.rule(f, h),
        };
        self.families.visit_unit(unit, describe)
    }
}

impl Projection {
    /// What the element stores.
    pub fn stored(&self) -> &[f64] {
        &self.stored[..self.stored_len]
    }
}

/// One constraint, described for a reader: see [`Simulation::projection`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    /// The constraint's family.
    pub family: Family,
    /// Its index within the family.
    pub constraint: usize,
    /// Its particles; the first [`Projection::len`] are used (2 for an edge, 4 otherwise).
    pub particles: [u32; 4],
    /// How many particles it has.
    pub len: usize,
    /// C now.
    pub value: f64,
    /// The rest value, d or V.
    pub rest: f64,
    /// What the element stores ([`crate::constraints::Constraint::store`]), the first
    /// `stored_len`: read them with [`Projection::stored`].
    pub stored: [f64; crate::constraints::MAX_STORED],
    /// How many numbers it stores.
    pub stored_len: usize,
    /// ∇ₚC for each particle.
    pub gradients: [DVec3; 4],
    /// The inverse mass w of each particle (0 if pinned or held).
    pub inverse_masses: [f64; 4],
    /// Σ wᵢ |∇ₚᵢC|².
    pub weighted_norm: f64,
    /// λ accumulated so far in this substep (XPBD).
    pub lambda: f64,
    /// XPBD: Δλ; PBD: k′ s. `None` when the projection is skipped (degenerate, every particle
    /// fixed, or [`crate::simulation::projection::LOCKED`]).
    pub delta_lambda: Option<f64>,
    /// Δx the projection would give each particle (zero when skipped).
    pub delta_x: [DVec3; 4],
    /// Whether ∇C is undefined here.
    pub degenerate: bool,
    /// The element's size at rest: its longest rest edge (of a particle alone, the longest
    /// rest edge at it), what the reach is measured in and arrows are drawn to.
    pub size: f64,
}

impl Projection {
    /// The particles it uses.
    pub fn particles(&self) -> &[u32] {
        &self.particles[..self.len]
    }
}

/// [`Projection`] of constraint `c` of `family`, within the projection of its unit.
struct Describe<'a, R> {
    simulation: &'a Simulation,
    family: Family,
    c: usize,
    rule: R,
}

impl<R: Fn(Family) -> Rule<f64>> VisitProjected for Describe<'_, R> {
    type Output = Projection;

    fn visit<const N: usize, const K: usize, P: Projected<N, K>>(
        self,
        families: [Family; K],
        constraint: &P,
    ) -> Projection {
        let (simulation, c) = (self.simulation, self.c);
        let (body, state) = (&simulation.body, &simulation.state);
        let arrays = (
            &state.positions[..],
            &body.rest_positions[..],
            &state.inverse_masses[..],
        );
        let rules = families.map(&self.rule);
        let reach = simulation.settings.reach;
        let h = simulation.settings.dt / f64::from(simulation.settings.substeps);
        let unit = project_unit(
            constraint,
            families,
            &body.sets,
            &state.lambdas,
            arrays,
            (&state.previous, h),
            rules,
            reach,
            c,
        );
        let v = families.iter().position(|&f| f == self.family).unwrap_or(0);
        let (evaluation, correction) = (unit.evaluations[v], unit.correction);
        let set: &ConstraintSet = &body.sets[self.family];
        let skipped = if K == 1 {
            correction.skipped[0].any()
        } else {
            correction.skipped[v].all
        };
        let mut projection = Projection {
            family: self.family,
            constraint: c,
            particles: [0; 4],
            len: N,
            value: evaluation.value,
            rest: set.rest()[c],
            stored: std::array::from_fn(|k| set.stored(c).get(k).copied().unwrap_or(0.0)),
            stored_len: set.stored_len(),
            gradients: [DVec3::ZERO; 4],
            inverse_masses: [0.0; 4],
            weighted_norm: crate::simulation::projection::weighted_norm(
                &unit.weights,
                &evaluation.gradients,
            ),
            lambda: unit.lambda[v],
            delta_lambda: (!skipped).then_some(correction.delta_lambda[v]),
            delta_x: [DVec3::ZERO; 4],
            degenerate: evaluation.degenerate,
            size: set.size()[c],
        };
        for k in 0..N {
            projection.particles[k] = unit.particles[k];
            projection.gradients[k] = evaluation.gradients[k];
            projection.inverse_masses[k] = unit.weights[k];
            if !(K == 1 && skipped) {
                projection.delta_x[k] = correction.delta_x[k];
            }
        }
        projection
    }
}
