//! How a study reports its phases while it runs.
//!
//! The command line draws them on stderr (a live line per phase on a terminal, one line per
//! phase in a log); a script passes [`Silent`]. A phase that counts its own work (the
//! optimisation: `critical-task pass 1: 312/1169`) reports it from any thread.

/// Where a study reports its phases.
pub trait Progress {
    /// Starts the next phase: a counted one (`[2/4]`), or, with `extra`, one that only some
    /// runs need (the partial balancing when no variant is feasible).
    fn phase(&mut self, name: &str, extra: bool) -> Box<dyn Phase>;
    /// A note for the user (the bounds derived from the mechanism).
    fn note(&mut self, _text: &str) {}
}

/// One running phase.
pub trait Phase: Sync {
    /// The phase's work reached `count` in `stage` (called from any thread).
    fn report(&self, stage: &str, count: Count);
    /// Ends the phase.
    fn finish(self: Box<Self>);
}

/// Reports nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct Silent;

impl Progress for Silent {
    fn phase(&mut self, _name: &str, _extra: bool) -> Box<dyn Phase> {
        Box::new(Silent)
    }
}

impl Phase for Silent {
    fn report(&self, _stage: &str, _count: Count) {}
    fn finish(self: Box<Self>) {}
}

/// How far a stage is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Count {
    /// `done` of `total` items (variants), shown as `312/1169`.
    Items { done: usize, total: usize },
    /// `done` of `total` of work whose items all end together (a grid evaluation of many
    /// variants), shown as a percentage.
    Share { done: usize, total: usize },
}

impl Count {
    pub fn parts(self) -> (usize, usize) {
        match self {
            Count::Items { done, total } | Count::Share { done, total } => (done, total),
        }
    }

    /// `312/1169` or `41 %`.
    pub fn shown(self) -> String {
        match self {
            Count::Items { done, total } => format!("{done}/{total}"),
            Count::Share { done, total } => {
                format!("{} %", (100 * done.min(total)) / total.max(1))
            }
        }
    }
}
