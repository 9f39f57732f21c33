//! Eight f32 numbers (and 3-vectors) side by side, so that the generic constraint formulas run on
//! eight independent constraints at once: [`F32x8`] wraps `wide`'s eight-lane vector (one AVX
//! register where the build targets a CPU with AVX, two SSE registers otherwise), [`Vec3x8`] holds
//! eight x, eight y and eight z. A lane computes the same IEEE operations as the formula on one
//! f32, whatever the registers.

use crate::numbers::vector::{Mask, Real, Vector3};
use glam::Vec3A;
use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, Neg, Not, Sub, SubAssign};
use wide::{f32x4, f32x8};

/// How many lanes.
pub const LANES: usize = 8;

/// How this build holds the lanes (chosen by `wide` from the CPU features the build targets).
pub const REGISTERS: &str = if cfg!(target_feature = "avx") {
    "one 256-bit AVX register"
} else if cfg!(target_feature = "sse") {
    "two 128-bit SSE registers"
} else if cfg!(all(target_feature = "neon", target_arch = "aarch64")) {
    "two 128-bit NEON registers"
} else if cfg!(target_feature = "simd128") {
    "two 128-bit WebAssembly SIMD registers"
} else {
    "arrays (no SIMD instructions)"
};

/// A padded 3-vector's register as four lanes: x, y, z and the padding (whose value the kernels
/// ignore). Free where glam keeps `Vec3A` in an SSE register; elsewhere built from the
/// components, with a zero fourth lane.
#[inline(always)]
pub fn padded(v: Vec3A) -> f32x4 {
    #[cfg(target_feature = "sse2")]
    return bytemuck::cast(v);
    #[cfg(not(target_feature = "sse2"))]
    return f32x4::new([v.x, v.y, v.z, 0.0]);
}

/// The 3-vector of the first three lanes: the inverse of [`padded`].
#[inline(always)]
pub(crate) fn unpadded(lanes: f32x4) -> Vec3A {
    #[cfg(target_feature = "sse2")]
    return bytemuck::cast(lanes);
    #[cfg(not(target_feature = "sse2"))]
    return {
        let [x, y, z, _] = lanes.to_array();
        Vec3A::new(x, y, z)
    };
}

/// Eight f32, one per lane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct F32x8(pub f32x8);

/// One flag per lane (all-ones or all-zeros bits, so that selecting is bitwise).
#[derive(Clone, Copy, Debug)]
pub struct Mask8(f32x8);

impl F32x8 {
    /// The lanes as an array.
    #[inline]
    pub fn to_array(self) -> [f32; LANES] {
        self.0.to_array()
    }

    /// Lane k of the result is `values[k]`.
    #[inline]
    pub fn new(values: [f32; LANES]) -> Self {
        F32x8(f32x8::new(values))
    }
}

impl Mask8 {
    /// Whether lane k is set.
    #[inline]
    pub fn lane(self, k: usize) -> bool {
        self.0.to_bitmask() & (1 << k) != 0
    }
}

impl PartialEq for Mask8 {
    fn eq(&self, other: &Self) -> bool {
        self.0.to_bitmask() == other.0.to_bitmask()
    }
}

macro_rules! lane_op {
    ($trait:ident, $method:ident) => {
        impl $trait for F32x8 {
            type Output = F32x8;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                F32x8($trait::$method(self.0, rhs.0))
            }
        }
    };
}
lane_op!(Add, add);
lane_op!(Sub, sub);
lane_op!(Mul, mul);
lane_op!(Div, div);

impl Neg for F32x8 {
    type Output = F32x8;
    #[inline(always)]
    fn neg(self) -> Self {
        F32x8(-self.0)
    }
}

impl AddAssign for F32x8 {
    #[inline(always)]
    fn add_assign(&mut self, rhs: Self) {
        self.0 = self.0 + rhs.0;
    }
}

impl SubAssign for F32x8 {
    #[inline(always)]
    fn sub_assign(&mut self, rhs: Self) {
        self.0 = self.0 - rhs.0;
    }
}

impl BitAnd for Mask8 {
    type Output = Mask8;
    #[inline(always)]
    fn bitand(self, rhs: Self) -> Self {
        Mask8(self.0 & rhs.0)
    }
}

impl BitOr for Mask8 {
    type Output = Mask8;
    #[inline(always)]
    fn bitor(self, rhs: Self) -> Self {
        Mask8(self.0 | rhs.0)
    }
}

impl Not for Mask8 {
    type Output = Mask8;
    #[inline(always)]
    fn not(self) -> Self {
        Mask8(!self.0)
    }
}

impl Mask for Mask8 {
    #[inline(always)]
    fn any(self) -> bool {
        self.0.to_bitmask() != 0
    }

    #[inline(always)]
    fn count(self) -> u32 {
        self.0.to_bitmask().count_ones()
    }
}

impl Real for F32x8 {
    type Mask = Mask8;
    const ZERO: Self = F32x8(f32x8::ZERO);
    const ONE: Self = F32x8(f32x8::ONE);
    const EPSILON: Self = F32x8(f32x8::EPSILON);
    const MIN_POSITIVE: Self = F32x8(f32x8::MIN_POSITIVE);
    #[inline(always)]
    fn from_f64(x: f64) -> Self {
        F32x8(f32x8::splat(x as f32))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        F32x8(self.0.sqrt())
    }
    #[inline(always)]
    fn finite(self) -> Mask8 {
        Mask8(self.0.is_finite())
    }
    #[inline(always)]
    fn le(self, other: Self) -> Mask8 {
        Mask8(self.0.simd_le(other.0))
    }
    #[inline(always)]
    fn gt(self, other: Self) -> Mask8 {
        Mask8(self.0.simd_gt(other.0))
    }
    #[inline(always)]
    fn select(mask: Mask8, if_true: Self, if_false: Self) -> Self {
        F32x8(mask.0.bitselect(if_true.0, if_false.0))
    }
    // The functions below are `wide`'s, in the lanes: no lane is computed on its own.
    #[inline(always)]
    fn sin(self) -> Self {
        F32x8(self.0.sin_cos().0)
    }
    #[inline(always)]
    fn cos(self) -> Self {
        F32x8(self.0.sin_cos().1)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        F32x8(self.0.exp())
    }
    #[inline(always)]
    fn ln(self) -> Self {
        F32x8(self.0.ln())
    }
    #[inline(always)]
    fn atan2(self, x: Self) -> Self {
        F32x8(self.0.atan2(x.0))
    }
    #[inline(always)]
    fn asin(self) -> Self {
        F32x8(self.0.asin())
    }
    #[inline(always)]
    fn acos(self) -> Self {
        F32x8(self.0.acos())
    }
    #[inline(always)]
    fn cbrt(self) -> Self {
        F32x8(self.0.cbrt())
    }
}

/// Eight 3-vectors, one per lane, stored as the eight x, the eight y and the eight z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vec3x8 {
    /// The x components.
    pub x: F32x8,
    /// The y components.
    pub y: F32x8,
    /// The z components.
    pub z: F32x8,
}

impl Vec3x8 {
    /// Lane k of the result is `vectors[k]`.
    #[inline(always)]
    pub fn gather(v: [Vec3A; LANES]) -> Self {
        Self::from_rows(v.map(padded))
    }

    /// Lane k of the result is (x, y, z) of `rows[k]`, the register of a padded 3-vector (its
    /// fourth component ignored). With AVX: each two rows k and k + 4 side by side in one
    /// register, then one 4 × 4 transpose in both halves at once (11 shuffles); elsewhere two
    /// 4 × 4 transposes of `wide`. The same bits either way: only data moves.
    #[inline(always)]
    pub(crate) fn from_rows(rows: [f32x4; LANES]) -> Self {
        let [x, y, z] = transpose::from_rows(rows);
        Vec3x8 {
            x: F32x8(x),
            y: F32x8(y),
            z: F32x8(z),
        }
    }

    /// The lanes as registers of padded 3-vectors (fourth component zero): the inverse of
    /// `Vec3x8::from_rows`.
    #[inline(always)]
    pub fn rows(self) -> [f32x4; LANES] {
        transpose::rows([self.x.0, self.y.0, self.z.0])
    }

    /// Lane k as a 3-vector.
    #[inline]
    pub fn lane(self, k: usize) -> Vec3A {
        Vec3A::new(
            self.x.to_array()[k],
            self.y.to_array()[k],
            self.z.to_array()[k],
        )
    }
}

macro_rules! vector_op {
    ($trait:ident, $method:ident) => {
        impl $trait for Vec3x8 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, r: Self) -> Self {
                Vec3x8 {
                    x: $trait::$method(self.x, r.x),
                    y: $trait::$method(self.y, r.y),
                    z: $trait::$method(self.z, r.z),
                }
            }
        }
    };
}
vector_op!(Add, add);
vector_op!(Sub, sub);

impl Neg for Vec3x8 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Vec3x8 {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }
}

impl Mul<F32x8> for Vec3x8 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, s: F32x8) -> Self {
        Vec3x8 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
}

impl Div<F32x8> for Vec3x8 {
    type Output = Self;
    #[inline(always)]
    fn div(self, s: F32x8) -> Self {
        Vec3x8 {
            x: self.x / s,
            y: self.y / s,
            z: self.z / s,
        }
    }
}

impl AddAssign for Vec3x8 {
    #[inline(always)]
    fn add_assign(&mut self, r: Self) {
        *self = *self + r;
    }
}

impl SubAssign for Vec3x8 {
    #[inline(always)]
    fn sub_assign(&mut self, r: Self) {
        *self = *self - r;
    }
}

impl Vector3 for Vec3x8 {
    type Real = F32x8;
    const ZERO: Self = Vec3x8 {
        x: F32x8::ZERO,
        y: F32x8::ZERO,
        z: F32x8::ZERO,
    };
    #[inline(always)]
    fn dot(self, r: Self) -> F32x8 {
        self.x * r.x + self.y * r.y + self.z * r.z
    }
    #[inline(always)]
    fn cross(self, r: Self) -> Self {
        Vec3x8 {
            x: self.y * r.z - self.z * r.y,
            y: self.z * r.x - self.x * r.z,
            z: self.x * r.y - self.y * r.x,
        }
    }
    #[inline(always)]
    fn from_f64s(x: f64, y: f64, z: f64) -> Self {
        Vec3x8 {
            x: F32x8::from_f64(x),
            y: F32x8::from_f64(y),
            z: F32x8::from_f64(z),
        }
    }
    #[inline(always)]
    fn y(self) -> F32x8 {
        self.y
    }
    #[inline(always)]
    fn set_y(&mut self, y: F32x8) {
        self.y = y;
    }
    #[inline(always)]
    fn select(mask: Mask8, if_true: Self, if_false: Self) -> Self {
        Vec3x8 {
            x: F32x8::select(mask, if_true.x, if_false.x),
            y: F32x8::select(mask, if_true.y, if_false.y),
            z: F32x8::select(mask, if_true.z, if_false.z),
        }
    }
    #[inline(always)]
    fn to_array(self) -> [F32x8; 3] {
        [self.x, self.y, self.z]
    }
    #[inline(always)]
    fn from_array(a: [F32x8; 3]) -> Self {
        Vec3x8 {
            x: a[0],
            y: a[1],
            z: a[2],
        }
    }
}

/// The two transposes between eight padded 3-vectors and [`Vec3x8`]'s eight x, y and z: what the
/// fast engine does at each gather and each write-back of a batch.
mod transpose {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
    pub(super) use avx::{from_rows, rows};
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
    pub(super) use portable::{from_rows, rows};

    /// Two 4 × 4 transposes of `wide`, and the halves joined or split.
    #[cfg_attr(all(target_arch = "x86_64", target_feature = "avx"), allow(dead_code))]
    pub(super) mod portable {
        use super::super::LANES;
        use wide::{f32x4, f32x8};

        /// The x, y and z of the eight rows.
        #[inline(always)]
        pub(crate) fn from_rows(rows: [f32x4; LANES]) -> [f32x8; 3] {
            let [r0, r1, r2, r3, r4, r5, r6, r7] = rows;
            let [x0, y0, z0, _] = f32x4::transpose([r0, r1, r2, r3]);
            let [x1, y1, z1, _] = f32x4::transpose([r4, r5, r6, r7]);
            let join = |a: f32x4, b: f32x4| bytemuck::cast([a, b]);
            [join(x0, x1), join(y0, y1), join(z0, z1)]
        }

        /// Eight rows (x, y, z, 0) of `xyz`.
        #[inline(always)]
        pub(crate) fn rows(xyz: [f32x8; 3]) -> [f32x4; LANES] {
            let split = |a: f32x8| bytemuck::cast::<f32x8, [f32x4; 2]>(a);
            let [[x0, x1], [y0, y1], [z0, z1]] = xyz.map(split);
            let [a0, a1, a2, a3] = f32x4::transpose([x0, y0, z0, f32x4::ZERO]);
            let [b0, b1, b2, b3] = f32x4::transpose([x1, y1, z1, f32x4::ZERO]);
            [a0, a1, a2, a3, b0, b1, b2, b3]
        }
    }

    /// The same in AVX shuffles (`safe_arch`'s safe wrappers of the intrinsics), working on both
    /// 128-bit halves of a register at once: rows k and k + 4 share a register (the low half
    /// and the high half). 4 inserts, 4 unpacks and 3 shuffles to gather (19 shuffles and joins
    /// in `portable`); 4 unpacks, 4 shuffles and 4 extracts to write back (19 there).
    #[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
    mod avx {
        use super::super::LANES;
        use safe_arch::{
            cast_to_m128_from_m256, extract_m128_from_m256, m128, m256, set_m128_m256,
            shuffle_m256, unpack_hi_m256, unpack_lo_m256, zeroed_m256,
        };
        use wide::{f32x4, f32x8};

        /// Lanes 0, 1 of `a` and 0, 1 of `b`, in each half.
        const LOW_PAIRS: i32 = 0b01_00_01_00;
        /// Lanes 2, 3 of `a` and 2, 3 of `b`, in each half.
        const HIGH_PAIRS: i32 = 0b11_10_11_10;

        /// The x, y and z of the eight rows.
        #[inline(always)]
        pub(crate) fn from_rows(rows: [f32x4; LANES]) -> [f32x8; 3] {
            let r: [m128; LANES] = bytemuck::cast(rows);
            let (a0, a1) = (set_m128_m256(r[4], r[0]), set_m128_m256(r[5], r[1]));
            let (a2, a3) = (set_m128_m256(r[6], r[2]), set_m128_m256(r[7], r[3]));
            // x0 x1 y0 y1 | x4 x5 y4 y5 and z0 z1 . . | z4 z5 . ., the same of rows 2, 3, 6, 7.
            let (t0, t1) = (unpack_lo_m256(a0, a1), unpack_hi_m256(a0, a1));
            let (t2, t3) = (unpack_lo_m256(a2, a3), unpack_hi_m256(a2, a3));
            let x = shuffle_m256::<LOW_PAIRS>(t0, t2);
            let y = shuffle_m256::<HIGH_PAIRS>(t0, t2);
            let z = shuffle_m256::<LOW_PAIRS>(t1, t3);
            bytemuck::cast([x, y, z])
        }

        /// Eight rows (x, y, z, 0) of `xyz`.
        #[inline(always)]
        pub(crate) fn rows(xyz: [f32x8; 3]) -> [f32x4; LANES] {
            let [x, y, z]: [m256; 3] = bytemuck::cast(xyz);
            let zero = zeroed_m256();
            // x0 y0 x1 y1 | x4 y4 x5 y5, x2 y2 x3 y3 | x6 ..., z0 0 z1 0 | z4 ..., z2 0 z3 0 | ...
            let (t0, t1) = (unpack_lo_m256(x, y), unpack_hi_m256(x, y));
            let (t2, t3) = (unpack_lo_m256(z, zero), unpack_hi_m256(z, zero));
            let a = [
                shuffle_m256::<LOW_PAIRS>(t0, t2),
                shuffle_m256::<HIGH_PAIRS>(t0, t2),
                shuffle_m256::<LOW_PAIRS>(t1, t3),
                shuffle_m256::<HIGH_PAIRS>(t1, t3),
            ];
            let low = a.map(cast_to_m128_from_m256);
            let high = a.map(extract_m128_from_m256::<1>);
            bytemuck::cast([low, high])
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraints::{distance, height, volume};
    use crate::numbers::random::SplitMix64;

    /// Each lane of a formula on lanes is that formula on one f32 (up to the last bits of the
    /// sums, which glam and the lanes may order differently), degenerate lanes included.
    #[test]
    fn a_lane_computes_what_one_f32_computes() {
        let mut rng = SplitMix64::new(9);
        for _ in 0..200 {
            let mut points = [[Vec3A::ZERO; 4]; LANES];
            for tet in &mut points {
                for p in tet.iter_mut() {
                    *p = rng.in_cube(1.0).as_vec3a();
                }
            }
            // Lane 3 is degenerate: all four points on one line.
            points[3] = [Vec3A::ZERO, Vec3A::X, Vec3A::X * 2.0, Vec3A::X * 3.0];
            let lanes: [Vec3x8; 4] =
                std::array::from_fn(|i| Vec3x8::gather(std::array::from_fn(|k| points[k][i])));
            let rest = [0.1, -0.2, 0.3, 0.05, 0.2, -0.1, 0.0, 0.4];
            let r = F32x8::new(rest);
            let v = volume::evaluate(&lanes, r);
            let h = height::evaluate(&lanes, r);
            let d = distance::evaluate(&[lanes[0], lanes[1]], r);
            let close = |a: f32, b: f32| (a - b).abs() <= 1e-5 * (1.0 + a.abs().max(b.abs()));
            for k in 0..LANES {
                let one = points[k];
                let one_v = volume::evaluate(&one, rest[k]);
                let one_h = height::evaluate(&one, rest[k]);
                let one_d = distance::evaluate(&[one[0], one[1]], rest[k]);
                for (lanes, one) in [(&v, &one_v), (&h, &one_h)] {
                    assert!(close(lanes.value.to_array()[k], one.value));
                    assert_eq!(lanes.degenerate.lane(k), one.degenerate);
                    for (g, g1) in lanes.gradients.iter().zip(&one.gradients) {
                        assert!((g.lane(k) - *g1).length() < 1e-4 * (1.0 + g1.length()));
                    }
                }
                assert!(close(d.value.to_array()[k], one_d.value));
                assert!((d.gradients[0].lane(k) - one_d.gradients[0]).length() < 1e-5);
            }
            assert!(v.degenerate.lane(3));
            assert!(v.gradients.iter().all(|g| g.lane(3) == Vec3A::ZERO));
        }
    }

    /// The transposes the fast engine uses (AVX shuffles where the build has AVX) give `wide`'s
    /// portable transposes' bits, and writing back inverts gathering, with a zero fourth lane.
    #[test]
    fn the_transposes_move_every_lane_where_the_portable_ones_do() {
        let mut rng = SplitMix64::new(17);
        for _ in 0..100 {
            let rows: [f32x4; LANES] = std::array::from_fn(|_| {
                let p = rng.in_cube(10.0).as_vec3a();
                f32x4::new([p.x, p.y, p.z, rng.in_cube(1.0).x as f32])
            });
            let bits = |v: [f32x8; 3]| v.map(|v| v.to_array().map(f32::to_bits));
            assert_eq!(
                bits(transpose::from_rows(rows)),
                bits(transpose::portable::from_rows(rows))
            );
            let v = Vec3x8::from_rows(rows);
            let back = v.rows();
            for k in 0..LANES {
                let [x, y, z, _] = rows[k].to_array();
                assert_eq!(back[k].to_array(), [x, y, z, 0.0]);
                assert_eq!(v.lane(k), Vec3A::new(x, y, z));
            }
            let xyz = [v.x.0, v.y.0, v.z.0];
            assert_eq!(
                transpose::rows(xyz).map(|r| r.to_array().map(f32::to_bits)),
                transpose::portable::rows(xyz).map(|r| r.to_array().map(f32::to_bits))
            );
        }
    }
}
