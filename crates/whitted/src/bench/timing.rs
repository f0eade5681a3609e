//! Tracing a ray set: once with every result kept (to compare structures
//! and count the work per ray), and repeatedly against the clock.

use std::hint::black_box;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use super::RaySet;
use crate::accel::{QueryContext, TraversalCounters};
use crate::math::Ray;
use crate::world::World;

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
/// traversal work of all of them. Here and in [`time_set`] the queries are
/// told how the set's rays relate ([`super::RayKind::coherence`]).
pub fn trace_all(world: &World, set: &RaySet) -> (TraceResults, TraversalCounters) {
    let mut ctx = QueryContext::new(set.kind.coherence());
    let results = if set.kind.is_any_hit() {
        TraceResults::Occluded(
            set.rays
                .iter()
                .map(|r| world.occluded_with(r, &mut ctx))
                .collect(),
        )
    } else {
        TraceResults::Closest(
            set.rays
                .iter()
                .map(|r| {
                    world
                        .intersect_with(r, &mut ctx)
                        .map(|h| (h.t(), h.primitive.0))
                })
                .collect(),
        )
    };
    (results, ctx.counters)
}

/// The best time in seconds of `runs` passes (after one warm-up pass) over
/// the ray set on a pool of `threads` threads.
///
/// Each thread takes the next 256 rays from a shared counter until
/// none are left, as the anchor harness hands out its tiles (tried rayon's
/// `par_chunks`: scaled worse, see docs/performance.md).
pub fn time_set(world: &World, set: &RaySet, threads: usize, runs: usize) -> Result<f64, String> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| format!("could not start {threads} threads: {e}"))?;
    let chunks: Vec<&[Ray]> = set.rays.chunks(CHUNK).collect();
    let next = AtomicUsize::new(0);
    let trace = |chunk: &[Ray], ctx: &mut QueryContext| {
        let found = |r: &&Ray| {
            if set.kind.is_any_hit() {
                world.occluded_with(r, ctx)
            } else {
                world.intersect_with(r, ctx).is_some()
            }
        };
        chunk.iter().filter(found).count()
    };
    let pass = || {
        next.store(0, Ordering::Relaxed);
        let per_thread = pool.broadcast(|_| {
            let mut ctx = QueryContext::new(set.kind.coherence());
            let mut found = 0;
            while let Some(chunk) = chunks.get(next.fetch_add(1, Ordering::Relaxed)) {
                found += trace(chunk, &mut ctx);
            }
            found
        });
        per_thread.into_iter().sum::<usize>()
    };
    black_box(pass());
    let mut best = f64::INFINITY;
    for _ in 0..runs.max(1) {
        let start = Instant::now();
        black_box(pass());
        best = best.min(start.elapsed().as_secs_f64());
    }
    Ok(best)
}
