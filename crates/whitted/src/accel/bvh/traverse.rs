//! Ray queries: an iterative walk over the eight-wide nodes with a fixed
//! stack, testing a node's child boxes at once in `f32` SIMD (`slabs`: one
//! AVX register with the AVX kernels, two SSE halves otherwise; the kernel
//! is chosen once per query, `accel/kernel.rs`); the closest-hit query
//! visits the children the ray meets nearest first. The leaves are the
//! caller's policy ([`ClosestLeaves`], [`AnyLeaves`]), inlined into the
//! walk.
//!
//! # Why the `f32` test never culls a box the `f64` ray meets
//!
//! Primitives are tested with the exact `f64` ray; the slab test runs in
//! `f32` on the nodes' boxes (rounded outward, so they contain the exact
//! boxes). A child may be culled only when the `f64` slab test of
//! [`Aabb::intersect_ray`](crate::math::Aabb::intersect_ray) (and of the
//! binary BVH this replaced), which widens both ends by 2γ(3), would cull
//! it. Along one axis, with `p` a box plane and `o`, `i` the ray's origin
//! and inverse direction in `f64`, that test's parameter is `(p − o)·i`.
//!
//! - **Origin.** The `f32` origin is rounded per axis and per end instead of
//!   to nearest: for the entry, whichever of the `f32` values just below and
//!   just above `o` makes `(p − o′)·i` no larger than `(p − o)·i` (the one
//!   above when `i > 0`, below when `i < 0`); for the exit the other one.
//!   This moves each end outward by at least the conversion's error
//!   `|o − o′|·|i|`, exactly, with no extra arithmetic per node, and stays
//!   valid when `o` lies beyond the `f32` range (`o′ = ±∞`).
//! - **Rounding.** The computed entry `fl(fl(p − o′)·fl₃₂(i))` differs from
//!   `(p − o′)·i` by the relative error of three `f32` roundings (the
//!   subtraction, `i` to `f32`, the product), under `3u` with `u = 2⁻²⁴`;
//!   the `f64` test's own roundings and its 2γ(3) are below `2⁻⁴⁹`. After the
//!   three axes are combined with `t_min` and `t_max` (by comparisons, which
//!   are exact), the entry is multiplied by `1 ∓ 8u` and the exit by
//!   `1 ± 8u` (the sign chosen to move away from the interval, so negative
//!   parameters are widened too; where `t_min` is not below zero the entry
//!   is not either, and the AVX test multiplies each end by its one factor).
//!   That product rounds once more: `k = 8`
//!   covers the `4u` (plus under `2⁻⁴⁹`) needed with room to spare, and both
//!   factors are exact in `f32`. `t_min` is rounded down and `t_max` up.
//!   Every rounding is monotone, so a plane beyond the `f32` range rounds to
//!   `±∞` on the safe side; results below `2⁻¹²⁶` round with an absolute
//!   error under `2⁻¹⁴⁹`, the one case the relative factor does not cover
//!   (it would need a box and `t_min` both within `10⁻⁴⁴` of the origin).
//! - **Parallel rays.** A direction component of `±0` gives `i = ±∞`:
//!   the parameter is `±∞` outside or inside the
//!   slab, or NaN (`0·∞`) with the origin on a face, which counts as inside.
//!   With directed origins, `p − o′ = 0` only when `o` lies on the face or
//!   between it and `o′`, where inside is the conservative answer. The
//!   combining comparisons are written so that a NaN never narrows the
//!   interval (`a > b ? a : b` keeps `b` when `a` is NaN), as in
//!   `Aabb::intersect_ray`; an `∞ − ∞` from an infinite box or origin is a
//!   NaN handled the same way. A component so small (below about
//!   `3·10⁻³⁹`) that `i` is finite in `f64` but not in `f32` would make an
//!   entry `+∞` where the exact one is finite: such an axis is made not to
//!   cull (entry origin `f32::MAX`, exit origin `−f32::MAX`, `i = 2¹⁰⁰`, so
//!   entries are `−∞` and exits `+∞` for every plane but `±f32::MAX` and the
//!   empty box's `±∞`).
//!
//! Unused slots hold the empty box (`+∞` minimum, `−∞` maximum): their
//! entry is `+∞` on every axis for any ray with a finite origin, so they are
//! never entered; a ray with a NaN origin enters every slot, and the walk
//! skips the unused ones' out-of-range child index.
//!
//! `counters.nodes` counts the wide nodes and the leaves the walk enters.
//!
//! # The walk, and why it is written so
//!
//! A node where the ray meets one child goes straight on to it, and one
//! where it meets two pushes only the farther, so the stack is written only
//! for what waits on it. The any-hit walk goes on to the last child it
//! meets and pushes the others in slot order. The stack is never cleared
//! (`accel/stack.rs`), and its size, short, middle-sized or for
//! [`MAX_DEPTH`], follows the tree's depth.
//!
//! Eight children a node are tested in one AVX register: eight-wide nodes
//! pay only with eight-wide registers, and a processor without AVX walks
//! them as two SSE halves. The slab test is written with explicit SIMD
//! operations rather than lane by lane for the compiler to vectorise (it
//! mixed scalar and vector code), and each axis's entry and exit planes are
//! read through rows chosen once per ray, not by a branch per axis and
//! node.
//!
//! The figures behind these choices are in docs/performance-log.md (eight-wide
//! BVH). Not kept, with their figures there too:
//! - Tried testing a binary node's two children at once in SIMD: slower.
//! - Tried sorting the hit children in an array, then copying: slower.
//! - Tried clearing a stack for [`MAX_DEPTH`] for every ray: slower.

use std::ops::Range;

use super::node::{BvhNode, WIDTH, round_up};
use super::slabs::SlabTest;
use super::{Bvh, MAX_DEPTH};
use crate::accel::kernel::{self, Kernel, KernelTask};
use crate::accel::stack::Stack;
use crate::accel::{AnyLeaves, ClosestLeaves, QueryContext, TraversalCounters};
use crate::math::Ray;

/// Entries the stack needs for a tree whose leaves lie at most `depth` deep:
/// a node at depth `d` finds at most `(WIDTH − 1)·d` entries pending and
/// pushes its (at most [`WIDTH`]) children before it pops the nearest.
pub(super) const fn stack_size(depth: usize) -> usize {
    (WIDTH - 1) * depth + WIDTH
}

/// Trees at most this deep use a short stack.
pub(super) const SHALLOW: usize = 12;

/// Trees deeper than [`SHALLOW`] but at most this deep use a middle-sized
/// stack, under half the one for [`MAX_DEPTH`].
pub(super) const MIDDLE: usize = 24;

/// A child to visit: a node (`count == 0`) or a leaf, and a lower bound on
/// the parameter where the ray enters its box.
#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    child: u32,
    count: u32,
    t: f32,
}

/// Slot `slot` (below [`WIDTH`]) of `node` as a child to visit.
#[inline(always)]
fn child_entry(node: &BvhNode, slot: usize, near: &[f32; WIDTH]) -> Entry {
    let slot = slot % WIDTH;
    Entry {
        child: node.children[slot],
        count: node.counts[slot],
        t: near[slot],
    }
}

/// Pushes the children of `node` in `mask` on `stack` so that the nearest
/// ends on top.
#[inline(always)]
fn push_sorted<const N: usize>(
    stack: &mut Stack<Entry, N>,
    node: &BvhNode,
    mask: u32,
    near: &[f32; WIDTH],
) {
    let floor = stack.len();
    let mut bits = mask;
    while bits != 0 {
        let entry = child_entry(node, bits.trailing_zeros() as usize, near);
        bits &= bits - 1;
        stack.insert_above(floor, entry, |new, other| other.t < new.t);
    }
}

impl Bvh {
    /// The closest hit (see [`crate::accel`]).
    #[inline]
    pub fn intersect(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        mut hit: impl FnMut(u32, f64) -> Option<f64>,
    ) -> Option<f64> {
        self.intersect_in_leaf_order(ray, ctx, |entries: Range<u32>, mut t_max| {
            let mut found = None;
            for entry in entries {
                if let Some(t) = hit(self.indices[entry as usize], t_max) {
                    t_max = t;
                    found = Some(t);
                }
            }
            found
        })
    }

    /// [`Self::intersect`], with `hit` given a whole leaf: the positions in
    /// [`Self::indices`] of its primitives and the closest parameter so
    /// far; it returns the closest hit among them closer than that, if
    /// any. A caller that keeps what it needs of the primitives in that
    /// order reads each leaf's together, and may test several at once.
    #[inline]
    pub fn intersect_in_leaf_order(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        hit: impl FnMut(Range<u32>, f64) -> Option<f64>,
    ) -> Option<f64> {
        /// The walk as a kernel's task.
        struct Closest<'q, L> {
            bvh: &'q Bvh,
            ray: &'q Ray,
            counters: &'q mut TraversalCounters,
            leaves: L,
        }
        impl<L: ClosestLeaves> KernelTask for Closest<'_, L> {
            type Output = Option<f64>;
            #[inline(always)]
            fn run<K: Kernel>(self) -> Option<f64> {
                self.bvh
                    .closest_with::<K>(self.ray, self.counters, self.leaves)
            }
        }
        let task = Closest {
            bvh: self,
            ray,
            counters: &mut ctx.counters,
            leaves: hit,
        };
        kernel::run(ctx.backend, task)
    }

    /// [`Self::intersect_in_leaf_order`] with kernel `K`, the leaves tested
    /// by `leaves`, adding the work to `counters`.
    #[inline(always)]
    pub(crate) fn closest_with<K: Kernel>(
        &self,
        ray: &Ray,
        counters: &mut TraversalCounters,
        leaves: impl ClosestLeaves,
    ) -> Option<f64> {
        if self.nodes.is_empty() {
            None
        } else if self.max_depth <= SHALLOW {
            self.closest::<{ stack_size(SHALLOW) }, K>(ray, counters, leaves)
        } else if self.max_depth <= MIDDLE {
            self.closest::<{ stack_size(MIDDLE) }, K>(ray, counters, leaves)
        } else {
            self.closest::<{ stack_size(MAX_DEPTH) }, K>(ray, counters, leaves)
        }
    }

    /// [`Self::intersect_in_leaf_order`] with a stack of `N` entries and
    /// kernel `K`.
    #[inline(always)]
    fn closest<const N: usize, K: Kernel>(
        &self,
        ray: &Ray,
        counters: &mut TraversalCounters,
        mut leaves: impl ClosestLeaves,
    ) -> Option<f64> {
        let slabs = K::Slabs::new(ray);
        let mut closest = ray.t_max;
        let mut far = round_up(closest);
        let mut found = None;
        let mut work = TraversalCounters::default();
        let mut stack = Stack::<Entry, N>::new();
        let mut current = Entry::default();
        loop {
            work.nodes += 1;
            let first = current.child as usize;
            if current.count > 0 {
                work.primitives += u64::from(current.count);
                if let Some(t) =
                    leaves.closest::<K>(current.child..current.child + current.count, closest)
                {
                    closest = t;
                    found = Some(t);
                    far = round_up(closest);
                }
            } else if let Some(node) = self.nodes.get(first) {
                let (mask, near) = slabs.test(node, far);
                if mask & (mask.wrapping_sub(1)) == 0 && mask != 0 {
                    // One child: straight on, the stack untouched.
                    current = child_entry(node, mask.trailing_zeros() as usize, &near);
                    continue;
                }
                let rest = mask & mask.wrapping_sub(1);
                if rest & rest.wrapping_sub(1) == 0 && rest != 0 {
                    // Two children: the farther waits on the stack.
                    let a = child_entry(node, mask.trailing_zeros() as usize, &near);
                    let b = child_entry(node, rest.trailing_zeros() as usize, &near);
                    let (nearer, farther) = if b.t < a.t { (b, a) } else { (a, b) };
                    stack.push(farther);
                    current = nearer;
                    continue;
                }
                if mask != 0 {
                    // All but the nearest stay on the stack.
                    push_sorted(&mut stack, node, mask, &near);
                    current = stack.pop().unwrap_or_default();
                    continue;
                }
            }
            // Resume with the nearest pending child the closest hit has not
            // yet put out of reach.
            loop {
                let Some(next) = stack.pop() else {
                    *counters += work;
                    return found;
                };
                if f64::from(next.t) <= closest {
                    current = next;
                    break;
                }
            }
        }
    }

    /// Any hit (see [`crate::accel`]).
    #[inline]
    pub fn occluded(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        mut occludes: impl FnMut(u32) -> bool,
    ) -> bool {
        self.occluded_in_leaf_order(ray, ctx, |mut entries: Range<u32>| {
            entries.any(|entry| occludes(self.indices[entry as usize]))
        })
    }

    /// [`Self::occluded`], with `occludes` given a whole leaf: the
    /// positions in [`Self::indices`] of its primitives (see
    /// [`Self::intersect_in_leaf_order`]); it says whether any of them lies
    /// in the ray's interval. The leaf counts as tested whole in
    /// `counters.primitives`, however early the caller stops.
    #[inline]
    pub fn occluded_in_leaf_order(
        &self,
        ray: &Ray,
        ctx: &mut QueryContext,
        occludes: impl FnMut(Range<u32>) -> bool,
    ) -> bool {
        /// The walk as a kernel's task.
        struct Any<'q, L> {
            bvh: &'q Bvh,
            ray: &'q Ray,
            counters: &'q mut TraversalCounters,
            leaves: L,
        }
        impl<L: AnyLeaves> KernelTask for Any<'_, L> {
            type Output = bool;
            #[inline(always)]
            fn run<K: Kernel>(self) -> bool {
                self.bvh.any_with::<K>(self.ray, self.counters, self.leaves)
            }
        }
        let task = Any {
            bvh: self,
            ray,
            counters: &mut ctx.counters,
            leaves: occludes,
        };
        kernel::run(ctx.backend, task)
    }

    /// [`Self::occluded_in_leaf_order`] with kernel `K`, the leaves tested
    /// by `leaves`, adding the work to `counters`.
    #[inline(always)]
    pub(crate) fn any_with<K: Kernel>(
        &self,
        ray: &Ray,
        counters: &mut TraversalCounters,
        leaves: impl AnyLeaves,
    ) -> bool {
        if self.nodes.is_empty() {
            false
        } else if self.max_depth <= SHALLOW {
            self.any::<{ stack_size(SHALLOW) }, K>(ray, counters, leaves)
        } else if self.max_depth <= MIDDLE {
            self.any::<{ stack_size(MIDDLE) }, K>(ray, counters, leaves)
        } else {
            self.any::<{ stack_size(MAX_DEPTH) }, K>(ray, counters, leaves)
        }
    }

    /// [`Self::occluded_in_leaf_order`] with a stack of `N` entries and
    /// kernel `K`.
    #[inline(always)]
    fn any<const N: usize, K: Kernel>(
        &self,
        ray: &Ray,
        counters: &mut TraversalCounters,
        mut leaves: impl AnyLeaves,
    ) -> bool {
        let slabs = K::Slabs::new(ray);
        let far = round_up(ray.t_max);
        let mut work = TraversalCounters::default();
        let mut stack = Stack::<Entry, N>::new();
        let mut current = Entry::default();
        let occluded = loop {
            work.nodes += 1;
            let first = current.child as usize;
            if current.count > 0 {
                work.primitives += u64::from(current.count);
                if leaves.occludes::<K>(current.child..current.child + current.count) {
                    break true;
                }
            } else if let Some(node) = self.nodes.get(first) {
                let (mask, near) = slabs.test(node, far);
                if mask != 0 {
                    // The last slot hit goes on, the others wait on the
                    // stack in slot order, unsorted: any hit will do. Tried
                    // nearest first: slower, see docs/performance-log.md.
                    let last = 31 - mask.leading_zeros();
                    let mut bits = mask & !(1 << last);
                    while bits != 0 {
                        stack.push(child_entry(node, bits.trailing_zeros() as usize, &near));
                        bits &= bits - 1;
                    }
                    current = child_entry(node, last as usize, &near);
                    continue;
                }
            }
            match stack.pop() {
                Some(next) => current = next,
                None => break false,
            }
        };
        *counters += work;
        occluded
    }
}

#[cfg(test)]
mod tests {
    use super::{MAX_DEPTH, stack_size};
    use crate::accel::kernel::Sse2Kernel;
    use crate::accel::{Bvh, Linear, QueryContext, TraversalCounters};
    use crate::math::random::Rng;
    use crate::math::{Aabb, Ray, Vec3};

    /// Unit cubes at x = 0, 2, 4, ...
    fn row(n: u32) -> Vec<Aabb> {
        (0..n)
            .map(|i| {
                let x = 2.0 * f64::from(i);
                Aabb::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 1.0, 1.0))
            })
            .collect()
    }

    /// A hit where the ray enters primitive `i`'s box.
    fn box_entry(boxes: &[Aabb], ray: &Ray, i: u32, t_max: f64) -> Option<f64> {
        let mut r = *ray;
        r.t_max = t_max;
        boxes[i as usize].intersect_ray(&r).map(|(near, _)| near)
    }

    #[test]
    fn nearer_children_first_so_a_near_hit_prunes_the_rest() {
        let boxes = row(256);
        let bvh = Bvh::build(&boxes);
        for (origin, dir, first) in [
            (Vec3::new(-5.0, 0.5, 0.5), Vec3::X, 0),
            (Vec3::new(600.0, 0.5, 0.5), -Vec3::X, 255),
        ] {
            let ray = Ray::new(origin, dir);
            let mut ctx = QueryContext::default();
            let mut hit_prim = None;
            let t = bvh.intersect(&ray, &mut ctx, |i, t_max| {
                let t = box_entry(&boxes, &ray, i, t_max)?;
                hit_prim = Some(i);
                Some(t)
            });
            assert_eq!(hit_prim, Some(first));
            assert_eq!(t, boxes[first as usize].intersect_ray(&ray).map(|(n, _)| n));
            assert!(ctx.counters.primitives <= 8, "{:?}", ctx.counters);
            assert!(ctx.counters.nodes <= 3 * 8 + 8, "{:?}", ctx.counters);
        }
    }

    #[test]
    fn any_hit_stops_at_the_first_occluder() {
        let boxes = row(256);
        let bvh = Bvh::build(&boxes);
        let ray = Ray::new(Vec3::new(-5.0, 0.5, 0.5), Vec3::X);
        let mut ctx = QueryContext::default();
        assert!(bvh.occluded(&ray, &mut ctx, |_| true));
        assert_eq!(ctx.counters.primitives, 1);
        let above = Ray::new(Vec3::new(-5.0, 1.5, 0.5), Vec3::X);
        assert!(!bvh.occluded(&above, &mut ctx, |_| true));
    }

    #[test]
    fn rays_lying_in_box_faces_are_inside_like_brute_force() {
        // Flat boxes in z = 0 at coordinates f32 cannot hold exactly; rays
        // in that plane along their faces have 0 · ∞ = NaN slabs, with
        // either sign of zero in their direction.
        let corner = |i: u32| Vec3::new(0.1 * f64::from(i % 8), 0.1 * f64::from(i / 8), 0.0);
        let size = Vec3::new(0.07, 0.03, 0.0);
        let boxes: Vec<Aabb> = (0..64)
            .map(|i| Aabb::new(corner(i), corner(i) + size))
            .collect();
        let bvh = Bvh::build(&boxes);
        let linear = Linear::build(&boxes);
        let faces = [0, 9, 26, 63].map(corner);
        let ys = faces
            .iter()
            .flat_map(|c| [c.y, c.y + size.y, c.y + 0.5 * size.y]);
        for y in ys {
            for (dy, dz) in [(0.0, 0.0), (-0.0, 0.0), (0.0, -0.0), (-0.0, -0.0)] {
                for dir in [Vec3::new(1.0, dy, dz), Vec3::new(-1.0, dy, dz)] {
                    let origin = Vec3::new(0.4 - 2.0 * dir.x, y, 0.0);
                    let ray = Ray::new(origin, dir);
                    let mut ctx = QueryContext::default();
                    let expected =
                        linear.intersect(&ray, &mut ctx, |i, t| box_entry(&boxes, &ray, i, t));
                    let actual =
                        bvh.intersect(&ray, &mut ctx, |i, t| box_entry(&boxes, &ray, i, t));
                    assert!(expected.is_some());
                    assert_eq!(actual, expected, "{ray:?}");
                    assert!(bvh.occluded(&ray, &mut ctx, |_| true));
                }
            }
        }
    }

    /// The BVH finds the same closest box entry as brute force, and the
    /// same answer to any hit, for every ray, with the slab test this
    /// processor uses and with the two SSE halves (the only one without
    /// AVX); returns how many rays hit.
    fn assert_agrees_with_brute_force(boxes: &[Aabb], rays: &[Ray]) -> usize {
        let bvh = Bvh::build(boxes);
        bvh.validate(boxes).unwrap();
        let linear = Linear::build(boxes);
        let mut ctx = QueryContext::default();
        let mut hits = 0;
        const N: usize = stack_size(MAX_DEPTH);
        for ray in rays {
            let expected = linear.intersect(ray, &mut ctx, |i, t| box_entry(boxes, ray, i, t));
            let actual = bvh.intersect(ray, &mut ctx, |i, t| box_entry(boxes, ray, i, t));
            assert_eq!(actual, expected, "{ray:?}");
            let halves =
                bvh.closest::<N, Sse2Kernel>(ray, &mut ctx.counters, |entries, mut t_max| {
                    let mut found = None;
                    for entry in entries {
                        let i = bvh.indices()[entry as usize];
                        if let Some(t) = box_entry(boxes, ray, i, t_max) {
                            t_max = t;
                            found = Some(t);
                        }
                    }
                    found
                });
            assert_eq!(halves, expected, "{ray:?}");
            let occluded = |i: u32| box_entry(boxes, ray, i, ray.t_max).is_some();
            assert_eq!(
                bvh.occluded(ray, &mut ctx, occluded),
                expected.is_some(),
                "{ray:?}"
            );
            let leaf_occluded = |mut entries: std::ops::Range<u32>| {
                entries.any(|entry| occluded(bvh.indices()[entry as usize]))
            };
            assert_eq!(
                bvh.any::<N, Sse2Kernel>(ray, &mut ctx.counters, leaf_occluded),
                expected.is_some(),
                "{ray:?}"
            );
            hits += usize::from(expected.is_some());
        }
        hits
    }

    #[test]
    fn far_from_the_origin_tiny_boxes_are_never_missed() {
        // Boxes of 1e-9 to 1e-3 around points 1e4 to 1e6 from the origin,
        // where an f32 ulp is 1e-3 to 0.06: rays from far away aimed at
        // their centres, corners and edges, and rays starting inside them.
        let mut rng = Rng::new(41);
        for scale in [1e4, 1e5, 1e6] {
            let centre = Vec3::new(scale, -0.7 * scale, 0.3 * scale);
            let boxes: Vec<Aabb> = (0..200)
                .map(|_| {
                    let c = centre + rng.point_in(Vec3::splat(-1.0), Vec3::ONE);
                    let half = Vec3::splat(10f64.powf(rng.range(-9.0, -3.0)));
                    Aabb::new(c - half, c + half)
                })
                .collect();
            let mut rays = Vec::new();
            for b in &boxes {
                let from = centre + rng.unit_vector() * rng.range(1.0, 2.0) * scale;
                for target in [
                    b.centroid(),
                    b.min,
                    b.max,
                    Vec3::new(b.min.x, b.max.y, b.min.z),
                ] {
                    rays.push(Ray::new(from, target - from));
                    rays.push(Ray::segment(from, target - from, 1.0));
                }
                rays.push(Ray::new(b.centroid(), rng.unit_vector()));
            }
            let hits = assert_agrees_with_brute_force(&boxes, &rays);
            assert!(hits > rays.len() / 2, "{hits} of {}", rays.len());
        }
    }

    #[test]
    fn axis_parallel_rays_on_box_faces_far_from_the_origin() {
        // Boxes with faces at coordinates f32 cannot hold, 1e5 from the
        // origin; rays along each axis whose origins lie exactly in face
        // planes (and on edges), with either sign of zero elsewhere.
        let corner = |i: u32| {
            Vec3::new(
                1e5 + 0.1 * f64::from(i % 4),
                -2e5 + 0.1 * f64::from(i / 4 % 4),
                3e5 + 0.1 * f64::from(i / 16),
            )
        };
        let size = Vec3::new(0.07, 0.03, 0.05);
        let boxes: Vec<Aabb> = (0..64)
            .map(|i| Aabb::new(corner(i), corner(i) + size))
            .collect();
        let mut rays = Vec::new();
        for b in boxes.iter().step_by(5) {
            for axis in 0..3 {
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                for (pu, pv) in [
                    (b.min[u], b.min[v]),
                    (b.max[u], b.max[v]),
                    (b.min[u], b.centroid()[v]),
                    (b.centroid()[u], b.max[v]),
                ] {
                    for sign in [1.0, -1.0] {
                        for zeros in [0.0, -0.0] {
                            let mut dir = Vec3::splat(zeros);
                            dir[axis] = sign;
                            let mut origin = b.centroid() - dir * 10.0;
                            origin[u] = pu;
                            origin[v] = pv;
                            rays.push(Ray::new(origin, dir));
                        }
                    }
                }
            }
        }
        let hits = assert_agrees_with_brute_force(&boxes, &rays);
        assert_eq!(hits, rays.len());
    }

    #[test]
    fn directions_too_small_for_f32_and_nan_origins() {
        let boxes: Vec<Aabb> = (0..100)
            .map(|i| {
                let p = Vec3::new(f64::from(i % 10), f64::from(i / 10), 0.0) * 1e-30;
                Aabb::new(p, p + Vec3::splat(3e-31))
            })
            .collect();
        let mut rays = Vec::new();
        for i in 0..10 {
            // Above box (i, 5), 1e-30 below it: it is reached at t = 1e9
            // or 1e10.
            let origin = Vec3::new(f64::from(i) * 1e-30 + 1.5e-31, 5.15e-30, -1e-30);
            for dir in [
                Vec3::new(1e-41, -1e-41, 1e-39),
                Vec3::new(-1e-45, 0.0, 1e-40),
            ] {
                rays.push(Ray::new(origin, dir));
                rays.push(Ray::segment(origin, dir, 2e10));
            }
        }
        assert_eq!(assert_agrees_with_brute_force(&boxes, &rays), rays.len());
        let bvh = Bvh::build(&boxes);
        let nan = Ray::new(Vec3::new(f64::NAN, 0.0, 0.0), Vec3::X);
        let mut ctx = QueryContext::default();
        assert_eq!(bvh.intersect(&nan, &mut ctx, |_, _| None), None);
        assert!(!bvh.occluded(&nan, &mut ctx, |_| false));
    }

    #[test]
    fn nothing_to_hit_without_primitives() {
        let bvh = Bvh::build(&[]);
        let ray = Ray::new(Vec3::ZERO, Vec3::X);
        let mut ctx = QueryContext::default();
        assert_eq!(bvh.intersect(&ray, &mut ctx, |_, _| Some(1.0)), None);
        assert!(!bvh.occluded(&ray, &mut ctx, |_| true));
        assert_eq!(ctx.counters, TraversalCounters::default());
    }
}
