//! The time integration around the constraint projections, written once for any precision: the
//! f64 solver ([`crate::simulation`]) and the fast f32 solver ([`crate::simulation::fast`]) both use it.

use crate::numbers::vector::{Mask, Real, Vector3, rounded};

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
) {
    let motion = Motion::of(substep);
    for i in 0..positions.len() {
        previous[i] = positions[i];
        if let Some(r) = &mut residuals {
            r.previous[i] = r.now[i];
        }
        let residual = residuals.as_ref().map(|r| r.now[i]);
        let force = forces.get(i).copied();
        let (x, v, r, push) = predict_particle(
            (positions[i], velocities[i], residual),
            inverse_masses[i],
            force,
            &motion,
        );
        positions[i] = x;
        velocities[i] = v;
        pushes[i] = push;
        if let (Some(residuals), Some(r)) = (&mut residuals, r) {
            residuals.now[i] = r;
        }
    }
}

/// A substep's prediction in the numbers of an engine ([`Substep`] converted once).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Motion<V: Vector3> {
    /// g h, along −y.
    pub pull: V,
    /// h.
    pub h: V::Real,
    /// The ground's height, if there is a ground.
    pub floor: Option<V::Real>,
    /// Whether every particle keeps its z.
    pub plane_strain: bool,
}

impl<V: Vector3> Motion<V> {
    /// `substep` in the numbers of `V`.
    pub(crate) fn of(substep: Substep) -> Motion<V> {
        Motion {
            pull: V::from_f64s(0.0, -substep.gravity, 0.0) * V::Real::from_f64(substep.h),
            h: V::Real::from_f64(substep.h),
            floor: substep.ground.map(V::Real::from_f64),
            plane_strain: substep.plane_strain,
        }
    }
}

/// One particle's prediction ([`predict`]), without a branch on a value (the GPU engine runs
/// it too): from its position x, velocity v and residual r (where kept) at the start of the
/// substep, its inverse mass `w` and the external force on it, the predicted x, v and r and the
/// ground's push. A held particle (w = 0) keeps x, v and r, and is not pushed.
#[inline(always)]
pub(crate) fn predict_particle<V: Vector3>(
    (x, v, r): (V, V, Option<V>),
    w: V::Real,
    force: Option<V>,
    motion: &Motion<V>,
) -> (V, V, Option<V>, V) {
    let free = w.gt(V::Real::ZERO);
    if !free.any() {
        return (x, v, r, V::ZERO);
    }
    let h = motion.h;
    let mut velocity = v + motion.pull;
    if let Some(force) = force {
        velocity += force * (w * h);
    }
    if motion.plane_strain {
        let [vx, vy, _] = velocity.to_array();
        velocity = V::from_array([vx, vy, V::Real::ZERO]);
    }
    let step = velocity * h;
    let (mut moved, mut residual) = match r {
        None => (x + step, None),
        Some(r) => {
            // Each rounding kept as it is, so that no compiler cancels x out (`rounded`).
            let step = rounded(step + r);
            let moved = rounded(x + step);
            (moved, Some(step - rounded(moved - x)))
        }
    };
    let mut push = V::ZERO;
    if let Some(floor) = motion.floor {
        let below = floor.gt(moved.y());
        if below.any() {
            let predicted = moved;
            let mut grounded = x;
            grounded.set_y(floor);
            let mut pushed = grounded - predicted;
            if let (Some(now), Some(start)) = (residual, r) {
                let mut back = start;
                back.set_y(V::Real::ZERO);
                pushed += back - now;
                residual = Some(V::select(below, back, now));
            }
            moved = V::select(below, grounded, moved);
            push = V::select(below, pushed, push);
        }
    }
    (
        V::select(free, moved, x),
        V::select(free, velocity, v),
        residual
            .zip(r)
            .map(|(now, start)| V::select(free, now, start)),
        V::select(free, push, V::ZERO),
    )
}

/// The ground as a constraint: y ≥ `ground` for every free particle, each move added to the
/// particle's push of the substep ([`Book::pushes`]).
pub(crate) fn project_ground<V: Vector3>(
    positions: &mut [V],
    inverse_masses: &[V::Real],
    ground: f64,
    pushes: &mut [V],
) {
    let floor = V::Real::from_f64(ground);
    for ((p, &w), push) in positions.iter_mut().zip(inverse_masses).zip(pushes) {
        (*p, *push) = ground_particle(*p, w, floor, *push);
    }
}

/// One particle of [`project_ground`]: its position and push after y ≥ `floor`, if it is free.
#[inline(always)]
pub(crate) fn ground_particle<V: Vector3>(p: V, w: V::Real, floor: V::Real, push: V) -> (V, V) {
    let under = w.gt(V::Real::ZERO) & floor.gt(p.y());
    if !under.any() {
        return (p, push);
    }
    let zero = V::Real::ZERO;
    let pushed = push + V::from_array([zero, floor - p.y(), zero]);
    let mut lifted = p;
    lifted.set_y(floor);
    (V::select(under, lifted, p), V::select(under, pushed, push))
}

/// Plane strain: every particle back at the z it had at the start of the substep (`previous`),
/// after a sweep's projections moved it. The prediction keeps v_z = 0, so each particle keeps
/// its starting z for the whole run: the extruded panel of a plane problem held in z.
pub(crate) fn hold_plane<V: Vector3>(positions: &mut [V], previous: &[V]) {
    for (p, q) in positions.iter_mut().zip(previous) {
        *p = plane_particle(*p, *q);
    }
}

/// One particle of [`hold_plane`]: `p` with the z of `start`.
#[inline(always)]
pub(crate) fn plane_particle<V: Vector3>(p: V, start: V) -> V {
    let [x, y, _] = p.to_array();
    V::from_array([x, y, start.to_array()[2]])
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
) {
    let ending = Ending::of(h, damping, cap, book.gravity);
    for i in 0..positions.len() {
        let moved = match residuals {
            None => positions[i] - previous[i],
            Some(r) => (positions[i] - previous[i]) + (r.now[i] - r.previous[i]),
        };
        let force = book.forces.get(i).copied();
        let w = book.inverse_masses[i];
        (velocities[i], book.taken[i]) = end_particle(
            (moved, velocities[i]),
            (w, force, book.pushes[i]),
            book.taken[i],
            &ending,
        );
    }
}

/// The end of a substep in the numbers of an engine: what [`end_particle`] needs.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Ending<V: Vector3> {
    /// h.
    pub h: V::Real,
    /// What damping keeps of a velocity: max(0, 1 − damping h).
    pub keep: V::Real,
    /// Whether there is damping.
    pub damped: bool,
    /// Whether |v| is capped (an edit settles).
    pub cap: bool,
    /// g h, along −y.
    pub pull: V,
}

impl<V: Vector3> Ending<V> {
    /// The end of a substep of length `h`, with `damping` per second, capped or not, under
    /// `gravity`.
    pub(crate) fn of(h: f64, damping: f64, cap: bool, gravity: f64) -> Ending<V> {
        Ending {
            h: V::Real::from_f64(h),
            keep: V::Real::from_f64((1.0 - damping * h).max(0.0)),
            damped: damping > 0.0,
            cap,
            pull: V::from_f64s(0.0, -gravity * h, 0.0),
        }
    }
}

/// One particle of [`update_velocities`], without a branch on a value (the GPU engine runs it
/// too): from how far it `moved` over the substep and its predicted velocity, its inverse mass,
/// the external force on it and the ground's push, its new velocity and what was taken from it
/// (`taken`, added to: x the ground's, y damping's, z the cap's; see [`Book`]).
#[inline(always)]
pub(crate) fn end_particle<V: Vector3>(
    (moved, predicted): (V, V),
    (w, force, push): (V::Real, Option<V>, V),
    taken: V,
    ending: &Ending<V>,
) -> (V, V) {
    let zero = V::Real::ZERO;
    let h = ending.h;
    let end = moved / h;
    let mut velocity = end;
    if ending.cap {
        let limit = predicted.length();
        let squared = velocity.length_squared();
        let over = squared.gt(limit * limit);
        if over.any() {
            velocity = V::select(over, (velocity / squared.sqrt()) * limit, velocity);
        }
    }
    let pushed = push.length_squared().gt(zero);
    let mut booked = pushed;
    if ending.damped || ending.cap {
        booked = booked | !booked;
    }
    let booked = w.gt(zero) & booked;
    // Most particles, most substeps, have nothing to book: no ground under them, no damping,
    // no cap. They pay one test.
    let mut taken = taken;
    if booked.any() {
        let half_mass = V::Real::from_f64(0.5) / w;
        let ground = if pushed.any() {
            let mut added = ending.pull;
            if let Some(force) = force {
                added += force * (w * h);
            }
            // `predicted` is v₀ + (g + w f) h.
            let start = predicted - added;
            V::Real::select(pushed, -(half_mass / h) * push.dot(start + velocity), zero)
        } else {
            zero
        };
        let kept = velocity.length_squared();
        let capped = half_mass * (end.length_squared() - kept);
        let lost = V::Real::ONE - ending.keep * ending.keep;
        let add = V::from_array([ground, half_mass * kept * lost, capped]);
        taken = V::select(booked, taken + add, taken);
    }
    (velocity * ending.keep, taken)
}
