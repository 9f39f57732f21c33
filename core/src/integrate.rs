//! The time integration around the constraint projections, written once for any precision: the
//! f64 solver ([`crate::solver`]) and the fast f32 solver ([`crate::fast`]) both use it.

use crate::vector::{Real, Vector3};

/// The prediction of a substep of length `h`: x_prev = x, and for every free particle (w > 0)
/// v += g h, x += v h with gravity g along −y. With a ground (at height `ground` in the
/// positions' frame: 0, or where y = 0 lies for the fast engine, which keeps positions relative
/// to an origin near the body), a particle predicted below it is put back at its previous
/// position, on the ground (sticking friction).
pub(crate) fn predict<V: Vector3>(
    positions: &mut [V],
    previous: &mut [V],
    velocities: &mut [V],
    inverse_masses: &[V::Real],
    gravity: f64,
    h: f64,
    ground: Option<f64>,
) where
    V::Real: PartialOrd,
{
    let pull = V::from_f64s(0.0, -gravity, 0.0) * V::Real::from_f64(h);
    let h = V::Real::from_f64(h);
    let floor = ground.map(V::Real::from_f64);
    for i in 0..positions.len() {
        previous[i] = positions[i];
        if inverse_masses[i] == V::Real::ZERO {
            continue;
        }
        velocities[i] += pull;
        positions[i] += velocities[i] * h;
        if let Some(floor) = floor
            && positions[i].y() < floor
        {
            positions[i] = previous[i];
            positions[i].set_y(floor);
        }
    }
}

/// The ground as a constraint: y ≥ `ground` for every free particle.
pub(crate) fn project_ground<V: Vector3>(
    positions: &mut [V],
    inverse_masses: &[V::Real],
    ground: f64,
) where
    V::Real: PartialOrd,
{
    let floor = V::Real::from_f64(ground);
    for (p, &w) in positions.iter_mut().zip(inverse_masses) {
        if w > V::Real::ZERO && p.y() < floor {
            p.set_y(floor);
        }
    }
}

/// v = (x − x_prev) / h, then damped: v *= max(0, 1 − damping · h). With `cap`, |v| is first
/// limited to the speed the particle had before (the predicted velocity in `velocities`).
pub(crate) fn update_velocities<V: Vector3>(
    positions: &[V],
    previous: &[V],
    velocities: &mut [V],
    h: f64,
    damping: f64,
    cap: bool,
) where
    V::Real: PartialOrd,
{
    let keep = V::Real::from_f64((1.0 - damping * h).max(0.0));
    let h = V::Real::from_f64(h);
    for i in 0..positions.len() {
        let mut velocity = (positions[i] - previous[i]) / h;
        if cap {
            let limit = velocities[i].length();
            let squared = velocity.length_squared();
            if squared > limit * limit {
                velocity = (velocity / squared.sqrt()) * limit;
            }
        }
        velocities[i] = velocity * keep;
    }
}
