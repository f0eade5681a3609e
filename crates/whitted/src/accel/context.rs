//! What a caller tells a query and learns from it, per query: how the rays
//! it traces relate (a hint that only the speed depends on, never the
//! answer: on an exact tie between primitives at the same `t` the walk's
//! order may pick the other one), and the work done (nodes visited and
//! primitives tested), which the cost AOV and `whitted bench` report.
//!
//! The kd-tree's walk branches at every node on the ray's direction along
//! the node's axis. Rays that go the same way one after the other (camera
//! rays, shadow rays towards one light, mirror reflections of neighbouring
//! pixels) take those branches alike and the branch predictor learns them;
//! rays whose directions are unrelated from one to the next (diffuse
//! bounces) do not, and the walk waits on mispredicted branches. For those
//! the kd-tree first goes down to the origin's leaf, branching on the
//! origin's side of each plane instead, which neighbouring origins share
//! (docs/performance-log.md, kd-tree descent to the origin's leaf). Embree's
//! intersection contexts carry the same hint
//! (`RTC_INTERSECT_CONTEXT_FLAG_COHERENT` / `INCOHERENT`).

use super::kernel::Backend;

/// How the directions of the rays a caller traces one after the other
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

/// Work done for one or more rays: what the cost AOV and `whitted bench`
/// report.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalCounters {
    /// Interior nodes, leaves or cells visited.
    pub nodes: u64,
    /// Primitive intersection tests made.
    pub primitives: u64,
}

impl std::ops::AddAssign for TraversalCounters {
    fn add_assign(&mut self, o: Self) {
        self.nodes += o.nodes;
        self.primitives += o.primitives;
    }
}

/// The context of a query: the caller's hint and the backend to run with
/// in, the work done out. A caller may keep one per thread of queries
/// (`whitted bench` does) or make a default one per query; the counters add
/// up over the queries made with it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct QueryContext {
    /// How the rays of the queries made with this context relate.
    pub coherence: RayCoherence,
    /// The instruction set the walks run with ([`Backend::current`] by
    /// default); every backend gives the same answers.
    pub backend: Backend,
    /// The work done so far by the queries made with this context.
    pub counters: TraversalCounters,
}

impl QueryContext {
    /// A context for rays that relate as `coherence` says, with the
    /// current backend and no work counted yet.
    pub fn new(coherence: RayCoherence) -> Self {
        Self {
            coherence,
            backend: Backend::current(),
            counters: TraversalCounters::default(),
        }
    }

    /// A context like this one with no work counted yet: for a query
    /// within a query (an instance's walk), whose work the caller adds.
    pub fn fresh(&self) -> Self {
        Self {
            counters: TraversalCounters::default(),
            ..*self
        }
    }
}
