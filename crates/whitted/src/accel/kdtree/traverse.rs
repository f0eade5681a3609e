//! Ray traversal: the ray is clipped to the root box, then walks the leaves
//! it passes from near to far with a fixed-size to-do stack of
//! `(node, t_min, t_max)` (pbrt-v4 `KdTreeAggregate::Intersect`). Among
//! rays the caller says are incoherent ([`crate::accel::RayCoherence`]),
//! one starting inside the tree first goes straight down to its origin's
//! leaf, pushing the cells it passes by on the same stack
//! ([`KdTree::descend`]).
//!
//! Every choice is conservative. The parameter where the ray crosses a
//! split plane is widened by its rounding error, and both children are
//! visited whenever the crossing lies within the node's range (also at its
//! very ends), or cannot be computed because the ray lies in the plane.
//!
//! A hit beyond the current cell is not final: a cell farther on is skipped
//! only when it starts beyond the closest hit found so far. That is the
//! usual "stop when the hit is within the cell" test, but it also holds
//! when a ray lying in a split plane visits both children over the same
//! range.
//!
//! A primitive lies in every leaf its box overlaps, so a ray meets it
//! again leaf after leaf: the shared mailbox (`accel/mailbox.rs`) tests it
//! once per ray, which saves primitive tests and instructions (figures in
//! docs/performance-log.md, kd-tree walk). The queries in leaf order (closest
//! and any hit) go without it and hand over whole leaves (see `mod.rs`): a
//! repeated test finds nothing new, and the caller takes a leaf in one
//! call, testing an any-hit ray against its triangles several at a time.

use super::KdTree;
use super::node::NodeKind;
use crate::accel::mailbox::Mailbox;
use crate::accel::stack::Stack;
use crate::accel::{QueryContext, RayCoherence, TraversalCounters};
use crate::math::{Ray, gamma};
use std::ops::Range;

/// Entries of the largest to-do stack: one per level at most, so this
/// bounds the tree's depth.
pub(super) const STACK_CAPACITY: usize = 64;

/// Trees at most this deep walk with a stack of this many entries.
pub(super) const SHALLOW: usize = 32;

/// A node to visit over a parameter range.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Entry {
    node: u32,
    t_min: f64,
    t_max: f64,
}

/// What to do after a leaf.
enum Flow {
    /// Go on; skip cells starting beyond this parameter.
    Continue(f64),
    /// Done.
    Stop,
}

impl KdTree {
    /// The closest hit (see [`crate::accel`]). A primitive met again in a
    /// later leaf is not tested again (the shared mailbox).
    #[inline]
    pub fn intersect(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        mut hit: impl FnMut(u32, f64) -> Option<f64>,
    ) -> Option<f64> {
        let coherence = ctx.coherence;
        let counters = &mut ctx.counters;
        let mut mailbox = Mailbox::new();
        self.closest_leaf(ray, coherence, counters, |entries, mut t_max, counters| {
            let mut found = None;
            for p in entries.map(|entry| self.indices[entry]) {
                if !mailbox.first_visit(p) {
                    continue;
                }
                counters.primitives += 1;
                if let Some(t) = hit(p, t_max) {
                    (t_max, found) = (t, Some(t));
                }
            }
            found
        })
    }

    /// [`Self::intersect`], with `hit` given a whole leaf: the positions in
    /// [`Self::indices`] of its primitives, and the closest hit so far; it
    /// returns the closest hit among them nearer than that. A caller that
    /// keeps what it needs of the primitives in that order reads each
    /// leaf's together. Each primitive kept aside comes as a leaf of its
    /// own. There is no mailbox, as for [`Self::occluded_in_leaf_order`]: a
    /// primitive met again is tested again, and cannot be nearer than the
    /// hit it gave before. The leaf counts as tested whole in
    /// `counters.primitives`.
    #[inline]
    pub fn intersect_in_leaf_order(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        mut hit: impl FnMut(Range<u32>, f64) -> Option<f64>,
    ) -> Option<f64> {
        let coherence = ctx.coherence;
        let counters = &mut ctx.counters;
        self.closest_leaf(ray, coherence, counters, |entries, t_max, counters| {
            counters.primitives += entries.len() as u64;
            hit(entries.start as u32..entries.end as u32, t_max)
        })
    }

    /// The closest of the hits `leaf` returns for the positions in
    /// [`Self::indices`] of every leaf the ray passes, near to far until no
    /// nearer hit can follow, and of every primitive kept aside whose box
    /// it meets (each one alone, tested first). `leaf` is given the closest
    /// hit so far and returns a nearer one, if any.
    #[inline(always)]
    fn closest_leaf(
        &self,
        ray: &Ray,
        coherence: RayCoherence,
        counters: &mut TraversalCounters,
        mut leaf: impl FnMut(Range<usize>, f64, &mut TraversalCounters) -> Option<f64>,
    ) -> Option<f64> {
        let mut closest = None;
        let mut clipped = *ray;
        let first_loose = self.indices.len() - self.loose.len();
        for (k, (_, b)) in self.loose.iter().enumerate() {
            counters.nodes += 1;
            let entry = first_loose + k;
            if b.intersect_ray(&clipped).is_some()
                && let Some(t) = leaf(entry..entry + 1, clipped.t_max, counters)
            {
                (clipped.t_max, closest) = (t, Some(t));
            }
        }
        let mut t_max = clipped.t_max;
        self.walk(&clipped, coherence, counters, |entries, counters| {
            if let Some(t) = leaf(entries, t_max, counters) {
                (t_max, closest) = (t, Some(t));
            }
            Flow::Continue(t_max)
        });
        closest
    }

    /// Any hit (see [`crate::accel`]). A primitive met again in a later
    /// leaf is not tested again (the shared mailbox).
    #[inline]
    pub fn occluded(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        mut occludes: impl FnMut(u32) -> bool,
    ) -> bool {
        let coherence = ctx.coherence;
        let counters = &mut ctx.counters;
        let mut mailbox = Mailbox::new();
        self.any_leaf(ray, coherence, counters, |entries, counters| {
            entries.map(|entry| self.indices[entry]).any(|p| {
                if !mailbox.first_visit(p) {
                    return false;
                }
                counters.primitives += 1;
                occludes(p)
            })
        })
    }

    /// [`Self::occluded`], with `occludes` given a whole leaf: the
    /// positions in [`Self::indices`] of its primitives (see
    /// [`Self::intersect_in_leaf_order`]); it says whether any of them lies
    /// in the ray's interval. Each primitive kept aside comes as a leaf of
    /// its own. There is no mailbox: a primitive met again is tested again
    /// (with the same answer), which lets the caller test a leaf's
    /// triangles several at a time. The leaf counts as tested whole in
    /// `counters.primitives`, however early the caller stops.
    #[inline]
    pub fn occluded_in_leaf_order(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        mut occludes: impl FnMut(Range<u32>) -> bool,
    ) -> bool {
        let coherence = ctx.coherence;
        let counters = &mut ctx.counters;
        self.any_leaf(ray, coherence, counters, |entries, counters| {
            counters.primitives += entries.len() as u64;
            occludes(entries.start as u32..entries.end as u32)
        })
    }

    /// Whether `leaf` says yes for the positions in [`Self::indices`] of
    /// some leaf the ray passes, or of some primitive kept aside whose box
    /// it meets (each one alone, tested first).
    #[inline(always)]
    fn any_leaf(
        &self,
        ray: &Ray,
        coherence: RayCoherence,
        counters: &mut TraversalCounters,
        mut leaf: impl FnMut(Range<usize>, &mut TraversalCounters) -> bool,
    ) -> bool {
        let first_loose = self.indices.len() - self.loose.len();
        for (k, (_, b)) in self.loose.iter().enumerate() {
            counters.nodes += 1;
            let entry = first_loose + k;
            if b.intersect_ray(ray).is_some() && leaf(entry..entry + 1, counters) {
                return true;
            }
        }
        let mut found = false;
        self.walk(ray, coherence, counters, |entries, counters| {
            if leaf(entries, counters) {
                found = true;
                Flow::Stop
            } else {
                Flow::Continue(ray.t_max)
            }
        });
        found
    }

    /// Calls `leaf` with the positions in [`Self::indices`] of the
    /// primitives of every leaf the ray passes, near to far, until it says
    /// stop; with the smallest stack that holds this tree's depth.
    #[inline]
    fn walk(
        &self,
        ray: &Ray,
        coherence: RayCoherence,
        counters: &mut TraversalCounters,
        leaf: impl FnMut(Range<usize>, &mut TraversalCounters) -> Flow,
    ) {
        if self.max_depth <= SHALLOW {
            self.walk_with::<SHALLOW>(ray, coherence, counters, leaf);
        } else {
            self.walk_with::<STACK_CAPACITY>(ray, coherence, counters, leaf);
        }
    }

    /// [`Self::walk`] with a stack of `N` entries, at least the tree's
    /// depth.
    ///
    /// Not kept (figures in docs/performance-log.md, kd-tree walk):
    /// - Tried prefetching a node's above child, or the far child: slower.
    /// - Tried loading both children before the branches: no faster.
    #[inline(always)]
    fn walk_with<const N: usize>(
        &self,
        ray: &Ray,
        coherence: RayCoherence,
        counters: &mut TraversalCounters,
        mut leaf: impl FnMut(Range<usize>, &mut TraversalCounters) -> Flow,
    ) {
        if self.bounds.is_empty() {
            return;
        }
        let Some((t_min, t_max)) = self.bounds.intersect_ray(ray) else {
            return;
        };
        let mut horizon = ray.t_max;
        let axes = Axes::new(ray);
        let mut work = TraversalCounters::default();
        let mut stack = Stack::<Entry, N>::new();
        let mut entry = Entry {
            node: 0,
            t_min,
            t_max,
        };
        // A ray starting inside the tree, among rays said to go every way,
        // first goes down to its origin's leaf.
        if coherence == RayCoherence::Incoherent && t_min <= ray.t_min {
            let Some(start) = self
                .descend(entry, &axes, &mut stack, &mut work)
                .or_else(|| stack.pop())
            else {
                *counters += work;
                return;
            };
            entry = start;
        }
        loop {
            work.nodes += 1;
            match self.nodes[entry.node as usize].kind() {
                NodeKind::Interior {
                    axis,
                    split,
                    below,
                    above,
                } if !below || above == 0 => {
                    // An empty-space cut: the walk goes on into the one
                    // stored child unless the ray misses it.
                    let child = if below { entry.node + 1 } else { above };
                    if let Some((t_min, t_max)) = stored_side(&entry, axis, split, below, &axes) {
                        entry = Entry {
                            node: child,
                            t_min,
                            t_max,
                        };
                        continue;
                    }
                }
                NodeKind::Interior {
                    axis, split, above, ..
                } => match children(&entry, axis, split, [entry.node + 1, above], &axes) {
                    [Some(first), Some(second)] => {
                        stack.push(second);
                        entry = first;
                        continue;
                    }
                    [Some(only), None] | [None, Some(only)] => {
                        entry = only;
                        continue;
                    }
                    [None, None] => {}
                },
                NodeKind::Leaf { offset, count } => {
                    let start = offset as usize;
                    match leaf(start..start + count as usize, &mut work) {
                        Flow::Continue(t) => horizon = t,
                        Flow::Stop => break,
                    }
                }
            }
            // The next pending cell that starts before the closest hit.
            let Some(next) = std::iter::from_fn(|| stack.pop()).find(|e| e.t_min <= horizon) else {
                break;
            };
            entry = next;
        }
        *counters += work;
    }
}

impl KdTree {
    /// The start of a walk for a ray whose origin lies in `root`'s cell
    /// (one that starts at `t_min` = 0 inside the root's box):
    /// down the nodes whose cells hold the origin, each step choosing the
    /// child on the origin's side of the plane and pushing the other one
    /// if the ray meets it, without a branch on the ray's direction (see
    /// [`crate::accel::RayCoherence`]). Stops at the origin's leaf, or at
    /// the stored child of an empty-space cut when the origin lies in the
    /// empty part. Returns where the walk goes on, `None` when the ray
    /// misses that node's cell (the walk then takes the next cell from the
    /// stack).
    ///
    /// Every range is the one [`children`] or [`stored_side`] gives, so the
    /// walk visits the same cells. Their order differs from the walk's only
    /// when the crossing lies at or behind the range's start (an origin on
    /// a plane, a negative `t_min`, a ray in a plane): the closest `t` is
    /// the same, and on an exact tie another primitive may be returned.
    /// The side chosen only orders the cells, so the call's condition (the
    /// point at `ray.t_min`, not the origin, inside the root) is for speed.
    ///
    /// Not kept (figures in docs/performance-log.md, kd-tree descent to the
    /// origin's leaf):
    /// - Tried pushing the other child whenever it is stored: no faster.
    /// - Tried comparing the origin's side as integer keys: slower.
    #[inline(always)]
    fn descend<const N: usize>(
        &self,
        root: Entry,
        axes: &Axes,
        stack: &mut Stack<Entry, N>,
        work: &mut TraversalCounters,
    ) -> Option<Entry> {
        let mut entry = root;
        while let NodeKind::Interior {
            axis,
            split,
            below,
            above,
        } = self.nodes[entry.node as usize].kind()
        {
            work.nodes += 1;
            let origin_above = axes.origin[axis] >= f64::from(split);
            if !below || above == 0 {
                let (t_min, t_max) = stored_side(&entry, axis, split, below, axes)?;
                entry = Entry {
                    node: if below { entry.node + 1 } else { above },
                    t_min,
                    t_max,
                };
                if origin_above == below {
                    break;
                }
                continue;
            }
            // The ranges of the child the ray meets first and second.
            let (t_low, t_high, down) = crossing(axis, split, axes);
            let first = (entry.t_min, min(t_high, entry.t_max));
            let second = (max(t_low, entry.t_min), entry.t_max);
            let down = opaque(u64::from(down).wrapping_neg());
            let below_range = (
                select(down, second.0, first.0),
                select(down, second.1, first.1),
            );
            let above_range = (
                select(down, first.0, second.0),
                select(down, first.1, second.1),
            );
            let ((go, go_range), (other, other_range)) = if origin_above {
                keep_as_branch();
                ((above, above_range), (entry.node + 1, below_range))
            } else {
                ((entry.node + 1, below_range), (above, above_range))
            };
            stack.push_if(
                Entry {
                    node: other,
                    t_min: other_range.0,
                    t_max: other_range.1,
                },
                at_least(other_range.1, other_range.0),
            );
            if !at_least(go_range.1, go_range.0) {
                return None;
            }
            entry = Entry {
                node: go,
                t_min: go_range.0,
                t_max: go_range.1,
            };
        }
        Some(entry)
    }
}

/// The ray's origin and inverse direction as arrays, so a node's axis picks
/// them by an indexed load: indexing the vectors compiled to a branch on
/// the axis, which changes from node to node and was mispredicted.
struct Axes {
    origin: [f64; 3],
    inv_dir: [f64; 3],
}

impl Axes {
    fn new(ray: &Ray) -> Self {
        Self {
            origin: ray.origin.to_array(),
            inv_dir: ray.inv_dir.to_array(),
        }
    }
}

/// Nothing, as an empty assembly statement the compiler must keep where it
/// is: in one arm of an `if`, it keeps the `if` a branch. The walk needs
/// its choice of the next node to be a predicted branch, so the next
/// node's load starts before the arithmetic that decides it is done. The
/// walk compiles to branches without it today, but small changes to
/// [`children`] made the compiler pick the below child and the near side
/// with conditional moves, so every node's load waited for the previous
/// node's: slower, see docs/performance-log.md (kd-tree walk).
///
/// Tried choosing the next node by selects on purpose: slower too.
#[inline(always)]
fn keep_as_branch() {
    #[cfg(any(target_arch = "x86_64", target_arch = "aarch64"))]
    // SAFETY: an empty statement reads and writes nothing.
    unsafe {
        std::arch::asm!("", options(nomem, nostack, preserves_flags));
    }
}

/// The smaller of two numbers, `b` if either is NaN (`minsd`; `f64::min`
/// returns the other one, with three more instructions).
#[inline(always)]
fn min(a: f64, b: f64) -> f64 {
    if a < b { a } else { b }
}

/// The larger of two numbers, `b` if either is NaN.
#[inline(always)]
fn max(a: f64, b: f64) -> f64 {
    if a > b { a } else { b }
}

/// `a >= b`, also true when either is NaN.
#[inline(always)]
#[allow(
    clippy::neg_cmp_op_on_partial_ord,
    reason = "a NaN crossing must pass the test"
)]
fn at_least(a: f64, b: f64) -> bool {
    !(a < b)
}

/// Where the ray crosses the plane at `split` on `axis`: the crossing's
/// parameter widened by its rounding error, as `(t_low, t_high)`, and
/// whether the ray goes down the axis, meeting the above side first.
///
/// The crossing's rounding error is below γ(3) relative. A NaN crossing
/// means the ray lies in the plane (0 · ∞), so it is on both sides
/// throughout: the callers' tests are written so that NaN passes them and
/// their bounds so that NaN leaves the node's own. A ray going up (or along
/// the plane with a +0 direction, whose crossing is ±∞) meets the below
/// side first.
///
/// Tried scaling the inverse direction once per ray: missed a box (see
/// docs/performance-log.md, kd-tree walk).
#[inline(always)]
fn crossing(axis: usize, split: f32, ray: &Axes) -> (f64, f64, bool) {
    let inv_dir = ray.inv_dir[axis];
    let t_plane = (f64::from(split) - ray.origin[axis]) * inv_dir;
    let a = t_plane * (1.0 - 2.0 * gamma(3));
    let b = t_plane * (1.0 + 2.0 * gamma(3));
    (min(a, b), max(a, b), inv_dir.is_sign_negative())
}

/// The children of the interior node `entry` that the ray meets, in the
/// order it meets them, each with its parameter range (never NaN: the
/// root's range comes from a box test, and a crossing that is NaN keeps
/// the node's range). `[below, above]` are the children's indices (a node
/// with one stored child goes to [`stored_side`] instead).
///
/// Not kept (figures in docs/performance-log.md, kd-tree walk):
/// - Tried one branch per node on both met/not-met tests: slower.
/// - Tried picking the near child by a select on a per-ray mask: slower.
/// - Tried the met tests against a range widened by 4γ(3): no faster.
#[inline]
fn children(
    entry: &Entry,
    axis: usize,
    split: f32,
    [below, above]: [u32; 2],
    ray: &Axes,
) -> [Option<Entry>; 2] {
    let (t_low, t_high, down) = crossing(axis, split, ray);
    let (first, second) = if down {
        keep_as_branch();
        (above, below)
    } else {
        (below, above)
    };
    let near = at_least(t_high, entry.t_min).then_some(Entry {
        node: first,
        t_min: entry.t_min,
        t_max: min(t_high, entry.t_max),
    });
    let far = at_least(entry.t_max, t_low).then_some(Entry {
        node: second,
        t_min: max(t_low, entry.t_min),
        t_max: entry.t_max,
    });
    [near, far]
}

/// The part `(t_min, t_max)` of the range of `entry`, an interior node with
/// one stored child, in which the ray is on that child's side of the plane
/// (below it if `below`), or `None` when it is never there: the range
/// [`children`] gives that child.
///
/// Which end of the range the crossing clips depends on the ray's
/// direction, but here, unlike at a node with two children, the direction
/// does not choose the next node, so the end is picked by a select: as a
/// branch it was mispredicted (figures in docs/performance-log.md, kd-tree
/// walk). At nodes with two children the same selects were slower.
#[inline(always)]
fn stored_side(
    entry: &Entry,
    axis: usize,
    split: f32,
    below: bool,
    ray: &Axes,
) -> Option<(f64, f64)> {
    let (t_low, t_high, down) = crossing(axis, split, ray);
    // The stored side is met first when the ray goes towards the other.
    let first = opaque(u64::from(below != down).wrapping_neg());
    let t_min = select(first, entry.t_min, max(t_low, entry.t_min));
    let t_max = select(first, min(t_high, entry.t_max), entry.t_max);
    at_least(t_max, t_min).then_some((t_min, t_max))
}

/// `mask`, passed through an empty assembly statement: the compiler can no
/// longer see that it is all zeros or all ones, so a [`select`] made with
/// it stays a select instead of being compiled back into a branch.
#[inline(always)]
fn opaque(mut mask: u64) -> u64 {
    #[cfg(any(target_arch = "x86_64", target_arch = "aarch64"))]
    // SAFETY: an empty statement (a comment naming the register) that
    // leaves the register as it is.
    unsafe {
        std::arch::asm!(
            "/* {0} */",
            inout(reg) mask,
            options(pure, nomem, nostack, preserves_flags)
        );
    }
    mask
}

/// `a` where `mask` is all ones, `b` where it is all zeros.
#[inline(always)]
fn select(mask: u64, a: f64, b: f64) -> f64 {
    f64::from_bits((a.to_bits() & mask) | (b.to_bits() & !mask))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Aabb, Vec3};

    fn entry(t_min: f64, t_max: f64) -> Entry {
        Entry {
            node: 10,
            t_min,
            t_max,
        }
    }

    fn nodes(children: [Option<Entry>; 2]) -> Vec<u32> {
        children.iter().flatten().map(|e| e.node).collect()
    }

    #[test]
    fn at_least_passes_nan_and_equal_values() {
        assert!(at_least(2.0, 1.0) && at_least(1.0, 1.0) && !at_least(0.5, 1.0));
        assert!(at_least(f64::NAN, 1.0) && at_least(1.0, f64::NAN));
        assert_eq!((min(f64::NAN, 3.0), max(f64::NAN, 3.0)), (3.0, 3.0));
    }

    #[test]
    fn a_ray_lying_in_the_plane_visits_both_children_over_its_whole_range() {
        for dir in [Vec3::Y, -Vec3::Y, Vec3::new(-0.0, 1.0, 0.0)] {
            let ray = Ray::new(Vec3::new(2.0, 0.0, 0.0), dir);
            let [a, b] = children(&entry(1.0, 5.0), 0, 2.0, [11, 20], &Axes::new(&ray));
            assert_eq!((a.unwrap().t_min, a.unwrap().t_max), (1.0, 5.0));
            assert_eq!((b.unwrap().t_min, b.unwrap().t_max), (1.0, 5.0));
        }
    }

    /// The children, below 11 and above 20 of the plane x = 2, that `ray`
    /// visits over `(t_min, t_max)`, in order.
    fn visited(ray: &Ray, t_min: f64, t_max: f64) -> Vec<u32> {
        nodes(children(
            &entry(t_min, t_max),
            0,
            2.0,
            [11, 20],
            &Axes::new(ray),
        ))
    }

    #[test]
    fn the_stored_side_of_a_cut_gets_the_range_children_gives_it() {
        let mut rng = crate::math::random::Rng::new(11);
        // Random rays, then rays along the plane (NaN crossings), rays
        // starting on it and crossings at the range's ends.
        let mut cases: Vec<(Ray, f64, f64)> = (0..2000)
            .map(|_| {
                let origin = rng.point_in(Vec3::splat(-4.0), Vec3::splat(4.0));
                let t_min = rng.range(0.0, 3.0);
                (
                    Ray::new(origin, rng.unit_vector()),
                    t_min,
                    t_min + rng.range(0.0, 3.0),
                )
            })
            .collect();
        for dir in [
            Vec3::Y,
            -Vec3::Y,
            Vec3::new(-0.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
        ] {
            for x in [1.5, 2.0, 2.5] {
                cases.push((Ray::new(Vec3::new(x, 0.0, 0.0), dir), 0.0, 5.0));
            }
        }
        let up = Ray::new(Vec3::ZERO, Vec3::X);
        cases.extend([(up, 2.0, 5.0), (up, 0.0, 2.0)]);
        for (ray, t_min, t_max) in cases {
            let axes = Axes::new(&ray);
            let e = entry(t_min, t_max);
            for (below, stored) in [(true, 11), (false, 20)] {
                let expected = children(&e, 0, 2.0, [11, 20], &axes)
                    .into_iter()
                    .flatten()
                    .find(|c| c.node == stored)
                    .map(|c| (c.t_min, c.t_max));
                assert_eq!(
                    stored_side(&e, 0, 2.0, below, &axes),
                    expected,
                    "{ray:?} over ({t_min}, {t_max}), below stored: {below}"
                );
            }
        }
    }

    #[test]
    fn a_ray_parallel_to_the_plane_visits_only_its_side() {
        for dir in [Vec3::Y, Vec3::new(-0.0, 1.0, 0.0)] {
            let below = Ray::new(Vec3::new(1.5, 0.0, 0.0), dir);
            assert_eq!(visited(&below, 1.0, 5.0), [11]);
            let above = Ray::new(Vec3::new(2.5, 0.0, 0.0), dir);
            assert_eq!(visited(&above, 1.0, 5.0), [20]);
        }
    }

    #[test]
    fn crossings_at_the_range_ends_visit_both_children() {
        // The ray crosses x = 2 at t = 2.
        let up = Ray::new(Vec3::ZERO, Vec3::X);
        assert_eq!(visited(&up, 2.0, 5.0), [11, 20]);
        assert_eq!(visited(&up, 0.0, 2.0), [11, 20]);
        assert_eq!(visited(&up, 0.0, 1.5), [11]);
        assert_eq!(visited(&up, 2.5, 5.0), [20]);
        let down = Ray::new(Vec3::new(4.0, 0.0, 0.0), -Vec3::X);
        assert_eq!(visited(&down, 0.0, 2.0), [20, 11]);
    }

    /// The cells of the tree's stored leaves, by node index.
    fn leaf_cells(tree: &KdTree) -> Vec<(u32, Aabb)> {
        let mut cells = Vec::new();
        let mut pending = vec![(0, tree.bounds)];
        while let Some((node, cell)) = pending.pop() {
            match tree.nodes[node as usize].kind() {
                NodeKind::Leaf { .. } => cells.push((node, cell)),
                NodeKind::Interior {
                    axis,
                    split,
                    below,
                    above,
                } => {
                    let [low, high] = super::super::split_cell(&cell, axis, f64::from(split));
                    if below {
                        pending.push((node + 1, low));
                    }
                    if above != 0 {
                        pending.push((above, high));
                    }
                }
            }
        }
        cells
    }

    #[test]
    fn the_descent_ends_in_the_leaf_holding_the_origin() {
        let mut rng = crate::math::random::Rng::new(12);
        let boxes = crate::accel::conformance::random_boxes(&mut rng, 3_000, 10.0, 1.0);
        let tree = KdTree::build(&boxes);
        let cells = leaf_cells(&tree);
        let mut in_leaves = 0;
        for _ in 0..3_000 {
            let origin = rng.point_in(tree.bounds.min, tree.bounds.max);
            let ray = Ray::new(origin, rng.unit_vector());
            let (t_min, t_max) = tree.bounds.intersect_ray(&ray).unwrap();
            let root = Entry {
                node: 0,
                t_min,
                t_max,
            };
            let mut stack = Stack::<Entry, STACK_CAPACITY>::new();
            let mut work = TraversalCounters::default();
            let end = tree.descend(root, &Axes::new(&ray), &mut stack, &mut work);
            let holding: Vec<u32> = cells
                .iter()
                .filter(|(_, c)| (0..3).all(|a| c.min[a] <= origin[a] && origin[a] <= c.max[a]))
                .map(|&(node, _)| node)
                .collect();
            if !holding.is_empty() {
                in_leaves += 1;
                let end = end.expect("the ray meets the origin's leaf");
                assert!(holding.contains(&end.node), "{ray:?} ended in {end:?}");
                assert_eq!(end.t_min, 0.0);
            }
            assert!(work.nodes > 0);
        }
        // Most of the volume is in stored leaves (cut-off empty space
        // aside), so most origins are.
        assert!(in_leaves > 1_500, "{in_leaves} origins in leaves");
    }

    #[test]
    fn a_ray_starting_on_the_plane_goes_to_the_side_it_points_to_first() {
        let up = Ray::new(Vec3::new(2.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0));
        let [near, far] = children(&entry(0.0, 5.0), 0, 2.0, [11, 20], &Axes::new(&up));
        // The below child is met only at t = 0 itself.
        assert_eq!(near.map(|e| (e.node, e.t_max)), Some((11, 0.0)));
        assert_eq!(far.map(|e| (e.node, e.t_min)), Some((20, 0.0)));
        let down = Ray::new(Vec3::new(2.0, 0.0, 0.0), Vec3::new(-1.0, 1.0, 0.0));
        let [near, far] = children(&entry(0.0, 5.0), 0, 2.0, [11, 20], &Axes::new(&down));
        assert_eq!(near.map(|e| (e.node, e.t_max)), Some((20, 0.0)));
        assert_eq!(far.map(|e| (e.node, e.t_min)), Some((11, 0.0)));
    }
}
