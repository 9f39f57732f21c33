//! How long the large colours take, and each thread's share of them: a diagnostic of the fast
//! engine's threads, compiled in only with the feature `share-timers` (without it every function
//! here is the closure it is given, and [`report`] is `None`). docs/performance.md ("Two threads
//! on the Xeon") reads it through `tetlab bench`:
//!
//! ```text
//! cargo run --release --features tetlab-core/share-timers -- bench --scene cube --resolution 15 --threads 2
//! ```
//!
//! A colour counts when it is large enough to be shared ([`super::PARALLEL_MIN`] elements or
//! more), whether a team shares it or one thread projects it all, so that one thread's figures
//! and two threads' compare colour for colour. On a body cut into regions only the last level is
//! projected colour by colour, so only its colours are timed ([`super::batches`], "Regions").
//! The sums are process-wide: one simulation at a time.

#[cfg(feature = "share-timers")]
mod enabled {
    use std::sync::atomic::{AtomicU64, Ordering};
    use std::time::Instant;

    /// Per worker (0 the caller, up to 8): nanoseconds in shares, and shares.
    static SHARE_NS: [AtomicU64; 8] = [const { AtomicU64::new(0) }; 8];
    static SHARES: [AtomicU64; 8] = [const { AtomicU64::new(0) }; 8];
    static COLOUR_NS: AtomicU64 = AtomicU64::new(0);
    static COLOURS: AtomicU64 = AtomicU64::new(0);

    fn timed<R>(ns: &AtomicU64, count: &AtomicU64, f: impl FnOnce() -> R) -> R {
        let start = Instant::now();
        let result = f();
        ns.fetch_add(start.elapsed().as_nanos() as u64, Ordering::Relaxed);
        count.fetch_add(1, Ordering::Relaxed);
        result
    }

    pub(crate) fn colour<R>(large: bool, f: impl FnOnce() -> R) -> R {
        if large {
            timed(&COLOUR_NS, &COLOURS, f)
        } else {
            f()
        }
    }

    pub(crate) fn share<R>(worker: usize, f: impl FnOnce() -> R) -> R {
        match (SHARE_NS.get(worker), SHARES.get(worker)) {
            (Some(ns), Some(count)) => timed(ns, count, f),
            _ => f(),
        }
    }

    pub(crate) fn reset() {
        for counter in SHARE_NS.iter().chain(&SHARES).chain([&COLOUR_NS, &COLOURS]) {
            counter.store(0, Ordering::Relaxed);
        }
    }

    pub(crate) fn report() -> Option<String> {
        let mean = |ns: &AtomicU64, count: &AtomicU64| {
            ns.load(Ordering::Relaxed) as f64 / count.load(Ordering::Relaxed).max(1) as f64 / 1e3
        };
        let colours = COLOURS.load(Ordering::Relaxed);
        let mut text = format!(
            "{colours} large colours, {:.2} µs each",
            mean(&COLOUR_NS, &COLOURS)
        );
        for (worker, (ns, count)) in SHARE_NS.iter().zip(&SHARES).enumerate() {
            if count.load(Ordering::Relaxed) > 0 {
                text += &format!("; thread {worker}'s share {:.2} µs", mean(ns, count));
            }
        }
        Some(text)
    }
}

#[cfg(feature = "share-timers")]
pub(crate) use enabled::{colour, report, reset, share};

/// Runs `f`, a colour (timed with the feature `share-timers` when `large`).
#[cfg(not(feature = "share-timers"))]
#[inline(always)]
pub(crate) fn colour<R>(_large: bool, f: impl FnOnce() -> R) -> R {
    f()
}

/// Runs `f`, worker `worker`'s share of a colour (timed with the feature `share-timers`).
#[cfg(not(feature = "share-timers"))]
#[inline(always)]
pub(crate) fn share<R>(_worker: usize, f: impl FnOnce() -> R) -> R {
    f()
}

/// Starts the sums afresh (with the feature `share-timers`).
#[cfg(not(feature = "share-timers"))]
#[inline(always)]
pub(crate) fn reset() {}

/// The mean time of a large colour and of each thread's share of one, since [`reset`]; `None`
/// without the feature `share-timers`.
#[cfg(not(feature = "share-timers"))]
pub(crate) fn report() -> Option<String> {
    None
}
