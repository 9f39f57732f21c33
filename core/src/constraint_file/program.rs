//! A constraint file's expressions, type-checked and compiled once ([`Program`]), then cut into
//! flat tapes ([`Tape`]): each instruction defines one register from earlier ones (single
//! assignment), so a tape runs front to back for values and back to front for gradients.
//!
//! Running a tape allocates nothing (its registers live on the stack, at most
//! [`MAX_REGISTERS`]) and is generic over the scalar type ([`Real`]): f64, f32, SIMD lanes, or
//! the dual numbers of forward-mode automatic differentiation ([`crate::numbers::dual::Tangent`]).
//!
//! # Gradients, two ways
//! - **Forward mode** ([`Tape::run`] over [`crate::numbers::dual::Tangent`] numbers): one pass per
//!   coordinate, 3N passes for N particles. Independent of everything below; `tetlab
//!   check-gradients` checks your gradient against it.
//! - **Reverse mode** ([`Tape::gradient`]): one pass forward for the values, one backward that
//!   carries ∂C/∂(register) from C to the particles, each instruction by its own derivative rule
//!   (for r = a·b: ā += r̄ b, b̄ += r̄ a). About three forward passes' work for the whole gradient:
//!   what a simulation uses. The two agree to rounding (`core/tests/constraint_files.rs`).

use super::expression::{BinaryOp, Expr, Span};
use crate::numbers::vector::Real;
use arrayvec::ArrayVec;
use std::collections::HashMap;

/// What an expression is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Type {
    /// A number.
    Scalar,
    /// A 3-vector.
    Vector,
}

impl Type {
    fn article(self) -> &'static str {
        match self {
            Type::Scalar => "a scalar",
            Type::Vector => "a vector",
        }
    }
}

/// A type or name error, at a span of the expression's text.
#[derive(Clone, Debug, PartialEq)]
pub struct CompileError {
    /// Where.
    pub span: Span,
    /// What.
    pub message: String,
}

/// A register: the index of the instruction that defines it.
type Reg = u16;

/// The most registers (instructions) a program may have: tapes keep their registers on the stack,
/// so that an evaluation allocates nothing.
pub const MAX_REGISTERS: usize = 160;

/// One instruction; it defines the register of its own index from the registers it names.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Op {
    Const(f64),
    Particle(u8),
    Rest,
    NegS(Reg),
    NegV(Reg),
    AddS(Reg, Reg),
    SubS(Reg, Reg),
    MulS(Reg, Reg),
    DivS(Reg, Reg),
    AddV(Reg, Reg),
    SubV(Reg, Reg),
    /// vector × scalar.
    Scale(Reg, Reg),
    /// vector ÷ scalar.
    Shrink(Reg, Reg),
    Dot(Reg, Reg),
    Cross(Reg, Reg),
    Length(Reg),
    Normalize(Reg),
    Sqrt(Reg),
    Abs(Reg),
    Min(Reg, Reg),
    Max(Reg, Reg),
    Det(Reg, Reg, Reg),
}

impl Op {
    /// The registers it reads.
    fn inputs(self) -> ArrayVec<Reg, 3> {
        let mut out = ArrayVec::new();
        match self {
            Op::Const(_) | Op::Particle(_) | Op::Rest => {}
            Op::NegS(a)
            | Op::NegV(a)
            | Op::Length(a)
            | Op::Normalize(a)
            | Op::Sqrt(a)
            | Op::Abs(a) => out.push(a),
            Op::AddS(a, b)
            | Op::SubS(a, b)
            | Op::MulS(a, b)
            | Op::DivS(a, b)
            | Op::AddV(a, b)
            | Op::SubV(a, b)
            | Op::Scale(a, b)
            | Op::Shrink(a, b)
            | Op::Dot(a, b)
            | Op::Cross(a, b)
            | Op::Min(a, b)
            | Op::Max(a, b) => out.extend([a, b]),
            Op::Det(a, b, c) => out.extend([a, b, c]),
        }
        out
    }

    /// The same instruction reading `map[r]` for each register r it reads.
    fn renumbered(self, map: &[Reg]) -> Op {
        let m = |r: Reg| map[r as usize];
        match self {
            Op::Const(_) | Op::Particle(_) | Op::Rest => self,
            Op::NegS(a) => Op::NegS(m(a)),
            Op::NegV(a) => Op::NegV(m(a)),
            Op::Length(a) => Op::Length(m(a)),
            Op::Normalize(a) => Op::Normalize(m(a)),
            Op::Sqrt(a) => Op::Sqrt(m(a)),
            Op::Abs(a) => Op::Abs(m(a)),
            Op::AddS(a, b) => Op::AddS(m(a), m(b)),
            Op::SubS(a, b) => Op::SubS(m(a), m(b)),
            Op::MulS(a, b) => Op::MulS(m(a), m(b)),
            Op::DivS(a, b) => Op::DivS(m(a), m(b)),
            Op::AddV(a, b) => Op::AddV(m(a), m(b)),
            Op::SubV(a, b) => Op::SubV(m(a), m(b)),
            Op::Scale(a, b) => Op::Scale(m(a), m(b)),
            Op::Shrink(a, b) => Op::Shrink(m(a), m(b)),
            Op::Dot(a, b) => Op::Dot(m(a), m(b)),
            Op::Cross(a, b) => Op::Cross(m(a), m(b)),
            Op::Min(a, b) => Op::Min(m(a), m(b)),
            Op::Max(a, b) => Op::Max(m(a), m(b)),
            Op::Det(a, b, c) => Op::Det(m(a), m(b), m(c)),
        }
    }
}

/// The functions of the language: name, argument types, result type.
const FUNCTIONS: [(&str, &[Type], Type); 9] = [
    ("dot", &[Type::Vector, Type::Vector], Type::Scalar),
    ("cross", &[Type::Vector, Type::Vector], Type::Vector),
    ("length", &[Type::Vector], Type::Scalar),
    ("normalize", &[Type::Vector], Type::Vector),
    ("sqrt", &[Type::Scalar], Type::Scalar),
    ("abs", &[Type::Scalar], Type::Scalar),
    ("min", &[Type::Scalar, Type::Scalar], Type::Scalar),
    ("max", &[Type::Scalar, Type::Scalar], Type::Scalar),
    (
        "det",
        &[Type::Vector, Type::Vector, Type::Vector],
        Type::Scalar,
    ),
];

/// The compiler of a file's expressions: the definitions, then its outputs (C, gradient
/// entries), each an instruction; [`Program::tape`] cuts out what some outputs need.
#[derive(Clone, Debug, PartialEq)]
pub struct Program {
    ops: Vec<Op>,
    names: HashMap<String, (Reg, Type)>,
    outputs: Vec<Reg>,
}

impl Program {
    /// A program whose names are p0…p(arity−1) (vectors) and, with `rest`, the scalar `rest`.
    pub fn new(arity: usize, rest: bool) -> Program {
        let mut program = Program {
            ops: Vec::new(),
            names: HashMap::new(),
            outputs: Vec::new(),
        };
        for k in 0..arity {
            let r = program.push(Op::Particle(k as u8));
            program.names.insert(format!("p{k}"), (r, Type::Vector));
        }
        if rest {
            let r = program.push(Op::Rest);
            program.names.insert("rest".to_owned(), (r, Type::Scalar));
        }
        program
    }

    /// Adds `name = expr`; later expressions may use `name`.
    pub fn define(&mut self, name: &str, name_span: Span, expr: &Expr) -> Result<(), CompileError> {
        if self.names.contains_key(name) || FUNCTIONS.iter().any(|f| f.0 == name) {
            return Err(CompileError {
                span: name_span,
                message: format!("`{name}` is already a name; give the definition another"),
            });
        }
        let compiled = self.compile(expr)?;
        self.names.insert(name.to_owned(), compiled);
        Ok(())
    }

    /// Adds an output of type `wanted`; returns its index, for [`Program::tape`].
    pub fn output(&mut self, expr: &Expr, wanted: Type, what: &str) -> Result<usize, CompileError> {
        let (reg, ty) = self.compile(expr)?;
        if ty != wanted {
            return Err(CompileError {
                span: expr.span(),
                message: format!(
                    "{what} must be {}, and this is {}",
                    wanted.article(),
                    ty.article()
                ),
            });
        }
        self.outputs.push(reg);
        Ok(self.outputs.len() - 1)
    }

    /// The instructions outputs `outputs` need and no other, in order, renumbered: a definition
    /// that only a gradient entry uses costs C's tape nothing.
    ///
    /// ```
    /// use tetlab_core::constraint_file::expression::parse_expression;
    /// use tetlab_core::constraint_file::program::{Program, Type};
    /// // C = |p0 − p1| − rest, the same tape in f64 and in f32.
    /// let mut program = Program::new(2, true);
    /// let c = program.output(&parse_expression("length(p0 - p1) - rest").unwrap(), Type::Scalar, "value").unwrap();
    /// let tape = program.tape(&[c]);
    /// let at = |points: &[[f64; 3]; 2]| tape.run(points, 1.0, |r| r.scalar(0));
    /// assert_eq!(at(&[[3.0, 0.0, 4.0], [0.0; 3]]), 4.0);
    /// assert_eq!(tape.run(&[[3.0f32, 0.0, 4.0], [0.0; 3]], 1.0, |r| r.scalar(0)), 4.0f32);
    /// // Its gradient, by the backward pass: ∇p0 C is the unit vector from p1 to p0, and
    /// // ∇p1 C = −∇p0 C.
    /// let (value, [g0, g1]) = tape.gradient(&[[3.0f64, 0.0, 4.0], [0.0; 3]], 1.0);
    /// assert_eq!(value, 4.0);
    /// assert!((g0[0] - 0.6).abs() < 1e-15 && g0[1] == 0.0 && (g0[2] - 0.8).abs() < 1e-15);
    /// assert_eq!(g1, g0.map(|x| -x));
    /// ```
    pub fn tape(&self, outputs: &[usize]) -> Tape {
        let mut needed = vec![false; self.ops.len()];
        for &o in outputs {
            needed[self.outputs[o] as usize] = true;
        }
        for r in (0..self.ops.len()).rev() {
            if needed[r] {
                for input in self.ops[r].inputs() {
                    needed[input as usize] = true;
                }
            }
        }
        let mut map = vec![0 as Reg; self.ops.len()];
        let mut ops = Vec::new();
        for (r, op) in self.ops.iter().enumerate() {
            if needed[r] {
                map[r] = ops.len() as Reg;
                ops.push(op.renumbered(&map));
            }
        }
        Tape {
            ops,
            outputs: outputs
                .iter()
                .map(|&o| map[self.outputs[o] as usize])
                .collect(),
        }
    }

    fn push(&mut self, op: Op) -> Reg {
        self.ops.push(op);
        (self.ops.len() - 1) as Reg
    }

    fn compile(&mut self, expr: &Expr) -> Result<(Reg, Type), CompileError> {
        if self.ops.len() + 1 >= MAX_REGISTERS {
            return Err(CompileError {
                span: expr.span(),
                message: format!(
                    "the expressions are too long: more than {MAX_REGISTERS} operations in all"
                ),
            });
        }
        match expr {
            Expr::Number(x, span) => {
                if !x.is_finite() {
                    return Err(CompileError {
                        span: *span,
                        message: "the number is too large for f64".to_owned(),
                    });
                }
                Ok((self.push(Op::Const(*x)), Type::Scalar))
            }
            Expr::Name(name, span) => self.names.get(name).copied().ok_or_else(|| CompileError {
                span: *span,
                message: self.unknown(name),
            }),
            Expr::Neg(inner, _) => {
                let (a, ty) = self.compile(inner)?;
                let op = match ty {
                    Type::Scalar => Op::NegS(a),
                    Type::Vector => Op::NegV(a),
                };
                Ok((self.push(op), ty))
            }
            Expr::Binary(op, left, right, span) => {
                let (a, ta) = self.compile(left)?;
                let (b, tb) = self.compile(right)?;
                use Type::{Scalar as S, Vector as V};
                let (instruction, ty) = match (op, ta, tb) {
                    (BinaryOp::Add, S, S) => (Op::AddS(a, b), S),
                    (BinaryOp::Sub, S, S) => (Op::SubS(a, b), S),
                    (BinaryOp::Mul, S, S) => (Op::MulS(a, b), S),
                    (BinaryOp::Div, S, S) => (Op::DivS(a, b), S),
                    (BinaryOp::Add, V, V) => (Op::AddV(a, b), V),
                    (BinaryOp::Sub, V, V) => (Op::SubV(a, b), V),
                    (BinaryOp::Mul, V, S) => (Op::Scale(a, b), V),
                    (BinaryOp::Mul, S, V) => (Op::Scale(b, a), V),
                    (BinaryOp::Div, V, S) => (Op::Shrink(a, b), V),
                    _ => {
                        let hint = match op {
                            BinaryOp::Mul => "; for vectors use dot(a, b) or cross(a, b)",
                            BinaryOp::Div => "; only a vector divided by a scalar is defined",
                            _ => "",
                        };
                        return Err(CompileError {
                            span: *span,
                            message: format!(
                                "type error: {} {} {}{hint}",
                                ta.article(),
                                op.symbol(),
                                tb.article()
                            ),
                        });
                    }
                };
                Ok((self.push(instruction), ty))
            }
            Expr::Call {
                name,
                name_span,
                args,
                span,
            } => {
                let Some(&(_, params, result)) = FUNCTIONS.iter().find(|f| f.0 == name) else {
                    return Err(CompileError {
                        span: *name_span,
                        message: format!(
                            "unknown function `{name}`: the functions are {}",
                            FUNCTIONS.map(|f| f.0).join(", ")
                        ),
                    });
                };
                if args.len() != params.len() {
                    return Err(CompileError {
                        span: *span,
                        message: format!(
                            "`{name}` takes {} argument{}, and is given {}",
                            params.len(),
                            if params.len() == 1 { "" } else { "s" },
                            args.len()
                        ),
                    });
                }
                let mut regs = [0 as Reg; 3];
                for (k, (arg, &param)) in args.iter().zip(params).enumerate() {
                    let (reg, ty) = self.compile(arg)?;
                    if ty != param {
                        return Err(CompileError {
                            span: arg.span(),
                            message: format!(
                                "type error: argument {} of `{name}` must be {}, and this is {}",
                                k + 1,
                                param.article(),
                                ty.article()
                            ),
                        });
                    }
                    regs[k] = reg;
                }
                let [a, b, c] = regs;
                let op = match name.as_str() {
                    "dot" => Op::Dot(a, b),
                    "cross" => Op::Cross(a, b),
                    "length" => Op::Length(a),
                    "normalize" => Op::Normalize(a),
                    "sqrt" => Op::Sqrt(a),
                    "abs" => Op::Abs(a),
                    "min" => Op::Min(a, b),
                    "max" => Op::Max(a, b),
                    _ => Op::Det(a, b, c),
                };
                Ok((self.push(op), result))
            }
        }
    }

    fn unknown(&self, name: &str) -> String {
        if name
            .strip_prefix('p')
            .is_some_and(|k| k.parse::<usize>().is_ok())
        {
            let arity = (0..4)
                .filter(|i| self.names.contains_key(&format!("p{i}")))
                .count();
            return format!(
                "unknown name `{name}`: this binding has p0…p{} only",
                arity.saturating_sub(1)
            );
        }
        if name == "rest" {
            return "`rest` cannot be used here (the rest value is what this computes)".to_owned();
        }
        let mut known: Vec<&str> = self.names.keys().map(String::as_str).collect();
        known.sort_unstable();
        format!(
            "unknown name `{name}`: the names here are {}",
            known.join(", ")
        )
    }
}

/// What some outputs of a [`Program`] need, as flat single-assignment instructions: instruction k
/// defines register k from earlier registers.
#[derive(Clone, Debug, PartialEq)]
pub struct Tape {
    ops: Vec<Op>,
    outputs: Vec<Reg>,
}

/// The registers of a tape after [`Tape::run`]: read its outputs.
pub struct Registers<'a, T> {
    registers: &'a [[T; 3]],
    outputs: &'a [Reg],
}

impl<T: Copy> Registers<'_, T> {
    /// Output `i` of the tape as a scalar.
    pub fn scalar(&self, i: usize) -> T {
        self.registers[self.outputs[i] as usize][0]
    }

    /// Output `i` of the tape as a vector.
    pub fn vector(&self, i: usize) -> [T; 3] {
        self.registers[self.outputs[i] as usize]
    }
}

impl Tape {
    /// How many instructions (and registers) it has.
    pub fn len(&self) -> usize {
        self.ops.len()
    }

    /// Whether it has none.
    pub fn is_empty(&self) -> bool {
        self.ops.is_empty()
    }

    /// Runs the tape on `points` with `rest` and reads its outputs with `read`.
    #[inline]
    pub fn run<T: Real, R>(
        &self,
        points: &[[T; 3]],
        rest: T,
        read: impl FnOnce(&Registers<'_, T>) -> R,
    ) -> R {
        let mut registers = ArrayVec::new();
        self.forward(points, rest, &mut registers);
        read(&Registers {
            registers: &registers,
            outputs: &self.outputs,
        })
    }

    /// Output 0, C, and its gradient with respect to every particle, by reverse mode: the values
    /// forward, then r̄ = ∂C/∂r from C back to the particles, each instruction by the derivative
    /// rule of what it computes. Non-finite where the gradient is undefined (a zero vector's
    /// length or direction, a division by zero).
    #[inline]
    pub fn gradient<T: Real, const N: usize>(
        &self,
        points: &[[T; 3]; N],
        rest: T,
    ) -> (T, [[T; 3]; N]) {
        let mut r = ArrayVec::new();
        self.forward(points, rest, &mut r);
        let r = &r;
        let out = self.outputs[0] as usize;
        let mut adjoint: ArrayVec<[T; 3], MAX_REGISTERS> = ArrayVec::new();
        for _ in 0..=out {
            adjoint.push([T::ZERO; 3]);
        }
        adjoint[out][0] = T::ONE;
        let mut gradient = [[T::ZERO; 3]; N];
        for k in (0..=out).rev() {
            let bar = adjoint[k];
            let s = bar[0];
            let value = |i: Reg| r[i as usize];
            let mut add = |i: Reg, v: [T; 3]| {
                let a = &mut adjoint[i as usize];
                a[0] += v[0];
                a[1] += v[1];
                a[2] += v[2];
            };
            let scalar = |x: T| [x, T::ZERO, T::ZERO];
            match self.ops[k] {
                Op::Const(_) | Op::Rest => {}
                Op::Particle(p) => gradient[p as usize] = add3(gradient[p as usize], bar),
                Op::NegS(a) => add(a, scalar(-s)),
                Op::NegV(a) => add(a, scale(bar, -T::ONE)),
                Op::AddS(a, b) => {
                    add(a, scalar(s));
                    add(b, scalar(s));
                }
                Op::SubS(a, b) => {
                    add(a, scalar(s));
                    add(b, scalar(-s));
                }
                Op::MulS(a, b) => {
                    add(a, scalar(s * value(b)[0]));
                    add(b, scalar(s * value(a)[0]));
                }
                Op::DivS(a, b) => {
                    // r = a / b: ā += r̄ / b, b̄ −= r̄ r / b.
                    let d = value(b)[0];
                    add(a, scalar(s / d));
                    add(b, scalar(-(s * r[k][0]) / d));
                }
                Op::AddV(a, b) => {
                    add(a, bar);
                    add(b, bar);
                }
                Op::SubV(a, b) => {
                    add(a, bar);
                    add(b, scale(bar, -T::ONE));
                }
                Op::Scale(v, f) => {
                    // r = v f: v̄ += r̄ f, f̄ += r̄·v.
                    add(v, scale(bar, value(f)[0]));
                    add(f, scalar(dot(bar, value(v))));
                }
                Op::Shrink(v, f) => {
                    // r = v / f: v̄ += r̄ / f, f̄ −= r̄·r / f.
                    let d = value(f)[0];
                    add(v, shrink(bar, d));
                    add(f, scalar(-dot(bar, r[k]) / d));
                }
                Op::Dot(a, b) => {
                    add(a, scale(value(b), s));
                    add(b, scale(value(a), s));
                }
                Op::Cross(a, b) => {
                    // r = a × b: ā += b × r̄, b̄ += r̄ × a.
                    add(a, cross(value(b), bar));
                    add(b, cross(bar, value(a)));
                }
                Op::Length(a) => add(a, scale(value(a), s / r[k][0])),
                Op::Normalize(a) => {
                    // r = a / |a|: ā += (r̄ − r (r·r̄)) / |a|.
                    let n = r[k];
                    let length = dot(value(a), value(a)).sqrt();
                    let along = dot(n, bar);
                    add(a, shrink(sub3(bar, scale(n, along)), length));
                }
                Op::Sqrt(a) => add(a, scalar(s / (r[k][0] + r[k][0]))),
                Op::Abs(a) => {
                    let x = value(a)[0];
                    add(a, scalar(T::select(x.le(T::ZERO), -s, s)));
                }
                Op::Min(a, b) => {
                    let first = value(a)[0].le(value(b)[0]);
                    add(a, scalar(T::select(first, s, T::ZERO)));
                    add(b, scalar(T::select(first, T::ZERO, s)));
                }
                Op::Max(a, b) => {
                    let first = value(a)[0].gt(value(b)[0]);
                    add(a, scalar(T::select(first, s, T::ZERO)));
                    add(b, scalar(T::select(first, T::ZERO, s)));
                }
                Op::Det(a, b, c) => {
                    // r = a·(b × c): ā += r̄ b×c, b̄ += r̄ c×a, c̄ += r̄ a×b.
                    let (a_, b_, c_) = (value(a), value(b), value(c));
                    add(a, scale(cross(b_, c_), s));
                    add(b, scale(cross(c_, a_), s));
                    add(c, scale(cross(a_, b_), s));
                }
            }
        }
        (r[out][0], gradient)
    }

    /// Every register's value, instruction by instruction, into `r` (empty; the caller's, so
    /// that it is never moved).
    #[inline]
    fn forward<T: Real>(
        &self,
        points: &[[T; 3]],
        rest: T,
        r: &mut ArrayVec<[T; 3], MAX_REGISTERS>,
    ) {
        for op in &self.ops {
            let v = |i: Reg| r[i as usize];
            let s = |i: Reg| r[i as usize][0];
            let scalar = |x: T| [x, T::ZERO, T::ZERO];
            let value = match *op {
                Op::Const(x) => scalar(T::from_f64(x)),
                Op::Particle(k) => points[k as usize],
                Op::Rest => scalar(rest),
                Op::NegS(a) => scalar(-s(a)),
                Op::NegV(a) => scale(v(a), -T::ONE),
                Op::AddS(a, b) => scalar(s(a) + s(b)),
                Op::SubS(a, b) => scalar(s(a) - s(b)),
                Op::MulS(a, b) => scalar(s(a) * s(b)),
                Op::DivS(a, b) => scalar(s(a) / s(b)),
                Op::AddV(a, b) => add3(v(a), v(b)),
                Op::SubV(a, b) => sub3(v(a), v(b)),
                Op::Scale(a, b) => scale(v(a), s(b)),
                Op::Shrink(a, b) => shrink(v(a), s(b)),
                Op::Dot(a, b) => scalar(dot(v(a), v(b))),
                Op::Cross(a, b) => cross(v(a), v(b)),
                Op::Length(a) => scalar(dot(v(a), v(a)).sqrt()),
                Op::Normalize(a) => shrink(v(a), dot(v(a), v(a)).sqrt()),
                Op::Sqrt(a) => scalar(s(a).sqrt()),
                Op::Abs(a) => {
                    let x = s(a);
                    scalar(T::select(x.le(T::ZERO), -x, x))
                }
                Op::Min(a, b) => {
                    let (x, y) = (s(a), s(b));
                    scalar(T::select(x.le(y), x, y))
                }
                Op::Max(a, b) => {
                    let (x, y) = (s(a), s(b));
                    scalar(T::select(x.gt(y), x, y))
                }
                Op::Det(a, b, c) => scalar(dot(v(a), cross(v(b), v(c)))),
            };
            r.push(value);
        }
    }
}

#[inline(always)]
fn add3<T: Real>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline(always)]
fn sub3<T: Real>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
fn scale<T: Real>(a: [T; 3], k: T) -> [T; 3] {
    [a[0] * k, a[1] * k, a[2] * k]
}

#[inline(always)]
fn shrink<T: Real>(a: [T; 3], k: T) -> [T; 3] {
    [a[0] / k, a[1] / k, a[2] / k]
}

#[inline(always)]
fn dot<T: Real>(a: [T; 3], b: [T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn cross<T: Real>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
