//! The slab test of `slabs` on one eight-lane AVX register, for processors
//! that have AVX (the AVX kernels of `accel/kernel.rs` use it): the same
//! operations in the same order as [`Halves`](super::slabs::Halves), so the
//! two agree bit for bit (`vmaxps`/`vminps` keep the second operand when
//! the first is NaN, as `maxps`/`minps` do). Its set-up computes the ray's
//! [`Planes`](super::slabs::Planes) its own way, for the three axes at
//! once; a test checks it against `Planes::new` bit for bit.

use std::arch::x86_64::{
    __m128, __m256, __m256d, _CMP_GT_OQ, _CMP_LE_OQ, _CMP_LT_OQ, _mm_add_epi32, _mm_blendv_ps,
    _mm_castps_si128, _mm_castsi128_ps, _mm_cmplt_ps, _mm_movemask_ps, _mm_set1_epi32, _mm_set1_ps,
    _mm_setzero_ps, _mm_shuffle_ps, _mm_srai_epi32, _mm_sub_epi32, _mm256_and_pd, _mm256_andnot_pd,
    _mm256_castpd_ps, _mm256_castps128_ps256, _mm256_castps256_ps128, _mm256_cmp_pd, _mm256_cmp_ps,
    _mm256_cvtpd_ps, _mm256_cvtps_pd, _mm256_extractf128_ps, _mm256_insertf128_ps, _mm256_loadu_ps,
    _mm256_max_ps, _mm256_min_ps, _mm256_movemask_ps, _mm256_mul_ps, _mm256_permute_ps,
    _mm256_set_pd, _mm256_set1_pd, _mm256_set1_ps, _mm256_storeu_ps, _mm256_sub_ps,
};

use super::node::{BvhNode, WIDTH, round_down};
use super::slabs::{GROW, NEVER_CULLS, SHRINK, SlabTest};
use crate::math::apart::coordinates_apart;
use crate::math::{Ray, Vec3};

/// The test on one AVX register.
pub(crate) struct Avx {
    entry_origin: [__m256; 3],
    exit_origin: [__m256; 3],
    inv_dir: [__m256; 3],
    rows: [(usize, usize); 3],
    t_min: __m256,
    /// The interval starts at or after zero (`-0` included), so every
    /// lane's `near` is too (see `run`).
    from_zero: bool,
}

/// One row of eight `f32`s in a register.
#[target_feature(enable = "avx")]
#[inline]
fn load(row: &[f32; WIDTH]) -> __m256 {
    // SAFETY: `row` is eight readable `f32`s; the load is unaligned.
    unsafe { _mm256_loadu_ps(row.as_ptr()) }
}

/// The low 32 bits of each of the four 64-bit lanes of a comparison's mask,
/// as a four-lane mask.
#[target_feature(enable = "avx")]
#[inline]
fn narrow(mask: __m256d) -> __m128 {
    let mask = _mm256_castpd_ps(mask);
    let (low, high) = (
        _mm256_castps256_ps128(mask),
        _mm256_extractf128_ps::<1>(mask),
    );
    _mm_shuffle_ps::<0b10_00_10_00>(low, high)
}

/// `v`'s coordinates and `w` in one register, read one by one
/// ([`coordinates_apart`]).
#[target_feature(enable = "avx")]
#[inline]
fn coordinates(v: &Vec3, w: f64) -> __m256d {
    let [x, y, z] = coordinates_apart(v);
    _mm256_set_pd(w, z, y, x)
}

/// The rows of `BvhNode::bounds` a ray enters and leaves through on `axis`:
/// the max face first where bit `axis` of `max_first` is set.
#[inline(always)]
fn rows(max_first: i32, axis: usize) -> (usize, usize) {
    if max_first >> axis & 1 == 1 {
        (axis + 3, axis)
    } else {
        (axis, axis + 3)
    }
}

/// Each of the first three lanes of `v` in a register of its own.
#[target_feature(enable = "avx")]
#[inline]
fn spread(v: __m128) -> [__m256; 3] {
    let both = _mm256_insertf128_ps::<1>(_mm256_castps128_ps256(v), v);
    [
        _mm256_permute_ps::<0x00>(both),
        _mm256_permute_ps::<0x55>(both),
        _mm256_permute_ps::<0xaa>(both),
    ]
}

impl Avx {
    /// The test for `ray`: the values of
    /// [`Planes::new`](super::slabs::Planes::new) bit for bit, computed for
    /// the three axes at once and kept in registers, so that no wide load
    /// reads them back from narrower stores ([`coordinates_apart`]; through
    /// a `Planes`: slower, see docs/performance-log.md).
    #[target_feature(enable = "avx")]
    #[inline]
    fn prepare(ray: &Ray) -> Self {
        let origin = coordinates(&ray.origin, 0.0);
        let inv = coordinates(&ray.inv_dir, 1.0);
        // `round_down` and `round_up` of each coordinate (see `node`): the
        // nearest `f32`, stepped one unit of its bits where it lies on the
        // wrong side.
        let nearest = _mm256_cvtpd_ps(origin);
        let back = _mm256_cvtps_pd(nearest);
        let too_high = narrow(_mm256_cmp_pd::<_CMP_GT_OQ>(back, origin));
        let too_low = narrow(_mm256_cmp_pd::<_CMP_LT_OQ>(back, origin));
        let bits = _mm_castps_si128(nearest);
        let sign = _mm_srai_epi32::<31>(bits);
        // One unit towards +∞ in bits: +1 for a positive value, −1 for a
        // negative one.
        let step = _mm_add_epi32(_mm_set1_epi32(1), _mm_add_epi32(sign, sign));
        let below = _mm_castsi128_ps(_mm_sub_epi32(bits, step));
        let above = _mm_castsi128_ps(_mm_add_epi32(bits, step));
        let down = _mm_blendv_ps(nearest, below, too_high);
        let up = _mm_blendv_ps(nearest, above, too_low);
        // The inverse direction in `f32` keeps the sign of the `f64` one,
        // which picks the entry and exit planes (`blendv` reads the sign).
        let inv_f32 = _mm256_cvtpd_ps(inv);
        let mut entry = _mm_blendv_ps(up, down, inv_f32);
        let mut exit = _mm_blendv_ps(down, up, inv_f32);
        // Finite but beyond `f32`: an axis that culls only the empty box.
        let magnitude = _mm256_andnot_pd(_mm256_set1_pd(-0.0), inv);
        let beyond = narrow(_mm256_and_pd(
            _mm256_cmp_pd::<_CMP_GT_OQ>(magnitude, _mm256_set1_pd(f64::from(f32::MAX))),
            _mm256_cmp_pd::<_CMP_LT_OQ>(magnitude, _mm256_set1_pd(f64::INFINITY)),
        ));
        entry = _mm_blendv_ps(entry, _mm_set1_ps(f32::MAX), beyond);
        exit = _mm_blendv_ps(exit, _mm_set1_ps(-f32::MAX), beyond);
        let inv = _mm_blendv_ps(inv_f32, _mm_set1_ps(NEVER_CULLS), beyond);
        let max_first = _mm_movemask_ps(_mm_cmplt_ps(inv, _mm_setzero_ps()));
        let rows = [rows(max_first, 0), rows(max_first, 1), rows(max_first, 2)];
        let t_min = round_down(ray.t_min);
        Self {
            entry_origin: spread(entry),
            exit_origin: spread(exit),
            inv_dir: spread(inv),
            rows,
            t_min: _mm256_set1_ps(t_min),
            from_zero: t_min >= 0.0,
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
        let (near, far) = if self.from_zero {
            // The same bits and mask as below, one step shorter: `near` is
            // at least `t_min`, so not below zero, and shrinking is the
            // smaller product. Where `far` is not below zero growing is the
            // larger; where it is below zero either product is, and the
            // lane fails the test either way.
            (_mm256_mul_ps(near, shrink), _mm256_mul_ps(far, grow))
        } else {
            (
                _mm256_min_ps(_mm256_mul_ps(near, shrink), _mm256_mul_ps(near, grow)),
                _mm256_max_ps(_mm256_mul_ps(far, shrink), _mm256_mul_ps(far, grow)),
            )
        };
        let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, far)) as u32;
        let mut lanes = [0.0; WIDTH];
        // SAFETY: `lanes` is eight writable `f32`s; the store is unaligned.
        unsafe { _mm256_storeu_ps(lanes.as_mut_ptr(), near) };
        (mask, lanes)
    }
}

impl SlabTest for Avx {
    #[inline(always)]
    fn new(ray: &Ray) -> Self {
        // SAFETY: an `Avx` is made only by the walks of the AVX kernels,
        // entered through a backend the processor runs (accel/kernel.rs).
        unsafe { Self::prepare(ray) }
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
    use crate::accel::bvh::node::round_up;
    use crate::accel::bvh::slabs::tests::{assert_conservative, face_cases, random_cases};
    use crate::accel::bvh::slabs::{Halves, Planes};
    use crate::math::random::Rng;

    #[test]
    fn rays_from_faces_far_origins_and_grazing_rays_keep_their_boxes() {
        if !crate::math::test_support::has_avx_or_skip_allowed() {
            return;
        }
        let kept: u32 = face_cases(48)
            .iter()
            .map(|(node, ray, t_max)| assert_conservative::<Avx>(node, ray, *t_max).count_ones())
            .sum();
        assert!(kept > 5_000, "{kept}");
    }

    #[test]
    fn agrees_with_the_two_halves_bit_for_bit() {
        if !crate::math::test_support::has_avx_or_skip_allowed() {
            return;
        }
        // Intervals that start before zero take the test's general form,
        // the others its short one; boxes behind the ray and negative
        // `t_max` make lanes whose `far` is below zero.
        let starts = [0.0, -0.0, 1e-30, 0.5, 3.0, -1e-30, -0.5, -6.0];
        let mut widened = [0usize; 2];
        for (case, (node, mut ray, t_max)) in random_cases(9).into_iter().enumerate() {
            ray.t_min = starts[case % starts.len()];
            let t_max = if case % 7 == 0 { -t_max } else { t_max };
            let avx = Avx::new(&ray);
            let (mask, near) = avx.test(&node, t_max);
            let (expected_mask, expected_near) = Halves::new(&ray).test(&node, t_max);
            assert_eq!(mask, expected_mask, "{ray:?}");
            assert_eq!(near.map(f32::to_bits), expected_near.map(f32::to_bits));
            widened[usize::from(avx.from_zero)] += mask.count_ones() as usize;
        }
        // Both forms kept many boxes.
        assert!(widened.iter().all(|&k| k > 20), "{widened:?}");
    }

    /// Lane 0 of each of three registers (the others are equal to it).
    fn first_lanes(registers: &[__m256; 3]) -> [u32; 3] {
        registers.map(|r| {
            let mut lanes = [0.0f32; WIDTH];
            // SAFETY: `lanes` is eight writable `f32`s; the store is unaligned.
            unsafe { _mm256_storeu_ps(lanes.as_mut_ptr(), r) };
            assert!(lanes.iter().all(|l| l.to_bits() == lanes[0].to_bits()));
            lanes[0].to_bits()
        })
    }

    /// Values at the edges of what `Planes::new` treats apart: both zeros,
    /// NaNs (with and without a payload), `f32::MAX` exactly and the values
    /// that round to it or just past it, the tie between it and `+∞`,
    /// `f32` subnormals and the ties between them, infinities.
    fn edges() -> Vec<f64> {
        let max = f64::from(f32::MAX);
        let tie = max + 2f64.powi(103);
        let tiny = f64::from(f32::from_bits(1));
        let magnitudes = [
            0.0,
            f64::NAN,
            f64::from_bits(0x7ff8_0000_0000_1234),
            max,
            max * (1.0 + 2f64.powi(-30)),
            tie,
            tie.next_down(),
            tie.next_up(),
            tiny,
            tiny * 0.5,
            tiny * 1.5,
            f64::from(f32::MIN_POSITIVE) * 0.75,
            1e-300,
            1e300,
            1.0 + 2f64.powi(-30),
            16_777_217.0,
            f64::INFINITY,
        ];
        magnitudes.iter().flat_map(|&m| [m, -m]).collect()
    }

    /// A coordinate of one of the kinds `Planes::new` treats apart: exact
    /// `f32`s and values between two, both signs and zeros, values beyond
    /// the `f32` range, infinities, and the edge values above.
    fn awkward(rng: &mut Rng, edges: &[f64]) -> f64 {
        let magnitude = match rng.below(10) {
            0 => return edges[rng.below(edges.len() as u32) as usize],
            1 => f64::from(rng.range(0.0, 100.0) as f32),
            2 => f64::from(f32::MAX) * rng.range(0.5, 4.0),
            3 => f64::INFINITY,
            4 => f64::from(f32::MIN_POSITIVE) * rng.range(0.0, 2.0),
            5 => 1e-300,
            6 => 1e300,
            _ => rng.range(0.0, 100.0),
        };
        if rng.below(2) == 0 {
            magnitude
        } else {
            -magnitude
        }
    }

    /// Whether the set-up in registers is `Planes::new` for `ray`, bit for
    /// bit.
    fn assert_same_planes(ray: &crate::math::Ray) {
        let planes = Planes::new(ray);
        let avx = Avx::new(ray);
        assert_eq!(
            first_lanes(&avx.entry_origin),
            planes.entry_origin.map(f32::to_bits),
            "{ray:?}"
        );
        assert_eq!(
            first_lanes(&avx.exit_origin),
            planes.exit_origin.map(f32::to_bits),
            "{ray:?}"
        );
        assert_eq!(
            first_lanes(&avx.inv_dir),
            planes.inv_dir.map(f32::to_bits),
            "{ray:?}"
        );
        assert_eq!(avx.rows, planes.rows, "{ray:?}");
        assert_eq!(first_lanes(&[avx.t_min; 3])[0], planes.t_min.to_bits());
    }

    #[test]
    fn the_set_up_in_registers_is_the_planes_at_the_edges() {
        if !crate::math::test_support::has_avx_or_skip_allowed() {
            return;
        }
        let edges = edges();
        let mut ray = crate::math::Ray::new(Vec3::ZERO, Vec3::X);
        for &a in &edges {
            for &b in &edges {
                // Each axis, and t_min, meets every pair of edge values.
                ray.origin = Vec3::new(a, b, a);
                ray.inv_dir = Vec3::new(b, a, -b);
                ray.t_min = a;
                assert_same_planes(&ray);
            }
        }
    }

    #[test]
    fn the_set_up_in_registers_is_the_planes_bit_for_bit() {
        if !crate::math::test_support::has_avx_or_skip_allowed() {
            return;
        }
        let edges = edges();
        let mut rng = Rng::new(31);
        let mut kinds = [0; 4];
        for _ in 0..20_000 {
            let mut ray = crate::math::Ray::new(Vec3::ZERO, Vec3::X);
            let mut awkward = || awkward(&mut rng, &edges);
            ray.origin = Vec3::new(awkward(), awkward(), awkward());
            ray.inv_dir = Vec3::new(awkward(), awkward(), awkward());
            ray.t_min = awkward().abs();
            assert_same_planes(&ray);
            let planes = Planes::new(&ray);
            for axis in 0..3 {
                let o = ray.origin[axis];
                kinds[0] += usize::from(round_up(o) != round_down(o));
                kinds[1] += usize::from(planes.inv_dir[axis] == NEVER_CULLS);
                kinds[2] += usize::from(planes.rows[axis].0 == axis + 3);
                kinds[3] += usize::from(ray.inv_dir[axis].is_infinite());
            }
        }
        // Every branch of `Planes::new` was taken often.
        assert!(kinds.iter().all(|&k| k > 1000), "{kinds:?}");
    }
}
