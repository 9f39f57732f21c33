//! The positions the kernels read and move, without a bounds check per access: the one place
//! tetlab uses `unsafe`.
//!
//! Sound because of one invariant of the fast solver: every particle index in a
//! [`super::batches::Batches`] is below its `particle_count` (checked when it is built, and its
//! fields are private), and a [`Particles`] is only made for a family whose `particle_count` is
//! the positions' length (checked in [`Particles::new`]). Threads sharing a colour never write
//! the same particle, nor read one another's writes: the constraints of a colour share none
//! ([`super::batches::Batches::colouring_is_valid`]), and a padding lane repeats a particle of
//! its own batch, which one thread projects. (With the Jacobi order, the threads only read the
//! positions and write the sums.)
#![allow(unsafe_code)]

use crate::lanes::{padded, unpadded};
use glam::Vec3A;
use std::marker::PhantomData;
use wide::f32x4;

/// Positions borrowed for the projection of one family.
#[derive(Clone, Copy)]
pub(crate) struct Particles<'a> {
    ptr: *mut Vec3A,
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
            len: positions.len(),
            borrow: PhantomData,
        }
    }

    /// Particle `i` as four lanes: x, y, z and a fourth the kernels ignore.
    #[inline(always)]
    pub(crate) fn get(self, i: u32) -> f32x4 {
        debug_assert!((i as usize) < self.len);
        // SAFETY: i is an index of the batches, below `len` (see the module).
        padded(unsafe { self.ptr.add(i as usize).read() })
    }

    /// Puts particle `i` at the first three lanes of `position`.
    #[inline(always)]
    pub(crate) fn set(self, i: u32, position: f32x4) {
        debug_assert!((i as usize) < self.len);
        // SAFETY: as for `get`; and no other thread reads or writes particle i meanwhile.
        unsafe { self.ptr.add(i as usize).write(unpadded(position)) }
    }

    /// Moves particle `i` by the first three lanes of `delta` (its fourth is zero).
    #[inline(always)]
    pub(crate) fn add(self, i: u32, delta: f32x4) {
        debug_assert!((i as usize) < self.len);
        // SAFETY: as for `get`; and no other thread reads or writes particle i meanwhile.
        unsafe {
            let p = self.ptr.add(i as usize);
            p.write(p.read() + unpadded(delta));
        }
    }
}
