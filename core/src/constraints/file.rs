//! A constraint file's family as a [`Constraint`]: its compiled tape gives C and ∇C. The file
//! joins the table of families in [`super::Families`].

use super::{Constraint, Evaluation, SubstepStart};
use super::{GROUP, MAX_STORED, Stored};
use crate::constraint_file::{ConstraintFile, sound};
use crate::constraints::material::Material;
use crate::numbers::block::Block;
use crate::numbers::lanes::{F32x8, Vec3x8};
use crate::numbers::vector::{Real, Vector3};
use arrayvec::ArrayVec;
use glam::DVec3;
use std::sync::Arc;

/// A constraint file's family as a [`Constraint`] on N particles: C and ∇C from the file's
/// compiled tape ([`ConstraintFile::evaluate_vectors`]), the rest value as the file defines it.
/// Whether it reads the rest shape is the file's ([`ConstraintFile::reads_rest_shape`], its row's
/// [`super::Row::reads_rest_shape`]), so that the solvers' code for files is compiled once per
/// arity.
pub struct FileConstraint<const N: usize>(pub Arc<ConstraintFile>);

impl<const N: usize> Constraint<N> for FileConstraint<N> {
    // What a file's tapes read of the rest shape at each projection is stored.
    const STORED_USES_REST_SHAPE: bool = false;
    // The tape's dispatch on each instruction, paid once for GROUP batches.
    const GROUPED: bool = true;

    /// C and ∇C with what the element stores worked out here from `rest_shape` and the default
    /// material: for the checkers and readers that hold no stored values (the solvers call
    /// [`Constraint::evaluate_stored`]).
    #[inline]
    fn evaluate<V: Vector3>(&self, p: &[V; N], rest: V::Real, shape: &[V; N]) -> Evaluation<V, N> {
        if self.0.stored_len() == 0 {
            return self.0.evaluate_vectors(p, rest, &[]);
        }
        let mut stored: ArrayVec<V::Real, MAX_STORED> = ArrayVec::new();
        let shape: [[V::Real; 3]; N] = std::array::from_fn(|k| shape[k].to_array());
        for x in self.0.store_in(&shape, &Material::default()) {
            stored.push(x);
        }
        self.0.evaluate_vectors(p, rest, &stored)
    }

    fn reads_motion(&self) -> bool {
        self.0.reads_motion()
    }

    #[inline(always)]
    fn evaluate_stored<V: Vector3>(
        &self,
        p: &[V; N],
        rest: V::Real,
        _: &[V; N],
        stored: &[V::Real],
        motion: SubstepStart<'_, V, N>,
    ) -> Evaluation<V, N> {
        let own = self.0.use_gradient;
        self.0
            .evaluate_by_moving(p, (motion.start, motion.h), rest, stored, own)
    }

    /// The GROUP batches as one `Block` of lanes through the tape, then each batch's lanes
    /// taken out: each lane computes what it computes in [`Constraint::evaluate_stored`].
    #[inline(always)]
    // Indexed loops: the iterator forms compiled to copies of these wide arrays.
    #[allow(clippy::needless_range_loop)]
    fn evaluate_batches(
        &self,
        p: &[[Vec3x8; N]; GROUP],
        rest: [F32x8; GROUP],
        _: &[[Vec3x8; N]; GROUP],
        stored: [&[F32x8]; GROUP],
        motion: (&[[Vec3x8; N]; GROUP], F32x8),
    ) -> [Evaluation<Vec3x8, N>; GROUP] {
        let mut out = [Evaluation {
            value: F32x8::ZERO,
            gradients: [Vec3x8::ZERO; N],
            degenerate: F32x8::ZERO.finite(),
        }; GROUP];
        through_tape(&self.0, p, (rest, stored), motion, &mut out);
        out
    }

    fn store(&self, rest_shape: &[DVec3; N], material: &Material) -> Stored {
        self.0.store(rest_shape, material)
    }

    fn rest_value(&self, rest_shape: &[DVec3; N], material: &Material) -> f64 {
        self.0.rest_value(rest_shape, material)
    }
}

/// The file's C and ∇C on a block of batches, as a call of its own: one copy of the interpreter
/// for every family and pair of this arity, which the instruction cache holds, rather than one
/// inlined into each kernel.
///
/// Its registers are this thread's [`SCRATCH`], not a new stack frame each call: a frame that
/// holds the most registers a tape may have (a hundred kilobytes of these wide numbers) costs more
/// to enter than a short tape costs to run.
#[inline(never)]
// Plain indexed loops, not `array::map`, `from_fn` or iterators over arrays: those compiled to
// copies of these wide arrays (memcpy), which cost more than the tape.
#[allow(clippy::needless_range_loop)]
fn through_tape<const N: usize>(
    file: &ConstraintFile,
    p: &[[Vec3x8; N]; GROUP],
    (rest, stored): ([F32x8; GROUP], [&[F32x8]; GROUP]),
    (start, h): (&[[Vec3x8; N]; GROUP], F32x8),
    out: &mut [Evaluation<Vec3x8, N>; GROUP],
) {
    let own = file.use_gradient;
    // Where the particles were, as blocks of the GROUP batches' lanes (read by the instructions
    // that name them; the particles again for a file that names none).
    let mut start_blocks = [[Block::<F32x8, GROUP>::ZERO; 3]; N];
    if file.reads_motion() {
        for j in 0..GROUP {
            for k in 0..N {
                let v = start[j][k];
                (
                    start_blocks[k][0].0[j],
                    start_blocks[k][1].0[j],
                    start_blocks[k][2].0[j],
                ) = (v.x, v.y, v.z);
            }
        }
    }
    let h = Block([h; GROUP]);
    SCRATCH.with_borrow_mut(|scratch| {
        let slots = file.gradient_slots(own);
        if scratch.len() < slots {
            // Once per thread and tape size: a later call of the same size allocates nothing.
            scratch.resize(slots, Block::ZERO);
        }
        // Each batch's lanes written into the registers where the tape reads them, a batch at a
        // time (never gathered into a block first and copied whole: a wide copy of what was
        // just written in halves waits for the writes to land), and taken out the same way.
        let place = |r: &mut [Block<F32x8, GROUP>], loads: &[u8]| {
            for j in 0..GROUP {
                for k in 0..N {
                    let v = p[j][k];
                    (r[3 * k].0[j], r[3 * k + 1].0[j], r[3 * k + 2].0[j]) = (v.x, v.y, v.z);
                }
                r[3 * N].0[j] = rest[j];
                for (i, &at) in loads.iter().enumerate() {
                    r[3 * N + 1 + i].0[j] = stored[j][at as usize];
                }
            }
        };
        file.gradient_placed((own, scratch), (&start_blocks, h), place, |r| {
            for j in 0..GROUP {
                let mut g = [[F32x8::ZERO; 3]; N];
                for k in 0..N {
                    let v = r.numbers(1 + k, 3);
                    for c in 0..3 {
                        g[k][c] = v[c].0[j];
                    }
                }
                out[j] = sound::<Vec3x8, N>(r.numbers(0, 1)[0].0[j], g);
            }
        });
    })
}

thread_local! {
    /// The registers of a file's tape, kept by each thread that projects a file's family on the
    /// fast engine ([`through_tape`]): grown to the largest tape it has run, never shrunk.
    static SCRATCH: std::cell::RefCell<Vec<Block<F32x8, GROUP>>> = const {
        std::cell::RefCell::new(Vec::new())
    };
}
