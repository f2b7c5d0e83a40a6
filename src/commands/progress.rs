//! Progress on stderr, the way a terminal user and a log reader each want it.
//!
//! - On a terminal: one live line per phase, `[2/4] Phase 2: balance search ⠋ 00:00:03`; the
//!   line stays, with the phase's time, when it ends.
//! - Not a terminal (a pipe, a log file, CI): one plain line when each phase starts, with the
//!   time elapsed so far, so a 30 s run is never silent and the log is not full of redraws.
//! - `--quiet`: nothing.
//!
//! The dynamics and the optimiser report no progress of their own, so a phase shows its
//! number among the phases and the time elapsed, not a count of variants.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

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
        let started = *self.started.get_or_insert_with(Instant::now);
        self.next += 1;
        let label = format!("[{}/{}] {name}", self.next, self.phases.max(self.next));
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
        }
    }
}

/// One running phase.
pub struct Phase {
    bar: Option<ProgressBar>,
    label: String,
    started: Instant,
}

impl Phase {
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
