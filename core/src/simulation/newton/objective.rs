//! What the Newton reference minimises ([`Objective`]), and its value, gradient and Hessian on
//! the free coordinates.
//!
//! # Formula
//! For an implicit Euler step of length h from the predicted positions x̃ (what XPBD's substep
//! starts from, [`crate::simulation::substep`]), or for a static equilibrium (no inertia, the load
//! instead):
//!
//! Φ(x) = Σᵢ mᵢ |xᵢ − x̃ᵢ|² / (2h²)                        (inertia; dynamic)
//!      − Σᵢ (mᵢ g + fᵢ)·xᵢ                                   (the load; static)
//!      + Σ_c ½ C_c(x)² / α_c                                 (every compliant constraint)
//!      + Σ_c (λ_c C_c(x) + ½ ρ C_c(x)²)                      (every rigid one: augmented Lagrangian)
//!      + ½ |x_p − target|² / α_grab                          (a compliant grab)
//!      + Σᵢ (max(0, μᵢ − ρ_g (yᵢ − y₀))² − μᵢ²) / (2ρ_g)     (the ground y ≥ y₀)
//!
//! ∇Φ and ∇²Φ gather each constraint's k C ∇C and k (∇C ∇Cᵀ + C ∇²C) (k = 1/α, or ρ with C + λ/ρ
//! for C), ∇²C by forward-mode AD ([`crate::constraints::differentiable::second_order`]). Each
//! constraint's block is projected to the nearest positive semi-definite matrix (its negative
//! eigenvalues set to 0), as projected Newton does per element, so that the system is positive
//! definite and every Newton step goes down.

use super::super::state::Body;
use crate::constraints::differentiable::{Matrix12, of_constraint_moving, second_order_moving};
use crate::constraints::{Families, Family, PerFamily};
use glam::DVec3;
use nalgebra::{DMatrix, SymmetricEigen};

/// Which coordinates move, and where each free one sits in the system.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct Dofs {
    /// Per coordinate (particle i's x, y, z at 3i, 3i + 1, 3i + 2): its row, or `None` if fixed.
    rows: Vec<Option<u32>>,
    /// How many are free.
    pub(super) count: usize,
}

impl Dofs {
    /// Particle i moves unless `fixed[i]` (pinned or held); with plane strain no z moves.
    pub(super) fn new(fixed: impl Iterator<Item = bool>, plane_strain: bool) -> Dofs {
        let mut rows = Vec::new();
        let mut count = 0;
        for fixed in fixed {
            for axis in 0..3 {
                let free = !(fixed || (plane_strain && axis == 2));
                rows.push(free.then(|| {
                    count += 1;
                    (count - 1) as u32
                }));
            }
        }
        Dofs { rows, count }
    }

    /// The row of coordinate `k`, if it moves.
    #[inline]
    pub(super) fn row(&self, k: usize) -> Option<usize> {
        self.rows[k].map(|r| r as usize)
    }
}

/// The inertia of an implicit Euler step: masses, the predicted positions, 1/h².
#[derive(Clone, Copy)]
pub(super) struct Inertia<'a> {
    pub(super) masses: &'a [f64],
    pub(super) predicted: &'a [DVec3],
    pub(super) over_h2: f64,
}

/// The load of a static problem: gravity along −y (m/s²) on the masses, and the external forces.
#[derive(Clone, Copy)]
pub(super) struct Load<'a> {
    pub(super) masses: &'a [f64],
    pub(super) gravity: f64,
    pub(super) forces: &'a [DVec3],
}

/// How each active family enters: with its stiffness 1/α, or rigid (α = 0).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) enum Term {
    /// Not active.
    #[default]
    Off,
    /// ½ C² / α: the stiffness 1/α.
    Compliant(f64),
    /// C = 0, by an augmented Lagrangian.
    Rigid,
}

/// The augmented Lagrangian's state: a multiplier per rigid constraint and per particle on the
/// ground, and the penalties.
#[derive(Clone, Debug, Default)]
pub(super) struct Multipliers {
    pub(super) rigid: PerFamily<Vec<f64>>,
    pub(super) rho: f64,
    pub(super) ground: Vec<f64>,
    pub(super) rho_ground: f64,
}

/// Φ of one problem.
pub(super) struct Objective<'a> {
    pub(super) families: &'a Families,
    pub(super) body: &'a Body,
    pub(super) terms: PerFamily<Term>,
    pub(super) inertia: Option<Inertia<'a>>,
    pub(super) load: Option<Load<'a>>,
    /// A compliant grab: the particle, the target, 1/α.
    pub(super) grab: Option<(usize, DVec3, f64)>,
    /// The ground's height, when there is one.
    pub(super) ground: Option<f64>,
    pub(super) dofs: &'a Dofs,
    /// Where every particle was at the start of the substep, and h: what a constraint on
    /// velocities reads (`None` in a static problem: at rest).
    pub(super) start: Option<(&'a [DVec3], f64)>,
}

/// The system at a point: Φ's gradient on the free coordinates, and the Hessian's values in the
/// order of [`Objective::pattern`], as it is and with each constraint's block projected.
#[derive(Default)]
pub(super) struct System {
    pub(super) gradient: Vec<f64>,
    /// Per free coordinate, the sum of the magnitudes of what its gradient gathers: what
    /// rounding in the gradient is relative to (a pre-stressed material's terms cancel at rest).
    pub(super) magnitude: Vec<f64>,
    pub(super) hessian: Vec<f64>,
    pub(super) projected: Vec<f64>,
}

impl Objective<'_> {
    /// Each active family's constraints, with their number of particles.
    fn families(&self) -> impl Iterator<Item = (Family, usize)> + '_ {
        self.families
            .all()
            .filter(|&f| self.terms[f] != Term::Off)
            .map(|f| (f, self.families.arity(f)))
    }

    /// The free rows of a constraint's coordinates (3 per particle, `None` where fixed).
    fn rows_of(&self, particles: &[u32]) -> [Option<usize>; 12] {
        let mut rows = [None; 12];
        for (k, &i) in particles.iter().enumerate() {
            for axis in 0..3 {
                rows[3 * k + axis] = self.dofs.row(3 * i as usize + axis);
            }
        }
        rows
    }

    /// The Hessian's entries, (row, column) with row ≥ column, in the order [`Objective::system`]
    /// gives their values: every diagonal first, then each constraint's block. The same for every
    /// point, so that the factorisation's analysis is done once.
    pub(super) fn pattern(&self) -> Vec<(usize, usize)> {
        let mut pattern: Vec<(usize, usize)> = (0..self.dofs.count).map(|r| (r, r)).collect();
        for (family, arity) in self.families() {
            let set = &self.body.sets[family];
            for c in 0..set.len() {
                let rows = self.rows_of(set.particles(c));
                for (a, row_a) in rows.iter().take(3 * arity).enumerate() {
                    for row_b in rows.iter().take(a + 1) {
                        if let (Some(i), Some(j)) = (row_a, row_b) {
                            pattern.push(((*i).max(*j), (*i).min(*j)));
                        }
                    }
                }
            }
        }
        pattern
    }

    /// Φ at `x`.
    pub(super) fn value(&self, x: &[DVec3], multipliers: &Multipliers) -> f64 {
        let mut sum = 0.0;
        for (family, _) in self.families() {
            let set = &self.body.sets[family];
            for c in 0..set.len() {
                let (k, offset) = self.scale(family, c, multipliers);
                let value = self.constraint_value(family, c, x);
                // ½ k (C + o)² less its constant ½ k o²: λ C + ½ ρ C² for a rigid constraint.
                sum += 0.5 * k * value * (value + 2.0 * offset);
            }
        }
        sum + self.particle_value(x, multipliers)
    }

    /// The terms of each particle: inertia, load, grab, ground.
    fn particle_value(&self, x: &[DVec3], multipliers: &Multipliers) -> f64 {
        let mut sum = 0.0;
        if let Some(inertia) = self.inertia {
            for (i, p) in x.iter().enumerate() {
                let moved = *p - inertia.predicted[i];
                sum += 0.5 * inertia.masses[i] * inertia.over_h2 * moved.length_squared();
            }
        }
        if let Some(load) = self.load {
            for (i, p) in x.iter().enumerate() {
                let force = DVec3::new(0.0, -load.gravity * load.masses[i], 0.0)
                    + load.forces.get(i).copied().unwrap_or(DVec3::ZERO);
                sum -= force.dot(*p);
            }
        }
        if let Some((particle, target, k)) = self.grab {
            sum += 0.5 * k * (x[particle] - target).length_squared();
        }
        if let Some(ground) = self.ground {
            let rho = multipliers.rho_ground;
            for (i, p) in x.iter().enumerate() {
                let mu = multipliers.ground.get(i).copied().unwrap_or(0.0);
                let push = (mu - rho * (p.y - ground)).max(0.0);
                sum += (push * push - mu * mu) / (2.0 * rho);
            }
        }
        sum
    }

    /// The stiffness a constraint enters with and what is added to its C: (1/α, 0) for a
    /// compliant one (α its own where its body's material gives one), (ρ, λ/ρ) for a rigid one.
    fn scale(&self, family: Family, c: usize, multipliers: &Multipliers) -> (f64, f64) {
        match self.terms[family] {
            Term::Compliant(k) => {
                let own = self.body.sets[family].own_compliance(c);
                (own.map_or(k, |alpha| 1.0 / alpha), 0.0)
            }
            Term::Rigid => (
                multipliers.rho,
                multipliers.rigid[family][c] / multipliers.rho,
            ),
            Term::Off => (0.0, 0.0),
        }
    }

    /// C of constraint `c` of `family` at `x`.
    pub(super) fn constraint_value(&self, family: Family, c: usize, x: &[DVec3]) -> f64 {
        let set = &self.body.sets[family];
        let rest = (set.rest()[c], set.stored(c));
        let particles = set.particles(c);
        of_constraint_moving(
            self.families,
            family,
            particles,
            rest,
            (x, &self.body.rest_positions),
            self.start,
        )
        .0
    }

    /// ∇Φ and ∇²Φ at `x`, the Hessian in the order of [`Objective::pattern`].
    pub(super) fn system(&self, x: &[DVec3], multipliers: &Multipliers, out: &mut System) {
        out.gradient.clear();
        out.gradient.resize(self.dofs.count, 0.0);
        out.magnitude.clear();
        out.magnitude.resize(self.dofs.count, 0.0);
        out.hessian.clear();
        out.hessian.resize(self.dofs.count, 0.0);
        self.particle_system(x, multipliers, out);
        out.projected.clone_from(&out.hessian);
        for (family, arity) in self.families() {
            let set = &self.body.sets[family];
            for c in 0..set.len() {
                let (k, offset) = self.scale(family, c, multipliers);
                let (value, gradient, hessian) = self.second_order(family, arity, c, x);
                let value = value + offset;
                let rows = self.rows_of(set.particles(c));
                let n = 3 * arity;
                let mut block = DMatrix::<f64>::zeros(n, n);
                for a in 0..n {
                    if let Some(row) = rows[a] {
                        out.gradient[row] += k * value * gradient[a];
                        out.magnitude[row] += (k * value * gradient[a]).abs();
                    }
                    for b in 0..n {
                        block[(a, b)] = k * (gradient[a] * gradient[b] + value * hessian[(a, b)]);
                    }
                }
                let projected = nearest_positive_semidefinite(&block);
                let projected = projected.as_ref().unwrap_or(&block);
                for (a, row_a) in rows.iter().take(n).enumerate() {
                    for (b, row_b) in rows.iter().take(a + 1).enumerate() {
                        if row_a.is_some() && row_b.is_some() {
                            out.hessian.push(block[(a, b)]);
                            out.projected.push(projected[(a, b)]);
                        }
                    }
                }
            }
        }
    }

    /// C, ∇C and ∇²C of constraint `c` of `family` at `x` (padded to 12).
    fn second_order(
        &self,
        family: Family,
        arity: usize,
        c: usize,
        x: &[DVec3],
    ) -> (f64, [f64; 12], Matrix12) {
        fn at<const N: usize>(
            o: &Objective<'_>,
            family: Family,
            c: usize,
            x: &[DVec3],
        ) -> (f64, [f64; 12], Matrix12) {
            let set = &o.body.sets[family];
            let idx = set.particles(c);
            let p: [DVec3; N] = std::array::from_fn(|k| x[idx[k] as usize]);
            let shape: [DVec3; N] = std::array::from_fn(|k| o.body.rest_positions[idx[k] as usize]);
            let start = o.start.map(|(start, h)| {
                let at: [DVec3; N] = std::array::from_fn(|k| start[idx[k] as usize]);
                (at, h)
            });
            second_order_moving(
                o.families,
                family,
                &p,
                (set.rest()[c], set.stored(c)),
                &shape,
                start.as_ref().map(|(at, h)| (at, *h)),
            )
        }
        crate::constraints::for_arity!(arity, |N| at::<N>(self, family, c, x))
    }

    /// The particles' terms of ∇Φ and of ∇²Φ's diagonal.
    fn particle_system(&self, x: &[DVec3], multipliers: &Multipliers, out: &mut System) {
        let mut add = |i: usize, axis: usize, gradient: f64, diagonal: f64| {
            if let Some(row) = self.dofs.row(3 * i + axis) {
                out.gradient[row] += gradient;
                out.magnitude[row] += gradient.abs();
                out.hessian[row] += diagonal;
            }
        };
        for (i, p) in x.iter().enumerate() {
            if let Some(inertia) = self.inertia {
                let k = inertia.masses[i] * inertia.over_h2;
                let moved = *p - inertia.predicted[i];
                for axis in 0..3 {
                    add(i, axis, k * moved[axis], k);
                }
            }
            if let Some(load) = self.load {
                let force = DVec3::new(0.0, -load.gravity * load.masses[i], 0.0)
                    + load.forces.get(i).copied().unwrap_or(DVec3::ZERO);
                for axis in 0..3 {
                    add(i, axis, -force[axis], 0.0);
                }
            }
            if let Some(ground) = self.ground {
                let rho = multipliers.rho_ground;
                let mu = multipliers.ground.get(i).copied().unwrap_or(0.0);
                let push = mu - rho * (p.y - ground);
                if push > 0.0 {
                    add(i, 1, -push, rho);
                }
            }
        }
        if let Some((particle, target, k)) = self.grab {
            let pulled = x[particle] - target;
            for axis in 0..3 {
                add(particle, axis, k * pulled[axis], k);
            }
        }
    }
}

/// The positive semi-definite matrix nearest to symmetric `block`: its eigenvalues below 0 set
/// to 0 (projected Newton, per element), or `None` where `block` is already so.
fn nearest_positive_semidefinite(block: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let eigen = SymmetricEigen::new(block.clone());
    if eigen.eigenvalues.iter().all(|&e| e >= 0.0) {
        return None;
    }
    let clamped = eigen.eigenvalues.map(|e| e.max(0.0));
    Some(&eigen.eigenvectors * DMatrix::from_diagonal(&clamped) * eigen.eigenvectors.transpose())
}
