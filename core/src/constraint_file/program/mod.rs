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
//! Scalars, vectors of 2 or 3 and matrices of 2 or 3 rows by 2 or 3 columns (a triangle's F is
//! 3 × 2). A vector is one register (a 2-vector's z is 0) and a matrix its columns, each a vector
//! register (`shapes.rs`); every matrix operation is compiled into vector and scalar
//! instructions (`M v` is Σⱼ cⱼ vⱼ, one instruction; `inverse(M)` of a 3 × 3 has the rows
//! (c₁×c₂, c₂×c₀, c₀×c₁) / det M), so a tape knows only scalars and vectors and each
//! instruction's derivative rule covers matrices too; the polar decomposition and the SVD are
//! instructions of their own, one per column of the result (`numbers::svd3`). The same
//! instruction on the same registers is compiled once (common subexpressions), x·1, x/1 and
//! −(−x) are x, and what a constant gives is folded.
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
mod expressions;
mod given;
mod op;
mod shapes;
mod tape;

use expressions::FUNCTIONS;
pub(super) use given::GIVEN_NAMES;
pub use op::RESTING_H;
pub(super) use op::{Inputs, MAX_REGISTERS, MAX_STORED, MAX_WRITTEN, holds};
use tape::InputLayout;
pub(super) use tape::{Registers, Tape};

use super::expression::{Expr, Span};
use arrayvec::ArrayVec;
use op::{MAX_SLOTS, Op, Reg};
use std::collections::HashMap;

#[cfg(doc)]
use crate::numbers::vector::Real;

/// What an expression is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Type {
    /// A number.
    Scalar,
    /// A vector of 2 or 3 components (a 2-vector's register keeps z = 0).
    Vector(u8),
    /// A matrix of (rows, columns), each 2 or 3: its columns are vectors of `rows` components.
    Matrix(u8, u8),
}

impl Type {
    /// A 3-vector: a particle, a gradient entry.
    pub(super) const VECTOR: Type = Type::Vector(3);
    /// A 3 × 3 matrix: a tet's F, a Hessian block.
    pub(super) const MATRIX: Type = Type::Matrix(3, 3);

    fn article(self) -> String {
        match self {
            Type::Scalar => "a scalar".to_owned(),
            Type::VECTOR => "a vector".to_owned(),
            Type::MATRIX => "a matrix".to_owned(),
            Type::Vector(n) => format!("a {n}-vector"),
            Type::Matrix(rows, columns) => format!("a {rows} × {columns} matrix"),
        }
    }

    /// (rows, columns) of a matrix; (n, 1) of an n-vector, (1, 1) of a scalar.
    fn shape(self) -> (u8, u8) {
        match self {
            Type::Scalar => (1, 1),
            Type::Vector(n) => (n, 1),
            Type::Matrix(rows, columns) => (rows, columns),
        }
    }
}

/// A type or name error, at a span of the expression's text.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct CompileError {
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
            ty: Type::VECTOR,
        }
    }

    fn matrix(columns: [Reg; 3]) -> Value {
        Value {
            r: columns,
            ty: Type::MATRIX,
        }
    }
}

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
pub(super) struct Program {
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
pub(super) struct Compiled {
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
    pub(super) fn new(arity: usize, rest: bool) -> Program {
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
    pub(super) fn at(&mut self, base: usize) {
        self.base = base;
    }

    /// Adds `name = expr`; later expressions may use `name`.
    pub(super) fn define(
        &mut self,
        name: &str,
        name_span: Span,
        expr: &Expr,
    ) -> Result<(), CompileError> {
        // q1 is q0's kind, start2 start0's.
        let numbered = |prefix: &str| {
            name.strip_prefix(prefix)
                .is_some_and(|k| k.len() == 1 && k.parse::<usize>().is_ok())
        };
        let given = GIVEN_NAMES.iter().find(|g| {
            g.0 == name || (numbered("q") && g.0 == "q0") || (numbered("start") && g.0 == "start0")
        });
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
    pub(super) fn output(
        &mut self,
        expr: &Expr,
        wanted: Type,
        what: &str,
    ) -> Result<usize, CompileError> {
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
        let columns = if wanted == Type::MATRIX { 3 } else { 1 };
        self.outputs.extend_from_slice(&value.r[..columns]);
        Ok(first)
    }

    /// The instructions outputs `outputs` need and no other, in order, renumbered: a definition
    /// that only a gradient entry uses costs C's tape nothing. Everything is in the one tape
    /// (nothing stored): what a tape run once, such as the rest value's, is cut into.
    pub(super) fn tape(&self, outputs: &[usize]) -> Tape {
        let regs: Vec<Reg> = outputs.iter().map(|&o| self.outputs[o]).collect();
        self.cut(&regs, &HashMap::new())
    }

    /// The outputs of each group of `groups` as a tape that runs at every projection, with what
    /// depends only on the element (the rest shape, the material) cut out into one prelude
    /// whose results the element stores. Fails when they are more than [`MAX_STORED`] numbers.
    pub(super) fn compiled(&self, groups: &[&[usize]]) -> Result<Compiled, String> {
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
            Op::Particle(_) | Op::Rest | Op::Start(_) | Op::Step => Depends::Projection,
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
}

#[cfg(test)]
mod examples {
    #[allow(unused_imports)]
    use super::*;

    /// The example of `compiled`'s documentation (a unit test: the item is not exported).
    #[test]
    fn compiled_example() {
        use crate::constraint_file::expression::parse_expression;
        use crate::constraint_file::program::{Inputs, Program, Type};
        // C = det F − 1: inverse(Dm) is stored (9 numbers), F = Ds inverse(Dm) is not.
        let mut program = Program::new(4, true);
        let c = program
            .output(
                &parse_expression("det(F) - 1").unwrap(),
                Type::Scalar,
                "value",
            )
            .unwrap();
        let compiled = program.compiled(&[&[c]]).unwrap();
        assert_eq!(compiled.stored, 9);
        let rest = [
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        let mut stored = vec![0.0; compiled.stored];
        compiled.prelude.run(
            &Inputs {
                material: [1.0, 1.0, 2.0],
                ..Inputs::of(&rest, 0.0)
            },
            |r| r.write_all(&mut stored),
        );
        // Stretched along x twice over: det F = 2.
        let points = [
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        let inputs = Inputs {
            stored: &stored,
            ..Inputs::of(&points, 0.0)
        };
        let value: f64 = compiled.tapes[0].run(&inputs, |r| r.scalar(0));
        assert!((value - 1.0).abs() < 1e-15);
    }

    /// The example of `tape`'s documentation (a unit test: the item is not exported).
    #[test]
    fn tape_example() {
        use crate::constraint_file::expression::parse_expression;
        use crate::constraint_file::program::{Inputs, Program, Type};
        // C = |p0 − p1| − rest, the same tape in f64 and in f32.
        let mut program = Program::new(2, true);
        let c = program
            .output(
                &parse_expression("length(p0 - p1) - rest").unwrap(),
                Type::Scalar,
                "value",
            )
            .unwrap();
        let tape = program.tape(&[c]);
        let points = [[3.0, 0.0, 4.0], [0.0; 3]];
        assert_eq!(tape.run(&Inputs::of(&points, 1.0), |r| r.scalar(0)), 4.0);
        let points32 = [[3.0f32, 0.0, 4.0], [0.0; 3]];
        assert_eq!(
            tape.run(&Inputs::of(&points32, 1.0), |r| r.scalar(0)),
            4.0f32
        );
    }
}
