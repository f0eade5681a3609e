//! A bounding volume hierarchy: a tree of boxes over the primitives, built
//! top-down as a binary tree with the binned surface area heuristic, then
//! collapsed into an array of 256-byte nodes of up to eight children each,
//! whose boxes one SIMD slab test covers.
//!
//! - `node`: the wide node, the build's binary node, and the outward
//!   rounding of their `f32` boxes.
//! - `build`: the SAH build, parallel and deterministic, over `prims` (the
//!   primitives' indices and boxes, reordered together), `fbox` (the
//!   build's `f32` box), `bins` (the binned SAH of large nodes) and `sweep`
//!   (the exact SAH of small ones).
//! - `collapse`: binary to eight-wide.
//! - `traverse`: the two ray queries, with the argument that their `f32`
//!   slab test (`slabs`, and `slabs_avx` where the processor has AVX) is
//!   conservative; `counters.nodes` counts the nodes and leaves
//!   the walk enters, `counters.primitives` the primitive tests.
//! - `validate`: the invariants.

mod bins;
mod build;
mod collapse;
mod fbox;
mod node;
mod packet;
mod packet_any;
mod prims;
mod slabs;
#[cfg(target_arch = "x86_64")]
mod slabs_avx;
mod sweep;
mod traverse;
mod validate;

pub use build::{BvhBuildParams, SplitMethod};
pub use node::{BvhNode, WIDTH};
pub use packet::PACKET_LANES;
pub(crate) use slabs::{Halves, SlabTest};
#[cfg(target_arch = "x86_64")]
pub(crate) use slabs_avx::Avx as SlabsAvx;

use super::AccelStats;
use crate::math::Aabb;

/// The deepest a binary node may lie, and so a bound on the depth of the
/// wide tree and on the traversal stack. The build guarantees it for up to
/// 2³² primitives.
const MAX_DEPTH: usize = 64;

/// A bounding volume hierarchy over primitives `0..n`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Bvh {
    /// Root first (none without primitives).
    nodes: Vec<BvhNode>,
    /// Primitive indices, reordered so that each leaf's are contiguous.
    indices: Vec<u32>,
    /// Depth of the deepest leaf (0 when all lie in the root's slots).
    max_depth: usize,
}

impl Bvh {
    /// A BVH over primitives `0..boxes.len()` with these boxes, built with
    /// the default [`BvhBuildParams`].
    pub fn build(boxes: &[Aabb]) -> Self {
        Self::build_with(boxes, &BvhBuildParams::default())
    }

    /// A BVH over primitives `0..boxes.len()` (at most 2³¹), built with
    /// `params`. The result does not depend on the number of threads.
    pub fn build_with(boxes: &[Aabb], params: &BvhBuildParams) -> Self {
        let (nodes, indices, max_depth) = build::build(boxes, params);
        Self {
            nodes,
            indices,
            max_depth,
        }
    }

    /// The nodes, root first.
    pub fn nodes(&self) -> &[BvhNode] {
        &self.nodes
    }

    /// Boxes that hold every primitive between them: the children of the
    /// first levels of nodes, a whole level at a time, down to the deepest
    /// level with at most `limit` boxes (the root's children whatever
    /// `limit`; none for an empty tree). Leaves met on the way stay as they
    /// are.
    pub fn covering_boxes(&self, limit: usize) -> Vec<Aabb> {
        /// A used slot: its box, and its node when it is not a leaf.
        type Slot = (Aabb, Option<u32>);
        let slots = |node: &BvhNode| -> Vec<Slot> {
            (0..WIDTH)
                .filter(|&i| node.is_used(i))
                .map(|i| {
                    let inner = (node.counts[i] == 0).then_some(node.children[i]);
                    (node.child_bounds(i), inner)
                })
                .collect()
        };
        let Some(root) = self.nodes.first() else {
            return Vec::new();
        };
        let mut level = slots(root);
        while level.iter().any(|(_, inner)| inner.is_some()) {
            let next: Vec<Slot> = level
                .iter()
                .flat_map(|&(bounds, inner)| match inner {
                    Some(node) => slots(&self.nodes[node as usize]),
                    None => vec![(bounds, None)],
                })
                .collect();
            if next.len() > limit {
                break;
            }
            level = next;
        }
        level.into_iter().map(|(bounds, _)| bounds).collect()
    }

    /// The primitive indices the leaves point into.
    pub fn indices(&self) -> &[u32] {
        &self.indices
    }

    /// Size and quality. The SAH cost counts one step per wide node entered
    /// and one test per primitive, relative to the root's box.
    pub fn stats(&self) -> AccelStats {
        let slots = || {
            self.nodes
                .iter()
                .flat_map(|n| (0..WIDTH).filter(|&i| n.is_used(i)).map(move |i| (n, i)))
        };
        let root_area = self.nodes.first().map_or(0.0, |root| {
            (0..WIDTH)
                .filter(|&i| root.is_used(i))
                .fold(Aabb::EMPTY, |b, i| b.union(&root.child_bounds(i)))
                .surface_area()
        });
        let weighted_area: f64 = root_area
            + slots()
                .map(|(n, i)| n.child_bounds(i).surface_area() * f64::from(n.counts[i].max(1)))
                .sum::<f64>();
        AccelStats {
            nodes: self.nodes.len(),
            leaves: slots().filter(|&(n, i)| n.counts[i] > 0).count(),
            references: self.indices.len(),
            memory_bytes: size_of_val(self.nodes.as_slice()) + size_of_val(self.indices.as_slice()),
            sah_cost: if root_area > 0.0 && root_area.is_finite() {
                weighted_area / root_area
            } else {
                0.0
            },
            max_depth: self.max_depth,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::AccelKind;
    use crate::accel::conformance::assert_conforms;
    use crate::accel::conformance::random_boxes;
    use crate::math::Vec3;
    use crate::math::random::Rng;

    #[test]
    fn covering_boxes_hold_every_primitive_a_level_at_a_time() {
        let contains = |outer: &Aabb, inner: &Aabb| {
            outer.min.cmple(inner.min).all() && outer.max.cmpge(inner.max).all()
        };
        let mut rng = Rng::new(5);
        let boxes = random_boxes(&mut rng, 5000, 10.0, 0.5);
        let bvh = Bvh::build(&boxes);
        let root = bvh.covering_boxes(0);
        let used = (0..WIDTH).filter(|&i| bvh.nodes[0].is_used(i)).count();
        assert_eq!(root.len(), used);
        let mut previous = root.len();
        for limit in [64, 512, 4096, 100_000] {
            let covering = bvh.covering_boxes(limit);
            assert!(
                covering.len() <= limit && covering.len() >= previous,
                "{limit}"
            );
            previous = covering.len();
            for b in &boxes {
                assert!(covering.iter().any(|c| contains(c, b)), "{limit}: {b:?}");
            }
        }
        // Deep enough, the leaves' boxes: one per leaf slot.
        let leaves: usize = bvh
            .nodes
            .iter()
            .map(|n| n.counts.iter().filter(|&&c| c > 0).count())
            .sum();
        assert_eq!(bvh.covering_boxes(100_000).len(), leaves);
        assert!(Bvh::build(&[]).covering_boxes(8).is_empty());
    }

    fn assert_valid(name: &str, boxes: &[Aabb], params: &BvhBuildParams) -> Bvh {
        let bvh = Bvh::build_with(boxes, params);
        if let Err(why) = bvh.validate(boxes) {
            panic!("{name}: {why}");
        }
        bvh
    }

    #[test]
    fn bvh_conforms_to_brute_force() {
        assert_conforms(AccelKind::Bvh);
    }

    #[test]
    fn builds_are_valid_for_random_inputs_of_many_sizes() {
        for n in [0, 1, 2, 3, 7, 8, 9, 100, 1000, 20_000] {
            for params in [BvhBuildParams::default(), BvhBuildParams::fastest_build()] {
                let bvh = assert_valid(
                    &format!("{n} boxes"),
                    &random_boxes(&mut Rng::new(n as u64), n, 100.0, 2.0),
                    &params,
                );
                assert_eq!(bvh.stats().references, n);
            }
        }
    }

    #[test]
    fn builds_are_valid_for_degenerate_inputs() {
        let unit = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let mut rng = Rng::new(3);
        let mut point = || {
            let p = rng.point_in(Vec3::splat(-1.0), Vec3::ONE);
            Aabb::new(p, p)
        };
        let points: Vec<Aabb> = (0..500).map(|_| point()).collect();
        let flat: Vec<Aabb> = points
            .iter()
            .map(|b| Aabb::new(b.min * Vec3::new(1.0, 1.0, 0.0), b.max + Vec3::X))
            .collect();
        let cases: Vec<(&str, Vec<Aabb>)> = vec![
            ("identical boxes", vec![unit; 1000]),
            (
                "nested boxes with one centroid",
                (1..=300).map(|i| unit.expanded(f64::from(i))).collect(),
            ),
            (
                "one point many times",
                vec![Aabb::new(Vec3::ONE, Vec3::ONE); 300],
            ),
            ("scattered points", points),
            ("flat boxes in one plane", flat),
            (
                "empty boxes among others",
                vec![Aabb::EMPTY, unit, Aabb::EMPTY],
            ),
            (
                "beyond the f32 range",
                vec![Aabb::new(Vec3::splat(-1e300), Vec3::splat(1e300)), unit],
            ),
        ];
        for (name, boxes) in &cases {
            assert_valid(name, boxes, &BvhBuildParams::default());
            assert_valid(name, boxes, &BvhBuildParams::fastest_build());
        }
    }

    #[test]
    fn geometric_spacing_stays_within_the_traversal_stack() {
        // Every centroid but the last falls in the first bin, so each SAH
        // split peels off one box: the tree would be as deep as it is long
        // without the fall-back to medians (collapsing to nodes of `WIDTH`
        // children takes about `1 / (WIDTH − 1)` of that depth). The boxes stay within the
        // `f32` range the build bins in (beyond it every box is infinite and
        // the SAH has nothing to compare).
        let boxes: Vec<Aabb> = (0..55)
            .map(|i| {
                let p = Vec3::new(17f64.powi(i) * 1e-30, 0.0, 0.0);
                Aabb::new(p, p + Vec3::splat(1e-30))
            })
            .collect();
        let bvh = assert_valid("geometric spacing", &boxes, &BvhBuildParams::default());
        assert!(bvh.stats().max_depth <= MAX_DEPTH);
        assert!(
            bvh.stats().max_depth >= 32 / (WIDTH - 1),
            "the test should come near the limit: depth {}",
            bvh.stats().max_depth
        );
    }

    #[test]
    fn same_tree_whatever_the_thread_count() {
        let boxes = random_boxes(&mut Rng::new(11), 20_000, 100.0, 2.0);
        let reference = Bvh::build(&boxes);
        assert_eq!(Bvh::build(&boxes), reference);
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            assert_eq!(pool.install(|| Bvh::build(&boxes)), reference);
        }
        let eager = BvhBuildParams {
            parallel_threshold: 2,
            ..BvhBuildParams::default()
        };
        let sequential = BvhBuildParams {
            parallel_threshold: usize::MAX,
            ..BvhBuildParams::default()
        };
        assert_eq!(Bvh::build_with(&boxes, &eager), reference);
        assert_eq!(Bvh::build_with(&boxes, &sequential), reference);
    }

    #[test]
    fn sah_beats_object_median_on_clustered_input() {
        // Dense clusters of very different sizes with sparse boxes between.
        let mut rng = Rng::new(17);
        let mut boxes = Vec::new();
        for (count, centre) in [(3000, -80.0), (300, 0.0), (30, 60.0)] {
            for _ in 0..count {
                let c = Vec3::splat(centre) + rng.point_in(Vec3::splat(-1.0), Vec3::ONE);
                boxes.push(Aabb::new(c, c + Vec3::splat(0.05)));
            }
        }
        boxes.extend(random_boxes(&mut Rng::new(18), 200, 100.0, 2.0));
        let sah = Bvh::build(&boxes).stats().sah_cost;
        let median = Bvh::build_with(&boxes, &BvhBuildParams::fastest_build())
            .stats()
            .sah_cost;
        assert!(sah < 0.8 * median, "SAH {sah}, median {median}");
    }

    #[test]
    fn stats_of_two_separate_boxes() {
        let a = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let b = Aabb::new(Vec3::splat(9.0), Vec3::splat(10.0));
        let stats = Bvh::build(&[a, b]).stats();
        let root = a.union(&b).surface_area();
        assert_eq!(stats.nodes, 1);
        assert_eq!(stats.leaves, 2);
        assert_eq!(stats.references, 2);
        assert_eq!(stats.memory_bytes, size_of::<BvhNode>() + 2 * 4);
        assert_eq!(stats.max_depth, 0);
        let expected = 1.0 + (a.surface_area() + b.surface_area()) / root;
        assert!((stats.sah_cost - expected).abs() < 1e-12);
        assert_eq!(Bvh::build(&[]).stats(), AccelStats::default());
    }
}
