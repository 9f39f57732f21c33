//! The engines' contract in numbers (docs/performance.md, "The engines' contract"): how far an
//! f32 engine's positions may lie from another engine's after one frame, and the gap measured.

use glam::DVec3;

/// f32's unit roundoff, 2⁻²⁴.
pub const UNIT_ROUNDOFF: f64 = 1.0 / 16_777_216.0;

/// How far apart the engines' positions may be after one frame of `substeps` substeps, for a
/// body of size `size`: each substep's f32 projections leave a rounding error of about u·L in a
/// position, which becomes an error of u·L / h in the velocity taken from it, carried through
/// the substeps that remain. With every substep's error in one direction, that sums to
/// u·L·S²/2 over a frame of S substeps.
pub fn frame_bound(size: f64, substeps: u32) -> f64 {
    let s = f64::from(substeps.max(1));
    UNIT_ROUNDOFF * size * s * s / 2.0
}

/// The largest distance between two bodies' positions, particle by particle.
pub fn largest_gap(a: &[DVec3], b: &[DVec3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (*x - *y).length())
        .fold(0.0, f64::max)
}
