//! What a reader asks of a simulation between steps: the order of a sweep, the constraints of
//! one tet, one projection described ([`Projection`]) or made (step-by-step mode), and the
//! counts and warnings the front ends show.

use super::*;

impl Simulation {
    /// The constraints one sweep projects, in order: every constraint of each active family
    /// (edges, then heights, then volumes), each family's in the order of
    /// [`Settings::order_seed`], as (family, index in the family).
    pub fn projection_order(&self) -> impl Iterator<Item = (Family, usize)> + '_ {
        let active = self.settings.active;
        self.families
            .all()
            .filter(move |&f| active[f] && !self.families.projected_by_partner(f, &active))
            .flat_map(move |f| {
                let set = &self.sets[f];
                (0..set.len()).map(move |k| (f, set.in_order(k)))
            })
    }

    /// The constraints of `family` on tet `tet`, as indices in the family: its edges (six), its
    /// four heights, or its volume ([`crate::constraints::Binding::of_tet`]).
    pub fn tet_constraints(&self, tet: usize, family: Family) -> impl Iterator<Item = usize> + '_ {
        let edges = self.sets[Family::EDGES].all_particles();
        self.families
            .binding(family)
            .of_tet(tet, self.tets[tet], edges)
    }

    /// The constraints of `family`: their particles, rest values and multipliers.
    pub fn constraints(&self, family: Family) -> &ConstraintSet {
        &self.sets[family]
    }

    /// The shortest edge of the rest shape (0 without edges).
    pub fn shortest_edge(&self) -> f64 {
        let lengths = self.sets[Family::EDGES].rest().iter().copied();
        lengths.filter(|&l| l > 0.0).reduce(f64::min).unwrap_or(0.0)
    }

    /// Why the settings may blow up, when an active family takes its compliance from the
    /// material and the substeps are too long for it
    /// ([`crate::constraints::material::Material::substeps_needed`]): a warning
    /// every front end shows.
    pub fn stability_warning(&self) -> Option<String> {
        let settings = &self.settings;
        let material_family = settings
            .active
            .families()
            .find(|&f| settings.from_material[f])?;
        let shortest = self.shortest_edge();
        let material = settings.material;
        let needed = material.substeps_needed(settings.dt, shortest, DENSITY);
        (needed > u64::from(settings.substeps)).then(|| {
            format!(
                "{} with material {} needs at least {needed} substeps per frame of {:.4} s on this \
                 mesh (pressure waves {:.3e} m/s, shortest edge {:.3e} m); with {} it may blow \
                 up",
                self.families.row(material_family).group,
                material.describe(),
                settings.dt,
                material.wave_speed(DENSITY),
                shortest,
                settings.substeps
            )
        })
    }

    /// Constraint projections one frame makes with the current settings: the active families'
    /// constraints × substeps × iterations.
    pub fn projections_per_frame(&self) -> u64 {
        self.settings
            .projections_per_frame(self.families.per_family(|f| self.constraint_count(f)))
    }

    /// How many constraints `family` has.
    pub fn constraint_count(&self, family: Family) -> usize {
        self.sets[family].len()
    }

    /// What projecting constraint `c` of `family` now would do, with the current λ and the rule
    /// (XPBD or PBD) of the current settings: C, ∇C, the inverse masses, Δλ and Δx.
    ///
    /// A family projected together with another ([`Families::partner_in`]) shows its own C and
    /// ∇C, and the Δλ and Δx of the pair's projection.
    pub fn projection(&self, family: Family, c: usize) -> Projection {
        let h = self.substep_length();
        let rule = self.rule(family, h);
        let mut projection = self.families.visit(
            family,
            Describe {
                set: &self.sets[family],
                positions: &self.positions,
                rest_positions: &self.rest_positions,
                inverse_masses: &self.inverse_masses,
                rule,
                c,
                reach: self.settings.reach,
            },
        );
        if let Some(partner) = self.families.partner_in(family, &self.settings.active) {
            let pair = pair::Pair {
                first: &self.sets[family],
                second: &self.sets[partner],
                positions: &self.positions,
                rest_positions: &self.rest_positions,
                inverse_masses: &self.inverse_masses,
                rules: [rule, self.rule(partner, h)],
                reach: self.settings.reach,
            };
            let correction = self
                .families
                .visit_pair(family, partner, pair::PairAt { pair, c });
            let skipped = projection.delta_lambda.is_none();
            projection.delta_lambda = (!skipped).then_some(correction.delta_lambda[0]);
            projection.delta_x = correction.delta_x;
        }
        projection
    }

    /// Projects constraint `c` of `family` once, exactly as a sweep does (with its partner, if
    /// it leads a pair).
    pub fn project(&mut self, family: Family, c: usize) {
        self.fast.edited();
        self.project_range(family, Projected::One(c), self.substep_length());
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
    /// fixed, or [`LOCKED`]).
    pub delta_lambda: Option<f64>,
    /// Δx the projection would give each particle (zero when skipped).
    pub delta_x: [DVec3; 4],
    /// Whether ∇C is undefined here.
    pub degenerate: bool,
}

impl Projection {
    /// The particles it uses.
    pub fn particles(&self) -> &[u32] {
        &self.particles[..self.len]
    }
}

/// [`Projection`] of constraint `c` of `set`.
struct Describe<'a> {
    set: &'a ConstraintSet,
    positions: &'a [DVec3],
    rest_positions: &'a [DVec3],
    inverse_masses: &'a [f64],
    rule: Rule<f64>,
    c: usize,
    reach: f64,
}

impl Visit for Describe<'_> {
    type Output = Projection;

    fn visit<const N: usize, C: Constraint<N>>(self, family: Family, constraint: &C) -> Projection {
        let c = self.c;
        let idx = self.set.indices::<N>(c);
        let p = idx.map(|i| self.positions[i as usize]);
        let shape = idx.map(|i| self.rest_positions[i as usize]);
        let evaluation =
            constraint.evaluate_stored(&p, self.set.rest()[c], &shape, self.set.stored(c));
        let weights = idx.map(|i| self.inverse_masses[i as usize]);
        let lambda = self.set.lambda()[c];
        let reach = self.reach * self.set.size()[c];
        let correction = correction(evaluation, weights, lambda, self.rule, reach);
        let mut projection = Projection {
            family,
            constraint: c,
            particles: [0; 4],
            len: N,
            value: evaluation.value,
            rest: self.set.rest()[c],
            stored: std::array::from_fn(|k| self.set.stored(c).get(k).copied().unwrap_or(0.0)),
            stored_len: self.set.stored_len(),
            gradients: [DVec3::ZERO; 4],
            inverse_masses: [0.0; 4],
            weighted_norm: crate::simulation::projection::weighted_norm(
                &weights,
                &evaluation.gradients,
            ),
            lambda,
            delta_lambda: correction.map(|c| c.delta_lambda),
            delta_x: [DVec3::ZERO; 4],
            degenerate: evaluation.degenerate,
        };
        for k in 0..N {
            projection.particles[k] = idx[k];
            projection.gradients[k] = evaluation.gradients[k];
            projection.inverse_masses[k] = weights[k];
            if let Some(correction) = &correction {
                projection.delta_x[k] = correction.delta_x[k];
            }
        }
        projection
    }
}
