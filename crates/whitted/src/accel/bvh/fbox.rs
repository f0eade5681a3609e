//! The build's box: `f32` corners in SIMD lanes, rounded outward from the
//! primitives' exact boxes.

use super::node::{round_down, round_up};
use crate::math::Aabb;
use glam::{Vec3A, Vec3Swizzles};

/// A box rounded outward to `f32`, its corners in SIMD lanes: the build's
/// unions are one `minps` and one `maxps` (the `f64` boxes' NaN-aware
/// minima and maxima took most of the binning's instructions). Rounding
/// commutes with unions, so the nodes' boxes are those of the exact boxes
/// rounded outward.
#[derive(Clone, Copy, Debug)]
pub(super) struct FBox {
    /// Smallest corner, rounded down.
    pub(super) min: Vec3A,
    /// Largest corner, rounded up.
    pub(super) max: Vec3A,
}

impl FBox {
    /// Contains nothing; the identity of [`FBox::union`].
    pub(super) const EMPTY: Self = Self {
        min: Vec3A::INFINITY,
        max: Vec3A::NEG_INFINITY,
    };

    /// The smallest `f32` box around `exact`.
    pub(super) fn outward(exact: &Aabb) -> Self {
        Self {
            min: Vec3A::from_array(exact.min.to_array().map(round_down)),
            max: Vec3A::from_array(exact.max.to_array().map(round_up)),
        }
    }

    /// The smallest box around both.
    #[inline]
    pub(super) fn union(&self, other: &Self) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// The smallest box around `self` and `p`.
    #[inline]
    pub(super) fn union_point(&self, p: Vec3A) -> Self {
        Self {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// The point used to sort and bin the box: the centre of its corners
    /// clamped to the finite `f32` range, so it is finite even for an empty
    /// box, an infinite one or one with NaN corners (whose centre means
    /// nothing; they only need a place).
    pub(super) fn centre(&self) -> Vec3A {
        let clamp = |v: Vec3A| v.max(Vec3A::splat(f32::MIN)).min(Vec3A::splat(f32::MAX));
        0.5 * clamp(self.min) + 0.5 * clamp(self.max)
    }

    /// The same box in `f64`, exactly.
    pub(super) fn to_aabb(self) -> Aabb {
        Aabb {
            min: self.min.as_dvec3(),
            max: self.max.as_dvec3(),
        }
    }

    /// Half the surface area, in `f32` SIMD lanes; meaningless for an
    /// empty box. The sweeps compute one per candidate plane at every node,
    /// which in `f64` with `Aabb`'s emptiness check took more instructions
    /// than the binning.
    #[inline]
    pub(super) fn half_area(&self) -> f32 {
        let d = self.max - self.min;
        d.dot(d.yzx())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

    #[test]
    fn outward_rounding_contains_the_exact_box() {
        let exact = Aabb::new(
            Vec3::new(0.1, -0.3, 1e-9),
            Vec3::new(0.7, 2.0 / 3.0, 1e9 + 1.0),
        );
        let rounded = FBox::outward(&exact).to_aabb();
        assert!(rounded.min.cmple(exact.min).all() && rounded.max.cmpge(exact.max).all());
    }

    #[test]
    fn centres_are_finite_for_empty_infinite_and_nan_boxes() {
        let nan = Aabb::new(Vec3::splat(f64::NAN), Vec3::ONE);
        let huge = Aabb::new(Vec3::splat(-1e300), Vec3::splat(1e300));
        for b in [FBox::EMPTY, FBox::outward(&huge), FBox::outward(&nan)] {
            assert!(b.centre().is_finite(), "{b:?}");
        }
        let unit = FBox::outward(&Aabb::new(Vec3::ZERO, Vec3::new(1.0, 2.0, 4.0)));
        assert_eq!(unit.centre(), Vec3A::new(0.5, 1.0, 2.0));
        assert_eq!(unit.half_area(), 2.0 + 8.0 + 4.0);
    }
}
