//! The small vector vocabulary the constraint formulas are written in.
//!
//! Every formula in [`crate::constraints`] is generic over [`Vector3`], so one implementation
//! serves the f64 path used for checking and teaching ([`glam::DVec3`]), the f32 path of the fast
//! solver ([`glam::Vec3`], [`glam::Vec3A`]) and its SIMD path, eight constraints at once
//! ([`crate::numbers::lanes::Vec3x8`]). The formulas never branch on a value: a comparison gives a
//! [`Mask`] (a `bool` for one number, one flag per lane for eight), and [`Real::select`] picks.

use crate::numbers::columns::Columns;
use crate::numbers::svd3::{self, Svd};
use std::fmt::Debug;
use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, Neg, Not, Sub, SubAssign};

/// The result of a comparison: `bool`, or one flag per lane.
pub trait Mask:
    Copy + Debug + PartialEq + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self>
{
    /// Whether any flag is set.
    fn any(self) -> bool;

    /// How many flags are set.
    fn count(self) -> u32;

    /// `self & other()`, calling `other` only when some flag of `self` is set (for a rare
    /// condition, most calls then skip the work).
    #[inline(always)]
    fn and_then(self, other: impl FnOnce() -> Self) -> Self {
        if self.any() { self & other() } else { self }
    }
}

impl Mask for bool {
    #[inline(always)]
    fn any(self) -> bool {
        self
    }

    #[inline(always)]
    fn count(self) -> u32 {
        u32::from(self)
    }
}

/// A floating-point number, or several in lanes: `f32`, `f64`, [`crate::numbers::lanes::F32x8`].
pub trait Real:
    Copy
    + Debug
    + PartialEq
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
{
    /// What comparing two of these gives.
    type Mask: Mask;
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// Machine epsilon: the gap between 1 and the next representable number.
    const EPSILON: Self;
    /// The smallest positive normal number.
    const MIN_POSITIVE: Self;
    /// The nearest value of this type to `x` (in every lane).
    fn from_f64(x: f64) -> Self;
    /// √self.
    fn sqrt(self) -> Self;
    /// Neither infinite nor NaN.
    fn finite(self) -> Self::Mask;
    /// self ≤ other (false with a NaN).
    fn le(self, other: Self) -> Self::Mask;
    /// self > other (false with a NaN).
    fn gt(self, other: Self) -> Self::Mask;
    /// `if_true` where `mask` is set, `if_false` elsewhere.
    fn select(mask: Self::Mask, if_true: Self, if_false: Self) -> Self;
    /// sin self (radians).
    fn sin(self) -> Self;
    /// cos self (radians).
    fn cos(self) -> Self;
    /// eˢᵉˡᶠ.
    fn exp(self) -> Self;
    /// The natural logarithm (NaN below 0, −∞ at 0).
    fn ln(self) -> Self;
    /// The angle of (x, y) = (`x`, self) from the x axis, in −π…π.
    fn atan2(self, x: Self) -> Self;
    /// arcsin self, in −π/2…π/2 (NaN outside −1…1).
    fn asin(self) -> Self;
    /// arccos self, in 0…π (NaN outside −1…1).
    fn acos(self) -> Self;
    /// The real cube root.
    fn cbrt(self) -> Self;
    /// The number exactly as it was rounded, kept from a compiler's algebra: itself, on the
    /// CPU. A shader compiler may rewrite (x + s) − x as s (WGSL has no `precise`), which
    /// turns a compensated sum's residual into 0; a traced number passes through this opaque
    /// to it ([`crate::numbers::traced`]). Where a sum's rounding is the point, each rounded
    /// value goes through this.
    #[inline(always)]
    fn rounded(self) -> Self {
        self
    }
    /// The number with nothing of a derivative: a dual number's slopes dropped (at every level),
    /// the number itself otherwise. What holds a value fixed while others are differentiated.
    #[inline]
    fn constant(self) -> Self {
        self
    }
    /// The signed singular value decomposition of the matrix of columns `f`: F = U diag(σ) Vᵀ
    /// with U and V rotations and σ₂ negative where det F is ([`svd3`]). Dual numbers give its
    /// exact derivative rather than the iteration's.
    #[inline]
    fn signed_svd(f: Columns<Self>) -> Svd<Self> {
        svd3::jacobi_svd(f)
    }
    /// The rotation R of the polar decomposition F = R S of the matrix of columns `f`: the
    /// rotation nearest F, U Vᵀ of [`Real::signed_svd`] ([`svd3`]). Dual numbers give its exact
    /// derivative, finite also where singular values repeat.
    #[inline]
    fn polar(f: Columns<Self>) -> Columns<Self> {
        svd3::rotation(&Self::signed_svd(f))
    }
}

macro_rules! impl_real {
    ($t:ty) => {
        impl Real for $t {
            type Mask = bool;
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
            const EPSILON: Self = <$t>::EPSILON;
            const MIN_POSITIVE: Self = <$t>::MIN_POSITIVE;
            #[inline]
            fn from_f64(x: f64) -> Self {
                x as $t
            }
            #[inline]
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }
            #[inline]
            fn finite(self) -> bool {
                <$t>::is_finite(self)
            }
            #[inline]
            fn le(self, other: Self) -> bool {
                self <= other
            }
            #[inline]
            fn gt(self, other: Self) -> bool {
                self > other
            }
            #[inline]
            fn select(mask: bool, if_true: Self, if_false: Self) -> Self {
                if mask { if_true } else { if_false }
            }
            #[inline]
            fn sin(self) -> Self {
                <$t>::sin(self)
            }
            #[inline]
            fn cos(self) -> Self {
                <$t>::cos(self)
            }
            #[inline]
            fn exp(self) -> Self {
                <$t>::exp(self)
            }
            #[inline]
            fn ln(self) -> Self {
                <$t>::ln(self)
            }
            #[inline]
            fn atan2(self, x: Self) -> Self {
                <$t>::atan2(self, x)
            }
            #[inline]
            fn asin(self) -> Self {
                <$t>::asin(self)
            }
            #[inline]
            fn acos(self) -> Self {
                <$t>::acos(self)
            }
            #[inline]
            fn cbrt(self) -> Self {
                <$t>::cbrt(self)
            }
        }
    };
}
impl_real!(f32);
impl_real!(f64);

/// A 3-vector with the operations the constraint formulas use.
pub trait Vector3:
    Copy
    + Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Neg<Output = Self>
    + Mul<<Self as Vector3>::Real, Output = Self>
    + Div<<Self as Vector3>::Real, Output = Self>
    + AddAssign
    + SubAssign
{
    /// The scalar type of the components.
    type Real: Real;
    /// The zero vector.
    const ZERO: Self;
    /// a·b.
    fn dot(self, rhs: Self) -> Self::Real;
    /// a×b.
    fn cross(self, rhs: Self) -> Self;
    /// |a|² = a·a.
    #[inline]
    fn length_squared(self) -> Self::Real {
        self.dot(self)
    }
    /// |a|.
    #[inline]
    fn length(self) -> Self::Real {
        self.length_squared().sqrt()
    }
    /// The vector built from f64 components (rounded to the component type).
    fn from_f64s(x: f64, y: f64, z: f64) -> Self;
    /// The y (up) component.
    fn y(self) -> Self::Real;
    /// Sets the y (up) component.
    fn set_y(&mut self, y: Self::Real);
    /// `if_true` where `mask` is set, `if_false` elsewhere.
    fn select(mask: <Self::Real as Real>::Mask, if_true: Self, if_false: Self) -> Self;
    /// The components x, y, z.
    fn to_array(self) -> [Self::Real; 3];
    /// The vector of components x, y, z.
    fn from_array(a: [Self::Real; 3]) -> Self;
}

macro_rules! impl_vector3 {
    ($v:ty, $t:ty) => {
        impl Vector3 for $v {
            type Real = $t;
            const ZERO: Self = <$v>::ZERO;
            #[inline]
            fn dot(self, rhs: Self) -> $t {
                <$v>::dot(self, rhs)
            }
            #[inline]
            fn cross(self, rhs: Self) -> Self {
                <$v>::cross(self, rhs)
            }
            #[inline]
            fn from_f64s(x: f64, y: f64, z: f64) -> Self {
                <$v>::new(x as $t, y as $t, z as $t)
            }
            #[inline]
            fn y(self) -> $t {
                self.y
            }
            #[inline]
            fn select(mask: bool, if_true: Self, if_false: Self) -> Self {
                if mask { if_true } else { if_false }
            }
            #[inline]
            fn set_y(&mut self, y: $t) {
                self.y = y;
            }
            #[inline]
            fn to_array(self) -> [$t; 3] {
                [self.x, self.y, self.z]
            }
            #[inline]
            fn from_array(a: [$t; 3]) -> Self {
                <$v>::new(a[0], a[1], a[2])
            }
        }
    };
}
impl_vector3!(glam::Vec3, f32);
impl_vector3!(glam::Vec3A, f32);
impl_vector3!(glam::DVec3, f64);

/// `v` with each component [`Real::rounded`]: itself, on the CPU.
#[inline(always)]
pub(crate) fn rounded<V: Vector3>(v: V) -> V {
    V::from_array(v.to_array().map(Real::rounded))
}

/// Whether `a` and `b` span no plane at working precision: |a×b| ≤ ε·|a|·|b|, compared squared
/// (no square roots; the squares overflow only for coordinates beyond about 10¹⁹ in f32).
///
/// Set when either vector is zero or the sine of the angle between them is below machine
/// epsilon; the normal `a×b/|a×b|` is then meaningless.
#[inline]
pub(crate) fn spans_no_plane<V: Vector3>(a: V, b: V, a_cross_b: V) -> <V::Real as Real>::Mask {
    let lhs = a_cross_b.length_squared();
    let epsilon = V::Real::EPSILON;
    let rhs = epsilon * epsilon * a.length_squared() * b.length_squared();
    // Anything but "greater" (also NaN from overflowing inputs) means no plane.
    !lhs.gt(rhs)
}
