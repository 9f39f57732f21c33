//! A constraint file's expressions, type-checked and compiled once into a flat list of
//! instructions over numbered registers ([`Program`]). Evaluating it allocates nothing (the
//! registers are the caller's, [`Program::registers`]) and is generic over the scalar type
//! ([`Real`]): f64, f32, SIMD lanes, or the dual numbers of automatic differentiation.

use super::expression::{BinaryOp, Expr, Span};
use crate::vector::Real;
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

type Reg = u16;

/// The most registers a program may use: [`super::ConstraintFile::evaluate_vectors`] keeps them
/// on the stack, so that an evaluation allocates nothing. Each operation takes one.
pub const MAX_REGISTERS: usize = 160;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Op {
    Const(Reg, f64),
    Particle(Reg, u8),
    Rest(Reg),
    NegS(Reg, Reg),
    NegV(Reg, Reg),
    AddS(Reg, Reg, Reg),
    SubS(Reg, Reg, Reg),
    MulS(Reg, Reg, Reg),
    DivS(Reg, Reg, Reg),
    AddV(Reg, Reg, Reg),
    SubV(Reg, Reg, Reg),
    /// vector × scalar.
    Scale(Reg, Reg, Reg),
    /// vector ÷ scalar.
    Shrink(Reg, Reg, Reg),
    Dot(Reg, Reg, Reg),
    Cross(Reg, Reg, Reg),
    Length(Reg, Reg),
    Normalize(Reg, Reg),
    Sqrt(Reg, Reg),
    Abs(Reg, Reg),
    Min(Reg, Reg, Reg),
    Max(Reg, Reg, Reg),
    Det(Reg, Reg, Reg, Reg),
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

/// Compiled expressions: the definitions, then outputs, each in a register.
#[derive(Clone, Debug, PartialEq)]
pub struct Program {
    ops: Vec<Op>,
    registers: usize,
    names: HashMap<String, (Reg, Type)>,
    outputs: Vec<(Reg, usize)>,
}

impl Program {
    /// A program whose names are p0…p(arity−1) (vectors) and, with `rest`, the scalar `rest`.
    pub fn new(arity: usize, rest: bool) -> Program {
        let mut program = Program {
            ops: Vec::new(),
            registers: 0,
            names: HashMap::new(),
            outputs: Vec::new(),
        };
        for k in 0..arity {
            let r = program.register();
            program.ops.push(Op::Particle(r, k as u8));
            program.names.insert(format!("p{k}"), (r, Type::Vector));
        }
        if rest {
            let r = program.register();
            program.ops.push(Op::Rest(r));
            program.names.insert("rest".to_owned(), (r, Type::Scalar));
        }
        program
    }

    /// How many registers an evaluation needs.
    pub fn registers(&self) -> usize {
        self.registers
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

    /// Adds an output of type `wanted`; returns its index for [`Program::output`].
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
        self.outputs.push((reg, self.ops.len()));
        Ok(self.outputs.len() - 1)
    }

    /// Runs the instructions up to output `last` (so that the later outputs cost nothing when
    /// only the first are wanted), on `points` with `rest`, into `registers` (at least
    /// [`Program::registers`] long).
    ///
    /// ```
    /// use tetlab_core::constraint_file::expression::parse_expression;
    /// use tetlab_core::constraint_file::program::{Program, Type};
    /// // C = |p0 − p1| − rest, the same program in f64 and in f32.
    /// let mut program = Program::new(2, true);
    /// let c = program.output(&parse_expression("length(p0 - p1) - rest").unwrap(), Type::Scalar, "value").unwrap();
    /// let mut registers = vec![[0.0f64; 3]; program.registers()];
    /// program.run(c, &[[3.0, 0.0, 4.0], [0.0; 3]], 1.0, &mut registers);
    /// assert_eq!(program.scalar(c, &registers), 4.0);
    /// let mut registers = vec![[0.0f32; 3]; program.registers()];
    /// program.run(c, &[[3.0, 0.0, 4.0], [0.0; 3]], 1.0, &mut registers);
    /// assert_eq!(program.scalar(c, &registers), 4.0f32);
    /// ```
    pub fn run<T: Real>(&self, last: usize, points: &[[T; 3]], rest: T, registers: &mut [[T; 3]]) {
        let end = self.outputs[last].1;
        for op in &self.ops[..end] {
            execute(op, points, rest, registers);
        }
    }

    /// Output `i` as a scalar, after [`Program::run`].
    pub fn scalar<T: Real>(&self, i: usize, registers: &[[T; 3]]) -> T {
        registers[self.outputs[i].0 as usize][0]
    }

    /// Output `i` as a vector, after [`Program::run`].
    pub fn vector<T: Real>(&self, i: usize, registers: &[[T; 3]]) -> [T; 3] {
        registers[self.outputs[i].0 as usize]
    }

    fn register(&mut self) -> Reg {
        self.registers += 1;
        (self.registers - 1) as Reg
    }

    fn compile(&mut self, expr: &Expr) -> Result<(Reg, Type), CompileError> {
        if self.registers + 1 >= MAX_REGISTERS {
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
                let r = self.register();
                self.ops.push(Op::Const(r, *x));
                Ok((r, Type::Scalar))
            }
            Expr::Name(name, span) => self.names.get(name).copied().ok_or_else(|| CompileError {
                span: *span,
                message: self.unknown(name),
            }),
            Expr::Neg(inner, _) => {
                let (a, ty) = self.compile(inner)?;
                let r = self.register();
                self.ops.push(match ty {
                    Type::Scalar => Op::NegS(r, a),
                    Type::Vector => Op::NegV(r, a),
                });
                Ok((r, ty))
            }
            Expr::Binary(op, left, right, span) => {
                let (a, ta) = self.compile(left)?;
                let (b, tb) = self.compile(right)?;
                let r = self.register();
                use Type::{Scalar as S, Vector as V};
                let (instruction, ty) = match (op, ta, tb) {
                    (BinaryOp::Add, S, S) => (Op::AddS(r, a, b), S),
                    (BinaryOp::Sub, S, S) => (Op::SubS(r, a, b), S),
                    (BinaryOp::Mul, S, S) => (Op::MulS(r, a, b), S),
                    (BinaryOp::Div, S, S) => (Op::DivS(r, a, b), S),
                    (BinaryOp::Add, V, V) => (Op::AddV(r, a, b), V),
                    (BinaryOp::Sub, V, V) => (Op::SubV(r, a, b), V),
                    (BinaryOp::Mul, V, S) => (Op::Scale(r, a, b), V),
                    (BinaryOp::Mul, S, V) => (Op::Scale(r, b, a), V),
                    (BinaryOp::Div, V, S) => (Op::Shrink(r, a, b), V),
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
                self.ops.push(instruction);
                Ok((r, ty))
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
                let r = self.register();
                let [a, b, c] = regs;
                self.ops.push(match name.as_str() {
                    "dot" => Op::Dot(r, a, b),
                    "cross" => Op::Cross(r, a, b),
                    "length" => Op::Length(r, a),
                    "normalize" => Op::Normalize(r, a),
                    "sqrt" => Op::Sqrt(r, a),
                    "abs" => Op::Abs(r, a),
                    "min" => Op::Min(r, a, b),
                    "max" => Op::Max(r, a, b),
                    _ => Op::Det(r, a, b, c),
                });
                Ok((r, result))
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

fn execute<T: Real>(op: &Op, points: &[[T; 3]], rest: T, r: &mut [[T; 3]]) {
    let s = |r: &[[T; 3]], i: Reg| r[i as usize][0];
    let v = |r: &[[T; 3]], i: Reg| r[i as usize];
    let scalar = |x: T| [x, T::ZERO, T::ZERO];
    let dot = |a: [T; 3], b: [T; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross = |a: [T; 3], b: [T; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let map = |a: [T; 3], f: &dyn Fn(T) -> T| [f(a[0]), f(a[1]), f(a[2])];
    let (dst, value) = match *op {
        Op::Const(d, x) => (d, scalar(T::from_f64(x))),
        Op::Particle(d, k) => (d, points[k as usize]),
        Op::Rest(d) => (d, scalar(rest)),
        Op::NegS(d, a) => (d, scalar(-s(r, a))),
        Op::NegV(d, a) => (d, map(v(r, a), &|x| -x)),
        Op::AddS(d, a, b) => (d, scalar(s(r, a) + s(r, b))),
        Op::SubS(d, a, b) => (d, scalar(s(r, a) - s(r, b))),
        Op::MulS(d, a, b) => (d, scalar(s(r, a) * s(r, b))),
        Op::DivS(d, a, b) => (d, scalar(s(r, a) / s(r, b))),
        Op::AddV(d, a, b) => {
            let (a, b) = (v(r, a), v(r, b));
            (d, [a[0] + b[0], a[1] + b[1], a[2] + b[2]])
        }
        Op::SubV(d, a, b) => {
            let (a, b) = (v(r, a), v(r, b));
            (d, [a[0] - b[0], a[1] - b[1], a[2] - b[2]])
        }
        Op::Scale(d, a, b) => {
            let k = s(r, b);
            (d, map(v(r, a), &|x| x * k))
        }
        Op::Shrink(d, a, b) => {
            let k = s(r, b);
            (d, map(v(r, a), &|x| x / k))
        }
        Op::Dot(d, a, b) => (d, scalar(dot(v(r, a), v(r, b)))),
        Op::Cross(d, a, b) => (d, cross(v(r, a), v(r, b))),
        Op::Length(d, a) => {
            let a = v(r, a);
            (d, scalar(dot(a, a).sqrt()))
        }
        Op::Normalize(d, a) => {
            let a = v(r, a);
            let l = dot(a, a).sqrt();
            (d, map(a, &|x| x / l))
        }
        Op::Sqrt(d, a) => (d, scalar(s(r, a).sqrt())),
        Op::Abs(d, a) => {
            let x = s(r, a);
            (d, scalar(T::select(x.le(T::ZERO), -x, x)))
        }
        Op::Min(d, a, b) => {
            let (x, y) = (s(r, a), s(r, b));
            (d, scalar(T::select(x.le(y), x, y)))
        }
        Op::Max(d, a, b) => {
            let (x, y) = (s(r, a), s(r, b));
            (d, scalar(T::select(x.gt(y), x, y)))
        }
        Op::Det(d, a, b, c) => (d, scalar(dot(v(r, a), cross(v(r, b), v(r, c))))),
    };
    r[dst as usize] = value;
}
