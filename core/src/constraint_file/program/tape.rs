//! A tape ([`Tape`]): what some outputs of a [`super::Program`] need, as flat single-assignment
//! instructions, run front to back for values ([`Tape::run`]) and back to front for gradients
//! ([`Tape::gradient`], reverse mode), on the stack, in any [`Real`].

use super::Origin;
use super::op::{Inputs, MAX_SLOTS, Op, Reg, add3, cross, dot, holds, scale, shrink, sub3};
use crate::numbers::vector::Real;
use arrayvec::ArrayVec;

/// What some outputs of a [`Program`] need, as flat single-assignment instructions: instruction k
/// defines the next register from earlier ones. The registers are numbers side by side, one for
/// a scalar and three for a vector, and an instruction names each register it reads by where
/// its value starts ([`Reg`]), so that a scalar instruction reads and writes one number.
#[derive(Clone, Debug, PartialEq)]
pub struct Tape {
    pub(super) ops: Vec<Op>,
    pub(super) origins: Vec<Origin>,
    /// Whether each instruction's value is a vector.
    vector: Vec<bool>,
    /// Where each instruction's value starts.
    starts: Vec<Reg>,
    pub(super) outputs: Vec<Reg>,
    /// The instruction that defines output 0 (C): the backward pass starts there.
    first_output: usize,
    /// For a prelude, whether each output is a vector (three stored numbers) or a scalar.
    pub(super) widths: Vec<bool>,
    /// Per number, whether it depends on a particle: the backward pass skips the others, and
    /// carries no adjoint into them (a stored number, a constant, `rest`).
    varying: Vec<bool>,
}

/// The registers of a tape after [`Tape::run`]: read its outputs.
pub struct Registers<'a, T> {
    registers: &'a [T],
    outputs: &'a [Reg],
    widths: &'a [bool],
}

impl<T: Copy> Registers<'_, T> {
    /// Output `i` of the tape as a scalar.
    pub fn scalar(&self, i: usize) -> T {
        self.registers[self.outputs[i] as usize]
    }

    /// Output `i` of the tape as a vector.
    pub fn vector(&self, i: usize) -> [T; 3] {
        let at = self.outputs[i] as usize;
        [
            self.registers[at],
            self.registers[at + 1],
            self.registers[at + 2],
        ]
    }

    /// A prelude's outputs, in order, into `out`: a scalar's one number, a vector's three
    /// ([`super::Compiled::stored`] of them in all).
    pub fn write_all(&self, out: &mut [T]) {
        let mut at = 0;
        for (i, &vector) in self.widths.iter().enumerate() {
            let width = if vector { 3 } else { 1 };
            let from = self.outputs[i] as usize;
            out[at..at + width].copy_from_slice(&self.registers[from..from + width]);
            at += width;
        }
    }
}

/// What the backward pass adds into a register.
#[derive(Clone, Copy)]
enum Adjoint<T> {
    Scalar(T),
    Vector([T; 3]),
}

/// Where a tape's value stops being finite ([`Tape::undefined_at`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Undefined {
    /// Where the text of the expression that gives the first non-finite value starts
    /// ([`Program::at`]).
    pub base: usize,
    /// The byte of that text where it is.
    pub offset: usize,
    /// What it is (`/`, `acos`) and why (`acos of 1.0000001: acos is defined on -1..1`).
    pub message: String,
}

/// A place where C may have a kink or a jump ([`Tape::switches_at`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Switch {
    /// Where the expression's text starts ([`Program::at`]).
    pub base: usize,
    /// The byte of that text.
    pub offset: usize,
    /// What it is: `abs`, `min`, `if`…
    pub what: &'static str,
    /// The value whose zero is the kink, at the configuration asked about.
    pub decides: f64,
}

impl Tape {
    /// The tape of instructions `ops` (each reading registers by where they start), from the
    /// text `origins` says, whose values are vectors where `vector` says, with `outputs`.
    pub(super) fn new(
        ops: Vec<Op>,
        origins: Vec<Origin>,
        vector: Vec<bool>,
        outputs: Vec<Reg>,
    ) -> Tape {
        let mut starts = Vec::with_capacity(ops.len());
        let mut varying: Vec<bool> = Vec::new();
        for (op, &wide) in ops.iter().zip(&vector) {
            starts.push(varying.len() as Reg);
            let v = match op {
                Op::Particle(_) => true,
                Op::Const(_)
                | Op::ConstVector(_)
                | Op::Rest
                | Op::RestParticle(_)
                | Op::Material(_)
                | Op::Stored(..) => false,
                _ => op.inputs().iter().any(|&i| varying[i as usize]),
            };
            varying.extend(std::iter::repeat_n(v, if wide { 3 } else { 1 }));
        }
        let first_output = outputs
            .first()
            .map_or(0, |&o| starts.iter().position(|&s| s == o).unwrap_or(0));
        Tape {
            ops,
            origins,
            vector,
            starts,
            outputs,
            first_output,
            widths: Vec::new(),
            varying,
        }
    }

    /// Whether it reads the rest shape (q0…).
    pub fn reads_rest_shape(&self) -> bool {
        self.ops.iter().any(|op| matches!(op, Op::RestParticle(_)))
    }

    /// How many instructions (and registers) it has.
    pub fn len(&self) -> usize {
        self.ops.len()
    }

    /// Whether it has none.
    pub fn is_empty(&self) -> bool {
        self.ops.is_empty()
    }

    /// Runs the tape on `inputs` and reads its outputs with `read`.
    #[inline(always)]
    pub fn run<T: Real, R>(
        &self,
        inputs: &Inputs<'_, T>,
        read: impl FnOnce(&Registers<'_, T>) -> R,
    ) -> R {
        let mut registers = ArrayVec::new();
        self.forward(inputs, &mut registers);
        read(&Registers {
            registers: &registers,
            outputs: &self.outputs,
            widths: &self.widths,
        })
    }

    /// The first instruction, in evaluation order, whose value is not finite while what it reads
    /// is, at `points` with `rest`: where and why C is undefined there. `None` where every value
    /// is finite.
    pub fn undefined_at(&self, inputs: &Inputs<'_, f64>) -> Option<Undefined> {
        let mut r: ArrayVec<f64, MAX_SLOTS> = ArrayVec::new();
        for (op, origin) in self.ops.iter().zip(&self.origins) {
            let start = r.len();
            op.apply(&mut r, inputs);
            let finite = |at: Reg| {
                let at = at as usize;
                r[at..at + self.width_at(at as Reg)]
                    .iter()
                    .all(|x| x.is_finite())
            };
            if !r[start..].iter().all(|x| x.is_finite()) && op.inputs().iter().all(|&i| finite(i)) {
                return Some(Undefined {
                    base: origin.base,
                    offset: origin.offset,
                    message: format!(
                        "`{}` is undefined: {}",
                        origin.what,
                        op.undefined(|i| r[i as usize])
                    ),
                });
            }
        }
        None
    }

    /// Where C may have a kink or a jump: for each `abs`, `sign`, `min`, `max`, `clamp` and
    /// `if` on C's path, where it is (as [`Undefined`] says) and what it is, with the value at
    /// `points` of what decides it (the argument of `abs`, the difference of `min`'s two, the
    /// two sides of a condition): the kink is where that value is 0.
    pub fn switches_at(&self, inputs: &Inputs<'_, f64>) -> Vec<Switch> {
        let mut r: ArrayVec<f64, MAX_SLOTS> = ArrayVec::new();
        let mut out = Vec::new();
        for (op, origin) in self.ops.iter().zip(&self.origins) {
            if op.switches() {
                let s = |i: Reg| r[i as usize];
                let decides = match *op {
                    Op::Abs(a) | Op::Sign(a) => s(a),
                    Op::Min(a, b) | Op::Max(a, b) => s(a) - s(b),
                    Op::If(_, a, b, ..) | Op::IfVector(_, a, b, ..) => s(a) - s(b),
                    _ => f64::NAN,
                };
                out.push(Switch {
                    base: origin.base,
                    offset: origin.offset,
                    what: origin.what,
                    decides,
                });
            }
            op.apply(&mut r, inputs);
        }
        out
    }

    /// How many numbers instruction `k`'s value is.
    fn width(&self, k: usize) -> usize {
        if self.vector[k] { 3 } else { 1 }
    }

    /// How many numbers the register starting at `at` is.
    fn width_at(&self, at: Reg) -> usize {
        self.starts.binary_search(&at).map_or(1, |k| self.width(k))
    }

    /// Output 0, C, and its gradient with respect to every particle, by reverse mode: the values
    /// forward, then r̄ = ∂C/∂r from C back to the particles, each instruction by the derivative
    /// rule of what it computes. Non-finite where the gradient is undefined (a zero vector's
    /// length or direction, a division by zero, `acos` at ±1).
    ///
    /// Generic over [`Real`]: run on [`crate::numbers::dual::Tangent`] numbers it gives the
    /// derivative of the gradient along the tangents, a column of the Hessian.
    #[inline(always)]
    pub fn gradient<T: Real, const N: usize>(&self, inputs: &Inputs<'_, T>) -> (T, [[T; 3]; N]) {
        let mut r = ArrayVec::new();
        self.forward(inputs, &mut r);
        let r = &r;
        let last = self.first_output;
        let out = self.outputs[0] as usize;
        let mut adjoint: ArrayVec<T, MAX_SLOTS> = ArrayVec::new();
        for _ in 0..self.starts[last] as usize + self.width(last) {
            adjoint.push(T::ZERO);
        }
        adjoint[out] = T::ONE;
        let mut gradient = [[T::ZERO; 3]; N];
        let varying = &self.varying;
        for k in (0..=last).rev() {
            let at = self.starts[k] as usize;
            if !varying[at] {
                continue;
            }
            let bar = if self.vector[k] {
                read3(&adjoint, at as Reg)
            } else {
                [adjoint[at], T::ZERO, T::ZERO]
            };
            let s = bar[0];
            let value = |i: Reg| read3(r, i);
            let x = |i: Reg| r[i as usize];
            // This instruction's own value.
            let own = r[at];
            let own3 = || read3(r, at as Reg);
            // r̄ into register i: all three numbers for a vector, the one for a scalar; nothing
            // into (and no work for) a register that does not depend on a particle.
            macro_rules! add {
                ($i:expr, $v:expr) => {{
                    let i = $i as usize;
                    if varying[i] {
                        match $v {
                            Adjoint::Vector(v) => {
                                adjoint[i] += v[0];
                                adjoint[i + 1] += v[1];
                                adjoint[i + 2] += v[2];
                            }
                            Adjoint::Scalar(x) => adjoint[i] += x,
                        }
                    }
                }};
            }
            let scalar = |x: T| Adjoint::Scalar(x);
            let vector = |v: [T; 3]| Adjoint::Vector(v);
            match self.ops[k] {
                Op::Const(_)
                | Op::ConstVector(_)
                | Op::Rest
                | Op::Sign(_)
                | Op::RestParticle(_)
                | Op::Material(_)
                | Op::Stored(..) => {}
                Op::Particle(p) if (p as usize) < N => {
                    gradient[p as usize] = add3(gradient[p as usize], bar)
                }
                Op::Particle(_) => {}
                Op::NegS(a) => add!(a, scalar(-s)),
                Op::NegV(a) => add!(a, vector(scale(bar, -T::ONE))),
                Op::AddS(a, b) => {
                    add!(a, scalar(s));
                    add!(b, scalar(s));
                }
                Op::SubS(a, b) => {
                    add!(a, scalar(s));
                    add!(b, scalar(-s));
                }
                Op::MulS(a, b) => {
                    add!(a, scalar(s * x(b)));
                    add!(b, scalar(s * x(a)));
                }
                Op::DivS(a, b) => {
                    // r = a / b: ā += r̄ / b, b̄ −= r̄ r / b.
                    let d = x(b);
                    add!(a, scalar(s / d));
                    add!(b, scalar(-(s * own) / d));
                }
                Op::AddV(a, b) => {
                    add!(a, vector(bar));
                    add!(b, vector(bar));
                }
                Op::SubV(a, b) => {
                    add!(a, vector(bar));
                    add!(b, vector(scale(bar, -T::ONE)));
                }
                Op::Scale(v, f) => {
                    // r = v f: v̄ += r̄ f, f̄ += r̄·v.
                    add!(v, vector(scale(bar, x(f))));
                    add!(f, scalar(dot(bar, value(v))));
                }
                Op::Shrink(v, f) => {
                    // r = v / f: v̄ += r̄ / f, f̄ −= r̄·r / f.
                    let d = x(f);
                    add!(v, vector(shrink(bar, d)));
                    add!(f, scalar(-dot(bar, own3()) / d));
                }
                Op::Dot(a, b) => {
                    add!(a, vector(scale(value(b), s)));
                    add!(b, vector(scale(value(a), s)));
                }
                Op::Cross(a, b) => {
                    // r = a × b: ā += b × r̄, b̄ += r̄ × a.
                    add!(a, vector(cross(value(b), bar)));
                    add!(b, vector(cross(bar, value(a))));
                }
                Op::Length(a) => add!(a, vector(scale(value(a), s / own))),
                Op::Normalize(a) => {
                    // r = a / |a|: ā += (r̄ − r (r·r̄)) / |a|.
                    let n = own3();
                    let length = dot(value(a), value(a)).sqrt();
                    let along = dot(n, bar);
                    add!(a, vector(shrink(sub3(bar, scale(n, along)), length)));
                }
                Op::Sqrt(a) => add!(a, scalar(s / (own + own))),
                Op::Abs(a) => add!(a, scalar(T::select(x(a).le(T::ZERO), -s, s))),
                Op::Min(a, b) => {
                    let first = x(a).le(x(b));
                    add!(a, scalar(T::select(first, s, T::ZERO)));
                    add!(b, scalar(T::select(first, T::ZERO, s)));
                }
                Op::Max(a, b) => {
                    let first = x(a).gt(x(b));
                    add!(a, scalar(T::select(first, s, T::ZERO)));
                    add!(b, scalar(T::select(first, T::ZERO, s)));
                }
                Op::Det(a, b, c) => {
                    // r = a·(b × c): ā += r̄ b×c, b̄ += r̄ c×a, c̄ += r̄ a×b.
                    let (a_, b_, c_) = (value(a), value(b), value(c));
                    add!(a, vector(scale(cross(b_, c_), s)));
                    add!(b, vector(scale(cross(c_, a_), s)));
                    add!(c, vector(scale(cross(a_, b_), s)));
                }
                // r = sin a: ā += r̄ cos a; r = cos a: ā −= r̄ sin a.
                Op::Sin(a) => add!(a, scalar(s * x(a).cos())),
                Op::Cos(a) => add!(a, scalar(-(s * x(a).sin()))),
                // r = eᵃ: ā += r̄ r; r = log a: ā += r̄ / a.
                Op::Exp(a) => add!(a, scalar(s * own)),
                Op::Ln(a) => add!(a, scalar(s / x(a))),
                Op::Atan2(y, x_) => {
                    // r = atan2(y, x): ȳ += r̄ x / (x² + y²), x̄ −= r̄ y / (x² + y²).
                    let (yv, xv) = (x(y), x(x_));
                    let d = xv * xv + yv * yv;
                    add!(y, scalar(s * xv / d));
                    add!(x_, scalar(-(s * yv) / d));
                }
                // r = asin a: ā += r̄ / √(1 − a²); r = acos a: ā −= r̄ / √(1 − a²).
                Op::Asin(a) => add!(a, scalar(s / (T::ONE - x(a) * x(a)).sqrt())),
                Op::Acos(a) => add!(a, scalar(-(s / (T::ONE - x(a) * x(a)).sqrt()))),
                // r = ∛a: ā += r̄ / (3 r²).
                Op::Cbrt(a) => add!(a, scalar(s / (T::from_f64(3.0) * own * own))),
                Op::Component(a, i) => {
                    let mut v = [T::ZERO; 3];
                    v[i as usize] = s;
                    add!(a, vector(v));
                }
                Op::Vec3(a, b, c) => {
                    add!(a, scalar(bar[0]));
                    add!(b, scalar(bar[1]));
                    add!(c, scalar(bar[2]));
                }
                Op::If(cmp, a, b, t, e) => {
                    let mask = holds(cmp, x(a), x(b));
                    add!(t, scalar(T::select(mask, s, T::ZERO)));
                    add!(e, scalar(T::select(mask, T::ZERO, s)));
                }
                Op::IfVector(cmp, a, b, t, e) => {
                    let mask = holds(cmp, x(a), x(b));
                    add!(t, vector(bar.map(|v| T::select(mask, v, T::ZERO))));
                    add!(e, vector(bar.map(|v| T::select(mask, T::ZERO, v))));
                }
            }
        }
        (r[out], gradient)
    }

    /// Every register's value, instruction by instruction, into `r` (empty; the caller's, so
    /// that it is never moved).
    #[inline(always)]
    fn forward<T: Real>(&self, inputs: &Inputs<'_, T>, r: &mut ArrayVec<T, MAX_SLOTS>) {
        for op in &self.ops {
            op.apply(r, inputs);
        }
    }
}

/// The vector whose numbers start at `at`.
#[inline(always)]
fn read3<T: Copy>(r: &[T], at: Reg) -> [T; 3] {
    let at = at as usize;
    [r[at], r[at + 1], r[at + 2]]
}
