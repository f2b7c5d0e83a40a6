//! Progress on stderr, the way a terminal user and a log reader each want it.
//!
//! - On a terminal: one live line per phase, `[2/4] Phase 2: balance search ⠋ 00:00:03`; the
//!   line stays, with the phase's time, when it ends.
//! - Not a terminal (a pipe, a log file, CI): one plain line when each phase starts, with the
//!   time elapsed so far, so a 30 s run is never silent and the log is not full of redraws.
//! - `--quiet`: nothing.
//!
//! A phase that reports its own progress (the optimisation: `critical-task pass 1: 312/1169`)
//! shows it as well: on a terminal the live line carries the stage, the count and an estimate
//! of the time left in the stage; in lines mode one line is printed as each stage starts.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use counterpoise_study::progress::Count;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// The label of a phase outside the count ([`Progress::extra_phase`]).
pub const EXTRA: &str = "[+]";

/// How progress is shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    Terminal,
    Lines,
    Quiet,
}

/// Progress of a run of `phases` phases.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    pub mode: Mode,
    phases: usize,
    next: usize,
    started: Option<Instant>,
}

impl Progress {
    /// Terminal or lines depending on stderr, or quiet.
    pub fn detect(quiet: bool, phases: usize) -> Progress {
        let mode = if quiet {
            Mode::Quiet
        } else if std::io::stderr().is_terminal() {
            Mode::Terminal
        } else {
            Mode::Lines
        };
        Progress {
            mode,
            phases,
            next: 0,
            started: None,
        }
    }

    /// Starts the next phase.
    pub fn phase(&mut self, name: &str) -> Phase {
        self.next += 1;
        let label = format!("[{}/{}] {name}", self.next, self.phases.max(self.next));
        self.start(label)
    }

    /// Starts a phase that only some runs need (the partial balancing when no variant is
    /// feasible), known only once the counted phases are under way: it is labelled `[+]`
    /// instead of a count, so that the counts already printed (`[3/4]`) stay true.
    pub fn extra_phase(&mut self, name: &str) -> Phase {
        self.start(format!("{EXTRA} {name}"))
    }

    fn start(&mut self, label: String) -> Phase {
        let started = *self.started.get_or_insert_with(Instant::now);
        let bar = match self.mode {
            Mode::Quiet => None,
            Mode::Lines => {
                eprintln!("{label} (elapsed {:.1} s)", started.elapsed().as_secs_f64());
                None
            }
            Mode::Terminal => {
                let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
                bar.set_style(
                    ProgressStyle::with_template("{msg} {spinner} {elapsed_precise}")
                        .expect("template"),
                );
                bar.set_message(label.clone());
                bar.enable_steady_tick(Duration::from_millis(120));
                Some(bar)
            }
        };
        Phase {
            bar,
            label,
            started: Instant::now(),
            mode: self.mode,
            stage: std::sync::Mutex::new(None),
        }
    }
}

/// One running phase.
pub struct Phase {
    bar: Option<ProgressBar>,
    label: String,
    started: Instant,
    mode: Mode,
    /// The stage being counted and when it started (for the estimate of the time left).
    stage: std::sync::Mutex<Option<(String, Instant)>>,
}

/// The estimated time left when `done` of `total` items took `elapsed`: `None` before the
/// first item (nothing to extrapolate from).
pub fn time_left(elapsed: Duration, done: usize, total: usize) -> Option<Duration> {
    (done > 0 && done <= total).then(|| elapsed.mul_f64((total - done) as f64 / done as f64))
}

impl Phase {
    /// The phase's work reached `count` in `stage` (called from any thread).
    pub fn report(&self, stage: &str, count: Count) {
        let (done, total) = count.parts();
        let mut current = self.stage.lock().expect("progress lock");
        let new_stage = current.as_ref().is_none_or(|(s, _)| s != stage);
        if new_stage {
            *current = Some((stage.to_string(), Instant::now()));
            if self.mode == Mode::Lines {
                let to_do = match count {
                    Count::Items { total, .. } => format!(", {total} to do"),
                    Count::Share { .. } => String::new(),
                };
                eprintln!(
                    "{}: {stage}{to_do} ({:.1} s into the phase)",
                    self.label,
                    self.started.elapsed().as_secs_f64()
                );
            }
        }
        if let (Some(bar), Some((_, since))) = (&self.bar, current.as_ref()) {
            let left = time_left(since.elapsed(), done, total).map_or(String::new(), |t| {
                format!(", about {:.0} s left", t.as_secs_f64())
            });
            bar.set_message(format!("{} — {stage}: {}{left}", self.label, count.shown()));
        }
    }

    /// Ends the phase; on a terminal its line stays with the time it took.
    pub fn finish(self) {
        if let Some(bar) = self.bar {
            bar.set_style(ProgressStyle::with_template("{msg}").expect("template"));
            bar.finish_with_message(format!(
                "{}: {:.2} s",
                self.label,
                self.started.elapsed().as_secs_f64()
            ));
        }
    }
}

impl counterpoise_study::Progress for Progress {
    fn phase(&mut self, name: &str, extra: bool) -> Box<dyn counterpoise_study::Phase> {
        Box::new(if extra {
            self.extra_phase(name)
        } else {
            Progress::phase(self, name)
        })
    }

    fn note(&mut self, text: &str) {
        if self.mode != Mode::Quiet {
            eprintln!("note: {text}");
        }
    }
}

impl counterpoise_study::Phase for Phase {
    fn report(&self, stage: &str, count: Count) {
        Phase::report(self, stage, count)
    }

    fn finish(self: Box<Self>) {
        Phase::finish(*self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_left_extrapolates_the_rate_so_far() {
        // 25 of 100 in 10 s: 75 more at the same rate take 30 s.
        assert_eq!(
            time_left(Duration::from_secs(10), 25, 100),
            Some(Duration::from_secs(30))
        );
        assert_eq!(time_left(Duration::from_secs(10), 0, 100), None);
        assert_eq!(
            time_left(Duration::from_secs(10), 100, 100),
            Some(Duration::ZERO)
        );
    }

    #[test]
    fn counts_show_items_or_a_whole_percentage() {
        assert_eq!(Count::Items { done: 3, total: 50 }.shown(), "3/50");
        // 417 thousandths: 41.7 %, shown rounded down (never 100 % before the end).
        assert_eq!(
            Count::Share {
                done: 417,
                total: 1000
            }
            .shown(),
            "41 %"
        );
        assert_eq!(
            Count::Share {
                done: 999,
                total: 1000
            }
            .shown(),
            "99 %"
        );
        assert_eq!(Count::Share { done: 0, total: 0 }.shown(), "0 %");
    }
}
