//! The nodes: the 256-byte eight-wide node the queries walk, the 32-byte
//! binary node the build works in, and the outward rounding of their `f32`
//! boxes.
//!
//! Boxes are rounded outward from `f64` to `f32`, so a node always contains
//! the exact boxes below it and culling against it stays conservative.

use crate::math::{Aabb, Vec3};
use std::alloc::{Layout, alloc_zeroed, handle_alloc_error};

/// Children per node of a [`super::Bvh`].
pub const WIDTH: usize = 8;

/// One node of a [`super::Bvh`]: up to [`WIDTH`] children, their boxes
/// stored axis by axis so one SIMD slab test covers all of them.
///
/// Child slot `i` is a leaf when `counts[i] > 0` (the primitives listed at
/// `children[i]..children[i] + counts[i]` of the BVH's index array), an
/// interior node at `children[i]` otherwise. An unused slot has count 0,
/// child [`u32::MAX`] and the empty box (`+∞` minimum, `−∞` maximum), which
/// no ray meets.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct BvhNode {
    /// `[min_x, min_y, min_z, max_x, max_y, max_z]`, each per child slot;
    /// minima rounded down, maxima up.
    pub bounds: [[f32; WIDTH]; 6],
    /// Interior: the child node's index. Leaf: its first index-array entry.
    pub children: [u32; WIDTH],
    /// Primitives of a leaf slot; 0 for an interior or unused slot.
    pub counts: [u32; WIDTH],
}

const _: () = assert!(size_of::<BvhNode>() == 256);

impl Default for BvhNode {
    /// Unused slots only.
    fn default() -> Self {
        let (min, max) = ([f32::INFINITY; WIDTH], [f32::NEG_INFINITY; WIDTH]);
        Self {
            bounds: [min, min, min, max, max, max],
            children: [u32::MAX; WIDTH],
            counts: [0; WIDTH],
        }
    }
}

impl BvhNode {
    /// Puts a child with box `bounds` in slot `slot`.
    pub(super) fn set_child(&mut self, slot: usize, bounds: &Aabb, child: u32, count: u32) {
        for axis in 0..3 {
            self.bounds[axis][slot] = round_down(bounds.min[axis]);
            self.bounds[axis + 3][slot] = round_up(bounds.max[axis]);
        }
        self.children[slot] = child;
        self.counts[slot] = count;
    }

    /// Slot `slot`'s box, exactly, in `f64` (empty for an unused slot).
    pub fn child_bounds(&self, slot: usize) -> Aabb {
        let coordinate = |axis: usize| f64::from(self.bounds[axis][slot]);
        Aabb {
            min: Vec3::new(coordinate(0), coordinate(1), coordinate(2)),
            max: Vec3::new(coordinate(3), coordinate(4), coordinate(5)),
        }
    }

    /// True when slot `slot` holds a child (leaf or interior).
    pub fn is_used(&self, slot: usize) -> bool {
        self.counts[slot] > 0 || self.children[slot] != u32::MAX
    }
}

/// A node of the binary tree the build makes before collapsing it: 32
/// bytes, its box already rounded outward to `f32` (half the scratch memory
/// of an `f64` box, which made the build slower).
///
/// An interior node (`count == 0`) has its two children at `first` and
/// `first + 1`; a leaf holds the `count` primitives listed at
/// `first..first + count` of the reordered index array.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct BinaryNode {
    /// Smallest corner, rounded down.
    pub min: [f32; 3],
    /// Largest corner, rounded up.
    pub max: [f32; 3],
    /// First child (interior) or first entry in the index array (leaf).
    pub first: u32,
    /// Number of primitives of a leaf; 0 for an interior node.
    pub count: u32,
}

const _: () = assert!(size_of::<BinaryNode>() == 32);

impl BinaryNode {
    /// A node over `bounds`, rounded outward.
    pub fn new(bounds: &Aabb, first: u32, count: u32) -> Self {
        Self {
            min: bounds.min.to_array().map(round_down),
            max: bounds.max.to_array().map(round_up),
            first,
            count,
        }
    }

    /// `len` nodes, each the default (all bits zero), in memory the
    /// allocator hands out zeroed: the system maps its pages in as the
    /// build first writes them, on the threads that write them, and never
    /// those of slots no subtree uses. `vec!` would fill every slot on one
    /// thread before the build started (see docs/performance-log.md, BVH build).
    pub fn zeroed_vec(len: usize) -> Vec<Self> {
        let Ok(layout) = Layout::array::<Self>(len) else {
            panic!("{len} BVH build nodes do not fit in memory");
        };
        if layout.size() == 0 {
            return Vec::new();
        }
        // SAFETY: the layout's size is not zero.
        let ptr = unsafe { alloc_zeroed(layout) }.cast::<Self>();
        if ptr.is_null() {
            handle_alloc_error(layout);
        }
        // SAFETY: `ptr` was allocated by the global allocator with the
        // layout of `len` nodes, and all-zero bits are a valid node (its
        // fields are `f32`s and `u32`s, for which they mean 0, and it has
        // no padding), so the `len` elements are initialised.
        unsafe { Vec::from_raw_parts(ptr, len, len) }
    }

    /// True for a leaf.
    pub fn is_leaf(&self) -> bool {
        self.count != 0
    }

    /// The node's box, exactly, in `f64`.
    pub fn bounds(&self) -> Aabb {
        Aabb {
            min: Vec3::from_array(self.min.map(f64::from)),
            max: Vec3::from_array(self.max.map(f64::from)),
        }
    }
}

/// The largest `f32` not above `x` (`-∞` below the `f32` range).
///
/// Every ray's walk rounds its origin, `t_min` and `t_max` so (seven
/// times), and whether the nearest `f32` lies above `x` goes either way at
/// random from one ray to the next: the step to the next `f32` below is
/// written as a select, not a branch, and without `f32::next_down`'s own
/// branches for values it never meets here. When the nearest `f32` is above
/// `x` it is neither NaN, `+0` (only a negative `x` rounds up to zero, and
/// to `-0`) nor `-∞`, so one step of the bits towards `-∞` is the next
/// `f32` below: down for a positive value (`+∞` to `f32::MAX` included), up
/// for a negative one (`-0` to the least negative `f32`).
#[inline(always)]
pub fn round_down(x: f64) -> f32 {
    let f = x as f32;
    let bits = f.to_bits();
    let negative = bits >> 31;
    let below = f32::from_bits(bits.wrapping_add(negative << 1).wrapping_sub(1));
    if f64::from(f) > x { below } else { f }
}

/// The smallest `f32` not below `x` (`+∞` above the `f32` range); the
/// mirror of [`round_down`]: when the nearest `f32` is below `x` it is
/// neither NaN, `-0` nor `+∞`, and one step of the bits towards `+∞` is
/// the next `f32` above.
#[inline(always)]
pub fn round_up(x: f64) -> f32 {
    let f = x as f32;
    let bits = f.to_bits();
    let negative = bits >> 31;
    let above = f32::from_bits(bits.wrapping_add(1).wrapping_sub(negative << 1));
    if f64::from(f) < x { above } else { f }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_node_is_256_bytes_on_a_cache_line_boundary() {
        assert_eq!(size_of::<BvhNode>(), 256);
        assert_eq!(align_of::<BvhNode>(), 64);
    }

    #[test]
    fn zeroed_nodes_are_default_nodes() {
        assert_eq!(
            BinaryNode::zeroed_vec(1000),
            vec![BinaryNode::default(); 1000]
        );
        assert!(BinaryNode::zeroed_vec(0).is_empty());
    }

    #[test]
    fn rounding_is_outward_and_tight() {
        for x in [0.1, -0.1, 1.0 / 3.0, -7.25, 1e-40, 3e38, -3e38, 0.0] {
            let (down, up) = (round_down(x), round_up(x));
            assert!(f64::from(down) <= x && f64::from(up) >= x, "{x}");
            assert!(f64::from(down.next_up()) > x || f64::from(down) == x, "{x}");
            assert!(f64::from(up.next_down()) < x || f64::from(up) == x, "{x}");
        }
        assert_eq!(round_down(0.5), 0.5);
        assert_eq!(round_up(0.5), 0.5);
        assert_eq!(round_up(1e300), f32::INFINITY);
        assert_eq!(round_down(1e300), f32::MAX);
        assert_eq!(round_down(-1e300), f32::NEG_INFINITY);
    }

    #[test]
    fn rounding_agrees_with_the_next_f32_of_the_standard_library() {
        let reference_down = |x: f64| {
            let f = x as f32;
            if f64::from(f) > x { f.next_down() } else { f }
        };
        let reference_up = |x: f64| {
            let f = x as f32;
            if f64::from(f) < x { f.next_up() } else { f }
        };
        let tiny = f64::from(f32::from_bits(1));
        let max = f64::from(f32::MAX);
        let special = [
            0.0,
            -0.0,
            tiny,
            -tiny,
            tiny / 3.0,
            -tiny / 3.0,
            1e-50,
            -1e-50,
            1e-39,
            -1e-39,
            max,
            -max,
            max * (1.0 + 1e-9),
            -max * (1.0 + 1e-9),
            1e300,
            -1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MIN_POSITIVE,
            0.1,
            -0.1,
        ];
        let mut rng = crate::math::random::Rng::new(5);
        let random = (0..200_000).map(|i| {
            let bits = (u64::from(rng.next_u32()) << 32) | u64::from(rng.next_u32());
            let near = f64::from(f32::from_bits(rng.next_u32()));
            match i % 3 {
                // Any bits; values near an f32 of any size; values near zero.
                0 => f64::from_bits(bits),
                1 => near * (1.0 + (rng.uniform() - 0.5) * 1e-7),
                _ => (rng.uniform() - 0.5) * tiny * 1e3,
            }
        });
        for x in special.into_iter().chain(random) {
            assert_eq!(
                round_down(x).to_bits(),
                reference_down(x).to_bits(),
                "{x:e}"
            );
            assert_eq!(round_up(x).to_bits(), reference_up(x).to_bits(), "{x:e}");
        }
    }

    #[test]
    fn child_box_contains_the_exact_box() {
        let exact = Aabb::new(
            Vec3::new(0.1, -0.3, 1e-9),
            Vec3::new(0.7, 2.0 / 3.0, 1e9 + 1.0),
        );
        let mut node = BvhNode::default();
        node.set_child(2, &exact, 0, 1);
        let rounded = node.child_bounds(2);
        assert!(rounded.min.cmple(exact.min).all() && rounded.max.cmpge(exact.max).all());
        assert!(node.is_used(2) && !node.is_used(1));
    }
}
