//! The instructions of a tape ([`Op`]): what each computes from the registers it reads
//! ([`Op::apply`], generic over [`Real`]), the registers it reads, and why its value is not
//! finite when it is not. Its derivative rule is in `derivative.rs`
//! ([`super::Program::differentiate`]).

use crate::constraint_file::expression::CompareOp;
use crate::numbers::columns::{add3, cross, dot, mat_vec, scale, shrink, sub3};
use crate::numbers::vector::Real;
use arrayvec::ArrayVec;

/// A register. In a [`super::Program`], the index of the instruction that defines it; in a
/// [`super::Tape`], where its value starts among the tape's numbers ([`super::tape::MAX_SLOTS`]): a
/// scalar is one number there, a vector three.
pub(super) type Reg = u16;

/// The most operations the expressions of a file may take in all.
pub(crate) const MAX_WRITTEN: usize = 160;

/// The most registers (instructions) a program may have, its gradient's included
/// ([`super::Program::differentiate`]): tapes keep their registers on the stack, so that an
/// evaluation allocates nothing.
pub(crate) const MAX_REGISTERS: usize = 4 * MAX_WRITTEN;

pub(crate) use crate::constraints::MAX_STORED;

/// The most numbers a tape's registers hold: three for each vector.
pub(super) const MAX_SLOTS: usize = 3 * MAX_REGISTERS;

/// One instruction; it defines the register of its own index from the registers it names.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Op {
    /// A number.
    Const(f64),
    /// A constant vector (from folding, or the columns of `I`).
    ConstVector([f64; 3]),
    Particle(u8),
    /// A particle's rest position.
    RestParticle(u8),
    /// A particle's position at the start of the substep.
    Start(u8),
    /// The substep's length h.
    Step,
    /// μ, λ or γ = 1 + μ/λ of the material.
    Material(u8),
    Rest,
    NegS(Reg),
    NegV(Reg),
    AddS(Reg, Reg),
    SubS(Reg, Reg),
    MulS(Reg, Reg),
    DivS(Reg, Reg),
    AddV(Reg, Reg),
    SubV(Reg, Reg),
    /// vector × scalar.
    Scale(Reg, Reg),
    /// vector ÷ scalar.
    Shrink(Reg, Reg),
    Dot(Reg, Reg),
    Cross(Reg, Reg),
    Length(Reg),
    Normalize(Reg),
    Sqrt(Reg),
    Abs(Reg),
    Min(Reg, Reg),
    Max(Reg, Reg),
    Det(Reg, Reg, Reg),
    /// A matrix (its columns c₀, c₁, c₂) times a vector v: c₀ v.x + c₁ v.y + c₂ v.z, summed in
    /// that order. One instruction for what would be eight (three components, three scalings,
    /// two sums): a matrix product is three of them.
    MatVec(Reg, Reg, Reg, Reg),
    Sin(Reg),
    Cos(Reg),
    Exp(Reg),
    Ln(Reg),
    /// atan2(y, x).
    Atan2(Reg, Reg),
    Asin(Reg),
    Acos(Reg),
    Cbrt(Reg),
    Sign(Reg),
    /// A vector's component 0, 1 or 2.
    Component(Reg, u8),
    Vec3(Reg, Reg, Reg),
    /// `if(a cmp b, then, otherwise)` of scalars.
    If(CompareOp, Reg, Reg, Reg, Reg),
    /// `if(a cmp b, then, otherwise)` of vectors.
    IfVector(CompareOp, Reg, Reg, Reg, Reg),
    /// Column k of the rotation R of the polar decomposition F = R S, F's columns being the three
    /// registers ([`Real::polar`]): a matrix result is its three columns, each one instruction.
    PolarColumn(Reg, Reg, Reg, u8),
    /// The signed singular values (σ₀, σ₁, σ₂) of F ([`Real::signed_svd`]).
    SingularValues(Reg, Reg, Reg),
    /// Column k of U of F's signed SVD ([`Real::signed_svd`]).
    SvdU(Reg, Reg, Reg, u8),
    /// Column k of V of F's signed SVD.
    SvdV(Reg, Reg, Reg, u8),
    /// All three columns of R, U or V of F at once, into this register and the next two: what a
    /// tape runs for the three column instructions of one matrix (each of which would decompose
    /// F again), the first replaced by this and the other two by [`Op::Written`].
    Decomposed(Decomposition, Reg, Reg, Reg),
    /// Nothing: the value was written by the [`Op::Decomposed`] before it.
    Written,
}

/// Which matrix of F's decompositions an [`Op::Decomposed`] writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Decomposition {
    /// R of F = R S.
    Polar,
    /// U of F = U diag(σ) Vᵀ.
    U,
    /// V of F = U diag(σ) Vᵀ.
    V,
}

impl Op {
    /// The column instruction this is, as (which matrix, F's columns, the column), if it is one.
    pub(super) fn column_of(self) -> Option<(Decomposition, [Reg; 3], u8)> {
        match self {
            Op::PolarColumn(a, b, c, k) => Some((Decomposition::Polar, [a, b, c], k)),
            Op::SvdU(a, b, c, k) => Some((Decomposition::U, [a, b, c], k)),
            Op::SvdV(a, b, c, k) => Some((Decomposition::V, [a, b, c], k)),
            _ => None,
        }
    }
}

impl Op {
    /// The same instruction with each register r it reads replaced by `f(r)`, in order.
    pub(super) fn map_inputs(self, mut f: impl FnMut(Reg) -> Reg) -> Op {
        use Op::*;
        match self {
            Const(_) | ConstVector(_) | Particle(_) | RestParticle(_) | Material(_) | Rest
            | Start(_) | Step | Written => self,
            NegS(a) => NegS(f(a)),
            NegV(a) => NegV(f(a)),
            Length(a) => Length(f(a)),
            Normalize(a) => Normalize(f(a)),
            Sqrt(a) => Sqrt(f(a)),
            Abs(a) => Abs(f(a)),
            Sin(a) => Sin(f(a)),
            Cos(a) => Cos(f(a)),
            Exp(a) => Exp(f(a)),
            Ln(a) => Ln(f(a)),
            Asin(a) => Asin(f(a)),
            Acos(a) => Acos(f(a)),
            Cbrt(a) => Cbrt(f(a)),
            Sign(a) => Sign(f(a)),
            Component(a, i) => Component(f(a), i),
            AddS(a, b) => AddS(f(a), f(b)),
            SubS(a, b) => SubS(f(a), f(b)),
            MulS(a, b) => MulS(f(a), f(b)),
            DivS(a, b) => DivS(f(a), f(b)),
            AddV(a, b) => AddV(f(a), f(b)),
            SubV(a, b) => SubV(f(a), f(b)),
            Scale(a, b) => Scale(f(a), f(b)),
            Shrink(a, b) => Shrink(f(a), f(b)),
            Dot(a, b) => Dot(f(a), f(b)),
            Cross(a, b) => Cross(f(a), f(b)),
            Min(a, b) => Min(f(a), f(b)),
            Max(a, b) => Max(f(a), f(b)),
            Atan2(a, b) => Atan2(f(a), f(b)),
            Det(a, b, c) => Det(f(a), f(b), f(c)),
            MatVec(a, b, c, v) => {
                let (a, b) = (f(a), f(b));
                let (c, v) = (f(c), f(v));
                MatVec(a, b, c, v)
            }
            Vec3(a, b, c) => Vec3(f(a), f(b), f(c)),
            SingularValues(a, b, c) => SingularValues(f(a), f(b), f(c)),
            PolarColumn(a, b, c, k) => PolarColumn(f(a), f(b), f(c), k),
            SvdU(a, b, c, k) => SvdU(f(a), f(b), f(c), k),
            SvdV(a, b, c, k) => SvdV(f(a), f(b), f(c), k),
            Decomposed(which, a, b, c) => Decomposed(which, f(a), f(b), f(c)),
            If(cmp, a, b, t, e) => {
                let (a, b) = (f(a), f(b));
                let (t, e) = (f(t), f(e));
                If(cmp, a, b, t, e)
            }
            IfVector(cmp, a, b, t, e) => {
                let (a, b) = (f(a), f(b));
                let (t, e) = (f(t), f(e));
                IfVector(cmp, a, b, t, e)
            }
        }
    }

    /// Whether it is `other`, to the bit: constants are compared by their bits, so that 0 and −0
    /// are two.
    pub(super) fn same_as(self, other: Op) -> bool {
        match (self, other) {
            (Op::Const(a), Op::Const(b)) => a.to_bits() == b.to_bits(),
            (Op::ConstVector(a), Op::ConstVector(b)) => a.map(f64::to_bits) == b.map(f64::to_bits),
            _ => self == other,
        }
    }

    /// The registers it reads.
    pub(super) fn inputs(self) -> ArrayVec<Reg, 4> {
        let mut out = ArrayVec::new();
        self.map_inputs(|r| {
            out.push(r);
            r
        });
        out
    }

    /// The same instruction reading `map[r]` for each register r it reads.
    pub(super) fn renumbered(self, map: &[Reg]) -> Op {
        self.map_inputs(|r| map[r as usize])
    }

    /// Whether its value is a vector.
    pub(super) fn is_vector(self) -> bool {
        matches!(
            self,
            Op::Particle(_)
                | Op::RestParticle(_)
                | Op::Start(_)
                | Op::NegV(_)
                | Op::AddV(..)
                | Op::SubV(..)
                | Op::Scale(..)
                | Op::Shrink(..)
                | Op::Cross(..)
                | Op::Normalize(_)
                | Op::Vec3(..)
                | Op::MatVec(..)
                | Op::ConstVector(_)
                | Op::IfVector(..)
                | Op::PolarColumn(..)
                | Op::SingularValues(..)
                | Op::SvdU(..)
                | Op::SvdV(..)
                | Op::Decomposed(..)
                | Op::Written
        )
    }

    /// Whether C has a kink (or a jump) where this instruction switches: the zeros of `abs`'s
    /// and `sign`'s argument, where `min`'s or `max`'s two agree, an `if`'s boundary.
    pub(super) fn switches(self) -> bool {
        matches!(
            self,
            Op::Abs(_) | Op::Min(..) | Op::Max(..) | Op::Sign(_) | Op::If(..) | Op::IfVector(..)
        )
    }

    /// Its value, from the registers `r` it reads (earlier ones) and the inputs, written into `r`
    /// from `at`: one number for a scalar, three for a vector.
    #[inline(always)]
    pub(super) fn apply<T: Real>(self, r: &mut [T], at: usize, inputs: &Inputs<'_, T>) {
        // Each arm writes its own value, so that nothing wider than it is moved.
        macro_rules! s {
            ($i:expr) => {
                r[$i as usize]
            };
        }
        macro_rules! v {
            ($i:expr) => {{
                let from = $i as usize;
                [r[from], r[from + 1], r[from + 2]]
            }};
        }
        macro_rules! scalar {
            ($x:expr) => {{
                let x = $x;
                r[at] = x;
            }};
        }
        macro_rules! vector {
            ($v:expr) => {{
                let [x, y, z] = $v;
                r[at] = x;
                r[at + 1] = y;
                r[at + 2] = z;
            }};
        }
        match self {
            Op::Const(x) => scalar!(T::from_f64(x)),
            Op::ConstVector(x) => vector!(x.map(T::from_f64)),
            Op::Particle(k) => vector!(inputs.points[k as usize]),
            Op::RestParticle(k) => vector!(inputs.shape[k as usize]),
            Op::Start(k) => vector!(inputs.start[k as usize]),
            Op::Step => scalar!(inputs.h),
            Op::Material(k) => scalar!(inputs.material[k as usize]),
            Op::Rest => scalar!(inputs.rest),
            Op::NegS(a) => scalar!(-s!(a)),
            Op::NegV(a) => vector!(scale(v!(a), -T::ONE)),
            Op::AddS(a, b) => scalar!(s!(a) + s!(b)),
            Op::SubS(a, b) => scalar!(s!(a) - s!(b)),
            Op::MulS(a, b) => scalar!(s!(a) * s!(b)),
            Op::DivS(a, b) => scalar!(s!(a) / s!(b)),
            Op::AddV(a, b) => vector!(add3(v!(a), v!(b))),
            Op::SubV(a, b) => vector!(sub3(v!(a), v!(b))),
            Op::Scale(a, b) => vector!(scale(v!(a), s!(b))),
            Op::Shrink(a, b) => vector!(shrink(v!(a), s!(b))),
            Op::Dot(a, b) => scalar!(dot(v!(a), v!(b))),
            Op::Cross(a, b) => vector!(cross(v!(a), v!(b))),
            Op::Length(a) => scalar!(dot(v!(a), v!(a)).sqrt()),
            Op::Normalize(a) => vector!(shrink(v!(a), dot(v!(a), v!(a)).sqrt())),
            Op::Sqrt(a) => scalar!(s!(a).sqrt()),
            Op::Abs(a) => {
                let x = s!(a);
                scalar!(T::select(x.le(T::ZERO), -x, x))
            }
            Op::Min(a, b) => {
                let (x, y) = (s!(a), s!(b));
                scalar!(T::select(x.le(y), x, y))
            }
            Op::Max(a, b) => {
                let (x, y) = (s!(a), s!(b));
                scalar!(T::select(x.gt(y), x, y))
            }
            Op::Det(a, b, c) => scalar!(dot(v!(a), cross(v!(b), v!(c)))),
            Op::MatVec(a, b, c, x) => vector!(mat_vec([v!(a), v!(b), v!(c)], v!(x))),
            Op::Sin(a) => scalar!(s!(a).sin()),
            Op::Cos(a) => scalar!(s!(a).cos()),
            Op::Exp(a) => scalar!(s!(a).exp()),
            Op::Ln(a) => scalar!(s!(a).ln()),
            Op::Atan2(y, x) => scalar!(s!(y).atan2(s!(x))),
            Op::Asin(a) => scalar!(s!(a).asin()),
            Op::Acos(a) => scalar!(s!(a).acos()),
            Op::Cbrt(a) => scalar!(s!(a).cbrt()),
            Op::Sign(a) => {
                let x = s!(a);
                let negative = T::select(T::ZERO.gt(x), -T::ONE, T::ZERO);
                scalar!(T::select(x.gt(T::ZERO), T::ONE, negative))
            }
            Op::Component(a, i) => scalar!(r[a as usize + i as usize]),
            Op::Vec3(a, b, c) => vector!([s!(a), s!(b), s!(c)]),
            Op::If(cmp, a, b, t, e) => {
                let mask = holds(cmp, s!(a), s!(b));
                scalar!(T::select(mask, s!(t), s!(e)))
            }
            Op::IfVector(cmp, a, b, t, e) => {
                let mask = holds(cmp, s!(a), s!(b));
                let (t, e) = (v!(t), v!(e));
                vector!([0, 1, 2].map(|k| T::select(mask, t[k], e[k])))
            }
            Op::PolarColumn(a, b, c, k) => vector!(T::polar([v!(a), v!(b), v!(c)])[k as usize]),
            Op::SingularValues(a, b, c) => vector!(T::signed_svd([v!(a), v!(b), v!(c)]).sigma),
            Op::SvdU(a, b, c, k) => vector!(T::signed_svd([v!(a), v!(b), v!(c)]).u[k as usize]),
            Op::SvdV(a, b, c, k) => vector!(T::signed_svd([v!(a), v!(b), v!(c)]).v[k as usize]),
            Op::Decomposed(which, a, b, c) => {
                let f = [v!(a), v!(b), v!(c)];
                let columns = match which {
                    Decomposition::Polar => T::polar(f),
                    Decomposition::U => T::signed_svd(f).u,
                    Decomposition::V => T::signed_svd(f).v,
                };
                for (j, column) in columns.iter().enumerate() {
                    r[at + 3 * j..at + 3 * j + 3].copy_from_slice(column);
                }
            }
            Op::Written => {}
        }
    }

    /// Why its value is not finite, given the finite values of what it reads (`s` reads a
    /// scalar).
    pub(super) fn undefined(self, s: impl Fn(Reg) -> f64) -> String {
        match self {
            Op::DivS(_, b) | Op::Shrink(_, b) if s(b) == 0.0 => "division by zero".to_owned(),
            Op::Ln(a) => format!("log of {}: log is defined above 0", s(a)),
            Op::Sqrt(a) => format!("sqrt of {}: sqrt is defined from 0 up", s(a)),
            Op::Asin(a) => format!("asin of {}: asin is defined on -1..1", s(a)),
            Op::Acos(a) => format!("acos of {}: acos is defined on -1..1", s(a)),
            Op::Normalize(_) => "normalize of a zero vector: it has no direction".to_owned(),
            _ => "the result is too large for f64".to_owned(),
        }
    }
}

/// h where no substep gives one (the check, a reader of the rest state): the default substep,
/// 1/60 s over 100 substeps (`core/tests/constraint_language.rs` checks it against the defaults).
pub const RESTING_H: f64 = 1.0 / 6000.0;

/// What a tape reads besides its instructions: the particles, their rest positions, where they
/// were at the start of the substep and its length h, the rest value, the material (μ, λ, γ) and
/// the numbers stored for the element.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Inputs<'a, T> {
    /// p0, p1, …
    pub points: &'a [[T; 3]],
    /// q0, q1, …: the rest positions (the points again, for a tape that reads none).
    pub shape: &'a [[T; 3]],
    /// start0, start1, …: the positions at the start of the substep (the points again where no
    /// substep gives them).
    pub start: &'a [[T; 3]],
    /// `h`, the substep's length in seconds ([`RESTING_H`] where no substep gives one).
    pub h: T,
    /// `rest`.
    pub rest: T,
    /// μ, λ and γ = 1 + μ/λ.
    pub material: [T; 3],
    /// What the element stores ([`super::Compiled::prelude`] worked it out).
    pub stored: &'a [T],
}

impl<'a, T: Real> Inputs<'a, T> {
    /// The inputs of a tape that reads only the particles and `rest`: at rest (the particles
    /// where they were at the start of the substep, h = [`RESTING_H`]).
    pub(crate) fn of(points: &'a [[T; 3]], rest: T) -> Self {
        Inputs {
            points,
            shape: points,
            start: points,
            h: T::from_f64(RESTING_H),
            rest,
            material: [T::ZERO; 3],
            stored: &[],
        }
    }
}

/// Whether `a cmp b` (false with a NaN).
#[inline(always)]
pub(crate) fn holds<T: Real>(cmp: CompareOp, a: T, b: T) -> T::Mask {
    match cmp {
        CompareOp::Less => b.gt(a),
        CompareOp::LessOrEqual => a.le(b),
        CompareOp::Greater => a.gt(b),
        CompareOp::GreaterOrEqual => b.le(a),
    }
}
