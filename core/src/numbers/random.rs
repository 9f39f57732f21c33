//! A small seeded random-number generator, so that every random input of tetlab (scrambles,
//! test configurations) is the same on every machine and every release.

use glam::DVec3;

/// SplitMix64 (Steele, Lea, Flood 2014): a 64-bit state advanced by a fixed odd constant and
/// scrambled by two multiply-xorshift rounds. Passes BigCrush; fixed output for a fixed seed.
#[derive(Clone, Debug)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator whose output is determined by `seed`.
    pub fn new(seed: u64) -> Self {
        Self { state: seed }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A uniform number in [0, 1) with 53 random bits.
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A uniform number in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }

    /// A point uniform in the cube [−r, r]³.
    pub fn in_cube(&mut self, r: f64) -> DVec3 {
        DVec3::new(self.range(-r, r), self.range(-r, r), self.range(-r, r))
    }

    /// A rotation drawn uniformly from SO(3) (Shoemake's method on a uniform unit quaternion).
    pub fn rotation(&mut self) -> glam::DQuat {
        let (u1, u2, u3) = (self.next_f64(), self.next_f64(), self.next_f64());
        let tau = std::f64::consts::TAU;
        let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
        glam::DQuat::from_xyzw(
            a * (tau * u2).sin(),
            a * (tau * u2).cos(),
            b * (tau * u3).sin(),
            b * (tau * u3).cos(),
        )
        .normalize()
    }
}

/// A permutation of 0..n drawn by Fisher–Yates from `seed` (with [`SplitMix64`]): the same
/// permutation for the same seed on every machine. The order seeds of the solvers use it
/// ([`crate::simulation::Settings::order_seed`]).
pub(crate) fn permutation(n: usize, seed: u64) -> Vec<u32> {
    let mut order: Vec<u32> = (0..n as u32).collect();
    let mut random = SplitMix64::new(seed);
    for i in (1..n).rev() {
        // Lemire's multiply-shift: a uniform index in 0..=i without a division.
        let j = ((u128::from(random.next_u64()) * (i as u128 + 1)) >> 64) as usize;
        order.swap(i, j);
    }
    order
}

#[cfg(test)]
mod examples {
    #[allow(unused_imports)]
    use super::*;

    /// The example of `permutation`'s documentation (a unit test: the item is not exported).
    #[test]
    fn permutation_example() {
        use crate::numbers::random::permutation;
        let p = permutation(10, 7);
        let mut sorted = p.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..10).collect::<Vec<u32>>(), "every index once");
        assert_eq!(p, permutation(10, 7), "the same seed, the same order");
        assert_ne!(p, permutation(10, 8));
    }
}
