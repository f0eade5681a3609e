//! The watertight ray/triangle test of [`watertight`] four times at once,
//! one per lane of an AVX register of `f64`s, for processors that have
//! AVX (the caller checks at run time): four triangles against one ray
//! ([`watertight4`], a shadow ray's leaf) or one triangle against four rays
//! ([`watertight_rays4`], a packet's leaf).
//!
//! Every lane runs the same operations in the same order as the
//! one-triangle test, so its answer is that test's, bit for bit: IEEE
//! arithmetic is exact per operation, Rust never fuses a multiply and an
//! add on its own, the comparisons are the ordered ones (false for NaN, as
//! Rust's), and the largest of the magnitudes is taken only of numbers that
//! are not NaN (a NaN anywhere in a lane makes its `t` NaN, which fails the
//! interval test first), where `vmaxpd` and `f64::max` agree.
//!
//! [`watertight`]: super::watertight

use std::arch::x86_64::{
    __m256d, _CMP_EQ_OQ, _CMP_GT_OQ, _CMP_LE_OQ, _CMP_LT_OQ, _mm256_add_pd, _mm256_and_pd,
    _mm256_andnot_pd, _mm256_cmp_pd, _mm256_div_pd, _mm256_max_pd, _mm256_movemask_pd,
    _mm256_mul_pd, _mm256_or_pd, _mm256_set1_pd, _mm256_setr_pd, _mm256_setzero_pd,
    _mm256_storeu_pd, _mm256_sub_pd,
};

use super::lanes::{Hits4, LANES};
use super::triangle::RayShear;
use crate::math::{Ray, Vec3, gamma};

/// A corner of each lane's triangle in the ray's sheared space.
#[derive(Clone, Copy)]
struct Corner {
    x: __m256d,
    y: __m256d,
    z: __m256d,
}

/// `|x|` per lane.
#[target_feature(enable = "avx")]
#[inline]
fn abs(x: __m256d) -> __m256d {
    _mm256_andnot_pd(_mm256_set1_pd(-0.0), x)
}

/// The largest of three magnitudes per lane.
#[target_feature(enable = "avx")]
#[inline]
fn max_abs(a: __m256d, b: __m256d, c: __m256d) -> __m256d {
    _mm256_max_pd(_mm256_max_pd(abs(a), abs(b)), abs(c))
}

/// The four lanes of a register.
#[target_feature(enable = "avx")]
#[inline]
fn lanes(x: __m256d) -> [f64; LANES] {
    let mut out = [0.0; LANES];
    // SAFETY: `out` is four writable `f64`s; the store is unaligned.
    unsafe { _mm256_storeu_pd(out.as_mut_ptr(), x) };
    out
}

/// The triangles `triangles` (lane `i` the `i`-th; repeat one to fill the
/// lanes) tested against `ray` with `t_max` in place of its own end, with
/// the ray's precomputed shear: lane by lane what
/// [`watertight`](super::watertight) returns.
///
/// # Safety
///
/// Call it only where the processor has AVX
/// (`is_x86_feature_detected!("avx")`).
#[target_feature(enable = "avx")]
#[inline]
pub fn watertight4(
    triangles: [&[Vec3; 3]; LANES],
    ray: &Ray,
    shear: &RayShear,
    t_max: f64,
) -> Hits4 {
    match shear.kz() {
        0 => permuted::<1, 2, 0>(triangles, ray, shear, t_max),
        1 => permuted::<2, 0, 1>(triangles, ray, shear, t_max),
        _ => permuted::<0, 1, 2>(triangles, ray, shear, t_max),
    }
}

/// Corner `k` of every lane's triangle, translated to the ray's origin
/// and sheared, the axes permuted by `KX`, `KY`, `KZ`.
#[target_feature(enable = "avx")]
#[inline]
fn corner<const KX: usize, const KY: usize, const KZ: usize>(
    triangles: &[&[Vec3; 3]; LANES],
    k: usize,
    origin: Vec3,
    sx: __m256d,
    sy: __m256d,
) -> Corner {
    let [t0, t1, t2, t3] = triangles;
    let q = |axis: usize| {
        (
            t0[k][axis],
            t1[k][axis],
            t2[k][axis],
            t3[k][axis],
            origin[axis],
        )
    };
    let (x, y, z) = (q(KX), q(KY), q(KZ));
    let x = _mm256_sub_pd(_mm256_setr_pd(x.0, x.1, x.2, x.3), _mm256_set1_pd(x.4));
    let y = _mm256_sub_pd(_mm256_setr_pd(y.0, y.1, y.2, y.3), _mm256_set1_pd(y.4));
    let z = _mm256_sub_pd(_mm256_setr_pd(z.0, z.1, z.2, z.3), _mm256_set1_pd(z.4));
    Corner {
        x: _mm256_add_pd(x, _mm256_mul_pd(sx, z)),
        y: _mm256_add_pd(y, _mm256_mul_pd(sy, z)),
        z,
    }
}

/// [`watertight4`] with the shear's axis permutation given as `KX`, `KY`,
/// `KZ`.
#[target_feature(enable = "avx")]
#[inline]
fn permuted<const KX: usize, const KY: usize, const KZ: usize>(
    triangles: [&[Vec3; 3]; LANES],
    ray: &Ray,
    shear: &RayShear,
    t_max: f64,
) -> Hits4 {
    let s = shear.factors();
    let (sx, sy, sz) = (
        _mm256_set1_pd(s.x),
        _mm256_set1_pd(s.y),
        _mm256_set1_pd(s.z),
    );
    let a = corner::<KX, KY, KZ>(&triangles, 0, ray.origin, sx, sy);
    let b = corner::<KX, KY, KZ>(&triangles, 1, ray.origin, sx, sy);
    let c = corner::<KX, KY, KZ>(&triangles, 2, ray.origin, sx, sy);
    test_corners(
        [a, b, c],
        sz,
        _mm256_set1_pd(ray.t_min),
        _mm256_set1_pd(t_max),
    )
}

/// The test of [`watertight`](super::watertight) from each lane's
/// corners in its ray's sheared space (z not yet scaled by `sz`), with
/// each lane's interval from `t_min` to `t_max`.
#[target_feature(enable = "avx")]
#[inline]
fn test_corners([a, b, c]: [Corner; 3], sz: __m256d, t_min: __m256d, t_max: __m256d) -> Hits4 {
    let cross = |p: __m256d, q: __m256d, r: __m256d, s: __m256d| {
        _mm256_sub_pd(_mm256_mul_pd(p, q), _mm256_mul_pd(r, s))
    };
    let e0 = cross(b.x, c.y, b.y, c.x);
    let e1 = cross(c.x, a.y, c.y, a.x);
    let e2 = cross(a.x, b.y, a.y, b.x);
    let zero = _mm256_setzero_pd();
    let any = |cmp: fn(__m256d, __m256d) -> __m256d| {
        _mm256_or_pd(_mm256_or_pd(cmp(e0, zero), cmp(e1, zero)), cmp(e2, zero))
    };
    let negative = any(|e, z| _mm256_cmp_pd::<_CMP_LT_OQ>(e, z));
    let positive = any(|e, z| _mm256_cmp_pd::<_CMP_GT_OQ>(e, z));
    let mixed = _mm256_movemask_pd(_mm256_and_pd(negative, positive)) as u32;
    let none = Hits4 {
        mask: 0,
        t: [0.0; LANES],
        u: [0.0; LANES],
        v: [0.0; LANES],
    };
    if mixed == 0b1111 {
        return none;
    }
    let det = _mm256_add_pd(_mm256_add_pd(e0, e1), e2);
    let det_zero = _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_EQ_OQ>(det, zero)) as u32;
    let (az, bz, cz) = (
        _mm256_mul_pd(a.z, sz),
        _mm256_mul_pd(b.z, sz),
        _mm256_mul_pd(c.z, sz),
    );
    let scaled = _mm256_add_pd(
        _mm256_add_pd(_mm256_mul_pd(e0, az), _mm256_mul_pd(e1, bz)),
        _mm256_mul_pd(e2, cz),
    );
    let t = _mm256_div_pd(scaled, det);
    let inside = _mm256_movemask_pd(_mm256_and_pd(
        _mm256_cmp_pd::<_CMP_GT_OQ>(t, t_min),
        _mm256_cmp_pd::<_CMP_LT_OQ>(t, t_max),
    )) as u32;
    let candidates = inside & !mixed & !det_zero;
    if candidates == 0 {
        return none;
    }

    // The error bounds of pbrt-v4, as in the one-triangle test.
    let max_x = max_abs(a.x, b.x, c.x);
    let max_y = max_abs(a.y, b.y, c.y);
    let max_z = max_abs(az, bz, cz);
    let g2 = _mm256_set1_pd(gamma(2));
    let g3 = _mm256_set1_pd(gamma(3));
    let g5 = _mm256_set1_pd(gamma(5));
    let delta_x = _mm256_mul_pd(g5, _mm256_add_pd(max_x, max_z));
    let delta_y = _mm256_mul_pd(g5, _mm256_add_pd(max_y, max_z));
    let delta_z = _mm256_mul_pd(g3, max_z);
    let delta_e = _mm256_mul_pd(
        _mm256_set1_pd(2.0),
        _mm256_add_pd(
            _mm256_add_pd(
                _mm256_mul_pd(_mm256_mul_pd(g2, max_x), max_y),
                _mm256_mul_pd(delta_y, max_x),
            ),
            _mm256_mul_pd(delta_x, max_y),
        ),
    );
    let abs_det = abs(det);
    let three = _mm256_set1_pd(3.0);
    let flat = _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_LE_OQ>(
        abs_det,
        _mm256_mul_pd(three, delta_e),
    )) as u32;
    let max_e = max_abs(e0, e1, e2);
    let delta_t = _mm256_div_pd(
        _mm256_mul_pd(
            three,
            _mm256_add_pd(
                _mm256_add_pd(
                    _mm256_mul_pd(_mm256_mul_pd(g3, max_e), max_z),
                    _mm256_mul_pd(delta_e, max_z),
                ),
                _mm256_mul_pd(delta_z, max_e),
            ),
        ),
        abs_det,
    );
    let too_near = _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_LE_OQ>(t, delta_t)) as u32;
    Hits4 {
        mask: candidates & !flat & !too_near,
        t: lanes(t),
        u: lanes(_mm256_div_pd(e1, det)),
        v: lanes(_mm256_div_pd(e2, det)),
    }
}

/// Up to four rays in the lanes of AVX registers, with their shears, for
/// [`watertight_rays4`]: their shears must permute the axes alike (the
/// same largest direction component), as neighbouring camera rays' do.
#[derive(Clone, Copy)]
pub struct RayLanes4 {
    /// The origins, by axis.
    origin: [__m256d; 3],
    /// The shear factor of x by z.
    sx: __m256d,
    /// The shear factor of y by z.
    sy: __m256d,
    /// The scale of z.
    sz: __m256d,
    /// The intervals' starts.
    t_min: __m256d,
    /// The axis every lane's shear makes z.
    kz: usize,
}

impl RayLanes4 {
    /// The rays `rays` with their shears `shears` (the same ray in several
    /// lanes is fine); `None` when the shears do not all make the same
    /// axis z.
    ///
    /// # Safety
    ///
    /// Call it only where the processor has AVX.
    #[target_feature(enable = "avx")]
    #[inline]
    pub fn new(rays: [&Ray; LANES], shears: [&RayShear; LANES]) -> Option<Self> {
        let kz = shears[0].kz();
        if shears.iter().any(|s| s.kz() != kz) {
            return None;
        }
        let each = |f: &dyn Fn(usize) -> f64| _mm256_setr_pd(f(0), f(1), f(2), f(3));
        Some(Self {
            origin: [0, 1, 2].map(|axis| each(&|lane| rays[lane].origin[axis])),
            sx: each(&|lane| shears[lane].factors().x),
            sy: each(&|lane| shears[lane].factors().y),
            sz: each(&|lane| shears[lane].factors().z),
            t_min: each(&|lane| rays[lane].t_min),
            kz,
        })
    }
}

/// The triangle `corners` tested against each of the four rays of `rays`,
/// lane `i`'s interval ending at `t_max[i]`: lane by lane what
/// [`watertight`](super::watertight) returns for that ray.
///
/// # Safety
///
/// Call it only where the processor has AVX.
#[target_feature(enable = "avx")]
#[inline]
pub fn watertight_rays4(corners: &[Vec3; 3], rays: &RayLanes4, t_max: [f64; LANES]) -> Hits4 {
    match rays.kz {
        0 => rays_permuted::<1, 2, 0>(corners, rays, t_max),
        1 => rays_permuted::<2, 0, 1>(corners, rays, t_max),
        _ => rays_permuted::<0, 1, 2>(corners, rays, t_max),
    }
}

/// [`watertight_rays4`] with the shears' axis permutation given as `KX`,
/// `KY`, `KZ`.
#[target_feature(enable = "avx")]
#[inline]
fn rays_permuted<const KX: usize, const KY: usize, const KZ: usize>(
    corners: &[Vec3; 3],
    rays: &RayLanes4,
    t_max: [f64; LANES],
) -> Hits4 {
    let corner = |p: Vec3| {
        let q = |axis: usize| _mm256_sub_pd(_mm256_set1_pd(p[axis]), rays.origin[axis]);
        let (x, y, z) = (q(KX), q(KY), q(KZ));
        Corner {
            x: _mm256_add_pd(x, _mm256_mul_pd(rays.sx, z)),
            y: _mm256_add_pd(y, _mm256_mul_pd(rays.sy, z)),
            z,
        }
    };
    let [t0, t1, t2, t3] = t_max;
    test_corners(
        corners.map(corner),
        rays.sz,
        rays.t_min,
        _mm256_setr_pd(t0, t1, t2, t3),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::random::Rng;
    use crate::shape::{ShapeHit, watertight};

    /// The four lanes' answers against the one-triangle test's, bit for
    /// bit; the caller has checked for AVX.
    fn assert_same(triangles: [&[Vec3; 3]; LANES], ray: &Ray, t_max: f64) -> usize {
        let shear = RayShear::new(ray);
        let mut bounded = *ray;
        bounded.t_max = t_max;
        let bits = |h: Option<ShapeHit>| h.map(|h| (h.t.to_bits(), h.u.to_bits(), h.v.to_bits()));
        // SAFETY: the callers return early without AVX.
        let hits = unsafe { watertight4(triangles, ray, &shear, t_max) };
        for (lane, [p0, p1, p2]) in triangles.iter().enumerate() {
            let one = watertight(*p0, *p1, *p2, &bounded, &shear);
            let four = (hits.mask & 1 << lane != 0).then(|| ShapeHit {
                t: hits.t[lane],
                u: hits.u[lane],
                v: hits.v[lane],
                part: 0,
            });
            assert_eq!(bits(four), bits(one), "lane {lane} {triangles:?} {ray:?}");
        }
        hits.mask.count_ones() as usize
    }

    #[test]
    fn random_triangles_match_the_one_triangle_test_bit_for_bit() {
        if !crate::math::test_support::has_avx_or_skip_allowed() {
            return;
        }
        let mut rng = Rng::new(7);
        let mut hits = 0;
        for scale in [1e-30, 1e-6, 1.0, 1e6, 1e30] {
            for _ in 0..10_000 {
                let centre = scale * rng.point_in(Vec3::splat(-1.0), Vec3::ONE);
                let triangles: [[Vec3; 3]; LANES] = [0; LANES].map(|_| {
                    [0; 3].map(|_| centre + scale * rng.point_in(Vec3::splat(-1.0), Vec3::ONE))
                });
                let origin = centre + 3.0 * scale * rng.unit_vector();
                let ray = Ray::new(origin, centre - origin + 0.5 * scale * rng.unit_vector());
                let t_max = if rng.uniform() < 0.5 {
                    f64::INFINITY
                } else {
                    rng.range(0.0, 4.0)
                };
                hits += assert_same(triangles.each_ref(), &ray, t_max);
            }
        }
        assert!(hits > 20_000, "{hits} hits");
    }

    /// The unit triangle in z = 0, its neighbour across the diagonal, a
    /// needle and a point (no area), one with a NaN corner and one with
    /// corners near the largest `f64`.
    fn awkward_triangles() -> [[Vec3; 3]; 6] {
        [
            [Vec3::ZERO, Vec3::X, Vec3::Y],
            [Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            [Vec3::ZERO, Vec3::X, 2.0 * Vec3::X],
            [Vec3::ONE; 3],
            [Vec3::splat(f64::NAN), Vec3::X, Vec3::Y],
            [Vec3::splat(-1e300), Vec3::new(1e300, 0.0, 0.0), Vec3::Y],
        ]
    }

    /// Each of four rays' answers for `corners` against the one-triangle
    /// test's, bit for bit; `None` when their shears differ in axis. The
    /// caller has checked for AVX.
    fn assert_rays_same(
        corners: &[Vec3; 3],
        rays: [&Ray; LANES],
        t_max: [f64; LANES],
    ) -> Option<usize> {
        let shears = rays.map(RayShear::new);
        // SAFETY: the callers return early without AVX.
        let lanes = unsafe { RayLanes4::new(rays, shears.each_ref()) }?;
        // SAFETY: as above.
        let hits = unsafe { watertight_rays4(corners, &lanes, t_max) };
        let bits = |h: Option<ShapeHit>| h.map(|h| (h.t.to_bits(), h.u.to_bits(), h.v.to_bits()));
        let [p0, p1, p2] = *corners;
        for lane in 0..LANES {
            let mut bounded = *rays[lane];
            bounded.t_max = t_max[lane];
            let one = watertight(p0, p1, p2, &bounded, &shears[lane]);
            let four = (hits.mask & 1 << lane != 0).then(|| ShapeHit {
                t: hits.t[lane],
                u: hits.u[lane],
                v: hits.v[lane],
                part: 0,
            });
            assert_eq!(
                bits(four),
                bits(one),
                "lane {lane} {corners:?} {:?}",
                rays[lane]
            );
        }
        Some(hits.mask.count_ones() as usize)
    }

    #[test]
    fn four_rays_against_one_triangle_match_the_one_triangle_test_bit_for_bit() {
        if !crate::math::test_support::has_avx_or_skip_allowed() {
            return;
        }
        let mut rng = Rng::new(8);
        let (mut hits, mut refused) = (0, 0);
        for scale in [1e-30, 1e-6, 1.0, 1e6, 1e30] {
            for _ in 0..10_000 {
                let centre = scale * rng.point_in(Vec3::splat(-1.0), Vec3::ONE);
                let corners =
                    [0; 3].map(|_| centre + scale * rng.point_in(Vec3::splat(-1.0), Vec3::ONE));
                // Four rays from near one point, as a packet's are, some
                // from elsewhere, each with its own interval.
                let from = centre + 3.0 * scale * rng.unit_vector();
                let rays = [0; LANES].map(|_| {
                    let origin = if rng.uniform() < 0.8 {
                        from
                    } else {
                        centre + 3.0 * scale * rng.unit_vector()
                    };
                    let mut ray =
                        Ray::new(origin, centre - origin + 0.7 * scale * rng.unit_vector());
                    ray.t_min = if rng.uniform() < 0.2 {
                        rng.range(0.0, 1.0)
                    } else {
                        0.0
                    };
                    ray
                });
                let t_max = [0; LANES].map(|_| {
                    if rng.uniform() < 0.5 {
                        f64::INFINITY
                    } else {
                        rng.range(0.0, 4.0)
                    }
                });
                match assert_rays_same(&corners, rays.each_ref(), t_max) {
                    Some(n) => hits += n,
                    None => refused += 1,
                }
            }
        }
        assert!(hits > 4_000, "{hits} hits");
        assert!(refused > 1_000, "{refused} sets of rays sheared apart");
    }

    #[test]
    fn four_rays_on_vertices_edges_and_planes_match_too() {
        if !crate::math::test_support::has_avx_or_skip_allowed() {
            return;
        }
        let from = Vec3::new(0.1, 0.2, 1.0);
        let rays: Vec<Ray> = [
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(0.5, 0.5, 0.0),
            Vec3::new(0.25, 0.0, 0.0),
            Vec3::new(2.0, 2.0, 0.0),
            Vec3::new(0.3, 0.3, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.5, 0.0),
        ]
        .into_iter()
        .map(|target| Ray::new(from, target - from))
        .chain([
            Ray::new(Vec3::new(0.2, 0.2, 0.0), Vec3::new(0.0, 0.0, -1.0)),
            Ray::new(from, Vec3::ZERO),
            Ray::new(from, Vec3::new(f64::NAN, 0.0, -1.0)),
        ])
        .collect();
        let mut hits = 0;
        for corners in awkward_triangles() {
            for first in 0..rays.len() {
                let four = [0, 1, 2, 3].map(|i| &rays[(first + i) % rays.len()]);
                for t_max in [[f64::INFINITY; LANES], [1.0, 0.0, 2.0, 0.5]] {
                    hits += assert_rays_same(&corners, four, t_max).unwrap_or(0);
                }
            }
        }
        assert!(hits > 8, "{hits} hits");
    }

    #[test]
    fn vertices_edges_planes_and_degenerate_triangles_match_too() {
        if !crate::math::test_support::has_avx_or_skip_allowed() {
            return;
        }
        let shapes = awkward_triangles();
        let mut rays = Vec::new();
        for target in [
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(0.5, 0.5, 0.0),
            Vec3::new(0.25, 0.0, 0.0),
            Vec3::new(2.0, 2.0, 0.0),
        ] {
            for from in [Vec3::new(0.1, 0.2, 1.0), Vec3::new(-1.0, 3.0, -2.0)] {
                rays.push(Ray::new(from, target - from));
            }
            // In the triangles' plane, and starting on them.
            rays.push(Ray::new(target - Vec3::X, Vec3::X));
            rays.push(Ray::new(target, Vec3::new(0.1, 0.2, 1.0)));
            rays.push(Ray::new(target, Vec3::new(0.0, 0.0, -1.0)));
        }
        let mut hits = 0;
        for (i, first) in shapes.iter().enumerate() {
            for second in &shapes {
                let (third, fourth) = (&shapes[(i + 2) % 6], &shapes[(i + 3) % 6]);
                for ray in &rays {
                    for t_max in [f64::INFINITY, 1.0, 0.0] {
                        hits += assert_same([first, second, third, fourth], ray, t_max);
                    }
                }
            }
        }
        assert!(hits > 100, "{hits} hits");
    }
}
