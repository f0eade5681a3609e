//! How long the tracing of a render took and how busy its threads were:
//! the figures `whitted render --stats` reports, so that anyone can see
//! whether a render was held up by its last tiles.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// The time spent tracing the tiles, and how the work spread over the
/// threads.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TraceTiming {
    /// Wall-clock seconds from the first tile started to the last one
    /// finished (the world and any photon map already built).
    pub seconds: f64,
    /// Seconds the threads spent in tiles, added over the threads.
    pub busy_seconds: f64,
    /// Worker threads that traced.
    pub threads: usize,
    /// Seconds from the moment the first thread found no tile left to the
    /// end: the tail, when some threads had no more work while others
    /// finished theirs.
    pub tail_seconds: f64,
    /// Tiles traced.
    pub tiles: usize,
}

impl TraceTiming {
    /// The share of the threads' wall-clock time spent in tiles, from 0 to
    /// 1 (1 when every thread was busy from the start to the end).
    pub fn utilisation(&self) -> f64 {
        let available = self.seconds * self.threads as f64;
        if available > 0.0 {
            (self.busy_seconds / available).min(1.0)
        } else {
            1.0
        }
    }
}

/// Collects [`TraceTiming`] from the tiles as the threads finish them.
pub(super) struct TraceClock {
    start: Instant,
    busy_nanos: AtomicU64,
    first_idle_nanos: AtomicU64,
    tiles: AtomicU64,
}

impl TraceClock {
    /// A clock started now.
    pub(super) fn start() -> Self {
        Self {
            start: Instant::now(),
            busy_nanos: AtomicU64::new(0),
            first_idle_nanos: AtomicU64::new(u64::MAX),
            tiles: AtomicU64::new(0),
        }
    }

    /// Times `work`, one tile's, as part of the render.
    pub(super) fn tile<T>(&self, work: impl FnOnce() -> T) -> T {
        let started = self.start.elapsed();
        let result = work();
        let spent = self.start.elapsed().saturating_sub(started);
        self.busy_nanos.fetch_add(nanos(spent), Ordering::Relaxed);
        self.tiles.fetch_add(1, Ordering::Relaxed);
        result
    }

    /// Notes that the calling thread found no tile left to take.
    pub(super) fn out_of_work(&self) {
        self.first_idle_nanos
            .fetch_min(nanos(self.start.elapsed()), Ordering::Relaxed);
    }

    /// The timing so far, for `threads` worker threads.
    pub(super) fn finish(&self, threads: usize) -> TraceTiming {
        let seconds = self.start.elapsed().as_secs_f64();
        let first_idle = match self.first_idle_nanos.load(Ordering::Relaxed) {
            u64::MAX => seconds,
            idle => idle as f64 * 1e-9,
        };
        TraceTiming {
            seconds,
            busy_seconds: self.busy_nanos.load(Ordering::Relaxed) as f64 * 1e-9,
            threads,
            tail_seconds: (seconds - first_idle).max(0.0),
            tiles: self.tiles.load(Ordering::Relaxed) as usize,
        }
    }
}

fn nanos(duration: Duration) -> u64 {
    u64::try_from(duration.as_nanos()).unwrap_or(u64::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn busy_time_adds_over_tiles_and_the_tail_runs_from_the_first_idle_thread() {
        let clock = TraceClock::start();
        let (idle, wait_for_idle) = std::sync::mpsc::channel();
        std::thread::scope(|scope| {
            // One thread with a short tile, one with two long ones, the
            // second started only once the first thread is out of work, so
            // that the tail holds it whatever the scheduler does.
            let clock = &clock;
            scope.spawn(move || {
                clock.tile(|| std::thread::sleep(Duration::from_millis(10)));
                clock.out_of_work();
                idle.send(()).unwrap();
            });
            scope.spawn(move || {
                clock.tile(|| std::thread::sleep(Duration::from_millis(30)));
                wait_for_idle.recv().unwrap();
                clock.tile(|| std::thread::sleep(Duration::from_millis(30)));
                clock.out_of_work();
            });
        });
        let timing = clock.finish(2);
        assert_eq!(timing.tiles, 3);
        assert!(timing.busy_seconds >= 0.07, "{timing:?}");
        assert!(timing.seconds >= 0.06, "{timing:?}");
        // The first thread ran out of work after at least its 10 ms; the
        // other then spent at least 30 ms more.
        assert!(timing.tail_seconds >= 0.03, "{timing:?}");
        assert!(timing.tail_seconds <= timing.seconds - 0.01, "{timing:?}");
        assert!(timing.utilisation() > 0.0 && timing.utilisation() <= 1.0);
    }

    #[test]
    fn no_thread_out_of_work_means_no_tail() {
        let clock = TraceClock::start();
        clock.tile(|| std::thread::sleep(Duration::from_millis(5)));
        assert_eq!(clock.finish(1).tail_seconds, 0.0);
    }

    #[test]
    fn two_threads_each_busy_half_the_time_are_half_utilised() {
        let timing = TraceTiming {
            seconds: 2.0,
            busy_seconds: 2.0,
            threads: 2,
            tail_seconds: 0.0,
            tiles: 4,
        };
        assert_eq!(timing.utilisation(), 0.5);
        assert_eq!(TraceTiming::default().utilisation(), 1.0);
    }
}
