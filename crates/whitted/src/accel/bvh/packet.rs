//! The closest-hit query for a packet of up to [`PACKET_LANES`] coherent
//! rays (a tile row's camera rays), walked together: one visit of a node
//! serves every ray of the packet, its children are culled for the whole
//! packet at once, and the rays that remain are tested against a child box
//! side by side in the lanes of one AVX register.
//!
//! # The node test
//!
//! First the packet's **interval test** culls a node's eight children at
//! once: per axis, the rays' rounded origins and inverse directions are
//! bounded by their least and greatest values over the packet, and the
//! entry parameter `(p − o)·i` is bounded below by `min((p − ô)·i_lo,
//! (p − ô)·i_hi)` with `ô` the greatest origin where the direction is
//! positive, the least where it is negative (the exit, above, the same
//! way). Every rounding is monotone, so these bounds hold for the `f32`
//! values each ray's own test computes; they are then combined and widened
//! by the same monotone steps as that test (see `traverse`), so the packet
//! keeps every child that one of its rays keeps. The children that remain
//! are tested **lane by lane**: each lane runs exactly the operations of
//! the single-ray test (`slabs_avx`) on that child's box, so a ray enters
//! the children its own walk would enter (for the same closest hit).
//!
//! # Why the answers are the single walk's
//!
//! A ray's single walk returns the primitive with the least hit parameter
//! in its interval, the first it visits among several at exactly that
//! parameter. The packet visits leaves in another order (nearest first for
//! the packet, not for each ray), so it tests each leaf with an interval
//! one ulp longer than the closest hit so far: a primitive hit at exactly
//! that parameter is reported, and the lane is marked **tied**. A tied lane
//! is walked again alone by the caller; every other lane's closest hit is
//! the unique least one, the single walk's answer. That needs the
//! primitives' reported parameter not to depend on the interval they are
//! tested with, beyond lying in it: the caller sends packets only where
//! that holds (closed-form shapes and triangles).
//!
//! Packets whose rays do not share a direction's sign per axis, or with a
//! direction component too small for `f32` or an origin beyond its range,
//! are not walked together (`None`): the caller walks their rays alone.

use std::ops::Range;

use crate::accel::kernel::{self, Kernel, KernelTask};
use crate::accel::{Backend, Isa, TraversalCounters};
use crate::math::Ray;

use super::Bvh;

/// The most rays a packet walk takes: the lanes of an AVX register.
pub const PACKET_LANES: usize = 8;

impl Bvh {
    /// The closest hits of `rays` (at most [`PACKET_LANES`]), walked
    /// together, with `hit(lane, entries, t_max)` testing a leaf for one
    /// ray as [`Self::intersect_in_leaf_order`] does (the closest hit among
    /// the entries closer than `t_max`, if any). Returns the lanes that
    /// must be walked again alone (ties, see the module documentation), or
    /// `None` when the packet cannot be walked together at all (always
    /// with a `backend` without AVX).
    pub fn intersect_packet_in_leaf_order(
        &self,
        rays: &[Ray],
        backend: Backend,
        counters: &mut TraversalCounters,
        mut hit: impl FnMut(usize, Range<u32>, f64) -> Option<f64>,
    ) -> Option<u32> {
        self.intersect_packet_by_leaf(rays, backend, counters, |lanes, range, t_max| {
            let mut found = 0;
            let mut bits = lanes;
            while bits != 0 {
                let lane = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                if let Some(t) = hit(lane, range.clone(), t_max[lane]) {
                    t_max[lane] = t;
                    found |= 1 << lane;
                }
            }
            found
        })
    }

    /// [`Self::intersect_packet_in_leaf_order`] with each leaf tested for
    /// all the lanes that reach it at once, so that its test may run
    /// across them: `hit(lanes, entries, t_max)` does for each lane whose
    /// bit is set in `lanes` what `hit` of that method does with
    /// `t_max[lane]`, and where that finds a hit, sets the lane's bit in
    /// the mask it returns and leaves the hit's `t` in `t_max[lane]`. The
    /// walk and `hit` run as one task of `backend`'s kernel
    /// (`accel/kernel.rs`).
    pub fn intersect_packet_by_leaf(
        &self,
        rays: &[Ray],
        backend: Backend,
        counters: &mut TraversalCounters,
        hit: impl FnMut(u32, Range<u32>, &mut [f64; PACKET_LANES]) -> u32,
    ) -> Option<u32> {
        /// The walk as a kernel's task.
        #[cfg_attr(
            not(target_arch = "x86_64"),
            expect(dead_code, reason = "packets are walked together on x86-64 only")
        )]
        struct Packet<'q, L> {
            bvh: &'q Bvh,
            rays: &'q [Ray],
            counters: &'q mut TraversalCounters,
            hit: L,
        }
        impl<L: FnMut(u32, Range<u32>, &mut [f64; PACKET_LANES]) -> u32> KernelTask for Packet<'_, L> {
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
                        counters,
                        hit,
                    } = self;
                    // SAFETY: the kernel has AVX, so the processor does.
                    let lanes = unsafe { avx::Lanes::new(rays) }?;
                    // SAFETY: as above.
                    Some(unsafe {
                        if bvh.max_depth <= SHALLOW {
                            bvh.packet::<{ stack_size(SHALLOW) }>(&lanes, rays, counters, hit)
                        } else if bvh.max_depth <= MIDDLE {
                            bvh.packet::<{ stack_size(MIDDLE) }>(&lanes, rays, counters, hit)
                        } else {
                            bvh.packet::<{ stack_size(super::MAX_DEPTH) }>(
                                &lanes, rays, counters, hit,
                            )
                        }
                    })
                }
                #[cfg(not(target_arch = "x86_64"))]
                None
            }
        }
        if rays.is_empty() || rays.len() > PACKET_LANES || self.nodes.is_empty() {
            return None;
        }
        let task = Packet {
            bvh: self,
            rays,
            counters,
            hit,
        };
        kernel::run(backend, task)
    }

    /// The walk of [`Self::intersect_packet_by_leaf`] with a stack of
    /// `N` entries.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn packet<const N: usize>(
        &self,
        lanes: &avx::Lanes,
        rays: &[Ray],
        counters: &mut TraversalCounters,
        mut hit: impl FnMut(u32, Range<u32>, &mut [f64; PACKET_LANES]) -> u32,
    ) -> u32 {
        use crate::accel::stack::Stack;
        use avx::PacketEntry;

        let active = (1u32 << rays.len()) - 1;
        let mut closest = [f64::NEG_INFINITY; PACKET_LANES];
        let mut far = [f32::NEG_INFINITY; PACKET_LANES];
        for (lane, ray) in rays.iter().enumerate() {
            closest[lane] = ray.t_max;
            far[lane] = super::node::round_up(ray.t_max);
        }
        let mut far_most = far.iter().fold(f32::NEG_INFINITY, |a, &b| a.max(b));
        let mut tied = 0;
        let mut work = TraversalCounters::default();
        let mut stack = Stack::<PacketEntry, N>::new();
        let mut current = PacketEntry::root(active);
        loop {
            work.nodes += 1;
            if current.count > 0 {
                let range = current.child..current.child + current.count;
                let mut t_max = [0.0; PACKET_LANES];
                let mut bits = current.lanes;
                while bits != 0 {
                    let lane = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    t_max[lane] = closest[lane].next_up();
                }
                work.primitives += u64::from(current.count * current.lanes.count_ones());
                let mut found = hit(current.lanes, range, &mut t_max) & current.lanes;
                while found != 0 {
                    let lane = found.trailing_zeros() as usize;
                    found &= found - 1;
                    let t = t_max[lane];
                    if t < closest[lane] {
                        closest[lane] = t;
                        far[lane] = super::node::round_up(t);
                    } else {
                        tied |= 1 << lane;
                    }
                }
                far_most = far.iter().fold(f32::NEG_INFINITY, |a, &b| a.max(b));
            } else if let Some(node) = self.nodes.get(current.child as usize) {
                let floor = stack.len();
                lanes.push_children::<N, false>(node, current.lanes, &far, far_most, &mut stack);
                if stack.len() > floor {
                    current = stack.pop().unwrap_or(current);
                    continue;
                }
            }
            // Resume with the nearest pending child that a lane may still
            // meet closer than its closest hit.
            loop {
                let Some(next) = stack.pop() else {
                    *counters += work;
                    return tied;
                };
                let still = next.lanes & lanes.before(&next.near, &far);
                if still != 0 {
                    current = next;
                    current.lanes = still;
                    break;
                }
            }
        }
    }
}

/// The AVX tests: the packet's interval test and the lane-by-lane test.
#[cfg(target_arch = "x86_64")]
pub(super) mod avx {
    use std::arch::x86_64::{
        __m128, __m256, _CMP_LE_OQ, _CMP_LT_OQ, _mm_cvtss_f32, _mm_max_ps, _mm_min_ps,
        _mm_movehl_ps, _mm_shuffle_ps, _mm256_and_ps, _mm256_castps128_ps256,
        _mm256_castps256_ps128, _mm256_cmp_ps, _mm256_cvtpd_ps, _mm256_extractf128_ps,
        _mm256_insertf128_ps, _mm256_loadu_pd, _mm256_loadu_ps, _mm256_max_ps, _mm256_min_ps,
        _mm256_movemask_ps, _mm256_mul_ps, _mm256_set1_ps, _mm256_setzero_ps, _mm256_storeu_ps,
        _mm256_sub_ps,
    };

    use super::super::node::{BvhNode, WIDTH};
    use super::super::slabs::{GROW, NEVER_CULLS, Planes, SHRINK};
    use super::PACKET_LANES;
    use crate::accel::stack::Stack;
    use crate::math::Ray;

    /// A child the packet visits: a node (`count == 0`) or a leaf, the
    /// lanes that may meet it, a lower bound on where any of them enters
    /// it (the order of the visit) and each lane's own.
    #[derive(Clone, Copy, Debug)]
    pub(in crate::accel::bvh) struct PacketEntry {
        pub(in crate::accel::bvh) child: u32,
        pub(in crate::accel::bvh) count: u32,
        pub(in crate::accel::bvh) lanes: u32,
        t: f32,
        pub(in crate::accel::bvh) near: [f32; PACKET_LANES],
    }

    impl PacketEntry {
        /// The root, for the lanes `lanes`.
        pub(in crate::accel::bvh) fn root(lanes: u32) -> Self {
            Self {
                child: 0,
                count: 0,
                lanes,
                t: f32::NEG_INFINITY,
                near: [f32::NEG_INFINITY; PACKET_LANES],
            }
        }
    }

    /// Eight `f32`s in a register.
    #[target_feature(enable = "avx")]
    #[inline]
    fn load(row: &[f32; 8]) -> __m256 {
        // SAFETY: `row` is eight readable `f32`s; the load is unaligned.
        unsafe { _mm256_loadu_ps(row.as_ptr()) }
    }

    /// A register's eight lanes.
    #[target_feature(enable = "avx")]
    #[inline]
    fn store(v: __m256) -> [f32; 8] {
        let mut lanes = [0.0; 8];
        // SAFETY: `lanes` is eight writable `f32`s; the store is unaligned.
        unsafe { _mm256_storeu_ps(lanes.as_mut_ptr(), v) };
        lanes
    }

    /// `min(x·a, x·b)` or, with `MAX`, `max(x·a, x·b)`.
    #[target_feature(enable = "avx")]
    #[inline]
    fn bound<const MAX: bool>(x: __m256, a: __m256, b: __m256) -> __m256 {
        let (p, q) = (_mm256_mul_ps(x, a), _mm256_mul_ps(x, b));
        if MAX {
            _mm256_max_ps(p, q)
        } else {
            _mm256_min_ps(p, q)
        }
    }

    /// The least of a register's lanes or, with `MAX`, the greatest.
    #[target_feature(enable = "avx")]
    #[inline]
    fn reduce<const MAX: bool>(v: __m256) -> f32 {
        let half = pick::<MAX>(_mm256_castps256_ps128(v), _mm256_extractf128_ps::<1>(v));
        let quarter = pick::<MAX>(half, _mm_movehl_ps(half, half));
        _mm_cvtss_f32(pick::<MAX>(quarter, _mm_shuffle_ps::<1>(quarter, quarter)))
    }

    /// `min(a, b)` or, with `MAX`, `max(a, b)`, lane by lane.
    #[target_feature(enable = "avx")]
    #[inline]
    fn pick<const MAX: bool>(a: __m128, b: __m128) -> __m128 {
        if MAX {
            _mm_max_ps(a, b)
        } else {
            _mm_min_ps(a, b)
        }
    }

    /// The least of a register's lanes.
    #[target_feature(enable = "avx")]
    #[inline]
    fn least(v: __m256) -> f32 {
        reduce::<false>(v)
    }

    /// The greatest of a register's lanes.
    #[target_feature(enable = "avx")]
    #[inline]
    fn most(v: __m256) -> f32 {
        reduce::<true>(v)
    }

    /// Widens `near` and `far` as the single-ray test does, and compares.
    #[target_feature(enable = "avx")]
    #[inline]
    fn widened(near: __m256, far: __m256) -> (u32, __m256) {
        let shrink = _mm256_set1_ps(SHRINK);
        let grow = _mm256_set1_ps(GROW);
        let near = _mm256_min_ps(_mm256_mul_ps(near, shrink), _mm256_mul_ps(near, grow));
        let far = _mm256_max_ps(_mm256_mul_ps(far, shrink), _mm256_mul_ps(far, grow));
        let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, far)) as u32;
        (mask, near)
    }

    /// A packet's rays, prepared for both tests.
    #[derive(Debug)]
    pub(in crate::accel::bvh) struct Lanes {
        /// Per lane, as the single-ray test has them.
        entry_origin: [[f32; 8]; 3],
        exit_origin: [[f32; 8]; 3],
        inv_dir: [[f32; 8]; 3],
        t_min: [f32; 8],
        /// The rows every ray enters and leaves through.
        rows: [(usize, usize); 3],
        /// The packet's bounds: the origin that bounds the entries from
        /// below and the one that bounds the exits from above, the least
        /// and the greatest inverse direction, the least `t_min`.
        entry_bound: [f32; 3],
        exit_bound: [f32; 3],
        inv_low: [f32; 3],
        inv_high: [f32; 3],
        t_min_low: f32,
    }

    impl Lanes {
        /// The lanes of `rays` (one to eight; the lanes past them repeat
        /// the first ray, so they widen no bound), or `None` when the
        /// packet cannot be walked together.
        #[target_feature(enable = "avx")]
        pub(in crate::accel::bvh) fn new(rays: &[Ray]) -> Option<Self> {
            let first = &rays[0];
            let shared = rays.iter().all(|ray| {
                ray.t_min.to_bits() == first.t_min.to_bits()
                    && (0..3).all(|axis| ray.origin[axis].to_bits() == first.origin[axis].to_bits())
            });
            if shared && let Some(lanes) = Self::sharing_start(rays) {
                return Some(lanes);
            }
            Self::each_its_own(rays)
        }

        /// [`Self::new`] for rays that share the first's origin and `t_min`
        /// bit for bit, as a pinhole camera's rays do, or `None` (the
        /// general way then decides). Where every lane's direction has the
        /// first's signs, each lane's planes are the first's but for the
        /// inverse direction, which is converted eight lanes at a time.
        #[target_feature(enable = "avx")]
        pub(super) fn sharing_start(rays: &[Ray]) -> Option<Self> {
            let first = Planes::new(&rays[0]);
            let finite = |row: [f32; 3]| row.iter().all(|o| o.abs() < f32::INFINITY);
            if !(first.t_min.is_finite() && finite(first.entry_origin) && finite(first.exit_origin))
            {
                return None;
            }
            let mut lanes = Self::repeating(&first);
            let never_culls = _mm256_set1_ps(NEVER_CULLS);
            let magnitude = _mm256_set1_ps(f32::from_bits(0x7fff_ffff));
            for axis in 0..3 {
                let mut inv = [rays[0].inv_dir[axis]; PACKET_LANES];
                for (lane, ray) in rays.iter().enumerate().skip(1) {
                    inv[lane] = ray.inv_dir[axis];
                }
                // SAFETY: `inv` is eight readable `f64`s; the loads are
                // unaligned.
                let (low, high) = unsafe {
                    (
                        _mm256_cvtpd_ps(_mm256_loadu_pd(inv.as_ptr())),
                        _mm256_cvtpd_ps(_mm256_loadu_pd(inv[4..].as_ptr())),
                    )
                };
                // `i as f32`, lane by lane, as `Planes::new` converts it.
                let v = _mm256_insertf128_ps::<1>(_mm256_castps128_ps256(low), high);
                // Beyond `NEVER_CULLS` (or beyond `f32`, or NaN) a lane
                // is not walked together.
                let ordinary =
                    _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_and_ps(v, magnitude), never_culls);
                let negative = _mm256_movemask_ps(v) as u32;
                let below =
                    _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(v, _mm256_setzero_ps())) as u32;
                let all = (1 << PACKET_LANES) - 1;
                let uniform = |mask: u32| mask == 0 || mask == all;
                if _mm256_movemask_ps(ordinary) as u32 != all
                    || !uniform(negative)
                    || !uniform(below)
                    || (negative != 0) != first.inv_dir[axis].is_sign_negative()
                {
                    return None;
                }
                lanes.inv_dir[axis] = store(v);
                (lanes.inv_low[axis], lanes.inv_high[axis]) = (least(v), most(v));
            }
            Some(lanes)
        }

        /// [`Self::new`] for any rays: each lane's planes of its own.
        #[target_feature(enable = "avx")]
        pub(super) fn each_its_own(rays: &[Ray]) -> Option<Self> {
            let first = Planes::new(&rays[0]);
            let mut lanes = Self::repeating(&first);
            let mut ordinary = first.t_min.is_finite();
            for (lane, ray) in rays.iter().enumerate() {
                let p = if lane == 0 { first } else { Planes::new(ray) };
                ordinary &= p.rows == first.rows && p.t_min.is_finite();
                for axis in 0..3 {
                    // False for NaN too.
                    ordinary &= p.inv_dir[axis].abs() < NEVER_CULLS
                        && p.entry_origin[axis].abs() < f32::INFINITY
                        && p.exit_origin[axis].abs() < f32::INFINITY;
                    lanes.entry_origin[axis][lane] = p.entry_origin[axis];
                    lanes.exit_origin[axis][lane] = p.exit_origin[axis];
                    lanes.inv_dir[axis][lane] = p.inv_dir[axis];
                }
                lanes.t_min[lane] = p.t_min;
            }
            if !ordinary {
                return None;
            }
            for axis in 0..3 {
                // (p − o)·i falls as o grows where i > 0 and rises where
                // i < 0.
                let positive = first.rows[axis].0 == axis;
                let (entry, exit) = (
                    load(&lanes.entry_origin[axis]),
                    load(&lanes.exit_origin[axis]),
                );
                (lanes.entry_bound[axis], lanes.exit_bound[axis]) = if positive {
                    (most(entry), least(exit))
                } else {
                    (least(entry), most(exit))
                };
                let inv = load(&lanes.inv_dir[axis]);
                (lanes.inv_low[axis], lanes.inv_high[axis]) = (least(inv), most(inv));
            }
            lanes.t_min_low = least(load(&lanes.t_min));
            Some(lanes)
        }

        /// Every lane the ray with planes `first`, bounds included.
        fn repeating(first: &Planes) -> Self {
            Self {
                entry_origin: first.entry_origin.map(|o| [o; PACKET_LANES]),
                exit_origin: first.exit_origin.map(|o| [o; PACKET_LANES]),
                inv_dir: first.inv_dir.map(|i| [i; PACKET_LANES]),
                t_min: [first.t_min; PACKET_LANES],
                rows: first.rows,
                entry_bound: first.entry_origin,
                exit_bound: first.exit_origin,
                inv_low: first.inv_dir,
                inv_high: first.inv_dir,
                t_min_low: first.t_min,
            }
        }

        /// Pushes the children of `node` that some lane of `active` may
        /// meet closer than its `far` on `stack`, nearest on top, each with
        /// the lanes that may: for a leaf, those its lane-by-lane test
        /// keeps; for a node, those too with `EXACT`, else all of `active`.
        /// The interval test alone is tight for rays from one point (camera
        /// rays); rays from points apart (shadow rays) need `EXACT`, without
        /// which a packet visits far more nodes than its rays alone would.
        #[target_feature(enable = "avx")]
        #[inline]
        pub(in crate::accel::bvh) fn push_children<const N: usize, const EXACT: bool>(
            &self,
            node: &BvhNode,
            active: u32,
            far: &[f32; PACKET_LANES],
            far_most: f32,
            stack: &mut Stack<PacketEntry, N>,
        ) {
            let (candidates, packet_near) = self.interval(node, far_most);
            let floor = stack.len();
            let mut bits = candidates;
            while bits != 0 {
                let slot = bits.trailing_zeros() as usize % WIDTH;
                bits &= bits - 1;
                let (lanes, near) = if EXACT || node.counts[slot] > 0 {
                    self.lane_by_lane(node, slot, far)
                } else {
                    (active, [packet_near[slot]; PACKET_LANES])
                };
                let lanes = lanes & active;
                if lanes == 0 {
                    continue;
                }
                let entry = PacketEntry {
                    child: node.children[slot],
                    count: node.counts[slot],
                    lanes,
                    t: packet_near[slot],
                    near,
                };
                stack.insert_above(floor, entry, |new, other| other.t < new.t);
            }
        }

        /// The lanes whose `near` is not beyond their `far`.
        #[target_feature(enable = "avx")]
        #[inline]
        pub(super) fn before(&self, near: &[f32; 8], far: &[f32; 8]) -> u32 {
            _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(load(near), load(far))) as u32
        }

        /// The packet's test of all of `node`'s children: those some ray may
        /// meet before `far_most`, and a lower bound on where any enters
        /// each.
        #[target_feature(enable = "avx")]
        #[inline]
        pub(super) fn interval(&self, node: &BvhNode, far_most: f32) -> (u32, [f32; WIDTH]) {
            let mut near = _mm256_set1_ps(self.t_min_low);
            let mut far = _mm256_set1_ps(far_most);
            for axis in 0..3 {
                let (enter, exit) = self.rows[axis];
                let low = _mm256_set1_ps(self.inv_low[axis]);
                let high = _mm256_set1_ps(self.inv_high[axis]);
                let to_entry = _mm256_sub_ps(
                    load(&node.bounds[enter]),
                    _mm256_set1_ps(self.entry_bound[axis]),
                );
                let to_exit = _mm256_sub_ps(
                    load(&node.bounds[exit]),
                    _mm256_set1_ps(self.exit_bound[axis]),
                );
                near = _mm256_max_ps(bound::<false>(to_entry, low, high), near);
                far = _mm256_min_ps(bound::<true>(to_exit, low, high), far);
            }
            let (mask, near) = widened(near, far);
            (mask, store(near))
        }

        /// Slot `slot` of `node` tested for each lane with exactly the
        /// single-ray test's operations: the lanes that may meet it before
        /// their `far`, and where each enters it.
        #[target_feature(enable = "avx")]
        #[inline]
        pub(super) fn lane_by_lane(
            &self,
            node: &BvhNode,
            slot: usize,
            far: &[f32; PACKET_LANES],
        ) -> (u32, [f32; PACKET_LANES]) {
            let mut near = load(&self.t_min);
            let mut far = load(far);
            for axis in 0..3 {
                let (enter, exit) = self.rows[axis];
                let inv = load(&self.inv_dir[axis]);
                let t_enter = _mm256_mul_ps(
                    _mm256_sub_ps(
                        _mm256_set1_ps(node.bounds[enter][slot]),
                        load(&self.entry_origin[axis]),
                    ),
                    inv,
                );
                let t_exit = _mm256_mul_ps(
                    _mm256_sub_ps(
                        _mm256_set1_ps(node.bounds[exit][slot]),
                        load(&self.exit_origin[axis]),
                    ),
                    inv,
                );
                near = _mm256_max_ps(t_enter, near);
                far = _mm256_min_ps(t_exit, far);
            }
            let (mask, near) = widened(near, far);
            (mask, store(near))
        }
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::avx::Lanes;
    use super::*;
    use crate::accel::QueryContext;
    use crate::accel::bvh::slabs::SlabTest;
    use crate::accel::bvh::slabs::tests::random_cases;
    use crate::accel::bvh::slabs_avx::Avx;
    use crate::math::random::Rng;
    use crate::math::{Aabb, Vec3};

    /// Packets of eight rays from near one point, spread by up to `spread`
    /// around one direction, as a camera's rays are.
    fn packets(rng: &mut Rng, count: usize, spread: f64) -> Vec<Vec<Ray>> {
        (0..count)
            .map(|_| {
                let origin = rng.point_in(Vec3::splat(-12.0), Vec3::splat(12.0));
                let towards = rng.point_in(Vec3::splat(-3.0), Vec3::splat(3.0)) - origin;
                let lanes = 1 + rng.below(PACKET_LANES as u32) as usize;
                (0..lanes)
                    .map(|_| {
                        let dir = towards + rng.point_in(Vec3::splat(-spread), Vec3::splat(spread));
                        let mut ray = Ray::new(origin, dir.normalize());
                        if rng.range(0.0, 1.0) < 0.3 {
                            ray.t_max = rng.range(5.0, 20.0);
                        }
                        ray
                    })
                    .collect()
            })
            .collect()
    }

    /// Random boxes, as primitives hit where the ray enters them.
    fn boxes(rng: &mut Rng, n: usize) -> Vec<Aabb> {
        (0..n)
            .map(|_| {
                let c = rng.point_in(Vec3::splat(-4.0), Vec3::splat(4.0));
                let half = rng.point_in(Vec3::splat(0.01), Vec3::splat(0.4));
                Aabb::new(c - half, c + half)
            })
            .collect()
    }

    /// The closest box `ray` enters in its interval, and which.
    fn single(bvh: &Bvh, boxes: &[Aabb], ray: &Ray) -> Option<(u32, f64)> {
        let mut which = None;
        let t = bvh.intersect(ray, &mut QueryContext::default(), |i, t_max| {
            let mut r = *ray;
            r.t_max = t_max;
            let (near, _) = boxes[i as usize].intersect_ray(&r)?;
            (near < t_max).then(|| {
                which = Some(i);
                near
            })
        })?;
        Some((which?, t))
    }

    #[test]
    fn lanes_of_rays_sharing_a_start_are_the_lanes_each_ray_makes_alone() {
        if !crate::math::test_support::has_avx_or_skip_allowed() {
            return;
        }
        // Packets from one origin, now and then with a direction component
        // at zero, negative zero, too small for an `f32` inverse or between
        // `NEVER_CULLS` and `f32::MAX`, or with signs that differ.
        let mut rng = Rng::new(31);
        let (mut shared, mut general) = (0, 0);
        for case in 0..20_000 {
            let origin = rng.point_in(Vec3::splat(-50.0), Vec3::splat(50.0));
            let t_min = if case % 3 == 0 {
                0.0
            } else {
                rng.range(0.0, 1.0)
            };
            let base = rng.unit_vector();
            let spread = [0.001, 0.1, 1.0][case % 3];
            let count = 1 + rng.below(PACKET_LANES as u32) as usize;
            let rays: Vec<Ray> = (0..count)
                .map(|_| {
                    let mut dir = base + rng.point_in(Vec3::splat(-spread), Vec3::splat(spread));
                    let axis = rng.below(3) as usize;
                    match rng.below(60) {
                        0 => dir[axis] = 0.0,
                        1 => dir[axis] = -0.0,
                        2 => dir[axis] = 1e-40_f64.copysign(dir[axis]),
                        3 => dir[axis] = 1e-35_f64.copysign(dir[axis]),
                        4 => dir[axis] = 1e50_f64.copysign(dir[axis]),
                        _ => {}
                    }
                    let mut ray = Ray::new(origin, dir);
                    ray.t_min = t_min;
                    ray
                })
                .collect();
            // SAFETY (all three): the processor has AVX.
            let alone = format!("{:?}", unsafe { Lanes::each_its_own(&rays) });
            assert_eq!(format!("{:?}", unsafe { Lanes::new(&rays) }), alone);
            match unsafe { Lanes::sharing_start(&rays) } {
                Some(lanes) => {
                    shared += 1;
                    assert_eq!(format!("{:?}", Some(lanes)), alone);
                }
                None => general += 1,
            }
        }
        assert!(shared > 5000 && general > 1000, "{shared} {general}");
    }

    #[test]
    fn the_interval_test_keeps_every_child_a_lane_keeps_and_lanes_test_as_single_rays() {
        if !crate::math::test_support::has_avx_or_skip_allowed() {
            return;
        }
        // Each random node against eight rays of one octant, from origins
        // and in directions spread widely, some with short intervals.
        let mut rng = Rng::new(11);
        let mut walked = 0;
        for (node, _, _) in random_cases(11) {
            let signs = rng.unit_vector();
            let base = rng.point_in(Vec3::splat(-8.0), Vec3::splat(8.0));
            let group: Vec<(Ray, f32)> = (0..PACKET_LANES)
                .map(|_| {
                    let origin = base + rng.point_in(Vec3::splat(-3.0), Vec3::splat(3.0));
                    let d = rng.unit_vector();
                    let dir = Vec3::new(
                        d.x.abs().copysign(signs.x),
                        d.y.abs().copysign(signs.y),
                        d.z.abs().copysign(signs.z),
                    );
                    let t_max = if rng.range(0.0, 1.0) < 0.5 {
                        f32::INFINITY
                    } else {
                        rng.range(0.0, 10.0) as f32
                    };
                    (Ray::new(origin, dir), t_max)
                })
                .collect();
            let rays: Vec<Ray> = group.iter().map(|(ray, _)| *ray).collect();
            // SAFETY: the processor has AVX.
            let Some(lanes) = (unsafe { Lanes::new(&rays) }) else {
                continue;
            };
            walked += 1;
            let mut far = [f32::NEG_INFINITY; PACKET_LANES];
            for (lane, (_, t_max)) in group.iter().enumerate() {
                far[lane] = *t_max;
            }
            let far_most = far.iter().fold(f32::NEG_INFINITY, |a, &b| a.max(b));
            // SAFETY: the processor has AVX.
            let (kept, packet_near) = unsafe { lanes.interval(&node, far_most) };
            for (lane, ray) in rays.iter().enumerate() {
                let (mask, near) = Avx::new(ray).test(&node, far[lane]);
                assert_eq!(mask & !kept, 0, "lane {lane}");
                for slot in (0..8).filter(|s| mask >> s & 1 == 1) {
                    assert!(packet_near[slot] <= near[slot]);
                    // SAFETY: as above.
                    let (lane_mask, lane_near) = unsafe { lanes.lane_by_lane(&node, slot, &far) };
                    assert_eq!(lane_mask >> lane & 1, 1);
                    assert_eq!(lane_near[lane].to_bits(), near[slot].to_bits());
                }
            }
        }
        assert!(walked > 1900, "{walked}");
    }

    #[test]
    fn packets_find_the_single_walks_closest_hits() {
        if !crate::accel::kernel::walks_with_avx_or_skip() {
            return;
        }
        let mut rng = Rng::new(21);
        let boxes = boxes(&mut rng, 3000);
        let bvh = Bvh::build(&boxes);
        let (mut together, mut hits) = (0, 0);
        for spread in [0.001, 0.05, 0.6] {
            for rays in packets(&mut rng, 300, spread) {
                let mut found = [None; PACKET_LANES];
                let mut counters = TraversalCounters::default();
                let alone = bvh.intersect_packet_in_leaf_order(
                    &rays,
                    crate::accel::Backend::current(),
                    &mut counters,
                    |lane, range, t_max| {
                        let mut r = rays[lane];
                        r.t_max = t_max;
                        let mut best = None;
                        for entry in range {
                            let i = bvh.indices[entry as usize];
                            if let Some((near, _)) = boxes[i as usize].intersect_ray(&r)
                                && near < r.t_max
                            {
                                r.t_max = near;
                                best = Some(near);
                                found[lane] = Some((i, near));
                            }
                        }
                        best
                    },
                );
                let Some(alone) = alone else { continue };
                together += 1;
                for (lane, ray) in rays.iter().enumerate() {
                    if alone >> lane & 1 == 0 {
                        assert_eq!(found[lane], single(&bvh, &boxes, ray), "{ray:?}");
                        hits += usize::from(found[lane].is_some());
                    }
                }
            }
        }
        assert!(together > 600 && hits > 500, "{together} {hits}");
    }

    #[test]
    fn lanes_with_tied_hits_are_left_to_the_single_walk() {
        if !crate::accel::kernel::walks_with_avx_or_skip() {
            return;
        }
        // Boxes across the plane z = 0, each hit where the ray crosses the
        // plane if that point lies in it: a ray meets several at exactly
        // the same parameter, and the single walk keeps the first it
        // visits, which the packet, visiting in its own order, cannot
        // know; it must give such lanes back.
        let mut rng = Rng::new(22);
        let boxes: Vec<Aabb> = (0..500)
            .map(|_| {
                let c = rng.point_in(Vec3::new(-4.0, -4.0, -0.3), Vec3::new(4.0, 4.0, 0.3));
                let half = rng.point_in(Vec3::new(0.05, 0.05, 0.4), Vec3::new(0.5, 0.5, 0.6));
                Aabb::new(c - half, c + half)
            })
            .collect();
        let bvh = Bvh::build(&boxes);
        let meets = |i: u32, ray: &Ray, t_max: f64| {
            let t = -ray.origin.z / ray.dir.z;
            let b = &boxes[i as usize];
            let p = ray.at(t);
            let inside = (0..2).all(|a| b.min[a] <= p[a] && p[a] <= b.max[a]);
            (t > ray.t_min && t < t_max && inside).then_some(t)
        };
        let (mut given_back, mut kept) = (0, 0);
        for rays in packets(&mut rng, 400, 0.02) {
            let mut found = [None; PACKET_LANES];
            let mut counters = TraversalCounters::default();
            let Some(alone) = bvh.intersect_packet_in_leaf_order(
                &rays,
                crate::accel::Backend::current(),
                &mut counters,
                |lane, range, mut t_max| {
                    let mut best = None;
                    for entry in range {
                        let i = bvh.indices[entry as usize];
                        if let Some(t) = meets(i, &rays[lane], t_max) {
                            t_max = t;
                            best = Some(t);
                            found[lane] = Some(i);
                        }
                    }
                    best
                },
            ) else {
                continue;
            };
            for (lane, ray) in rays.iter().enumerate() {
                let mut first = None;
                bvh.intersect(ray, &mut QueryContext::default(), |i, t_max| {
                    let t = meets(i, ray, t_max)?;
                    first = Some(i);
                    Some(t)
                });
                if alone >> lane & 1 == 1 {
                    given_back += 1;
                } else {
                    assert_eq!(found[lane], first, "{ray:?}");
                    kept += usize::from(first.is_some());
                }
            }
        }
        assert!(given_back > 300 && kept > 150, "{given_back} {kept}");
    }

    #[test]
    fn mixed_signs_and_axis_parallel_rays_are_not_walked_together() {
        if !crate::accel::kernel::walks_with_avx_or_skip() {
            return;
        }
        let forward = Ray::new(Vec3::ZERO, Vec3::new(1.0, 0.5, 0.25).normalize());
        let back = Ray::new(Vec3::ZERO, Vec3::new(-1.0, 0.5, 0.25).normalize());
        let parallel = Ray::new(Vec3::ZERO, Vec3::X);
        let far = Ray::new(Vec3::splat(1e300), forward.dir);
        // SAFETY: the processor has AVX.
        let lanes = |rays: &[Ray]| unsafe { Lanes::new(rays) }.is_some();
        assert!(lanes(&[forward, forward]));
        assert!(!lanes(&[forward, back]));
        assert!(!lanes(&[forward, parallel]));
        assert!(!lanes(&[forward, far]));
        let bvh = Bvh::build(&[Aabb::new(Vec3::splat(1.0), Vec3::splat(2.0))]);
        let mut counters = TraversalCounters::default();
        let walk = |rays: &[Ray], counters: &mut TraversalCounters| {
            bvh.intersect_packet_in_leaf_order(
                rays,
                crate::accel::Backend::current(),
                counters,
                |_, _, _| None,
            )
        };
        assert_eq!(walk(&[forward, back], &mut counters), None);
        assert_eq!(walk(&[], &mut counters), None);
        assert_eq!(walk(&[forward; PACKET_LANES + 1], &mut counters), None);
        assert_eq!(walk(&[forward; 3], &mut counters), Some(0));
    }
}
