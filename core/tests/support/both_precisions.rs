//! C and ∇C of one constraint in f64 and in f32, as a [`Visit`]: what the tests that compare a
//! constraint file with a built-in family evaluate at each constraint.

use glam::{DVec3, Vec3};
use tetlab_core::constraints::{Constraint, Family, SubstepStart, Visit};

/// One constraint: its points, rest value, rest shape and what its element stores (empty for a
/// family that stores nothing).
pub struct Both<'a> {
    pub points: &'a [DVec3],
    pub rest: f64,
    pub shape: &'a [DVec3],
    pub stored: &'a [f64],
}

/// C, ∇C padded to four particles, and whether it is degenerate.
pub type Values = (f64, [DVec3; 4], bool);

impl Visit for Both<'_> {
    type Output = [Values; 2];
    fn visit<const N: usize, C: Constraint<N>>(self, _: Family, c: &C) -> Self::Output {
        let p: [DVec3; N] = std::array::from_fn(|k| self.points[k]);
        let q: [DVec3; N] = std::array::from_fn(|k| self.shape[k]);
        let e = c.evaluate_stored(&p, self.rest, &q, self.stored, SubstepStart::at_rest(&p));
        let mut g64 = [DVec3::ZERO; 4];
        g64[..N].copy_from_slice(&e.gradients);
        let stored32: Vec<f32> = self.stored.iter().map(|&x| x as f32).collect();
        let p32 = p.map(|v| v.as_vec3());
        let e32 = c.evaluate_stored(
            &p32,
            self.rest as f32,
            &q.map(|v| v.as_vec3()),
            &stored32,
            SubstepStart::at_rest(&p32),
        );
        let mut g32 = [DVec3::ZERO; 4];
        for (g, v) in g32.iter_mut().zip(e32.gradients.iter()) {
            *g = Vec3::as_dvec3(v);
        }
        [
            (e.value, g64, e.degenerate),
            (f64::from(e32.value), g32, e32.degenerate),
        ]
    }
}
