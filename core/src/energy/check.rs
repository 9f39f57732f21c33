//! The Hessian of one constraint, ∇²C, checked as its gradient is ([`check`]): on seeded random
//! configurations ([`crate::constraints::verify::draw`]), forward mode over ∇C (the family's
//! formula, or a file's compiled AD) against second-order dual numbers of C alone, and against
//! central differences of ∇C by forward-mode AD; and a file's own `[hessian]` blocks against AD,
//! block by block.

use crate::constraint_file::ConstraintFile;
use crate::constraints::differentiable::value_and_gradient_moving;
use crate::constraints::material::Material;
use crate::constraints::verify::{TableFamily, draw, well_conditioned};
use crate::constraints::{Families, Family};
use crate::numbers::dual::{seed_one, seed_two};
use crate::numbers::random::SplitMix64;
use glam::DVec3;
use nalgebra::DMatrix;

/// At most this many configurations are compared (each costs (3N)² evaluations of C).
pub const MAX_SAMPLES: usize = 500;

/// The outcome of [`check`].
#[derive(Clone, Debug, PartialEq)]
pub struct HessianReport {
    /// Well-conditioned configurations compared.
    pub compared: usize,
    /// The largest max |H − H₂| / max |H₂|: H by forward mode over ∇C, H₂ by second-order dual
    /// numbers.
    pub against_second_order: f64,
    /// The largest max |H − H_fd| / max |H|, H_fd central differences of AD's ∇C at a step of
    /// 10⁻⁵ of the configuration's size.
    pub against_finite_differences: f64,
    /// Per block the file gives (`[hessian]`): its particles and the largest relative error
    /// against AD, |yours − AD|∞ / max |∇²C|.
    pub yours: Vec<((usize, usize), f64)>,
}

impl HessianReport {
    /// Whether every block the file gives agrees with AD within `tolerance`.
    pub fn yours_agree(&self, tolerance: f64) -> bool {
        self.yours.iter().all(|&(_, e)| e <= tolerance)
    }
}

/// ∇²C of `family` by forward mode over ∇C, (3N)², at `x`.
fn forward<const N: usize>(
    families: &Families,
    family: Family,
    x: &[DVec3; N],
    (rest, stored): (f64, &[f64]),
    shape: &[DVec3; N],
) -> DMatrix<f64> {
    let n = 3 * N;
    let mut h = DMatrix::zeros(n, n);
    for j in 0..n {
        let p = seed_one(&x.map(|q| q.to_array()), j);
        let (_, g) = constraint(families, family, &p, (rest, stored), (shape, x));
        for i in 0..n {
            h[(i, j)] = g[i / 3][i % 3].slope;
        }
    }
    h
}

/// C and ∇C of one constraint at the dual numbers `p`, at rest: where the particles were at the
/// start of the substep is `x` itself (their values, not differentiated by), h the default.
fn constraint<T: crate::numbers::vector::Real<Mask = bool>, const N: usize>(
    families: &Families,
    family: Family,
    p: &[[T; 3]; N],
    rest: (f64, &[f64]),
    (shape, x): (&[DVec3; N], &[DVec3; N]),
) -> (T, [[T; 3]; N]) {
    let start = Some((x, crate::constraint_file::RESTING_H));
    value_and_gradient_moving(families, family, p, rest, shape, start)
}

/// ∇²C by dual numbers of dual numbers on C alone.
fn second_order<const N: usize>(
    families: &Families,
    family: Family,
    x: &[DVec3; N],
    (rest, stored): (f64, &[f64]),
    shape: &[DVec3; N],
) -> DMatrix<f64> {
    let n = 3 * N;
    DMatrix::from_fn(n, n, |i, j| {
        let p = seed_two(&x.map(|q| q.to_array()), i, j);
        constraint(families, family, &p, (rest, stored), (shape, x))
            .0
            .slope
            .slope
    })
}

/// ∇C by forward mode over C alone, at `x`, the particles having been at `start` (held there
/// while `x` moves for a difference quotient).
fn gradient<const N: usize>(
    families: &Families,
    family: Family,
    x: &[DVec3; N],
    (rest, stored): (f64, &[f64]),
    shape: &[DVec3; N],
    start: &[DVec3; N],
) -> Vec<f64> {
    (0..3 * N)
        .map(|j| {
            let p = seed_one(&x.map(|q| q.to_array()), j);
            constraint(families, family, &p, (rest, stored), (shape, start))
                .0
                .slope
        })
        .collect()
}

fn relative(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).amax() / b.amax().max(f64::MIN_POSITIVE)
}

/// ∇²C of `family` (whose file, for a file's family, is `file`, to check its own blocks) on up to
/// `samples` ([`MAX_SAMPLES`] at most) well-conditioned random configurations drawn from `seed`.
pub fn check(
    families: &Families,
    family: Family,
    file: Option<&ConstraintFile>,
    samples: usize,
    seed: u64,
) -> HessianReport {
    crate::constraints::for_arity!(families.arity(family), |N| check_on::<N>(
        families, family, file, samples, seed
    ))
}

fn check_on<const N: usize>(
    families: &Families,
    family: Family,
    file: Option<&ConstraintFile>,
    samples: usize,
    seed: u64,
) -> HessianReport {
    use crate::constraints::verify::GradientSource;
    let source = TableFamily { families, family };
    let material = Material::default();
    let mut rng = SplitMix64::new(seed);
    let mut report = HessianReport {
        compared: 0,
        against_second_order: 0.0,
        against_finite_differences: 0.0,
        yours: Vec::new(),
    };
    let wanted = samples.min(MAX_SAMPLES);
    let mut tries = 0;
    while report.compared < wanted && tries < 20 * wanted + 100 {
        tries += 1;
        let (points, around, size) = draw(&mut rng, &source);
        if !well_conditioned(&points) || !well_conditioned(&around.rest_shape) {
            continue;
        }
        let x: [DVec3; N] = std::array::from_fn(|k| points[k]);
        let shape: [DVec3; N] = std::array::from_fn(|k| around.rest_shape[k]);
        let rest = source.natural_rest(&points, &around);
        let stored = families.constraint(family).store(&shape, &material);
        let at = (rest, &stored[..]);
        let h = forward(families, family, &x, at, &shape);
        let h2 = second_order(families, family, &x, at, &shape);
        if !h.iter().chain(h2.iter()).all(|v| v.is_finite()) || !rest.is_finite() {
            continue;
        }
        let step = 1e-5 * size;
        let mut fd = DMatrix::zeros(3 * N, 3 * N);
        for j in 0..3 * N {
            let (mut plus, mut minus) = (x, x);
            plus[j / 3][j % 3] += step;
            minus[j / 3][j % 3] -= step;
            let (a, b) = (
                gradient(families, family, &plus, at, &shape, &x),
                gradient(families, family, &minus, at, &shape, &x),
            );
            for i in 0..3 * N {
                fd[(i, j)] = (a[i] - b[i]) / (2.0 * step);
            }
        }
        if !fd.iter().all(|v| v.is_finite()) {
            continue;
        }
        report.compared += 1;
        report.against_second_order = report.against_second_order.max(relative(&h, &h2));
        report.against_finite_differences =
            report.against_finite_differences.max(relative(&fd, &h));
        if let Some(file) = file {
            let scale = h2.amax().max(f64::MIN_POSITIVE);
            for ((i, j), block) in file.your_hessian(&points, rest, (&shape, &material)) {
                let mut error: f64 = 0.0;
                for c in 0..3 {
                    for r in 0..3 {
                        let exact = h2[(3 * i + r, 3 * j + c)];
                        error = error.max((block.col(c)[r] - exact).abs() / scale);
                    }
                }
                let error = if error.is_finite() {
                    error
                } else {
                    f64::INFINITY
                };
                match report.yours.iter_mut().find(|(pair, _)| *pair == (i, j)) {
                    Some((_, worst)) => *worst = worst.max(error),
                    None => report.yours.push(((i, j), error)),
                }
            }
        }
    }
    report
}
