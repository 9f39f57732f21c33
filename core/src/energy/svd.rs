//! The signed singular value decomposition of a deformation gradient, F = U Σ Vᵀ with U and V
//! rotations ([`signed_svd`]), and the split of a direction in F-space into twist, flip and scale
//! in its frame (`twist_flip_scale`, after Smith et al. 2019): what the modes' classes
//! ([`super::modes`]) and the neo-Hookean analytic system ([`super::neohookean`]) are written in.
//!
//! ```
//! use glam::DMat3;
//! use tetlab_core::energy::svd::signed_svd;
//! // A reflection: an inverted tet's F has one negative singular value, U and V stay rotations.
//! let f = DMat3::from_diagonal(glam::DVec3::new(2.0, 3.0, -5.0));
//! let (u, sigma, v) = signed_svd(&f);
//! assert!(u.determinant() > 0.0 && v.determinant() > 0.0);
//! assert_eq!(sigma.iter().filter(|s| **s < 0.0).count(), 1);
//! let back = u * DMat3::from_diagonal(sigma.into()) * v.transpose();
//! assert!((back - f).to_cols_array().iter().all(|e| e.abs() < 1e-12));
//! ```

use crate::numbers::vector::Real;
use glam::DMat3;

/// F = U diag(σ) Vᵀ with U and V rotations (det +1) and |σ₀| ≥ |σ₁| ≥ |σ₂|: an inverted F has
/// σ₂ < 0 ([`crate::numbers::svd3`], the decomposition constraint files use too).
pub fn signed_svd(f: &DMat3) -> (DMat3, [f64; 3], DMat3) {
    let columns = [f.x_axis, f.y_axis, f.z_axis].map(|c| c.to_array());
    let svd = f64::signed_svd(columns);
    let to_glam = |m: [[f64; 3]; 3]| DMat3::from_cols_array_2d(&m);
    (to_glam(svd.u), svd.sigma, to_glam(svd.v))
}

/// How much of an F-space direction `m` is twist, flip and scale in the frame of F = U Σ Vᵀ: the
/// squared norms of the antisymmetric off-diagonal part, the symmetric off-diagonal part and the
/// diagonal of Uᵀ m V (they sum to ‖m‖²).
pub(crate) fn twist_flip_scale(u: &DMat3, v: &DMat3, m: &DMat3) -> [f64; 3] {
    let g = u.transpose() * *m * *v;
    let e = |r: usize, c: usize| g.col(c)[r];
    let (mut twist, mut flip, mut scale) = (0.0, 0.0, 0.0);
    for (a, b) in [(1, 2), (2, 0), (0, 1)] {
        twist += (e(a, b) - e(b, a)).powi(2) / 2.0;
        flip += (e(a, b) + e(b, a)).powi(2) / 2.0;
    }
    for k in 0..3 {
        scale += e(k, k).powi(2);
    }
    [twist, flip, scale]
}
