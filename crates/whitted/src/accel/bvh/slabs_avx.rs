//! The slab test of `slabs` on one eight-lane AVX register, for processors
//! that have AVX (checked at run time by the walk's caller): the same
//! operations in the same order as [`Halves`](super::slabs::Halves), so the
//! two agree bit for bit (`vmaxps`/`vminps` keep the second operand when
//! the first is NaN, as `maxps`/`minps` do).

use std::arch::x86_64::{
    __m256, _CMP_LE_OQ, _mm256_cmp_ps, _mm256_loadu_ps, _mm256_max_ps, _mm256_min_ps,
    _mm256_movemask_ps, _mm256_mul_ps, _mm256_set1_ps, _mm256_storeu_ps, _mm256_sub_ps,
};

use super::node::{BvhNode, WIDTH};
use super::slabs::{GROW, Planes, SHRINK, SlabTest};

/// The test on one AVX register.
pub(super) struct Avx {
    entry_origin: [__m256; 3],
    exit_origin: [__m256; 3],
    inv_dir: [__m256; 3],
    rows: [(usize, usize); 3],
    t_min: __m256,
}

/// One row of eight `f32`s in a register.
#[target_feature(enable = "avx")]
#[inline]
fn load(row: &[f32; WIDTH]) -> __m256 {
    // SAFETY: `row` is eight readable `f32`s; the load is unaligned.
    unsafe { _mm256_loadu_ps(row.as_ptr()) }
}

impl Avx {
    #[target_feature(enable = "avx")]
    #[inline]
    fn prepare(planes: &Planes) -> Self {
        // Written out: closures (as for `array::map`) are compiled without
        // AVX and were not inlined.
        let [e0, e1, e2] = planes.entry_origin;
        let [x0, x1, x2] = planes.exit_origin;
        let [i0, i1, i2] = planes.inv_dir;
        Self {
            entry_origin: [_mm256_set1_ps(e0), _mm256_set1_ps(e1), _mm256_set1_ps(e2)],
            exit_origin: [_mm256_set1_ps(x0), _mm256_set1_ps(x1), _mm256_set1_ps(x2)],
            inv_dir: [_mm256_set1_ps(i0), _mm256_set1_ps(i1), _mm256_set1_ps(i2)],
            rows: planes.rows,
            t_min: _mm256_set1_ps(planes.t_min),
        }
    }

    #[target_feature(enable = "avx")]
    #[inline]
    fn run(&self, node: &BvhNode, t_max: f32) -> (u32, [f32; WIDTH]) {
        let mut near = self.t_min;
        let mut far = _mm256_set1_ps(t_max);
        for axis in 0..3 {
            let (enter, exit) = self.rows[axis];
            let t_enter = _mm256_mul_ps(
                _mm256_sub_ps(load(&node.bounds[enter]), self.entry_origin[axis]),
                self.inv_dir[axis],
            );
            let t_exit = _mm256_mul_ps(
                _mm256_sub_ps(load(&node.bounds[exit]), self.exit_origin[axis]),
                self.inv_dir[axis],
            );
            near = _mm256_max_ps(t_enter, near);
            far = _mm256_min_ps(t_exit, far);
        }
        let shrink = _mm256_set1_ps(SHRINK);
        let grow = _mm256_set1_ps(GROW);
        let near = _mm256_min_ps(_mm256_mul_ps(near, shrink), _mm256_mul_ps(near, grow));
        let far = _mm256_max_ps(_mm256_mul_ps(far, shrink), _mm256_mul_ps(far, grow));
        let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, far)) as u32;
        let mut lanes = [0.0; WIDTH];
        // SAFETY: `lanes` is eight writable `f32`s; the store is unaligned.
        unsafe { _mm256_storeu_ps(lanes.as_mut_ptr(), near) };
        (mask, lanes)
    }
}

impl SlabTest for Avx {
    #[inline(always)]
    fn new(planes: &Planes) -> Self {
        // SAFETY: an `Avx` is made only by walks entered after
        // `is_x86_feature_detected!("avx")` (see `traverse`).
        unsafe { Self::prepare(planes) }
    }

    #[inline(always)]
    fn test(&self, node: &BvhNode, t_max: f32) -> (u32, [f32; WIDTH]) {
        // SAFETY: as in `new`.
        unsafe { self.run(node, t_max) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::bvh::slabs::Halves;
    use crate::accel::bvh::slabs::tests::random_cases;

    #[test]
    fn agrees_with_the_two_halves_bit_for_bit() {
        if !crate::math::test_support::has_avx_or_skip_allowed() {
            return;
        }
        for (node, ray, t_max) in random_cases(9) {
            let planes = Planes::new(&ray);
            let (mask, near) = Avx::new(&planes).test(&node, t_max);
            let (expected_mask, expected_near) = Halves::new(&planes).test(&node, t_max);
            assert_eq!(mask, expected_mask, "{ray:?}");
            assert_eq!(near.map(f32::to_bits), expected_near.map(f32::to_bits));
        }
    }
}
