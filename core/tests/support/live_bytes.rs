//! A global allocator that counts, per thread, the allocations made and the bytes held
//! (allocated minus freed): for tests that show a step allocates nothing and that live memory
//! stays flat. Per thread, because the other tests of a binary run (and allocate) at the same
//! time. It only forwards to [`System`].

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// Counts each thread's allocations and the bytes it holds.
pub struct LiveBytes;

thread_local! {
    static LIVE: Cell<isize> = const { Cell::new(0) };
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for LiveBytes {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // During thread teardown the counter may be gone; those bytes are no test's.
        let _ = LIVE.try_with(|n| n.set(n.get() + layout.size() as isize));
        let _ = ALLOCATIONS.try_with(|n| n.set(n.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        let _ = LIVE.try_with(|n| n.set(n.get() - layout.size() as isize));
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: LiveBytes = LiveBytes;

/// The bytes the calling thread holds now (relative to an arbitrary start).
#[allow(dead_code)]
pub fn live() -> isize {
    LIVE.with(Cell::get)
}

/// The allocations the calling thread has made so far.
#[allow(dead_code)]
pub fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}
