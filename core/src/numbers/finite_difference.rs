//! Numerical gradients, to check the analytic ones.

use glam::DVec3;

/// The step of a central difference for coordinates of size `scale`: h = ∛ε · max(scale, 1e-3),
/// which balances the truncation error (∝ h²) against rounding (∝ ε/h).
pub(crate) fn step_for_scale(scale: f64) -> f64 {
    f64::EPSILON.cbrt() * scale.max(1e-3)
}

/// ∇C by central differences: ∂C/∂xᵢ ≈ (C(x + h eᵢ) − C(x − h eᵢ)) / 2h for every coordinate
/// of every point, with h from `step_for_scale` of the largest coordinate.
///
/// ```
/// use glam::DVec3;
/// use tetlab_core::numbers::finite_difference::central_difference;
/// // C = |p0|², ∇C = 2 p0.
/// let g = central_difference(&[DVec3::new(1.0, -2.0, 0.5)], |p| p[0].length_squared());
/// assert!((g[0] - DVec3::new(2.0, -4.0, 1.0)).length() < 1e-8);
/// ```
pub fn central_difference(points: &[DVec3], value: impl Fn(&[DVec3]) -> f64) -> Vec<DVec3> {
    let scale = points
        .iter()
        .map(|p| p.abs().max_element())
        .fold(0.0, f64::max);
    let h = step_for_scale(scale);
    let mut probe = points.to_vec();
    let mut gradients = vec![DVec3::ZERO; points.len()];
    for (i, gradient) in gradients.iter_mut().enumerate() {
        for axis in 0..3 {
            let original = probe[i][axis];
            probe[i][axis] = original + h;
            let forward = value(&probe);
            probe[i][axis] = original - h;
            let backward = value(&probe);
            probe[i][axis] = original;
            gradient[axis] = (forward - backward) / (2.0 * h);
        }
    }
    gradients
}
