//! Running the binary under a deadline, for the harnesses that feed it hostile input (the
//! extreme-value fuzz of `tests/fuzz.rs`): a hang is killed and reported instead of stalling
//! the run.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// How one run of the binary ended.
pub enum Ran {
    /// Exited with this status and standard error.
    Exited(i32, String),
    /// Ended by a signal (an abort, a stack overflow).
    Signalled(String),
    /// Still running at the deadline (killed), with the processor time it had used by then
    /// where the system tells it.
    Hung(Option<Duration>),
}

/// Processor time process `pid` has used: the first field of Linux's
/// `/proc/PID/task/TID/schedstat` (nanoseconds on a processor) summed over its threads.
/// `None` elsewhere. A case killed at the deadline having used much less than the deadline
/// waited for a processor (a loaded machine), not in a loop.
pub fn processor_time(pid: u32) -> Option<Duration> {
    let mut nanos = 0;
    for task in std::fs::read_dir(format!("/proc/{pid}/task")).ok()? {
        let text = std::fs::read_to_string(task.ok()?.path().join("schedstat")).ok()?;
        nanos += text.split_whitespace().next()?.parse::<u64>().ok()?;
    }
    Some(Duration::from_nanos(nanos))
}

/// Runs the binary with `args` until `deadline`, killing it past that. Standard output is
/// dropped (a case's summary is not under test) and standard error goes to a file, so that
/// neither pipe can fill and stall the child.
pub fn run_binary(args: &[&str], dir: &Path, deadline: Instant) -> Ran {
    let err_path = dir.join("stderr");
    let mut child = Command::new(env!("CARGO_BIN_EXE_counterpoise"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&err_path).unwrap())
        .spawn()
        .expect("the binary runs");
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if Instant::now() >= deadline {
            let used = processor_time(child.id());
            let _ = child.kill();
            let _ = child.wait();
            return Ran::Hung(used);
        }
        std::thread::sleep(Duration::from_millis(1));
    };
    let stderr = std::fs::read_to_string(&err_path).unwrap_or_default();
    match status.code() {
        Some(code) => Ran::Exited(code, stderr),
        None => Ran::Signalled(format!("{status:?}: {stderr}")),
    }
}
