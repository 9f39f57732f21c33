//! Forward-mode automatic differentiation for the constraint code: [`Tangent`], a dual number
//! a + a′ε (ε² = 0) over any [`Real`], and [`DualVec3`], a 3-vector of them, as a [`Vector3`].
//! Any formula written over those traits (the built-in families, a constraint file's compiled
//! program) then gives, beside its value, its derivative along one direction of the inputs: seed
//! one coordinate's slope with 1 and read ∂C/∂x from the value's slope. A dual number of dual
//! numbers, seeded along two directions, gives a second derivative.

use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub, SubAssign};

use crate::numbers::columns::Columns;
use crate::numbers::svd3::{self, Svd};
use crate::numbers::vector::{Real, Vector3};

/// A dual number over any [`Real`] (f64, f32, the fast solver's lanes): `value + slope ε` with
/// ε² = 0. Its own type rather than num-dual's, whose dual numbers need a scalar primitive and so
/// cannot carry the eight lanes of the fast solver.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tangent<T> {
    /// The value.
    pub value: T,
    /// Its derivative along the seeded direction.
    pub slope: T,
}

impl<T: Real> Tangent<T> {
    /// `value` with slope 0 (a constant) or 1 (the variable differentiated by).
    pub fn new(value: T, slope: T) -> Self {
        Tangent { value, slope }
    }
}

impl<T: Real> Add for Tangent<T> {
    type Output = Self;
    #[inline]
    fn add(self, b: Self) -> Self {
        Tangent::new(self.value + b.value, self.slope + b.slope)
    }
}
impl<T: Real> Sub for Tangent<T> {
    type Output = Self;
    #[inline]
    fn sub(self, b: Self) -> Self {
        Tangent::new(self.value - b.value, self.slope - b.slope)
    }
}
impl<T: Real> Mul for Tangent<T> {
    type Output = Self;
    /// (a + a′ε)(b + b′ε) = ab + (a′b + ab′)ε.
    #[inline]
    fn mul(self, b: Self) -> Self {
        Tangent::new(
            self.value * b.value,
            self.slope * b.value + self.value * b.slope,
        )
    }
}
impl<T: Real> Div for Tangent<T> {
    type Output = Self;
    /// (a + a′ε) / (b + b′ε) = a/b + (a′b − ab′)/b² ε.
    #[inline]
    fn div(self, b: Self) -> Self {
        Tangent::new(
            self.value / b.value,
            (self.slope * b.value - self.value * b.slope) / (b.value * b.value),
        )
    }
}
impl<T: Real> Neg for Tangent<T> {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Tangent::new(-self.value, -self.slope)
    }
}
impl<T: Real> AddAssign for Tangent<T> {
    #[inline]
    fn add_assign(&mut self, b: Self) {
        *self = *self + b;
    }
}
impl<T: Real> SubAssign for Tangent<T> {
    #[inline]
    fn sub_assign(&mut self, b: Self) {
        *self = *self - b;
    }
}

impl<T: Real> Real for Tangent<T> {
    type Mask = T::Mask;
    const ZERO: Self = Tangent {
        value: T::ZERO,
        slope: T::ZERO,
    };
    const ONE: Self = Tangent {
        value: T::ONE,
        slope: T::ZERO,
    };
    const EPSILON: Self = Tangent {
        value: T::EPSILON,
        slope: T::ZERO,
    };
    const MIN_POSITIVE: Self = Tangent {
        value: T::MIN_POSITIVE,
        slope: T::ZERO,
    };
    #[inline]
    fn from_f64(x: f64) -> Self {
        Tangent::new(T::from_f64(x), T::ZERO)
    }
    /// The value, itself without slopes, and slope 0.
    #[inline]
    fn constant(self) -> Self {
        Tangent::new(self.value.constant(), T::ZERO)
    }
    /// The value's SVD with the exact derivatives of U, σ and V ([`svd3`]).
    #[inline]
    fn signed_svd(f: Columns<Self>) -> Svd<Self> {
        svd3::svd_of_tangents(f)
    }
    /// The value's polar rotation with its exact derivative ([`svd3`]).
    #[inline]
    fn polar(f: Columns<Self>) -> Columns<Self> {
        svd3::polar_of_tangents(f)
    }
    /// √(a + a′ε) = √a + a′ / (2√a) ε.
    #[inline]
    fn sqrt(self) -> Self {
        let root = self.value.sqrt();
        Tangent::new(root, self.slope / (root + root))
    }
    #[inline]
    fn finite(self) -> T::Mask {
        self.value.finite() & self.slope.finite()
    }
    #[inline]
    fn le(self, other: Self) -> T::Mask {
        self.value.le(other.value)
    }
    #[inline]
    fn gt(self, other: Self) -> T::Mask {
        self.value.gt(other.value)
    }
    #[inline]
    fn select(mask: T::Mask, if_true: Self, if_false: Self) -> Self {
        Tangent::new(
            T::select(mask, if_true.value, if_false.value),
            T::select(mask, if_true.slope, if_false.slope),
        )
    }
    /// sin(a + a′ε) = sin a + a′ cos a ε.
    #[inline]
    fn sin(self) -> Self {
        Tangent::new(self.value.sin(), self.slope * self.value.cos())
    }
    /// cos(a + a′ε) = cos a − a′ sin a ε.
    #[inline]
    fn cos(self) -> Self {
        Tangent::new(self.value.cos(), -(self.slope * self.value.sin()))
    }
    /// exp(a + a′ε) = eᵃ + a′ eᵃ ε.
    #[inline]
    fn exp(self) -> Self {
        let e = self.value.exp();
        Tangent::new(e, self.slope * e)
    }
    /// ln(a + a′ε) = ln a + a′ / a ε.
    #[inline]
    fn ln(self) -> Self {
        Tangent::new(self.value.ln(), self.slope / self.value)
    }
    /// atan2(y + y′ε, x + x′ε) = atan2(y, x) + (x y′ − y x′) / (x² + y²) ε.
    #[inline]
    fn atan2(self, x: Self) -> Self {
        let (y, x_) = (self.value, x.value);
        let slope = (x_ * self.slope - y * x.slope) / (x_ * x_ + y * y);
        Tangent::new(y.atan2(x_), slope)
    }
    /// asin(a + a′ε) = asin a + a′ / √(1 − a²) ε.
    #[inline]
    fn asin(self) -> Self {
        let a = self.value;
        Tangent::new(a.asin(), self.slope / (T::ONE - a * a).sqrt())
    }
    /// acos(a + a′ε) = acos a − a′ / √(1 − a²) ε.
    #[inline]
    fn acos(self) -> Self {
        let a = self.value;
        Tangent::new(a.acos(), -(self.slope / (T::ONE - a * a).sqrt()))
    }
    /// ∛(a + a′ε) = ∛a + a′ / (3 ∛a²) ε.
    #[inline]
    fn cbrt(self) -> Self {
        let root = self.value.cbrt();
        Tangent::new(root, self.slope / (T::from_f64(3.0) * root * root))
    }
}

/// A dual number over f64.
pub type Dual64 = Tangent<f64>;

/// The numbers `x` (N groups of three, a point each) as dual numbers with number `j` (group j / 3,
/// entry j % 3) seeded: the slope of anything computed from them is its derivative along that one
/// number. One pass of forward mode.
pub(crate) fn seed_one<const N: usize>(x: &[[f64; 3]; N], j: usize) -> [[Tangent<f64>; 3]; N] {
    std::array::from_fn(|k| {
        std::array::from_fn(|a| Tangent::new(x[k][a], if 3 * k + a == j { 1.0 } else { 0.0 }))
    })
}

/// The numbers `x` as second-order dual numbers, number `i` seeded along the inner ε₁ and `j`
/// along the outer ε₂: the ε₁ε₂ part (`.slope.slope`) of anything computed from them is its second
/// derivative ∂²/∂xᵢ∂xⱼ.
pub(crate) fn seed_two<const N: usize>(
    x: &[[f64; 3]; N],
    i: usize,
    j: usize,
) -> [[Tangent<Tangent<f64>>; 3]; N] {
    let one = |at: usize, k: usize| if at == k { 1.0 } else { 0.0 };
    std::array::from_fn(|k| {
        std::array::from_fn(|a| {
            let at = 3 * k + a;
            Tangent::new(
                Tangent::new(x[k][a], one(at, i)),
                Tangent::new(one(at, j), 0.0),
            )
        })
    })
}

/// A 3-vector of dual numbers: over f64 ([`Dual64`], the default), or of any number that compares
/// to a `bool` (dual numbers of dual numbers, for second derivatives), as a [`Vector3`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DualVec3<T = Dual64>(pub [T; 3]);

impl DualVec3 {
    /// The point `p` with the slopes `direction`.
    pub fn seeded(p: glam::DVec3, direction: glam::DVec3) -> Self {
        DualVec3([0, 1, 2].map(|i| Tangent::new(p[i], direction[i])))
    }
}

impl<T: Real<Mask = bool>> Add for DualVec3<T> {
    type Output = Self;
    fn add(self, b: Self) -> Self {
        DualVec3([0, 1, 2].map(|i| self.0[i] + b.0[i]))
    }
}
impl<T: Real<Mask = bool>> Sub for DualVec3<T> {
    type Output = Self;
    fn sub(self, b: Self) -> Self {
        DualVec3([0, 1, 2].map(|i| self.0[i] - b.0[i]))
    }
}
impl<T: Real<Mask = bool>> Neg for DualVec3<T> {
    type Output = Self;
    fn neg(self) -> Self {
        DualVec3(self.0.map(|x| -x))
    }
}
impl<T: Real<Mask = bool>> Mul<T> for DualVec3<T> {
    type Output = Self;
    fn mul(self, k: T) -> Self {
        DualVec3(self.0.map(|x| x * k))
    }
}
impl<T: Real<Mask = bool>> Div<T> for DualVec3<T> {
    type Output = Self;
    fn div(self, k: T) -> Self {
        DualVec3(self.0.map(|x| x / k))
    }
}
impl<T: Real<Mask = bool>> AddAssign for DualVec3<T> {
    fn add_assign(&mut self, b: Self) {
        *self = *self + b;
    }
}
impl<T: Real<Mask = bool>> SubAssign for DualVec3<T> {
    fn sub_assign(&mut self, b: Self) {
        *self = *self - b;
    }
}

impl<T: Real<Mask = bool>> Vector3 for DualVec3<T> {
    type Real = T;
    const ZERO: Self = DualVec3([T::ZERO; 3]);
    fn dot(self, b: Self) -> T {
        self.0[0] * b.0[0] + self.0[1] * b.0[1] + self.0[2] * b.0[2]
    }
    fn cross(self, b: Self) -> Self {
        let (a, b) = (self.0, b.0);
        DualVec3([
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ])
    }
    fn from_f64s(x: f64, y: f64, z: f64) -> Self {
        DualVec3([x, y, z].map(T::from_f64))
    }
    fn y(self) -> T {
        self.0[1]
    }
    fn set_y(&mut self, y: T) {
        self.0[1] = y;
    }
    fn select(mask: bool, if_true: Self, if_false: Self) -> Self {
        if mask { if_true } else { if_false }
    }
    fn to_array(self) -> [T; 3] {
        self.0
    }
    fn from_array(a: [T; 3]) -> Self {
        DualVec3(a)
    }
}

/// ∇C by forward-mode automatic differentiation: for every coordinate of every point, `value`
/// evaluated on dual numbers seeded with slope 1 on that coordinate; ∂C/∂x is the value's slope.
/// `None` when a derivative is not finite (a length or normalisation of a zero vector, a
/// division by zero: the gradient is undefined there).
///
/// ```
/// use glam::DVec3;
/// use tetlab_core::numbers::dual::{gradient, DualVec3};
/// use tetlab_core::numbers::vector::Vector3;
/// // C = |p0 − p1|: ∇p0 C is the unit vector from p1 to p0, ∇p1 C its negative.
/// let points = [DVec3::new(3.0, 0.0, 4.0), DVec3::ZERO];
/// let g = gradient(&points, |p: &[DualVec3]| (p[0] - p[1]).length()).unwrap();
/// assert!((g[0] - DVec3::new(0.6, 0.0, 0.8)).length() < 1e-15);
/// assert_eq!(g[1], -g[0]);
/// ```
pub fn gradient(
    points: &[glam::DVec3],
    mut value: impl FnMut(&[DualVec3]) -> Dual64,
) -> Option<Vec<glam::DVec3>> {
    let mut seeded: Vec<DualVec3> = points
        .iter()
        .map(|&p| DualVec3::seeded(p, glam::DVec3::ZERO))
        .collect();
    let mut gradients = vec![glam::DVec3::ZERO; points.len()];
    for (i, gradient) in gradients.iter_mut().enumerate() {
        for axis in 0..3 {
            seeded[i].0[axis].slope = 1.0;
            let d = value(&seeded).slope;
            seeded[i].0[axis].slope = 0.0;
            if !d.is_finite() {
                return None;
            }
            gradient[axis] = d;
        }
    }
    Some(gradients)
}
