//! A tape ([`Tape`]): what some outputs of a [`super::Program`] need, as flat single-assignment
//! instructions, run front to back ([`Tape::run`]) on the stack or in the caller's registers
//! ([`Tape::run_in`]), in any [`Real`]. A gradient is outputs like any other: its instructions
//! were compiled ([`super::Program::differentiate`]).

use super::Origin;
use super::op::{Inputs, MAX_SLOTS, Op, Reg};
use crate::numbers::vector::Real;
use arrayvec::ArrayVec;

/// What some outputs of a [`Program`] need, as flat single-assignment instructions.
///
/// The registers are numbers side by side, one for a scalar and three for a vector, and an
/// instruction names each register it reads by where its value starts ([`Reg`]), so that a scalar
/// instruction reads and writes one number. The first registers are the tape's inputs, placed
/// there before any instruction runs: the particles (three numbers each, p0 from 0), `rest`, then
/// the stored numbers the tape reads ([`Op`] has no instruction for them, so that reading an input
/// costs no dispatch). Instruction k then defines the next register from earlier ones.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Tape {
    /// How many particles the inputs begin with.
    arity: usize,
    /// Per stored number the tape reads, in the order of its registers, where it is among the
    /// numbers the element stores.
    loads: Vec<u8>,
    /// The stored registers: where each starts, whether a vector, and the text it came from.
    loaded: Vec<(Reg, bool, Origin)>,
    /// The constants' numbers, which follow the stored ones among the inputs.
    constants: Vec<f64>,
    pub(super) ops: Vec<Op>,
    pub(super) origins: Vec<Origin>,
    /// Whether each instruction's value is a vector.
    vector: Vec<bool>,
    /// Where each instruction's value starts.
    starts: Vec<Reg>,
    pub(super) outputs: Vec<Reg>,
    /// For a prelude, whether each output is a vector (three stored numbers) or a scalar.
    pub(super) widths: Vec<bool>,
    /// How many numbers the registers are, inputs included.
    slots: usize,
    /// Whether an instruction reads the rest shape or the material (a prelude's, a rest
    /// value's), not only the inputs it is given in its registers.
    reads_element: bool,
}

/// The registers of a tape after [`Tape::run`]: read its outputs.
pub(crate) struct Registers<'a, T> {
    registers: &'a [T],
    outputs: &'a [Reg],
    widths: &'a [bool],
}

impl<T: Copy> Registers<'_, T> {
    /// Output `i` of the tape as a scalar.
    pub(crate) fn scalar(&self, i: usize) -> T {
        self.registers[self.outputs[i] as usize]
    }

    /// Output `i` of the tape as a vector.
    pub(crate) fn vector(&self, i: usize) -> [T; 3] {
        let at = self.outputs[i] as usize;
        [
            self.registers[at],
            self.registers[at + 1],
            self.registers[at + 2],
        ]
    }

    /// Output `i` of the tape where it is: one number for a scalar, three for a vector (a caller
    /// that takes only part of each number reads only that part).
    pub(crate) fn numbers(&self, i: usize, width: usize) -> &[T] {
        let at = self.outputs[i] as usize;
        &self.registers[at..at + width]
    }

    /// A prelude's outputs, in order, into `out`: a scalar's one number, a vector's three
    /// ([`super::Compiled::stored`] of them in all).
    pub(crate) fn write_all(&self, out: &mut [T]) {
        let mut at = 0;
        for (i, &vector) in self.widths.iter().enumerate() {
            let width = if vector { 3 } else { 1 };
            let from = self.outputs[i] as usize;
            out[at..at + width].copy_from_slice(&self.registers[from..from + width]);
            at += width;
        }
    }
}

/// `ops` with each run of a matrix's three column instructions (R's, U's or V's columns 0, 1, 2
/// of the same F, one after the other: their values side by side) run as one decomposition
/// ([`Op::Decomposed`], then [`Op::Written`] twice): the same numbers, a third of the work.
fn decompose_once(mut ops: Vec<Op>) -> Vec<Op> {
    for i in 0..ops.len().saturating_sub(2) {
        let columns = [ops[i], ops[i + 1], ops[i + 2]].map(Op::column_of);
        if let [Some((which, f, 0)), Some((w1, f1, 1)), Some((w2, f2, 2))] = columns
            && which == w1
            && which == w2
            && f == f1
            && f == f2
        {
            ops[i] = Op::Decomposed(which, f[0], f[1], f[2]);
            ops[i + 1] = Op::Written;
            ops[i + 2] = Op::Written;
        }
    }
    ops
}

/// Where a tape's value stops being finite ([`Tape::undefined_at`]).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Undefined {
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
pub(crate) struct Switch {
    /// Where the expression's text starts ([`Program::at`]).
    pub base: usize,
    /// The byte of that text.
    pub offset: usize,
    /// What it is: `abs`, `min`, `if`…
    pub what: &'static str,
    /// The value whose zero is the kink, at the configuration asked about.
    pub decides: f64,
}

/// A tape's inputs, placed in its registers ahead of its instructions: `arity` particles, `rest`,
/// the stored numbers (`loads`: per number, its place among the element's stored numbers;
/// `loaded`: per stored register, where it starts, whether a vector, its text), then the numbers
/// of its `constants`.
pub(super) struct InputLayout {
    pub arity: usize,
    pub loads: Vec<u8>,
    pub loaded: Vec<(Reg, bool, Origin)>,
    pub constants: Vec<f64>,
}

impl Tape {
    /// The tape whose inputs are placed as `inputs` says, then the instructions `ops` (each
    /// reading registers by where they start), from the text `origins` says, whose values are
    /// vectors where `vector` says, with `outputs`.
    pub(super) fn new(
        InputLayout {
            arity,
            loads,
            loaded,
            constants,
        }: InputLayout,
        ops: Vec<Op>,
        origins: Vec<Origin>,
        vector: Vec<bool>,
        outputs: Vec<Reg>,
    ) -> Tape {
        let reads_element = ops
            .iter()
            .any(|op| matches!(op, Op::RestParticle(_) | Op::Material(_)));
        let ops = decompose_once(ops);
        let mut slots = 3 * arity + 1 + loads.len() + constants.len();
        let mut starts = Vec::with_capacity(ops.len());
        for &wide in &vector {
            starts.push(slots as Reg);
            slots += if wide { 3 } else { 1 };
        }
        Tape {
            arity,
            loads,
            loaded,
            constants,
            ops,
            origins,
            vector,
            starts,
            outputs,
            widths: Vec::new(),
            slots,
            reads_element,
        }
    }

    /// Whether it reads the rest shape (q0…).
    pub(crate) fn reads_rest_shape(&self) -> bool {
        self.ops.iter().any(|op| matches!(op, Op::RestParticle(_)))
    }

    /// Whether it reads where the particles were at the start of the substep or h.
    pub(crate) fn reads_motion(&self) -> bool {
        self.ops
            .iter()
            .any(|op| matches!(op, Op::Start(_) | Op::Step))
    }

    /// How many numbers its registers are, inputs included: what [`Tape::run_in`]'s slice must
    /// hold.
    pub(crate) fn slots(&self) -> usize {
        self.slots
    }

    /// Runs the tape on `inputs` and reads its outputs with `read`.
    #[inline(always)]
    pub(crate) fn run<T: Real, R>(
        &self,
        inputs: &Inputs<'_, T>,
        read: impl FnOnce(&Registers<'_, T>) -> R,
    ) -> R {
        let mut registers: ArrayVec<T, MAX_SLOTS> = ArrayVec::new();
        registers.extend(std::iter::repeat_n(T::ZERO, self.slots));
        self.run_in(inputs, &mut registers, read)
    }

    /// [`Tape::run`] in the caller's registers `r`, at least [`Tape::slots`] numbers (what they
    /// hold before does not matter: each is written before it is read). A caller that runs the
    /// tape many times on wide numbers keeps them, rather than a stack frame of [`MAX_SLOTS`]
    /// of them for each run.
    #[inline(always)]
    pub(crate) fn run_in<T: Real, R>(
        &self,
        inputs: &Inputs<'_, T>,
        r: &mut [T],
        read: impl FnOnce(&Registers<'_, T>) -> R,
    ) -> R {
        self.load(inputs, r);
        for (op, &at) in self.ops.iter().zip(&self.starts) {
            op.apply(r, at as usize, inputs);
        }
        read(&Registers {
            registers: r,
            outputs: &self.outputs,
            widths: &self.widths,
        })
    }

    /// [`Tape::run_in`] with the inputs placed by the caller: `place` gets the registers and, per
    /// stored number the tape reads, where it is among the element's, and writes the particles'
    /// coordinates into registers 0, 1, 2, … (p0's x first), `rest` after them, then those stored
    /// numbers in that order. For a caller whose inputs come in another layout (the fast
    /// engine's batches): each number is written once, where the tape reads it, and in the
    /// width it is read in.
    ///
    /// # Panics
    /// When the tape reads the rest shape or the material (a tape that runs at each projection
    /// reads them from what is stored), or `r` is shorter than [`Tape::slots`].
    #[inline(always)]
    pub(crate) fn run_placed<T: Real, R>(
        &self,
        r: &mut [T],
        (start, h): (&[[T; 3]], T),
        place: impl FnOnce(&mut [T], &[u8]),
        read: impl FnOnce(&Registers<'_, T>) -> R,
    ) -> R {
        assert!(
            !self.reads_element,
            "a tape that reads the rest shape or the material is run from its inputs"
        );
        place(r, &self.loads);
        self.load_constants(r);
        let none = Inputs {
            start,
            h,
            ..Inputs::of(&[], T::ZERO)
        };
        for (op, &at) in self.ops.iter().zip(&self.starts) {
            op.apply(r, at as usize, &none);
        }
        read(&Registers {
            registers: r,
            outputs: &self.outputs,
            widths: &self.widths,
        })
    }

    /// The first instruction, in evaluation order, whose value is not finite while what it reads
    /// is, at `points` with `rest`: where and why C is undefined there. `None` where every value
    /// is finite.
    pub(crate) fn undefined_at(&self, inputs: &Inputs<'_, f64>) -> Option<Undefined> {
        let mut r = vec![0.0; self.slots()];
        self.load(inputs, &mut r);
        // A stored number is not finite where the rest shape makes it so (a flat rest tet's
        // inverse(Dm)): named where its expression is.
        for &(at, vector, origin) in &self.loaded {
            let at = at as usize;
            if !r[at..at + if vector { 3 } else { 1 }]
                .iter()
                .all(|x| x.is_finite())
            {
                return Some(Undefined {
                    base: origin.base,
                    offset: origin.offset,
                    message: format!(
                        "`{}` is undefined on the rest shape: what the element stores is not \
                         finite",
                        origin.what
                    ),
                });
            }
        }
        for (k, (op, origin)) in self.ops.iter().zip(&self.origins).enumerate() {
            let start = self.starts[k] as usize;
            op.apply(&mut r, start, inputs);
            let finite = |at: Reg| {
                let at = at as usize;
                r[at..at + self.width_at(at as Reg)]
                    .iter()
                    .all(|x| x.is_finite())
            };
            let value = &r[start..start + self.width(k)];
            if !value.iter().all(|x| x.is_finite()) && op.inputs().iter().all(|&i| finite(i)) {
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
    pub(crate) fn switches_at(&self, inputs: &Inputs<'_, f64>) -> Vec<Switch> {
        let mut r = vec![0.0; self.slots()];
        self.load(inputs, &mut r);
        let mut out = Vec::new();
        for (k, (op, origin)) in self.ops.iter().zip(&self.origins).enumerate() {
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
            op.apply(&mut r, self.starts[k] as usize, inputs);
        }
        out
    }

    /// How many numbers instruction `k`'s value is.
    fn width(&self, k: usize) -> usize {
        if self.vector[k] { 3 } else { 1 }
    }

    /// How many numbers the register starting at `at` is.
    fn width_at(&self, at: Reg) -> usize {
        if let Ok(k) = self.starts.binary_search(&at) {
            return self.width(k);
        }
        if let Some(&(_, vector, _)) = self.loaded.iter().find(|l| l.0 == at) {
            return if vector { 3 } else { 1 };
        }
        // A particle; else `rest`, or a number of a constant (finite, folding saw to it).
        if (at as usize) < 3 * self.arity { 3 } else { 1 }
    }

    /// The inputs into the first registers of `r`: the particles, `rest`, the stored numbers the
    /// tape reads, then the constants.
    #[inline(always)]
    fn load<T: Real>(&self, inputs: &Inputs<'_, T>, r: &mut [T]) {
        let particles = 3 * self.arity;
        for (k, p) in inputs.points[..self.arity].iter().enumerate() {
            r[3 * k] = p[0];
            r[3 * k + 1] = p[1];
            r[3 * k + 2] = p[2];
        }
        r[particles] = inputs.rest;
        for (k, &at) in self.loads.iter().enumerate() {
            r[particles + 1 + k] = inputs.stored[at as usize];
        }
        self.load_constants(r);
    }

    /// The constants' numbers into their registers, after the stored numbers'.
    #[inline(always)]
    fn load_constants<T: Real>(&self, r: &mut [T]) {
        let first = 3 * self.arity + 1 + self.loads.len();
        for (k, &x) in self.constants.iter().enumerate() {
            r[first + k] = T::from_f64(x);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraint_file::expression::parse_expression;
    use crate::constraint_file::program::op::Decomposition;
    use crate::constraint_file::program::{Program, Type};

    /// A matrix's three column instructions run as one decomposition, to the same bits as three.
    #[test]
    fn three_columns_of_one_decomposition_are_worked_out_once() {
        for (value, which) in [
            (
                "norm(polar(mat3(p0, p1, cross(p0, p1) + vec3(0.2, -0.1, 0.3))))",
                "polar",
            ),
            (
                "norm(svd_u(mat3(p0, p1, p0 - p1 + vec3(0.5, 0, 0.1))))",
                "U",
            ),
            (
                "trace(svd_v(mat3(p0, p1, p0 - p1 + vec3(0.5, 0, 0.1))))",
                "V",
            ),
        ] {
            let mut program = Program::new(2, true);
            let c = program
                .output(&parse_expression(value).unwrap(), Type::Scalar, "value")
                .unwrap();
            let gradient = program.differentiate(c).unwrap();
            let mut outputs = vec![c];
            outputs.extend(&gradient);
            let tape = program.tape(&outputs);
            let decompositions = tape
                .ops
                .iter()
                .filter(|op| matches!(op, Op::Decomposed(..)))
                .count();
            let columns = tape
                .ops
                .iter()
                .filter(|op| op.column_of().is_some())
                .count();
            assert!(decompositions >= 1, "{which}: {:?}", tape.ops);
            assert_eq!(columns, 0, "{which}: every column runs in a decomposition");
            // The same numbers as the three columns one by one.
            let points = [[0.9, 0.2, -0.3], [0.1, 1.1, 0.4]];
            let fused = tape.run(&Inputs::of(&points, 0.0), |r| {
                (0..3)
                    .map(|k| r.vector(k).map(f64::to_bits))
                    .collect::<Vec<_>>()
            });
            let mut unfused = tape.clone();
            for (k, op) in unfused.ops.clone().iter().enumerate() {
                if let Op::Decomposed(kind, a, b, c) = *op {
                    let column = |j: u8| match kind {
                        Decomposition::Polar => Op::PolarColumn(a, b, c, j),
                        Decomposition::U => Op::SvdU(a, b, c, j),
                        Decomposition::V => Op::SvdV(a, b, c, j),
                    };
                    for j in 0..3 {
                        unfused.ops[k + j] = column(j as u8);
                    }
                }
            }
            let apart = unfused.run(&Inputs::of(&points, 0.0), |r| {
                (0..3)
                    .map(|k| r.vector(k).map(f64::to_bits))
                    .collect::<Vec<_>>()
            });
            assert_eq!(fused, apart, "{which}");
        }
    }
}
