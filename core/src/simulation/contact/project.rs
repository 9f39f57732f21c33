//! The contact stage of a sweep, after the other families ([`ContactPass`]): each pair the broad
//! phase found is projected by its family's formula while its particle is over the triangle, was
//! on its outer side at the substep's start (its height then at least −d), and is too close
//! (C < 0), then held or slowed along the surface by friction. In any precision, one
//! pair after another in a fixed order, so the bits do not depend on the thread count.
//!
//! A pair already inside the thickness at the substep's start (C_start < 0) is first only
//! stopped, at C ≥ C_start (what gives velocity, since velocity is (x − x_start) / h), and then
//! moved out to C = 0 together with where its particles were at the substep's start, which gives
//! none: the "pre-stabilization" of Macklin et al. 2014 (§ 4.4), applied to the layer. Stopping
//! alone was a ratchet: another projection pushed such a particle a little deeper in one
//! substep, the next held it at that new depth, and the folded bar's upper leg came to rest
//! 8.6 mm into the layer. Throwing it out with velocity instead gave a neo-Hookean cube landing
//! on another's edge 762 J in one frame. The move bends the pair's body, though, and the
//! body's rigid constraints undo the bend with speed: a box set down touching a plate, its
//! underside inside the layer, flew off at 19 m/s. So a scene that starts with a pair inside
//! the layer settles as an edit does ([`crate::simulation::Settings::settle_edits`]): no
//! particle moves faster than it did until the corrections die down.
//!
//! Friction, as Macklin et al. 2014 (§ 6.1) and Müller et al. 2020 (§ 3.5) write it for
//! positions: let Δx be the particle's motion over the substep relative to the point of the
//! triangle under it (its corners' motion weighted by the foot's barycentric coordinates b),
//! Δx_t its part along the surface, and d_n how far the contact's projection just moved the
//! particle away from the triangle along n. If |Δx_t| < μ_s d_n the particle sticks: Δx_t is
//! undone whole (static friction); otherwise it is undone by μ_k d_n only (kinetic friction).
//! The undoing is shared by the inverse masses as a constraint on the relative position:
//! the particle moves −w₀/W Δ and corner i moves b_i wᵢ/W Δ, W = w₀ + Σ bᵢ² wᵢ, so momentum is
//! kept and friction only ever takes energy.

use crate::constraints::{Constraint, Family, Visit};
use crate::numbers::vector::{Real, Vector3};
use crate::simulation::projection::{Rule, SkipCounts, correction};

/// One contact family's pass over the pairs of a frame, on an engine's arrays.
pub(crate) struct ContactPass<'a, V: Vector3> {
    /// The pairs: [particle, a, b, c] in the engine's numbering.
    pub found: &'a [[u32; 4]],
    /// The order to project them in (`None`: as found).
    pub order: Option<&'a [u32]>,
    pub positions: &'a mut [V],
    /// Where the particles were at the substep's start: moved with them where a pair leaves the
    /// layer it was already in (see the module docs), so that it gains no speed.
    pub previous: &'a mut [V],
    pub inverse_masses: &'a [V::Real],
    /// The multipliers of this family's pairs.
    pub lambdas: &'a mut [V::Real],
    /// The thickness d, the rest value of every pair.
    pub thickness: V::Real,
    /// The family's rule.
    pub rule: Rule<V::Real>,
    /// μ_s and μ_k.
    pub friction: [V::Real; 2],
    /// Project this pair alone (an index into `found`; step-by-step mode), or every pair in
    /// `order` (`None`).
    pub only: Option<usize>,
}

impl<V: Vector3> Visit for ContactPass<'_, V>
where
    V::Real: Real<Mask = bool> + PartialOrd,
{
    type Output = SkipCounts;

    fn visit<const N: usize, C: Constraint<N>>(mut self, _: Family, constraint: &C) -> SkipCounts {
        let mut skipped = SkipCounts::default();
        if N != 4 {
            return skipped;
        }
        if let Some(c) = self.only {
            if c < self.found.len() {
                self.pair(constraint, c, &mut skipped);
            }
            return skipped;
        }
        for k in 0..self.found.len() {
            let c = self.order.map_or(k, |order| order[k] as usize);
            self.pair(constraint, c, &mut skipped);
        }
        skipped
    }
}

impl<V: Vector3> ContactPass<'_, V>
where
    V::Real: Real<Mask = bool> + PartialOrd,
{
    /// Projects pair `c` of `found`, as the module docs say; counts a skipped projection in
    /// `skipped`.
    fn pair<const N: usize, C: Constraint<N>>(
        &mut self,
        constraint: &C,
        c: usize,
        skipped: &mut SkipCounts,
    ) {
        let ids = self.found[c];
        let p: [V; N] = std::array::from_fn(|i| self.positions[ids[i] as usize]);
        let Some(b) = over_triangle(p[0], [p[1], p[2], p[3]]) else {
            return;
        };
        // The particle must have been on the triangle's outer side at the substep's start
        // (or at most one thickness under it): a particle found behind it, deeper than the
        // substep could have taken it, came in another way (past an edge of the surface,
        // where no triangle holds it) and is not thrown out through this one.
        let start: [V; N] = std::array::from_fn(|i| self.previous[ids[i] as usize]);
        let corners = [start[0], start[1], start[2], start[3]];
        let height = crate::constraints::contact::evaluate(&corners, V::Real::ZERO);
        if !at_least(height.value, -self.thickness) {
            return;
        }
        // A particle already closer than the thickness at the substep's start (one that came
        // over the triangle's edge into the layer, not through its face, or was pushed in by
        // another projection) is stopped at its floor C_start = min(0, C at the substep's
        // start), so contact gives it no speed, and then leaves the layer with where it
        // started (the module docs).
        let floor = constraint.evaluate(&start, self.thickness, &start).value;
        let floor = if floor.finite() { floor } else { V::Real::ZERO };
        let floor = if floor < V::Real::ZERO {
            floor
        } else {
            V::Real::ZERO
        };
        let w: [V::Real; N] = std::array::from_fn(|i| self.inverse_masses[ids[i] as usize]);
        let mut e = constraint.evaluate(&p, self.thickness, &p);
        e.value -= floor;
        if above(V::Real::ZERO, e.value) {
            self.stop_the_approach(c, e, ids, w, b, skipped);
        }
        if floor < V::Real::ZERO {
            self.leave_the_layer(constraint, ids, w);
        }
    }

    /// Projects pair `c` (`ids`, inverse masses `w`, the foot at barycentric `b`) to its floor
    /// from `e` (C less the floor, below 0), then applies friction to what that moved it apart.
    /// A skipped projection is counted in `skipped`.
    fn stop_the_approach<const N: usize>(
        &mut self,
        c: usize,
        e: crate::constraints::Evaluation<V, N>,
        ids: [u32; 4],
        w: [V::Real; N],
        b: [V::Real; 3],
        skipped: &mut SkipCounts,
    ) {
        let unbounded = V::Real::from_f64(f64::INFINITY);
        let normal = e.gradients[0];
        let Some(fix) = correction(e, w, self.lambdas[c], self.rule, unbounded) else {
            let none = e.degenerate || !(e.value.finite());
            skipped.degenerate += u64::from(none);
            return;
        };
        self.lambdas[c] += fix.delta_lambda[0];
        for (k, dx) in fix.delta_x.iter().enumerate() {
            self.positions[ids[k] as usize] += *dx;
        }
        let moved_apart =
            fix.delta_x[0] - weighted(b, [fix.delta_x[1], fix.delta_x[2], fix.delta_x[3]]);
        let length = normal.length();
        if !above(length, V::Real::ZERO) {
            return;
        }
        let n = normal / length;
        let pushed = moved_apart.dot(n);
        let w = [w[0], w[1], w[2], w[3]];
        self.friction(ids, w, b, n, pushed);
    }

    /// Moves the pair `ids`, already within the thickness at the substep's start and held there
    /// by its floor, out to C = 0, and where its particles were at the substep's start with
    /// them: a rigid projection (Δxᵢ = −wᵢ C ∇Cᵢ / Σ wⱼ |∇Cⱼ|²) that gives no velocity, since
    /// velocity is (x − x_start) / h. Skipped where C is not finite or ∇C vanishes.
    fn leave_the_layer<const N: usize, C: Constraint<N>>(
        &mut self,
        constraint: &C,
        ids: [u32; 4],
        w: [V::Real; N],
    ) {
        let p: [V; N] = std::array::from_fn(|i| self.positions[ids[i] as usize]);
        let e = constraint.evaluate(&p, self.thickness, &p);
        if e.degenerate || !e.value.finite() || !above(V::Real::ZERO, e.value) {
            return;
        }
        let mut weight = V::Real::ZERO;
        for (g, &wi) in e.gradients.iter().zip(&w) {
            weight += wi * g.dot(*g);
        }
        if !above(weight, V::Real::ZERO) || !weight.finite() {
            return;
        }
        let scale = -e.value / weight;
        for (k, (g, &wi)) in e.gradients.iter().zip(&w).enumerate() {
            let (i, dx) = (ids[k], *g * (scale * wi));
            self.positions[i as usize] += dx;
            self.previous[i as usize] += dx;
        }
    }

    /// Static or kinetic friction on the pair `ids` with inverse masses `w`, the foot at
    /// barycentric `b`, normal `n`, after a projection that pushed the particle `pushed` away.
    fn friction(&mut self, ids: [u32; 4], w: [V::Real; 4], b: [V::Real; 3], n: V, pushed: V::Real) {
        let [mu_static, mu_kinetic] = self.friction;
        let zero = V::Real::ZERO;
        if !above(pushed, zero) || !(above(mu_static, zero) || above(mu_kinetic, zero)) {
            return;
        }
        let motion = |i: usize| self.positions[ids[i] as usize] - self.previous[ids[i] as usize];
        let relative = motion(0) - weighted(b, [motion(1), motion(2), motion(3)]);
        let tangential = relative - n * relative.dot(n);
        let slide = tangential.length();
        if !above(slide, V::Real::ZERO) {
            return;
        }
        let undo = if slide < mu_static * pushed {
            tangential
        } else {
            let kept = mu_kinetic * pushed / slide;
            tangential
                * if kept < V::Real::ONE {
                    kept
                } else {
                    V::Real::ONE
                }
        };
        let total = w[0] + b[0] * b[0] * w[1] + b[1] * b[1] * w[2] + b[2] * b[2] * w[3];
        if !above(total, V::Real::ZERO) {
            return;
        }
        self.positions[ids[0] as usize] += undo * (-w[0] / total);
        for i in 0..3 {
            self.positions[ids[i + 1] as usize] += undo * (b[i] * w[i + 1] / total);
        }
    }
}

/// a > b, false where either is NaN.
fn above<R: PartialOrd>(a: R, b: R) -> bool {
    a > b
}

/// a ≥ b, false where either is NaN.
fn at_least<R: PartialOrd>(a: R, b: R) -> bool {
    a >= b
}

/// b₀ a + b₁ b + b₂ c.
fn weighted<V: Vector3>(b: [V::Real; 3], [a, bb, c]: [V; 3]) -> V {
    a * b[0] + bb * b[1] + c * b[2]
}

/// The barycentric coordinates of `x`'s foot on the triangle (a, b, c) when it falls inside it
/// (each ≥ 0); `None` when outside or the triangle has no area.
pub(crate) fn over_triangle<V: Vector3>(x: V, [a, b, c]: [V; 3]) -> Option<[V::Real; 3]>
where
    V::Real: Real<Mask = bool> + PartialOrd,
{
    let normal = (b - a).cross(c - a);
    let squared = normal.dot(normal);
    if !above(squared, V::Real::ZERO) {
        return None;
    }
    let part = |from: V, to: V| (to - from).cross(x - from).dot(normal) / squared;
    let coordinates = [part(b, c), part(c, a), part(a, b)];
    coordinates
        .iter()
        .all(|&u| u >= V::Real::ZERO)
        .then_some(coordinates)
}
