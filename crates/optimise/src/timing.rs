//! Wall and CPU time of the optimiser's stages.
//!
//! On a shared machine the wall time of a stage says more about the other jobs than about the
//! stage; the process CPU time (every thread) does not, and their ratio is the stage's
//! parallel utilisation.

use serde::Serialize;

/// Time spent in one stage, seconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct StageTime {
    pub wall: f64,
    /// CPU time of the whole process (all threads) during the stage.
    pub cpu: f64,
}

impl std::ops::AddAssign for StageTime {
    fn add_assign(&mut self, other: StageTime) {
        self.wall += other.wall;
        self.cpu += other.cpu;
    }
}

/// CPU time used so far by every thread of the process, seconds (0 where the clock is not
/// available).
#[cfg(unix)]
pub fn process_cpu_seconds() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid, writable timespec; the call only writes it.
    let ok = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut t) } == 0;
    if ok {
        t.tv_sec as f64 + 1e-9 * t.tv_nsec as f64
    } else {
        0.0
    }
}

/// CPU time used so far by the process: not measured on this platform.
#[cfg(not(unix))]
pub fn process_cpu_seconds() -> f64 {
    0.0
}

/// A started stage.
pub struct Stopwatch {
    wall: std::time::Instant,
    cpu: f64,
}

impl Stopwatch {
    pub fn start() -> Stopwatch {
        Stopwatch {
            wall: std::time::Instant::now(),
            cpu: process_cpu_seconds(),
        }
    }

    pub fn elapsed(&self) -> StageTime {
        StageTime {
            wall: self.wall.elapsed().as_secs_f64(),
            cpu: (process_cpu_seconds() - self.cpu).max(0.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpu_time_of_busy_work_is_counted() {
        let watch = Stopwatch::start();
        // Spin for 50 ms of wall time on this thread: the process CPU clock must advance by
        // most of it (the thread is runnable throughout; allow for a loaded machine).
        let until = std::time::Instant::now() + std::time::Duration::from_millis(50);
        let mut x = 0u64;
        while std::time::Instant::now() < until {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1);
        }
        std::hint::black_box(x);
        let t = watch.elapsed();
        assert!(t.wall >= 0.05, "{t:?}");
        assert!(t.cpu > 0.0 && t.cpu <= t.wall * 2.0 + 0.01, "{t:?}");
    }
}
