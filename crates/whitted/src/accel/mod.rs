//! Acceleration structures: index structures over bounding boxes.
//!
//! A structure never knows what a shape is. It is built from the primitives'
//! world-space boxes, and its queries take a closure that intersects
//! primitive `i`; the caller keeps whatever hit data it needs in the
//! closure's state. Unbounded shapes (infinite planes) never enter a
//! structure: the world (the `world` module, a layer above) tests them in
//! a short list beside it.
//!
//! Every structure implements [`AccelerationStructure`]: the closest hit
//! (`intersect`), any hit (`occluded`), both also a leaf at a time for
//! callers that keep primitive data in leaf order, `validate` and `stats`.
//! [`Accelerator`] is the enum over the four, dispatched by `match`.
//!
//! Every query takes a [`QueryContext`]: the caller says there how its
//! rays relate ([`RayCoherence`]), and the structure adds the work it did.
//! A structure may pick how it walks by the hint, never the closest `t` it
//! returns (on an exact tie, which primitive may change, as between
//! structures).
//!
//! Culling must be conservative: a structure may skip a primitive only when
//! the ray provably cannot meet its box within the interval, so every
//! structure returns exactly the closest hit the brute-force [`Linear`]
//! returns. A structure never skips a primitive hit at exactly the closest
//! `t` so far either (its walk goes on into a cell or child that starts
//! there), so a caller that keeps the lower-numbered of a tie, as the
//! world's leaf tests do, gets the same primitive from every structure.

pub mod bvh;
mod context;
pub mod grid;
pub mod kdtree;
pub mod kernel;
mod leaves;
pub mod linear;
mod mailbox;
mod stack;

#[cfg(test)]
pub(crate) mod conformance;

pub use bvh::{Bvh, BvhBuildParams};
pub use context::{QueryContext, RayCoherence, TraversalCounters};
pub use grid::{Grid, GridBuildParams};
pub use kdtree::{Clipper, KdTree, KdTreeBuildParams};
use kernel::Kernel;
pub use kernel::{Backend, ISA_VARIABLE, Isa};
pub(crate) use leaves::{AnyLeaves, ClosestLeaves};
pub use linear::Linear;

use crate::math::{Aabb, Ray};
use std::ops::Range;

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

    /// An estimate of the most bytes a structure of this kind takes per
    /// primitive while it is built and used: its boxes, scratch and nodes
    /// (the kd-tree's references clipped to its cells included). Measured
    /// on the bunny and the dragon (docs/performance-log.md, "Large
    /// models"), rounded up; an estimate, not a bound.
    pub fn bytes_per_primitive(self) -> u64 {
        match self {
            AccelKind::Linear => 48,
            AccelKind::Grid => 96,
            AccelKind::Bvh => 160,
            AccelKind::KdTree => 512,
        }
    }
}

/// What every acceleration structure offers, checked by the compiler;
/// [`Accelerator`] dispatches to the four by `match`. Positions in
/// [`Self::leaf_order`] are what the leaf-order queries hand out.
pub trait AccelerationStructure {
    /// The closest hit: `hit(i, t_max)` intersects primitive `i` and returns
    /// the parameter of a hit closer than `t_max`, if any; the structure
    /// returns the closest parameter found.
    fn intersect(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        hit: impl FnMut(u32, f64) -> Option<f64>,
    ) -> Option<f64>;

    /// Any hit: stops at the first primitive for which `occludes(i)` holds.
    fn occluded(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        occludes: impl FnMut(u32) -> bool,
    ) -> bool;

    /// The primitive numbers that the positions handed out by the
    /// leaf-order queries stand for, each leaf's together; `None` when the
    /// positions are the primitive numbers themselves.
    fn leaf_order(&self) -> Option<&[u32]> {
        None
    }

    /// The closest hit, with `hit` given a whole leaf at a time: a range of
    /// positions (see [`Self::leaf_order`]) and the closest hit so far; it
    /// returns the closest hit among them nearer than that. By default
    /// each primitive comes as a leaf of its own.
    fn intersect_in_leaf_order(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        mut hit: impl FnMut(Range<u32>, f64) -> Option<f64>,
    ) -> Option<f64> {
        self.intersect(ray, ctx, |p, t_max| hit(p..p + 1, t_max))
    }

    /// Any hit, with `occludes` given a whole leaf at a time as for
    /// [`Self::intersect_in_leaf_order`]; it says whether any of them lies
    /// in the ray's interval.
    fn occluded_in_leaf_order(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        mut occludes: impl FnMut(Range<u32>) -> bool,
    ) -> bool {
        self.occluded(ray, ctx, |p| occludes(p..p + 1))
    }

    /// Checks the structure's invariants against the boxes it was built
    /// from: every primitive reachable, children inside parents, depth
    /// within the traversal stack.
    fn validate(&self, boxes: &[Aabb]) -> Result<(), String>;

    /// Size and quality.
    fn stats(&self) -> AccelStats;
}

/// Implements [`AccelerationStructure`] for a structure by its inherent
/// methods of the same names; `leaf order` names the structures whose
/// leaf-order queries are their own.
macro_rules! structure_by_inherent_methods {
    ($structure:ty $(, leaf order: $indices:ident)?) => {
        impl AccelerationStructure for $structure {
            #[inline(always)]
            fn intersect(
                &self,
                ray: &Ray,
                ctx: &mut QueryContext,
                hit: impl FnMut(u32, f64) -> Option<f64>,
            ) -> Option<f64> {
                <$structure>::intersect(self, ray, ctx, hit)
            }

            #[inline(always)]
            fn occluded(
                &self,
                ray: &Ray,
                ctx: &mut QueryContext,
                occludes: impl FnMut(u32) -> bool,
            ) -> bool {
                <$structure>::occluded(self, ray, ctx, occludes)
            }

            $(
            fn leaf_order(&self) -> Option<&[u32]> {
                Some(self.$indices())
            }

            #[inline(always)]
            fn intersect_in_leaf_order(
                &self,
                ray: &Ray,
                ctx: &mut QueryContext,
                hit: impl FnMut(Range<u32>, f64) -> Option<f64>,
            ) -> Option<f64> {
                <$structure>::intersect_in_leaf_order(self, ray, ctx, hit)
            }

            #[inline(always)]
            fn occluded_in_leaf_order(
                &self,
                ray: &Ray,
                ctx: &mut QueryContext,
                occludes: impl FnMut(Range<u32>) -> bool,
            ) -> bool {
                <$structure>::occluded_in_leaf_order(self, ray, ctx, occludes)
            }
            )?

            fn validate(&self, boxes: &[Aabb]) -> Result<(), String> {
                <$structure>::validate(self, boxes)
            }

            fn stats(&self) -> AccelStats {
                <$structure>::stats(self)
            }
        }
    };
}

structure_by_inherent_methods!(Bvh, leaf order: indices);
structure_by_inherent_methods!(KdTree, leaf order: indices);
structure_by_inherent_methods!(Grid);
structure_by_inherent_methods!(Linear);

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

/// Calls `$call` on the structure inside an [`Accelerator`], whatever its
/// kind.
macro_rules! each_structure {
    ($accel:expr, $s:ident => $call:expr) => {
        match $accel {
            Accelerator::Bvh($s) => $call,
            Accelerator::Linear($s) => $call,
            Accelerator::Grid($s) => $call,
            Accelerator::KdTree($s) => $call,
        }
    };
}

impl Accelerator {
    /// Builds a structure of `kind` over primitives `0..boxes.len()`. (A
    /// kd-tree that should clip straddling primitives to its cells is built
    /// with [`KdTree::build_clipped`].)
    pub fn build(kind: AccelKind, boxes: &[Aabb]) -> Self {
        match kind {
            AccelKind::Bvh => Accelerator::Bvh(Bvh::build(boxes)),
            AccelKind::Linear => Accelerator::Linear(Linear::build(boxes)),
            AccelKind::Grid => Accelerator::Grid(Grid::build(boxes)),
            AccelKind::KdTree => Accelerator::KdTree(KdTree::build(boxes)),
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
}

impl Accelerator {
    /// The closest hit with kernel `K`, the leaves tested by `leaves` (see
    /// [`AccelerationStructure::intersect_in_leaf_order`]).
    #[inline(always)]
    pub(crate) fn closest_with<K: Kernel>(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        mut leaves: impl ClosestLeaves,
    ) -> Option<f64> {
        match self {
            Accelerator::Bvh(bvh) => bvh.closest_with::<K>(ray, &mut ctx.counters, leaves),
            other => other.intersect_in_leaf_order(ray, ctx, |range, t_max| {
                leaves.closest::<K>(range, t_max)
            }),
        }
    }

    /// Any hit with kernel `K`, the leaves tested by `leaves` (see
    /// [`AccelerationStructure::occluded_in_leaf_order`]).
    #[inline(always)]
    pub(crate) fn any_with<K: Kernel>(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        mut leaves: impl AnyLeaves,
    ) -> bool {
        match self {
            Accelerator::Bvh(bvh) => bvh.any_with::<K>(ray, &mut ctx.counters, leaves),
            other => other.occluded_in_leaf_order(ray, ctx, |range| leaves.occludes::<K>(range)),
        }
    }
}

impl AccelerationStructure for Accelerator {
    #[inline]
    fn intersect(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        hit: impl FnMut(u32, f64) -> Option<f64>,
    ) -> Option<f64> {
        each_structure!(self, s => AccelerationStructure::intersect(s, ray, ctx, hit))
    }

    #[inline]
    fn occluded(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        occludes: impl FnMut(u32) -> bool,
    ) -> bool {
        each_structure!(self, s => AccelerationStructure::occluded(s, ray, ctx, occludes))
    }

    fn leaf_order(&self) -> Option<&[u32]> {
        each_structure!(self, s => s.leaf_order())
    }

    #[inline]
    fn intersect_in_leaf_order(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        hit: impl FnMut(Range<u32>, f64) -> Option<f64>,
    ) -> Option<f64> {
        each_structure!(self, s => AccelerationStructure::intersect_in_leaf_order(s, ray, ctx, hit))
    }

    #[inline]
    fn occluded_in_leaf_order(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        occludes: impl FnMut(Range<u32>) -> bool,
    ) -> bool {
        each_structure!(self, s => AccelerationStructure::occluded_in_leaf_order(s, ray, ctx, occludes))
    }

    fn validate(&self, boxes: &[Aabb]) -> Result<(), String> {
        each_structure!(self, s => AccelerationStructure::validate(s, boxes))
    }

    fn stats(&self) -> AccelStats {
        each_structure!(self, s => AccelerationStructure::stats(s))
    }
}
