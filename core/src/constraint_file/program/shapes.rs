//! Matrices and vectors of two or three: how a [`Value`] of each shape is laid out in registers,
//! and the operations that depend on the shape: components (`v.x`, `M.c0`, `M.r1`, `M.xy`),
//! column-wise arithmetic, products, the transpose, the inverse, the determinant, the trace and
//! the Frobenius norm.
//!
//! A 2-vector is a vector register whose z is 0 (every instruction that makes one keeps it so),
//! and a matrix of `r` rows and `c` columns is `c` column registers, each an `r`-vector; a
//! 2-column matrix's third register is the zero vector, so that `M v` is one
//! [`Op::MatVec`] whatever the shape.

use super::op::{Op, Reg};
use super::{CompileError, Program, Type, Value};
use crate::constraint_file::expression::Span;

impl Program {
    /// The zero vector's register.
    pub(super) fn zero_vector(&mut self, span: Span) -> Result<Reg, CompileError> {
        self.emit(Op::ConstVector([0.0; 3]), span, "0")
    }

    /// The 2-vector (x, y).
    pub(super) fn vector2(&mut self, x: Reg, y: Reg, span: Span) -> Result<Reg, CompileError> {
        let zero = self.emit(Op::Const(0.0), span, "0")?;
        self.emit(Op::Vec3(x, y, zero), span, "vec2")
    }

    /// A matrix of `rows` rows whose columns are `columns` (two or three of them).
    pub(super) fn shaped(
        &mut self,
        rows: u8,
        columns: &[Reg],
        span: Span,
    ) -> Result<Value, CompileError> {
        let mut r = [0; 3];
        r[..columns.len()].copy_from_slice(columns);
        if columns.len() == 2 {
            r[2] = self.zero_vector(span)?;
        }
        Ok(Value {
            r,
            ty: Type::Matrix(rows, columns.len() as u8),
        })
    }

    /// `op` applied to each column of matrix `m` (`column` gives the instruction for one).
    pub(super) fn columns(
        &mut self,
        m: Value,
        span: Span,
        what: &'static str,
        column: impl Fn(Reg) -> Op,
    ) -> Result<Value, CompileError> {
        let (rows, count) = m.ty.shape();
        let mut out = [0; 3];
        for (j, slot) in out.iter_mut().enumerate().take(count as usize) {
            *slot = self.emit(column(m.r[j]), span, what)?;
        }
        self.shaped(rows, &out[..count as usize], span)
    }

    /// M v = Σⱼ cⱼ vⱼ, one instruction ([`Op::MatVec`]).
    pub(super) fn times_vector(
        &mut self,
        m: Value,
        v: Reg,
        span: Span,
    ) -> Result<Reg, CompileError> {
        let [c0, c1, c2] = m.r;
        self.emit(Op::MatVec(c0, c1, c2, v), span, "*")
    }

    /// A B, column by column: (A B)ⱼ = A bⱼ; the shapes are checked by the caller.
    pub(super) fn product(
        &mut self,
        a: Value,
        b: Value,
        span: Span,
    ) -> Result<Value, CompileError> {
        let (rows, _) = a.ty.shape();
        let (_, count) = b.ty.shape();
        let mut out = [0; 3];
        for (j, slot) in out.iter_mut().enumerate().take(count as usize) {
            *slot = self.times_vector(a, b.r[j], span)?;
        }
        self.shaped(rows, &out[..count as usize], span)
    }

    /// Mᵀ: its rows as columns.
    pub(super) fn transpose(&mut self, m: Value, span: Span) -> Result<Value, CompileError> {
        let (rows, count) = m.ty.shape();
        let zero = self.emit(Op::Const(0.0), span, "transpose")?;
        let mut out = [0; 3];
        for (i, row) in out.iter_mut().enumerate().take(rows as usize) {
            let mut entries = [zero; 3];
            for (j, entry) in entries.iter_mut().enumerate().take(count as usize) {
                *entry = self.emit(Op::Component(m.r[j], i as u8), span, "transpose")?;
            }
            *row = self.emit(
                Op::Vec3(entries[0], entries[1], entries[2]),
                span,
                "transpose",
            )?;
        }
        self.shaped(count, &out[..rows as usize], span)
    }

    /// The entries a, b, c, d of a 2 × 2 matrix [a b; c d] (columns (a, c) and (b, d)).
    fn entries2(
        &mut self,
        m: Value,
        span: Span,
        what: &'static str,
    ) -> Result<[Reg; 4], CompileError> {
        let a = self.emit(Op::Component(m.r[0], 0), span, what)?;
        let c = self.emit(Op::Component(m.r[0], 1), span, what)?;
        let b = self.emit(Op::Component(m.r[1], 0), span, what)?;
        let d = self.emit(Op::Component(m.r[1], 1), span, what)?;
        Ok([a, b, c, d])
    }

    /// det M of a square matrix: c₀·(c₁ × c₂), or ad − bc.
    pub(super) fn determinant(
        &mut self,
        m: Value,
        span: Span,
        what: &'static str,
    ) -> Result<Reg, CompileError> {
        if m.ty == Type::MATRIX {
            let [c0, c1, c2] = m.r;
            return self.emit(Op::Det(c0, c1, c2), span, what);
        }
        let [a, b, c, d] = self.entries2(m, span, what)?;
        let ad = self.emit(Op::MulS(a, d), span, what)?;
        let bc = self.emit(Op::MulS(b, c), span, what)?;
        self.emit(Op::SubS(ad, bc), span, what)
    }

    /// M⁻¹ of a square matrix: the rows (c₁×c₂, c₂×c₀, c₀×c₁) / det M, transposed into columns;
    /// or [d −b; −c a] / (ad − bc).
    pub(super) fn inverse(&mut self, m: Value, span: Span) -> Result<Value, CompileError> {
        let det = self.determinant(m, span, "inverse")?;
        if m.ty == Type::MATRIX {
            let [c0, c1, c2] = m.r;
            let mut rows = [0; 3];
            for (k, (a, b)) in [(c1, c2), (c2, c0), (c0, c1)].into_iter().enumerate() {
                let cross = self.emit(Op::Cross(a, b), span, "inverse")?;
                rows[k] = self.emit(Op::Shrink(cross, det), span, "inverse")?;
            }
            return self.transpose(Value::matrix(rows), span);
        }
        let [a, b, c, d] = self.entries2(m, span, "inverse")?;
        let (minus_b, minus_c) = (
            self.emit(Op::NegS(b), span, "inverse")?,
            self.emit(Op::NegS(c), span, "inverse")?,
        );
        let mut columns = [0; 2];
        for (column, (x, y)) in columns.iter_mut().zip([(d, minus_c), (minus_b, a)]) {
            let v = self.vector2(x, y, span)?;
            *column = self.emit(Op::Shrink(v, det), span, "inverse")?;
        }
        self.shaped(2, &columns, span)
    }

    /// tr M of a square matrix: the sum of its diagonal.
    pub(super) fn trace(&mut self, m: Value, span: Span) -> Result<Reg, CompileError> {
        let (n, _) = m.ty.shape();
        let mut sum = self.emit(Op::Component(m.r[0], 0), span, "trace")?;
        for j in 1..n {
            let entry = self.emit(Op::Component(m.r[j as usize], j), span, "trace")?;
            sum = self.emit(Op::AddS(sum, entry), span, "trace")?;
        }
        Ok(sum)
    }

    /// ‖M‖_F = √(Σⱼ cⱼ·cⱼ).
    pub(super) fn norm(&mut self, m: Value, span: Span) -> Result<Reg, CompileError> {
        let (_, count) = m.ty.shape();
        let mut sum = self.emit(Op::Dot(m.r[0], m.r[0]), span, "norm")?;
        for j in 1..count as usize {
            let square = self.emit(Op::Dot(m.r[j], m.r[j]), span, "norm")?;
            sum = self.emit(Op::AddS(sum, square), span, "norm")?;
        }
        self.emit(Op::Sqrt(sum), span, "norm")
    }

    /// `a.x` and the like: a vector's components; a matrix's columns `.c0`…, rows `.r0`… and
    /// entries `.xy` (row x, column y), as many as its shape has.
    pub(super) fn member(
        &mut self,
        a: Value,
        component: &str,
        span: Span,
    ) -> Result<Value, CompileError> {
        let axes = |n: u8| &"xyz"[..n as usize];
        let axis = |c: char, n: u8| axes(n).find(c);
        match a.ty {
            Type::Vector(n) => match component.chars().next().and_then(|c| axis(c, n)) {
                Some(i) if component.len() == 1 => Ok(Value::scalar(self.emit(
                    Op::Component(a.r[0], i as u8),
                    span,
                    ".",
                )?)),
                _ => {
                    let list: Vec<String> = axes(n).chars().map(|c| format!(".{c}")).collect();
                    Err(CompileError {
                        span,
                        message: format!(
                            "{} has components {}, not .{component}",
                            a.ty.article(),
                            and_list(&list)
                        ),
                    })
                }
            },
            Type::Matrix(rows, count) => {
                let mut chars = component.chars();
                let (first, second) = (chars.next(), chars.next());
                let digit = |c: Option<char>, n: u8| {
                    c.and_then(|c| c.to_digit(10))
                        .filter(|&d| d < n as u32)
                        .map(|d| d as usize)
                };
                match (first, second, component.len()) {
                    (Some('c'), d, 2) if digit(d, count).is_some() => Ok(Value {
                        r: [a.r[digit(d, count).unwrap_or(0)]; 3],
                        ty: Type::Vector(rows),
                    }),
                    (Some('r'), d, 2) if digit(d, rows).is_some() => {
                        let transposed = self.transpose(a, span)?;
                        Ok(Value {
                            r: [transposed.r[digit(d, rows).unwrap_or(0)]; 3],
                            ty: Type::Vector(count),
                        })
                    }
                    (Some(x), Some(y), 2)
                        if axis(x, rows).is_some() && axis(y, count).is_some() =>
                    {
                        let (i, j) = (axis(x, rows).unwrap_or(0), axis(y, count).unwrap_or(0));
                        Ok(Value::scalar(self.emit(
                            Op::Component(a.r[j], i as u8),
                            span,
                            ".",
                        )?))
                    }
                    _ => {
                        let numbered = |letter: char, n: u8| -> Vec<String> {
                            (0..n).map(|k| format!(".{letter}{k}")).collect()
                        };
                        let (first, last) = (
                            ".xx .xy",
                            format!(
                                ".{}{}",
                                &axes(rows)[rows as usize - 1..],
                                &axes(count)[count as usize - 1..]
                            ),
                        );
                        Err(CompileError {
                            span,
                            message: format!(
                                "{} has columns {}, rows {} and entries {first} … {last} \
                                 (row, column), not .{component}",
                                a.ty.article(),
                                numbered('c', count).join(" "),
                                numbered('r', rows).join(" "),
                            ),
                        })
                    }
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
}

/// "a, b and c".
fn and_list(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}
