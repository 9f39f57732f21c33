//! The broad phase: which (particle, triangle) pairs may meet within a frame, found once a frame
//! with a spatial hash ([`ContactFinder::find`]).
//!
//! Every surface particle is entered in its cell of a uniform grid (the cell hashed to 64 bits,
//! one entry per particle, kept sorted in one flat array); every surface triangle's bounding
//! box, grown by a margin m, looks in the cells it overlaps. A pair is kept when the particle may touch the
//! triangle ([`super::ContactSurface::may_touch`]), lies within m of the triangle's plane on its
//! outer side or at most one thickness d under it (−d ≤ h ≤ m), and its foot on the plane lies
//! within m of the triangle. The margin covers the largest motion of the frame:
//! m = d + 2 v_max Δt + g Δt², v_max the fastest surface particle's speed at the frame's start,
//! since the particle and the triangle may close on each other at that speed each, and gravity
//! adds g Δt² at most to what they close by. A particle that would cross a triangle within the
//! frame is therefore paired with it at the frame's start, and is stopped by its contact in the
//! substep where it would cross: a fast body does not tunnel.
//!
//! A uniform grid rather than a bounding-volume hierarchy: the bodies are of one scale (a
//! triangle's size varies little across a tet mesh), the grid is rebuilt in one sort a frame
//! and holds exactly one entry per surface particle, so it never grows after the first frame
//! (the pairs found keep room for twice the most yet: [`super::keep_room`]); a hierarchy would have to be refitted or
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
    /// The margin of the last search, m.
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
        let fastest = surface
            .particles
            .iter()
            .map(|&i| velocities.get(i as usize).map_or(0.0, |v| v.length()))
            .filter(|v| v.is_finite())
            .fold(0.0f64, f64::max);
        let margin =
            reach.thickness + 2.0 * fastest * reach.dt + reach.gravity.abs() * reach.dt * reach.dt;
        self.margin = margin;
        if surface.triangles.is_empty() || !margin.is_finite() {
            return &self.found;
        }
        let bounds = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            (
                a.min(b).min(c) - DVec3::splat(margin),
                a.max(b).max(c) + DVec3::splat(margin),
            )
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
        super::keep_room(&mut self.found, len);
        self.found.sort_unstable();
        self.found.dedup();
        &self.found
    }

    /// The pairs of the last search.
    pub fn found(&self) -> &[[u32; 4]] {
        &self.found
    }

    /// The margin of the last search, m.
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
