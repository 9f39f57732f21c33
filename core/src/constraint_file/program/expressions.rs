//! How an expression of a constraint file becomes instructions of its [`Program`]: the
//! functions of the language and their arguments ([`FUNCTIONS`]), and the compilation of
//! numbers, names, operators and calls, vectors and matrices of two or three typed by their
//! shape (`shapes.rs`), the names given without a definition in `given.rs`.

use super::given::given_here;
use super::op::{Op, Reg};
use super::{CompileError, Program, Type, Value};
use crate::constraint_file::expression::{BinaryOp, Expr, Span};

/// What an argument can be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Param {
    /// This type.
    Is(Type),
    /// A 2- or 3-vector.
    AnyVector,
    /// A matrix of any shape.
    AnyMatrix,
    /// A 2 × 2 or 3 × 3 matrix.
    Square,
    /// A comparison `a < b`.
    Condition,
    /// A scalar or a vector, the same as the other `Same` arguments (and the result).
    Same,
}

impl Param {
    /// Whether a value of type `ty` can be this argument (`Condition` and `Same` are checked
    /// where they are taken).
    fn admits(self, ty: Type) -> bool {
        match self {
            Is(wanted) => ty == wanted,
            AnyVector => matches!(ty, Type::Vector(_)),
            AnyMatrix => matches!(ty, Type::Matrix(..)),
            Square => matches!(ty, Type::Matrix(r, c) if r == c),
            Condition | Same => true,
        }
    }

    /// What it must be, for a message.
    fn wanted(self) -> String {
        match self {
            Is(ty) => ty.article(),
            AnyVector => "a vector (of 2 or 3)".to_owned(),
            AnyMatrix => "a matrix".to_owned(),
            Square => "a square matrix (2 × 2 or 3 × 3)".to_owned(),
            Condition => "a comparison".to_owned(),
            Same => "a scalar or a vector".to_owned(),
        }
    }
}

use Param::{AnyMatrix, AnyVector, Condition, Is, Same, Square};
const S: Param = Is(Type::Scalar);
const V: Param = AnyVector;
const V3: Param = Is(Type::VECTOR);
const M: Param = AnyMatrix;
const M3: Param = Is(Type::MATRIX);

/// The functions of the language and their arguments (`det` also takes one square matrix).
/// Vectors and matrices of two as well as three, except where noted by `V3` and `M3`.
pub(super) const FUNCTIONS: [(&str, &[Param]); 36] = [
    ("dot", &[V, V]),
    ("cross", &[V3, V3]),
    ("length", &[V]),
    ("normalize", &[V]),
    ("det", &[V3, V3, V3]),
    ("vec3", &[S, S, S]),
    ("vec2", &[S, S]),
    ("mat3", &[V, V, V]),
    ("mat2", &[V, V]),
    ("outer", &[V, V]),
    ("transpose", &[M]),
    ("inverse", &[Square]),
    ("trace", &[Square]),
    ("norm", &[M]),
    ("polar", &[M3]),
    ("singular_values", &[M3]),
    ("svd_u", &[M3]),
    ("svd_v", &[M3]),
    ("sqrt", &[S]),
    ("cbrt", &[S]),
    ("pow", &[S, S]),
    ("exp", &[S]),
    ("log", &[S]),
    ("sin", &[S]),
    ("cos", &[S]),
    ("tan", &[S]),
    ("asin", &[S]),
    ("acos", &[S]),
    ("atan2", &[S, S]),
    ("abs", &[S]),
    ("sign", &[S]),
    ("min", &[S, S]),
    ("max", &[S, S]),
    ("clamp", &[S, S, S]),
    ("if", &[Condition, Same, Same]),
    ("select", &[Condition, Same, Same]),
];

/// The names of the functions, for the message for an unknown one.
fn function_names() -> impl Iterator<Item = &'static str> {
    FUNCTIONS.iter().map(|f| f.0).filter(|&f| f != "select")
}

impl Program {
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
                    Vc(_) => Ok(Value {
                        r: [self.emit(Op::NegV(a.r[0]), *span, "-")?; 3],
                        ty: a.ty,
                    }),
                    Mx(..) => self.columns(a, *span, "-", Op::NegV),
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
                    (BinaryOp::Add, Vc(n), Vc(m)) if n == m => single(self, Op::AddV(x, y), a.ty),
                    (BinaryOp::Sub, Vc(n), Vc(m)) if n == m => single(self, Op::SubV(x, y), a.ty),
                    (BinaryOp::Mul, Vc(_), Sc) => single(self, Op::Scale(x, y), a.ty),
                    (BinaryOp::Mul, Sc, Vc(_)) => single(self, Op::Scale(y, x), b.ty),
                    (BinaryOp::Div, Vc(_), Sc) => single(self, Op::Shrink(x, y), a.ty),
                    (BinaryOp::Add | BinaryOp::Sub, Mx(..), Mx(..)) if a.ty == b.ty => {
                        let (rows, count) = a.ty.shape();
                        let mut out = [0; 3];
                        for (j, slot) in out.iter_mut().enumerate().take(count as usize) {
                            let instruction = if *op == BinaryOp::Add {
                                Op::AddV(a.r[j], b.r[j])
                            } else {
                                Op::SubV(a.r[j], b.r[j])
                            };
                            *slot = self.emit(instruction, *span, what)?;
                        }
                        self.shaped(rows, &out[..count as usize], *span)
                    }
                    (BinaryOp::Mul, Mx(..), Sc) => {
                        self.columns(a, *span, what, |c| Op::Scale(c, y))
                    }
                    (BinaryOp::Mul, Sc, Mx(..)) => {
                        self.columns(b, *span, what, |c| Op::Scale(c, x))
                    }
                    (BinaryOp::Div, Mx(..), Sc) => {
                        self.columns(a, *span, what, |c| Op::Shrink(c, y))
                    }
                    (BinaryOp::Mul, Mx(rows, count), Vc(n)) if count == n => Ok(Value {
                        r: [self.times_vector(a, y, *span)?; 3],
                        ty: Vc(rows),
                    }),
                    (BinaryOp::Mul, Mx(_, count), Mx(rows, _)) if count == rows => {
                        self.product(a, b, *span)
                    }
                    (BinaryOp::Mul, Mx(_, count), Vc(n) | Mx(n, _)) => Err(CompileError {
                        span: *span,
                        message: format!(
                            "type error: {} * {}: the columns of the first ({count}) must be \
                             as many as the rows of the second ({n})",
                            a.ty.article(),
                            b.ty.article()
                        ),
                    }),
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

    /// A call of one of the [`FUNCTIONS`]: its arguments checked against what it takes, then
    /// its instructions (`tan`, `pow`, `clamp` and the matrix functions are made of others).
    fn call(
        &mut self,
        name: &str,
        name_span: Span,
        args: &[Expr],
        span: Span,
    ) -> Result<Value, CompileError> {
        let Some(&(what, params)) = FUNCTIONS.iter().find(|f| f.0 == name) else {
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
            &[Square]
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
                Is(_) | AnyVector | AnyMatrix | Square => {
                    let value = self.compile(arg)?;
                    if !param.admits(value.ty) {
                        return Err(CompileError {
                            span: arg.span(),
                            message: format!(
                                "type error: argument {} of `{name}` must be {}, and this is {}",
                                k + 1,
                                param.wanted(),
                                value.ty.article()
                            ),
                        });
                    }
                    values[k] = value;
                }
                Same => {
                    let value = self.compile(arg)?;
                    if matches!(value.ty, Type::Matrix(..)) {
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
        // Vectors that must be of one length: dot's two, mat3's and mat2's columns.
        let lengths = |count: usize| -> Result<(), CompileError> {
            let first = values[0].ty;
            match (1..count).find(|&k| values[k].ty != first) {
                Some(k) => Err(CompileError {
                    span: args[k].span(),
                    message: format!(
                        "type error: argument {} of `{name}` is {}, and argument 1 {}: they must \
                         be of one length",
                        k + 1,
                        values[k].ty.article(),
                        first.article()
                    ),
                }),
                None => Ok(()),
            }
        };
        match name {
            "dot" => {
                lengths(2)?;
                scalar(self, Op::Dot(a, b))
            }
            "cross" => vector(self, Op::Cross(a, b)),
            "length" => scalar(self, Op::Length(a)),
            "normalize" => Ok(Value {
                r: [self.emit(Op::Normalize(a), span, what)?; 3],
                ty: values[0].ty,
            }),
            "det" if matches!(values[0].ty, Type::Matrix(..)) => {
                Ok(Value::scalar(self.determinant(values[0], span, what)?))
            }
            "det" => scalar(self, Op::Det(a, b, c)),
            "vec3" => vector(self, Op::Vec3(a, b, c)),
            "vec2" => Ok(Value {
                r: [self.vector2(a, b, span)?; 3],
                ty: Type::Vector(2),
            }),
            "mat3" | "mat2" => {
                let count = if name == "mat3" { 3 } else { 2 };
                lengths(count)?;
                let (rows, _) = values[0].ty.shape();
                self.shaped(rows, &[a, b, c][..count], span)
            }
            "outer" => {
                // a bᵀ: column j is a bⱼ.
                let ((rows, _), (count, _)) = (values[0].ty.shape(), values[1].ty.shape());
                let mut columns = [0; 3];
                for (j, column) in columns.iter_mut().enumerate().take(count as usize) {
                    let bj = self.emit(Op::Component(b, j as u8), span, what)?;
                    *column = self.emit(Op::Scale(a, bj), span, what)?;
                }
                self.shaped(rows, &columns[..count as usize], span)
            }
            "transpose" => self.transpose(values[0], span),
            "inverse" => self.inverse(values[0], span),
            "polar" => {
                // R of F = R S, column by column (`numbers::svd3`).
                let [c0, c1, c2] = values[0].r;
                let mut columns = [0; 3];
                for (k, column) in columns.iter_mut().enumerate() {
                    *column = self.emit(Op::PolarColumn(c0, c1, c2, k as u8), span, what)?;
                }
                Ok(Value::matrix(columns))
            }
            "svd_u" | "svd_v" => {
                // U or V of F = U diag(σ) Vᵀ, column by column (`numbers::svd3`).
                let [c0, c1, c2] = values[0].r;
                let mut columns = [0; 3];
                for (k, column) in columns.iter_mut().enumerate() {
                    let op = if name == "svd_u" {
                        Op::SvdU(c0, c1, c2, k as u8)
                    } else {
                        Op::SvdV(c0, c1, c2, k as u8)
                    };
                    *column = self.emit(op, span, what)?;
                }
                Ok(Value::matrix(columns))
            }
            "singular_values" => {
                let [c0, c1, c2] = values[0].r;
                vector(self, Op::SingularValues(c0, c1, c2))
            }
            "trace" => Ok(Value::scalar(self.trace(values[0], span)?)),
            "norm" => Ok(Value::scalar(self.norm(values[0], span)?)),
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
                let op = if matches!(same, Some(Type::Vector(_))) {
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
        let given: Vec<&str> = given_here(self.arity).collect();
        format!(
            "unknown name `{name}`: the names here are {}, and {} (the rest shape, the material)",
            known.join(", "),
            given.join(", ")
        )
    }
}
