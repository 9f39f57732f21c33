//! The time integration around the constraint projections, written once for any precision: the
//! f64 solver ([`crate::simulation`]) and the fast f32 solver ([`crate::simulation::fast`]) both use it.

use crate::numbers::vector::{Real, Vector3};

/// The sub-ulp parts of the positions, for an engine whose positions are too coarse to hold a
/// substep's motion (the fast engine's f32): the position meant is x + r, with x the stored
/// position and r what rounding x + v h left out (compensated summation). `previous` holds r at
/// the start of the substep, as `previous` of [`predict`] holds x.
///
/// Why: at the default 100 substeps (h = 1/6000 s) a particle 0.5 m from the origin moves
/// v h ≈ 2.7·10⁻⁷ m per substep after one frame of free fall, four or five f32 ulps (6·10⁻⁸ m).
/// Taking v = (x − x_prev) / h from such rounded positions quantises v to ulp / h ≈ 3.6·10⁻⁴
/// m/s, and the errors pile up: without r, a Gmsh ball fell 5.5 % too fast on the fast engine
/// (9.21 cm against 8.73 cm in 8 frames, `tetlab run --scene ../shared/meshes/ball_v41.msh
/// --frames 8 --json --engine fast`, then `--engine reference`) and drifted sideways.
pub(crate) struct Residuals<'a, V> {
    /// r now.
    pub now: &'a mut [V],
    /// r at the start of the substep.
    pub previous: &'a mut [V],
}

/// What a substep's prediction needs to know: gravity g (m/s², along −y), the substep's length
/// h (s), the ground's height, if there is one, and whether every particle keeps its z
/// (plane strain, `hold_plane`).
#[derive(Clone, Copy, Debug)]
pub struct Substep {
    /// Gravity g in m/s², along −y.
    pub gravity: f64,
    /// The substep's length h in s.
    pub h: f64,
    /// The ground's height, if there is a ground.
    pub ground: Option<f64>,
    /// Whether every particle keeps its z.
    pub plane_strain: bool,
}

/// The prediction of a substep of length `h`: x_prev = x, and for every free particle (w > 0)
/// v += (g + w fᵢ) h, x += v h with gravity g along −y and `forces` fᵢ the external force on
/// particle i in N (a load lumped onto the nodes; empty: none). With plane strain, v_z = 0. With a ground (at height `ground` in the
/// positions' frame: 0, or where y = 0 lies for the fast engine, which keeps positions relative
/// to an origin near the body), a particle predicted below it is put back at its previous
/// position, on the ground (sticking friction).
///
/// With `residuals` ([`Residuals`]), x + r advances by v h: x = fl(x + (v h + r)), and r keeps
/// what the rounding lost, r = (v h + r) − (x_new − x).
///
/// `pushes` starts the substep's tally of the ground's moves ([`Book::pushes`]): 0, or the move
/// back onto the ground of a particle predicted below it.
#[allow(clippy::too_many_arguments)]
pub(crate) fn predict<V: Vector3>(
    positions: &mut [V],
    previous: &mut [V],
    velocities: &mut [V],
    inverse_masses: &[V::Real],
    forces: &[V],
    substep: Substep,
    mut residuals: Option<Residuals<'_, V>>,
    pushes: &mut [V],
) where
    V::Real: PartialOrd,
{
    let Substep {
        gravity,
        h,
        ground,
        plane_strain,
    } = substep;
    let pull = V::from_f64s(0.0, -gravity, 0.0) * V::Real::from_f64(h);
    let h = V::Real::from_f64(h);
    let floor = ground.map(V::Real::from_f64);
    let zero = V::from_f64s(0.0, 0.0, 0.0);
    for i in 0..positions.len() {
        previous[i] = positions[i];
        pushes[i] = zero;
        if let Some(r) = &mut residuals {
            r.previous[i] = r.now[i];
        }
        if inverse_masses[i] == V::Real::ZERO {
            continue;
        }
        velocities[i] += pull;
        if let Some(&force) = forces.get(i) {
            velocities[i] += force * (inverse_masses[i] * h);
        }
        if plane_strain {
            let [x, y, _] = velocities[i].to_array();
            velocities[i] = V::from_array([x, y, V::Real::ZERO]);
        }
        let step = velocities[i] * h;
        match &mut residuals {
            None => positions[i] += step,
            Some(r) => {
                let step = step + r.now[i];
                let x = positions[i] + step;
                r.now[i] = step - (x - positions[i]);
                positions[i] = x;
            }
        }
        if let Some(floor) = floor
            && positions[i].y() < floor
        {
            let predicted = positions[i];
            positions[i] = previous[i];
            positions[i].set_y(floor);
            pushes[i] = positions[i] - predicted;
            if let Some(r) = &mut residuals {
                let predicted = r.now[i];
                r.now[i] = r.previous[i];
                r.now[i].set_y(V::Real::ZERO);
                pushes[i] += r.now[i] - predicted;
            }
        }
    }
}

/// The ground as a constraint: y ≥ `ground` for every free particle, each move added to the
/// particle's push of the substep ([`Book::pushes`]).
pub(crate) fn project_ground<V: Vector3>(
    positions: &mut [V],
    inverse_masses: &[V::Real],
    ground: f64,
    pushes: &mut [V],
) where
    V::Real: PartialOrd,
{
    let floor = V::Real::from_f64(ground);
    for ((p, &w), push) in positions.iter_mut().zip(inverse_masses).zip(pushes) {
        if w > V::Real::ZERO && p.y() < floor {
            *push += V::from_array([V::Real::ZERO, floor - p.y(), V::Real::ZERO]);
            p.set_y(floor);
        }
    }
}

/// Plane strain: every particle back at the z it had at the start of the substep (`previous`),
/// after a sweep's projections moved it. The prediction keeps v_z = 0, so each particle keeps
/// its starting z for the whole run: the extruded panel of a plane problem held in z.
pub(crate) fn hold_plane<V: Vector3>(positions: &mut [V], previous: &[V]) {
    for (p, q) in positions.iter_mut().zip(previous) {
        let [x, y, _] = p.to_array();
        *p = V::from_array([x, y, q.to_array()[2]]);
    }
}

/// What the velocity update books of each particle's energy: what the ground, damping and the
/// settling cap took from it ([`crate::simulation::Taken`]).
///
/// The ground acts on a particle by moving it (`pushes`: the sum of its moves within the
/// substep, Δx_g, from [`predict`] and [`project_ground`]), an impulse m Δx_g / h. Its work is
/// that impulse against the particle's mean velocity over the substep, (v₀ + v₁) / 2, v₀ at the
/// start (before gravity and the forces) and v₁ at the end (after the settling cap, before
/// damping): the work of an impulse, exact when nothing else acts, and 0 for a particle resting
/// on the ground (v₀ = v₁ = 0), whose push only undoes gravity's. The impulses of a substep
/// share its change of kinetic energy so, each against the same mean velocity. It is negative
/// for a landing or a particle held by the ground's sticking (the ground took −W), and positive
/// where the ground pushes a particle out from under it (it gave: the height it lifts it by).
/// Damping took ½ m |v₁|² (1 − k²) of the velocity it multiplied by k; the settling cap
/// ½ m (|v|² − |v₁|²) of the velocity v the projections gave.
pub(crate) struct Book<'a, V: Vector3> {
    /// The inverse masses (0: held, not booked).
    pub inverse_masses: &'a [V::Real],
    /// The external forces per particle, N (empty: none), which the prediction added.
    pub forces: &'a [V],
    /// Gravity, m/s², along −y, which the prediction added.
    pub gravity: f64,
    /// The ground's moves of each particle within the substep, Δx_g.
    pub pushes: &'a [V],
    /// Per particle, what was taken so far (J), added to: x the ground's, y damping's, z the
    /// settling cap's.
    pub taken: &'a mut [V],
}

/// v = (x − x_prev) / h, then damped: v *= max(0, 1 − damping · h). With `cap`, |v| is first
/// limited to the speed the particle had before (the predicted velocity in `velocities`). With
/// `residuals` ([`Residuals`]), v = ((x − x_prev) + (r − r_prev)) / h: the motion of x + r.
/// What the ground, damping and the cap took is added to `book` ([`Book`]).
#[allow(clippy::too_many_arguments)]
pub(crate) fn update_velocities<V: Vector3>(
    positions: &[V],
    previous: &[V],
    velocities: &mut [V],
    h: f64,
    damping: f64,
    cap: bool,
    residuals: Option<&Residuals<'_, V>>,
    book: Book<'_, V>,
) where
    V::Real: PartialOrd,
{
    let keep = V::Real::from_f64((1.0 - damping * h).max(0.0));
    let damped = damping > 0.0;
    let lost = V::Real::ONE - keep * keep;
    let half = V::Real::from_f64(0.5);
    let pull = V::from_f64s(0.0, -book.gravity * h, 0.0);
    let h = V::Real::from_f64(h);
    for i in 0..positions.len() {
        let moved = match residuals {
            None => positions[i] - previous[i],
            Some(r) => (positions[i] - previous[i]) + (r.now[i] - r.previous[i]),
        };
        let end = moved / h;
        let mut velocity = end;
        if cap {
            let limit = velocities[i].length();
            let squared = velocity.length_squared();
            if squared > limit * limit {
                velocity = (velocity / squared.sqrt()) * limit;
            }
        }
        let w = book.inverse_masses[i];
        let push = book.pushes[i];
        let pushed = push.length_squared() > V::Real::ZERO;
        // Most particles, most substeps, have nothing to book: no ground under them, no
        // damping, no cap. They pay one test.
        if w > V::Real::ZERO && (pushed || damped || cap) {
            let half_mass = half / w;
            let ground = if pushed {
                let mut added = pull;
                if let Some(&force) = book.forces.get(i) {
                    added += force * (w * h);
                }
                // velocities[i] is still the predicted velocity, v₀ + (g + w f) h.
                let start = velocities[i] - added;
                -(half_mass / h) * push.dot(start + velocity)
            } else {
                V::Real::ZERO
            };
            let kept = velocity.length_squared();
            let capped = half_mass * (end.length_squared() - kept);
            book.taken[i] += V::from_array([ground, half_mass * kept * lost, capped]);
        }
        velocities[i] = velocity * keep;
    }
}
