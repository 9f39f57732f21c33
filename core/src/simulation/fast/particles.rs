//! The positions the kernels read and move, without a bounds check per access: the one place
//! tetlab uses `unsafe`.
//!
//! Sound because of one invariant of the fast solver: every particle index in a
//! [`super::batches::Batches`] is below its `particle_count` (checked when it is built, and its
//! fields are private), and a [`Particles`] is only made for a family whose `particle_count` is
//! the positions' length (checked in [`Particles::new`]). Threads sharing a colour never write
//! the same particle, nor read one another's writes: the constraints of a colour share none
//! ([`super::batches::Layout::colouring_is_valid`]), and a padding lane repeats a particle of
//! its own batch, which one thread projects. (With the Jacobi order, the threads only read the
//! positions and write the sums.)
#![allow(unsafe_code)]

use crate::numbers::lanes::{padded, unpadded};
use glam::Vec3A;
use std::marker::PhantomData;
use wide::f32x4;

/// Positions borrowed for the projection of one family, and what their rounding left out
/// (optional, [`Particles::compensated`]).
#[derive(Clone, Copy)]
pub(crate) struct Particles<'a> {
    ptr: *mut Vec3A,
    /// The residuals, one per position, or null.
    residuals: *mut Vec3A,
    len: usize,
    borrow: PhantomData<&'a mut [Vec3A]>,
}

// SAFETY: the threads share the pointer but never an element (see the module).
unsafe impl Send for Particles<'_> {}
unsafe impl Sync for Particles<'_> {}

impl<'a> Particles<'a> {
    /// `positions`, for batches built for `particle_count` particles.
    pub(crate) fn new(positions: &'a mut [Vec3A], particle_count: usize) -> Self {
        assert_eq!(positions.len(), particle_count, "batches of another body");
        Particles {
            ptr: positions.as_mut_ptr(),
            residuals: std::ptr::null_mut(),
            len: positions.len(),
            borrow: PhantomData,
        }
    }

    /// `positions` with their `residuals` ([`crate::simulation::integrate::Residuals`]): a correction
    /// added by [`Particles::add`] keeps what rounding the sum to f32 leaves out. Without them
    /// a correction smaller than half an ulp of its position is lost whole: at 100 substeps a
    /// hanging bar's restoring corrections are of that size (gravity moves it 2.7·10⁻⁷ m a
    /// substep, two f32 ulps at 2 m), and it sagged 13 % too far on the neo-Hookean pair.
    pub(crate) fn compensated(
        positions: &'a mut [Vec3A],
        residuals: &'a mut [Vec3A],
        particle_count: usize,
    ) -> Self {
        assert_eq!(
            residuals.len(),
            positions.len(),
            "one residual per position"
        );
        Particles {
            residuals: residuals.as_mut_ptr(),
            ..Particles::new(positions, particle_count)
        }
    }

    /// Particle `i` as four lanes: x, y, z and a fourth the kernels ignore.
    #[inline(always)]
    pub(crate) fn get(self, i: u32) -> f32x4 {
        debug_assert!((i as usize) < self.len);
        // SAFETY: i is an index of the batches, below `len` (see the module).
        padded(unsafe { self.ptr.add(i as usize).read() })
    }

    /// Moves particle `i` by the first three lanes of `delta` (its fourth is zero): with
    /// residuals, x + r moves by δ (x = fl(x + (δ + r)), r = (δ + r) − (x_new − x)).
    #[inline(always)]
    pub(crate) fn add(self, i: u32, delta: f32x4) {
        debug_assert!((i as usize) < self.len);
        // SAFETY: as for `get`; and no other thread reads or writes particle i meanwhile; the
        // residuals, when there are any, are one per position (checked in `compensated`).
        unsafe {
            let p = self.ptr.add(i as usize);
            if self.residuals.is_null() {
                p.write(p.read() + unpadded(delta));
            } else {
                let r = self.residuals.add(i as usize);
                let x = p.read();
                let step = unpadded(delta) + r.read();
                let moved = x + step;
                r.write(step - (moved - x));
                p.write(moved);
            }
        }
    }
}
