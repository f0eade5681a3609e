//! The SAH build in O(N log N) (Wald and Havran, "On building fast kd-trees
//! for ray tracing, and on doing that in O(N log N)", 2006, section 4.3).
//!
//! The events of all boxes are sorted once. At each node one sweep per axis
//! finds the cheapest plane ([`best_split`]); the primitives are classified
//! below, above or both against it, and each axis's list is split into the
//! children's lists by one pass that keeps its order. Only the primitives
//! on both sides need new events (their boxes clipped to each child's
//! cell, or with perfect splits the boxes of their parts inside each
//! cell): those few are sorted and merged in. A node becomes a leaf when no
//! plane is cheaper than testing its primitives, or at the depth limit that
//! stops degenerate input (identical boxes, one box around everything).

use super::events::{Event, EventKind, EventLists, merge, push_events, snap_outward, sort_events};
use super::node::{KdNode, MAX_FIELD, MAX_NODE};
use super::sah::{Costs, Split, best_split};
use super::traverse::STACK_CAPACITY;
use super::{Clipper, KdTree, KdTreeBuildParams, split_cell};
use crate::math::Aabb;

/// Work done by a build, to check its complexity without timing it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct BuildCounters {
    /// Events visited by the sweeps, summed over nodes.
    pub(super) events_swept: usize,
    /// Events passed to a sort: the initial lists and the straddling
    /// primitives' new events.
    pub(super) events_sorted: usize,
}

/// Where a primitive goes at a split.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Side {
    Below,
    Above,
    Both,
}

/// A child about to be built.
struct Child {
    cell: Aabb,
    events: EventLists,
    count: usize,
}

/// The depth limit used when none is given: 4 + 1.3 log2 N (pbrt's rule
/// is 8 + 1.3 log2 N; see the module doc of `kdtree` for why 4), within
/// the traversal stack.
pub(super) fn default_max_depth(count: usize) -> usize {
    let log = (count.max(1) as f64).log2();
    (4 + (1.3 * log).round() as usize).min(STACK_CAPACITY)
}

/// The box primitive `i` with box `b` has in the tree, widened to the `f32`
/// grid, or `None` when it is kept aside.
pub(super) fn placed_box(i: usize, b: &Aabb) -> Option<Aabb> {
    snap_outward(b).filter(|_| i < MAX_FIELD as usize)
}

/// The box of the part of primitive `p` (with box `b`) inside `cell`:
/// `b` ∩ `cell`, or with `clip` the clipped bounds widened to the `f32`
/// grid, ∩ `b` ∩ `cell`. `None` when it does not meet the cell.
pub(super) fn bounds_in(p: u32, b: &Aabb, cell: &Aabb, clip: Option<Clipper>) -> Option<Aabb> {
    let within = b.intersection(cell)?;
    match clip {
        Some(clip) => snap_outward(&clip(p, cell)?)?.intersection(&within),
        None => Some(within),
    }
}

/// Builds the tree over `boxes` and reports the work done.
pub(super) fn build(
    boxes: &[Aabb],
    params: &KdTreeBuildParams,
    clip: Option<Clipper>,
) -> (KdTree, BuildCounters) {
    let mut snapped = Vec::with_capacity(boxes.len());
    let mut loose = Vec::new();
    let mut events = EventLists::default();
    let mut bounds = Aabb::EMPTY;
    for (i, b) in boxes.iter().enumerate() {
        let placed = placed_box(i, b);
        match placed {
            Some(s) => {
                push_events(&s, i as u32, &mut events);
                bounds = bounds.union(&s);
            }
            None => loose.push((i as u32, *b)),
        }
        snapped.push(placed.unwrap_or(Aabb::EMPTY));
    }
    events.iter_mut().for_each(|l| sort_events(l));
    let count = boxes.len() - loose.len();
    let mut builder = Builder {
        clip,
        sides: vec![Side::Both; boxes.len()],
        boxes: snapped,
        costs: Costs {
            traversal: params.traversal_cost,
            intersection: params.intersection_cost,
            empty_factor: params.empty_factor,
        },
        max_depth: params
            .max_depth
            .unwrap_or_else(|| default_max_depth(count))
            .min(STACK_CAPACITY),
        deepest: 0,
        nodes: Vec::new(),
        indices: Vec::new(),
        counters: BuildCounters {
            events_swept: 0,
            events_sorted: events.iter().map(Vec::len).sum(),
        },
    };
    builder.node(bounds, events, count, 0);
    let mut indices = builder.indices;
    indices.extend(loose.iter().map(|&(i, _)| i));
    let tree = KdTree {
        nodes: builder.nodes,
        indices,
        bounds,
        loose,
        max_depth: builder.deepest,
    };
    (tree, builder.counters)
}

struct Builder<'c> {
    /// Clips straddling primitives to the children's cells, if given.
    clip: Option<Clipper<'c>>,
    /// Every primitive's box widened to the `f32` grid (empty for loose
    /// ones).
    boxes: Vec<Aabb>,
    /// Scratch: each primitive's side at the split being made.
    sides: Vec<Side>,
    costs: Costs,
    max_depth: usize,
    /// The depth of the deepest leaf built so far.
    deepest: usize,
    nodes: Vec<KdNode>,
    indices: Vec<u32>,
    counters: BuildCounters,
}

impl Builder<'_> {
    /// Builds the subtree of `cell`, holding `count` primitives with these
    /// events, at index `self.nodes.len()`.
    fn node(&mut self, cell: Aabb, events: EventLists, count: usize, depth: usize) {
        // Room for this node, its children and the above children still
        // pending on the path, so every index fits a node's field.
        let room = self.nodes.len() + 2 + STACK_CAPACITY <= MAX_NODE as usize;
        let split = if count > 0 && depth < self.max_depth && room {
            self.counters.events_swept += events.iter().map(Vec::len).sum::<usize>();
            best_split(&cell, &events, count, &self.costs)
        } else {
            None
        };
        let Some(split) = split else {
            self.deepest = self.deepest.max(depth);
            self.leaf(&events[0]);
            return;
        };
        let index = self.nodes.len();
        self.nodes.push(KdNode::leaf(0, 0));
        let [below, above] = self.partition(&cell, &split, events);
        // A child without primitives is not stored (see `node.rs`).
        let has_below = below.count > 0;
        if has_below {
            self.node(below.cell, below.events, below.count, depth + 1);
        }
        let above_index = if above.count > 0 {
            let above_index = self.nodes.len() as u32;
            self.node(above.cell, above.events, above.count, depth + 1);
            above_index
        } else {
            0
        };
        let plane = split.position as f32;
        self.nodes[index] = KdNode::interior(split.axis, plane, has_below, above_index);
    }

    /// A leaf holding the primitives that have events in `events`.
    fn leaf(&mut self, events: &[Event]) {
        let offset = self.indices.len();
        let primitives = events.iter().filter(|e| e.kind != EventKind::End);
        self.indices.extend(primitives.map(|e| e.primitive));
        let count = self.indices.len() - offset;
        self.nodes.push(KdNode::leaf(offset as u32, count as u32));
    }

    /// Splits `cell` and its events at `split`. A box that straddles the
    /// plane goes to each side its primitive meets (both, without a
    /// clipper), one that touches it to the side it lies
    /// on, and one lying flat in it to the side the split chose. The plane
    /// is exactly the stored `f32` and the boxes are widened to the `f32`
    /// grid, so each box is inside the closed cells it is given to.
    fn partition(&mut self, cell: &Aabb, split: &Split, events: EventLists) -> [Child; 2] {
        let (axis, plane) = (split.axis, split.position);
        let mut straddling = Vec::new();
        for e in &events[axis] {
            let side = &mut self.sides[e.primitive as usize];
            match e.kind {
                EventKind::Start if e.position >= plane => *side = Side::Above,
                EventKind::Start => *side = Side::Both,
                EventKind::End if *side != Side::Both => {}
                EventKind::End if e.position <= plane => *side = Side::Below,
                EventKind::End => straddling.push(e.primitive),
                EventKind::Planar => {
                    let below = e.position < plane || (e.position == plane && split.planar_below);
                    *side = if below { Side::Below } else { Side::Above };
                }
            }
        }

        let [below_cell, above_cell] = split_cell(cell, axis, plane);

        let mut below = EventLists::default();
        let mut above = EventLists::default();
        for (list, (b, a)) in events.into_iter().zip(below.iter_mut().zip(&mut above)) {
            for e in list {
                match self.sides[e.primitive as usize] {
                    Side::Below => b.push(e),
                    Side::Above => a.push(e),
                    Side::Both => {}
                }
            }
        }
        let primitives = |l: &EventLists| l[0].iter().filter(|e| e.kind != EventKind::End).count();
        let (below_count, above_count) = (primitives(&below), primitives(&above));

        let mut new_below = EventLists::default();
        let mut new_above = EventLists::default();
        let (mut straddling_below, mut straddling_above) = (0, 0);
        for &p in &straddling {
            let b = self.boxes[p as usize];
            if let Some(c) = bounds_in(p, &b, &below_cell, self.clip) {
                push_events(&c, p, &mut new_below);
                straddling_below += 1;
            }
            if let Some(c) = bounds_in(p, &b, &above_cell, self.clip) {
                push_events(&c, p, &mut new_above);
                straddling_above += 1;
            }
        }
        for list in new_below.iter_mut().chain(&mut new_above) {
            sort_events(list);
            self.counters.events_sorted += list.len();
        }
        let merged = |old: EventLists, new: EventLists| {
            let [a, b, c] = old;
            let [x, y, z] = new;
            [merge(a, x), merge(b, y), merge(c, z)]
        };
        [
            Child {
                cell: below_cell,
                events: merged(below, new_below),
                count: below_count + straddling_below,
            },
            Child {
                cell: above_cell,
                events: merged(above, new_above),
                count: above_count + straddling_above,
            },
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::conformance::random_boxes;
    use crate::math::Vec3;
    use crate::math::random::Rng;

    #[test]
    fn work_grows_like_n_log_n_and_events_are_sorted_about_once() {
        let params = KdTreeBuildParams::default();
        let (_, small) = build(
            &random_boxes(&mut Rng::new(1), 2_000, 100.0, 2.0),
            &params,
            None,
        );
        let (tree, large) = build(
            &random_boxes(&mut Rng::new(1), 8_000, 100.0, 2.0),
            &params,
            None,
        );
        // N log N predicts a ratio of about 4.6 for 4x the boxes; N² gives 16.
        let ratio = large.events_swept as f64 / small.events_swept as f64;
        assert!(ratio > 3.0 && ratio < 6.0, "swept events grew {ratio}x");
        // Sorting the 6N initial events dominates: the straddlers' re-sorts
        // are a small fraction, not a sort per node.
        let initial = 6 * 8_000;
        assert!(large.events_sorted < initial + initial / 2, "{large:?}");
        assert!(large.events_swept > 10 * large.events_sorted, "{large:?}");
        assert!(
            tree.validate(&random_boxes(&mut Rng::new(1), 8_000, 100.0, 2.0))
                .is_ok()
        );
    }

    #[test]
    fn the_depth_limit_is_within_the_stack_for_any_count() {
        assert_eq!(default_max_depth(0), 4);
        assert_eq!(default_max_depth(1 << 20), 30);
        assert!(default_max_depth(usize::MAX) <= STACK_CAPACITY);
    }

    #[test]
    fn straddling_boxes_are_clipped_to_each_child() {
        // A long bar across many small cubes: it is in many leaves, and
        // each copy's events lie inside that child's cell.
        let mut boxes: Vec<Aabb> = (0..64)
            .map(|i| {
                let x = f64::from(i) * 3.0;
                Aabb::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 1.0, 1.0))
            })
            .collect();
        boxes.push(Aabb::new(
            Vec3::new(-1.0, 0.25, 0.25),
            Vec3::new(200.0, 0.75, 0.75),
        ));
        let (tree, _) = build(&boxes, &KdTreeBuildParams::default(), None);
        assert!(tree.validate(&boxes).is_ok());
        let bar_copies = tree.indices.iter().filter(|&&p| p == 64).count();
        assert!(bar_copies > 8, "the bar is in {bar_copies} leaves");
    }
}
