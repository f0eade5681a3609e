//! The cull of [`Sphere::intersect`](super::Sphere::intersect) on four
//! spheres at once, one per lane of an AVX register of `f64`s, for
//! processors that have AVX (the caller checks at run time).
//!
//! A lane is a candidate when its sphere's quadratic has real roots and the
//! cull of `beyond` keeps it: exactly the spheres for which the
//! one-sphere test computes roots, because every lane runs that test's
//! operations in the same order (IEEE arithmetic is exact per operation,
//! Rust never fuses a multiply and an add, and the comparisons are the
//! ordered ones, false for NaN, as Rust's). The caller then tests only the
//! candidates, one by one. Where spheres overlap (a ray then tests many
//! and culls most), the four culls run side by side with no branch to
//! mispredict (measured: docs/performance-log.md, "Spheres four at a
//! time").
//!
//! A lane culled for `t_max` stays culled for any smaller end: each
//! quantity the cull compares moves monotonically with `t_max`, and
//! rounding keeps that order. A closest-hit search that lowers its end
//! while it tests a run's candidates may therefore keep the mask it made
//! with the end it started from.

use std::arch::x86_64::{
    __m256d, _CMP_GE_OQ, _CMP_GT_OQ, _CMP_LE_OQ, _CMP_LT_OQ, _mm256_add_pd, _mm256_and_pd,
    _mm256_andnot_pd, _mm256_cmp_pd, _mm256_movemask_pd, _mm256_mul_pd, _mm256_or_pd,
    _mm256_set1_pd, _mm256_setr_pd, _mm256_setzero_pd, _mm256_sub_pd, _mm256_xor_pd,
};

use super::lanes::LANES;
use super::sphere::BEYOND_MARGIN;
use crate::math::{Ray, Vec3, gamma};

/// The lanes (bit `i` for `centers[i]`, `radii[i]`) whose sphere the
/// one-sphere test would not cull for `ray` ending at `t_max`: those for
/// which it computes roots. The others have no hit in `(t_min, t_max)`.
///
/// The spheres come by reference so that their numbers are read where they
/// lie: copied into an array just before the call, they were read back
/// across two stores each, which the processor cannot forward (see
/// docs/performance-log.md, "Spheres four at a time").
///
/// # Safety
///
/// Call it only where the processor has AVX
/// (`is_x86_feature_detected!("avx")`).
#[target_feature(enable = "avx")]
#[inline]
pub fn sphere_candidates4(
    centers: [&Vec3; LANES],
    radii: [&f64; LANES],
    ray: &Ray,
    t_max: f64,
) -> u32 {
    let d = ray.dir;
    let a = d.length_squared();
    if a == 0.0 {
        return 0;
    }
    let (add, sub, mul) = (_mm256_add_pd, _mm256_sub_pd, _mm256_mul_pd);
    let lane = |axis: usize| {
        _mm256_sub_pd(
            _mm256_set1_pd(ray.origin[axis]),
            _mm256_setr_pd(
                centers[0][axis],
                centers[1][axis],
                centers[2][axis],
                centers[3][axis],
            ),
        )
    };
    let (fx, fy, fz) = (lane(0), lane(1), lane(2));
    let (dx, dy, dz) = (
        _mm256_set1_pd(d.x),
        _mm256_set1_pd(d.y),
        _mm256_set1_pd(d.z),
    );
    let r = _mm256_setr_pd(*radii[0], *radii[1], *radii[2], *radii[3]);
    let r2 = mul(r, r);
    let dot = |x: __m256d, y: __m256d, z: __m256d, p: __m256d, q: __m256d, s: __m256d| {
        add(add(mul(x, p), mul(y, q)), mul(z, s))
    };
    let b = dot(fx, fy, fz, dx, dy, dz);
    let c = sub(dot(fx, fy, fz, fx, fy, fz), r2);
    // f × d, as glam computes it.
    let kx = sub(mul(fy, dz), mul(dy, fz));
    let ky = sub(mul(fz, dx), mul(dz, fx));
    let kz = sub(mul(fx, dy), mul(dx, fy));
    let disc = sub(mul(_mm256_set1_pd(a), r2), dot(kx, ky, kz, kx, ky, kz));
    let zero = _mm256_setzero_pd();
    let roots = _mm256_cmp_pd::<_CMP_GE_OQ>(disc, zero);
    if ray.t_min < 0.0 || ray.t_min.is_nan() {
        return _mm256_movemask_pd(roots) as u32;
    }

    // `beyond`, lane by lane.
    let t = t_max * BEYOND_MARGIN;
    let t_v = _mm256_set1_pd(t);
    let g4 = _mm256_set1_pd(gamma(4));
    let bound = mul(
        mul(_mm256_set1_pd(t * t), disc),
        _mm256_set1_pd(1.0 + gamma(4)),
    );
    let root_beyond = |left: __m256d, error: __m256d| {
        let left = sub(left, mul(g4, error));
        _mm256_and_pd(
            _mm256_cmp_pd::<_CMP_GT_OQ>(left, zero),
            _mm256_cmp_pd::<_CMP_GE_OQ>(mul(left, left), bound),
        )
    };
    let negate = |x: __m256d| _mm256_xor_pd(x, _mm256_set1_pd(-0.0));
    let bt = mul(b, t_v);
    let when_negative = _mm256_and_pd(
        _mm256_cmp_pd::<_CMP_GE_OQ>(negate(b), _mm256_set1_pd(a * t)),
        _mm256_or_pd(
            _mm256_cmp_pd::<_CMP_LE_OQ>(c, zero),
            root_beyond(add(c, bt), sub(c, bt)),
        ),
    );
    let when_positive = _mm256_or_pd(
        _mm256_cmp_pd::<_CMP_GT_OQ>(c, zero),
        root_beyond(sub(negate(c), bt), sub(bt, c)),
    );
    let beyond = _mm256_or_pd(
        _mm256_and_pd(_mm256_cmp_pd::<_CMP_LT_OQ>(b, zero), when_negative),
        _mm256_and_pd(_mm256_cmp_pd::<_CMP_GE_OQ>(b, zero), when_positive),
    );
    _mm256_movemask_pd(_mm256_andnot_pd(beyond, roots)) as u32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::random::Rng;
    use crate::math::test_support::has_avx_or_skip_allowed;
    use crate::shape::Sphere;

    fn random_vec(rng: &mut Rng, scale: f64) -> Vec3 {
        Vec3::new(
            scale * (2.0 * rng.uniform() - 1.0),
            scale * (2.0 * rng.uniform() - 1.0),
            scale * (2.0 * rng.uniform() - 1.0),
        )
    }

    /// The lanes' answers against the one-sphere test's for `t_max`, and
    /// for every smaller end the one-sphere test hits at: the mask holds
    /// exactly the spheres it computes roots for, and every sphere it hits
    /// below an end at most `t_max`.
    fn assert_same(spheres: &[(Vec3, f64); LANES], ray: &Ray, t_max: f64) -> u32 {
        let centers = [0, 1, 2, 3].map(|i| &spheres[i].0);
        let radii = [0, 1, 2, 3].map(|i| &spheres[i].1);
        // SAFETY: the callers return early without AVX.
        let mask = unsafe { sphere_candidates4(centers, radii, ray, t_max) };
        let mut bounded = *ray;
        for (i, &(center, radius)) in spheres.iter().enumerate() {
            let sphere = Sphere::from_accepted(center, radius);
            bounded.t_max = t_max;
            let in_mask = mask & 1 << i != 0;
            assert_eq!(
                in_mask,
                sphere.roots(&bounded).is_some(),
                "lane {i}: {sphere:?}, {ray:?}, t_max {t_max}"
            );
            for end in [t_max, t_max * 0.5, t_max * 0.01, 1.0, 1e-3] {
                bounded.t_max = end.min(t_max);
                if sphere.intersect(&bounded).is_some() {
                    assert!(in_mask, "lane {i} hit below {end} but culled");
                }
            }
        }
        mask
    }

    #[test]
    fn lanes_cull_exactly_what_one_sphere_at_a_time_does() {
        if !has_avx_or_skip_allowed() {
            return;
        }
        let mut rng = Rng::new(11);
        let mut candidates = 0;
        for _ in 0..20_000 {
            // Overlapping spheres around the ray's start, as in `shells`.
            let spheres: [(Vec3, f64); LANES] =
                std::array::from_fn(|_| (random_vec(&mut rng, 2.0), 0.01 + 3.0 * rng.uniform()));
            let dir = random_vec(&mut rng, 1.0) * (10.0 * rng.uniform() + 1e-3);
            let mut ray = Ray::new(random_vec(&mut rng, 3.0), dir);
            if rng.below(2) == 0 {
                // Nearly grazing the first sphere, whose roots then nearly
                // meet: the cull's error terms decide there.
                let (center, radius) = spheres[0];
                let side = dir.cross(random_vec(&mut rng, 1.0)).normalize();
                let miss = radius * (1.0 - 10f64.powi(-(rng.below(12) as i32)));
                ray.origin = center + side * miss - dir * (1.0 + 5.0 * rng.uniform());
            }
            ray.t_min = [0.0, 1e-9, -1.0, 0.5][rng.below(4) as usize];
            let t_max = [f64::INFINITY, 0.3, 2.0, 1e-6, 40.0][rng.below(5) as usize];
            candidates += assert_same(&spheres, &ray, t_max).count_ones();
            // Ends right at a root, where the cull's margins decide.
            let sphere = Sphere::from_accepted(spheres[0].0, spheres[0].1);
            if let Some((t0, t1)) = sphere.roots(&Ray { t_min: 0.0, ..ray }) {
                for root in [t0, t1] {
                    for ulps in [-3_i64, -1, 0, 1, 3, 1 << 12, 1 << 14] {
                        let end = f64::from_bits((root.abs().to_bits() as i64 + ulps) as u64);
                        assert_same(&spheres, &ray, end);
                    }
                }
            }
        }
        // Both answers occur often.
        assert!(candidates > 10_000 && candidates < 70_000, "{candidates}");
    }

    #[test]
    fn grazing_tiny_and_degenerate_rays_agree_too() {
        if !has_avx_or_skip_allowed() {
            return;
        }
        let unit = (Vec3::ZERO, 1.0);
        let spheres = [
            unit,
            (Vec3::new(0.0, 1.0, 0.0), 1e-300),
            (Vec3::new(1e8, 0.0, 0.0), 1e-4),
            (Vec3::new(0.0, 0.0, 5.0), 1.0),
        ];
        let rays = [
            // Grazing the unit sphere along its tangent line.
            Ray::new(Vec3::new(-5.0, 1.0, 0.0), Vec3::X),
            // From its centre, from its surface, from far away.
            Ray::new(Vec3::ZERO, Vec3::Y),
            Ray::new(Vec3::new(1.0, 0.0, 0.0), Vec3::X),
            Ray::new(Vec3::new(-1e9, 0.0, 0.0), Vec3::X),
            // Tiny and huge directions, a zero one and a NaN one.
            Ray::new(Vec3::new(0.0, 0.0, -3.0), Vec3::new(0.0, 0.0, 1e-200)),
            Ray::new(Vec3::new(0.0, 0.0, -3.0), Vec3::new(0.0, 0.0, 1e150)),
            Ray::new(Vec3::new(0.0, 0.0, -3.0), Vec3::ZERO),
            Ray::new(Vec3::new(0.0, 0.0, -3.0), Vec3::new(f64::NAN, 0.0, 1.0)),
        ];
        for ray in &rays {
            for t_max in [f64::INFINITY, 3.0, 1e-12, 0.0] {
                assert_same(&spheres, ray, t_max);
            }
        }
        // The zero direction has no roots at all.
        // SAFETY: checked for AVX above.
        let mask = unsafe {
            sphere_candidates4(
                [0, 1, 2, 3].map(|i| &spheres[i].0),
                [0, 1, 2, 3].map(|i| &spheres[i].1),
                &rays[6],
                1.0,
            )
        };
        assert_eq!(mask, 0);
    }
}
