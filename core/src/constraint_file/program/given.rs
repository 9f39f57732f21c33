//! The names a file may use without defining them ([`GIVEN_NAMES`]), compiled when first used:
//! the rest positions, where the particles were at the start of the substep and its length h,
//! the material, the identity, and what a tet or a surface triangle is at rest and now (`Dm`,
//! `Ds`, `F`, `V0`, `A0`).
//!
//! # A triangle's F
//! A surface triangle's rest edges e₁ = q1 − q0 and e₂ = q2 − q0 are written in the triangle's
//! own frame, x along e₁ and y in its plane towards q2: `Dm` = [[|e₁|, e₂·x̂], [0, |e₁ × e₂| / |e₁|]]
//! (columns (|e₁|, 0) and (e₂·x̂, |e₁ × e₂| / |e₁|)), 2 × 2 with det Dm = 2 A₀ > 0. `Ds` =
//! [p1 − p0, p2 − p0] is 3 × 2, and F = Ds Dm⁻¹ (3 × 2) maps the rest frame's axes to where they
//! are now: FᵀF = I for a triangle moved rigidly. Another choice of the frame turns F on the right
//! by a rotation of the plane, which changes none of FᵀF's invariants (trace, determinant).

use super::op::Op;
use super::{CompileError, Program, Value};
use crate::constraint_file::expression::Span;

/// Names a program knows without a definition, made when first used: the rest shape, the
/// material and the identity. `(name, what it is)`.
pub(crate) const GIVEN_NAMES: [(&str, &str); 12] = [
    ("q0", "the rest position of p0 (q1, q2, q3 likewise)"),
    (
        "start0",
        "where p0 was at the start of the substep (start1, start2, start3 likewise)",
    ),
    ("h", "the substep's length in seconds"),
    (
        "Dm",
        "the rest edges [q1 - q0, q2 - q0, q3 - q0] as columns (a triangle's: 2 × 2, in its own frame)",
    ),
    (
        "Ds",
        "the edges [p1 - p0, p2 - p0, p3 - p0] as columns (a triangle's: 3 × 2)",
    ),
    ("F", "the deformation gradient Ds inverse(Dm)"),
    ("V0", "a tet's rest volume det(Dm) / 6"),
    ("A0", "a triangle's rest area det(Dm) / 2"),
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

/// The given names of an element of `arity` particles: a tet's or a triangle's.
pub(super) fn given_here(arity: usize) -> impl Iterator<Item = &'static str> {
    GIVEN_NAMES.iter().map(|g| g.0).filter(move |&g| match g {
        "Dm" | "Ds" | "F" => arity >= 3,
        "V0" => arity == 4,
        "A0" => arity == 3,
        _ => true,
    })
}

impl Program {
    /// A name the program knows without a definition ([`GIVEN_NAMES`]), made now; `None` for
    /// any other.
    pub(super) fn given(&mut self, name: &str, span: Span) -> Result<Option<Value>, CompileError> {
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
        let start = name
            .strip_prefix("start")
            .filter(|k| k.len() == 1)
            .and_then(|k| k.parse::<usize>().ok())
            .filter(|&k| k < self.arity);
        if let Some(k) = start {
            return Ok(Some(Value::vector(self.emit(
                Op::Start(k as u8),
                span,
                "a position at the start of the substep",
            )?)));
        }
        if name == "h" {
            return Ok(Some(Value::scalar(self.emit(Op::Step, span, "h")?)));
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
        if !matches!(name, "Dm" | "Ds" | "F" | "V0" | "A0") {
            return Ok(None);
        }
        if !given_here(self.arity).any(|g| g == name) {
            let whose = match name {
                "V0" => "a tet's (a triangle has A0)",
                "A0" => "a surface triangle's (a tet has V0)",
                _ => "a tet's or a triangle's",
            };
            return Err(CompileError {
                span,
                message: format!(
                    "`{name}` is {whose}: this binding has {} particles, p0…p{}",
                    ["no", "one", "two", "three", "four"][self.arity.min(4)],
                    self.arity.saturating_sub(1)
                ),
            });
        }
        if self.arity == 3 {
            return self.triangle(name, span).map(Some);
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
                self.product(ds, inverse, span)?
            }
        };
        Ok(Some(value))
    }

    /// `Dm`, `Ds`, `F` or `A0` of a surface triangle (the module's documentation).
    fn triangle(&mut self, name: &str, span: Span) -> Result<Value, CompileError> {
        let what: &'static str = match name {
            "Dm" => "Dm",
            "Ds" => "Ds",
            "A0" => "A0",
            _ => "F",
        };
        let edge = |program: &mut Program, corner: fn(u8) -> Op, k: u8| {
            let origin = program.emit(corner(0), span, what)?;
            let p = program.emit(corner(k), span, what)?;
            program.emit(Op::SubV(p, origin), span, what)
        };
        let ds = [edge(self, Op::Particle, 1)?, edge(self, Op::Particle, 2)?];
        let ds = self.shaped(3, &ds, span)?;
        if name == "Ds" {
            return Ok(ds);
        }
        let (e1, e2) = (
            edge(self, Op::RestParticle, 1)?,
            edge(self, Op::RestParticle, 2)?,
        );
        let normal = self.emit(Op::Cross(e1, e2), span, what)?;
        let twice_area = self.emit(Op::Length(normal), span, what)?;
        if name == "A0" {
            let two = self.emit(Op::Const(2.0), span, what)?;
            return Ok(Value::scalar(self.emit(
                Op::DivS(twice_area, two),
                span,
                what,
            )?));
        }
        let length = self.emit(Op::Length(e1), span, what)?;
        let along = self.emit(Op::Dot(e1, e2), span, what)?;
        let along = self.emit(Op::DivS(along, length), span, what)?;
        let across = self.emit(Op::DivS(twice_area, length), span, what)?;
        let zero = self.emit(Op::Const(0.0), span, what)?;
        let first = self.vector2(length, zero, span)?;
        let second = self.vector2(along, across, span)?;
        let dm = self.shaped(2, &[first, second], span)?;
        if name == "Dm" {
            return Ok(dm);
        }
        let inverse = self.inverse(dm, span)?;
        self.product(ds, inverse, span)
    }
}
