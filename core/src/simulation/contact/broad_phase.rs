//! The broad phase: which (particle, triangle) pairs may meet within a frame, found once a frame
//! with a spatial hash ([`ContactFinder::find`]).
//!
//! Every surface particle is entered in its cell of a uniform grid (the cell hashed to 64 bits,
//! one entry per particle, kept sorted in one flat array); every surface triangle's bounding
//! box, grown by a margin m, looks in the cells it overlaps. A pair is kept when the particle may touch the
//! triangle ([`super::ContactSurface::may_touch`]), lies within m of the triangle's plane on its
//! outer side or at most one thickness d under it (−d ≤ h ≤ m), and its foot on the plane lies
//! within m of the triangle. The margin is the pair's own and covers the most the two can close
//! on each other within the frame: m = d + (v_p + v_t) Δt + g Δt², v_p the particle's speed and
//! v_t the fastest of the triangle's corners at the frame's start, and gravity adds g Δt² at
//! most to what they close by. A particle that would cross a triangle within the frame is
//! therefore paired with it at the frame's start, and is stopped by its contact in the substep
//! where it would cross: a fast body does not tunnel. A triangle looks in the cells its box
//! covers grown by the most any pair of it may need, d + (v_t + v_max) Δt + g Δt², v_max the
//! fastest surface particle; each pair then keeps to its own margin, so that one fast particle
//! grows the search but not the pairs of every slow triangle.
//!
//! A uniform grid rather than a bounding-volume hierarchy: the bodies are of one scale (a
//! triangle's size varies little across a tet mesh), the grid is rebuilt in one sort a frame
//! and holds exactly one entry per surface particle, so it never grows after the first frame
//! (the pairs found keep room for twice the most yet, and at least twice the surface's particles:
//! [`super::keep_room`]); a hierarchy would have to be refitted or
//! rebuilt every frame too (docs/performance.md has the measured cost).

use super::ContactSurface;
use glam::DVec3;

/// The scratch arrays of the broad phase, kept between frames so that finding allocates nothing
/// once they have grown, and the pairs found.
#[derive(Clone, Debug, Default)]
pub struct ContactFinder {
    /// (cell hash, surface particle), sorted: one entry per surface particle.
    cells: Vec<(u64, u32)>,
    /// The pairs found: [particle, triangle's three corners], sorted.
    found: Vec<[u32; 4]>,
    /// The largest margin a pair of the last search could have: d + 2 v_max Δt + g Δt².
    margin: f64,
}

/// What the margin of a frame depends on.
#[derive(Clone, Copy, Debug)]
pub struct Reach {
    /// The thickness d.
    pub thickness: f64,
    /// The frame's length Δt.
    pub dt: f64,
    /// Gravity's magnitude.
    pub gravity: f64,
}

impl ContactFinder {
    /// The pairs of `surface` at `positions` that may meet within a frame, with the particles'
    /// `velocities`: each `[particle, a, b, c]`, (a, b, c) the triangle wound outwards, sorted.
    pub fn find(
        &mut self,
        surface: &ContactSurface,
        positions: &[DVec3],
        velocities: &[DVec3],
        reach: Reach,
    ) -> &[[u32; 4]] {
        self.cells.clear();
        self.found.clear();
        let speed = |i: u32| {
            let v = velocities.get(i as usize).map_or(0.0, |v| v.length());
            if v.is_finite() { v } else { 0.0 }
        };
        let fastest = surface
            .particles
            .iter()
            .map(|&i| speed(i))
            .fold(0.0f64, f64::max);
        // m for a pair closing at `closing` m/s.
        let margin = |closing: f64| {
            reach.thickness + closing * reach.dt + reach.gravity.abs() * reach.dt * reach.dt
        };
        let largest_margin = margin(2.0 * fastest);
        self.margin = largest_margin;
        if surface.triangles.is_empty() || !largest_margin.is_finite() {
            return &self.found;
        }
        let triangle_speed = |t: &[u32; 3]| t.iter().map(|&i| speed(i)).fold(0.0f64, f64::max);
        let bounds = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            let grown = DVec3::splat(margin(triangle_speed(t) + fastest));
            (a.min(b).min(c) - grown, a.max(b).max(c) + grown)
        };
        // The cell: the mean grown box's largest side, so that a triangle covers a few cells,
        // and at least an eighth of the largest, so that none covers more than 9 a side (a
        // body stretched apart).
        let (mut sum, mut largest) = (0.0, 0.0f64);
        for t in &surface.triangles {
            let (low, high) = bounds(t);
            let side = (high - low).max_element();
            sum += side;
            largest = largest.max(side);
        }
        let cell = (sum / surface.triangles.len() as f64).max(largest / 8.0);
        if !(cell.is_finite() && cell > 0.0) {
            return &self.found;
        }
        let index = |p: DVec3| (p / cell).floor();
        let key = |[x, y, z]: [f64; 3]| hash([x as i64, y as i64, z as i64]);
        // Each surface particle in its one cell: as many entries as surface particles, every
        // frame, so the array never grows after the first.
        self.cells.reserve_exact(surface.particles.len());
        for &particle in &surface.particles {
            let at = index(positions[particle as usize]);
            self.cells.push((key(at.to_array()), particle));
        }
        self.cells.sort_unstable();
        // Each triangle looks in the cells its grown box covers.
        for triangle in &surface.triangles {
            let (low, high) = bounds(triangle);
            let (low, high) = (index(low), index(high));
            let span = high - low;
            let corners = triangle.map(|i| positions[i as usize]);
            let triangle_speed = triangle_speed(triangle);
            for x in 0..=span.x as i64 {
                for y in 0..=span.y as i64 {
                    for z in 0..=span.z as i64 {
                        let at = low + DVec3::new(x as f64, y as f64, z as f64);
                        let cell = key(at.to_array());
                        let start = self.cells.partition_point(|&(h, _)| h < cell);
                        for &(h, particle) in &self.cells[start..] {
                            if h != cell {
                                break;
                            }
                            if !surface.may_touch(particle, *triangle) {
                                continue;
                            }
                            let x = positions[particle as usize];
                            let margin = margin(speed(particle) + triangle_speed);
                            if near(x, corners, margin, reach.thickness) {
                                let [a, b, c] = *triangle;
                                self.found.push([particle, a, b, c]);
                            }
                        }
                    }
                }
            }
        }
        let len = self.found.len();
        super::keep_room(&mut self.found, len.max(surface.particles.len()));
        self.found.sort_unstable();
        self.found.dedup();
        &self.found
    }

    /// The pairs of the last search.
    pub fn found(&self) -> &[[u32; 4]] {
        &self.found
    }

    /// The largest margin a pair of the last search could have: d + 2 v_max Δt + g Δt².
    pub fn margin(&self) -> f64 {
        self.margin
    }
}

/// Whether `x` is within `margin` of the plane of `corners` (a, b, c) on its outer side, or at
/// most `thickness` under it, with its foot within `margin` of the triangle.
fn near(x: DVec3, [a, b, c]: [DVec3; 3], margin: f64, thickness: f64) -> bool {
    let normal = (b - a).cross(c - a);
    let twice_area = normal.length();
    if !(twice_area > 0.0 && twice_area.is_finite()) {
        return false;
    }
    let n = normal / twice_area;
    let height = (x - a).dot(n);
    if !(-thickness..=margin).contains(&height) {
        return false;
    }
    // The foot's distance outside each edge: twice the signed area of (edge, foot) over the
    // edge's length.
    let foot = x - n * height;
    [(a, b), (b, c), (c, a)].into_iter().all(|(from, to)| {
        let edge = to - from;
        edge.cross(foot - from).dot(n) >= -margin * edge.length()
    })
}

/// A cell's 64-bit hash (two cells that share one only make extra pairs to test).
fn hash([x, y, z]: [i64; 3]) -> u64 {
    let mut h = (x as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    h ^= (y as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
    h = h.rotate_left(31);
    h ^= (z as u64).wrapping_mul(0x1656_67B1_9E37_79F9);
    h ^ (h >> 29)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three tets: A on the ground, B 0.5 m above A's apex, C 100 m away.
    fn scene(velocity_of_b: DVec3, velocity_of_c: DVec3) -> Vec<[u32; 4]> {
        let tets = [[0, 1, 2, 3], [4, 5, 6, 7], [8, 9, 10, 11]];
        let surface = ContactSurface::of(&tets, 12);
        let shape = [DVec3::ZERO, DVec3::X, DVec3::Z, DVec3::new(0.3, 1.0, 0.3)];
        let at = |offset: DVec3| shape.map(|p| p + offset);
        let positions: Vec<DVec3> =
            [at(DVec3::ZERO), at(1.5 * DVec3::Y), at(100.0 * DVec3::X)].concat();
        let velocities: Vec<DVec3> =
            [[DVec3::ZERO; 4], [velocity_of_b; 4], [velocity_of_c; 4]].concat();
        let reach = Reach {
            thickness: 0.01,
            dt: 1.0 / 60.0,
            gravity: 9.81,
        };
        let mut finder = ContactFinder::default();
        finder
            .find(&surface, &positions, &velocities, reach)
            .to_vec()
    }

    /// A body that will close a 0.5 m gap within the frame (40 m/s for 1/60 s) is paired with
    /// what it will reach; a body at rest is not, even while another body far away moves fast:
    /// each pair keeps to its own margin.
    #[test]
    fn each_pair_has_the_margin_of_its_own_motion() {
        let falling = scene(-40.0 * DVec3::Y, DVec3::ZERO);
        let b = 4..8;
        assert!(
            (falling.iter()).any(|p| p[0] == 3 && p[1..].iter().all(|i| b.contains(i))),
            "A's apex is paired with B's underside: {falling:?}"
        );
        assert_eq!(scene(DVec3::ZERO, DVec3::ZERO), Vec::<[u32; 4]>::new());
        let far_and_fast = scene(DVec3::ZERO, 100.0 * DVec3::Z);
        assert_eq!(
            far_and_fast,
            Vec::<[u32; 4]>::new(),
            "B at rest, C fast and far"
        );
    }
}
