//! How the Newton reference minimises an [`Objective`]: Newton steps on the free coordinates, each
//! a sparse Cholesky solve of the projected Hessian (faer's, with a fill-reducing ordering; the
//! pattern analysed once and refilled each step), then a backtracking line search on Φ (Armijo);
//! inside an augmented Lagrangian for the rigid constraints and the ground, whose multipliers are
//! updated until what they hold is held to the tolerance.

use super::objective::{Dofs, Multipliers, Objective, System, Term};
use super::{Options, Report};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{Argsort, Pair, SparseColMat, SymbolicSparseColMat};
use faer::{Mat, Side};
use glam::DVec3;

/// The analysed pattern of a system's Hessian, kept while the pattern stays the same.
#[derive(Default)]
pub(super) struct Factoriser {
    pattern: Vec<(usize, usize)>,
    size: usize,
    symbolic: Option<(
        SymbolicSparseColMat<usize>,
        Argsort<usize>,
        SymbolicLlt<usize>,
    )>,
    system: System,
}

impl Factoriser {
    /// Analyses `pattern` (rows ≥ columns) of a `size` × `size` system, unless it is the one
    /// analysed last.
    fn analyse(&mut self, size: usize, pattern: Vec<(usize, usize)>) -> Result<(), String> {
        if self.symbolic.is_some() && self.size == size && self.pattern == pattern {
            return Ok(());
        }
        let pairs: Vec<Pair<usize, usize>> = pattern
            .iter()
            .map(|&(row, col)| Pair { row, col })
            .collect();
        let (symbolic, argsort) = SymbolicSparseColMat::try_new_from_indices(size, size, &pairs)
            .map_err(|e| format!("the system's pattern: {e:?}"))?;
        let llt = SymbolicLlt::try_new(symbolic.as_ref(), Side::Lower)
            .map_err(|e| format!("the system's analysis: {e:?}"))?;
        self.symbolic = Some((symbolic, argsort, llt));
        (self.size, self.pattern) = (size, pattern);
        Ok(())
    }

    /// Solves H d = −g for the system's values `hessian` and `gradient`: d. The matrix is shifted
    /// by σ I, σ = 10⁻¹⁴ of its largest diagonal entry, and by 100 times more until it factorises
    /// and the solution's own residual ‖H d + g‖ is within 10⁻⁸ ‖g‖: a body free to slide (a
    /// volume alone leaves a face's apex free along the face) is not moved where no force pulls.
    fn solve(&self, hessian: &[f64], gradient: &[f64]) -> Result<Vec<f64>, String> {
        let (symbolic, argsort, llt) = self.symbolic.as_ref().expect("analysed first");
        let n = self.size;
        let mut diagonal = vec![0.0; n];
        for (&(row, col), &value) in self.pattern.iter().zip(hessian) {
            if row == col {
                diagonal[row] += value;
            }
        }
        let largest = diagonal.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
        let norm = gradient.iter().map(|g| g * g).sum::<f64>().sqrt();
        let mut shifted = hessian.to_vec();
        let mut shift = 0.0;
        for attempt in 0..8 {
            let next = largest.max(f64::MIN_POSITIVE) * 10f64.powi(2 * attempt - 14);
            for value in &mut shifted[..n] {
                *value += next - shift;
            }
            shift = next;
            let matrix = SparseColMat::new_from_argsort(symbolic.clone(), argsort, &shifted)
                .map_err(|e| format!("the system: {e:?}"))?;
            let Ok(factor) = Llt::try_new_with_symbolic(llt.clone(), matrix.as_ref(), Side::Lower)
            else {
                continue;
            };
            let mut rhs = Mat::from_fn(n, 1, |i, _| -gradient[i]);
            factor.solve_in_place(rhs.as_mut());
            let d: Vec<f64> = (0..n).map(|i| rhs[(i, 0)]).collect();
            if d.iter().all(|v| v.is_finite())
                && self.residual(&shifted, &d, gradient) <= 1e-8 * norm.max(f64::MIN_POSITIVE)
            {
                return Ok(d);
            }
        }
        Err("the Newton system could not be solved (not positive definite)".into())
    }

    /// Solves H d = −g as it is, with no shift: `None` unless H factorises (is positive definite)
    /// and the solution is finite and solves the system to 10⁻⁸ ‖g‖.
    fn solve_exact(&self, hessian: &[f64], gradient: &[f64]) -> Option<Vec<f64>> {
        let (symbolic, argsort, llt) = self.symbolic.as_ref().expect("analysed first");
        let n = self.size;
        let matrix = SparseColMat::new_from_argsort(symbolic.clone(), argsort, hessian).ok()?;
        let factor = Llt::try_new_with_symbolic(llt.clone(), matrix.as_ref(), Side::Lower).ok()?;
        let mut rhs = Mat::from_fn(n, 1, |i, _| -gradient[i]);
        factor.solve_in_place(rhs.as_mut());
        let d: Vec<f64> = (0..n).map(|i| rhs[(i, 0)]).collect();
        let norm = gradient.iter().map(|g| g * g).sum::<f64>().sqrt();
        (d.iter().all(|v| v.is_finite())
            && self.residual(hessian, &d, gradient) <= 1e-8 * norm.max(f64::MIN_POSITIVE))
        .then_some(d)
    }

    /// ‖H d + g‖ for the symmetric H whose lower triangle `values` holds.
    fn residual(&self, values: &[f64], d: &[f64], gradient: &[f64]) -> f64 {
        let mut r = gradient.to_vec();
        for (&(row, col), &value) in self.pattern.iter().zip(values) {
            r[row] += value * d[col];
            if row != col {
                r[col] += value * d[row];
            }
        }
        r.iter().map(|v| v * v).sum::<f64>().sqrt()
    }
}

/// How far the positions are from what the rigid constraints and the ground hold: the largest
/// |C| relative to its element's size, and the largest depth below the ground relative to the
/// body's size.
fn violation(objective: &Objective<'_>, x: &[DVec3], size: f64) -> f64 {
    let mut worst: f64 = 0.0;
    for family in objective.families.all() {
        if objective.terms[family] != Term::Rigid {
            continue;
        }
        let set = &objective.body.sets[family];
        for c in 0..set.len() {
            let value = objective.constraint_value(family, c, x);
            worst = worst.max(value.abs() / set.size()[c].max(f64::MIN_POSITIVE));
        }
    }
    if let Some(ground) = objective.ground {
        for (i, p) in x.iter().enumerate() {
            if objective.dofs.row(3 * i + 1).is_some() {
                worst = worst.max((ground - p.y).max(0.0) / size);
            }
        }
    }
    worst
}

/// The scales of a problem: its system's diagonal (the largest m/h² or 1/α), from which the
/// penalties ρ start; the body's size, which the ground's depth is measured against; and its
/// forces (the largest weight or external force), which the residual is measured against.
pub(super) struct Scales {
    pub(super) stiffness: f64,
    pub(super) size: f64,
    pub(super) force: f64,
}

/// Minimises `objective` from `x` (moved in place): Newton on Φ, in an augmented Lagrangian loop
/// when it has rigid constraints or a ground. With a ground, `ground_forces` gets the force (N,
/// along +y) it holds each particle up with at the end, max(0, μ − ρ_g (y − y₀)) (0 without).
pub(super) fn minimize(
    objective: &Objective<'_>,
    x: &mut [DVec3],
    factoriser: &mut Factoriser,
    scales: Scales,
    options: &Options,
    ground_forces: &mut Vec<f64>,
) -> Result<Report, String> {
    let Scales {
        stiffness,
        size,
        force,
    } = scales;
    let dofs = objective.dofs;
    factoriser.analyse(dofs.count, objective.pattern())?;
    let has_rigid = objective
        .families
        .all()
        .any(|f| objective.terms[f] == Term::Rigid);
    let mut multipliers = Multipliers {
        rigid: objective
            .families
            .per_family(|f| vec![0.0; objective.body.sets[f].len()]),
        rho: 1e4 * stiffness.max(1e-12),
        ground: vec![0.0; x.len()],
        rho_ground: 1e4 * stiffness.max(1e-12),
    };
    let mut report = Report::default();
    let mut last_violation = f64::INFINITY;
    // What the residual is measured against: the forces of the problem, or its start's gradient.
    objective.system(x, &multipliers, &mut factoriser.system);
    let start = (factoriser.system.gradient.iter()).fold(0.0f64, |a, &g| a.max(g.abs()));
    let scale = start.max(force).max(options.force_scale);
    loop {
        report.outer_iterations += 1;
        newton(
            objective,
            x,
            factoriser,
            (&multipliers, scale),
            options,
            &mut report,
        )?;
        report.violation = violation(objective, x, size);
        if !(has_rigid || objective.ground.is_some()) || report.violation <= options.tolerance {
            break;
        }
        if report.outer_iterations >= options.max_outer_iterations {
            report.converged = false;
            break;
        }
        update_multipliers(objective, x, &mut multipliers);
        if report.violation > 0.25 * last_violation {
            multipliers.rho *= 10.0;
            multipliers.rho_ground *= 10.0;
        }
        last_violation = report.violation;
    }
    ground_forces.clear();
    ground_forces.resize(x.len(), 0.0);
    if let Some(ground) = objective.ground {
        let rho = multipliers.rho_ground;
        for ((force, mu), p) in ground_forces.iter_mut().zip(&multipliers.ground).zip(&*x) {
            *force = (mu - rho * (p.y - ground)).max(0.0);
        }
    }
    Ok(report)
}

/// λ += ρ C for each rigid constraint; μ = max(0, μ − ρ_g (y − y₀)) for each particle.
fn update_multipliers(objective: &Objective<'_>, x: &[DVec3], multipliers: &mut Multipliers) {
    for family in objective.families.all() {
        if objective.terms[family] != Term::Rigid {
            continue;
        }
        for c in 0..objective.body.sets[family].len() {
            let value = objective.constraint_value(family, c, x);
            multipliers.rigid[family][c] += multipliers.rho * value;
        }
    }
    if let Some(ground) = objective.ground {
        for (mu, p) in multipliers.ground.iter_mut().zip(x) {
            *mu = (*mu - multipliers.rho_ground * (p.y - ground)).max(0.0);
        }
    }
}

/// Newton steps on Φ with the multipliers held, until ‖∇Φ‖∞ is at most the tolerance times
/// `scale` (or no step lowers Φ any more).
fn newton(
    objective: &Objective<'_>,
    x: &mut [DVec3],
    factoriser: &mut Factoriser,
    (multipliers, scale): (&Multipliers, f64),
    options: &Options,
    report: &mut Report,
) -> Result<(), String> {
    let dofs = objective.dofs;
    let mut system = std::mem::take(&mut factoriser.system);
    let result = (|| {
        for _ in 0..options.max_iterations {
            objective.system(x, multipliers, &mut system);
            // ‖∇Φ‖∞ against the problem's forces, or against what rounding leaves of it where
            // that is more: the tolerance never asks for less than rounding can give.
            let largest = system.gradient.iter().fold(0.0f64, |a, &g| a.max(g.abs()));
            report.residual =
                largest / scale.max(rounding(factoriser, &system, x) / options.tolerance);
            if report.residual <= options.tolerance {
                report.converged = true;
                return Ok(());
            }
            // The Hessian as it is where it is positive definite and gives a way down (near a
            // stable minimum: quadratic convergence), else with each block projected.
            let slope_of = |d: &[f64]| d.iter().zip(&system.gradient).map(|(a, b)| a * b).sum();
            let (d, slope) = match factoriser.solve_exact(&system.hessian, &system.gradient) {
                Some(d) if slope_of(&d) < 0.0 => {
                    let slope: f64 = slope_of(&d);
                    (d, slope)
                }
                _ => {
                    let d = factoriser.solve(&system.projected, &system.gradient)?;
                    let slope: f64 = slope_of(&d);
                    (d, slope)
                }
            };
            report.newton_iterations += 1;
            let start = objective.value(x, multipliers);
            // Near the minimum Φ changes by less than its own rounding: a step within that is
            // taken, and the residual decides.
            let rounding = 64.0 * f64::EPSILON * start.abs();
            let mut step = 1.0;
            let mut moved = x.to_vec();
            loop {
                apply(dofs, x, &d, step, &mut moved);
                let value = objective.value(&moved, multipliers);
                if value <= start + 1e-4 * step * slope + rounding || step < 1e-12 {
                    break;
                }
                step *= 0.5;
            }
            if step < 1e-12 {
                // No step lowers Φ: it is as low as rounding lets it be found.
                report.converged = report.residual <= options.tolerance.sqrt();
                return Ok(());
            }
            x.copy_from_slice(&moved);
        }
        report.converged = false;
        Ok(())
    })();
    factoriser.system = system;
    result
}

/// What rounding leaves of ∇Φ at `x`: the sums that make it, rounded (10⁶ ε = 2·10⁻¹⁰ of their
/// terms' largest magnitude, a pre-stressed material's terms cancelling at rest), and the
/// positions, rounded (16 ε of the largest coordinate, times the stiffest diagonal of the
/// Hessian: an augmented Lagrangian's penalty grows it until a step of one ulp moves ∇Φ more
/// than the tolerance allows).
fn rounding(factoriser: &Factoriser, system: &System, x: &[DVec3]) -> f64 {
    let terms = system.magnitude.iter().fold(0.0f64, |a, &m| a.max(m));
    let mut diagonal = vec![0.0; factoriser.size];
    for (&(row, col), &value) in factoriser.pattern.iter().zip(&system.hessian) {
        if row == col {
            diagonal[row] += value;
        }
    }
    let stiffest = diagonal.iter().fold(0.0f64, |a, &d| a.max(d.abs()));
    let extent = x.iter().fold(0.0f64, |a, p| a.max(p.abs().max_element()));
    (1e6 * f64::EPSILON * terms).max(16.0 * f64::EPSILON * stiffest * extent)
}

/// `moved` = `x` + `step` d on the free coordinates.
fn apply(dofs: &Dofs, x: &[DVec3], d: &[f64], step: f64, moved: &mut [DVec3]) {
    for (i, (p, q)) in x.iter().zip(moved.iter_mut()).enumerate() {
        *q = *p;
        for axis in 0..3 {
            if let Some(row) = dofs.row(3 * i + axis) {
                q[axis] += step * d[row];
            }
        }
    }
}
