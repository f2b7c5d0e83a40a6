//! Progress of the optimisation, for a caller that shows it (the command line's progress line).
//!
//! The optimiser calls the sink from worker threads as variants finish a stage, so the sink
//! must be cheap and thread-safe; what it shows is the caller's business. Reports never change
//! a result.

use std::sync::atomic::{AtomicUsize, Ordering};

/// Where the optimisation is: `done` of `total` items of the named stage.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StageProgress {
    /// `"critical-task pass 1"`, `"spring choice"`, `"final evaluation"`, …
    pub stage: &'static str,
    /// The pass of the critical-task loop (1-based; 0 outside the loop).
    pub pass: usize,
    pub done: usize,
    pub total: usize,
}

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
}
