//! The Hessian of an element's energy by automatic differentiation, two independent ways, and the
//! checks of it: against central differences of the gradient over several decades of step
//! ([`convergence`]), and its symmetry ([`asymmetry`]).
//!
//! # Formula
//! With x the tet's 12 coordinates (corner 0's x, y, z first) and E = Σ ½ C² / α,
//!
//! ∇E = Σ C ∇C / α,   H = ∇²E = Σ (∇C ∇Cᵀ + C ∇²C) / α.
//!
//! [`hessian`] seeds one coordinate at a time with a dual number and reads ∇²C's column from the
//! slopes of ∇C, as each family gives ∇C (its formula, or a file's compiled reverse-mode AD):
//! forward mode over ∇C, 12 passes. [`second_order`] differentiates E alone twice, with dual
//! numbers of dual numbers seeded along two coordinates, every (i, j) apart: 144 passes that never
//! touch a gradient formula, so the two check each other.

use super::element::ElementEnergy;
use crate::numbers::dual::{seed_one, seed_two};
use nalgebra::SMatrix;

/// A 12 × 12 matrix: a tet's Hessian (coordinates corner by corner, x y z).
pub type Matrix12 = SMatrix<f64, 12, 12>;

/// The tet's corners as 12 coordinates, each a number of type `T` made by `seed(k, value)`.
/// The 12 coordinates as four corners.
fn corners(x: &[f64; 12]) -> [[f64; 3]; 4] {
    std::array::from_fn(|i| std::array::from_fn(|a| x[3 * i + a]))
}

/// The corners as 12 coordinates.
pub fn coordinates(corners: &[glam::DVec3; 4]) -> [f64; 12] {
    std::array::from_fn(|k| corners[k / 3][k % 3])
}

/// E at `x`.
pub fn energy(e: &ElementEnergy, x: &[f64; 12]) -> f64 {
    e.energy(&corners(x))
}

/// ∇E at `x` by forward mode over E alone: one pass per coordinate.
pub fn gradient(e: &ElementEnergy, x: &[f64; 12]) -> [f64; 12] {
    std::array::from_fn(|k| e.energy(&seed_one(&corners(x), k)).slope)
}

/// H at `x`, forward mode over ∇C: Σ (∇C ∇Cᵀ + C ∇²C) / α, column j of ∇²C the slopes of ∇C
/// with coordinate j seeded. Symmetric to rounding, not by construction ([`asymmetry`]).
pub fn hessian(e: &ElementEnergy, x: &[f64; 12]) -> Matrix12 {
    let mut h = Matrix12::zeros();
    for (t, term) in e.terms().iter().enumerate() {
        for j in 0..12 {
            let (c, g) = e.evaluate(t, &seed_one(&corners(x), j));
            let gj = g[j / 3][j % 3].value;
            for i in 0..12 {
                let gi = g[i / 3][i % 3];
                h[(i, j)] += term.stiffness * (gi.value * gj + c.value * gi.slope);
            }
        }
    }
    h
}

/// H at `x` from E alone, by second-order dual numbers: entry (i, j) is the ε₁ε₂ part of E with
/// coordinate i seeded along ε₁ and j along ε₂.
pub fn second_order(e: &ElementEnergy, x: &[f64; 12]) -> Matrix12 {
    let mut h = Matrix12::zeros();
    for i in 0..12 {
        for j in 0..12 {
            h[(i, j)] = e.energy(&seed_two(&corners(x), i, j)).slope.slope;
        }
    }
    h
}

/// max |Hᵢⱼ − Hⱼᵢ| / max |Hᵢⱼ| (0 for a zero matrix).
pub fn asymmetry(h: &Matrix12) -> f64 {
    let largest = h.amax();
    if largest == 0.0 {
        return 0.0;
    }
    (h - h.transpose()).amax() / largest
}

/// How H compares with central differences of ∇E over steps of several decades ([`convergence`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Convergence {
    /// Each step (relative to the tet's size) and the error there: max |H_fd − H| / max |H|.
    pub steps: Vec<(f64, f64)>,
    /// The slope of log error against log step, fitted over the decades where the error falls
    /// tenfold or more per decade (2 for central differences: the error goes as ε²).
    pub slope: f64,
    /// How many decades of step that fall spans.
    pub decades: f64,
    /// The smallest error, where rounding meets the truncation error.
    pub floor: f64,
}

/// H against central differences of ∇E along twelve directions d of no special kind (a
/// coordinate axis plus a fixed oblique vector: along an axis alone, C is often linear and the
/// difference exact), (∇E(x + ε d) − ∇E(x − ε d)) / 2ε against H d, for ε = size × 10⁻¹ … 10⁻⁸:
/// the truncation error falls as ε² until rounding, which grows as 1/ε, takes over. The slope is
/// fitted over the steps, from the largest, while each decade takes the error down at least
/// tenfold.
pub fn convergence(e: &ElementEnergy, x: &[f64; 12], h: &Matrix12) -> Convergence {
    let size = (0..4)
        .flat_map(|a| (0..4).map(move |b| (a, b)))
        .map(|(a, b)| {
            (0..3)
                .map(|k| (x[3 * a + k] - x[3 * b + k]).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let scale = h.amax().max(f64::MIN_POSITIVE);
    let steps: Vec<(f64, f64)> = (1..=8)
        .map(|k| {
            let step = 10f64.powi(-k);
            let eps = step * size;
            let mut error: f64 = 0.0;
            for j in 0..12 {
                let direction: [f64; 12] = std::array::from_fn(|k| {
                    let oblique = ((7 * k + 3) % 12) as f64 / 12.0 - 0.5;
                    oblique + if k == j { 1.0 } else { 0.0 }
                });
                let (mut plus, mut minus) = (*x, *x);
                for k in 0..12 {
                    plus[k] += eps * direction[k];
                    minus[k] -= eps * direction[k];
                }
                let (above, below) = (gradient(e, &plus), gradient(e, &minus));
                for i in 0..12 {
                    let numeric = (above[i] - below[i]) / (2.0 * eps);
                    let exact: f64 = (0..12).map(|k| h[(i, k)] * direction[k]).sum();
                    error = error.max((numeric - exact).abs());
                }
            }
            (step, error / scale)
        })
        .collect();
    let lowest = (0..steps.len())
        .min_by(|&a, &b| steps[a].1.total_cmp(&steps[b].1))
        .unwrap_or(0);
    // The truncation regime: from the largest step, while each decade takes the error down at
    // least tenfold (rounding, once it dominates, does not).
    let mut end = 0;
    while end + 1 < steps.len() && steps[end + 1].1 < steps[end].1 / 10.0 {
        end += 1;
    }
    let falling = &steps[..=end];
    let (slope, decades) = if falling.len() >= 2 {
        let logs: Vec<(f64, f64)> = falling
            .iter()
            .map(|&(s, err)| (s.log10(), err.max(f64::MIN_POSITIVE).log10()))
            .collect();
        let n = logs.len() as f64;
        let (mx, my) = (
            logs.iter().map(|l| l.0).sum::<f64>() / n,
            logs.iter().map(|l| l.1).sum::<f64>() / n,
        );
        let sxy: f64 = logs.iter().map(|l| (l.0 - mx) * (l.1 - my)).sum();
        let sxx: f64 = logs.iter().map(|l| (l.0 - mx).powi(2)).sum();
        (sxy / sxx, logs[0].0 - logs[logs.len() - 1].0)
    } else {
        (0.0, 0.0)
    };
    Convergence {
        floor: steps[lowest].1,
        steps,
        slope,
        decades,
    }
}
