//! The top-down build: surface area heuristic (SAH) splits, binned for
//! large nodes (`bins`) and exact for small ones (`sweep`), an object
//! median where the SAH has nothing to offer, subtrees built in parallel.
//!
//! The primitives' indices and `f32` boxes are reordered together in place
//! (`prims`), so each node reads its boxes in order. Every subtree over `n`
//! primitives owns, in a scratch node array, its own slot plus a region of
//! `2n - 2` slots for its descendants (a binary tree with `n` non-empty
//! leaves never needs more), so the two halves of a split write to
//! disjoint slices and the result is the same whatever the number of
//! threads. The binary tree is then collapsed into eight-wide nodes
//! (`collapse`).

use super::MAX_DEPTH;
use super::bins::{Bins, MAX_BINS};
use super::collapse::collapse;
use super::fbox::FBox;
use super::node::{BinaryNode, BvhNode};
use super::prims::{Prims, bounds_of};
use super::sweep::{self, SWEEP_MAX};
use crate::math::Aabb;
use rayon::prelude::*;

/// How a node's primitives are divided between its two children.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplitMethod {
    /// The cheapest of the planes between centroid bins on all three axes,
    /// by the surface area heuristic; a leaf when no split is cheaper.
    BinnedSah,
    /// Half the primitives on each side, sorted by centroid along the
    /// widest axis: fast to build, slower to trace.
    ObjectMedian,
}

/// Options of [`super::Bvh::build_with`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BvhBuildParams {
    /// How nodes are split.
    pub split: SplitMethod,
    /// Centroid bins per axis for [`SplitMethod::BinnedSah`], clamped to
    /// `2..=64`; a node of `n` primitives uses at most `2n`.
    pub bins: usize,
    /// Nodes with more primitives are always split (at least 1).
    pub max_leaf_size: usize,
    /// Subtrees of at least this many primitives are built in parallel,
    /// and the primitives' boxes are prepared in parallel runs of this many.
    pub parallel_threshold: usize,
}

impl Default for BvhBuildParams {
    /// Binned SAH with 16 bins, leaves of at most 8 primitives.
    fn default() -> Self {
        Self {
            split: SplitMethod::BinnedSah,
            bins: 16,
            max_leaf_size: 8,
            parallel_threshold: 4096,
        }
    }
}

impl BvhBuildParams {
    /// Object-median splits down to single primitives: the quickest build,
    /// a baseline for the SAH.
    pub fn fastest_build() -> Self {
        Self {
            split: SplitMethod::ObjectMedian,
            max_leaf_size: 1,
            ..Self::default()
        }
    }

    /// Binned SAH with 32 bins: a slower build for a slightly better tree.
    pub fn high_quality() -> Self {
        Self {
            bins: 32,
            ..Self::default()
        }
    }
}

/// Below this depth splits may be as uneven as the SAH likes; from it on
/// they are object medians, which halve the count, so no leaf of a tree
/// over up to 2³² primitives lies deeper than [`MAX_DEPTH`].
const SAH_DEPTH_LIMIT: usize = MAX_DEPTH - 32;

/// The packed nodes, the reordered primitive indices and the deepest leaf's
/// depth. No primitives, no nodes.
pub(super) fn build(boxes: &[Aabb], params: &BvhBuildParams) -> (Vec<BvhNode>, Vec<u32>, usize) {
    let n = boxes.len();
    if n == 0 {
        return (Vec::new(), Vec::new(), 0);
    }
    let builder = Builder {
        params: BvhBuildParams {
            bins: params.bins.clamp(2, MAX_BINS),
            max_leaf_size: params.max_leaf_size.max(1),
            ..*params
        },
    };
    let mut boxes: Vec<FBox> = boxes
        .par_iter()
        .with_min_len(builder.params.parallel_threshold.max(1))
        .map(FBox::outward)
        .collect();
    let mut indices: Vec<u32> = (0..n as u32).collect();
    let mut scratch = BinaryNode::zeroed_vec(2 * n - 1);
    let (root, below) = scratch.split_at_mut(1);
    let (bounds, centroid_bounds) = bounds_of(&boxes);
    let task = Subtree {
        prims: Prims {
            ids: &mut indices,
            boxes: &mut boxes,
        },
        first_prim: 0,
        depth: 0,
        bounds,
        centroid_bounds,
        node: &mut root[0],
        below,
        first_below: 1,
    };
    builder.subtree(task, &mut Bins::new());
    let (nodes, max_depth) = collapse(&scratch);
    (nodes, indices, max_depth)
}

/// Read-only state shared by every subtree.
struct Builder {
    params: BvhBuildParams,
}

/// One subtree to build: its primitives and where its nodes go.
struct Subtree<'s> {
    /// Its part of the index and box arrays, reordered in place.
    prims: Prims<'s>,
    /// Position of `prims` in the whole index array.
    first_prim: usize,
    depth: usize,
    /// The box around its primitives, known from its parent's bins.
    bounds: FBox,
    /// The box around its primitives' centroids, gathered by its parent's
    /// partition.
    centroid_bounds: FBox,
    /// Its root's slot.
    node: &'s mut BinaryNode,
    /// The `2 * prims.len() - 2` slots reserved for its descendants.
    below: &'s mut [BinaryNode],
    /// Position of `below` in the scratch node array.
    first_below: usize,
}

/// Where a node's primitives are divided.
enum Split {
    Leaf,
    /// `prims[..mid]` go left, the rest right.
    At(Halves),
}

/// The two sides of a split: how many primitives go left, and each side's
/// box and centroid box.
pub(super) struct Halves {
    /// `prims[..mid]` go left.
    pub(super) mid: usize,
    /// The left side's box and the box around its centroids.
    pub(super) left: (FBox, FBox),
    /// The right side's box and the box around its centroids.
    pub(super) right: (FBox, FBox),
}

impl Builder {
    fn subtree(&self, mut task: Subtree<'_>, bins: &mut Bins) {
        let bounds = task.bounds;
        let count = task.prims.len();
        let split = self.split(
            &mut task.prims,
            task.depth,
            &bounds,
            &task.centroid_bounds,
            bins,
        );
        let halves = match split {
            Split::Leaf => {
                *task.node =
                    BinaryNode::new(&bounds.to_aabb(), task.first_prim as u32, count as u32);
                return;
            }
            Split::At(halves) => halves,
        };
        let mid = halves.mid;
        *task.node = BinaryNode::new(&bounds.to_aabb(), task.first_below as u32, 0);
        let (pair, rest) = task.below.split_at_mut(2);
        let (left_node, right_node) = pair.split_at_mut(1);
        let (left_below, right_below) = rest.split_at_mut(2 * mid - 2);
        let parallel = count >= self.params.parallel_threshold;
        let (left_prims, right_prims) = task.prims.split_at(mid);
        let left = Subtree {
            prims: left_prims,
            first_prim: task.first_prim,
            depth: task.depth + 1,
            bounds: halves.left.0,
            centroid_bounds: halves.left.1,
            node: &mut left_node[0],
            below: left_below,
            first_below: task.first_below + 2,
        };
        let right = Subtree {
            prims: right_prims,
            first_prim: task.first_prim + mid,
            depth: task.depth + 1,
            bounds: halves.right.0,
            centroid_bounds: halves.right.1,
            node: &mut right_node[0],
            first_below: task.first_below + 2 * mid,
            below: right_below,
        };
        if parallel {
            rayon::join(
                || self.subtree(left, bins),
                || self.subtree(right, &mut Bins::new()),
            );
        } else {
            self.subtree(left, bins);
            self.subtree(right, bins);
        }
    }

    /// Decides where to split and partitions `prims` accordingly.
    fn split(
        &self,
        prims: &mut Prims,
        depth: usize,
        bounds: &FBox,
        centroid_bounds: &FBox,
        bins: &mut Bins,
    ) -> Split {
        let n = prims.len();
        if n == 1 {
            return Split::Leaf;
        }
        let must_split = n > self.params.max_leaf_size;
        if self.params.split == SplitMethod::BinnedSah && depth < SAH_DEPTH_LIMIT {
            let found = if n <= SWEEP_MAX {
                sweep::best_split(prims)
            } else {
                bins.best_plane(self.params.bins, prims.boxes, centroid_bounds)
                    .map(|plane| (plane.cost, plane.partition(prims)))
            };
            if let Some((cost, halves)) = found {
                // Costs times the parent's half area: traversal step 1,
                // primitive test 1.
                // Tried a step of 0.5: no faster, see docs/performance-log.md.
                // Tried pricing leaves by blocks of four triangles: slower.
                let area = bounds.half_area();
                if !must_split && cost + area >= n as f32 * area {
                    return Split::Leaf;
                }
                return Split::At(halves);
            }
        }
        if must_split {
            let mid = median(prims, centroid_bounds);
            let (left, right) = prims.boxes.split_at(mid);
            Split::At(Halves {
                mid,
                left: bounds_of(left),
                right: bounds_of(right),
            })
        } else {
            Split::Leaf
        }
    }
}

/// Splits at the centroid median of the widest centroid axis; equal
/// centroids are ordered by index, so both halves are never empty.
fn median(prims: &mut Prims, centroid_bounds: &FBox) -> usize {
    let axis = (centroid_bounds.max - centroid_bounds.min).max_position();
    let mid = prims.len() / 2;
    let key = |i: usize| (prims.boxes[i].centre()[axis], prims.ids[i]);
    let mut order: Vec<usize> = (0..prims.len()).collect();
    order.select_nth_unstable_by(mid, |&a, &b| {
        let ((ca, ia), (cb, ib)) = (key(a), key(b));
        ca.total_cmp(&cb).then(ia.cmp(&ib))
    });
    prims.permute(&mut order);
    mid
}
