//! What a caller knows of the rays it traces on a thread: whether they
//! go the same way one after the other. Only the speed of a query depends
//! on it, never its answer (on an exact tie between primitives at the same
//! `t`, the walk's order may pick the other one).
//!
//! The kd-tree's walk branches at every node on the ray's direction along
//! the node's axis. Rays that go the same way one after the other (camera
//! rays, shadow rays towards one light, mirror reflections of neighbouring
//! pixels) take those branches alike and the branch predictor learns them;
//! rays whose directions are unrelated from one to the next (diffuse
//! bounces) do not, and the walk waits on mispredicted branches. For those
//! the kd-tree first goes down to the origin's leaf, branching on the
//! origin's side of each plane instead, which neighbouring origins share
//! (`kdtree/mod.rs` has the figures). Embree's intersection contexts carry
//! the same hint (`RTC_INTERSECT_CONTEXT_FLAG_COHERENT` / `INCOHERENT`).

use std::cell::Cell;

/// How the directions of the rays traced one after the other on a thread
/// relate.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RayCoherence {
    /// Each ray goes about the way the one before went, or the way a ray
    /// of a few queries before went in a pattern that repeats (a pixel's
    /// camera, shadow and reflected rays, then the next pixel's).
    #[default]
    Coherent,
    /// The directions are unrelated from one ray to the next, as for
    /// bounces drawn at random.
    Incoherent,
}

thread_local! {
    /// The hint in force on this thread.
    static CURRENT: Cell<RayCoherence> = const { Cell::new(RayCoherence::Coherent) };
}

/// Calls `trace` with the queries it makes on this thread told that their
/// rays are `coherence`, and returns what it returns. The hint in force
/// before comes back afterwards, also when `trace` panics. Queries made on
/// other threads (a thread pool's) need their own call there.
pub fn with_ray_coherence<R>(coherence: RayCoherence, trace: impl FnOnce() -> R) -> R {
    /// Puts the previous hint back when dropped.
    struct Restore(RayCoherence);
    impl Drop for Restore {
        fn drop(&mut self) {
            CURRENT.set(self.0);
        }
    }
    let _restore = Restore(CURRENT.replace(coherence));
    trace()
}

/// The hint in force on this thread ([`RayCoherence::Coherent`] unless a
/// [`with_ray_coherence`] call says otherwise).
#[inline(always)]
pub fn current_ray_coherence() -> RayCoherence {
    CURRENT.get()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rays_are_coherent_unless_told_otherwise() {
        assert_eq!(current_ray_coherence(), RayCoherence::Coherent);
        let inside = with_ray_coherence(RayCoherence::Incoherent, current_ray_coherence);
        assert_eq!(inside, RayCoherence::Incoherent);
        assert_eq!(current_ray_coherence(), RayCoherence::Coherent);
    }

    #[test]
    fn nested_hints_unwind_in_order_and_past_a_panic() {
        with_ray_coherence(RayCoherence::Incoherent, || {
            with_ray_coherence(RayCoherence::Coherent, || {
                assert_eq!(current_ray_coherence(), RayCoherence::Coherent);
            });
            assert_eq!(current_ray_coherence(), RayCoherence::Incoherent);
            let panicked = std::panic::catch_unwind(|| {
                with_ray_coherence(RayCoherence::Coherent, || panic!("in a trace"))
            });
            assert!(panicked.is_err());
            assert_eq!(current_ray_coherence(), RayCoherence::Incoherent);
        });
        assert_eq!(current_ray_coherence(), RayCoherence::Coherent);
    }

    #[test]
    fn the_hint_belongs_to_one_thread() {
        with_ray_coherence(RayCoherence::Incoherent, || {
            let other = std::thread::spawn(current_ray_coherence).join().unwrap();
            assert_eq!(other, RayCoherence::Coherent);
        });
    }
}
