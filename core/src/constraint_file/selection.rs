//! Which particles a file bound to single particles applies to: its `where`, a condition on each
//! particle's rest position ([`Selection`]), so that a pin set, a handle or the particles above a
//! plane are chosen by where they are on the mesh rather than by number.
//!
//! # The condition
//! Comparisons `a < b`, `a <= b`, `a > b`, `a >= b` of scalar expressions, joined by `and` and
//! `or` (`and` first), over `q0` (the particle's rest position) and `rest_min`, `rest_max` (the
//! corners of the rest shape's bounding box), with every function of the language:
//! `q0.y > rest_max.y - 0.01` is the top layer of any mesh, `length(q0 - vec3(0, 1, 0)) < 0.1`
//! the particles near a point. It is evaluated once, when the family is laid on a mesh; the
//! particles it chooses are fixed from then on, as the elements of every other binding are.

use super::expression::{self, CompareOp, Expr, Span};
use super::program::{CompileError, Inputs, Program, Tape, Type, holds};
use glam::DVec3;

/// The names a `where` may use.
const NAMES: [&str; 3] = ["q0", "rest_min", "rest_max"];

/// A compiled `where`: the `or` of conjunctions of comparisons, each side an output of one tape.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Selection {
    /// Outputs 2k and 2k + 1 are the two sides of comparison k.
    tape: Tape,
    /// Per conjunction, its comparisons, numbered in order across all of them.
    conjunctions: Vec<Vec<CompareOp>>,
}

/// A mistake in a `where`: at a byte of its text, or a syntax error at an offset.
pub(super) enum SelectionError {
    /// A syntax error at this byte.
    Syntax(expression::SyntaxError),
    /// A name or type error.
    Compile(CompileError),
}

impl Selection {
    /// Compiles the condition `text`.
    pub(super) fn compile(text: &str) -> Result<Selection, SelectionError> {
        let parsed = expression::parse_condition(text).map_err(SelectionError::Syntax)?;
        // The tape's particles are the rest position and the box's corners: p0 is q0 (what
        // the tape reads as q0 is given the same), p1 and p2 the corners, named here.
        let mut program = Program::new(3, false);
        let none = Span { start: 0, end: 0 };
        for (k, name) in ["rest_min", "rest_max"].iter().enumerate() {
            let corner = Expr::Name(format!("p{}", k + 1), none);
            program
                .define(name, none, &corner)
                .map_err(SelectionError::Compile)?;
        }
        let mut conjunctions = Vec::new();
        for conjunction in &parsed {
            let mut ops = Vec::new();
            for clause in conjunction {
                let Expr::Compare(op, left, right, _) = clause else {
                    unreachable!("the grammar makes each clause a comparison")
                };
                for side in [left, right] {
                    only_named(side)?;
                    program
                        .output(side, Type::Scalar, "each side of a comparison")
                        .map_err(SelectionError::Compile)?;
                }
                ops.push(*op);
            }
            conjunctions.push(ops);
        }
        let outputs: Vec<usize> =
            (0..2 * conjunctions.iter().map(Vec::len).sum::<usize>()).collect();
        Ok(Selection {
            tape: program.tape(&outputs),
            conjunctions,
        })
    }

    /// Whether the particle at rest at `rest` is chosen, the rest shape's bounding box being
    /// `(rest_min, rest_max)`. A side that is not finite there (a division by zero) makes its
    /// comparison false.
    pub(super) fn chooses(&self, rest: DVec3, (rest_min, rest_max): (DVec3, DVec3)) -> bool {
        let points = [rest, rest_min, rest_max].map(|p| p.to_array());
        let inputs = Inputs::of(&points, 0.0);
        self.tape.run(&inputs, |r| {
            let mut k = 0;
            self.conjunctions.iter().any(|ops| {
                // Every comparison is read, so that k counts them all.
                ops.iter().fold(true, |all, op| {
                    let (a, b) = (r.scalar(2 * k), r.scalar(2 * k + 1));
                    k += 1;
                    all && holds(*op, a, b)
                })
            })
        })
    }
}

/// Refuses a name other than [`NAMES`] in `expr` (a particle's position now, the file's
/// definitions: a `where` is read on the rest shape alone, before anything moves).
fn only_named(expr: &Expr) -> Result<(), SelectionError> {
    let refuse = |name: &str, span: Span| {
        Err(SelectionError::Compile(CompileError {
            span,
            message: format!(
                "`{name}`: a `where` chooses particles by where they are at rest, and may name \
                 q0 (the particle's rest position) and rest_min, rest_max (the corners of the \
                 rest shape's bounding box)"
            ),
        }))
    };
    match expr {
        Expr::Number(..) => Ok(()),
        Expr::Name(name, span) if !NAMES.contains(&name.as_str()) => refuse(name, *span),
        Expr::Name(..) => Ok(()),
        Expr::Neg(a, _) | Expr::Member(a, ..) => only_named(a),
        Expr::Binary(_, a, b, _) | Expr::Compare(_, a, b, _) => {
            only_named(a)?;
            only_named(b)
        }
        Expr::Call { args, .. } => args.iter().try_for_each(only_named),
    }
}

impl super::ConstraintFile {
    /// The particles of a mesh at rest at `rest_positions` that this file applies to, in
    /// order: those its `where` chooses; every one for a file without one.
    ///
    /// ```
    /// use glam::DVec3;
    /// use std::path::Path;
    /// use tetlab_core::constraint_file::ConstraintFile;
    /// let text = "name = \"pin-top\"\napplies_to = \"particles\"\n\
    ///             where = \"q0.y > rest_max.y - 0.01\"\nvalue = \"length(p0 - q0)\"\n";
    /// let file = ConstraintFile::parse(Path::new("pin.toml"), text).unwrap();
    /// let rest = [DVec3::ZERO, DVec3::Y, DVec3::new(1.0, 1.0, 0.0), DVec3::X];
    /// assert_eq!(file.chooses(&rest), [1, 2], "the two at the top");
    /// ```
    pub fn chooses(&self, rest_positions: &[DVec3]) -> Vec<u32> {
        let all = 0..rest_positions.len() as u32;
        let Some(selection) = &self.selection else {
            return all.collect();
        };
        let bounds = crate::scene::mesh::bounds(rest_positions);
        all.filter(|&i| selection.chooses(rest_positions[i as usize], bounds))
            .collect()
    }
}
