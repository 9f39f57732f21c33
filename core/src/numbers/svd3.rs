//! The signed singular value decomposition of a 3 × 3 matrix, F = U diag(σ) Vᵀ, and its polar
//! decomposition, F = R S, in any [`Real`] (f64, f32, the fast engine's lanes) without a branch,
//! so that every lane of a SIMD batch runs the same instructions; and their exact derivatives,
//! which the dual numbers ([`crate::numbers::dual::Tangent`]) use in place of differentiating the
//! iterations.
//!
//! # Signed
//! U and V are rotations (det +1), never reflections, and |σ₀| ≥ |σ₁| ≥ |σ₂| with σ₀, σ₁ ≥ 0: an
//! inverted F (det F < 0) has σ₂ < 0. Then R = U Vᵀ is the rotation nearest F (it maximises
//! tr(RᵀF) over rotations), and S = Rᵀ F = V diag(σ) Vᵀ is symmetric with a negative eigenvalue
//! where F is inverted: the split corotated and ARAP models pull F towards.
//!
//! # How
//! Cyclic Jacobi on FᵀF (exact rotations, a fixed number of sweeps) gives V; the columns of B = F V
//! are sorted by length, and B's QR decomposition by Givens rotations gives U (a product of
//! rotations) and R's diagonal, σ, its last entry carrying det F's sign (after McAdams et al.
//! 2011, "Computing the singular value decomposition of 3 × 3 matrices with minimal branching").
//!
//! # Derivatives, and repeated singular values
//! With P = Uᵀ dF V: dσᵢ = Pᵢᵢ, and dU = U Ω_U, dV = V Ω_V with, for i ≠ j,
//! (Ω_U)ᵢⱼ = (σⱼ Pᵢⱼ + σᵢ Pⱼᵢ) / (σⱼ² − σᵢ²) and (Ω_V)ᵢⱼ = (σᵢ Pᵢⱼ + σⱼ Pⱼᵢ) / (σⱼ² − σᵢ²).
//! Where two |σ| are equal U and V are not unique (any rotation of the pair's plane serves) and
//! have no derivative: those entries are not finite, and a projection that uses them is skipped
//! as degenerate. σ itself stays continuous there but has a kink (two sorted values that meet);
//! what is symmetric in σ (their sum, their product) is smooth, and its derivative above is exact
//! there because it does not depend on which basis of the pair's plane was picked.
//!
//! The polar rotation is smoother: dR = R \[w\]ₓ, where (tr S · I − S) w = vee(Rᵀ dF − dFᵀ R).
//! It is finite at repeated singular values (at F = I, dR is dF's antisymmetric part) and fails
//! only where σᵢ + σⱼ = 0, an inverted F whose two smallest |σ| are equal: there R jumps
//! between rotations and no derivative exists.
//!
//! ```
//! use tetlab_core::numbers::columns::{mat_mul, transpose_mul};
//! use tetlab_core::numbers::vector::Real;
//! // An inverted F: the polar rotation is a rotation, and S = RᵀF is symmetric.
//! let f = [[0.3, 1.2, -0.4], [2.0, 0.1, 0.5], [-0.2, 0.7, 1.1]];
//! let svd = f64::signed_svd(f);
//! assert!(svd.sigma[2] < 0.0 && svd.sigma[0] >= svd.sigma[1] && svd.sigma[1] >= -svd.sigma[2]);
//! let r = f64::polar(f);
//! let (rtr, s) = (transpose_mul(r, r), transpose_mul(r, f));
//! for i in 0..3 {
//!     for j in 0..3 {
//!         let identity = if i == j { 1.0 } else { 0.0 };
//!         assert!((rtr[j][i] - identity).abs() < 1e-14);
//!         assert!((s[j][i] - s[i][j]).abs() < 1e-14);
//!     }
//! }
//! ```

use crate::numbers::columns::{
    Columns, cross, dot, identity, mat_mul, mat_vec, mul_transpose, scale, solve, sub3,
    transpose_mul,
};
use crate::numbers::dual::Tangent;
use crate::numbers::vector::Real;

/// F = U diag(σ) Vᵀ with U and V rotations (signed, see the module's documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Svd<T> {
    /// The left singular vectors, as columns: a rotation.
    pub u: Columns<T>,
    /// σ₀ ≥ σ₁ ≥ |σ₂|, σ₂ negative where det F is.
    pub sigma: [T; 3],
    /// The right singular vectors, as columns: a rotation.
    pub v: Columns<T>,
}

/// Sweeps of cyclic Jacobi over the three pairs. Convergence is quadratic once the off-diagonal
/// is small: on the 20,000 random matrices of this file's tests four sweeps already give F back
/// to 1e-13 in f64 and three do not; six leave a margin.
const SWEEPS: usize = 6;

/// The signed SVD of F (columns `f`), without a branch ([`Real::signed_svd`] calls it).
pub fn jacobi_svd<T: Real>(f: Columns<T>) -> Svd<T> {
    // A = FᵀF, symmetric; V accumulates the Jacobi rotations that make it diagonal.
    let mut a = transpose_mul(f, f);
    let mut v = identity();
    for _ in 0..SWEEPS {
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            let (c, s) = jacobi_rotation(a[p][p], a[q][q], a[p][q]);
            // A ← Jᵀ A J and V ← V J, J's column p being c eₚ − s e_q and column q s eₚ + c e_q.
            rotate_columns(&mut a, p, q, c, s);
            rotate_rows(&mut a, p, q, c, s);
            rotate_columns(&mut v, p, q, c, s);
        }
    }
    // B = F V has orthogonal columns of lengths |σᵢ|: sort them longest first, swapping V's
    // columns with them and negating one of each swapped pair so that V stays a rotation.
    let mut b = [mat_vec(f, v[0]), mat_vec(f, v[1]), mat_vec(f, v[2])];
    let mut length = [dot(b[0], b[0]), dot(b[1], b[1]), dot(b[2], b[2])];
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        let swap = length[j].gt(length[i]);
        for m in [&mut b, &mut v] {
            let (x, y) = (m[i], m[j]);
            m[i] = [0, 1, 2].map(|k| T::select(swap, y[k], x[k]));
            m[j] = [0, 1, 2].map(|k| T::select(swap, -x[k], y[k]));
        }
        let (x, y) = (length[i], length[j]);
        length[i] = T::select(swap, y, x);
        length[j] = T::select(swap, x, y);
    }
    // B = U R by Givens rotations: zero B₁₀, B₂₀, then B₂₁; each G taken on rows p and q,
    // B ← G B and U ← U Gᵀ, with G's rows p and q being (c, s) and (−s, c).
    let mut u = identity();
    for (p, q, k) in [(0, 1, 0), (0, 2, 0), (1, 2, 1)] {
        let (x, y) = (b[k][p], b[k][q]);
        let r = (x * x + y * y).sqrt();
        let nonzero = r.gt(T::ZERO);
        let c = T::select(nonzero, x / r, T::ONE);
        let s = T::select(nonzero, y / r, T::ZERO);
        rotate_rows(&mut b, p, q, c, -s);
        rotate_columns(&mut u, p, q, c, -s);
    }
    Svd {
        u,
        sigma: [b[0][0], b[1][1], b[2][2]],
        v,
    }
}

/// The rotation of F's polar decomposition, R = U Vᵀ.
pub fn rotation<T: Real>(svd: &Svd<T>) -> Columns<T> {
    mul_transpose(svd.u, svd.v)
}

/// (c, s) of the Jacobi rotation that zeroes the off-diagonal entry o = A_pq of the symmetric
/// 2 × 2 block [a_pp o; o a_qq]: t = s / c is the smaller root of t² + 2θt − 1 = 0,
/// θ = (a_qq − a_pp) / 2o, written t = 2o sign(d) / (|d| + √(d² + 4o²)) with d = a_qq − a_pp so
/// that o = 0 gives t = 0 rather than a division by zero.
#[inline(always)]
fn jacobi_rotation<T: Real>(app: T, aqq: T, o: T) -> (T, T) {
    let d = aqq - app;
    let sign = T::select(T::ZERO.gt(d), -T::ONE, T::ONE);
    let two_o = o + o;
    let denominator = d * sign + (d * d + two_o * two_o).sqrt();
    let t = T::select(denominator.gt(T::ZERO), two_o * sign / denominator, T::ZERO);
    let c = T::ONE / (T::ONE + t * t).sqrt();
    (c, t * c)
}

/// M ← M J on columns p and q: column p becomes c mₚ − s m_q, column q s mₚ + c m_q.
#[inline(always)]
fn rotate_columns<T: Real>(m: &mut Columns<T>, p: usize, q: usize, c: T, s: T) {
    let (x, y) = (m[p], m[q]);
    m[p] = sub3(scale(x, c), scale(y, s));
    m[q] = [0, 1, 2].map(|i| x[i] * s + y[i] * c);
}

/// M ← Jᵀ M on rows p and q: row p becomes c rowₚ − s row_q, row q s rowₚ + c row_q.
#[inline(always)]
fn rotate_rows<T: Real>(m: &mut Columns<T>, p: usize, q: usize, c: T, s: T) {
    for column in m.iter_mut() {
        let (x, y) = (column[p], column[q]);
        column[p] = c * x - s * y;
        column[q] = s * x + c * y;
    }
}

/// The values and slopes of matrix `f` of dual numbers.
fn parts<T: Real>(f: Columns<Tangent<T>>) -> (Columns<T>, Columns<T>) {
    (f.map(|c| c.map(|x| x.value)), f.map(|c| c.map(|x| x.slope)))
}

/// The dual matrix of `value` and `slope`.
fn join<T: Real>(value: Columns<T>, slope: Columns<T>) -> Columns<Tangent<T>> {
    [0, 1, 2].map(|j| [0, 1, 2].map(|i| Tangent::new(value[j][i], slope[j][i])))
}

/// The signed SVD of a matrix of dual numbers: the value's SVD, and the exact derivatives of U, σ
/// and V along the slope (the module's documentation); not finite where two |σ| are equal.
pub(crate) fn svd_of_tangents<T: Real>(f: Columns<Tangent<T>>) -> Svd<Tangent<T>> {
    let (value, slope) = parts(f);
    let svd = T::signed_svd(value);
    let p = transpose_mul(svd.u, mat_mul(slope, svd.v));
    let sigma = svd.sigma;
    let mut omega_u = [[T::ZERO; 3]; 3];
    let mut omega_v = [[T::ZERO; 3]; 3];
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        let (pij, pji) = (p[j][i], p[i][j]);
        let gap = sigma[j] * sigma[j] - sigma[i] * sigma[i];
        let u = (sigma[j] * pij + sigma[i] * pji) / gap;
        let v = (sigma[i] * pij + sigma[j] * pji) / gap;
        (omega_u[j][i], omega_u[i][j]) = (u, -u);
        (omega_v[j][i], omega_v[i][j]) = (v, -v);
    }
    Svd {
        u: join(svd.u, mat_mul(svd.u, omega_u)),
        sigma: [0, 1, 2].map(|i| Tangent::new(sigma[i], p[i][i])),
        v: join(svd.v, mat_mul(svd.v, omega_v)),
    }
}

/// The polar rotation of a matrix of dual numbers: the value's, and dR = R \[w\]ₓ with
/// (tr S · I − S) w = vee(Rᵀ dF − dFᵀ R), S = Rᵀ F (the module's documentation).
pub(crate) fn polar_of_tangents<T: Real>(f: Columns<Tangent<T>>) -> Columns<Tangent<T>> {
    let (value, slope) = parts(f);
    let r = T::polar(value);
    join(r, polar_slope(r, value, slope))
}

/// dR of the polar rotation R of F along dF: R \[w\]ₓ, (tr S · I − S) w = vee(Rᵀ dF − dFᵀ R).
fn polar_slope<T: Real>(r: Columns<T>, f: Columns<T>, df: Columns<T>) -> Columns<T> {
    let s = transpose_mul(r, f);
    let trace = s[0][0] + s[1][1] + s[2][2];
    let mut m = s.map(|column| column.map(|x| -x));
    for (j, column) in m.iter_mut().enumerate() {
        column[j] += trace;
    }
    let a = transpose_mul(r, df);
    let b = [a[1][2] - a[2][1], a[2][0] - a[0][2], a[0][1] - a[1][0]];
    let w = solve(m, b);
    let unit: Columns<T> = identity();
    [0, 1, 2].map(|j| mat_vec(r, cross(w, unit[j])))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numbers::random::SplitMix64 as Random;

    fn random_matrix(random: &mut Random, spread: f64) -> Columns<f64> {
        [0, 1, 2].map(|_| [0, 1, 2].map(|_| random.range(-spread, spread)))
    }

    fn largest_difference(a: Columns<f64>, b: Columns<f64>) -> f64 {
        (0..9)
            .map(|k| (a[k / 3][k % 3] - b[k / 3][k % 3]).abs())
            .fold(0.0, f64::max)
    }

    fn diagonal(s: [f64; 3]) -> Columns<f64> {
        [[s[0], 0.0, 0.0], [0.0, s[1], 0.0], [0.0, 0.0, s[2]]]
    }

    fn det(m: Columns<f64>) -> f64 {
        dot(m[0], cross(m[1], m[2]))
    }

    /// U and V rotations, σ ordered and signed as documented, F = U Σ Vᵀ, to rounding.
    fn assert_signed_svd(f: Columns<f64>, tolerance: f64) {
        let svd = f64::signed_svd(f);
        let size = svd.sigma[0].max(1e-300);
        for m in [svd.u, svd.v] {
            assert!(largest_difference(transpose_mul(m, m), identity()) < tolerance);
            assert!((det(m) - 1.0).abs() < tolerance);
        }
        let [s0, s1, s2] = svd.sigma;
        assert!(s0 >= s1 && s1 >= s2.abs() && s1 >= 0.0, "{:?}", svd.sigma);
        assert!(det(f) * s2 >= 0.0 || s2.abs() < tolerance * size);
        let back = mul_transpose(mat_mul(svd.u, diagonal(svd.sigma)), svd.v);
        assert!(
            largest_difference(back, f) < tolerance * size,
            "{f:?} gives back {back:?}"
        );
    }

    #[test]
    fn random_matrices_decompose_to_rounding() {
        let mut random = Random::new(7);
        for _ in 0..20_000 {
            let f = random_matrix(&mut random, 2.0);
            assert_signed_svd(f, 1e-13);
        }
    }

    #[test]
    fn repeated_zero_and_reflected_singular_values_decompose() {
        let rotation = f64::polar([[0.0, 0.6, 0.8], [0.0, -0.8, 0.6], [1.0, 0.0, 0.0]]);
        for sigma in [
            [1.0, 1.0, 1.0],
            [1.0, 1.0, -1.0],
            [2.0, 1.0, 1.0],
            [2.0, 2.0, -1.0],
            [3.0, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            [1.0, 1e-9, -1e-9],
            [1e-150, 1e-151, 1e-152],
        ] {
            let f = mat_mul(rotation, diagonal(sigma));
            assert_signed_svd(f, 1e-13);
            let svd = f64::signed_svd(f);
            for (got, want) in svd.sigma.iter().zip(sigma) {
                assert!((got - want).abs() <= 1e-13 * sigma[0].abs().max(1e-300));
            }
        }
    }

    #[test]
    fn f32_and_lanes_agree_with_f64() {
        use crate::numbers::lanes::F32x8;
        let mut random = Random::new(11);
        for _ in 0..2_000 {
            let f = random_matrix(&mut random, 2.0);
            let exact = f64::polar(f);
            let single = f32::polar(f.map(|c| c.map(|x| x as f32)));
            let lanes = F32x8::polar(f.map(|c| c.map(F32x8::from_f64)));
            // f32 rounding, amplified near the jump of an inverted F with σ₁ ≈ −σ₂.
            let svd = f64::signed_svd(f);
            let conditioning = 1.0 / (svd.sigma[1] + svd.sigma[2]).abs().min(1.0);
            for j in 0..3 {
                for i in 0..3 {
                    let error = (single[j][i] as f64 - exact[j][i]).abs();
                    assert!(error < 1e-5 * conditioning, "{f:?}: {error}");
                    assert_eq!(lanes[j][i].0.to_array()[3], single[j][i]);
                }
            }
        }
    }

    /// The derivative along one direction by central differences of the f64 decomposition.
    fn central<const N: usize>(
        f: Columns<f64>,
        df: Columns<f64>,
        value: impl Fn(Columns<f64>) -> [f64; N],
    ) -> [f64; N] {
        let h = 1e-6;
        let at = |t: f64| value([0, 1, 2].map(|j| [0, 1, 2].map(|i| f[j][i] + t * df[j][i])));
        let (plus, minus) = (at(h), at(-h));
        std::array::from_fn(|k| (plus[k] - minus[k]) / (2.0 * h))
    }

    fn flat(m: Columns<f64>) -> [f64; 9] {
        [0, 1, 2, 3, 4, 5, 6, 7, 8].map(|k| m[k / 3][k % 3])
    }

    #[test]
    fn tangents_match_central_differences() {
        let mut random = Random::new(3);
        for _ in 0..500 {
            let f = random_matrix(&mut random, 2.0);
            let df = random_matrix(&mut random, 1.0);
            let svd = f64::signed_svd(f);
            let gaps = [
                svd.sigma[0] - svd.sigma[1],
                svd.sigma[1] - svd.sigma[2].abs(),
            ];
            let sums = svd.sigma[1] + svd.sigma[2];
            if gaps.iter().any(|g| *g < 1e-2) || sums.abs() < 1e-2 {
                continue;
            }
            let dual = join(f, df);
            let polar = polar_of_tangents(dual).map(|c| c.map(|x| x.slope));
            let expected = central(f, df, |m| flat(f64::polar(m)));
            let got = flat(polar);
            for k in 0..9 {
                assert!(
                    (got[k] - expected[k]).abs() < 1e-5,
                    "{f:?}: {got:?} {expected:?}"
                );
            }
            let sigma = svd_of_tangents(dual).sigma.map(|x| x.slope);
            let expected = central(f, df, |m| f64::signed_svd(m).sigma);
            for k in 0..3 {
                assert!((sigma[k] - expected[k]).abs() < 1e-5);
            }
            // U's derivative, up to the sign convention a difference quotient keeps.
            let du = flat(svd_of_tangents(dual).u.map(|c| c.map(|x| x.slope)));
            let expected = central(f, df, |m| flat(f64::signed_svd(m).u));
            for k in 0..9 {
                assert!((du[k] - expected[k]).abs() < 1e-4, "{du:?} {expected:?}");
            }
        }
    }

    /// At F = I all σ are equal: the rotation's derivative is dF's antisymmetric part, σ's sum
    /// has the derivative tr dF, and U's derivative is not finite (U is not unique there).
    #[test]
    fn at_repeated_singular_values_the_rotation_and_symmetric_functions_have_derivatives() {
        let f: Columns<f64> = identity();
        let df = [[0.3, -0.2, 0.5], [0.7, 0.1, -0.4], [0.2, 0.9, -0.6]];
        let dual = join(f, df);
        let dr = polar_of_tangents(dual).map(|c| c.map(|x| x.slope));
        for j in 0..3 {
            for i in 0..3 {
                let antisymmetric = 0.5 * (df[j][i] - df[i][j]);
                assert!((dr[j][i] - antisymmetric).abs() < 1e-14);
            }
        }
        let expected = central(f, df, |m| flat(f64::polar(m)));
        for (got, want) in flat(dr).iter().zip(expected) {
            assert!((got - want).abs() < 1e-6);
        }
        let svd = svd_of_tangents(dual);
        let sum: f64 = svd.sigma.iter().map(|x| x.slope).sum();
        assert!((sum - (df[0][0] + df[1][1] + df[2][2])).abs() < 1e-14);
        assert!(svd.u.iter().flatten().any(|x| !x.slope.is_finite()));
        // Where an inverted F's two smallest |σ| are equal, R has no derivative.
        let mirrored = diagonal([1.0, 1.0, -1.0]);
        let slope = polar_of_tangents(join(mirrored, df));
        assert!(slope.iter().flatten().any(|x| !x.slope.is_finite()));
    }
}
