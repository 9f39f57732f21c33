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

use super::expression::{BinaryOp, CompareOp, Expr, Span};
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
    /// A number or (from folding) a constant vector; a scalar is `[x, 0, 0]`.
    Const([f64; 3]),
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
    Sin(Reg),
    Cos(Reg),
    Exp(Reg),
    Ln(Reg),
    /// atan2(y, x).
    Atan2(Reg, Reg),
    Asin(Reg),
    Acos(Reg),
    Cbrt(Reg),
    Sign(Reg),
    /// A vector's component 0, 1 or 2.
    Component(Reg, u8),
    Vec3(Reg, Reg, Reg),
    /// `if(a cmp b, then, otherwise)`, scalars or vectors.
    If(CompareOp, Reg, Reg, Reg, Reg),
}

impl Op {
    /// The same instruction with each register r it reads replaced by `f(r)`, in order.
    fn map_inputs(self, mut f: impl FnMut(Reg) -> Reg) -> Op {
        use Op::*;
        match self {
            Const(_) | Particle(_) | Rest => self,
            NegS(a) => NegS(f(a)),
            NegV(a) => NegV(f(a)),
            Length(a) => Length(f(a)),
            Normalize(a) => Normalize(f(a)),
            Sqrt(a) => Sqrt(f(a)),
            Abs(a) => Abs(f(a)),
            Sin(a) => Sin(f(a)),
            Cos(a) => Cos(f(a)),
            Exp(a) => Exp(f(a)),
            Ln(a) => Ln(f(a)),
            Asin(a) => Asin(f(a)),
            Acos(a) => Acos(f(a)),
            Cbrt(a) => Cbrt(f(a)),
            Sign(a) => Sign(f(a)),
            Component(a, i) => Component(f(a), i),
            AddS(a, b) => AddS(f(a), f(b)),
            SubS(a, b) => SubS(f(a), f(b)),
            MulS(a, b) => MulS(f(a), f(b)),
            DivS(a, b) => DivS(f(a), f(b)),
            AddV(a, b) => AddV(f(a), f(b)),
            SubV(a, b) => SubV(f(a), f(b)),
            Scale(a, b) => Scale(f(a), f(b)),
            Shrink(a, b) => Shrink(f(a), f(b)),
            Dot(a, b) => Dot(f(a), f(b)),
            Cross(a, b) => Cross(f(a), f(b)),
            Min(a, b) => Min(f(a), f(b)),
            Max(a, b) => Max(f(a), f(b)),
            Atan2(a, b) => Atan2(f(a), f(b)),
            Det(a, b, c) => Det(f(a), f(b), f(c)),
            Vec3(a, b, c) => Vec3(f(a), f(b), f(c)),
            If(cmp, a, b, t, e) => {
                let (a, b) = (f(a), f(b));
                let (t, e) = (f(t), f(e));
                If(cmp, a, b, t, e)
            }
        }
    }

    /// The registers it reads.
    fn inputs(self) -> ArrayVec<Reg, 4> {
        let mut out = ArrayVec::new();
        self.map_inputs(|r| {
            out.push(r);
            r
        });
        out
    }

    /// The same instruction reading `map[r]` for each register r it reads.
    fn renumbered(self, map: &[Reg]) -> Op {
        self.map_inputs(|r| map[r as usize])
    }

    /// Whether C has a kink (or a jump) where this instruction switches: the zeros of `abs`'s
    /// and `sign`'s argument, where `min`'s or `max`'s two agree, an `if`'s boundary.
    fn switches(self) -> bool {
        matches!(
            self,
            Op::Abs(_) | Op::Min(..) | Op::Max(..) | Op::Sign(_) | Op::If(..)
        )
    }

    /// Its value from the values `v` of the registers it reads, and the inputs.
    #[inline(always)]
    fn apply<T: Real>(self, v: impl Fn(Reg) -> [T; 3], points: &[[T; 3]], rest: T) -> [T; 3] {
        let s = |i: Reg| v(i)[0];
        let scalar = |x: T| [x, T::ZERO, T::ZERO];
        match self {
            Op::Const(x) => x.map(T::from_f64),
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
            Op::Sin(a) => scalar(s(a).sin()),
            Op::Cos(a) => scalar(s(a).cos()),
            Op::Exp(a) => scalar(s(a).exp()),
            Op::Ln(a) => scalar(s(a).ln()),
            Op::Atan2(y, x) => scalar(s(y).atan2(s(x))),
            Op::Asin(a) => scalar(s(a).asin()),
            Op::Acos(a) => scalar(s(a).acos()),
            Op::Cbrt(a) => scalar(s(a).cbrt()),
            Op::Sign(a) => {
                let x = s(a);
                let negative = T::select(T::ZERO.gt(x), -T::ONE, T::ZERO);
                scalar(T::select(x.gt(T::ZERO), T::ONE, negative))
            }
            Op::Component(a, i) => scalar(v(a)[i as usize]),
            Op::Vec3(a, b, c) => [s(a), s(b), s(c)],
            Op::If(cmp, a, b, t, e) => {
                let mask = holds(cmp, s(a), s(b));
                let (t, e) = (v(t), v(e));
                [0, 1, 2].map(|k| T::select(mask, t[k], e[k]))
            }
        }
    }

    /// Why its value is not finite, given the finite values `v` of what it reads.
    fn undefined(self, v: impl Fn(Reg) -> [f64; 3]) -> String {
        let s = |i: Reg| v(i)[0];
        match self {
            Op::DivS(_, b) | Op::Shrink(_, b) if s(b) == 0.0 => "division by zero".to_owned(),
            Op::Ln(a) => format!("log of {}: log is defined above 0", s(a)),
            Op::Sqrt(a) => format!("sqrt of {}: sqrt is defined from 0 up", s(a)),
            Op::Asin(a) => format!("asin of {}: asin is defined on -1..1", s(a)),
            Op::Acos(a) => format!("acos of {}: acos is defined on -1..1", s(a)),
            Op::Normalize(_) => "normalize of a zero vector: it has no direction".to_owned(),
            _ => "the result is too large for f64".to_owned(),
        }
    }
}

/// Whether `a cmp b` (false with a NaN).
#[inline(always)]
fn holds<T: Real>(cmp: CompareOp, a: T, b: T) -> T::Mask {
    match cmp {
        CompareOp::Less => b.gt(a),
        CompareOp::LessOrEqual => a.le(b),
        CompareOp::Greater => a.gt(b),
        CompareOp::GreaterOrEqual => b.le(a),
    }
}

/// A type an argument or result can be; `Same` is whatever the other branches of an `if` are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Param {
    Is(Type),
    /// A comparison `a < b`.
    Condition,
    /// A scalar or a vector, the same as the other `Same` arguments (and the result).
    Same,
}

use Param::{Condition, Is, Same};
const S: Param = Is(Type::Scalar);
const V: Param = Is(Type::Vector);

/// The functions of the language: name, arguments, result, and what it computes (the docs and
/// the message for an unknown function list them).
pub const FUNCTION_NAMES: [&str; 23] = {
    let mut names = [""; 23];
    let mut i = 0;
    while i < FUNCTIONS.len() {
        names[i] = FUNCTIONS[i].0;
        i += 1;
    }
    names
};

const FUNCTIONS: [(&str, &[Param], Param); 23] = [
    ("dot", &[V, V], S),
    ("cross", &[V, V], V),
    ("length", &[V], S),
    ("normalize", &[V], V),
    ("det", &[V, V, V], S),
    ("vec3", &[S, S, S], V),
    ("sqrt", &[S], S),
    ("cbrt", &[S], S),
    ("pow", &[S, S], S),
    ("exp", &[S], S),
    ("log", &[S], S),
    ("sin", &[S], S),
    ("cos", &[S], S),
    ("tan", &[S], S),
    ("asin", &[S], S),
    ("acos", &[S], S),
    ("atan2", &[S, S], S),
    ("abs", &[S], S),
    ("sign", &[S], S),
    ("min", &[S, S], S),
    ("max", &[S, S], S),
    ("clamp", &[S, S, S], S),
    ("if", &[Condition, Same, Same], Same),
];

/// Where an instruction came from: the expression (the byte of the file where its text starts,
/// [`Program::at`]) and the byte of that text, and what was written there (`/`, `acos`, `pow`),
/// for the message when it is undefined.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Origin {
    base: usize,
    offset: usize,
    what: &'static str,
}

/// The compiler of a file's expressions: the definitions, then its outputs (C, gradient
/// entries), each an instruction; [`Program::tape`] cuts out what some outputs need.
///
/// Instructions whose inputs are all constants are worked out as they are compiled (constant
/// folding), so that `1 / (1 - 1)` or `1e308 * 10` is an error at its place in the file rather
/// than a constraint undefined everywhere.
#[derive(Clone, Debug, PartialEq)]
pub struct Program {
    ops: Vec<Op>,
    origins: Vec<Origin>,
    names: HashMap<String, (Reg, Type)>,
    outputs: Vec<Reg>,
    /// Where in the file the expression being compiled starts ([`Program::at`]).
    base: usize,
}

impl Program {
    /// A program whose names are p0…p(arity−1) (vectors) and, with `rest`, the scalar `rest`.
    pub fn new(arity: usize, rest: bool) -> Program {
        let mut program = Program {
            ops: Vec::new(),
            origins: Vec::new(),
            names: HashMap::new(),
            outputs: Vec::new(),
            base: 0,
        };
        for k in 0..arity {
            let r = program.push(Op::Particle(k as u8), "a particle");
            program.names.insert(format!("p{k}"), (r, Type::Vector));
        }
        if rest {
            let r = program.push(Op::Rest, "rest");
            program.names.insert("rest".to_owned(), (r, Type::Scalar));
        }
        program
    }

    /// Says that the expressions compiled next start at byte `base` of the file: the tape's
    /// messages name their place ([`Tape::undefined_at`]).
    pub fn at(&mut self, base: usize) {
        self.base = base;
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
        let mut origins = Vec::new();
        for (r, op) in self.ops.iter().enumerate() {
            if needed[r] {
                map[r] = ops.len() as Reg;
                ops.push(op.renumbered(&map));
                origins.push(self.origins[r]);
            }
        }
        Tape {
            ops,
            origins,
            outputs: outputs
                .iter()
                .map(|&o| map[self.outputs[o] as usize])
                .collect(),
        }
    }

    fn push(&mut self, op: Op, what: &'static str) -> Reg {
        self.ops.push(op);
        self.origins.push(Origin {
            base: self.base,
            offset: 0,
            what,
        });
        (self.ops.len() - 1) as Reg
    }

    /// Adds `op`, from the text at `span` that `what` names, folded to a constant when every
    /// input is one; an error when that constant is not finite.
    fn emit(&mut self, op: Op, span: Span, what: &'static str) -> Result<Reg, CompileError> {
        if self.ops.len() + 1 >= MAX_REGISTERS {
            return Err(CompileError {
                span,
                message: format!(
                    "the expressions are too long: more than {MAX_REGISTERS} operations in all"
                ),
            });
        }
        let constant = |r: Reg| match self.ops[r as usize] {
            Op::Const(x) => Some(x),
            _ => None,
        };
        let inputs = op.inputs();
        if !inputs.is_empty() && inputs.iter().all(|&r| constant(r).is_some()) {
            let value = |r: Reg| constant(r).unwrap_or_default();
            let folded = op.apply::<f64>(value, &[], 0.0);
            if !folded.iter().all(|x| x.is_finite()) {
                return Err(CompileError {
                    span,
                    message: format!("`{what}` is undefined here: {}", op.undefined(value)),
                });
            }
            return self.emit_unfolded(Op::Const(folded), span, what);
        }
        self.emit_unfolded(op, span, what)
    }

    fn emit_unfolded(
        &mut self,
        op: Op,
        span: Span,
        what: &'static str,
    ) -> Result<Reg, CompileError> {
        self.ops.push(op);
        self.origins.push(Origin {
            base: self.base,
            offset: span.start,
            what,
        });
        Ok((self.ops.len() - 1) as Reg)
    }

    fn compile(&mut self, expr: &Expr) -> Result<(Reg, Type), CompileError> {
        use Type::{Scalar as S, Vector as V};
        match expr {
            Expr::Number(x, span) => {
                if !x.is_finite() {
                    return Err(CompileError {
                        span: *span,
                        message: "the number is too large for f64".to_owned(),
                    });
                }
                Ok((self.emit(Op::Const([*x, 0.0, 0.0]), *span, "a number")?, S))
            }
            Expr::Name(name, span) => self.names.get(name).copied().ok_or_else(|| CompileError {
                span: *span,
                message: self.unknown(name),
            }),
            Expr::Neg(inner, span) => {
                let (a, ty) = self.compile(inner)?;
                let op = match ty {
                    S => Op::NegS(a),
                    V => Op::NegV(a),
                };
                Ok((self.emit(op, *span, "-")?, ty))
            }
            Expr::Member(inner, component, span) => {
                let (a, ty) = self.compile(inner)?;
                let index = ["x", "y", "z"].iter().position(|c| c == component);
                match (ty, index) {
                    (V, Some(i)) => Ok((self.emit(Op::Component(a, i as u8), *span, ".")?, S)),
                    (V, None) => Err(CompileError {
                        span: *span,
                        message: format!("a vector has components .x, .y and .z, not .{component}"),
                    }),
                    (S, _) => Err(CompileError {
                        span: *span,
                        message: format!(
                            "type error: .{component} of a scalar (only a vector has components)"
                        ),
                    }),
                }
            }
            Expr::Compare(_, _, _, span) => Err(CompileError {
                span: *span,
                message: "a comparison can only be the condition of if(…): if(a < b, x, y)"
                    .to_owned(),
            }),
            Expr::Binary(op, left, right, span) => {
                let (a, ta) = self.compile(left)?;
                let (b, tb) = self.compile(right)?;
                if *op == BinaryOp::Div && self.ops[b as usize] == Op::Const([0.0; 3]) {
                    return Err(CompileError {
                        span: right.span(),
                        message: "division by zero: the divisor is 0 whatever the particles"
                            .to_owned(),
                    });
                }
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
                Ok((self.emit(instruction, *span, op.symbol())?, ty))
            }
            Expr::Call {
                name,
                name_span,
                args,
                span,
            } => self.call(name, *name_span, args, *span),
        }
    }

    /// A call of one of the [`FUNCTIONS`]: its arguments checked against what it takes, then
    /// its instructions (`tan`, `pow`, `clamp` are made of others).
    fn call(
        &mut self,
        name: &str,
        name_span: Span,
        args: &[Expr],
        span: Span,
    ) -> Result<(Reg, Type), CompileError> {
        let Some(&(what, params, result)) = FUNCTIONS.iter().find(|f| f.0 == name) else {
            return Err(CompileError {
                span: name_span,
                message: format!(
                    "unknown function `{name}`: the functions are {}",
                    FUNCTION_NAMES.join(", ")
                ),
            });
        };
        if args.len() != params.len() {
            return Err(CompileError {
                span,
                message: format!(
                    "`{name}` takes {} argument{}, and is given {}",
                    params.len(),
                    if params.len() == 1 { "" } else { "s" },
                    args.len()
                ),
            });
        }
        let mut regs = [0 as Reg; 3];
        let mut same = None;
        let mut condition = None;
        for (k, (arg, &param)) in args.iter().zip(params).enumerate() {
            let wrong = |ty: &str| CompileError {
                span: arg.span(),
                message: format!("type error: argument {} of `{name}` must be {ty}", k + 1),
            };
            match param {
                Condition => {
                    let Expr::Compare(cmp, a, b, _) = arg else {
                        return Err(wrong("a comparison, such as x < 0"));
                    };
                    let (ra, ta) = self.compile(a)?;
                    let (rb, tb) = self.compile(b)?;
                    if ta != Type::Scalar || tb != Type::Scalar {
                        return Err(wrong("a comparison of two scalars"));
                    }
                    condition = Some((*cmp, ra, rb));
                }
                Is(wanted) => {
                    let (reg, ty) = self.compile(arg)?;
                    if ty != wanted {
                        return Err(CompileError {
                            span: arg.span(),
                            message: format!(
                                "type error: argument {} of `{name}` must be {}, and this is {}",
                                k + 1,
                                wanted.article(),
                                ty.article()
                            ),
                        });
                    }
                    regs[k] = reg;
                }
                Same => {
                    let (reg, ty) = self.compile(arg)?;
                    if same.is_some_and(|t| t != ty) {
                        return Err(wrong("of the same type as the other branch"));
                    }
                    same = Some(ty);
                    regs[k] = reg;
                }
            }
        }
        let ty = match result {
            Is(t) => t,
            _ => same.unwrap_or(Type::Scalar),
        };
        let [a, b, c] = regs;
        let emit = |program: &mut Program, op| program.emit(op, span, what);
        let reg = match name {
            "dot" => emit(self, Op::Dot(a, b))?,
            "cross" => emit(self, Op::Cross(a, b))?,
            "length" => emit(self, Op::Length(a))?,
            "normalize" => emit(self, Op::Normalize(a))?,
            "det" => emit(self, Op::Det(a, b, c))?,
            "vec3" => emit(self, Op::Vec3(a, b, c))?,
            "sqrt" => emit(self, Op::Sqrt(a))?,
            "cbrt" => emit(self, Op::Cbrt(a))?,
            "exp" => emit(self, Op::Exp(a))?,
            "log" => emit(self, Op::Ln(a))?,
            "sin" => emit(self, Op::Sin(a))?,
            "cos" => emit(self, Op::Cos(a))?,
            "tan" => {
                let (sin, cos) = (emit(self, Op::Sin(a))?, emit(self, Op::Cos(a))?);
                emit(self, Op::DivS(sin, cos))?
            }
            "asin" => emit(self, Op::Asin(a))?,
            "acos" => emit(self, Op::Acos(a))?,
            "atan2" => emit(self, Op::Atan2(a, b))?,
            "abs" => emit(self, Op::Abs(a))?,
            "sign" => emit(self, Op::Sign(a))?,
            "min" => emit(self, Op::Min(a, b))?,
            "max" => emit(self, Op::Max(a, b))?,
            "clamp" => {
                let low = emit(self, Op::Max(a, b))?;
                emit(self, Op::Min(low, c))?
            }
            "pow" => self.pow(a, b, span)?,
            _ => {
                let (cmp, x, y) = condition.expect("if has a condition");
                emit(self, Op::If(cmp, x, y, b, c))?
            }
        };
        Ok((reg, ty))
    }

    /// aᵇ: for a whole constant b (|b| ≤ 64), products by repeated squaring (any a, exact
    /// derivatives); for b = ½, √a; otherwise exp(b log a), for a > 0.
    fn pow(&mut self, a: Reg, b: Reg, span: Span) -> Result<Reg, CompileError> {
        let exponent = match self.ops[b as usize] {
            Op::Const([x, ..]) => Some(x),
            _ => None,
        };
        match exponent {
            Some(n) if n.fract() == 0.0 && n.abs() <= 64.0 => {
                let mut k = n.abs() as u32;
                let mut result = None;
                let mut square = a;
                while k > 0 {
                    if k & 1 == 1 {
                        result = Some(match result {
                            None => square,
                            Some(r) => self.emit(Op::MulS(r, square), span, "pow")?,
                        });
                    }
                    k >>= 1;
                    if k > 0 {
                        square = self.emit(Op::MulS(square, square), span, "pow")?;
                    }
                }
                let one = self.emit(Op::Const([1.0, 0.0, 0.0]), span, "pow")?;
                let positive = result.unwrap_or(one);
                if n < 0.0 {
                    self.emit(Op::DivS(one, positive), span, "pow")
                } else {
                    Ok(positive)
                }
            }
            Some(half) if half == 0.5 => self.emit(Op::Sqrt(a), span, "pow"),
            _ => {
                let log = self.emit(Op::Ln(a), span, "pow")?;
                let product = self.emit(Op::MulS(b, log), span, "pow")?;
                self.emit(Op::Exp(product), span, "pow")
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
    origins: Vec<Origin>,
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

    /// The first instruction, in evaluation order, whose value is not finite while what it reads
    /// is, at `points` with `rest`: where and why C is undefined there. `None` where every value
    /// is finite.
    pub fn undefined_at(&self, points: &[[f64; 3]], rest: f64) -> Option<Undefined> {
        let mut r: ArrayVec<[f64; 3], MAX_REGISTERS> = ArrayVec::new();
        for (op, origin) in self.ops.iter().zip(&self.origins) {
            let value = op.apply(|i| r[i as usize], points, rest);
            let finite = |v: &[f64; 3]| v.iter().all(|x| x.is_finite());
            if !finite(&value) && op.inputs().iter().all(|&i| finite(&r[i as usize])) {
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
            r.push(value);
        }
        None
    }

    /// Where C may have a kink or a jump: for each `abs`, `sign`, `min`, `max`, `clamp` and
    /// `if` on C's path, where it is (as [`Undefined`] says) and what it is, with the value at
    /// `points` of what decides it (the argument of `abs`, the difference of `min`'s two, the
    /// two sides of a condition): the kink is where that value is 0.
    pub fn switches_at(&self, points: &[[f64; 3]], rest: f64) -> Vec<Switch> {
        let mut r: ArrayVec<[f64; 3], MAX_REGISTERS> = ArrayVec::new();
        let mut out = Vec::new();
        for (op, origin) in self.ops.iter().zip(&self.origins) {
            if op.switches() {
                let s = |i: Reg| r[i as usize][0];
                let decides = match *op {
                    Op::Abs(a) | Op::Sign(a) => s(a),
                    Op::Min(a, b) | Op::Max(a, b) => s(a) - s(b),
                    Op::If(_, a, b, ..) => s(a) - s(b),
                    _ => f64::NAN,
                };
                out.push(Switch {
                    base: origin.base,
                    offset: origin.offset,
                    what: origin.what,
                    decides,
                });
            }
            r.push(op.apply(|i| r[i as usize], points, rest));
        }
        out
    }

    /// Output 0, C, and its gradient with respect to every particle, by reverse mode: the values
    /// forward, then r̄ = ∂C/∂r from C back to the particles, each instruction by the derivative
    /// rule of what it computes. Non-finite where the gradient is undefined (a zero vector's
    /// length or direction, a division by zero, `acos` at ±1).
    ///
    /// Generic over [`Real`]: run on [`crate::numbers::dual::Tangent`] numbers it gives the
    /// derivative of the gradient along the tangents, a column of the Hessian.
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
            let x = |i: Reg| r[i as usize][0];
            let mut add = |i: Reg, v: [T; 3]| {
                let a = &mut adjoint[i as usize];
                a[0] += v[0];
                a[1] += v[1];
                a[2] += v[2];
            };
            let scalar = |x: T| [x, T::ZERO, T::ZERO];
            match self.ops[k] {
                Op::Const(_) | Op::Rest | Op::Sign(_) => {}
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
                    add(a, scalar(s * x(b)));
                    add(b, scalar(s * x(a)));
                }
                Op::DivS(a, b) => {
                    // r = a / b: ā += r̄ / b, b̄ −= r̄ r / b.
                    let d = x(b);
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
                    add(v, scale(bar, x(f)));
                    add(f, scalar(dot(bar, value(v))));
                }
                Op::Shrink(v, f) => {
                    // r = v / f: v̄ += r̄ / f, f̄ −= r̄·r / f.
                    let d = x(f);
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
                Op::Abs(a) => add(a, scalar(T::select(x(a).le(T::ZERO), -s, s))),
                Op::Min(a, b) => {
                    let first = x(a).le(x(b));
                    add(a, scalar(T::select(first, s, T::ZERO)));
                    add(b, scalar(T::select(first, T::ZERO, s)));
                }
                Op::Max(a, b) => {
                    let first = x(a).gt(x(b));
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
                // r = sin a: ā += r̄ cos a; r = cos a: ā −= r̄ sin a.
                Op::Sin(a) => add(a, scalar(s * x(a).cos())),
                Op::Cos(a) => add(a, scalar(-(s * x(a).sin()))),
                // r = eᵃ: ā += r̄ r; r = log a: ā += r̄ / a.
                Op::Exp(a) => add(a, scalar(s * r[k][0])),
                Op::Ln(a) => add(a, scalar(s / x(a))),
                Op::Atan2(y, x_) => {
                    // r = atan2(y, x): ȳ += r̄ x / (x² + y²), x̄ −= r̄ y / (x² + y²).
                    let (yv, xv) = (x(y), x(x_));
                    let d = xv * xv + yv * yv;
                    add(y, scalar(s * xv / d));
                    add(x_, scalar(-(s * yv) / d));
                }
                // r = asin a: ā += r̄ / √(1 − a²); r = acos a: ā −= r̄ / √(1 − a²).
                Op::Asin(a) => add(a, scalar(s / (T::ONE - x(a) * x(a)).sqrt())),
                Op::Acos(a) => add(a, scalar(-(s / (T::ONE - x(a) * x(a)).sqrt()))),
                // r = ∛a: ā += r̄ / (3 r²).
                Op::Cbrt(a) => add(a, scalar(s / (T::from_f64(3.0) * r[k][0] * r[k][0]))),
                Op::Component(a, i) => {
                    let mut v = [T::ZERO; 3];
                    v[i as usize] = s;
                    add(a, v);
                }
                Op::Vec3(a, b, c) => {
                    add(a, scalar(bar[0]));
                    add(b, scalar(bar[1]));
                    add(c, scalar(bar[2]));
                }
                Op::If(cmp, a, b, t, e) => {
                    let mask = holds(cmp, x(a), x(b));
                    add(t, bar.map(|v| T::select(mask, v, T::ZERO)));
                    add(e, bar.map(|v| T::select(mask, T::ZERO, v)));
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
            let value = op.apply(|i| r[i as usize], points, rest);
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
