//! Progress of a grid evaluation, for a caller that shows it (the command line's live line).
//!
//! A grid evaluation of many variants runs them all together, in parallel over the grid's
//! units of work (the sub-tasks of the cyclic decomposition, or the tasks themselves), so the
//! only progress there is to report is the share of those units done. The hook is called from
//! the worker threads as each unit ends, inside the parallel loop: counting never splits the
//! batch, and never changes a result.

use std::sync::atomic::{AtomicUsize, Ordering};

/// Receives `(done, total)` units of a grid evaluation, from any thread; the calls of one
/// evaluation report `0` first, then every count from 1 to `total` exactly once (in the order
/// the threads reach them).
pub type GridProgress<'a> = &'a (dyn Fn(usize, usize) + Sync);

/// A hook that ignores every report.
pub fn silent(_: usize, _: usize) {}

/// Counts the units of one evaluation and reports each one done.
pub(crate) struct Ticker<'a> {
    hook: GridProgress<'a>,
    total: usize,
    done: AtomicUsize,
}

impl<'a> Ticker<'a> {
    /// Reports the start (0 of `total`).
    pub(crate) fn start(hook: GridProgress<'a>, total: usize) -> Ticker<'a> {
        hook(0, total);
        Ticker {
            hook,
            total,
            done: AtomicUsize::new(0),
        }
    }

    /// One more unit done.
    pub(crate) fn tick(&self) {
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        (self.hook)(done, self.total);
    }
}
