//! ∇C compiled: reverse-mode automatic differentiation carried out once, when a file is compiled,
//! over its instructions ([`Program::differentiate`]). Each instruction's derivative rule adds
//! new instructions to the program, so ∇C is worked out by an ordinary tape that runs front to
//! back like C's, in any [`crate::numbers::vector::Real`]: no backward pass at each projection,
//! no adjoints to clear and accumulate, and what is constant in the derivative (the adjoint 1 of
//! C, a `/ 6`) folded away as it is compiled.
//!
//! # Formula
//! For C computed by instructions rₖ = fₖ(rᵢ, rⱼ, …), the adjoint r̄ = ∂C/∂r is 1 at C and, from
//! C back, r̄ᵢ = Σₖ r̄ₖ ∂fₖ/∂rᵢ over the instructions k that read rᵢ (for r = a·b: ā += r̄ b,
//! b̄ += r̄ a). ∇ₚC is the adjoint of particle p. Each rule is written once, here; an instruction
//! that does not depend on a particle gets no adjoint.
//!
//! The sums are added in the order a backward pass would add them, so the compiled gradient is,
//! number for number, what reverse mode at run time gives. Run on
//! [`crate::numbers::dual::Tangent`] numbers, the gradient's tape gives the Hessian of C times the
//! tangent direction (forward over reverse).

use super::op::{Op, Reg};
use super::{CompileError, Origin, Program};
use crate::constraint_file::expression::CompareOp;

impl Program {
    /// Adds the instructions of ∇C, C being output `c` (a scalar), and one output per particle,
    /// its gradient (a vector; the zero vector for a particle C does not depend on). Returns
    /// those outputs, p0's first.
    pub(crate) fn differentiate(&mut self, c: usize) -> Result<Vec<usize>, CompileError> {
        let c = self.outputs[c] as usize;
        // Which instructions depend on a particle: only they carry an adjoint.
        let mut varies = vec![false; self.ops.len()];
        for (r, op) in self.ops.iter().enumerate() {
            varies[r] =
                matches!(op, Op::Particle(_)) || op.inputs().iter().any(|&i| varies[i as usize]);
        }
        let mut adjoints: Vec<Option<Reg>> = vec![None; self.ops.len()];
        let mut gradients: Vec<Option<Reg>> = vec![None; self.arity];
        if varies[c] {
            adjoints[c] = Some(self.emit_from(Op::Const(1.0), self.origins[c])?);
        }
        for k in (0..=c).rev() {
            let Some(bar) = adjoints[k] else { continue };
            let op = self.ops[k];
            let origin = self.origins[k];
            let mut rule = Rule {
                program: self,
                adjoints: &mut adjoints,
                varies: &varies,
                origin,
                own: k as Reg,
                bar,
            };
            if let Op::Particle(p) = op {
                let p = p as usize;
                if p < gradients.len() {
                    gradients[p] = Some(match gradients[p] {
                        None => bar,
                        Some(sum) => rule.emit(Op::AddV(sum, bar))?,
                    });
                }
            } else {
                rule.apply(op)?;
            }
        }
        let mut outputs = Vec::with_capacity(self.arity);
        for gradient in gradients {
            let r = match gradient {
                Some(r) => r,
                None => self.emit_from(Op::ConstVector([0.0; 3]), self.origins[c])?,
            };
            self.outputs.push(r);
            outputs.push(self.outputs.len() - 1);
        }
        Ok(outputs)
    }
}

/// One instruction's derivative rule at work: it reads the instruction's adjoint `bar` and adds
/// into the adjoints of what the instruction reads.
struct Rule<'a> {
    program: &'a mut Program,
    adjoints: &'a mut [Option<Reg>],
    varies: &'a [bool],
    /// Where the instruction came from: its derivative's instructions are placed there too.
    origin: Origin,
    /// The instruction's own register (its value).
    own: Reg,
    bar: Reg,
}

impl Rule<'_> {
    fn emit(&mut self, op: Op) -> Result<Reg, CompileError> {
        self.program.emit_from(op, self.origin)
    }

    /// Adds `value` (of `what`'s type) into the adjoint of register `i`, when `i` depends on a
    /// particle; `value` is worked out only then.
    fn add(
        &mut self,
        i: Reg,
        value: impl FnOnce(&mut Self) -> Result<Reg, CompileError>,
    ) -> Result<(), CompileError> {
        if !self.varies[i as usize] {
            return Ok(());
        }
        let value = value(self)?;
        let sum = match self.adjoints[i as usize] {
            None => value,
            Some(sum) if self.program.is_vector(i) => self.emit(Op::AddV(sum, value))?,
            Some(sum) => self.emit(Op::AddS(sum, value))?,
        };
        self.adjoints[i as usize] = Some(sum);
        Ok(())
    }

    /// Subtracts `value` from the adjoint of register `i` (−`value` when it has none yet): for a
    /// rule whose contribution is a negation, x + (−y) being x − y to the bit.
    fn subtract(&mut self, i: Reg, value: Reg) -> Result<(), CompileError> {
        if !self.varies[i as usize] {
            return Ok(());
        }
        let vector = self.program.is_vector(i);
        let difference = match (self.adjoints[i as usize], vector) {
            (None, true) => self.emit(Op::NegV(value))?,
            (None, false) => self.emit(Op::NegS(value))?,
            (Some(sum), true) => self.emit(Op::SubV(sum, value))?,
            (Some(sum), false) => self.emit(Op::SubS(sum, value))?,
        };
        self.adjoints[i as usize] = Some(difference);
        Ok(())
    }

    fn constant(&mut self, x: f64) -> Result<Reg, CompileError> {
        self.emit(Op::Const(x))
    }

    /// The derivative rule of `op`, the instruction whose adjoint is `self.bar`.
    fn apply(&mut self, op: Op) -> Result<(), CompileError> {
        let (s, bar, own) = (self.bar, self.bar, self.own);
        match op {
            Op::Const(_)
            | Op::ConstVector(_)
            | Op::Rest
            | Op::Sign(_)
            | Op::RestParticle(_)
            | Op::Start(_)
            | Op::Step
            | Op::Material(_)
            | Op::Particle(_) => {}
            Op::NegS(a) => self.subtract(a, s)?,
            Op::NegV(a) => self.subtract(a, bar)?,
            Op::AddS(a, b) => {
                self.add(a, |_| Ok(s))?;
                self.add(b, |_| Ok(s))?;
            }
            Op::SubS(a, b) => {
                self.add(a, |_| Ok(s))?;
                self.subtract(b, s)?;
            }
            Op::MulS(a, b) => {
                self.add(a, |r| r.emit(Op::MulS(s, b)))?;
                self.add(b, |r| r.emit(Op::MulS(s, a)))?;
            }
            Op::DivS(a, b) => {
                // r = a / b: ā += r̄ / b, b̄ −= r̄ r / b.
                self.add(a, |r| r.emit(Op::DivS(s, b)))?;
                self.add(b, |r| {
                    let product = r.emit(Op::MulS(s, own))?;
                    let negative = r.emit(Op::NegS(product))?;
                    r.emit(Op::DivS(negative, b))
                })?;
            }
            Op::AddV(a, b) => {
                self.add(a, |_| Ok(bar))?;
                self.add(b, |_| Ok(bar))?;
            }
            Op::SubV(a, b) => {
                self.add(a, |_| Ok(bar))?;
                self.subtract(b, bar)?;
            }
            Op::Scale(v, f) => {
                // r = v f: v̄ += r̄ f, f̄ += r̄·v.
                self.add(v, |r| r.emit(Op::Scale(bar, f)))?;
                self.add(f, |r| r.emit(Op::Dot(bar, v)))?;
            }
            Op::Shrink(v, f) => {
                // r = v / f: v̄ += r̄ / f, f̄ −= r̄·r / f.
                self.add(v, |r| r.emit(Op::Shrink(bar, f)))?;
                self.add(f, |r| {
                    let along = r.emit(Op::Dot(bar, own))?;
                    let negative = r.emit(Op::NegS(along))?;
                    r.emit(Op::DivS(negative, f))
                })?;
            }
            // r = a·a: ā += 2 r̄ a.
            Op::Dot(a, b) if a == b => self.add(a, |r| {
                let twice = r.emit(Op::AddS(s, s))?;
                r.emit(Op::Scale(a, twice))
            })?,
            Op::Dot(a, b) => {
                self.add(a, |r| r.emit(Op::Scale(b, s)))?;
                self.add(b, |r| r.emit(Op::Scale(a, s)))?;
            }
            Op::Cross(a, b) => {
                // r = a × b: ā += b × r̄, b̄ += r̄ × a.
                self.add(a, |r| r.emit(Op::Cross(b, bar)))?;
                self.add(b, |r| r.emit(Op::Cross(bar, a)))?;
            }
            Op::Length(a) => self.add(a, |r| {
                let k = r.emit(Op::DivS(s, own))?;
                r.emit(Op::Scale(a, k))
            })?,
            Op::Normalize(a) => self.add(a, |r| {
                // r = a / |a|: ā += (r̄ − r (r·r̄)) / |a|.
                let length = r.emit(Op::Length(a))?;
                let along = r.emit(Op::Dot(own, bar))?;
                let parallel = r.emit(Op::Scale(own, along))?;
                let across = r.emit(Op::SubV(bar, parallel))?;
                r.emit(Op::Shrink(across, length))
            })?,
            Op::Sqrt(a) => self.add(a, |r| {
                let twice = r.emit(Op::AddS(own, own))?;
                r.emit(Op::DivS(s, twice))
            })?,
            Op::Abs(a) => self.add(a, |r| {
                let zero = r.constant(0.0)?;
                let negative = r.emit(Op::NegS(s))?;
                r.emit(Op::If(CompareOp::LessOrEqual, a, zero, negative, s))
            })?,
            Op::Min(a, b) => self.switch(CompareOp::LessOrEqual, (a, b), (a, b), false)?,
            Op::Max(a, b) => self.switch(CompareOp::Greater, (a, b), (a, b), false)?,
            Op::If(cmp, a, b, t, e) => self.switch(cmp, (a, b), (t, e), false)?,
            Op::IfVector(cmp, a, b, t, e) => self.switch(cmp, (a, b), (t, e), true)?,
            Op::Det(a, b, c) => {
                // r = a·(b × c): ā += r̄ b×c, b̄ += r̄ c×a, c̄ += r̄ a×b.
                for (into, (x, y)) in [(a, (b, c)), (b, (c, a)), (c, (a, b))] {
                    self.add(into, |r| {
                        let cross = r.emit(Op::Cross(x, y))?;
                        r.emit(Op::Scale(cross, s))
                    })?;
                }
            }
            Op::MatVec(c0, c1, c2, v) => {
                // r = Σⱼ cⱼ vⱼ: c̄ⱼ += r̄ vⱼ, v̄ⱼ += r̄·cⱼ.
                for (j, column) in [c0, c1, c2].into_iter().enumerate() {
                    self.add(column, |r| {
                        let vj = r.emit(Op::Component(v, j as u8))?;
                        r.emit(Op::Scale(bar, vj))
                    })?;
                }
                self.add(v, |r| {
                    let [x, y, z] = [c0, c1, c2].map(|c| r.emit(Op::Dot(bar, c)));
                    r.emit(Op::Vec3(x?, y?, z?))
                })?;
            }
            // r = sin a: ā += r̄ cos a; r = cos a: ā −= r̄ sin a.
            Op::Sin(a) => self.add(a, |r| {
                let cos = r.emit(Op::Cos(a))?;
                r.emit(Op::MulS(s, cos))
            })?,
            Op::Cos(a) => self.add(a, |r| {
                let sin = r.emit(Op::Sin(a))?;
                let product = r.emit(Op::MulS(s, sin))?;
                r.emit(Op::NegS(product))
            })?,
            // r = eᵃ: ā += r̄ r; r = log a: ā += r̄ / a.
            Op::Exp(a) => self.add(a, |r| r.emit(Op::MulS(s, own)))?,
            Op::Ln(a) => self.add(a, |r| r.emit(Op::DivS(s, a)))?,
            Op::Atan2(y, x) => {
                // r = atan2(y, x): ȳ += r̄ x / (x² + y²), x̄ −= r̄ y / (x² + y²).
                let mut denominator = None;
                let mut squares = |r: &mut Self| -> Result<Reg, CompileError> {
                    if let Some(d) = denominator {
                        return Ok(d);
                    }
                    let xx = r.emit(Op::MulS(x, x))?;
                    let yy = r.emit(Op::MulS(y, y))?;
                    let d = r.emit(Op::AddS(xx, yy))?;
                    denominator = Some(d);
                    Ok(d)
                };
                self.add(y, |r| {
                    let d = squares(r)?;
                    let product = r.emit(Op::MulS(s, x))?;
                    r.emit(Op::DivS(product, d))
                })?;
                self.add(x, |r| {
                    let d = squares(r)?;
                    let product = r.emit(Op::MulS(s, y))?;
                    let negative = r.emit(Op::NegS(product))?;
                    r.emit(Op::DivS(negative, d))
                })?;
            }
            // r = asin a: ā += r̄ / √(1 − a²); r = acos a: ā −= r̄ / √(1 − a²).
            Op::Asin(a) => self.add(a, |r| {
                let root = r.one_minus_square_root(a)?;
                r.emit(Op::DivS(s, root))
            })?,
            Op::Acos(a) => self.add(a, |r| {
                let root = r.one_minus_square_root(a)?;
                let quotient = r.emit(Op::DivS(s, root))?;
                r.emit(Op::NegS(quotient))
            })?,
            // r = ∛a: ā += r̄ / (3 r²).
            Op::Cbrt(a) => self.add(a, |r| {
                let three = r.constant(3.0)?;
                let thrice = r.emit(Op::MulS(three, own))?;
                let square = r.emit(Op::MulS(thrice, own))?;
                r.emit(Op::DivS(s, square))
            })?,
            Op::Component(a, i) => self.add(a, |r| {
                let zero = r.constant(0.0)?;
                let mut entries = [zero; 3];
                entries[i as usize] = s;
                r.emit(Op::Vec3(entries[0], entries[1], entries[2]))
            })?,
            Op::Vec3(a, b, c) => {
                for (i, into) in [a, b, c].into_iter().enumerate() {
                    self.add(into, |r| r.emit(Op::Component(bar, i as u8)))?;
                }
            }
            Op::PolarColumn(c0, c1, c2, k) => self.polar_column([c0, c1, c2], k)?,
            Op::SingularValues(c0, c1, c2) => self.singular_values([c0, c1, c2])?,
            Op::SvdU(c0, c1, c2, k) => self.singular_vector([c0, c1, c2], k, true)?,
            Op::SvdV(c0, c1, c2, k) => self.singular_vector([c0, c1, c2], k, false)?,
            // Made only when a tape is cut, after differentiation.
            Op::Decomposed(..) | Op::Written => {}
        }
        Ok(())
    }

    /// r = column k of F's polar rotation R: with a = Rᵀ r̄, R̄ = r̄ eₖᵀ gives
    /// vee(RᵀR̄ − R̄ᵀR) = eₖ × a, and F̄ += R \[y\]ₓ with (tr S · I − S) y = eₖ × a, S = Rᵀ F
    /// (`numbers::svd3`: ⟨R̄, dR⟩ = ⟨R \[y\]ₓ, dF⟩). Not finite where two singular values sum to
    /// zero, where R has no derivative.
    fn polar_column(&mut self, f: [Reg; 3], k: u8) -> Result<(), CompileError> {
        if !f.iter().any(|&c| self.varies[c as usize]) {
            return Ok(());
        }
        let [c0, c1, c2] = f;
        let bar = self.bar;
        let unit = |j: usize| {
            let mut e = [0.0; 3];
            e[j] = 1.0;
            Op::ConstVector(e)
        };
        let mut r = [0; 3];
        for (j, column) in r.iter_mut().enumerate() {
            *column = self.emit(Op::PolarColumn(c0, c1, c2, j as u8))?;
        }
        let a = self.row_products(r, bar)?;
        let ek = self.emit(unit(k as usize))?;
        let b = self.emit(Op::Cross(ek, a))?;
        // S = Rᵀ F by columns, its trace, M = tr S · I − S, y = M⁻¹ b.
        let mut s = [0; 3];
        for (j, column) in s.iter_mut().enumerate() {
            *column = self.row_products(r, f[j])?;
        }
        let mut diagonal = [0; 3];
        for (j, entry) in diagonal.iter_mut().enumerate() {
            *entry = self.emit(Op::Component(s[j], j as u8))?;
        }
        let partial = self.emit(Op::AddS(diagonal[0], diagonal[1]))?;
        let trace = self.emit(Op::AddS(partial, diagonal[2]))?;
        let mut m = [0; 3];
        for (j, column) in m.iter_mut().enumerate() {
            let e = self.emit(unit(j))?;
            let along = self.emit(Op::Scale(e, trace))?;
            *column = self.emit(Op::SubV(along, s[j]))?;
        }
        let mut rows = [0; 3];
        for (row, (x, y)) in rows
            .iter_mut()
            .zip([(m[1], m[2]), (m[2], m[0]), (m[0], m[1])])
        {
            *row = self.emit(Op::Cross(x, y))?;
        }
        let det = self.emit(Op::Dot(m[0], rows[0]))?;
        let numerator = self.row_products(rows, b)?;
        let y = self.emit(Op::Shrink(numerator, det))?;
        for (j, column) in f.into_iter().enumerate() {
            self.add(column, |rule| {
                let e = rule.emit(unit(j))?;
                let turned = rule.emit(Op::Cross(y, e))?;
                rule.emit(Op::MatVec(r[0], r[1], r[2], turned))
            })?;
        }
        Ok(())
    }

    /// r = σ, F's signed singular values: F̄ += U diag(σ̄) Vᵀ, whose column j is
    /// U (σ̄ᵢ (vᵢ)ⱼ)ᵢ. Exact for what is symmetric in σ also where two σ are equal
    /// (`numbers::svd3`).
    fn singular_values(&mut self, f: [Reg; 3]) -> Result<(), CompileError> {
        if !f.iter().any(|&c| self.varies[c as usize]) {
            return Ok(());
        }
        let [c0, c1, c2] = f;
        let bar = self.bar;
        let (u, v) = self.singular_vectors([c0, c1, c2])?;
        let mut weight = [0; 3];
        for (i, w) in weight.iter_mut().enumerate() {
            *w = self.emit(Op::Component(bar, i as u8))?;
        }
        for (j, column) in f.into_iter().enumerate() {
            self.add(column, |rule| {
                let mut scaled = [0; 3];
                for i in 0..3 {
                    let entry = rule.emit(Op::Component(v[i], j as u8))?;
                    scaled[i] = rule.emit(Op::MulS(weight[i], entry))?;
                }
                let along = rule.emit(Op::Vec3(scaled[0], scaled[1], scaled[2]))?;
                rule.emit(Op::MatVec(u[0], u[1], u[2], along))
            })?;
        }
        Ok(())
    }

    /// r = column k of U (`left`) or of V of F's signed SVD. From dU = U Ω_U, dV = V Ω_V
    /// (`numbers::svd3`), with aₘ = uₘ·r̄ (or vₘ·r̄) and gₘ = σₖ² − σₘ² for each m ≠ k:
    /// F̄ += U P̄ Vᵀ, P̄ being zero but for P̄ₘₖ = aₘ σₖ / gₘ and P̄ₖₘ = aₘ σₘ / gₘ (U's; V's
    /// swaps σₖ and σₘ). Not finite where |σₖ| = |σₘ|, where the column has no derivative.
    fn singular_vector(&mut self, f: [Reg; 3], k: u8, left: bool) -> Result<(), CompileError> {
        if !f.iter().any(|&c| self.varies[c as usize]) {
            return Ok(());
        }
        let [c0, c1, c2] = f;
        let k = k as usize;
        let bar = self.bar;
        let (u, v) = self.singular_vectors([c0, c1, c2])?;
        let mut sigma = [0; 3];
        let values = self.emit(Op::SingularValues(c0, c1, c2))?;
        for (i, s) in sigma.iter_mut().enumerate() {
            *s = self.emit(Op::Component(values, i as u8))?;
        }
        // P̄ₘₖ and P̄ₖₘ for the two m ≠ k.
        let others: Vec<usize> = (0..3).filter(|&m| m != k).collect();
        let square_k = self.emit(Op::MulS(sigma[k], sigma[k]))?;
        let mut entries = Vec::with_capacity(2);
        for &m in &others {
            let a = self.emit(Op::Dot(if left { u[m] } else { v[m] }, bar))?;
            let square_m = self.emit(Op::MulS(sigma[m], sigma[m]))?;
            let gap = self.emit(Op::SubS(square_k, square_m))?;
            let share = self.emit(Op::DivS(a, gap))?;
            let (first, second) = if left {
                (sigma[k], sigma[m])
            } else {
                (sigma[m], sigma[k])
            };
            let mk = self.emit(Op::MulS(share, first))?;
            let km = self.emit(Op::MulS(share, second))?;
            entries.push((m, mk, km));
        }
        // Column j of U P̄ Vᵀ is U w with wₘ = P̄ₘₖ (vₖ)ⱼ and wₖ = Σₘ P̄ₖₘ (vₘ)ⱼ.
        for (j, column) in f.into_iter().enumerate() {
            self.add(column, |rule| {
                let mut w = [0; 3];
                let vkj = rule.emit(Op::Component(v[k], j as u8))?;
                let mut along_k = None;
                for &(m, mk, km) in &entries {
                    w[m] = rule.emit(Op::MulS(mk, vkj))?;
                    let vmj = rule.emit(Op::Component(v[m], j as u8))?;
                    let term = rule.emit(Op::MulS(km, vmj))?;
                    along_k = Some(match along_k {
                        None => term,
                        Some(sum) => rule.emit(Op::AddS(sum, term))?,
                    });
                }
                w[k] = along_k.expect("two others");
                let weights = rule.emit(Op::Vec3(w[0], w[1], w[2]))?;
                rule.emit(Op::MatVec(u[0], u[1], u[2], weights))
            })?;
        }
        Ok(())
    }

    /// U's columns, then V's, of F's signed SVD, each three one after the other so that a tape
    /// runs each matrix as one decomposition (`tape.rs`, `decompose_once`).
    fn singular_vectors(&mut self, f: [Reg; 3]) -> Result<([Reg; 3], [Reg; 3]), CompileError> {
        let [c0, c1, c2] = f;
        let mut u = [0; 3];
        for (i, column) in u.iter_mut().enumerate() {
            *column = self.emit(Op::SvdU(c0, c1, c2, i as u8))?;
        }
        let mut v = [0; 3];
        for (i, column) in v.iter_mut().enumerate() {
            *column = self.emit(Op::SvdV(c0, c1, c2, i as u8))?;
        }
        Ok((u, v))
    }

    /// (m₀·x, m₁·x, m₂·x): Mᵀ x for the matrix of columns `m`.
    fn row_products(&mut self, m: [Reg; 3], x: Reg) -> Result<Reg, CompileError> {
        let [a, b, c] = m.map(|column| self.emit(Op::Dot(column, x)));
        self.emit(Op::Vec3(a?, b?, c?))
    }

    /// √(1 − a²).
    fn one_minus_square_root(&mut self, a: Reg) -> Result<Reg, CompileError> {
        let one = self.constant(1.0)?;
        let square = self.emit(Op::MulS(a, a))?;
        let difference = self.emit(Op::SubS(one, square))?;
        self.emit(Op::Sqrt(difference))
    }

    /// The rule of a choice by `cmp` of (a, b) between (t, e), `min`, `max` and `if`: the adjoint
    /// goes to the branch taken, nothing to the other.
    fn switch(
        &mut self,
        cmp: CompareOp,
        (a, b): (Reg, Reg),
        (t, e): (Reg, Reg),
        vector: bool,
    ) -> Result<(), CompileError> {
        let bar = self.bar;
        let zero = if vector {
            self.emit(Op::ConstVector([0.0; 3]))?
        } else {
            self.constant(0.0)?
        };
        let choose = |taken: bool| {
            let (then, otherwise) = if taken { (bar, zero) } else { (zero, bar) };
            if vector {
                Op::IfVector(cmp, a, b, then, otherwise)
            } else {
                Op::If(cmp, a, b, then, otherwise)
            }
        };
        self.add(t, |r| r.emit(choose(true)))?;
        self.add(e, |r| r.emit(choose(false)))?;
        Ok(())
    }
}

#[cfg(test)]
mod examples {
    #[allow(unused_imports)]
    use super::*;

    /// The example of `differentiate`'s documentation (a unit test: the item is not exported).
    #[test]
    fn differentiate_example() {
        use crate::constraint_file::expression::parse_expression;
        use crate::constraint_file::program::{Inputs, Program, Type};
        // C = |p0 − p1| − rest: ∇p0 C is the unit vector from p1 to p0, ∇p1 C its negative.
        let mut program = Program::new(2, true);
        let c = program
            .output(
                &parse_expression("length(p0 - p1) - rest").unwrap(),
                Type::Scalar,
                "value",
            )
            .unwrap();
        let gradient = program.differentiate(c).unwrap();
        let mut outputs = vec![c];
        outputs.extend(&gradient);
        let tape = program.tape(&outputs);
        let points: [[f64; 3]; 2] = [[3.0, 0.0, 4.0], [0.0; 3]];
        tape.run(&Inputs::of(&points, 1.0), |r| {
            assert_eq!(r.scalar(0), 4.0);
            let (g0, g1) = (r.vector(1), r.vector(2));
            assert!((g0[0] - 0.6).abs() < 1e-15 && g0[1] == 0.0 && (g0[2] - 0.8).abs() < 1e-15);
            assert_eq!(g1, g0.map(|x| -x));
        });
    }
}
