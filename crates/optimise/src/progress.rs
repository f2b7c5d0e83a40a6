//! Progress of the optimisation, for a caller that shows it (the command line's progress line).
//!
//! The optimiser calls the sink from worker threads as variants finish a stage, so the sink
//! must be cheap and thread-safe; what it shows is the caller's business. Reports never change
//! a result.

use std::sync::atomic::{AtomicUsize, Ordering};

/// Where the optimisation is: `done` of `total` of the named stage, counted in `unit`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StageProgress {
    /// `"critical-task pass 1"`, `"spring choice"`, `"final evaluation"`, …
    pub stage: &'static str,
    /// The pass of the critical-task loop (1-based; 0 outside the loop).
    pub pass: usize,
    pub done: usize,
    pub total: usize,
    pub unit: Unit,
}

/// What a stage's `done` and `total` count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    /// Variants, each counted as it leaves the stage.
    Variants,
    /// The share of a grid evaluation of `variants` variants, in thousandths (`total` is
    /// [`SHARE_SCALE`]): the evaluation runs its variants together over the task grid, so
    /// they all end at once and only the share of the grid done can move.
    Share { variants: usize },
}

/// The `total` of a [`Unit::Share`] stage.
pub const SHARE_SCALE: usize = 1000;

/// Receives progress reports (from any thread).
pub type ProgressSink<'a> = &'a (dyn Fn(StageProgress) + Sync);

/// A sink that ignores every report.
pub fn silent(_: StageProgress) {}

/// Counts the items of one stage and reports each one done.
pub struct StageCounter<'a> {
    sink: ProgressSink<'a>,
    stage: &'static str,
    pass: usize,
    total: usize,
    done: AtomicUsize,
}

impl<'a> StageCounter<'a> {
    /// Reports the stage's start (0 of `total`).
    pub fn start(
        sink: ProgressSink<'a>,
        stage: &'static str,
        pass: usize,
        total: usize,
    ) -> StageCounter<'a> {
        sink(StageProgress {
            stage,
            pass,
            done: 0,
            total,
            unit: Unit::Variants,
        });
        StageCounter {
            sink,
            stage,
            pass,
            total,
            done: AtomicUsize::new(0),
        }
    }

    /// One more item done.
    pub fn tick(&self) {
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        (self.sink)(StageProgress {
            stage: self.stage,
            pass: self.pass,
            done,
            total: self.total,
            unit: Unit::Variants,
        });
    }
}

/// Reports the share done of a stage that evaluates `variants` variants over the task grid,
/// possibly as consecutive batches (variants with springs to the base apart from the others).
pub struct ShareCounter<'a> {
    sink: ProgressSink<'a>,
    stage: &'static str,
    pass: usize,
    variants: usize,
    /// The largest share sent: a report that does not raise it is dropped, so the sink hears
    /// at most [`SHARE_SCALE`] reports per stage (a batch through the direct path has one unit
    /// per task, 58,653 on the palletizer) and never a share going back.
    sent: AtomicUsize,
}

impl<'a> ShareCounter<'a> {
    /// Reports the stage's start (0 of [`SHARE_SCALE`]).
    pub fn start(
        sink: ProgressSink<'a>,
        stage: &'static str,
        pass: usize,
        variants: usize,
    ) -> ShareCounter<'a> {
        let counter = ShareCounter {
            sink,
            stage,
            pass,
            variants,
            sent: AtomicUsize::new(0),
        };
        counter.send(0);
        counter
    }

    /// A batch of `members` variants, which follows batches of `before` variants of the
    /// stage, has done `done` of its `total` units of work: each batch weighs as its share of
    /// the stage's variants.
    pub fn batch(&self, before: usize, members: usize, done: usize, total: usize) {
        let variants = self.variants.max(1) as f64;
        let within = if total == 0 {
            1.0
        } else {
            done.min(total) as f64 / total as f64
        };
        let share = (before as f64 + members as f64 * within) / variants;
        let done = ((share * SHARE_SCALE as f64).floor() as usize).min(SHARE_SCALE);
        if self.sent.fetch_max(done, Ordering::Relaxed) < done {
            self.send(done);
        }
    }

    fn send(&self, done: usize) {
        (self.sink)(StageProgress {
            stage: self.stage,
            pass: self.pass,
            done,
            total: SHARE_SCALE,
            unit: Unit::Share {
                variants: self.variants,
            },
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;

    #[test]
    fn a_counter_reports_its_start_and_every_item_once() {
        let seen = Mutex::new(Vec::new());
        let sink = |p: StageProgress| seen.lock().unwrap().push((p.done, p.total));
        let counter = StageCounter::start(&sink, "spring choice", 0, 3);
        std::thread::scope(|s| {
            for _ in 0..3 {
                s.spawn(|| counter.tick());
            }
        });
        let mut seen = seen.into_inner().unwrap();
        seen.sort();
        assert_eq!(seen, vec![(0, 3), (1, 3), (2, 3), (3, 3)]);
    }

    #[test]
    fn batches_weigh_as_their_share_of_the_variants() {
        let seen = Mutex::new(Vec::new());
        let sink = |p: StageProgress| {
            assert_eq!(p.unit, Unit::Share { variants: 4 });
            seen.lock().unwrap().push(p.done);
        };
        let counter = ShareCounter::start(&sink, "final evaluation", 0, 4);
        // One variant in a batch of 10 units, then three in a batch of 4 units.
        counter.batch(0, 1, 5, 10); // half of 1/4: 125 thousandths
        counter.batch(0, 1, 5, 10); // the same share again: not sent
        counter.batch(0, 1, 4, 10); // a thread reporting late: not sent
        counter.batch(0, 1, 10, 10); // 1/4
        counter.batch(1, 3, 2, 4); // 1/4 + 3/4 · 1/2 = 5/8
        counter.batch(1, 3, 4, 4); // all
        assert_eq!(seen.into_inner().unwrap(), vec![0, 125, 250, 625, 1000]);
    }
}
