//! How an expression of a constraint file becomes instructions of its [`Program`]: the
//! functions of the language and their types ([`FUNCTIONS`]), the names a file may use without
//! defining them ([`GIVEN_NAMES`]), and the compilation of numbers, names, members (`v.x`, `M.c0`),
//! operators and calls, matrices compiled column by column.

use super::op::{Op, Reg};
use super::{CompileError, Program, Type, Value};
use crate::constraint_file::expression::{BinaryOp, Expr, Span};

/// A type an argument or result can be; `Same` is whatever the other branches of an `if` are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Param {
    Is(Type),
    /// A comparison `a < b`.
    Condition,
    /// A scalar or a vector, the same as the other `Same` arguments (and the result).
    Same,
}

use Param::{Condition, Is, Same};
const S: Param = Is(Type::Scalar);
const V: Param = Is(Type::Vector);
const M: Param = Is(Type::Matrix);

/// The functions of the language: name, arguments and result (`det` also takes one matrix).
pub(super) const FUNCTIONS: [(&str, &[Param], Param); 30] = [
    ("dot", &[V, V], S),
    ("cross", &[V, V], V),
    ("length", &[V], S),
    ("normalize", &[V], V),
    ("det", &[V, V, V], S),
    ("vec3", &[S, S, S], V),
    ("mat3", &[V, V, V], M),
    ("outer", &[V, V], M),
    ("transpose", &[M], M),
    ("inverse", &[M], M),
    ("trace", &[M], S),
    ("norm", &[M], S),
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
    ("select", &[Condition, Same, Same], Same),
];

/// The names of the functions, for the message for an unknown one.
fn function_names() -> impl Iterator<Item = &'static str> {
    FUNCTIONS.iter().map(|f| f.0).filter(|&f| f != "select")
}

/// Names a program knows without a definition, made when first used: the rest shape, the
/// material and the identity. `(name, what it is)`.
pub(crate) const GIVEN_NAMES: [(&str, &str); 9] = [
    ("q0", "the rest position of p0 (q1, q2, q3 likewise)"),
    (
        "Dm",
        "the rest edges [q1 - q0, q2 - q0, q3 - q0] as columns",
    ),
    ("Ds", "the edges [p1 - p0, p2 - p0, p3 - p0] as columns"),
    ("F", "the deformation gradient Ds inverse(Dm)"),
    ("V0", "the rest volume det(Dm) / 6"),
    (
        "mu",
        "the material's shear modulus μ (Lamé's second parameter)",
    ),
    ("lambda", "the material's λ (Lamé's first parameter)"),
    (
        "gamma",
        "1 + mu / lambda, the neo-Hookean rest value of det F",
    ),
    ("I", "the 3 × 3 identity"),
];

impl Program {
    /// `op` applied to each column of matrix `m` (`column` gives the instruction for one).
    fn columns(
        &mut self,
        m: Value,
        span: Span,
        what: &'static str,
        column: impl Fn(Reg) -> Op,
    ) -> Result<Value, CompileError> {
        let mut out = [0; 3];
        for (j, slot) in out.iter_mut().enumerate() {
            *slot = self.emit(column(m.r[j]), span, what)?;
        }
        Ok(Value::matrix(out))
    }

    /// M v = Σⱼ cⱼ vⱼ, one instruction ([`Op::MatVec`]).
    fn times_vector(&mut self, m: Value, v: Reg, span: Span) -> Result<Reg, CompileError> {
        let [c0, c1, c2] = m.r;
        self.emit(Op::MatVec(c0, c1, c2, v), span, "*")
    }

    /// Mᵀ: its rows as columns.
    fn transpose(&mut self, m: Value, span: Span) -> Result<Value, CompileError> {
        let mut rows = [0; 3];
        for (i, row) in rows.iter_mut().enumerate() {
            let mut entries = [0; 3];
            for (j, entry) in entries.iter_mut().enumerate() {
                *entry = self.emit(Op::Component(m.r[j], i as u8), span, "transpose")?;
            }
            *row = self.emit(
                Op::Vec3(entries[0], entries[1], entries[2]),
                span,
                "transpose",
            )?;
        }
        Ok(Value::matrix(rows))
    }

    /// M⁻¹: the rows (c₁×c₂, c₂×c₀, c₀×c₁) / det M, transposed into columns.
    fn inverse(&mut self, m: Value, span: Span) -> Result<Value, CompileError> {
        let [c0, c1, c2] = m.r;
        let det = self.emit(Op::Det(c0, c1, c2), span, "inverse")?;
        let mut rows = [0; 3];
        for (k, (a, b)) in [(c1, c2), (c2, c0), (c0, c1)].into_iter().enumerate() {
            let cross = self.emit(Op::Cross(a, b), span, "inverse")?;
            rows[k] = self.emit(Op::Shrink(cross, det), span, "inverse")?;
        }
        self.transpose(Value::matrix(rows), span)
    }

    /// `expr` compiled into instructions: its value, typed.
    pub(super) fn compile(&mut self, expr: &Expr) -> Result<Value, CompileError> {
        use Type::{Matrix as Mx, Scalar as Sc, Vector as Vc};
        match expr {
            Expr::Number(x, span) => {
                if !x.is_finite() {
                    return Err(CompileError {
                        span: *span,
                        message: "the number is too large for f64".to_owned(),
                    });
                }
                Ok(Value::scalar(self.emit(
                    Op::Const(*x),
                    *span,
                    "a number",
                )?))
            }
            Expr::Name(name, span) => match self.names.get(name) {
                Some(&value) => Ok(value),
                None => match self.given(name, *span)? {
                    Some(value) => {
                        self.names.insert(name.clone(), value);
                        Ok(value)
                    }
                    None => Err(CompileError {
                        span: *span,
                        message: self.unknown(name),
                    }),
                },
            },
            Expr::Neg(inner, span) => {
                let a = self.compile(inner)?;
                match a.ty {
                    Sc => Ok(Value::scalar(self.emit(Op::NegS(a.r[0]), *span, "-")?)),
                    Vc => Ok(Value::vector(self.emit(Op::NegV(a.r[0]), *span, "-")?)),
                    Mx => self.columns(a, *span, "-", Op::NegV),
                }
            }
            Expr::Member(inner, component, span) => {
                let a = self.compile(inner)?;
                self.member(a, component, *span)
            }
            Expr::Compare(_, _, _, span) => Err(CompileError {
                span: *span,
                message: "a comparison can only be the condition of if(…): if(a < b, x, y)"
                    .to_owned(),
            }),
            Expr::Binary(op, left, right, span) => {
                let a = self.compile(left)?;
                let b = self.compile(right)?;
                let (x, y) = (a.r[0], b.r[0]);
                if *op == BinaryOp::Div && self.ops[y as usize] == Op::Const(0.0) {
                    return Err(CompileError {
                        span: right.span(),
                        message: "division by zero: the divisor is 0 whatever the particles"
                            .to_owned(),
                    });
                }
                let what = op.symbol();
                let single = |program: &mut Program, op, ty| -> Result<Value, CompileError> {
                    let r = program.emit(op, *span, what)?;
                    Ok(Value { r: [r; 3], ty })
                };
                match (op, a.ty, b.ty) {
                    (BinaryOp::Add, Sc, Sc) => single(self, Op::AddS(x, y), Sc),
                    (BinaryOp::Sub, Sc, Sc) => single(self, Op::SubS(x, y), Sc),
                    (BinaryOp::Mul, Sc, Sc) => single(self, Op::MulS(x, y), Sc),
                    (BinaryOp::Div, Sc, Sc) => single(self, Op::DivS(x, y), Sc),
                    (BinaryOp::Add, Vc, Vc) => single(self, Op::AddV(x, y), Vc),
                    (BinaryOp::Sub, Vc, Vc) => single(self, Op::SubV(x, y), Vc),
                    (BinaryOp::Mul, Vc, Sc) => single(self, Op::Scale(x, y), Vc),
                    (BinaryOp::Mul, Sc, Vc) => single(self, Op::Scale(y, x), Vc),
                    (BinaryOp::Div, Vc, Sc) => single(self, Op::Shrink(x, y), Vc),
                    (BinaryOp::Add, Mx, Mx) | (BinaryOp::Sub, Mx, Mx) => {
                        let mut out = [0; 3];
                        for (slot, (&x, &y)) in out.iter_mut().zip(a.r.iter().zip(&b.r)) {
                            let instruction = if *op == BinaryOp::Add {
                                Op::AddV(x, y)
                            } else {
                                Op::SubV(x, y)
                            };
                            *slot = self.emit(instruction, *span, what)?;
                        }
                        Ok(Value::matrix(out))
                    }
                    (BinaryOp::Mul, Mx, Sc) => self.columns(a, *span, what, |c| Op::Scale(c, y)),
                    (BinaryOp::Mul, Sc, Mx) => self.columns(b, *span, what, |c| Op::Scale(c, x)),
                    (BinaryOp::Div, Mx, Sc) => self.columns(a, *span, what, |c| Op::Shrink(c, y)),
                    (BinaryOp::Mul, Mx, Vc) => Ok(Value::vector(self.times_vector(a, y, *span)?)),
                    (BinaryOp::Mul, Mx, Mx) => {
                        let mut out = [0; 3];
                        for (j, slot) in out.iter_mut().enumerate() {
                            *slot = self.times_vector(a, b.r[j], *span)?;
                        }
                        Ok(Value::matrix(out))
                    }
                    _ => {
                        let hint = match op {
                            BinaryOp::Mul => {
                                "; for two vectors use dot(a, b), cross(a, b) or outer(a, b)"
                            }
                            BinaryOp::Div => {
                                "; only a vector or a matrix divided by a scalar is defined"
                            }
                            _ => "",
                        };
                        Err(CompileError {
                            span: *span,
                            message: format!(
                                "type error: {} {} {}{hint}",
                                a.ty.article(),
                                op.symbol(),
                                b.ty.article()
                            ),
                        })
                    }
                }
            }
            Expr::Call {
                name,
                name_span,
                args,
                span,
            } => self.call(name, *name_span, args, *span),
        }
    }

    /// `a.x` and the like: a vector's components; a matrix's columns `.c0`…, rows `.r0`… and
    /// entries `.xy` (row x, column y).
    fn member(&mut self, a: Value, component: &str, span: Span) -> Result<Value, CompileError> {
        let axis = |c: char| "xyz".find(c);
        match a.ty {
            Type::Vector => match component.chars().next().and_then(axis) {
                Some(i) if component.len() == 1 => Ok(Value::scalar(self.emit(
                    Op::Component(a.r[0], i as u8),
                    span,
                    ".",
                )?)),
                _ => Err(CompileError {
                    span,
                    message: format!("a vector has components .x, .y and .z, not .{component}"),
                }),
            },
            Type::Matrix => {
                let mut chars = component.chars();
                let (first, second) = (chars.next(), chars.next());
                let digit = |c: Option<char>| c.and_then(|c| c.to_digit(10)).filter(|&d| d < 3);
                match (first, second, component.len()) {
                    (Some('c'), d, 2) if digit(d).is_some() => {
                        Ok(Value::vector(a.r[digit(d).unwrap_or(0) as usize]))
                    }
                    (Some('r'), d, 2) if digit(d).is_some() => {
                        let rows = self.transpose(a, span)?;
                        Ok(Value::vector(rows.r[digit(d).unwrap_or(0) as usize]))
                    }
                    (Some(x), Some(y), 2) if axis(x).is_some() && axis(y).is_some() => {
                        let (i, j) = (axis(x).unwrap_or(0), axis(y).unwrap_or(0));
                        Ok(Value::scalar(self.emit(
                            Op::Component(a.r[j], i as u8),
                            span,
                            ".",
                        )?))
                    }
                    _ => Err(CompileError {
                        span,
                        message: format!(
                            "a matrix has columns .c0 .c1 .c2, rows .r0 .r1 .r2 and entries \
                             .xx .xy … .zz (row, column), not .{component}"
                        ),
                    }),
                }
            }
            Type::Scalar => Err(CompileError {
                span,
                message: format!(
                    "type error: .{component} of a scalar (only a vector or a matrix has components)"
                ),
            }),
        }
    }

    /// A name the program knows without a definition ([`GIVEN_NAMES`]), made now; `None` for
    /// any other.
    fn given(&mut self, name: &str, span: Span) -> Result<Option<Value>, CompileError> {
        let rest_particle = name
            .strip_prefix('q')
            .and_then(|k| k.parse::<usize>().ok())
            .filter(|&k| k < self.arity && name.len() == 2);
        if let Some(k) = rest_particle {
            return Ok(Some(Value::vector(self.emit(
                Op::RestParticle(k as u8),
                span,
                "a rest position",
            )?)));
        }
        let material = ["mu", "lambda", "gamma"].iter().position(|&m| m == name);
        if let Some(k) = material {
            return Ok(Some(Value::scalar(self.emit(
                Op::Material(k as u8),
                span,
                "the material",
            )?)));
        }
        if name == "I" {
            let mut columns = [0; 3];
            for (j, column) in columns.iter_mut().enumerate() {
                let mut e = [0.0; 3];
                e[j] = 1.0;
                *column = self.emit(Op::ConstVector(e), span, "I")?;
            }
            return Ok(Some(Value::matrix(columns)));
        }
        if !matches!(name, "Dm" | "Ds" | "F" | "V0") {
            return Ok(None);
        }
        if self.arity != 4 {
            return Err(CompileError {
                span,
                message: format!(
                    "`{name}` is a tet's: this binding has {} particles, p0…p{}",
                    ["no", "one", "two", "three"][self.arity.min(3)],
                    self.arity.saturating_sub(1)
                ),
            });
        }
        let edges = |program: &mut Program, corner: fn(u8) -> Op, what| {
            let origin = program.emit(corner(0), span, what)?;
            let mut columns = [0; 3];
            for (k, column) in columns.iter_mut().enumerate() {
                let p = program.emit(corner(k as u8 + 1), span, what)?;
                *column = program.emit(Op::SubV(p, origin), span, what)?;
            }
            Ok::<_, CompileError>(Value::matrix(columns))
        };
        let value = match name {
            "Dm" => edges(self, Op::RestParticle, "Dm")?,
            "Ds" => edges(self, Op::Particle, "Ds")?,
            "V0" => {
                let dm = edges(self, Op::RestParticle, "V0")?;
                let det = self.emit(Op::Det(dm.r[0], dm.r[1], dm.r[2]), span, "V0")?;
                let six = self.emit(Op::Const(6.0), span, "V0")?;
                Value::scalar(self.emit(Op::DivS(det, six), span, "V0")?)
            }
            _ => {
                let ds = edges(self, Op::Particle, "F")?;
                let dm = edges(self, Op::RestParticle, "F")?;
                let inverse = self.inverse(dm, span)?;
                let mut columns = [0; 3];
                for (j, column) in columns.iter_mut().enumerate() {
                    *column = self.times_vector(ds, inverse.r[j], span)?;
                }
                Value::matrix(columns)
            }
        };
        Ok(Some(value))
    }

    /// A call of one of the [`FUNCTIONS`]: its arguments checked against what it takes, then
    /// its instructions (`tan`, `pow`, `clamp` and the matrix functions are made of others).
    fn call(
        &mut self,
        name: &str,
        name_span: Span,
        args: &[Expr],
        span: Span,
    ) -> Result<Value, CompileError> {
        let Some(&(what, params, _)) = FUNCTIONS.iter().find(|f| f.0 == name) else {
            return Err(CompileError {
                span: name_span,
                message: format!(
                    "unknown function `{name}`: the functions are {}",
                    function_names().collect::<Vec<_>>().join(", ")
                ),
            });
        };
        // det(M) as well as det(a, b, c).
        let params: &[Param] = if name == "det" && args.len() == 1 {
            &[M]
        } else {
            params
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
        let mut values = [Value::scalar(0); 3];
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
                    let (a, b) = (self.compile(a)?, self.compile(b)?);
                    if a.ty != Type::Scalar || b.ty != Type::Scalar {
                        return Err(wrong("a comparison of two scalars"));
                    }
                    condition = Some((*cmp, a.r[0], b.r[0]));
                }
                Is(wanted) => {
                    let value = self.compile(arg)?;
                    if value.ty != wanted {
                        return Err(CompileError {
                            span: arg.span(),
                            message: format!(
                                "type error: argument {} of `{name}` must be {}, and this is {}",
                                k + 1,
                                wanted.article(),
                                value.ty.article()
                            ),
                        });
                    }
                    values[k] = value;
                }
                Same => {
                    let value = self.compile(arg)?;
                    if value.ty == Type::Matrix {
                        return Err(wrong("a scalar or a vector"));
                    }
                    if same.is_some_and(|t| t != value.ty) {
                        return Err(wrong("of the same type as the other branch"));
                    }
                    same = Some(value.ty);
                    values[k] = value;
                }
            }
        }
        let [a, b, c] = values.map(|v| v.r[0]);
        let scalar = |program: &mut Program, op| Ok(Value::scalar(program.emit(op, span, what)?));
        let vector = |program: &mut Program, op| Ok(Value::vector(program.emit(op, span, what)?));
        match name {
            "dot" => scalar(self, Op::Dot(a, b)),
            "cross" => vector(self, Op::Cross(a, b)),
            "length" => scalar(self, Op::Length(a)),
            "normalize" => vector(self, Op::Normalize(a)),
            "det" if values[0].ty == Type::Matrix => {
                let [c0, c1, c2] = values[0].r;
                scalar(self, Op::Det(c0, c1, c2))
            }
            "det" => scalar(self, Op::Det(a, b, c)),
            "vec3" => vector(self, Op::Vec3(a, b, c)),
            "mat3" => Ok(Value::matrix([a, b, c])),
            "outer" => {
                // a bᵀ: column j is a bⱼ.
                let mut columns = [0; 3];
                for (j, column) in columns.iter_mut().enumerate() {
                    let bj = self.emit(Op::Component(b, j as u8), span, what)?;
                    *column = self.emit(Op::Scale(a, bj), span, what)?;
                }
                Ok(Value::matrix(columns))
            }
            "transpose" => self.transpose(values[0], span),
            "inverse" => self.inverse(values[0], span),
            "trace" => {
                let [c0, c1, c2] = values[0].r;
                let x = self.emit(Op::Component(c0, 0), span, what)?;
                let y = self.emit(Op::Component(c1, 1), span, what)?;
                let z = self.emit(Op::Component(c2, 2), span, what)?;
                let xy = self.emit(Op::AddS(x, y), span, what)?;
                scalar(self, Op::AddS(xy, z))
            }
            "norm" => {
                // ‖M‖_F = √(Σⱼ cⱼ·cⱼ).
                let [c0, c1, c2] = values[0].r;
                let x = self.emit(Op::Dot(c0, c0), span, what)?;
                let y = self.emit(Op::Dot(c1, c1), span, what)?;
                let z = self.emit(Op::Dot(c2, c2), span, what)?;
                let xy = self.emit(Op::AddS(x, y), span, what)?;
                let sum = self.emit(Op::AddS(xy, z), span, what)?;
                scalar(self, Op::Sqrt(sum))
            }
            "sqrt" => scalar(self, Op::Sqrt(a)),
            "cbrt" => scalar(self, Op::Cbrt(a)),
            "exp" => scalar(self, Op::Exp(a)),
            "log" => scalar(self, Op::Ln(a)),
            "sin" => scalar(self, Op::Sin(a)),
            "cos" => scalar(self, Op::Cos(a)),
            "tan" => {
                let (sin, cos) = (
                    self.emit(Op::Sin(a), span, what)?,
                    self.emit(Op::Cos(a), span, what)?,
                );
                scalar(self, Op::DivS(sin, cos))
            }
            "asin" => scalar(self, Op::Asin(a)),
            "acos" => scalar(self, Op::Acos(a)),
            "atan2" => scalar(self, Op::Atan2(a, b)),
            "abs" => scalar(self, Op::Abs(a)),
            "sign" => scalar(self, Op::Sign(a)),
            "min" => scalar(self, Op::Min(a, b)),
            "max" => scalar(self, Op::Max(a, b)),
            "clamp" => {
                let low = self.emit(Op::Max(a, b), span, what)?;
                scalar(self, Op::Min(low, c))
            }
            "pow" => Ok(Value::scalar(self.pow(a, b, span)?)),
            _ => {
                let (cmp, x, y) = condition.expect("if has a condition");
                let op = if same == Some(Type::Vector) {
                    Op::IfVector(cmp, x, y, b, c)
                } else {
                    Op::If(cmp, x, y, b, c)
                };
                let r = self.emit(op, span, "if")?;
                Ok(Value {
                    r: [r; 3],
                    ty: same.unwrap_or(Type::Scalar),
                })
            }
        }
    }

    /// aᵇ: for a whole constant b (|b| ≤ 64), products by repeated squaring (any a, exact
    /// derivatives); for b = ½, √a; otherwise exp(b log a), for a > 0.
    fn pow(&mut self, a: Reg, b: Reg, span: Span) -> Result<Reg, CompileError> {
        let exponent = match self.ops[b as usize] {
            Op::Const(x) => Some(x),
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
                let one = self.emit(Op::Const(1.0), span, "pow")?;
                let positive = result.unwrap_or(one);
                if n < 0.0 {
                    self.emit(Op::DivS(one, positive), span, "pow")
                } else {
                    Ok(positive)
                }
            }
            Some(0.5) => self.emit(Op::Sqrt(a), span, "pow"),
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
            .or_else(|| name.strip_prefix('q'))
            .is_some_and(|k| k.parse::<usize>().is_ok())
        {
            let letter = &name[..1];
            return format!(
                "unknown name `{name}`: this binding has {letter}0…{letter}{} only",
                self.arity.saturating_sub(1)
            );
        }
        if name == "rest" {
            return "`rest` cannot be used here (the rest value is what this computes)".to_owned();
        }
        let mut known: Vec<&str> = self.names.keys().map(String::as_str).collect();
        known.sort_unstable();
        let given: Vec<&str> = GIVEN_NAMES
            .iter()
            .map(|g| g.0)
            .filter(|g| self.arity == 4 || !matches!(*g, "Dm" | "Ds" | "F" | "V0"))
            .collect();
        format!(
            "unknown name `{name}`: the names here are {}, and {} (the rest shape, the material)",
            known.join(", "),
            given.join(", ")
        )
    }
}
