//! A constraint file's expressions, type-checked and compiled once ([`Program`]), then cut into
//! flat tapes ([`Tape`]): each instruction defines one register from earlier ones (single
//! assignment), and a tape runs front to back.
//!
//! Running a tape allocates nothing (its registers live on the stack, at most
//! [`MAX_REGISTERS`], or in the caller's) and is generic over the scalar type ([`Real`]): f64,
//! f32, SIMD lanes, or the dual numbers of forward-mode automatic differentiation
//! ([`crate::numbers::dual::Tangent`]).
//!
//! # Types
//! Scalars, 3-vectors and 3×3 matrices. A matrix is compiled into its three columns, each a
//! vector register, and every matrix operation into vector and scalar instructions (`M v` is
//! Σⱼ cⱼ vⱼ, one instruction; `inverse(M)` has the rows (c₁×c₂, c₂×c₀, c₀×c₁) / det M), so a
//! tape knows only scalars and vectors and each instruction's derivative rule covers matrices
//! too. The same instruction on the same registers is compiled once (common subexpressions),
//! x·1, x/1 and −(−x) are x, and what a constant gives is folded.
//!
//! # What is worked out once per element
//! An instruction that reads only the rest shape (`q0`…, `Dm`, `V0`) and the material (`mu`,
//! `lambda`, `gamma`), never the particles, has the same value at every projection of its
//! element. [`Program::compiled`] cuts those into a prelude, run once per element when the rest
//! values are measured, whose results the element stores; the tapes that run at
//! every projection read them.
//!
//! # Gradients, two ways
//! - **Forward mode** ([`Tape::run`] over [`crate::numbers::dual::Tangent`] numbers): one pass per
//!   coordinate, 3N passes for N particles. Independent of everything below; `tetlab
//!   check-gradients` checks your gradient against it.
//! - **Reverse mode, compiled** ([`Program::differentiate`], in `derivative.rs`): the backward
//!   pass that carries ∂C/∂(register) from C to the particles, each instruction by its own
//!   derivative rule (for r = a·b: ā += r̄ b, b̄ += r̄ a), carried out once when the file is
//!   compiled, into instructions of the program. ∇C is then outputs of one tape that runs
//!   forward, about three times C's work: what a simulation uses. The two agree to rounding
//!   (`core/tests/constraint_files.rs`).

mod derivative;
mod op;
mod tape;

pub use op::{Inputs, MAX_REGISTERS, MAX_STORED, MAX_WRITTEN};
use tape::InputLayout;
pub use tape::{Registers, Switch, Tape, Undefined};

use super::expression::{BinaryOp, Expr, Span};
use arrayvec::ArrayVec;
use op::{MAX_SLOTS, Op, Reg};
use std::collections::HashMap;

#[cfg(doc)]
use crate::numbers::vector::Real;

/// What an expression is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Type {
    /// A number.
    Scalar,
    /// A 3-vector.
    Vector,
    /// A 3×3 matrix.
    Matrix,
}

impl Type {
    fn article(self) -> &'static str {
        match self {
            Type::Scalar => "a scalar",
            Type::Vector => "a vector",
            Type::Matrix => "a matrix",
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

/// A compiled value: one register for a scalar or a vector, three (the columns) for a matrix.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Value {
    r: [Reg; 3],
    ty: Type,
}

impl Value {
    fn scalar(r: Reg) -> Value {
        Value {
            r: [r; 3],
            ty: Type::Scalar,
        }
    }

    fn vector(r: Reg) -> Value {
        Value {
            r: [r; 3],
            ty: Type::Vector,
        }
    }

    fn matrix(columns: [Reg; 3]) -> Value {
        Value {
            r: columns,
            ty: Type::Matrix,
        }
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
const M: Param = Is(Type::Matrix);

/// The functions of the language: name, arguments and result (`det` also takes one matrix).
const FUNCTIONS: [(&str, &[Param], Param); 30] = [
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

/// The names of the functions, for the docs and the message for an unknown one.
pub fn function_names() -> impl Iterator<Item = &'static str> {
    FUNCTIONS.iter().map(|f| f.0).filter(|&f| f != "select")
}

/// Names a program knows without a definition, made when first used: the rest shape, the
/// material and the identity. `(name, what it is)`.
pub const GIVEN_NAMES: [(&str, &str); 9] = [
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

/// Where an instruction came from: the expression (the byte of the file where its text starts,
/// [`Program::at`]) and the byte of that text, and what was written there (`/`, `acos`, `pow`),
/// for the message when it is undefined.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Origin {
    base: usize,
    offset: usize,
    what: &'static str,
}

/// What an instruction's value depends on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Depends {
    /// Nothing: a constant.
    Nothing,
    /// The rest shape and the material only: the same at every projection of an element.
    Element,
    /// The particles or the rest value.
    Projection,
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
    depends: Vec<Depends>,
    names: HashMap<String, Value>,
    outputs: Vec<Reg>,
    arity: usize,
    /// Where in the file the expression being compiled starts ([`Program::at`]).
    base: usize,
}

/// A program's outputs cut into tapes: the prelude, run once per element, whose outputs are
/// what the element stores, and per group of outputs the tape that reads them.
#[derive(Clone, Debug, PartialEq)]
pub struct Compiled {
    /// Reads the rest shape and the material; its outputs, in order, are the stored numbers
    /// (a scalar's one, a vector's three).
    pub prelude: Tape,
    /// How many numbers the prelude's outputs are.
    pub stored: usize,
    /// One tape per group of outputs asked for.
    pub tapes: Vec<Tape>,
}

impl Program {
    /// A program whose names are p0…p(arity−1) (vectors), the rest shape and the material
    /// ([`GIVEN_NAMES`]) and, with `rest`, the scalar `rest`.
    pub fn new(arity: usize, rest: bool) -> Program {
        let mut program = Program {
            ops: Vec::new(),
            origins: Vec::new(),
            depends: Vec::new(),
            names: HashMap::new(),
            outputs: Vec::new(),
            arity,
            base: 0,
        };
        for k in 0..arity {
            let r = program.push(Op::Particle(k as u8), "a particle");
            program.names.insert(format!("p{k}"), Value::vector(r));
        }
        if rest {
            let r = program.push(Op::Rest, "rest");
            program.names.insert("rest".to_owned(), Value::scalar(r));
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
        let given = GIVEN_NAMES
            .iter()
            .find(|g| g.0 == name || (name.len() == 2 && name.starts_with('q') && g.0 == "q0"));
        if self.names.contains_key(name) || FUNCTIONS.iter().any(|f| f.0 == name) {
            return Err(CompileError {
                span: name_span,
                message: format!("`{name}` is already a name; give the definition another"),
            });
        }
        if let Some((_, what)) = given {
            return Err(CompileError {
                span: name_span,
                message: format!(
                    "`{name}` is already a name ({what}); give the definition another"
                ),
            });
        }
        let compiled = self.compile(expr)?;
        self.names.insert(name.to_owned(), compiled);
        Ok(())
    }

    /// Adds an output of type `wanted`; returns its index, for [`Program::tape`]. A matrix is
    /// three outputs, its columns, from that index on.
    pub fn output(&mut self, expr: &Expr, wanted: Type, what: &str) -> Result<usize, CompileError> {
        let value = self.compile(expr)?;
        if value.ty != wanted {
            return Err(CompileError {
                span: expr.span(),
                message: format!(
                    "{what} must be {}, and this is {}",
                    wanted.article(),
                    value.ty.article()
                ),
            });
        }
        let first = self.outputs.len();
        let columns = if wanted == Type::Matrix { 3 } else { 1 };
        self.outputs.extend_from_slice(&value.r[..columns]);
        Ok(first)
    }

    /// The instructions outputs `outputs` need and no other, in order, renumbered: a definition
    /// that only a gradient entry uses costs C's tape nothing. Everything is in the one tape
    /// (nothing stored): what a tape run once, such as the rest value's, is cut into.
    ///
    /// ```
    /// use tetlab_core::constraint_file::expression::parse_expression;
    /// use tetlab_core::constraint_file::program::{Inputs, Program, Type};
    /// // C = |p0 − p1| − rest, the same tape in f64 and in f32.
    /// let mut program = Program::new(2, true);
    /// let c = program.output(&parse_expression("length(p0 - p1) - rest").unwrap(), Type::Scalar, "value").unwrap();
    /// let tape = program.tape(&[c]);
    /// let points = [[3.0, 0.0, 4.0], [0.0; 3]];
    /// assert_eq!(tape.run(&Inputs::of(&points, 1.0), |r| r.scalar(0)), 4.0);
    /// let points32 = [[3.0f32, 0.0, 4.0], [0.0; 3]];
    /// assert_eq!(tape.run(&Inputs::of(&points32, 1.0), |r| r.scalar(0)), 4.0f32);
    /// ```
    pub fn tape(&self, outputs: &[usize]) -> Tape {
        let regs: Vec<Reg> = outputs.iter().map(|&o| self.outputs[o]).collect();
        self.cut(&regs, &HashMap::new())
    }

    /// The outputs of each group of `groups` as a tape that runs at every projection, with what
    /// depends only on the element (the rest shape, the material) cut out into one prelude
    /// whose results the element stores. Fails when they are more than [`MAX_STORED`] numbers.
    ///
    /// ```
    /// use tetlab_core::constraint_file::expression::parse_expression;
    /// use tetlab_core::constraint_file::program::{Inputs, Program, Type};
    /// // C = det F − 1: inverse(Dm) is stored (9 numbers), F = Ds inverse(Dm) is not.
    /// let mut program = Program::new(4, true);
    /// let c = program.output(&parse_expression("det(F) - 1").unwrap(), Type::Scalar, "value").unwrap();
    /// let compiled = program.compiled(&[&[c]]).unwrap();
    /// assert_eq!(compiled.stored, 9);
    /// let rest = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut stored = vec![0.0; compiled.stored];
    /// compiled.prelude.run(&Inputs { material: [1.0, 1.0, 2.0], ..Inputs::of(&rest, 0.0) }, |r| {
    ///     r.write_all(&mut stored)
    /// });
    /// // Stretched along x twice over: det F = 2.
    /// let points = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let inputs = Inputs { stored: &stored, ..Inputs::of(&points, 0.0) };
    /// let value: f64 = compiled.tapes[0].run(&inputs, |r| r.scalar(0));
    /// assert!((value - 1.0).abs() < 1e-15);
    /// ```
    pub fn compiled(&self, groups: &[&[usize]]) -> Result<Compiled, String> {
        // What the tapes need, then which of it depends only on the element and is read by
        // what does not: those are stored.
        let needed = self.needed(
            groups
                .iter()
                .flat_map(|g| g.iter().map(|&o| self.outputs[o])),
        );
        let mut stored_regs = Vec::new();
        for (r, &is_needed) in needed.iter().enumerate() {
            let element = self.depends[r] == Depends::Element;
            let read_by_projection = || {
                (r + 1..self.ops.len()).any(|later| {
                    needed[later]
                        && self.depends[later] == Depends::Projection
                        && self.ops[later].inputs().contains(&(r as Reg))
                })
            };
            let is_output = groups
                .iter()
                .any(|g| g.iter().any(|&o| self.outputs[o] as usize == r));
            if is_needed && element && (is_output || read_by_projection()) {
                stored_regs.push(r as Reg);
            }
        }
        let mut offsets = HashMap::new();
        let mut width = 0usize;
        for &r in &stored_regs {
            let vector = self.is_vector(r);
            offsets.insert(r, (width as u8, vector));
            width += if vector { 3 } else { 1 };
        }
        if width > MAX_STORED {
            return Err(format!(
                "what depends only on the rest shape and the material is {width} numbers per \
                 element; at most {MAX_STORED} are stored"
            ));
        }
        let mut prelude = self.cut(&stored_regs, &HashMap::new());
        prelude.widths = stored_regs.iter().map(|&r| self.is_vector(r)).collect();
        let tapes = groups
            .iter()
            .map(|g| {
                let regs: Vec<Reg> = g.iter().map(|&o| self.outputs[o]).collect();
                self.cut(&regs, &offsets)
            })
            .collect();
        Ok(Compiled {
            prelude,
            stored: width,
            tapes,
        })
    }

    /// Which instructions the registers `outputs` need.
    fn needed(&self, outputs: impl Iterator<Item = Reg>) -> Vec<bool> {
        let mut needed = vec![false; self.ops.len()];
        for o in outputs {
            needed[o as usize] = true;
        }
        for r in (0..self.ops.len()).rev() {
            if needed[r] {
                for input in self.ops[r].inputs() {
                    needed[input as usize] = true;
                }
            }
        }
        needed
    }

    /// The tape of `outputs`, reading the registers of `stored` (offset, whether a vector) from
    /// what the element stores instead of working them out.
    fn cut(&self, outputs: &[Reg], stored: &HashMap<Reg, (u8, bool)>) -> Tape {
        let mut needed = vec![false; self.ops.len()];
        for &o in outputs {
            needed[o as usize] = true;
        }
        for r in (0..self.ops.len()).rev() {
            if needed[r] && !stored.contains_key(&(r as Reg)) {
                for input in self.ops[r].inputs() {
                    needed[input as usize] = true;
                }
            }
        }
        // Each register renumbered to where its value starts among the tape's numbers: first
        // the inputs (the particles, `rest`, the stored registers it reads), then one register
        // per instruction.
        let mut map = vec![0 as Reg; self.ops.len()];
        let mut slots = 3 * self.arity + 1;
        let (mut loads, mut loaded) = (Vec::new(), Vec::new());
        for (r, op) in self.ops.iter().enumerate() {
            if !needed[r] {
                continue;
            }
            if let Some(&(at, vector)) = stored.get(&(r as Reg)) {
                map[r] = slots as Reg;
                loaded.push((slots as Reg, vector, self.origins[r]));
                let width = if vector { 3 } else { 1 };
                loads.extend(at..at + width);
                slots += width as usize;
            } else if let Op::Particle(k) = op {
                map[r] = 3 * *k as Reg;
            } else if *op == Op::Rest {
                map[r] = 3 * self.arity as Reg;
            }
        }
        // Then the constants, placed with the inputs (no instruction works them out).
        let mut constants = Vec::new();
        for (r, op) in self.ops.iter().enumerate() {
            let value = match *op {
                Op::Const(x) => &[x][..],
                Op::ConstVector(ref v) => &v[..],
                _ => continue,
            };
            if needed[r] && !stored.contains_key(&(r as Reg)) {
                map[r] = slots as Reg;
                constants.extend_from_slice(value);
                slots += value.len();
            }
        }
        let mut ops = Vec::new();
        let mut origins = Vec::new();
        let mut vector = Vec::new();
        for (r, op) in self.ops.iter().enumerate() {
            let input = matches!(
                op,
                Op::Particle(_) | Op::Rest | Op::Const(_) | Op::ConstVector(_)
            ) || stored.contains_key(&(r as Reg));
            if needed[r] && !input {
                map[r] = slots as Reg;
                ops.push(op.renumbered(&map));
                origins.push(self.origins[r]);
                let wide = self.is_vector(r as Reg);
                vector.push(wide);
                slots += if wide { 3 } else { 1 };
            }
        }
        Tape::new(
            InputLayout {
                arity: self.arity,
                loads,
                loaded,
                constants,
            },
            ops,
            origins,
            vector,
            outputs.iter().map(|&o| map[o as usize]).collect(),
        )
    }

    /// Whether register `r` holds a vector (its instruction's result type).
    fn is_vector(&self, r: Reg) -> bool {
        self.ops[r as usize].is_vector()
    }

    fn push(&mut self, op: Op, what: &'static str) -> Reg {
        self.record(op, Span { start: 0, end: 0 }, what)
    }

    fn record(&mut self, op: Op, span: Span, what: &'static str) -> Reg {
        let depends = match op {
            Op::Const(_) | Op::ConstVector(_) => Depends::Nothing,
            Op::RestParticle(_) | Op::Material(_) => Depends::Element,
            Op::Particle(_) | Op::Rest => Depends::Projection,
            _ => op
                .inputs()
                .iter()
                .map(|&i| self.depends[i as usize])
                .max_by_key(|d| *d as u8)
                .unwrap_or(Depends::Nothing),
        };
        self.ops.push(op);
        self.depends.push(depends);
        self.origins.push(Origin {
            base: self.base,
            offset: span.start,
            what,
        });
        (self.ops.len() - 1) as Reg
    }

    /// Adds `op`, from the text at `span` that `what` names, folded to a constant when every
    /// input is one; an error when that constant is not finite.
    fn emit(&mut self, op: Op, span: Span, what: &'static str) -> Result<Reg, CompileError> {
        if self.ops.len() + 1 >= MAX_WRITTEN {
            return Err(CompileError {
                span,
                message: format!(
                    "the expressions are too long: more than {MAX_WRITTEN} operations in all"
                ),
            });
        }
        self.emit_unchecked(op, span, what)
    }

    /// Adds `op` for the derivative of the instruction that came from `origin`
    /// ([`Program::differentiate`]), placed where that instruction is.
    fn emit_from(&mut self, op: Op, origin: Origin) -> Result<Reg, CompileError> {
        let span = Span {
            start: origin.offset,
            end: origin.offset,
        };
        if self.ops.len() + 1 >= MAX_REGISTERS {
            return Err(CompileError {
                span: Span { start: 0, end: 0 },
                message: format!(
                    "its gradient is too long to compile: more than {MAX_REGISTERS} operations \
                     with C's"
                ),
            });
        }
        let base = std::mem::replace(&mut self.base, origin.base);
        let emitted = self.emit_unchecked(op, span, origin.what);
        self.base = base;
        emitted
    }

    /// [`Program::emit`] without the limit: folded when every input is a constant, an identity
    /// (x·1, x/1, −(−x)) reduced to what it is.
    fn emit_unchecked(
        &mut self,
        op: Op,
        span: Span,
        what: &'static str,
    ) -> Result<Reg, CompileError> {
        if let Some(same) = self.identity(op) {
            return Ok(same);
        }
        if let Some(fused) = self.fused(op, span, what)? {
            return Ok(fused);
        }
        let constant = |r: Reg| match self.ops[r as usize] {
            Op::Const(x) => Some([x, 0.0, 0.0]),
            Op::ConstVector(x) => Some(x),
            _ => None,
        };
        let inputs = op.inputs();
        if !inputs.is_empty() && inputs.iter().all(|&r| constant(r).is_some()) {
            let value = |r: Reg| constant(r).unwrap_or_default();
            let scalar = |r: Reg| value(r)[0];
            // The inputs laid out as a tape's registers, then the instruction run on them.
            let mut registers: ArrayVec<f64, MAX_SLOTS> = ArrayVec::new();
            let laid_out = op.map_inputs(|r| {
                let at = registers.len() as Reg;
                let width = if self.is_vector(r) { 3 } else { 1 };
                registers.extend(value(r)[..width].iter().copied());
                at
            });
            let start = registers.len();
            registers.extend([0.0; 3]);
            laid_out.apply(&mut registers, start, &Inputs::of(&[], 0.0));
            let width = if op.is_vector() { 3 } else { 1 };
            let mut folded = [0.0; 3];
            folded[..width].copy_from_slice(&registers[start..start + width]);
            if !folded.iter().all(|x| x.is_finite()) {
                return Err(CompileError {
                    span,
                    message: format!("`{what}` is undefined here: {}", op.undefined(scalar)),
                });
            }
            let constant = if op.is_vector() {
                Op::ConstVector(folded)
            } else {
                Op::Const(folded[0])
            };
            return Ok(self.record(constant, span, what));
        }
        // The same instruction on the same registers, when there is one, is the same value
        // (common subexpressions): but for a switch, whose every place is a kink of its own.
        if !op.switches() {
            let earlier = self.ops.iter().rposition(|&o| o.same_as(op));
            if let Some(r) = earlier {
                return Ok(r as Reg);
            }
        }
        Ok(self.record(op, span, what))
    }

    /// One instruction for a chain of them, where it computes the same numbers in the same order:
    /// (a x + b y) + c z of vectors a, b, c and scalars x, y, z is a matrix times a vector
    /// ([`Op::MatVec`]), which the gradient of a matrix product is made of.
    fn fused(
        &mut self,
        op: Op,
        span: Span,
        what: &'static str,
    ) -> Result<Option<Reg>, CompileError> {
        let Op::AddV(sum, last) = op else {
            return Ok(None);
        };
        let (Op::AddV(first, second), Op::Scale(c, z)) =
            (self.ops[sum as usize], self.ops[last as usize])
        else {
            return Ok(None);
        };
        let (Op::Scale(a, x), Op::Scale(b, y)) =
            (self.ops[first as usize], self.ops[second as usize])
        else {
            return Ok(None);
        };
        let v = self.emit_unchecked(Op::Vec3(x, y, z), span, what)?;
        Ok(Some(self.emit_unchecked(
            Op::MatVec(a, b, c, v),
            span,
            what,
        )?))
    }

    /// The register `op` would equal exactly, bit for bit, when it is an identity: x·1, 1·x, v·1,
    /// x/1, v/1, −(−x).
    fn identity(&self, op: Op) -> Option<Reg> {
        let one = |r: Reg| self.ops[r as usize] == Op::Const(1.0);
        match op {
            Op::MulS(a, b) if one(b) => Some(a),
            Op::MulS(a, b) if one(a) => Some(b),
            Op::Scale(v, f) | Op::Shrink(v, f) if one(f) => Some(v),
            Op::DivS(a, b) if one(b) => Some(a),
            Op::NegS(a) => match self.ops[a as usize] {
                Op::NegS(x) => Some(x),
                _ => None,
            },
            Op::NegV(a) => match self.ops[a as usize] {
                Op::NegV(x) => Some(x),
                _ => None,
            },
            _ => None,
        }
    }

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

    fn compile(&mut self, expr: &Expr) -> Result<Value, CompileError> {
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
                message: format!("`{name}` is a tet's: this binding has two particles"),
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
