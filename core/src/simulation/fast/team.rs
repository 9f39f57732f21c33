//! The threads the fast engine shares its large colours with: a team started once with the
//! simulation and kept for its whole life ([`Team`]). A colour is one job: every worker (the
//! calling thread is worker 0) projects its own contiguous share of the colour's batches, and the
//! caller waits until all have, which is the barrier between two colours. Between jobs a worker
//! spins briefly, then yields, then sleeps until the next job, so a paused simulation's threads
//! are idle and a running one's hand over in well under a microsecond instead of waking from
//! sleep at every colour. A job allocates nothing.
//!
//! Which worker projects which batch changes nothing: the batches of one colour share no
//! particle, so the result is the same to the bit for any number of threads.
//!
//! ```
//! use std::sync::atomic::{AtomicUsize, Ordering};
//! use tetlab_core::simulation::fast::Team;
//! let team = Team::new(3);
//! let ran = AtomicUsize::new(0);
//! // Every worker runs the job once, and `run` returns once all have.
//! team.run(&|worker| {
//!     assert!(worker < 3);
//!     ran.fetch_add(1 << (8 * worker), Ordering::Relaxed);
//! });
//! assert_eq!(ran.load(Ordering::Relaxed), 0x01_01_01);
//! ```

// The one other `unsafe` module of the fast engine, beside `particles`: a job borrowed from the
// caller's stack is run on other threads (as `std::thread::scope` would, without starting threads
// for each colour), and a slice is written in disjoint parts by them.
#![allow(unsafe_code)]

use std::sync::atomic::{AtomicBool, AtomicPtr, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex};

/// A job: what each worker runs, given its number (0 is the caller).
pub(super) type Job<'a> = &'a (dyn Fn(usize) + Sync);

/// The most threads a team has.
pub(super) const MAX_THREADS: usize = 64;

/// How many times a waiting thread checks for the next job before it starts to yield (a few
/// microseconds: a colour's hand-over; longer spins cost other processes' time on a busy machine).
const SPINS: u32 = 1 << 8;
/// How long it then yields before it goes to sleep: longer than the serial work between two
/// shared colours (small colours, the other families, the ground), so that a running simulation's
/// threads are never woken from sleep, which costs tens of microseconds.
const YIELD_FOR: std::time::Duration = std::time::Duration::from_millis(2);

/// Threads kept for a simulation's life, that run one job at a time with the caller.
pub struct Team {
    threads: usize,
    shared: Arc<Shared>,
    handles: Vec<std::thread::JoinHandle<()>>,
}

/// What the caller and the workers share.
struct Shared {
    /// Grows by one for each job; a worker runs a job when it sees it change.
    epoch: AtomicUsize,
    /// The job under way: a pointer to the caller's `Job`, valid until every worker is done.
    job: AtomicPtr<()>,
    /// Workers that have not finished the job under way.
    pending: AtomicUsize,
    /// Workers asleep, waiting for a job.
    sleepers: AtomicUsize,
    /// Set when a worker's job panicked; the caller panics in turn.
    panicked: AtomicBool,
    /// Set when the team is dropped.
    stop: AtomicBool,
    lock: Mutex<()>,
    wake: Condvar,
}

impl Team {
    /// A team of `threads` in all (at most `MAX_THREADS`): the caller and `threads − 1`
    /// workers started now (none for 1).
    pub fn new(threads: usize) -> Team {
        let threads = threads.clamp(1, MAX_THREADS);
        let shared = Arc::new(Shared {
            epoch: AtomicUsize::new(0),
            job: AtomicPtr::new(std::ptr::null_mut()),
            pending: AtomicUsize::new(0),
            sleepers: AtomicUsize::new(0),
            panicked: AtomicBool::new(false),
            stop: AtomicBool::new(false),
            lock: Mutex::new(()),
            wake: Condvar::new(),
        });
        let handles = (1..threads)
            .map(|worker| {
                let shared = Arc::clone(&shared);
                std::thread::Builder::new()
                    .name(format!("tetlab worker {worker}"))
                    .spawn(move || shared.work(worker))
                    .expect("a thread can be started")
            })
            .collect();
        Team {
            threads,
            shared,
            handles,
        }
    }

    /// How many threads run a job, the caller's included.
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// How many of its workers are asleep, waiting for a job: all of them soon after the last
    /// job (a paused simulation's threads use no CPU).
    #[cfg(test)]
    pub(crate) fn sleeping(&self) -> usize {
        self.shared.sleepers.load(Ordering::SeqCst)
    }

    /// Runs `job(worker)` for every worker `0..threads()`, worker 0 on this thread, and returns
    /// when every one has returned. Panics when a worker's job panicked.
    pub fn run(&self, job: Job<'_>) {
        if self.threads == 1 {
            job(0);
            return;
        }
        let shared = &self.shared;
        shared.pending.store(self.threads - 1, Ordering::Relaxed);
        // The workers read the job only between this epoch and `pending` reaching zero, which
        // `run` waits for before `job` goes out of scope.
        shared
            .job
            .store(&job as *const Job<'_> as *mut (), Ordering::Relaxed);
        shared.epoch.fetch_add(1, Ordering::SeqCst);
        if shared.sleepers.load(Ordering::SeqCst) > 0 {
            let _guard = shared.lock.lock().unwrap_or_else(|e| e.into_inner());
            shared.wake.notify_all();
        }
        job(0);
        let mut waited = 0u32;
        while shared.pending.load(Ordering::Acquire) > 0 {
            waited = waited.saturating_add(1);
            if waited < SPINS {
                std::hint::spin_loop();
            } else {
                std::thread::yield_now();
            }
        }
        shared.job.store(std::ptr::null_mut(), Ordering::Relaxed);
        if shared.panicked.swap(false, Ordering::Relaxed) {
            panic!("a thread of the fast engine panicked");
        }
    }
}

impl Shared {
    /// A worker's life: wait for a job, run it, say so; until the team is dropped.
    fn work(&self, worker: usize) {
        let mut seen = 0;
        loop {
            let mut waited = 0u32;
            let mut yielding = None;
            loop {
                let epoch = self.epoch.load(Ordering::SeqCst);
                if epoch != seen {
                    seen = epoch;
                    break;
                }
                if self.stop.load(Ordering::Acquire) {
                    return;
                }
                waited = waited.saturating_add(1);
                if waited < SPINS {
                    std::hint::spin_loop();
                    continue;
                }
                let since = *yielding.get_or_insert_with(std::time::Instant::now);
                if since.elapsed() < YIELD_FOR {
                    std::thread::yield_now();
                } else {
                    let mut guard = self.lock.lock().unwrap_or_else(|e| e.into_inner());
                    self.sleepers.fetch_add(1, Ordering::SeqCst);
                    while self.epoch.load(Ordering::SeqCst) == seen
                        && !self.stop.load(Ordering::Acquire)
                    {
                        guard = self.wake.wait(guard).unwrap_or_else(|e| e.into_inner());
                    }
                    self.sleepers.fetch_sub(1, Ordering::SeqCst);
                    waited = 0;
                    yielding = None;
                }
            }
            // Safety: the caller keeps the job alive until `pending` reaches zero, below.
            let job = unsafe { *(self.job.load(Ordering::Relaxed) as *const Job<'_>) };
            let ran = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| job(worker)));
            if ran.is_err() {
                self.panicked.store(true, Ordering::Relaxed);
            }
            self.pending.fetch_sub(1, Ordering::Release);
        }
    }
}

impl Drop for Team {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::Release);
        {
            let _guard = self.shared.lock.lock().unwrap_or_else(|e| e.into_inner());
            self.shared.wake.notify_all();
        }
        for handle in self.handles.drain(..) {
            handle.join().ok();
        }
    }
}

impl std::fmt::Debug for Team {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Team({} threads)", self.threads)
    }
}

/// Worker `worker`'s share of `len` items among `workers`: a contiguous range, the shares in
/// worker order, their sizes differing by at most one. (Contiguous shares, not chunks dealt in
/// turn: neighbouring batches write neighbouring particles, and two threads writing into the
/// same cache lines slow each other down, which dealing chunks was measured to do.)
pub(crate) fn share(len: usize, worker: usize, workers: usize) -> std::ops::Range<usize> {
    let workers = workers.max(1);
    len * worker / workers..len * (worker + 1) / workers
}

/// `K` slices of one length that the workers of one job write in disjoint parts: worker w's
/// [`share`] of each, or the parts given by [`Disjoint::cut`], handed out once
/// ([`Disjoint::take`]).
pub(crate) struct Disjoint<'a, T, const K: usize> {
    starts: [*mut T; K],
    /// Worker w's part is cuts[w]..cuts[w + 1].
    cuts: [usize; MAX_THREADS + 1],
    workers: usize,
    /// Bit w: worker w's part was handed out.
    taken: std::sync::atomic::AtomicU64,
    _slices: std::marker::PhantomData<&'a mut [T]>,
}

// Safety: every part is handed out at most once and no two overlap ([`Disjoint::take`]), so
// sharing a `Disjoint` between threads shares no element.
unsafe impl<T: Send, const K: usize> Sync for Disjoint<'_, T, K> {}

impl<'a, T, const K: usize> Disjoint<'a, T, K> {
    /// `slices` (all of one length), to be written in `workers` parts (at most [`MAX_THREADS`]).
    pub(crate) fn new(slices: [&'a mut [T]; K], workers: usize) -> Self {
        let len = slices.first().map_or(0, |s| s.len());
        Self::cut(slices, workers, |w| share(len, w, workers).start)
    }

    /// `slices` (all of one length), worker w's part starting at `cut(w)`: `cut(0)` must be 0,
    /// `cut(workers)` their length, and the cuts in order.
    pub(crate) fn cut(
        slices: [&'a mut [T]; K],
        workers: usize,
        cut: impl Fn(usize) -> usize,
    ) -> Self {
        let len = slices.first().map_or(0, |s| s.len());
        assert!(slices.iter().all(|s| s.len() == len));
        assert!((1..=MAX_THREADS).contains(&workers));
        let mut cuts = [0; MAX_THREADS + 1];
        for (w, at) in cuts.iter_mut().enumerate().take(workers + 1) {
            *at = cut(w);
        }
        assert!(
            cuts[0] == 0 && cuts[workers] == len,
            "the parts cover the slices"
        );
        assert!(cuts[..=workers].is_sorted(), "the parts are in order");
        Disjoint {
            starts: slices.map(|s| s.as_mut_ptr()),
            cuts,
            workers,
            taken: std::sync::atomic::AtomicU64::new(0),
            _slices: std::marker::PhantomData,
        }
    }

    /// Worker `worker`'s part of each slice and where it lies. Panics when that part
    /// was handed out before.
    #[allow(clippy::mut_from_ref)] // each part once: the bit of `taken`
    pub(crate) fn take(&self, worker: usize) -> ([&mut [T]; K], std::ops::Range<usize>) {
        assert!(worker < self.workers);
        let before = self.taken.fetch_or(1 << worker, Ordering::Relaxed);
        assert!(
            before & (1 << worker) == 0,
            "worker {worker}'s part is taken"
        );
        let range = self.cuts[worker]..self.cuts[worker + 1];
        // Safety: in bounds and disjoint from every other worker's part (the cuts cover the
        // slices, in order: checked in `cut`), and handed out once (the bit above).
        let parts = self
            .starts
            .map(|p| unsafe { std::slice::from_raw_parts_mut(p.add(range.start), range.len()) });
        (parts, range)
    }
}

/// Skip counts added up from several workers (an integer sum: the same for any order).
#[derive(Default)]
pub(crate) struct SharedSkips {
    degenerate: std::sync::atomic::AtomicU64,
    too_long: std::sync::atomic::AtomicU64,
}

impl SharedSkips {
    /// Adds one worker's counts.
    pub(crate) fn add(&self, skips: crate::simulation::projection::SkipCounts) {
        self.degenerate
            .fetch_add(skips.degenerate, Ordering::Relaxed);
        self.too_long.fetch_add(skips.too_long, Ordering::Relaxed);
    }

    /// The sum.
    pub(crate) fn get(&self) -> crate::simulation::projection::SkipCounts {
        crate::simulation::projection::SkipCounts {
            degenerate: self.degenerate.load(Ordering::Relaxed),
            too_long: self.too_long.load(Ordering::Relaxed),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shares_cover_every_item_once_in_order() {
        for len in [0, 1, 7, 64, 1000] {
            for workers in 1..=5 {
                let mut next = 0;
                for worker in 0..workers {
                    let range = share(len, worker, workers);
                    assert_eq!(range.start, next);
                    assert!(range.len() <= len / workers + 1);
                    next = range.end;
                }
                assert_eq!(next, len);
            }
        }
    }

    #[test]
    fn each_worker_writes_its_part_and_a_part_is_handed_out_once() {
        let team = Team::new(3);
        let (mut a, mut b) = (vec![0usize; 100], vec![0usize; 100]);
        for _ in 0..50 {
            // A job after another: the workers wake, spin and wait between them.
            let mut few = [0u8; 4];
            let parts = Disjoint::new([&mut few[..]], 3);
            team.run(&|worker| {
                parts.take(worker);
            });
        }
        let parts = Disjoint::new([&mut a[..], &mut b[..]], 3);
        team.run(&|worker| {
            let ([a, b], range) = parts.take(worker);
            for (k, (a, b)) in range.zip(a.iter_mut().zip(b.iter_mut())) {
                *a = k;
                *b = worker;
            }
        });
        let again = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| parts.take(1)));
        assert!(again.is_err(), "worker 1's part was handed out already");
        for k in 0..100 {
            assert_eq!(a[k], k);
            assert!(
                share(100, b[k], 3).contains(&k),
                "{k} written by worker {}",
                b[k]
            );
        }
    }

    #[test]
    fn parts_cut_where_asked_must_cover_the_slices_in_order() {
        let mut a = [0u8; 10];
        let parts = Disjoint::cut([&mut a[..]], 3, |w| [0, 4, 4, 10][w]);
        assert_eq!(parts.take(1).1, 4..4, "a worker may have nothing");
        assert_eq!(parts.take(2).1, 4..10);
        let backwards = std::panic::catch_unwind(|| {
            let mut a = [0u8; 10];
            Disjoint::cut([&mut a[..]], 2, |w| [0, 6, 4][w]).take(0).1
        });
        assert!(backwards.is_err(), "parts out of order would overlap");
        let short = std::panic::catch_unwind(|| {
            let mut a = [0u8; 10];
            Disjoint::cut([&mut a[..]], 2, |w| [0, 4, 8][w]).take(0).1
        });
        assert!(short.is_err(), "parts must cover the slices");
    }

    #[test]
    fn between_jobs_the_workers_go_to_sleep_and_wake_for_the_next() {
        let team = Team::new(3);
        for round in 0..3 {
            let count = AtomicUsize::new(0);
            team.run(&|_| {
                count.fetch_add(1, Ordering::Relaxed);
            });
            assert_eq!(count.load(Ordering::Relaxed), 3, "round {round}");
            let started = std::time::Instant::now();
            while team.sleeping() < 2 {
                assert!(
                    started.elapsed() < std::time::Duration::from_secs(10),
                    "the workers are still awake after 10 s"
                );
                std::thread::sleep(std::time::Duration::from_millis(1));
            }
        }
    }

    #[test]
    fn a_panicking_job_panics_in_the_caller_and_the_team_goes_on() {
        let team = Team::new(2);
        let ran = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            team.run(&|worker| assert!(worker == 0, "worker {worker} fails"));
        }));
        assert!(ran.is_err());
        let count = AtomicUsize::new(0);
        team.run(&|_| {
            count.fetch_add(1, Ordering::Relaxed);
        });
        assert_eq!(count.load(Ordering::Relaxed), 2);
    }
}
