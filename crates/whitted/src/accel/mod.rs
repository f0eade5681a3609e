//! Acceleration structures: index structures over bounding boxes.
//!
//! A structure never knows what a shape is. It is built from the primitives'
//! world-space boxes, and its queries take a closure that intersects
//! primitive `i`; the caller keeps whatever hit data it needs in the
//! closure's state. Unbounded shapes (infinite planes) never enter a
//! structure: the world (the `world` module, a layer above) tests them in
//! a short list beside it.
//!
//! Every structure offers the same inherent methods, dispatched by
//! [`Accelerator`]:
//! - `intersect(ray, counters, hit)`: the closest hit. `hit(i, t_max)`
//!   intersects primitive `i` and returns the parameter of a hit closer than
//!   `t_max`, if any; the structure returns the closest parameter found.
//! - `occluded(ray, counters, occludes)`: any hit; stops at the first
//!   primitive for which `occludes(i)` holds.
//! - `validate(boxes)`: checks the built structure's invariants.
//! - `stats()`: its size and quality.
//!
//! A caller may say how the rays it traces on a thread relate
//! ([`with_ray_coherence`]); a structure may pick how it walks by it, never
//! the closest `t` it returns (on an exact tie, which primitive may
//! change, as between structures).
//!
//! Culling must be conservative: a structure may skip a primitive only when
//! the ray provably cannot meet its box within the interval, so every
//! structure returns exactly the closest hit the brute-force [`Linear`]
//! returns (ties at equal `t` may pick either primitive).

pub mod bvh;
mod coherence;
pub mod grid;
pub mod kdtree;
pub mod linear;
mod mailbox;
mod stack;

#[cfg(test)]
pub(crate) mod conformance;

pub use bvh::{Bvh, BvhBuildParams};
pub use coherence::{RayCoherence, current_ray_coherence, with_ray_coherence};
pub use grid::{Grid, GridBuildParams};
pub use kdtree::{Clipper, KdTree, KdTreeBuildParams};
pub use linear::Linear;

use crate::math::{Aabb, Ray};
use std::ops::Range;

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

/// Size and quality of a built structure.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AccelStats {
    /// All nodes (or cells), interior and leaf.
    pub nodes: usize,
    /// Leaves (or non-empty cells).
    pub leaves: usize,
    /// Primitive references stored (a primitive may be in several leaves).
    pub references: usize,
    /// Bytes of memory the structure holds.
    pub memory_bytes: usize,
    /// Surface-area-heuristic cost of the structure (traversal step 1,
    /// primitive test 1, relative to the root box), 0 where not defined.
    pub sah_cost: f64,
    /// Deepest leaf (0 for a single leaf).
    pub max_depth: usize,
}

/// Which structure to build.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum AccelKind {
    /// Bounding volume hierarchy, built with the binned SAH.
    #[default]
    Bvh,
    /// Brute force: the reference.
    Linear,
    /// A uniform grid walked by a 3D-DDA.
    Grid,
    /// Kd-tree, built with the SAH in O(N log N).
    KdTree,
}

impl AccelKind {
    /// Every kind, in the order `whitted bench` reports them.
    pub const ALL: [AccelKind; 4] = [
        AccelKind::Bvh,
        AccelKind::KdTree,
        AccelKind::Grid,
        AccelKind::Linear,
    ];

    /// The name used on the command line and in scene files.
    pub fn name(&self) -> &'static str {
        match self {
            AccelKind::Bvh => "bvh",
            AccelKind::Linear => "linear",
            AccelKind::Grid => "grid",
            AccelKind::KdTree => "kdtree",
        }
    }

    /// The kind called `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// A built acceleration structure of any kind.
#[derive(Clone, Debug)]
pub enum Accelerator {
    /// Bounding volume hierarchy.
    Bvh(Bvh),
    /// Brute force.
    Linear(Linear),
    /// A uniform grid.
    Grid(Grid),
    /// Kd-tree.
    KdTree(KdTree),
}

impl Accelerator {
    /// Builds a structure of `kind` over primitives `0..boxes.len()`.
    pub fn build(kind: AccelKind, boxes: &[Aabb]) -> Self {
        match kind {
            AccelKind::Bvh => Accelerator::Bvh(Bvh::build(boxes)),
            AccelKind::Linear => Accelerator::Linear(Linear::build(boxes)),
            AccelKind::Grid => Accelerator::Grid(Grid::build(boxes)),
            AccelKind::KdTree => Accelerator::KdTree(KdTree::build(boxes)),
        }
    }

    /// Builds a structure of `kind` over primitives `0..boxes.len()`; a
    /// kd-tree clips its straddling primitives to the cells with `clip`
    /// ([`KdTree::build_clipped`]), the other structures ignore it.
    pub fn build_clipped(kind: AccelKind, boxes: &[Aabb], clip: Clipper) -> Self {
        match kind {
            AccelKind::KdTree => Accelerator::KdTree(KdTree::build_clipped(
                boxes,
                &KdTreeBuildParams::default(),
                clip,
            )),
            _ => Self::build(kind, boxes),
        }
    }

    /// Which kind it is.
    pub fn kind(&self) -> AccelKind {
        match self {
            Accelerator::Bvh(_) => AccelKind::Bvh,
            Accelerator::Linear(_) => AccelKind::Linear,
            Accelerator::Grid(_) => AccelKind::Grid,
            Accelerator::KdTree(_) => AccelKind::KdTree,
        }
    }

    /// The closest hit; see the module documentation.
    #[inline]
    pub fn intersect(
        &self,
        ray: &Ray,
        counters: &mut TraversalCounters,
        hit: impl FnMut(u32, f64) -> Option<f64>,
    ) -> Option<f64> {
        match self {
            Accelerator::Bvh(s) => s.intersect(ray, counters, hit),
            Accelerator::Linear(s) => s.intersect(ray, counters, hit),
            Accelerator::Grid(s) => s.intersect(ray, counters, hit),
            Accelerator::KdTree(s) => s.intersect(ray, counters, hit),
        }
    }

    /// Any hit; see the module documentation.
    #[inline]
    pub fn occluded(
        &self,
        ray: &Ray,
        counters: &mut TraversalCounters,
        occludes: impl FnMut(u32) -> bool,
    ) -> bool {
        match self {
            Accelerator::Bvh(s) => s.occluded(ray, counters, occludes),
            Accelerator::Linear(s) => s.occluded(ray, counters, occludes),
            Accelerator::Grid(s) => s.occluded(ray, counters, occludes),
            Accelerator::KdTree(s) => s.occluded(ray, counters, occludes),
        }
    }

    /// The primitive numbers that the positions handed out by
    /// [`Self::intersect_in_leaf_order`] and [`Self::occluded_in_leaf_order`]
    /// stand for, each leaf's together, for the structures that list them
    /// (BVH, kd-tree); `None` for the others, whose positions are the
    /// primitive numbers themselves.
    pub fn leaf_order(&self) -> Option<&[u32]> {
        match self {
            Accelerator::Bvh(s) => Some(s.indices()),
            Accelerator::KdTree(s) => Some(s.indices()),
            Accelerator::Linear(_) | Accelerator::Grid(_) => None,
        }
    }

    /// The closest hit, with `hit` given a whole leaf at a time: a range of
    /// positions (see [`Self::leaf_order`]) and the closest hit so far; it
    /// returns the closest hit among them nearer than that. A grid or brute
    /// force hands each primitive over as a leaf of its own.
    #[inline]
    pub fn intersect_in_leaf_order(
        &self,
        ray: &Ray,
        counters: &mut TraversalCounters,
        mut hit: impl FnMut(Range<u32>, f64) -> Option<f64>,
    ) -> Option<f64> {
        match self {
            Accelerator::Bvh(s) => s.intersect_in_leaf_order(ray, counters, hit),
            Accelerator::KdTree(s) => s.intersect_in_leaf_order(ray, counters, hit),
            Accelerator::Linear(_) | Accelerator::Grid(_) => {
                self.intersect(ray, counters, |p, t_max| hit(p..p + 1, t_max))
            }
        }
    }

    /// Any hit, with `occludes` given a whole leaf at a time as for
    /// [`Self::intersect_in_leaf_order`]; it says whether any of them lies
    /// in the ray's interval.
    #[inline]
    pub fn occluded_in_leaf_order(
        &self,
        ray: &Ray,
        counters: &mut TraversalCounters,
        mut occludes: impl FnMut(Range<u32>) -> bool,
    ) -> bool {
        match self {
            Accelerator::Bvh(s) => s.occluded_in_leaf_order(ray, counters, occludes),
            Accelerator::KdTree(s) => s.occluded_in_leaf_order(ray, counters, occludes),
            Accelerator::Linear(_) | Accelerator::Grid(_) => {
                self.occluded(ray, counters, |p| occludes(p..p + 1))
            }
        }
    }

    /// Checks the structure's invariants against the boxes it was built
    /// from: every primitive reachable, children inside parents, depth
    /// within the traversal stack.
    pub fn validate(&self, boxes: &[Aabb]) -> Result<(), String> {
        match self {
            Accelerator::Bvh(s) => s.validate(boxes),
            Accelerator::Linear(s) => s.validate(boxes),
            Accelerator::Grid(s) => s.validate(boxes),
            Accelerator::KdTree(s) => s.validate(boxes),
        }
    }

    /// Size and quality.
    pub fn stats(&self) -> AccelStats {
        match self {
            Accelerator::Bvh(s) => s.stats(),
            Accelerator::Linear(s) => s.stats(),
            Accelerator::Grid(s) => s.stats(),
            Accelerator::KdTree(s) => s.stats(),
        }
    }
}
