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
//! kept aside) and at most 2^32 references.

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
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KdTreeBuildParams {
    /// Cost of one traversal step.
    pub traversal_cost: f64,
    /// Cost of one primitive test, relative to a traversal step.
    pub intersection_cost: f64,
    /// Multiplies the cost of a split that leaves one side empty (below 1
    /// favours cutting off empty space).
    pub empty_factor: f64,
    /// Deepest leaf allowed; `None` means 8 + 1.3 log2 N. Always capped at
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
#[derive(Clone, Debug)]
pub struct KdTree {
    /// The nodes, root first, each below child right after its parent.
    nodes: Vec<KdNode>,
    /// The leaves' primitives, each leaf a contiguous run.
    indices: Vec<u32>,
    /// The root cell: the placed boxes' union, widened to `f32`.
    bounds: Aabb,
    /// Primitives whose boxes could not be placed, with their boxes.
    loose: Vec<(u32, Aabb)>,
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
