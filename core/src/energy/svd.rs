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

use glam::DMat3;
use nalgebra::Matrix3;

/// F = U diag(σ) Vᵀ with U and V rotations (det +1): where an SVD's U or V is a reflection, its
/// column of the smallest |σ| is negated, and σ with it, so that an inverted F has one negative σ.
pub fn signed_svd(f: &DMat3) -> (DMat3, [f64; 3], DMat3) {
    let m = Matrix3::from_column_slice(&f.to_cols_array());
    let svd = m.svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return (
            DMat3::IDENTITY,
            [f.x_axis.x, f.y_axis.y, f.z_axis.z],
            DMat3::IDENTITY,
        );
    };
    let to_glam = |m: Matrix3<f64>| DMat3::from_cols_slice(m.as_slice());
    let mut u = to_glam(u);
    let mut v = to_glam(v_t.transpose());
    let mut sigma = [
        svd.singular_values[0],
        svd.singular_values[1],
        svd.singular_values[2],
    ];
    let smallest = (0..3)
        .min_by(|&a, &b| sigma[a].total_cmp(&sigma[b]))
        .unwrap_or(2);
    let negate = |m: &mut DMat3| {
        let column = m.col(smallest);
        *m.col_mut(smallest) = -column;
    };
    if u.determinant() < 0.0 {
        negate(&mut u);
        sigma[smallest] = -sigma[smallest];
    }
    if v.determinant() < 0.0 {
        negate(&mut v);
        sigma[smallest] = -sigma[smallest];
    }
    (u, sigma, v)
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
