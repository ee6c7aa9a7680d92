//! Clocks for the figures that say where time went: the calling thread's CPU time (what a
//! recognizer, the simulator or the scoring cost, whatever else shares the cores) beside the
//! wall clock (what a user waits).
//!
//! The thread CPU clock is `clock_gettime(CLOCK_THREAD_CPUTIME_ID)` (through `rustix`), which
//! reads to the nanosecond on Linux; `/proc/thread-self/schedstat`, read before, moved in
//! 4 ms steps on a virtual machine, more than a lap of a small scenario costs.

use std::time::Instant;

/// CPU time of the calling thread so far, seconds.
pub fn thread_cpu_s() -> f64 {
    let t = rustix::time::clock_gettime(rustix::time::ClockId::ThreadCPUTime);
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

/// Both clocks, started together.
#[derive(Clone, Copy, Debug)]
pub struct Stopwatch {
    wall: Instant,
    cpu_s: f64,
}

impl Stopwatch {
    /// Starts now, on the calling thread.
    pub fn start() -> Self {
        Stopwatch {
            wall: Instant::now(),
            cpu_s: thread_cpu_s(),
        }
    }

    /// Seconds of the calling thread's CPU since [`Self::start`] (call on the same thread).
    pub fn cpu_s(&self) -> f64 {
        (thread_cpu_s() - self.cpu_s).max(0.0)
    }

    /// Wall-clock seconds since [`Self::start`].
    pub fn wall_s(&self) -> f64 {
        self.wall.elapsed().as_secs_f64()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The thread clock moves with work done on the thread, by less than the wall clock, and
    /// resolves far below the 4 ms steps of schedstat (a few microseconds of work register).
    #[test]
    fn the_thread_clock_counts_this_threads_work_finely() {
        let w = Stopwatch::start();
        let mut x = 0u64;
        while w.cpu_s() == 0.0 {
            x = x.wrapping_mul(31).wrapping_add(7);
        }
        let first = w.cpu_s();
        assert!(first < 1e-3, "first step {first} s (x {x})");
        std::thread::sleep(std::time::Duration::from_millis(20));
        assert!(w.cpu_s() < w.wall_s(), "sleeping costs no CPU");
    }
}
