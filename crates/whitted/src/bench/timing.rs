//! Tracing a ray set: once with every result kept (to compare structures
//! and count the work per ray), and repeatedly against the clock.

use std::hint::black_box;
use std::time::Instant;

use rayon::prelude::*;

use super::RaySet;
use crate::accel::TraversalCounters;
use crate::geometry::Geometry;

/// Rays handed to a thread at a time (as the anchor's 16 × 16 tiles).
const CHUNK: usize = 256;

/// What a ray set's rays hit.
#[derive(Clone, Debug, PartialEq)]
pub enum TraceResults {
    /// Closest hits: `(t, primitive)` or `None` for a miss.
    Closest(Vec<Option<(f64, u32)>>),
    /// Any-hit answers.
    Occluded(Vec<bool>),
}

/// Traces every ray once on this thread, keeping each result, and counts the
/// traversal work of all of them.
pub fn trace_all(geometry: &Geometry, set: &RaySet) -> (TraceResults, TraversalCounters) {
    let mut counters = TraversalCounters::default();
    let results = if set.kind.is_any_hit() {
        TraceResults::Occluded(
            set.rays
                .iter()
                .map(|r| geometry.occluded_counted(r, &mut counters))
                .collect(),
        )
    } else {
        TraceResults::Closest(
            set.rays
                .iter()
                .map(|r| {
                    geometry
                        .intersect_counted(r, &mut counters)
                        .map(|h| (h.t(), h.primitive))
                })
                .collect(),
        )
    };
    (results, counters)
}

/// The best time in seconds of `runs` passes (after one warm-up pass) over
/// the ray set on a pool of `threads` threads.
pub fn time_set(
    geometry: &Geometry,
    set: &RaySet,
    threads: usize,
    runs: usize,
) -> Result<f64, String> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| format!("could not start {threads} threads: {e}"))?;
    let pass = || {
        set.rays
            .par_chunks(CHUNK)
            .map(|chunk| {
                let mut counters = TraversalCounters::default();
                chunk
                    .iter()
                    .filter(|r| {
                        if set.kind.is_any_hit() {
                            geometry.occluded_counted(r, &mut counters)
                        } else {
                            geometry.intersect_counted(r, &mut counters).is_some()
                        }
                    })
                    .count()
            })
            .sum::<usize>()
    };
    pool.install(|| {
        black_box(pass());
        let mut best = f64::INFINITY;
        for _ in 0..runs.max(1) {
            let start = Instant::now();
            black_box(pass());
            best = best.min(start.elapsed().as_secs_f64());
        }
        Ok(best)
    })
}
