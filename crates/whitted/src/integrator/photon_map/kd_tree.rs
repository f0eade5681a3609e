//! A balanced kd-tree over points, stored implicitly: the k nearest points
//! to a query within a maximum distance.
//!
//! The items are reordered once so that every range `lo..hi` of the array
//! is a subtree whose root is its middle item `mid = (lo + hi) / 2`, split
//! on the axis kept for it in `axes[mid]`; its left subtree is `lo..mid`,
//! its right `mid + 1..hi`. Building is a median selection per level on
//! the axis of largest extent (O(N log N), the two halves in parallel for
//! large ranges), so the tree is balanced by construction and needs no
//! pointers: one byte per item beside the items themselves. This is
//! Jensen's balanced photon map without its heap-order renumbering: the
//! middle-of-range layout gives the same depth, ⌈log₂(N + 1)⌉.

use std::cmp::Ordering;

use crate::math::{Aabb, Vec3};

/// Ranges at least this large build their two halves in parallel.
const PARALLEL_BUILD: usize = 1 << 14;

/// Something with a position, that a [`KdTree`] can hold.
pub trait Located {
    /// Where it is.
    fn position(&self) -> Vec3;
}

/// A balanced kd-tree over items with positions (see the module docs).
#[derive(Clone, Debug, Default)]
pub struct KdTree<T> {
    items: Vec<T>,
    axes: Vec<u8>,
}

/// One neighbour found: its squared distance and its index in
/// [`KdTree::items`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Neighbour {
    /// Squared distance from the query point.
    pub distance_squared: f64,
    /// Index into [`KdTree::items`].
    pub index: u32,
}

impl Eq for Neighbour {}

impl PartialOrd for Neighbour {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Neighbour {
    /// Farther first (the heap's top), ties broken by index so that the
    /// set kept never depends on the order of discovery.
    fn cmp(&self, other: &Self) -> Ordering {
        self.distance_squared
            .total_cmp(&other.distance_squared)
            .then(self.index.cmp(&other.index))
    }
}

/// The k nearest items found so far, farthest on top: reused from one
/// query to the next so that a query allocates nothing.
#[derive(Clone, Debug, Default)]
pub struct Neighbours {
    heap: std::collections::BinaryHeap<Neighbour>,
}

impl Neighbours {
    /// The neighbours found, in no particular order.
    pub fn as_slice(&self) -> &[Neighbour] {
        self.heap.as_slice()
    }

    /// How many were found.
    pub fn len(&self) -> usize {
        self.heap.len()
    }

    /// True when none were.
    pub fn is_empty(&self) -> bool {
        self.heap.is_empty()
    }

    /// The squared distance of the farthest one kept, if any.
    pub fn farthest_squared(&self) -> Option<f64> {
        self.heap.peek().map(|n| n.distance_squared)
    }
}

impl<T: Located + Send> KdTree<T> {
    /// Builds the tree over `items` (reordering them).
    pub fn build(mut items: Vec<T>) -> Self {
        let mut axes = vec![0u8; items.len()];
        build_range(&mut items, &mut axes);
        Self { items, axes }
    }
}

impl<T: Located> KdTree<T> {
    /// The items, in the tree's order.
    pub fn items(&self) -> &[T] {
        &self.items
    }

    /// Finds the (at most) `k` items nearest to `point` whose squared
    /// distance is below `max_distance_squared` and that `accept` takes,
    /// into `found` (emptied first). Of items at equal distances the lower
    /// index is kept.
    pub fn nearest(
        &self,
        point: Vec3,
        k: usize,
        max_distance_squared: f64,
        accept: impl Fn(&T) -> bool,
        found: &mut Neighbours,
    ) {
        found.heap.clear();
        if k == 0 {
            return;
        }
        let mut query = Query {
            point,
            k,
            max_distance_squared,
            accept,
            found,
        };
        self.visit(0, self.items.len(), &mut query);
    }

    fn visit<F: Fn(&T) -> bool>(&self, lo: usize, hi: usize, query: &mut Query<'_, F>) {
        if lo >= hi {
            return;
        }
        let mid = (lo + hi) / 2;
        let item = &self.items[mid];
        let axis = usize::from(self.axes[mid]);
        let delta = query.point[axis] - item.position()[axis];
        let (near, far) = if delta < 0.0 {
            ((lo, mid), (mid + 1, hi))
        } else {
            ((mid + 1, hi), (lo, mid))
        };
        self.visit(near.0, near.1, query);
        let distance_squared = (item.position() - query.point).length_squared();
        if distance_squared <= query.reach() && (query.accept)(item) {
            query.offer(Neighbour {
                distance_squared,
                index: mid as u32,
            });
        }
        if delta * delta <= query.reach() {
            self.visit(far.0, far.1, query);
        }
    }
}

/// The state of one nearest-neighbour search.
struct Query<'n, F> {
    point: Vec3,
    k: usize,
    max_distance_squared: f64,
    accept: F,
    found: &'n mut Neighbours,
}

impl<F> Query<'_, F> {
    /// The squared distance within which a new item could still be kept
    /// (at it, only one of a lower index than the farthest kept).
    fn reach(&self) -> f64 {
        if self.found.heap.len() < self.k {
            self.max_distance_squared
        } else {
            self.found
                .farthest_squared()
                .unwrap_or(self.max_distance_squared)
        }
    }

    fn offer(&mut self, neighbour: Neighbour) {
        let heap = &mut self.found.heap;
        if neighbour.distance_squared >= self.max_distance_squared {
            return;
        }
        if heap.len() < self.k {
            heap.push(neighbour);
        } else if heap.peek().is_some_and(|top| neighbour < *top) {
            heap.pop();
            heap.push(neighbour);
        }
    }
}

/// Arranges `items` (and fills `axes`) as the subtree of one range.
fn build_range<T: Located + Send>(items: &mut [T], axes: &mut [u8]) {
    if items.len() <= 1 {
        return;
    }
    let bounds = items
        .iter()
        .fold(Aabb::EMPTY, |b, item| b.union_point(item.position()));
    let axis = bounds.extent().max_position();
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |a, b| {
        a.position()[axis].total_cmp(&b.position()[axis])
    });
    axes[mid] = axis as u8;
    let (left, rest) = items.split_at_mut(mid);
    let right = &mut rest[1..];
    let (left_axes, rest_axes) = axes.split_at_mut(mid);
    let right_axes = &mut rest_axes[1..];
    if left.len() + right.len() >= PARALLEL_BUILD {
        rayon::join(
            || build_range(left, left_axes),
            || build_range(right, right_axes),
        );
    } else {
        build_range(left, left_axes);
        build_range(right, right_axes);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::random::Rng;

    #[derive(Clone, Copy, Debug, PartialEq)]
    struct Point(Vec3, u32);

    impl Located for Point {
        fn position(&self) -> Vec3 {
            self.0
        }
    }

    /// The k nearest by sorting every point, the lower index first among
    /// equal distances: the oracle.
    fn brute_force(points: &[Point], p: Vec3, k: usize, max: f64, odd_only: bool) -> Vec<u32> {
        let mut all: Vec<(f64, u32)> = points
            .iter()
            .enumerate()
            .filter(|(_, q)| !odd_only || q.1 % 2 == 1)
            .map(|(i, q)| ((q.0 - p).length_squared(), i as u32))
            .filter(|&(d, _)| d < max)
            .collect();
        all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut ids: Vec<u32> = all.into_iter().take(k).map(|(_, id)| id).collect();
        ids.sort_unstable();
        ids
    }

    fn clouds(rng: &mut Rng) -> Vec<Vec<Point>> {
        let uniform: Vec<Point> = (0..3000)
            .map(|i| Point(rng.point_in(Vec3::splat(-1.0), Vec3::splat(1.0)), i))
            .collect();
        // Points on a plane, duplicates, and a tight cluster: the cases a
        // caustic map has.
        let flat: Vec<Point> = (0..2000)
            .map(|i| {
                let q = rng.point_in(Vec3::splat(-1.0), Vec3::splat(1.0));
                let q = if i % 7 == 0 {
                    Vec3::new(0.25, 0.0, 0.25)
                } else if i % 3 == 0 {
                    q * 1e-3
                } else {
                    q
                };
                Point(Vec3::new(q.x, 0.0, q.z), i)
            })
            .collect();
        vec![uniform, flat, Vec::new(), vec![Point(Vec3::ZERO, 0)]]
    }

    #[test]
    fn nearest_matches_brute_force_on_random_clouds() {
        let mut rng = Rng::new(1);
        let mut found = Neighbours::default();
        for points in clouds(&mut rng) {
            let tree = KdTree::build(points.clone());
            assert_eq!(tree.items().len(), points.len());
            for _ in 0..300 {
                let p = rng.point_in(Vec3::splat(-1.2), Vec3::splat(1.2));
                let p = if rng.uniform() < 0.3 {
                    Vec3::new(p.x, 0.0, p.z)
                } else {
                    p
                };
                let k = 1 + rng.below(60) as usize;
                let max = if rng.uniform() < 0.5 {
                    f64::INFINITY
                } else {
                    rng.range(0.0, 0.3)
                };
                let odd_only = rng.uniform() < 0.3;
                tree.nearest(p, k, max, |q| !odd_only || q.1 % 2 == 1, &mut found);
                let mut ids: Vec<u32> = found.as_slice().iter().map(|n| n.index).collect();
                ids.sort_unstable();
                assert_eq!(ids, brute_force(tree.items(), p, k, max, odd_only));
            }
        }
    }

    #[test]
    fn the_tree_is_balanced_and_split_at_medians() {
        let mut rng = Rng::new(2);
        let points: Vec<Point> = (0..40_000)
            .map(|i| Point(rng.point_in(Vec3::ZERO, Vec3::new(4.0, 1.0, 2.0)), i))
            .collect();
        let tree = KdTree::build(points);
        // Every item of a left subtree is at most its root's coordinate on
        // the root's axis, every item of a right one at least.
        fn check(tree: &KdTree<Point>, lo: usize, hi: usize, depth: u32) -> u32 {
            if lo >= hi {
                return depth;
            }
            let mid = (lo + hi) / 2;
            let axis = usize::from(tree.axes[mid]);
            let split = tree.items[mid].0[axis];
            assert!(tree.items[lo..mid].iter().all(|p| p.0[axis] <= split));
            assert!(tree.items[mid + 1..hi].iter().all(|p| p.0[axis] >= split));
            check(tree, lo, mid, depth + 1).max(check(tree, mid + 1, hi, depth + 1))
        }
        let depth = check(&tree, 0, tree.items.len(), 0);
        assert_eq!(depth, 16); // ⌈log₂(40001)⌉
        // The root splits the longest side.
        assert_eq!(tree.axes[tree.items.len() / 2], 0);
    }
}
