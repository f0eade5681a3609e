//! The any-hit query for a packet of up to [`PACKET_LANES`] coherent rays
//! (shadow rays from neighbouring hits towards one light, as
//! `whitted bench --packets` walks them; the renderer's stay single),
//! walked together with the closest-hit packet's node tests (see
//! `packet`): the packet culls a node's children at once, and the lanes
//! that remain test each child as their own single walk does.
//!
//! Each lane keeps its own interval to the end. A lane's single walk
//! enters every leaf its slab test keeps, in some order, and stops at the
//! first that holds a primitive in the interval; the packet walk tests
//! each lane against every leaf that lane's slab test keeps (the same
//! operations on the same values) until one holds such a primitive, then
//! drops the lane. So the lane is occluded in the packet exactly when its
//! single walk finds it occluded: whether a leaf holds a primitive in the
//! interval does not depend on the order of the visit.

use std::ops::Range;

use crate::accel::kernel::{self, Kernel, KernelTask};
use crate::accel::{Backend, Isa, TraversalCounters};
use crate::math::Ray;

use super::{Bvh, PACKET_LANES};

impl Bvh {
    /// Which of the lanes `lanes` of `rays` (at most [`PACKET_LANES`]) meet
    /// a primitive in their interval, walked together, with
    /// `occludes(lanes, entries)` telling which of the lanes `lanes` meet
    /// one of the leaf's entries (as [`Self::occluded_in_leaf_order`]'s
    /// test tells it for one ray): the mask of the occluded lanes, or
    /// `None` when the packet cannot be walked together (see `packet`;
    /// always with a `backend` without AVX). With no lane asked for, or an
    /// empty hierarchy, that is `Some(0)` whatever the rays. The walk and
    /// `occludes` run as one task of `backend`'s kernel (`accel/kernel.rs`).
    pub fn occluded_packet_by_leaf(
        &self,
        rays: &[Ray],
        (lanes, backend): (u32, Backend),
        counters: &mut TraversalCounters,
        occludes: impl FnMut(u32, Range<u32>) -> u32,
    ) -> Option<u32> {
        /// The walk as a kernel's task.
        #[cfg_attr(
            not(target_arch = "x86_64"),
            expect(dead_code, reason = "packets are walked together on x86-64 only")
        )]
        struct Packet<'q, L> {
            bvh: &'q Bvh,
            rays: &'q [Ray],
            lanes: u32,
            counters: &'q mut TraversalCounters,
            occludes: L,
        }
        impl<L: FnMut(u32, Range<u32>) -> u32> KernelTask for Packet<'_, L> {
            type Output = Option<u32>;
            #[inline(always)]
            fn run<K: Kernel>(self) -> Option<u32> {
                if K::ISA < Isa::Avx {
                    return None;
                }
                #[cfg(target_arch = "x86_64")]
                {
                    use super::traverse::{MIDDLE, SHALLOW, stack_size};
                    let Self {
                        bvh,
                        rays,
                        lanes,
                        counters,
                        occludes,
                    } = self;
                    // SAFETY: the kernel has AVX, so the processor does.
                    let packet = unsafe { super::packet::avx::Lanes::new(rays) }?;
                    // SAFETY: as above.
                    Some(unsafe {
                        if bvh.max_depth <= SHALLOW {
                            bvh.occluded_walk::<{ stack_size(SHALLOW) }>(
                                &packet, rays, lanes, counters, occludes,
                            )
                        } else if bvh.max_depth <= MIDDLE {
                            bvh.occluded_walk::<{ stack_size(MIDDLE) }>(
                                &packet, rays, lanes, counters, occludes,
                            )
                        } else {
                            bvh.occluded_walk::<{ stack_size(super::MAX_DEPTH) }>(
                                &packet, rays, lanes, counters, occludes,
                            )
                        }
                    })
                }
                #[cfg(not(target_arch = "x86_64"))]
                None
            }
        }
        if rays.is_empty() || rays.len() > PACKET_LANES {
            return None;
        }
        let lanes = lanes & ((1u32 << rays.len()) - 1);
        if self.nodes.is_empty() || lanes == 0 {
            return Some(0);
        }
        let task = Packet {
            bvh: self,
            rays,
            lanes,
            counters,
            occludes,
        };
        kernel::run(backend, task)
    }

    /// The walk of [`Self::occluded_packet_by_leaf`] with a stack of `N`
    /// entries.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn occluded_walk<const N: usize>(
        &self,
        packet: &super::packet::avx::Lanes,
        rays: &[Ray],
        lanes: u32,
        counters: &mut TraversalCounters,
        mut occludes: impl FnMut(u32, Range<u32>) -> u32,
    ) -> u32 {
        use super::node::round_up;
        use super::packet::avx::PacketEntry;
        use crate::accel::stack::Stack;

        // A lane found occluded has no interval left: every test drops it.
        let mut far = [f32::NEG_INFINITY; PACKET_LANES];
        let mut bits = lanes;
        while bits != 0 {
            let lane = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            far[lane] = round_up(rays[lane].t_max);
        }
        let mut far_most = far.iter().fold(f32::NEG_INFINITY, |a, &b| a.max(b));
        let mut occluded = 0;
        let mut work = TraversalCounters::default();
        let mut stack = Stack::<PacketEntry, N>::new();
        let mut current = PacketEntry::root(lanes);
        loop {
            work.nodes += 1;
            if current.count > 0 {
                let range = current.child..current.child + current.count;
                work.primitives += u64::from(current.count * current.lanes.count_ones());
                let mut found = occludes(current.lanes, range) & current.lanes;
                if found != 0 {
                    occluded |= found;
                    if occluded == lanes {
                        break;
                    }
                    while found != 0 {
                        far[found.trailing_zeros() as usize] = f32::NEG_INFINITY;
                        found &= found - 1;
                    }
                    far_most = far.iter().fold(f32::NEG_INFINITY, |a, &b| a.max(b));
                }
            } else if let Some(node) = self.nodes.get(current.child as usize) {
                let floor = stack.len();
                packet.push_children::<N, true>(
                    node,
                    current.lanes & !occluded,
                    &far,
                    far_most,
                    &mut stack,
                );
                if stack.len() > floor {
                    current = stack.pop().unwrap_or(current);
                    continue;
                }
            }
            // Resume with a pending child that a lane not yet occluded may
            // still meet. A lane's interval does not change until it is
            // occluded, so its own test when the child was pushed still
            // holds (testing `near` again against the unwidened `far` would
            // drop children the single walk enters).
            let next = loop {
                let Some(next) = stack.pop() else {
                    break None;
                };
                let still = next.lanes & !occluded;
                if still != 0 {
                    let mut next = next;
                    next.lanes = still;
                    break Some(next);
                }
            };
            match next {
                Some(next) => current = next,
                None => break,
            }
        }
        *counters += work;
        occluded
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;
    use crate::accel::QueryContext;
    use crate::math::random::Rng;
    use crate::math::{Aabb, Vec3};

    /// Random boxes, as primitives met anywhere in a ray's interval.
    fn boxes(rng: &mut Rng, n: usize) -> Vec<Aabb> {
        (0..n)
            .map(|_| {
                let c = rng.point_in(Vec3::splat(-4.0), Vec3::splat(4.0));
                let half = rng.point_in(Vec3::splat(0.01), Vec3::splat(0.3));
                Aabb::new(c - half, c + half)
            })
            .collect()
    }

    /// Whether `ray` meets box `i` in its interval.
    fn meets(boxes: &[Aabb], ray: &Ray, i: u32) -> bool {
        boxes[i as usize].intersect_ray(ray).is_some()
    }

    /// Packets of up to eight shadow rays: from points scattered over a
    /// patch of side `spread` towards one light, each ending at it; some
    /// start past their origin, some run on to infinity, some end where
    /// they start.
    fn shadow_packets(rng: &mut Rng, count: usize, spread: f64) -> Vec<Vec<Ray>> {
        (0..count)
            .map(|_| {
                let centre = rng.point_in(Vec3::splat(-5.0), Vec3::splat(5.0));
                let light = rng.point_in(Vec3::splat(-20.0), Vec3::splat(20.0));
                let lanes = 1 + rng.below(PACKET_LANES as u32) as usize;
                (0..lanes)
                    .map(|_| {
                        let from = centre + rng.point_in(Vec3::splat(-spread), Vec3::splat(spread));
                        let to = light - from;
                        let mut ray = Ray::segment(from, to.normalize(), to.length());
                        match rng.below(8) {
                            0 => ray.t_min = rng.range(0.0, ray.t_max),
                            1 => ray.t_max = f64::INFINITY,
                            2 => ray.t_max = ray.t_min,
                            _ => {}
                        }
                        ray
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn packets_find_each_lane_occluded_as_its_single_walk_does() {
        let backend = crate::accel::Backend::current();
        if !crate::accel::kernel::walks_with_avx_or_skip() {
            return;
        }
        let mut rng = Rng::new(31);
        let boxes = boxes(&mut rng, 3000);
        let bvh = Bvh::build(&boxes);
        let (mut together, mut occluded, mut clear) = (0, 0, 0);
        for spread in [0.01, 0.3, 4.0] {
            for rays in shadow_packets(&mut rng, 400, spread) {
                // Bits past the packet's rays are asked for too, and ignored.
                let lanes = rng.below(1 << PACKET_LANES) | 1;
                let mut counters = TraversalCounters::default();
                let mut done = 0;
                let found = bvh.occluded_packet_by_leaf(
                    &rays,
                    (lanes, backend),
                    &mut counters,
                    |asked, range| {
                        // Only lanes asked for and not yet found occluded.
                        assert_eq!(asked & !lanes, 0);
                        assert_eq!(asked & done, 0);
                        let mut hit = 0;
                        for lane in (0..rays.len()).filter(|l| asked >> l & 1 == 1) {
                            if range
                                .clone()
                                .any(|e| meets(&boxes, &rays[lane], bvh.indices[e as usize]))
                            {
                                hit |= 1 << lane;
                            }
                        }
                        done |= hit;
                        hit
                    },
                );
                let Some(found) = found else { continue };
                together += 1;
                assert!(counters.nodes > 0);
                for (lane, ray) in rays.iter().enumerate() {
                    let expected = lanes >> lane & 1 == 1
                        && bvh.occluded_in_leaf_order(ray, &mut QueryContext::default(), |range| {
                            range
                                .into_iter()
                                .any(|e| meets(&boxes, ray, bvh.indices[e as usize]))
                        });
                    let brute = (0..boxes.len() as u32).any(|i| meets(&boxes, ray, i));
                    assert_eq!(found >> lane & 1 == 1, expected, "lane {lane} of {rays:?}");
                    if lanes >> lane & 1 == 1 {
                        assert_eq!(expected, brute);
                        occluded += usize::from(expected);
                        clear += usize::from(!expected);
                    }
                }
            }
        }
        assert!(
            together > 1000 && occluded > 500 && clear > 500,
            "{together} {occluded} {clear}"
        );
    }

    #[test]
    fn a_lane_ending_just_short_of_a_box_enters_it_as_its_single_walk_does() {
        let backend = crate::accel::Backend::current();
        if !crate::accel::kernel::walks_with_avx_or_skip() {
            return;
        }
        // Unit cubes in a row, each its own leaf's; rays along the row end
        // just short of a cube's face, where the slab test's widening still
        // keeps the cube: the single walk enters that leaf, and so must
        // each lane, however the packet's walk orders its children.
        let cubes: Vec<Aabb> = (0..256)
            .map(|i| {
                let x = 2.0 * f64::from(i);
                Aabb::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 1.0, 1.0))
            })
            .collect();
        let bvh = Bvh::build(&cubes);
        let dir = Vec3::new(1.0, 1e-3, 1e-3).normalize();
        let origin = Vec3::new(-5.0, 0.5, 0.5);
        let mut entered = 0;
        for k in (1..256).step_by(7) {
            let entry = (2.0 * f64::from(k) + 5.0) / dir.x;
            let rays: Vec<Ray> = (10..18)
                .map(|c| Ray::segment(origin, dir, entry / (1.0 + f64::from(c) * 2f64.powi(-24))))
                .collect();
            // "Occluded" when the leaf holds cube k: a test the leaf's
            // being entered alone decides.
            let holds = |range: Range<u32>| range.into_iter().any(|e| bvh.indices[e as usize] == k);
            let mut counters = TraversalCounters::default();
            let found = bvh.occluded_packet_by_leaf(
                &rays,
                (0xff, backend),
                &mut counters,
                |asked, range| {
                    if holds(range) { asked } else { 0 }
                },
            );
            let Some(found) = found else { continue };
            for (lane, ray) in rays.iter().enumerate() {
                let single =
                    bvh.occluded_in_leaf_order(ray, &mut QueryContext::default(), |range| {
                        holds(range)
                    });
                assert_eq!(found >> lane & 1 == 1, single, "cube {k}, lane {lane}");
                entered += usize::from(single);
            }
        }
        assert!(entered > 100, "{entered}");
    }

    #[test]
    fn packets_that_cannot_be_walked_together_are_refused() {
        let backend = crate::accel::Backend::current();
        let bvh = Bvh::build(&[Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0))]);
        let mut counters = TraversalCounters::default();
        let towards = |x: f64| {
            Ray::segment(
                Vec3::new(0.0, 0.0, 5.0),
                Vec3::new(x, 0.05, -1.0).normalize(),
                10.0,
            )
        };
        let none = |_: u32, _: Range<u32>| -> u32 { panic!("no leaf is tested") };
        assert_eq!(
            bvh.occluded_packet_by_leaf(&[], (1, backend), &mut counters, none),
            None
        );
        assert_eq!(
            bvh.occluded_packet_by_leaf(&[towards(0.1); 9], (1, backend), &mut counters, none),
            None
        );
        assert_eq!(
            bvh.occluded_packet_by_leaf(&[towards(0.1)], (0, backend), &mut counters, none),
            Some(0)
        );
        if crate::accel::Backend::current().has_avx() {
            // Directions of both signs along x are not walked together.
            let mixed = [towards(0.1), towards(-0.1)];
            assert_eq!(
                bvh.occluded_packet_by_leaf(&mixed, (0b11, backend), &mut counters, none),
                None
            );
            let same = [towards(0.1), towards(0.2)];
            let all = |lanes: u32, _: Range<u32>| lanes;
            assert_eq!(
                bvh.occluded_packet_by_leaf(&same, (0b11, backend), &mut counters, all),
                Some(0b11)
            );
        }
    }
}
