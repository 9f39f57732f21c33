//! The neo-Hookean energy in F-space and its analytic eigensystem, derived here from the energy
//! (after Smith, de Goes and Kim 2019, "Analytic eigensystems for isotropic distortion
//! energies"; no code taken from anywhere).
//!
//! # Formula
//! Per unit rest volume, tetlab's neo-Hookean pair has the energy
//!
//! Ψ(F) = μ/2 ‖F‖²_F + λ/2 (J − γ)²,   J = det F,  γ = 1 + μ/λ,  λ = λ_L + μ,
//!
//! which is the stable neo-Hookean energy μ/2 (‖F‖² − 3) − μ (J − 1) + λ/2 (J − 1)² plus a
//! constant. With g = ∂J/∂F (the cofactor matrix) and H_J = ∂²J/∂F²,
//!
//! ∂²Ψ/∂F² = μ I₉ + λ g gᵀ + λ (J − γ) H_J.
//!
//! Write F = U Σ Vᵀ with U, V rotations and Σ = diag(σ₀, σ₁, σ₂) (one σ negative when the tet is
//! inverted, [`signed_svd`]). In that frame, for each axis k and the other two (a, b):
//!
//! - the **twist** U (eₐe_bᵀ − e_beₐᵀ)/√2 Vᵀ: det(Σ + t T) = σₖ (σₐσ_b + t²/2), so H_J gives it σₖ,
//!   g is orthogonal to it, and its eigenvalue is μ + λ (J − γ) σₖ;
//! - the **flip** U (eₐe_bᵀ + e_beₐᵀ)/√2 Vᵀ: det = σₖ (σₐσ_b − t²/2), eigenvalue μ − λ (J − γ) σₖ;
//! - the three **scalings** U diag(q) Vᵀ: q an eigenvector of the 3 × 3
//!   A = μ I + λ g_σ g_σᵀ + λ (J − γ) [[0, σ₂, σ₁], [σ₂, 0, σ₀], [σ₁, σ₀, 0]], g_σ = (σ₁σ₂, σ₀σ₂, σ₀σ₁).
//!
//! At rest (F = I, J = 1) the twists are 0 (the rotations), the flips 2μ, the scalings 2μ, 2μ and
//! 3λ − μ. Where J < γ − 1/σₖ the twist is negative: the energy is not convex there.
//!
//! The tet's 12 × 12 Hessian is |V₀| Bᵀ (∂²Ψ/∂F²) B, B = ∂vec F/∂x (9 × 12, [`d_f_d_x`]).
//! Clamping the nine analytic eigenvalues at zero before that product ([`projected_in_f_space`])
//! gives a different matrix from clamping the 12 × 12's ([`super::modes::Modes::projected`]).

use super::modes::Class;
use super::svd::{signed_svd, twist_flip_scale};
use crate::numbers::dual::seed_two;
use crate::numbers::vector::Real;
use glam::{DMat3, DVec3};
use nalgebra::{Matrix3, SMatrix, SymmetricEigen};

/// A 9 × 9 matrix over vec F (column-major: F's first column first).
pub type Matrix9 = SMatrix<f64, 9, 9>;

/// μ, λ and γ of the pair (from [`crate::constraints::material::Material`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Parameters {
    /// μ.
    pub mu: f64,
    /// λ = λ_L + μ.
    pub lambda: f64,
    /// γ = 1 + μ/λ.
    pub gamma: f64,
}

impl Parameters {
    /// The parameters of `material`.
    pub fn of(material: &crate::constraints::material::Material) -> Parameters {
        Parameters {
            mu: material.mu(),
            lambda: material.lambda(),
            gamma: material.gamma(),
        }
    }
}

/// Ψ(F) in any number type.
pub(crate) fn psi<T: Real>(f: &[[T; 3]; 3], p: &Parameters) -> T {
    // f[c][r]: column c.
    let mut norm = T::ZERO;
    for column in f {
        for &x in column {
            norm += x * x;
        }
    }
    let [a, b, c] = *f;
    let det = a[0] * (b[1] * c[2] - b[2] * c[1]) - b[0] * (a[1] * c[2] - a[2] * c[1])
        + c[0] * (a[1] * b[2] - a[2] * b[1]);
    let gap = det - T::from_f64(p.gamma);
    T::from_f64(p.mu / 2.0) * norm + T::from_f64(p.lambda / 2.0) * gap * gap
}

/// ∂²Ψ/∂F² by second-order dual numbers: entry (i, j) the ε₁ε₂ part of Ψ with vec F's entry i
/// seeded along ε₁ and j along ε₂. Independent of the analytic system.
pub fn hessian_by_ad(f: &DMat3, p: &Parameters) -> Matrix9 {
    let columns = f.to_cols_array_2d();
    Matrix9::from_fn(|i, j| psi(&seed_two(&columns, i, j), p).slope.slope)
}

/// One mode of ∂²Ψ/∂F².
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FMode {
    /// Its eigenvalue.
    pub value: f64,
    /// Its unit eigenvector as a matrix (‖·‖_F = 1).
    pub matrix: DMat3,
    /// Twist, flip or scale.
    pub class: Class,
}

/// The nine modes of ∂²Ψ/∂F² at `f`, from the formulas above: three twists, three flips (about
/// F's principal axes 0, 1, 2), then the three scalings.
pub fn analytic(f: &DMat3, p: &Parameters) -> [FMode; 9] {
    let (u, s, v) = signed_svd(f);
    let j = s[0] * s[1] * s[2];
    let slack = p.lambda * (j - p.gamma);
    let frame = |m: DMat3| u * m * v.transpose();
    let unit = |a: usize, b: usize, sign: f64| {
        let mut m = DMat3::ZERO;
        m.col_mut(b)[a] = std::f64::consts::FRAC_1_SQRT_2;
        m.col_mut(a)[b] = sign * std::f64::consts::FRAC_1_SQRT_2;
        m
    };
    let pairs = [(1, 2), (2, 0), (0, 1)];
    let mut modes = [FMode {
        value: 0.0,
        matrix: DMat3::ZERO,
        class: Class::Scale,
    }; 9];
    for (k, &(a, b)) in pairs.iter().enumerate() {
        modes[k] = FMode {
            value: p.mu + slack * s[k],
            matrix: frame(unit(a, b, -1.0)),
            class: Class::Twist,
        };
        modes[3 + k] = FMode {
            value: p.mu - slack * s[k],
            matrix: frame(unit(a, b, 1.0)),
            class: Class::Flip,
        };
    }
    let g = [s[1] * s[2], s[0] * s[2], s[0] * s[1]];
    let hj = [[0.0, s[2], s[1]], [s[2], 0.0, s[0]], [s[1], s[0], 0.0]];
    let a = Matrix3::from_fn(|r, c| {
        let identity = if r == c { p.mu } else { 0.0 };
        identity + p.lambda * g[r] * g[c] + slack * hj[r][c]
    });
    let eigen = SymmetricEigen::new(a);
    for k in 0..3 {
        let q = eigen.eigenvectors.column(k);
        modes[6 + k] = FMode {
            value: eigen.eigenvalues[k],
            matrix: frame(DMat3::from_diagonal(DVec3::new(q[0], q[1], q[2]))),
            class: Class::Scale,
        };
    }
    modes
}

/// The shares of twist, flip and scale of a unit F-space direction `m` at `f` (they sum to 1).
pub fn f_space_shares(f: &DMat3, m: &DMat3) -> [f64; 3] {
    let (u, _, v) = signed_svd(f);
    let [twist, flip, scale] = twist_flip_scale(&u, &v, m);
    let total = (twist + flip + scale).max(f64::MIN_POSITIVE);
    [twist / total, flip / total, scale / total]
}

/// B = ∂vec F/∂x for F = Ds Dm⁻¹ on the rest shape `rest` (9 × 12; x corner by corner): row
/// 3c + r is F's entry (r, c), ∂F_rc/∂p_{i+1,r} = (Dm⁻¹)ᵢc and ∂F_rc/∂p_{0,r} = −Σᵢ (Dm⁻¹)ᵢc.
pub fn d_f_d_x(rest: &[DVec3; 4]) -> SMatrix<f64, 9, 12> {
    let dm = DMat3::from_cols(rest[1] - rest[0], rest[2] - rest[0], rest[3] - rest[0]);
    let inverse = dm.inverse();
    let mut b = SMatrix::<f64, 9, 12>::zeros();
    for c in 0..3 {
        for r in 0..3 {
            let row = 3 * c + r;
            let mut sum = 0.0;
            for i in 0..3 {
                let entry = inverse.col(c)[i];
                b[(row, 3 * (i + 1) + r)] = entry;
                sum += entry;
            }
            b[(row, r)] = -sum;
        }
    }
    b
}

/// ∂²Ψ/∂F² rebuilt from its analytic modes, with each eigenvalue replaced by `value(λ)`.
pub fn rebuilt(f: &DMat3, p: &Parameters, value: impl Fn(f64) -> f64) -> Matrix9 {
    let mut out = Matrix9::zeros();
    for mode in analytic(f, p) {
        let q = nalgebra::SVector::<f64, 9>::from_column_slice(&mode.matrix.to_cols_array());
        out += q * q.transpose() * value(mode.value);
    }
    out
}

/// The tet's 12 × 12 Hessian from F-space: |V₀| Bᵀ (∂²Ψ/∂F²) B at rest shape `rest` and
/// deformation `f`, with the F-space eigenvalues clamped at zero when `clamped` (projected
/// Newton in F-space).
pub fn projected_in_f_space(
    rest: &[DVec3; 4],
    f: &DMat3,
    p: &Parameters,
    clamped: bool,
) -> super::hessian::Matrix12 {
    let b = d_f_d_x(rest);
    let h = rebuilt(f, p, |l| if clamped { l.max(0.0) } else { l });
    let v0 = crate::constraints::volume::signed_volume(rest).abs();
    b.transpose() * h * b * v0
}

/// The F-space picture of a tet's deformation: the analytic system beside a numeric one, and the
/// 12 × 12 eigenvalues after clamping in F-space.
#[derive(Clone, Debug, PartialEq)]
pub struct FSpace {
    /// F = Ds Dm⁻¹.
    pub f: DMat3,
    /// Its signed singular values.
    pub singular_values: [f64; 3],
    /// The nine analytic modes ([`analytic`]).
    pub analytic: [FMode; 9],
    /// The eigenvalues of AD's ∂²Ψ/∂F² ([`hessian_by_ad`]) decomposed numerically, lowest first.
    pub numeric: Vec<f64>,
    /// max |analytic − numeric| / max |λ|, both sorted.
    pub relative_difference: f64,
    /// The eigenvalues of |V₀| Bᵀ H_F⁺ B, H_F's eigenvalues clamped at zero, lowest first.
    pub projected_in_f_space: Vec<f64>,
}

impl FSpace {
    /// At the corners `x` of a tet at rest at `rest`, with the pair's parameters `p`.
    pub fn of(rest: &[DVec3; 4], x: &[DVec3; 4], p: &Parameters) -> FSpace {
        let edges = |q: &[DVec3; 4]| DMat3::from_cols(q[1] - q[0], q[2] - q[0], q[3] - q[0]);
        let f = edges(x) * edges(rest).inverse();
        let (_, singular_values, _) = signed_svd(&f);
        let analytic = analytic(&f, p);
        let numeric = sorted_eigenvalues(hessian_by_ad(&f, p));
        let mut exact: Vec<f64> = analytic.iter().map(|m| m.value).collect();
        exact.sort_by(f64::total_cmp);
        let scale = numeric
            .iter()
            .fold(f64::MIN_POSITIVE, |m, x| m.max(x.abs()));
        let difference = numeric
            .iter()
            .zip(&exact)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        FSpace {
            f,
            singular_values,
            analytic,
            numeric,
            relative_difference: difference / scale,
            projected_in_f_space: sorted_eigenvalues(projected_in_f_space(rest, &f, p, true)),
        }
    }
}

/// The eigenvalues of a symmetric D × D matrix, lowest first.
pub(crate) fn sorted_eigenvalues<const D: usize>(m: SMatrix<f64, D, D>) -> Vec<f64> {
    let dynamic = nalgebra::DMatrix::from_column_slice(D, D, m.as_slice());
    let mut values: Vec<f64> = SymmetricEigen::new(dynamic)
        .eigenvalues
        .iter()
        .copied()
        .collect();
    values.sort_by(f64::total_cmp);
    values
}
