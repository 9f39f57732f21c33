//! K numbers of one [`Real`] type side by side as one ([`Block`]): every operation is the same
//! operation on each of the K, so a lane of a block computes exactly what it computes alone.
//!
//! The fast engine runs a constraint file's tape on a block of several batches of lanes at once
//! (`Block<F32x8, 4>`: 32 constraints of one colour), so that the tape's dispatch on each
//! instruction is paid once for the 32 rather than once for each 8
//! ([`crate::constraints::Constraint::evaluate_batches`]).

use crate::numbers::vector::{Mask, Real};
use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, Neg, Not, Sub, SubAssign};

/// K numbers, each computed on its own: `(a + b).0[k] == a.0[k] + b.0[k]`, and likewise for
/// every operation of [`Real`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Block<T, const K: usize>(pub [T; K]);

// Plain loops over the K numbers (not `array::map`, which the optimiser does not always see
// through): each operation compiles to K instructions of T.
impl<T: Copy, const K: usize> Block<T, K> {
    /// `f` of each number.
    #[inline(always)]
    fn map(mut self, f: impl Fn(T) -> T) -> Self {
        for x in &mut self.0 {
            *x = f(*x);
        }
        self
    }

    /// `f` of each pair of numbers.
    #[inline(always)]
    fn zip(mut self, other: Self, f: impl Fn(T, T) -> T) -> Self {
        for (x, y) in self.0.iter_mut().zip(other.0) {
            *x = f(*x, y);
        }
        self
    }

    /// `f` of each pair of numbers, into another type (a comparison's flags).
    #[inline(always)]
    fn zip_into<R: Copy>(self, other: Self, first: R, f: impl Fn(T, T) -> R) -> Block<R, K> {
        let mut out = [first; K];
        for (k, out) in out.iter_mut().enumerate() {
            *out = f(self.0[k], other.0[k]);
        }
        Block(out)
    }
}

macro_rules! each {
    ($trait:ident, $method:ident, $bound:ident) => {
        impl<T: Copy + $bound<Output = T>, const K: usize> $trait for Block<T, K> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                self.zip(rhs, $bound::$method)
            }
        }
    };
}
each!(Add, add, Add);
each!(Sub, sub, Sub);
each!(Mul, mul, Mul);
each!(Div, div, Div);
each!(BitAnd, bitand, BitAnd);
each!(BitOr, bitor, BitOr);

impl<T: Copy + Neg<Output = T>, const K: usize> Neg for Block<T, K> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self.map(Neg::neg)
    }
}

impl<T: Copy + Not<Output = T>, const K: usize> Not for Block<T, K> {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        self.map(Not::not)
    }
}

impl<T: Copy + AddAssign, const K: usize> AddAssign for Block<T, K> {
    #[inline(always)]
    fn add_assign(&mut self, rhs: Self) {
        for (a, b) in self.0.iter_mut().zip(rhs.0) {
            *a += b;
        }
    }
}

impl<T: Copy + SubAssign, const K: usize> SubAssign for Block<T, K> {
    #[inline(always)]
    fn sub_assign(&mut self, rhs: Self) {
        for (a, b) in self.0.iter_mut().zip(rhs.0) {
            *a -= b;
        }
    }
}

impl<M: Mask, const K: usize> Mask for Block<M, K> {
    #[inline(always)]
    fn any(self) -> bool {
        self.0.iter().any(|m| m.any())
    }

    #[inline(always)]
    fn count(self) -> u32 {
        self.0.iter().map(|m| m.count()).sum()
    }
}

impl<T: Real, const K: usize> Real for Block<T, K> {
    type Mask = Block<T::Mask, K>;
    const ZERO: Self = Block([T::ZERO; K]);
    const ONE: Self = Block([T::ONE; K]);
    const EPSILON: Self = Block([T::EPSILON; K]);
    const MIN_POSITIVE: Self = Block([T::MIN_POSITIVE; K]);
    #[inline(always)]
    fn from_f64(x: f64) -> Self {
        Block([T::from_f64(x); K])
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(T::sqrt)
    }
    #[inline(always)]
    fn finite(self) -> Self::Mask {
        let first = T::ZERO.finite();
        self.zip_into(self, first, |x, _| x.finite())
    }
    #[inline(always)]
    fn le(self, other: Self) -> Self::Mask {
        let first = T::ZERO.finite();
        self.zip_into(other, first, T::le)
    }
    #[inline(always)]
    fn gt(self, other: Self) -> Self::Mask {
        let first = T::ZERO.finite();
        self.zip_into(other, first, T::gt)
    }
    #[inline(always)]
    fn select(mask: Self::Mask, mut if_true: Self, if_false: Self) -> Self {
        for (k, x) in if_true.0.iter_mut().enumerate() {
            *x = T::select(mask.0[k], *x, if_false.0[k]);
        }
        if_true
    }
    #[inline(always)]
    fn sin(self) -> Self {
        self.map(T::sin)
    }
    #[inline(always)]
    fn cos(self) -> Self {
        self.map(T::cos)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        self.map(T::exp)
    }
    #[inline(always)]
    fn ln(self) -> Self {
        self.map(T::ln)
    }
    #[inline(always)]
    fn atan2(self, x: Self) -> Self {
        self.zip(x, T::atan2)
    }
    #[inline(always)]
    fn asin(self) -> Self {
        self.map(T::asin)
    }
    #[inline(always)]
    fn acos(self) -> Self {
        self.map(T::acos)
    }
    #[inline(always)]
    fn cbrt(self) -> Self {
        self.map(T::cbrt)
    }
}

#[cfg(test)]
mod examples {
    #[allow(unused_imports)]
    use super::*;

    /// The example of `block`'s documentation (a unit test: the item is not exported).
    #[test]
    fn block_example() {
        use crate::numbers::block::Block;
        use crate::numbers::vector::Real;
        let a = Block([0.25f32, 4.0, -1.0]);
        let b = Block([2.0f32, 0.5, 3.0]);
        // Each number of the block is what the operation gives on that number alone, to the bit.
        let r = (a * b + a.sqrt()).atan2(b);
        for k in 0..3 {
            assert_eq!(
                r.0[k].to_bits(),
                (a.0[k] * b.0[k] + a.0[k].sqrt()).atan2(b.0[k]).to_bits()
            );
        }
        // A comparison gives one flag per number, and select picks per number.
        assert_eq!(Block::select(a.gt(b), a, b).0, [2.0, 4.0, 3.0]);
    }
}
