//! Tracing a ray set: once with every result kept (to compare structures
//! and count the work per ray), and repeatedly against the clock.

use std::hint::black_box;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use super::RaySet;
use crate::accel::{QueryContext, TraversalCounters};
use crate::math::Ray;
use crate::world::{Hit, PACKET_SIZE, World};

/// Rays handed to a thread at a time (as the anchor's 16 × 16 tiles).
const CHUNK: usize = 256;

/// How the closest-hit queries of a set walk the structure.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Walk {
    /// One ray at a time.
    #[default]
    Single,
    /// [`PACKET_SIZE`] consecutive rays at a time
    /// ([`World::intersect_packet`] and [`World::occluded_packet`]:
    /// together where the world and the rays allow it, one at a time
    /// otherwise).
    Packets,
}

/// The closest hits of `rays` (one thread's chunk), walked as `walk`
/// says, each passed to `found` in order.
fn closest_hits(
    world: &World,
    rays: &[Ray],
    walk: Walk,
    ctx: &mut QueryContext,
    mut found: impl FnMut(Option<Hit>),
) {
    match walk {
        Walk::Single => rays
            .iter()
            .for_each(|r| found(world.intersect_with(r, ctx))),
        Walk::Packets => {
            let mut hits = [None; PACKET_SIZE];
            for packet in rays.chunks(PACKET_SIZE) {
                world.intersect_packet(packet, ctx, &mut hits);
                hits[..packet.len()].iter().for_each(|&h| found(h));
            }
        }
    }
}

/// The any-hit answers of `rays` (one thread's chunk), walked as `walk`
/// says, each passed to `found` in order.
fn any_hits(
    world: &World,
    rays: &[Ray],
    walk: Walk,
    ctx: &mut QueryContext,
    mut found: impl FnMut(bool),
) {
    match walk {
        Walk::Single => rays.iter().for_each(|r| found(world.occluded_with(r, ctx))),
        Walk::Packets => {
            for packet in rays.chunks(PACKET_SIZE) {
                let occluded = world.occluded_packet(packet, ctx);
                (0..packet.len()).for_each(|lane| found(occluded & 1 << lane != 0));
            }
        }
    }
}

/// What a ray set's rays hit.
#[derive(Clone, Debug, PartialEq)]
pub enum TraceResults {
    /// Closest hits: `(t, primitive)` or `None` for a miss.
    Closest(Vec<Option<(f64, u32)>>),
    /// Any-hit answers.
    Occluded(Vec<bool>),
}

/// Traces every ray once on this thread, walking as `walk` says, keeping
/// each result, and counts the traversal work of all of them. Here and in [`time_set`] the queries are
/// told how the set's rays relate ([`super::RayKind::coherence`]).
pub fn trace_all(world: &World, set: &RaySet, walk: Walk) -> (TraceResults, TraversalCounters) {
    let mut ctx = QueryContext::new(set.kind.coherence());
    let results = if set.kind.is_any_hit() {
        let mut occluded = Vec::with_capacity(set.rays.len());
        any_hits(world, &set.rays, walk, &mut ctx, |o| occluded.push(o));
        TraceResults::Occluded(occluded)
    } else {
        let mut hits = Vec::with_capacity(set.rays.len());
        closest_hits(world, &set.rays, walk, &mut ctx, |h| {
            hits.push(h.map(|h| (h.t(), h.primitive.0)));
        });
        TraceResults::Closest(hits)
    };
    (results, ctx.counters)
}

/// The best time in seconds of `runs` passes (after one warm-up pass) over
/// the ray set on a pool of `threads` threads.
///
/// Each thread takes the next 256 rays from a shared counter until
/// none are left, as the anchor harness hands out its tiles (tried rayon's
/// `par_chunks`: scaled worse, see docs/performance-log.md).
pub fn time_set(
    world: &World,
    set: &RaySet,
    walk: Walk,
    threads: usize,
    runs: usize,
) -> Result<f64, String> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| format!("could not start {threads} threads: {e}"))?;
    let chunks: Vec<&[Ray]> = set.rays.chunks(CHUNK).collect();
    let next = AtomicUsize::new(0);
    let trace = |chunk: &[Ray], ctx: &mut QueryContext| {
        let mut count = 0;
        if set.kind.is_any_hit() {
            any_hits(world, chunk, walk, ctx, |o| count += usize::from(o));
            return count;
        }
        closest_hits(world, chunk, walk, ctx, |h| {
            count += usize::from(h.is_some())
        });
        count
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::scene_ray_sets;
    use crate::scene::default_scene;

    #[test]
    fn packets_find_what_single_rays_find_and_time_the_same_sets() {
        let scene = default_scene();
        let world = World::new(&scene.objects);
        // The packet walk runs where the current backend has AVX; elsewhere
        // the packets' rays go one at a time, with the same answers.
        assert_eq!(
            world.walks_packets(),
            crate::accel::Backend::current().has_avx()
        );
        let sets = scene_ray_sets(&scene, &world, 96, 64);
        for set in &sets {
            let (single, _) = trace_all(&world, set, Walk::Single);
            let (packets, _) = trace_all(&world, set, Walk::Packets);
            assert_eq!(single, packets, "{}", set.kind.name());
            assert!(time_set(&world, set, Walk::Packets, 1, 1).unwrap() > 0.0);
        }
        let TraceResults::Closest(primary) = trace_all(&world, &sets[0], Walk::Packets).0 else {
            panic!("primary rays ask for the closest hit");
        };
        assert!(primary.iter().filter(|h| h.is_some()).count() > 1000);
    }
}
