//! Who projects which of a family's batches, and when: one sweep of a [`Layout`], level by level
//! (see [`super::batches`], "Regions"). At a level of several groups the threads share out the
//! groups, each projecting its own through all their colours, with no barrier between colours;
//! the last level, the whole body, is projected colour by colour, a large colour shared by the
//! threads, with a barrier after each.
//!
//! ```text
//! thread 0: (region 0, c0 … cC) (region 1, c0 … cC)   thread 1: (region 2, …) (region 3, …)
//! ─────────────────────────────── barrier ───────────────────────────────
//! thread 0: (regions 0–1, c0 … cC)                    thread 1: (regions 2–3, c0 … cC)
//! ─────────────────────────────── barrier ───────────────────────────────
//! (the body, c0): both threads ─ barrier ─ (the body, c1): both threads ─ barrier ─ …
//! ```
//!
//! With one region (a small body) there is one level: colour after colour, a large colour
//! shared. The result is the same to the bit for any number of threads: the groups of a level
//! share no particle, nor do a colour's batches.

use super::batches::{Colour, Layout, PARALLEL_MIN, group_index};
use super::share_timers;
use super::team::{Disjoint, SharedSkips, Team, share};
use crate::numbers::lanes::F32x8;
use crate::simulation::projection::SkipCounts;
use std::ops::Range;

/// Projects one sweep of `layout`, its colours in `order` (empty: the layout's), through
/// `project(batches, multipliers)`: the batches of one entry and the `K` families' multipliers
/// of those batches (`lambdas`: a row per batch of the layout). With a `team`, the threads share
/// the regions and the border's large colours. Returns the skips of each family, summed.
pub(crate) fn sweep<const K: usize, F>(
    layout: &Layout,
    order: &[u32],
    team: Option<&Team>,
    lambdas: [&mut [F32x8]; K],
    project: F,
) -> [SkipCounts; K]
where
    F: Fn(Range<usize>, [&mut [F32x8]; K]) -> [SkipCounts; K] + Sync,
{
    let regions = layout.regions();
    let mut skips = [SkipCounts::default(); K];
    let mut add = |more: [SkipCounts; K]| {
        for (sum, more) in skips.iter_mut().zip(more) {
            *sum = *sum + more;
        }
    };
    // What is left of the multipliers: the rows of batches `offset..`.
    let (mut lambda, mut offset) = (lambdas, 0);
    for level in 0..layout.levels() {
        let groups = layout.groups(level);
        let end = layout.group_batches(level, 0..groups).end;
        let rows = lambda.each_mut().map(|rest| {
            let (this, after) = std::mem::take(rest).split_at_mut(end - offset);
            *rest = after;
            this
        });
        if groups > 1 {
            add(groups_through_their_colours(
                layout,
                order,
                team,
                level,
                (rows, offset),
                &project,
            ));
        } else {
            add(colour_by_colour(
                layout,
                order,
                team,
                group_index(regions, level, 0),
                (rows, offset),
                &project,
            ));
        }
        offset = end;
    }
    skips
}

/// Level `level`'s groups, shared out among the threads (one thread projects a group through
/// all its colours); `lambda` holds the rows of the batches from `offset` on.
fn groups_through_their_colours<const K: usize, F>(
    layout: &Layout,
    order: &[u32],
    team: Option<&Team>,
    level: usize,
    (lambda, offset): ([&mut [F32x8]; K], usize),
    project: &F,
) -> [SkipCounts; K]
where
    F: Fn(Range<usize>, [&mut [F32x8]; K]) -> [SkipCounts; K] + Sync,
{
    let groups = layout.groups(level);
    // Groups `groups` through all their colours, their rows in `lambda` from batch `offset`.
    let project_groups = |groups: Range<usize>, lambda: &mut [&mut [F32x8]; K], offset: usize| {
        let mut skips = [SkipCounts::default(); K];
        for group in groups {
            let group = group_index(layout.regions(), level, group);
            for k in 0..layout.colour_count() {
                let batches = layout.entry(group, k, order).batches.clone();
                let rows = batches.start - offset..batches.end - offset;
                let more = project(batches, lambda.each_mut().map(|l| &mut l[rows.clone()]));
                for (sum, more) in skips.iter_mut().zip(more) {
                    *sum = *sum + more;
                }
            }
        }
        skips
    };
    match team {
        Some(team) => {
            let threads = team.threads();
            let start =
                |w: usize| layout.group_batches(level, share(groups, w, threads)).start - offset;
            let parts = Disjoint::cut(lambda, threads, start);
            let totals: [SharedSkips; K] = std::array::from_fn(|_| SharedSkips::default());
            team.run(&|worker| {
                let (mut lambda, part) = parts.take(worker);
                let skips = project_groups(
                    share(groups, worker, threads),
                    &mut lambda,
                    offset + part.start,
                );
                for (total, skips) in totals.iter().zip(skips) {
                    total.add(skips);
                }
            });
            totals.map(|total| total.get())
        }
        None => {
            let mut lambda = lambda;
            project_groups(0..groups, &mut lambda, offset)
        }
    }
}

/// Group `group`'s colours one after the other, a large colour shared by the threads; `lambda`
/// holds the rows of the batches from `offset` on.
fn colour_by_colour<const K: usize, F>(
    layout: &Layout,
    order: &[u32],
    team: Option<&Team>,
    group: usize,
    (mut lambda, offset): ([&mut [F32x8]; K], usize),
    project: &F,
) -> [SkipCounts; K]
where
    F: Fn(Range<usize>, [&mut [F32x8]; K]) -> [SkipCounts; K] + Sync,
{
    let mut skips = [SkipCounts::default(); K];
    for k in 0..layout.colour_count() {
        let colour: &Colour = layout.entry(group, k, order);
        let batches = colour.batches.clone();
        let rows = batches.start - offset..batches.end - offset;
        let lambda = lambda.each_mut().map(|l| &mut l[rows.clone()]);
        let large = colour.elements >= PARALLEL_MIN;
        let run = || match team.filter(|_| large) {
            Some(team) => {
                let parts = Disjoint::new(lambda, team.threads());
                let totals: [SharedSkips; K] = std::array::from_fn(|_| SharedSkips::default());
                team.run(&|worker| {
                    let (lambda, share) = parts.take(worker);
                    let at = batches.start + share.start..batches.start + share.end;
                    let skips = share_timers::share(worker, || project(at, lambda));
                    for (total, skips) in totals.iter().zip(skips) {
                        total.add(skips);
                    }
                });
                totals.map(|total| total.get())
            }
            None => project(batches.clone(), lambda),
        };
        for (sum, more) in skips.iter_mut().zip(share_timers::colour(large, run)) {
            *sum = *sum + more;
        }
    }
    skips
}

/// Bodies of fewer particles than this have their per-particle passes (the prediction, the
/// velocities) run on one thread: below it, handing out the work costs more than it saves.
pub(super) const PARALLEL_PARTICLES: usize = 4096;

/// Runs `pass(particles, parts)` over `slices` (one entry per particle each), in contiguous parts
/// of whole cache lines (four 16-byte particles), one per thread of `team` for a body of
/// [`PARALLEL_PARTICLES`] or more, else in one part. `pass` must treat each particle on its own:
/// then the result is the same to the bit for any number of threads.
pub(crate) fn by_particles<T: Send, const K: usize, F>(
    team: Option<&Team>,
    slices: [&mut [T]; K],
    pass: F,
) where
    F: Fn(Range<usize>, [&mut [T]; K]) + Sync,
{
    let len = slices.first().map_or(0, |s| s.len());
    match team.filter(|_| len >= PARALLEL_PARTICLES) {
        Some(team) => {
            let threads = team.threads();
            let lines = len.div_ceil(4);
            let parts = Disjoint::cut(slices, threads, |w| (lines * w / threads * 4).min(len));
            team.run(&|worker| {
                let (slices, range) = parts.take(worker);
                pass(range, slices);
            });
        }
        None => pass(0..len, slices),
    }
}
