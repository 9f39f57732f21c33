//! Four f32 numbers (and 3-vectors) side by side, so that the generic constraint formulas run on
//! four independent constraints at once: [`F32x4`] wraps `wide`'s SSE vector, [`Vec3x4`] holds
//! four x, four y and four z. A lane computes the same IEEE operations as the formula on one f32.

use crate::vector::{Mask, Real, Vector3};
use glam::Vec3A;
use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, Neg, Not, Sub, SubAssign};
use wide::f32x4;

/// How many lanes.
pub const LANES: usize = 4;

/// Four f32, one per lane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct F32x4(pub f32x4);

/// One flag per lane (all-ones or all-zeros bits, so that selecting is bitwise).
#[derive(Clone, Copy, Debug)]
pub struct Mask4(f32x4);

impl F32x4 {
    /// The lanes as an array.
    #[inline]
    pub fn to_array(self) -> [f32; LANES] {
        self.0.to_array()
    }

    /// Lane k of the result is `values[k]`.
    #[inline]
    pub fn new(values: [f32; LANES]) -> Self {
        F32x4(f32x4::new(values))
    }
}

impl Mask4 {
    /// Whether lane k is set.
    #[inline]
    pub fn lane(self, k: usize) -> bool {
        self.0.to_bitmask() & (1 << k) != 0
    }
}

impl PartialEq for Mask4 {
    fn eq(&self, other: &Self) -> bool {
        self.0.to_bitmask() == other.0.to_bitmask()
    }
}

macro_rules! lane_op {
    ($trait:ident, $method:ident) => {
        impl $trait for F32x4 {
            type Output = F32x4;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                F32x4($trait::$method(self.0, rhs.0))
            }
        }
    };
}
lane_op!(Add, add);
lane_op!(Sub, sub);
lane_op!(Mul, mul);
lane_op!(Div, div);

impl Neg for F32x4 {
    type Output = F32x4;
    #[inline(always)]
    fn neg(self) -> Self {
        F32x4(-self.0)
    }
}

impl AddAssign for F32x4 {
    #[inline(always)]
    fn add_assign(&mut self, rhs: Self) {
        self.0 = self.0 + rhs.0;
    }
}

impl SubAssign for F32x4 {
    #[inline(always)]
    fn sub_assign(&mut self, rhs: Self) {
        self.0 = self.0 - rhs.0;
    }
}

impl BitAnd for Mask4 {
    type Output = Mask4;
    #[inline(always)]
    fn bitand(self, rhs: Self) -> Self {
        Mask4(self.0 & rhs.0)
    }
}

impl BitOr for Mask4 {
    type Output = Mask4;
    #[inline(always)]
    fn bitor(self, rhs: Self) -> Self {
        Mask4(self.0 | rhs.0)
    }
}

impl Not for Mask4 {
    type Output = Mask4;
    #[inline(always)]
    fn not(self) -> Self {
        Mask4(!self.0)
    }
}

impl Mask for Mask4 {
    #[inline(always)]
    fn any(self) -> bool {
        self.0.to_bitmask() != 0
    }
}

impl Real for F32x4 {
    type Mask = Mask4;
    const ZERO: Self = F32x4(f32x4::ZERO);
    const ONE: Self = F32x4(f32x4::ONE);
    const EPSILON: Self = F32x4(f32x4::EPSILON);
    const MIN_POSITIVE: Self = F32x4(f32x4::MIN_POSITIVE);
    #[inline(always)]
    fn from_f64(x: f64) -> Self {
        F32x4(f32x4::splat(x as f32))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        F32x4(self.0.sqrt())
    }
    #[inline(always)]
    fn finite(self) -> Mask4 {
        Mask4(self.0.is_finite())
    }
    #[inline(always)]
    fn le(self, other: Self) -> Mask4 {
        Mask4(self.0.simd_le(other.0))
    }
    #[inline(always)]
    fn gt(self, other: Self) -> Mask4 {
        Mask4(self.0.simd_gt(other.0))
    }
    #[inline(always)]
    fn select(mask: Mask4, if_true: Self, if_false: Self) -> Self {
        F32x4(mask.0.bitselect(if_true.0, if_false.0))
    }
}

/// Four 3-vectors, one per lane, stored as the four x, the four y and the four z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vec3x4 {
    /// The x components.
    pub x: F32x4,
    /// The y components.
    pub y: F32x4,
    /// The z components.
    pub z: F32x4,
}

impl Vec3x4 {
    /// Lane k of the result is `vectors[k]`.
    #[inline(always)]
    pub fn gather(v: [Vec3A; LANES]) -> Self {
        Vec3x4 {
            x: F32x4::new([v[0].x, v[1].x, v[2].x, v[3].x]),
            y: F32x4::new([v[0].y, v[1].y, v[2].y, v[3].y]),
            z: F32x4::new([v[0].z, v[1].z, v[2].z, v[3].z]),
        }
    }

    /// The four lanes.
    #[inline(always)]
    pub fn scatter(self) -> [Vec3A; LANES] {
        let (x, y, z) = (self.x.to_array(), self.y.to_array(), self.z.to_array());
        std::array::from_fn(|k| Vec3A::new(x[k], y[k], z[k]))
    }
}

macro_rules! vector_op {
    ($trait:ident, $method:ident) => {
        impl $trait for Vec3x4 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, r: Self) -> Self {
                Vec3x4 {
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

impl Neg for Vec3x4 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Vec3x4 {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }
}

impl Mul<F32x4> for Vec3x4 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, s: F32x4) -> Self {
        Vec3x4 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
}

impl Div<F32x4> for Vec3x4 {
    type Output = Self;
    #[inline(always)]
    fn div(self, s: F32x4) -> Self {
        Vec3x4 {
            x: self.x / s,
            y: self.y / s,
            z: self.z / s,
        }
    }
}

impl AddAssign for Vec3x4 {
    #[inline(always)]
    fn add_assign(&mut self, r: Self) {
        *self = *self + r;
    }
}

impl SubAssign for Vec3x4 {
    #[inline(always)]
    fn sub_assign(&mut self, r: Self) {
        *self = *self - r;
    }
}

impl Vector3 for Vec3x4 {
    type Real = F32x4;
    const ZERO: Self = Vec3x4 {
        x: F32x4::ZERO,
        y: F32x4::ZERO,
        z: F32x4::ZERO,
    };
    #[inline(always)]
    fn dot(self, r: Self) -> F32x4 {
        self.x * r.x + self.y * r.y + self.z * r.z
    }
    #[inline(always)]
    fn cross(self, r: Self) -> Self {
        Vec3x4 {
            x: self.y * r.z - self.z * r.y,
            y: self.z * r.x - self.x * r.z,
            z: self.x * r.y - self.y * r.x,
        }
    }
    #[inline(always)]
    fn from_f64s(x: f64, y: f64, z: f64) -> Self {
        Vec3x4 {
            x: F32x4::from_f64(x),
            y: F32x4::from_f64(y),
            z: F32x4::from_f64(z),
        }
    }
    #[inline(always)]
    fn y(self) -> F32x4 {
        self.y
    }
    #[inline(always)]
    fn set_y(&mut self, y: F32x4) {
        self.y = y;
    }
    #[inline(always)]
    fn select(mask: Mask4, if_true: Self, if_false: Self) -> Self {
        Vec3x4 {
            x: F32x4::select(mask, if_true.x, if_false.x),
            y: F32x4::select(mask, if_true.y, if_false.y),
            z: F32x4::select(mask, if_true.z, if_false.z),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraints::{distance, plane, volume};
    use crate::random::SplitMix64;

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
            let lanes: [Vec3x4; 4] =
                std::array::from_fn(|i| Vec3x4::gather(std::array::from_fn(|k| points[k][i])));
            let rest = [0.1, -0.2, 0.3, 0.05];
            let r = F32x4::new(rest);
            let v = volume::evaluate(&lanes, r);
            let h = plane::evaluate(&lanes, r);
            let d = distance::evaluate(&[lanes[0], lanes[1]], r);
            let close = |a: f32, b: f32| (a - b).abs() <= 1e-5 * (1.0 + a.abs().max(b.abs()));
            for k in 0..LANES {
                let one = points[k];
                let one_v = volume::evaluate(&one, rest[k]);
                let one_h = plane::evaluate(&one, rest[k]);
                let one_d = distance::evaluate(&[one[0], one[1]], rest[k]);
                for (lanes, one) in [(&v, &one_v), (&h, &one_h)] {
                    assert!(close(lanes.value.to_array()[k], one.value));
                    assert_eq!(lanes.degenerate.lane(k), one.degenerate);
                    for (g, g1) in lanes.gradients.iter().zip(&one.gradients) {
                        assert!((g.scatter()[k] - *g1).length() < 1e-4 * (1.0 + g1.length()));
                    }
                }
                assert!(close(d.value.to_array()[k], one_d.value));
                assert!((d.gradients[0].scatter()[k] - one_d.gradients[0]).length() < 1e-5);
            }
            assert!(v.degenerate.lane(3));
            assert!(v.gradients.iter().all(|g| g.scatter()[3] == Vec3A::ZERO));
        }
    }
}
