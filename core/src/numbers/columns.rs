//! 3-vectors as `[T; 3]` and 3 × 3 matrices as their three columns (`[[T; 3]; 3]`), over any
//! [`Real`]: the arithmetic that a constraint file's tape (`Op::apply`) and the decompositions of
//! [`super::svd3`] share. Sums are added in the order written, so that every [`Real`] gives the
//! same rounding.
//!
//! ```
//! use tetlab_core::numbers::columns::{cross, dot, mat_vec};
//! // a × b is perpendicular to a and to b; the identity's columns give v back.
//! let (a, b) = ([1.0, 2.0, 3.0], [-2.0, 0.5, 4.0]);
//! let c = cross(a, b);
//! assert_eq!((dot(c, a), dot(c, b)), (0.0, 0.0));
//! let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
//! assert_eq!(mat_vec(identity, a), a);
//! ```

use crate::numbers::vector::Real;

/// A 3 × 3 matrix as its columns: `m[j][i]` is the entry of row i, column j.
pub type Columns<T> = [[T; 3]; 3];

/// a + b.
#[inline(always)]
pub fn add3<T: Real>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// a − b.
#[inline(always)]
pub fn sub3<T: Real>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// a k.
#[inline(always)]
pub fn scale<T: Real>(a: [T; 3], k: T) -> [T; 3] {
    [a[0] * k, a[1] * k, a[2] * k]
}

/// a / k.
#[inline(always)]
pub fn shrink<T: Real>(a: [T; 3], k: T) -> [T; 3] {
    [a[0] / k, a[1] / k, a[2] / k]
}

/// a·b = a.x b.x + a.y b.y + a.z b.z, in that order.
#[inline(always)]
pub fn dot<T: Real>(a: [T; 3], b: [T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The matrix of columns `m` times `v`: m₀ v.x + m₁ v.y + m₂ v.z, summed in that order.
#[inline(always)]
pub fn mat_vec<T: Real>(m: Columns<T>, v: [T; 3]) -> [T; 3] {
    add3(
        add3(scale(m[0], v[0]), scale(m[1], v[1])),
        scale(m[2], v[2]),
    )
}

/// a × b.
#[inline(always)]
pub fn cross<T: Real>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// A B, column by column: (A B)ⱼ = A bⱼ.
#[inline(always)]
pub fn mat_mul<T: Real>(a: Columns<T>, b: Columns<T>) -> Columns<T> {
    [mat_vec(a, b[0]), mat_vec(a, b[1]), mat_vec(a, b[2])]
}

/// Aᵀ B: entry (i, j) is aᵢ·bⱼ.
#[inline(always)]
pub fn transpose_mul<T: Real>(a: Columns<T>, b: Columns<T>) -> Columns<T> {
    [0, 1, 2].map(|j| [0, 1, 2].map(|i| dot(a[i], b[j])))
}

/// A Bᵀ = Σₖ aₖ bₖᵀ: column j is Σₖ aₖ (bₖ)ⱼ.
#[inline(always)]
pub fn mul_transpose<T: Real>(a: Columns<T>, b: Columns<T>) -> Columns<T> {
    [0, 1, 2].map(|j| mat_vec(a, [b[0][j], b[1][j], b[2][j]]))
}

/// The identity.
#[inline(always)]
pub fn identity<T: Real>() -> Columns<T> {
    let (o, l) = (T::ZERO, T::ONE);
    [[l, o, o], [o, l, o], [o, o, l]]
}

/// M⁻¹ v for the matrix of columns m: (v·(m₁×m₂), v·(m₂×m₀), v·(m₀×m₁)) / det M, the rows of
/// M⁻¹ being those cross products over the determinant. Not finite where det M = 0.
#[inline(always)]
pub fn solve<T: Real>(m: Columns<T>, v: [T; 3]) -> [T; 3] {
    let rows = [cross(m[1], m[2]), cross(m[2], m[0]), cross(m[0], m[1])];
    let det = dot(m[0], rows[0]);
    [
        dot(rows[0], v) / det,
        dot(rows[1], v) / det,
        dot(rows[2], v) / det,
    ]
}
