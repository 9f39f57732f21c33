//! Numbers that write WGSL ([`Traced`], [`TracedMask`], [`TracedVec3`]): running a formula on
//! them records each operation as a line of a compute shader instead of computing it, so that
//! the GPU engine runs the very formula the CPU engines run (a family's `evaluate`, a constraint
//! file's tape, the projection rule, the integration), written once in Rust and never again in
//! WGSL.
//!
//! A recording ([`record`]) collects `let tN: f32 = …;` lines, one per operation, on the thread
//! that runs it. Operations on constants are done at once, in f32, as the GPU would do them.
//! The formulas never branch on a value (they run on SIMD lanes too, where a comparison gives one
//! flag per lane), so recording a formula records every path: a comparison is a `bool`, and
//! [`Real::select`] is WGSL's `select`. [`crate::numbers::vector::Mask::any`] of a recorded
//! flag is `true`, as it is for lanes when some lane might take the path: the work is recorded,
//! and its result selected per thread.
//!
//! Infinity and NaN have no literal in WGSL: a recorded formula reads them from the shader's
//! `special` vector (x: +∞, y: NaN), which the shader that holds it declares.
//!
//! ```
//! use tetlab_core::numbers::traced::{Traced, TracedVec3, record};
//! use tetlab_core::numbers::vector::{Real, Vector3};
//! let (length, code) = record(|| {
//!     let v = TracedVec3::input("a", "b", "c");
//!     v.length()
//! });
//! assert!(code.contains("sqrt("));
//! // Constants fold: √4 is 2 without a line of code.
//! let (two, code) = record(|| Traced::from_f64(4.0).sqrt());
//! assert_eq!((two, code.as_str()), (Traced::Const(2.0), ""));
//! # let _ = length;
//! ```

use super::vector::{Mask, Real, Vector3};
use std::cell::RefCell;
use std::fmt;
use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, Neg, Not, Sub, SubAssign};

thread_local! {
    static RECORDING: RefCell<Option<Recording>> = const { RefCell::new(None) };
}

/// The lines recorded so far, and the number of the next variable.
struct Recording {
    code: String,
    next: u32,
}

/// Runs `formula` while recording every operation on traced numbers; returns what it gave and
/// the WGSL lines recorded (each `let tN: … = …;` on a line of its own). Variables are numbered
/// from `first`: a shader that records several formulas one after the other numbers them on
/// ([`record_from`]).
pub fn record<T>(formula: impl FnOnce() -> T) -> (T, String) {
    let ((value, code), _) = record_from(0, formula);
    (value, code)
}

/// [`record`] with the variables numbered from `first`; also returns the first number not
/// used.
///
/// # Panics
/// If a recording is already under way on this thread (recordings do not nest).
pub fn record_from<T>(first: u32, formula: impl FnOnce() -> T) -> ((T, String), u32) {
    RECORDING.with(|r| {
        let mut r = r.borrow_mut();
        assert!(r.is_none(), "recordings of traced numbers do not nest");
        *r = Some(Recording {
            code: String::new(),
            next: first,
        });
    });
    let value = formula();
    let recording = RECORDING
        .with(|r| r.borrow_mut().take())
        .expect("started above");
    ((value, recording.code), recording.next)
}

/// Records `let tN: ty = expression;` and returns N.
///
/// # Panics
/// Outside a recording ([`record`]): a traced number that is not a constant exists only in
/// one.
fn emit(ty: &str, expression: fmt::Arguments<'_>) -> u32 {
    RECORDING.with(|r| {
        let mut r = r.borrow_mut();
        let r = r
            .as_mut()
            .expect("traced numbers are computed only while recording");
        let n = r.next;
        r.next += 1;
        use fmt::Write;
        writeln!(r.code, "    let t{n}: {ty} = {expression};").expect("a String takes any text");
        n
    })
}

/// Records a line of WGSL as it is (a store, a call): `line` ends with `;`.
///
/// # Panics
/// Outside a recording.
pub fn statement(line: fmt::Arguments<'_>) {
    RECORDING.with(|r| {
        let mut r = r.borrow_mut();
        let r = r
            .as_mut()
            .expect("statements are recorded only while recording");
        use fmt::Write;
        writeln!(r.code, "    {line}").expect("a String takes any text");
    });
}

/// A number of a recorded formula: a constant, or the variable of a line of WGSL.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Traced {
    /// A number known while recording.
    Const(f32),
    /// The variable `tN`.
    Var(u32),
}

/// A flag of a recorded formula: a constant, or the `bool` variable of a line of WGSL.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TracedMask {
    /// A flag known while recording.
    Const(bool),
    /// The variable `tN`.
    Var(u32),
}

/// A 3-vector of recorded numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TracedVec3 {
    /// x.
    pub x: Traced,
    /// y (up).
    pub y: Traced,
    /// z.
    pub z: Traced,
}

impl Traced {
    /// A number the shader has under `expression` (an `f32` WGSL expression: a buffer's
    /// element, a uniform's field), taken into a variable.
    pub fn input(expression: &str) -> Traced {
        Traced::Var(emit("f32", format_args!("{expression}")))
    }

    fn unary(self, function: &str, fold: fn(f32) -> f32) -> Traced {
        match self {
            Traced::Const(x) => Traced::Const(fold(x)),
            Traced::Var(_) => Traced::Var(emit("f32", format_args!("{function}({self})"))),
        }
    }

    fn binary(self, op: &str, other: Traced, fold: fn(f32, f32) -> f32) -> Traced {
        match (self, other) {
            (Traced::Const(a), Traced::Const(b)) => Traced::Const(fold(a, b)),
            _ => Traced::Var(emit("f32", format_args!("{self} {op} {other}"))),
        }
    }

    fn compare(self, op: &str, other: Traced, fold: fn(f32, f32) -> bool) -> TracedMask {
        match (self, other) {
            (Traced::Const(a), Traced::Const(b)) => TracedMask::Const(fold(a, b)),
            _ => TracedMask::Var(emit("bool", format_args!("{self} {op} {other}"))),
        }
    }
}

impl fmt::Display for Traced {
    /// The WGSL expression: `tN`, or the constant as an f32 literal that gives back its bits
    /// (in parentheses when negative), or `special.x` / `special.y` for ±∞ and NaN.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Traced::Var(n) => write!(f, "t{n}"),
            Traced::Const(x) if x.is_nan() => write!(f, "special.y"),
            Traced::Const(x) if x == f32::INFINITY => write!(f, "special.x"),
            Traced::Const(x) if x == f32::NEG_INFINITY => write!(f, "(-special.x)"),
            Traced::Const(x) if x.is_sign_negative() => write!(f, "(-{:?}f)", -x),
            Traced::Const(x) => write!(f, "{x:?}f"),
        }
    }
}

impl fmt::Display for TracedMask {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            TracedMask::Var(n) => write!(f, "t{n}"),
            TracedMask::Const(b) => write!(f, "{b}"),
        }
    }
}

impl TracedMask {
    /// A flag the shader has under `expression` (a `bool` WGSL expression).
    pub fn input(expression: &str) -> TracedMask {
        TracedMask::Var(emit("bool", format_args!("{expression}")))
    }
}

impl BitAnd for TracedMask {
    type Output = TracedMask;
    fn bitand(self, other: TracedMask) -> TracedMask {
        match (self, other) {
            (TracedMask::Const(false), _) | (_, TracedMask::Const(false)) => {
                TracedMask::Const(false)
            }
            (TracedMask::Const(true), m) | (m, TracedMask::Const(true)) => m,
            _ => TracedMask::Var(emit("bool", format_args!("{self} && {other}"))),
        }
    }
}

impl BitOr for TracedMask {
    type Output = TracedMask;
    fn bitor(self, other: TracedMask) -> TracedMask {
        match (self, other) {
            (TracedMask::Const(true), _) | (_, TracedMask::Const(true)) => TracedMask::Const(true),
            (TracedMask::Const(false), m) | (m, TracedMask::Const(false)) => m,
            _ => TracedMask::Var(emit("bool", format_args!("{self} || {other}"))),
        }
    }
}

impl Not for TracedMask {
    type Output = TracedMask;
    fn not(self) -> TracedMask {
        match self {
            TracedMask::Const(b) => TracedMask::Const(!b),
            TracedMask::Var(_) => TracedMask::Var(emit("bool", format_args!("!{self}"))),
        }
    }
}

impl Mask for TracedMask {
    /// A recorded flag may be set in some thread: `true` unless it is the constant `false`.
    fn any(self) -> bool {
        self != TracedMask::Const(false)
    }

    /// 1 where [`TracedMask::any`], 0 otherwise: how many threads set it is known only on the
    /// GPU.
    fn count(self) -> u32 {
        u32::from(self.any())
    }
}

impl Add for Traced {
    type Output = Traced;
    fn add(self, other: Traced) -> Traced {
        match (self, other) {
            (Traced::Const(z), x) | (x, Traced::Const(z)) if z == 0.0 && x != Traced::Const(z) => x,
            _ => self.binary("+", other, |a, b| a + b),
        }
    }
}

impl Sub for Traced {
    type Output = Traced;
    fn sub(self, other: Traced) -> Traced {
        match other {
            Traced::Const(z) if z == 0.0 && matches!(self, Traced::Var(_)) => self,
            _ => self.binary("-", other, |a, b| a - b),
        }
    }
}

impl Mul for Traced {
    type Output = Traced;
    fn mul(self, other: Traced) -> Traced {
        match (self, other) {
            (Traced::Const(one), x @ Traced::Var(_)) | (x @ Traced::Var(_), Traced::Const(one))
                if one == 1.0 =>
            {
                x
            }
            _ => self.binary("*", other, |a, b| a * b),
        }
    }
}

impl Div for Traced {
    type Output = Traced;
    fn div(self, other: Traced) -> Traced {
        match other {
            Traced::Const(one) if one == 1.0 && matches!(self, Traced::Var(_)) => self,
            _ => self.binary("/", other, |a, b| a / b),
        }
    }
}

impl Neg for Traced {
    type Output = Traced;
    fn neg(self) -> Traced {
        match self {
            Traced::Const(x) => Traced::Const(-x),
            Traced::Var(_) => Traced::Var(emit("f32", format_args!("-{self}"))),
        }
    }
}

impl AddAssign for Traced {
    fn add_assign(&mut self, other: Traced) {
        *self = *self + other;
    }
}

impl SubAssign for Traced {
    fn sub_assign(&mut self, other: Traced) {
        *self = *self - other;
    }
}

impl Real for Traced {
    type Mask = TracedMask;
    const ZERO: Self = Traced::Const(0.0);
    const ONE: Self = Traced::Const(1.0);
    const EPSILON: Self = Traced::Const(f32::EPSILON);
    const MIN_POSITIVE: Self = Traced::Const(f32::MIN_POSITIVE);

    fn from_f64(x: f64) -> Self {
        Traced::Const(x as f32)
    }

    fn sqrt(self) -> Self {
        self.unary("sqrt", f32::sqrt)
    }

    /// WGSL has no test for ∞ or NaN (and a compiler may assume there are none): the exponent
    /// bits are tested instead, all ones meaning ∞ or NaN.
    fn finite(self) -> TracedMask {
        match self {
            Traced::Const(x) => TracedMask::Const(x.is_finite()),
            Traced::Var(_) => TracedMask::Var(emit(
                "bool",
                format_args!("(bitcast<u32>({self}) & 0x7f800000u) != 0x7f800000u"),
            )),
        }
    }

    fn le(self, other: Self) -> TracedMask {
        self.compare("<=", other, |a, b| a <= b)
    }

    fn gt(self, other: Self) -> TracedMask {
        self.compare(">", other, |a, b| a > b)
    }

    fn select(mask: TracedMask, if_true: Self, if_false: Self) -> Self {
        match mask {
            TracedMask::Const(true) => if_true,
            TracedMask::Const(false) => if_false,
            TracedMask::Var(_) if if_true == if_false => if_true,
            TracedMask::Var(_) => Traced::Var(emit(
                "f32",
                format_args!("select({if_false}, {if_true}, {mask})"),
            )),
        }
    }

    fn sin(self) -> Self {
        self.unary("sin", f32::sin)
    }

    fn cos(self) -> Self {
        self.unary("cos", f32::cos)
    }

    fn exp(self) -> Self {
        self.unary("exp", f32::exp)
    }

    fn ln(self) -> Self {
        self.unary("log", f32::ln)
    }

    fn atan2(self, x: Self) -> Self {
        match (self, x) {
            (Traced::Const(y), Traced::Const(x)) => Traced::Const(y.atan2(x)),
            _ => Traced::Var(emit("f32", format_args!("atan2({self}, {x})"))),
        }
    }

    fn asin(self) -> Self {
        self.unary("asin", f32::asin)
    }

    fn acos(self) -> Self {
        self.unary("acos", f32::acos)
    }

    /// The number through an integer operation on its bits that a compiler cannot see through
    /// (an exclusive or with the bits of `special.z`, which is 0): no algebra rewrites it away.
    fn rounded(self) -> Self {
        match self {
            Traced::Const(_) => self,
            Traced::Var(_) => Traced::Var(emit(
                "f32",
                format_args!("bitcast<f32>(bitcast<u32>({self}) ^ bitcast<u32>(special.z))"),
            )),
        }
    }

    /// The real cube root: WGSL's `pow` takes no negative base, so the sign is put back.
    fn cbrt(self) -> Self {
        match self {
            Traced::Const(x) => Traced::Const(x.cbrt()),
            Traced::Var(_) => Traced::Var(emit(
                "f32",
                format_args!("sign({self}) * pow(abs({self}), 1.0f / 3.0f)"),
            )),
        }
    }
}

impl TracedVec3 {
    /// The vector the shader has under three `f32` expressions.
    pub fn input(x: &str, y: &str, z: &str) -> TracedVec3 {
        TracedVec3 {
            x: Traced::input(x),
            y: Traced::input(y),
            z: Traced::input(z),
        }
    }

    /// The vector of the first three components of a `vec4<f32>` expression.
    pub fn input_xyz(vec4: &str) -> TracedVec3 {
        TracedVec3::input(
            &format!("{vec4}.x"),
            &format!("{vec4}.y"),
            &format!("{vec4}.z"),
        )
    }

    fn each(self, f: impl Fn(Traced) -> Traced) -> TracedVec3 {
        TracedVec3 {
            x: f(self.x),
            y: f(self.y),
            z: f(self.z),
        }
    }

    fn zip(self, other: TracedVec3, f: impl Fn(Traced, Traced) -> Traced) -> TracedVec3 {
        TracedVec3 {
            x: f(self.x, other.x),
            y: f(self.y, other.y),
            z: f(self.z, other.z),
        }
    }
}

impl fmt::Display for TracedVec3 {
    /// The WGSL `vec3<f32>` of its components.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "vec3<f32>({}, {}, {})", self.x, self.y, self.z)
    }
}

impl Add for TracedVec3 {
    type Output = TracedVec3;
    fn add(self, other: TracedVec3) -> TracedVec3 {
        self.zip(other, |a, b| a + b)
    }
}

impl Sub for TracedVec3 {
    type Output = TracedVec3;
    fn sub(self, other: TracedVec3) -> TracedVec3 {
        self.zip(other, |a, b| a - b)
    }
}

impl Neg for TracedVec3 {
    type Output = TracedVec3;
    fn neg(self) -> TracedVec3 {
        self.each(|a| -a)
    }
}

impl Mul<Traced> for TracedVec3 {
    type Output = TracedVec3;
    fn mul(self, s: Traced) -> TracedVec3 {
        self.each(|a| a * s)
    }
}

impl Div<Traced> for TracedVec3 {
    type Output = TracedVec3;
    fn div(self, s: Traced) -> TracedVec3 {
        self.each(|a| a / s)
    }
}

impl AddAssign for TracedVec3 {
    fn add_assign(&mut self, other: TracedVec3) {
        *self = *self + other;
    }
}

impl SubAssign for TracedVec3 {
    fn sub_assign(&mut self, other: TracedVec3) {
        *self = *self - other;
    }
}

impl Vector3 for TracedVec3 {
    type Real = Traced;
    const ZERO: Self = TracedVec3 {
        x: Traced::ZERO,
        y: Traced::ZERO,
        z: Traced::ZERO,
    };

    fn dot(self, rhs: Self) -> Traced {
        self.x * rhs.x + self.y * rhs.y + self.z * rhs.z
    }

    fn cross(self, rhs: Self) -> Self {
        TracedVec3 {
            x: self.y * rhs.z - self.z * rhs.y,
            y: self.z * rhs.x - self.x * rhs.z,
            z: self.x * rhs.y - self.y * rhs.x,
        }
    }

    fn from_f64s(x: f64, y: f64, z: f64) -> Self {
        TracedVec3 {
            x: Traced::from_f64(x),
            y: Traced::from_f64(y),
            z: Traced::from_f64(z),
        }
    }

    fn y(self) -> Traced {
        self.y
    }

    fn set_y(&mut self, y: Traced) {
        self.y = y;
    }

    fn select(mask: TracedMask, if_true: Self, if_false: Self) -> Self {
        TracedVec3 {
            x: Traced::select(mask, if_true.x, if_false.x),
            y: Traced::select(mask, if_true.y, if_false.y),
            z: Traced::select(mask, if_true.z, if_false.z),
        }
    }

    fn to_array(self) -> [Traced; 3] {
        [self.x, self.y, self.z]
    }

    fn from_array([x, y, z]: [Traced; 3]) -> Self {
        TracedVec3 { x, y, z }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Constants print as literals that give back their bits, negative ones in parentheses.
    #[test]
    fn constants_print_as_exact_literals() {
        for x in [1.0f32, -0.5, 1e-7, f32::EPSILON, f32::MIN_POSITIVE, 3.4e38] {
            let text = Traced::Const(x).to_string();
            let digits = text.trim_start_matches("(-").trim_end_matches("f)");
            let digits = digits.trim_end_matches('f');
            let back: f32 = digits.parse().expect("a number");
            assert_eq!(back, x.abs(), "{text}");
            assert_eq!(text.starts_with("(-"), x < 0.0);
        }
        assert_eq!(Traced::Const(f32::INFINITY).to_string(), "special.x");
        assert_eq!(Traced::Const(f32::NAN).to_string(), "special.y");
    }

    /// A selection on a flag known while recording takes its side without code.
    #[test]
    fn a_known_flag_selects_without_code() {
        let ((), code) = record(|| {
            let a = Traced::input("1.0f");
            let picked = Traced::select(TracedMask::Const(true), a, Traced::ZERO);
            assert_eq!(picked, a);
            assert!((a.gt(Traced::ZERO) | TracedMask::Const(true)) == TracedMask::Const(true));
        });
        // The input and the comparison; neither the selection nor the `| true` wrote a line.
        assert_eq!(code.lines().count(), 2, "{code}");
    }
}
