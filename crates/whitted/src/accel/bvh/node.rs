//! The flattened node: an `f32` box and a pair of `u32`, 32 bytes.
//!
//! Boxes are rounded outward from `f64` to `f32`, so a node always contains
//! the exact boxes below it and culling against it stays conservative.

use crate::math::{Aabb, Vec3};

/// One node of a [`super::Bvh`], interior or leaf.
///
/// An interior node (`count == 0`) has its two children at `first` and
/// `first + 1`; a leaf holds the `count` primitives listed at
/// `first..first + count` of the BVH's reordered index array.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct BvhNode {
    /// Smallest corner, rounded down.
    pub min: [f32; 3],
    /// Largest corner, rounded up.
    pub max: [f32; 3],
    /// First child (interior) or first entry in the index array (leaf).
    pub first: u32,
    /// Number of primitives of a leaf; 0 for an interior node.
    pub count: u32,
}

const _: () = assert!(size_of::<BvhNode>() == 32);

impl BvhNode {
    /// A leaf over index-array entries `first..first + count` (`count > 0`).
    pub fn leaf(bounds: &Aabb, first: u32, count: u32) -> Self {
        Self {
            min: bounds.min.to_array().map(round_down),
            max: bounds.max.to_array().map(round_up),
            first,
            count,
        }
    }

    /// An interior node whose children are at `first` and `first + 1`.
    pub fn interior(bounds: &Aabb, first: u32) -> Self {
        Self::leaf(bounds, first, 0)
    }

    /// True for a leaf.
    #[inline(always)]
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
pub fn round_down(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) > x { f.next_down() } else { f }
}

/// The smallest `f32` not below `x` (`+∞` above the `f32` range).
pub fn round_up(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) < x { f.next_up() } else { f }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_node_is_32_bytes() {
        assert_eq!(size_of::<BvhNode>(), 32);
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
    fn node_box_contains_the_exact_box() {
        let exact = Aabb::new(
            Vec3::new(0.1, -0.3, 1e-9),
            Vec3::new(0.7, 2.0 / 3.0, 1e9 + 1.0),
        );
        let node = BvhNode::leaf(&exact, 0, 1).bounds();
        assert!(node.min.cmple(exact.min).all() && node.max.cmpge(exact.max).all());
    }
}
