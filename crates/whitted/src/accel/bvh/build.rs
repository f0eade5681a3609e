//! The top-down build: binned surface area heuristic (SAH) splits, an object
//! median where the SAH has nothing to offer, subtrees built in parallel.
//!
//! Every subtree over `n` primitives owns, in a scratch node array, its own
//! slot plus a region of `2n - 2` slots for its descendants (a binary tree
//! with `n` non-empty leaves never needs more), so the two halves of a split
//! write to disjoint slices and the result is the same whatever the number
//! of threads. The binary tree is then collapsed into four-wide nodes
//! (`collapse`).

use super::MAX_DEPTH;
use super::collapse::collapse;
use super::node::{BinaryNode, BvhNode, round_down, round_up};
use crate::math::{Aabb, Vec3};
use glam::{Vec3A, Vec3Swizzles};

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
    /// Subtrees of at least this many primitives are built in parallel.
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

/// The most bins per axis.
const MAX_BINS: usize = 64;

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
        boxes: boxes.iter().map(FBox::outward).collect(),
        centroids: boxes.iter().map(Aabb::centroid).collect(),
        params: BvhBuildParams {
            bins: params.bins.clamp(2, MAX_BINS),
            max_leaf_size: params.max_leaf_size.max(1),
            ..*params
        },
    };
    let mut indices: Vec<u32> = (0..n as u32).collect();
    let mut scratch = vec![BinaryNode::default(); 2 * n - 1];
    let (root, below) = scratch.split_at_mut(1);
    let (bounds, centroid_bounds) = builder.bounds(&indices);
    let task = Subtree {
        prims: &mut indices,
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
    /// The primitives' boxes, rounded outward to `f32`.
    boxes: Vec<FBox>,
    /// The centres of their exact boxes.
    centroids: Vec<Vec3>,
    params: BvhBuildParams,
}

/// One subtree to build: its primitives and where its nodes go.
struct Subtree<'s> {
    /// Its slice of the index array, reordered in place.
    prims: &'s mut [u32],
    /// Position of `prims` in the whole index array.
    first_prim: usize,
    depth: usize,
    /// The box around its primitives, known from its parent's bins.
    bounds: FBox,
    /// The box around its primitives' centroids, gathered by its parent's
    /// partition.
    centroid_bounds: Aabb,
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
struct Halves {
    mid: usize,
    left: (FBox, Aabb),
    right: (FBox, Aabb),
}

impl Builder {
    fn subtree(&self, task: Subtree<'_>, bins: &mut Bins) {
        let bounds = task.bounds;
        let halves = match self.split(task.prims, task.depth, &bounds, &task.centroid_bounds, bins)
        {
            Split::Leaf => {
                *task.node = BinaryNode::new(
                    &bounds.to_aabb(),
                    task.first_prim as u32,
                    task.prims.len() as u32,
                );
                return;
            }
            Split::At(halves) => halves,
        };
        let mid = halves.mid;
        *task.node = BinaryNode::new(&bounds.to_aabb(), task.first_below as u32, 0);
        let (pair, rest) = task.below.split_at_mut(2);
        let (left_node, right_node) = pair.split_at_mut(1);
        let (left_below, right_below) = rest.split_at_mut(2 * mid - 2);
        let parallel = task.prims.len() >= self.params.parallel_threshold;
        let (left_prims, right_prims) = task.prims.split_at_mut(mid);
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

    /// The box around the primitives and the box around their centroids.
    /// Only the root and median splits need it: an SAH split knows its
    /// sides' boxes from the bins and gathers their centroid boxes while it
    /// partitions (recomputing both at every node took a third of the
    /// build's instructions).
    fn bounds(&self, prims: &[u32]) -> (FBox, Aabb) {
        prims.iter().fold((FBox::EMPTY, Aabb::EMPTY), |(b, c), &p| {
            let p = p as usize;
            (b.union(&self.boxes[p]), c.union_point(self.centroids[p]))
        })
    }

    /// Decides where to split and partitions `prims` accordingly.
    fn split(
        &self,
        prims: &mut [u32],
        depth: usize,
        bounds: &FBox,
        centroid_bounds: &Aabb,
        bins: &mut Bins,
    ) -> Split {
        let n = prims.len();
        if n == 1 {
            return Split::Leaf;
        }
        let must_split = n > self.params.max_leaf_size;
        if self.params.split == SplitMethod::BinnedSah
            && depth < SAH_DEPTH_LIMIT
            && let Some(best) = bins.best_plane(self, prims, centroid_bounds)
        {
            // Costs times the parent's half area: traversal step 1,
            // primitive test 1.
            let area = bounds.half_area();
            if !must_split && best.cost + area >= n as f64 * area {
                return Split::Leaf;
            }
            return Split::At(self.partition(prims, &best));
        }
        if must_split {
            let mid = self.median(prims, centroid_bounds);
            let (left, right) = prims.split_at(mid);
            Split::At(Halves {
                mid,
                left: self.bounds(left),
                right: self.bounds(right),
            })
        } else {
            Split::Leaf
        }
    }

    /// Moves the primitives left of `plane` to the front; returns how many,
    /// with the sides' boxes from the plane and their centroid boxes.
    fn partition(&self, prims: &mut [u32], plane: &Plane) -> Halves {
        let mut left = 0;
        let mut right = prims.len();
        let (mut left_centroids, mut right_centroids) = (Aabb::EMPTY, Aabb::EMPTY);
        while left < right {
            let c = self.centroids[prims[left] as usize];
            if plane.bin_of(c[plane.axis]) < plane.first_right_bin {
                left_centroids = left_centroids.union_point(c);
                left += 1;
            } else {
                right_centroids = right_centroids.union_point(c);
                right -= 1;
                prims.swap(left, right);
            }
        }
        Halves {
            mid: left,
            left: (plane.left, left_centroids),
            right: (plane.right, right_centroids),
        }
    }

    /// Splits at the centroid median of the widest centroid axis; equal
    /// centroids are ordered by index, so both halves are never empty.
    fn median(&self, prims: &mut [u32], centroid_bounds: &Aabb) -> usize {
        let axis = centroid_bounds.extent().max_position();
        let mid = prims.len() / 2;
        prims.select_nth_unstable_by(mid, |&a, &b| {
            let (ca, cb) = (
                self.centroids[a as usize][axis],
                self.centroids[b as usize][axis],
            );
            ca.total_cmp(&cb).then(a.cmp(&b))
        });
        mid
    }
}

/// A box rounded outward to `f32`, its corners in SIMD lanes: the build's
/// unions are one `minps` and one `maxps` (the `f64` boxes' NaN-aware
/// minima and maxima took most of the binning's instructions). Rounding
/// commutes with unions, so the nodes' boxes are those of the exact boxes
/// rounded outward, as before.
#[derive(Clone, Copy, Debug)]
struct FBox {
    min: Vec3A,
    max: Vec3A,
}

impl FBox {
    /// Contains nothing; the identity of [`FBox::union`].
    const EMPTY: Self = Self {
        min: Vec3A::INFINITY,
        max: Vec3A::NEG_INFINITY,
    };

    /// The smallest `f32` box around `exact`.
    fn outward(exact: &Aabb) -> Self {
        Self {
            min: Vec3A::from_array(exact.min.to_array().map(round_down)),
            max: Vec3A::from_array(exact.max.to_array().map(round_up)),
        }
    }

    #[inline]
    fn union(&self, other: &Self) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// The same box in `f64`, exactly.
    fn to_aabb(self) -> Aabb {
        Aabb {
            min: self.min.as_dvec3(),
            max: self.max.as_dvec3(),
        }
    }

    /// Half the surface area, in `f32` SIMD lanes, as `f64`; meaningless
    /// for an empty box. The sweep over the bins computes one per bin and
    /// axis at every node, which in `f64` with `Aabb`'s emptiness check took
    /// more instructions than the binning.
    #[inline]
    fn half_area(&self) -> f64 {
        let d = self.max - self.min;
        f64::from(d.dot(d.yzx()))
    }
}

/// A candidate split: the bins of one axis from `first_right_bin` on go
/// right.
struct Plane {
    axis: usize,
    low: f64,
    scale: f64,
    bins: usize,
    /// `bins - 1`.
    last_bin: f64,
    first_right_bin: usize,
    /// Σ half area × count over both sides (before dividing by the parent's
    /// half area).
    cost: f64,
    /// The box around the bins on the left.
    left: FBox,
    /// The box around the bins on the right.
    right: FBox,
}

impl Plane {
    /// The bin of centroid coordinate `c` (the last for a NaN). Clamping
    /// in `f64` before a cast to `u32` takes fewer instructions than a
    /// saturating cast to `usize` then a clamp, and this is the binning's
    /// innermost step.
    #[inline]
    fn bin_of(&self, c: f64) -> usize {
        ((c - self.low) * self.scale).min(self.last_bin) as u32 as usize
    }
}

/// The bins' contents and the sweep's partial sums, reused from node to node
/// of one thread: fixed arrays, so no node allocates.
struct Bins {
    /// Axis `a`'s bins at `a * MAX_BINS..`.
    bounds: [FBox; 3 * MAX_BINS],
    counts: [usize; 3 * MAX_BINS],
    /// The box around bins `i..` of the axis being swept.
    right_bounds: [FBox; MAX_BINS],
    /// Half area × count of bins `i..` of the axis being swept.
    right_cost: [f64; MAX_BINS],
}

impl Bins {
    fn new() -> Self {
        Self {
            bounds: [FBox::EMPTY; 3 * MAX_BINS],
            counts: [0; 3 * MAX_BINS],
            right_bounds: [FBox::EMPTY; MAX_BINS],
            right_cost: [0.0; MAX_BINS],
        }
    }

    /// The cheapest plane between bins that leaves primitives on both sides,
    /// if the centroids are spread along any axis.
    fn best_plane(&mut self, builder: &Builder, prims: &[u32], centroids: &Aabb) -> Option<Plane> {
        // Small nodes need fewer bins to find their planes: on 100k random
        // boxes this saves a quarter of the build's instructions and changes
        // the SAH cost by 5e-6.
        let bins = builder.params.bins.min(2 * prims.len());
        let planes = [0, 1, 2].map(|axis| {
            let low = centroids.min[axis];
            let extent = centroids.max[axis] - low;
            let spread = extent > 0.0 && extent.is_finite();
            Plane {
                axis,
                low,
                // Without spread everything lands in bin 0.
                scale: if spread { bins as f64 / extent } else { 0.0 },
                bins,
                last_bin: (bins - 1) as f64,
                first_right_bin: 0,
                cost: f64::INFINITY,
                left: FBox::EMPTY,
                right: FBox::EMPTY,
            }
        });
        self.fill(builder, prims, &planes);
        let mut best: Option<Plane> = None;
        for mut plane in planes {
            let bounds = &self.bounds[plane.axis * MAX_BINS..][..bins];
            let counts = &self.counts[plane.axis * MAX_BINS..][..bins];
            // Right to left: the box and cost of everything from bin i on.
            let (mut area_box, mut count) = (FBox::EMPTY, 0);
            for i in (1..bins).rev() {
                area_box = area_box.union(&bounds[i]);
                count += counts[i];
                self.right_bounds[i] = area_box;
                self.right_cost[i] = area_box.half_area() * count as f64;
            }
            // Left to right, pairing with the right side of each plane.
            let (mut area_box, mut count) = (FBox::EMPTY, 0);
            for i in 1..bins {
                area_box = area_box.union(&bounds[i - 1]);
                count += counts[i - 1];
                if count == 0 || count == prims.len() {
                    continue;
                }
                let cost = area_box.half_area() * count as f64 + self.right_cost[i];
                if cost < plane.cost {
                    plane.cost = cost;
                    plane.first_right_bin = i;
                    plane.left = area_box;
                    plane.right = self.right_bounds[i];
                }
            }
            if plane.first_right_bin > 0 && best.as_ref().is_none_or(|b| plane.cost < b.cost) {
                best = Some(plane);
            }
        }
        best
    }

    /// Puts every primitive in its bin along each axis, in one pass (one
    /// pass per axis made the whole build run 12% more instructions).
    /// Binning nodes of 16k primitives or more in parallel chunks of 8k,
    /// merging the chunks' bins (exactly, so still deterministic), was not
    /// faster: bunny 37.0 against 35.7 ms (best of 10, back to back, two
    /// shared cores), the dragon within noise.
    fn fill(&mut self, builder: &Builder, prims: &[u32], planes: &[Plane; 3]) {
        let bins = planes[0].bins;
        for axis in 0..3 {
            self.bounds[axis * MAX_BINS..][..bins].fill(FBox::EMPTY);
            self.counts[axis * MAX_BINS..][..bins].fill(0);
        }
        for &p in prims {
            let p = p as usize;
            let centroid = builder.centroids[p];
            let bounds = &builder.boxes[p];
            for plane in planes {
                let bin = plane.axis * MAX_BINS + plane.bin_of(centroid[plane.axis]);
                self.bounds[bin] = self.bounds[bin].union(bounds);
                self.counts[bin] += 1;
            }
        }
    }
}
