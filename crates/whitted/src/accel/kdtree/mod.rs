//! A kd-tree built with the surface area heuristic in O(N log N) (Wald and
//! Havran 2006), stored as 8-byte nodes (pbrt-v4 `KdTreeNode`).
//!
//! - `node.rs`: the compact node.
//! - `events.rs`: split events, sorted once.
//! - `sah.rs`: the cost model and the sweep that picks a plane.
//! - `build.rs`: the recursive build that splits the sorted events.
//! - `traverse.rs`: closest-hit and any-hit queries.
//! - `check.rs`: `validate` and `stats`.
//!
//! Split planes are `f32`. Boxes are widened outwards to the `f32` grid
//! before the build, so every plane is an exact event position and the
//! primitives are assigned against the plane traversal tests: a box that
//! straddles it goes to both children, one that touches it to the side it
//! lies on, one lying flat in it to the cheaper side. Cells are closed:
//! traversal visits both children wherever the ray may be on the plane.
//! Boxes that cannot be placed (empty, not finite or
//! beyond `f32`) are kept aside and tested for every ray, as brute force
//! would.
//!
//! "Perfect splits" (Wald and Havran 2006, section 4.4): a build may be
//! given a [`Clipper`], the bounds of a primitive inside a cell. A
//! primitive straddling a split then gets, in each child, the box of its
//! own part inside that child's cell instead of its box ∩ the cell, and
//! goes to no child it does not meet: a triangle crossing a cell
//! diagonally is not copied into every cell its box reaches.
//!
//! Limits: at most 2^30 − 1 primitives are placed in the tree (more are
//! kept aside), at most 2^32 references, and splitting stops near 2^29
//! nodes.
//!
//! # How it is walked, and why
//!
//! A child cell without primitives is not stored: its parent says so, and
//! the walk never steps into it (`node.rs`). [`KdTree::indices`] lists the
//! leaves' primitives in leaf order, and `World` keeps the triangle
//! corners per entry of it, as for the BVH, so a leaf's triangles are read
//! together, at the price of 80 bytes per reference rather than per
//! triangle. The default depth limit, 4 + 1.3 log2 N instead of pbrt's
//! 8 + 1.3 log2 N, gives fewer, slightly larger leaves (fewer nodes and
//! references, a quicker build) at the same trace speed.
//!
//! The walk (`traverse.rs`) spends most of its time on its own steps, not
//! on the primitive tests nor on memory: what a step waits on is the
//! branch predictor. At a node with two stored children the next node is
//! chosen by a branch on the ray's direction, which the predictor learns
//! for rays that go the same way; a predicted branch lets the next node's
//! load start before the arithmetic that decides it is done, where a
//! select would make every load wait for the previous step. At a node with
//! one stored child (an empty-space cut) there is no choice of node, only
//! whether the ray meets the child, so there the end of the range that the
//! crossing clips is picked by a select (`stored_side`), leaving one
//! branch, on dead ends. The plane crossing has no NaN branch (a NaN
//! crossing keeps both children over the node's range), and the to-do
//! stack is not cleared for every ray; its size follows the tree's depth
//! (32 entries up to depth 32, else 64).
//!
//! The leaf-order queries hand the caller whole leaves, without the
//! mailbox: one call a leaf, no mailbox to clear per ray nor index to read
//! per primitive, and a shadow ray's triangles can be tested four at a
//! time (AVX), as the BVH's are.
//!
//! Rays whose directions are unrelated from one to the next make the
//! branch on the direction a coin flip. For rays the caller says are
//! incoherent ([`crate::accel::RayCoherence::Incoherent`] in the query's
//! [`crate::accel::QueryContext`]; `whitted bench` says so of its diffuse
//! rays), a ray starting inside the tree first goes down
//! the cells holding its origin, choosing each child by the origin's side
//! of the plane (a branch neighbouring origins take alike) and pushing the
//! other without a branch on the direction (`traverse.rs`, `descend`); it
//! also goes through empty-space cuts whose stored child holds the origin.
//! Other rays walk from the root: for rays that go the same way the walk's
//! branches are well predicted and skip most of the arithmetic that a step
//! of the descent always does.
//!
//! The figures behind these choices are in docs/performance-log.md (kd-tree
//! walk; kd-tree descent to the origin's leaf). Tried and not kept, with
//! their figures there too (more at the spots in `traverse.rs`):
//! - Tried any-hit rays without the mailbox, one call a primitive: no gain.
//! - Tried the corners once per primitive, through the indices: slower.
//! - Tried the mailbox back on leaf-order closest hits: no faster.
//! - Tried closest hits testing four triangles at a time: slower.
//! - Tried the descent for every ray: slower for coherent rays.
//! - Tried guessing incoherent rays per thread from their octants: slower.

mod build;
mod check;
mod events;
mod node;
mod sah;
mod traverse;

#[cfg(test)]
mod tests;

use crate::math::Aabb;
use node::KdNode;

/// Options of the kd-tree build.
///
/// Tried other cost constants and depth limits: none faster, see
/// docs/performance-log.md (kd-tree build parameters).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KdTreeBuildParams {
    /// Cost of one traversal step.
    pub traversal_cost: f64,
    /// Cost of one primitive test, relative to a traversal step.
    pub intersection_cost: f64,
    /// Multiplies the cost of a split that leaves one side empty (below 1
    /// favours cutting off empty space).
    pub empty_factor: f64,
    /// Deepest leaf allowed; `None` means 4 + 1.3 log2 N. Always capped at
    /// the traversal stack's 64 entries.
    pub max_depth: Option<usize>,
}

impl Default for KdTreeBuildParams {
    fn default() -> Self {
        Self {
            traversal_cost: 1.0,
            intersection_cost: 1.5,
            empty_factor: 0.8,
            max_depth: None,
        }
    }
}

/// A kd-tree over primitive boxes.
///
/// Its queries start the walk of a ray at its origin's leaf when the
/// caller says the rays are incoherent
/// ([`crate::accel::RayCoherence::Incoherent`] in the query's
/// [`crate::accel::QueryContext`]), at the root otherwise. Only their speed depends on it: both starts
/// return the same closest `t` (on an exact tie, possibly another
/// primitive).
#[derive(Clone, Debug)]
pub struct KdTree {
    /// The nodes, root first, each below child right after its parent.
    nodes: Vec<KdNode>,
    /// The leaves' primitives, each leaf a contiguous run, then those of
    /// `loose` in its order.
    indices: Vec<u32>,
    /// The root cell: the placed boxes' union, widened to `f32`.
    bounds: Aabb,
    /// Primitives whose boxes could not be placed, with their boxes (also
    /// at the end of `indices`).
    loose: Vec<(u32, Aabb)>,
    /// The depth of the deepest leaf (the root's is 0), at most the
    /// traversal stack's capacity: it picks the stack a walk uses.
    max_depth: usize,
}

impl KdTree {
    /// A tree over primitives `0..boxes.len()` with these boxes, built with
    /// the default options.
    pub fn build(boxes: &[Aabb]) -> Self {
        Self::build_with(boxes, &KdTreeBuildParams::default())
    }

    /// A tree over primitives `0..boxes.len()` with these boxes.
    pub fn build_with(boxes: &[Aabb], params: &KdTreeBuildParams) -> Self {
        build::build(boxes, params, None).0
    }

    /// A tree over primitives `0..boxes.len()` with these boxes, whose
    /// straddling primitives are clipped to the cells by `clip` ("perfect
    /// splits"). Validate it with [`KdTree::validate_clipped`].
    pub fn build_clipped(boxes: &[Aabb], params: &KdTreeBuildParams, clip: Clipper) -> Self {
        build::build(boxes, params, Some(clip)).0
    }

    /// The primitive numbers the leaf-order queries' positions refer to
    /// ([`KdTree::intersect_in_leaf_order`]): each leaf's as a contiguous
    /// run (a primitive appears once per leaf that holds it), then those
    /// kept aside.
    pub fn indices(&self) -> &[u32] {
        &self.indices
    }
}

/// The bounds of primitive `i` inside the closed box `cell`, or `None`
/// when the primitive does not meet it. It must be conservative: every
/// point of the primitive inside `cell` lies in the returned box (which
/// the build then intersects with the primitive's box and the cell).
pub type Clipper<'a> = &'a dyn Fn(u32, &Aabb) -> Option<Aabb>;

/// The cells below and above `plane` on `axis`.
fn split_cell(cell: &Aabb, axis: usize, plane: f64) -> [Aabb; 2] {
    let mut below = *cell;
    below.max[axis] = plane;
    let mut above = *cell;
    above.min[axis] = plane;
    [below, above]
}
