//! Tests of the superellipsoid: known answers, the shared edge-case
//! families, and an independent numeric reference on random rays.

use std::f64::consts::{PI, TAU};

use super::*;
use crate::math::random::Rng;
use crate::shape::testing::{
    assert_convex_exits_cleanly, assert_no_nan_for_awkward_rays, assert_no_self_intersection,
    assert_surface_is_sane, assert_tangents_follow_uv,
};
use crate::shape::{Shape, Sphere};

fn shape(e: f64, n: f64) -> Superellipsoid {
    Superellipsoid::new(Vec3::ZERO, 1.0, e, n).unwrap()
}

/// POV-Ray's function written out directly (no care for underflow: used
/// only where the exponents keep it in range).
fn reference_f(e: f64, n: f64, p: Vec3) -> f64 {
    (p.x.abs().powf(2.0 / e) + p.y.abs().powf(2.0 / e)).powf(e / n) + p.z.abs().powf(2.0 / n) - 1.0
}

/// What the reference saw along a ray.
enum Reference {
    /// The first crossing.
    Hit(f64),
    /// No crossing.
    Miss,
    /// Within 1e-6 of tangency somewhere: no verdict.
    NearTangent,
}

/// The reference: `f` sampled at 20,000 points over the ray's stretch in
/// the box, the first sign change bisected to the last bit. A local
/// extremum of the samples within 1e-6 of zero, or a crossing at which the
/// ray meets the surface within 1e-6 of tangency, leaves the ray out.
fn reference(e: f64, n: f64, ray: &Ray) -> Reference {
    let cube = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
    let Some((t0, t1)) = cube.intersect_ray(ray) else {
        return Reference::Miss;
    };
    let f = |t: f64| reference_f(e, n, ray.at(t));
    const SAMPLES: usize = 20_000;
    let ts: Vec<f64> = (0..=SAMPLES)
        .map(|i| t0 + (t1 - t0) * i as f64 / SAMPLES as f64)
        .collect();
    let fs: Vec<f64> = ts.iter().map(|&t| f(t)).collect();
    for i in 1..SAMPLES {
        let extremum = (fs[i] - fs[i - 1]) * (fs[i + 1] - fs[i]) <= 0.0;
        if extremum && fs[i].abs() < 1e-6 {
            return Reference::NearTangent;
        }
    }
    let Some(i) = (1..=SAMPLES).find(|&i| (fs[i] > 0.0) != (fs[0] > 0.0)) else {
        return Reference::Miss;
    };
    let (mut a, mut b) = (ts[i - 1], ts[i]);
    let inside_first = fs[i - 1] <= 0.0;
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        if (f(m) <= 0.0) == inside_first {
            a = m;
        } else {
            b = m;
        }
    }
    // Grazing: the slope of f along the unit direction at the crossing.
    let h = 1e-7 * (t1 - t0);
    let slope = (f(b + h) - f(a - h)) / (b - a + 2.0 * h) * ray.dir.length().recip();
    if slope.abs() < 1e-6 {
        return Reference::NearTangent;
    }
    Reference::Hit(b)
}

#[test]
fn random_rays_agree_with_a_dense_sampling_reference() {
    let mut rng = Rng::new(17);
    let (mut hits, mut misses, mut skipped) = (0, 0, 0);
    let mut worst: f64 = 0.0;
    for _ in 0..4000 {
        let e = [0.25, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0][rng.below(7) as usize] * rng.range(0.8, 1.2);
        let n = [0.25, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0][rng.below(7) as usize] * rng.range(0.8, 1.2);
        let s = shape(e, n);
        let origin = [0.5, 3.0][rng.below(2) as usize] * rng.unit_vector();
        let target = rng.point_in(Vec3::splat(-1.0), Vec3::splat(1.0));
        let ray = Ray::new(origin, target - origin);
        let ours = s.intersect(&ray).map(|h| h.t);
        match (reference(e, n, &ray), ours) {
            (Reference::NearTangent, _) => skipped += 1,
            (Reference::Miss, None) => misses += 1,
            (Reference::Hit(t), Some(ours)) => {
                let error = (ours - t).abs() / t;
                worst = worst.max(error);
                assert!(error < 1e-7, "e {e} n {n} {ray:?}: {ours} against {t}");
                hits += 1;
            }
            (Reference::Hit(t), None) => panic!("e {e} n {n} {ray:?}: missed, reference {t}"),
            (Reference::Miss, Some(t)) => {
                panic!("e {e} n {n} {ray:?}: hit at {t}, reference missed")
            }
        }
    }
    assert!(hits > 2000 && misses > 200, "{hits} hits, {misses} misses");
    assert!(skipped < 40, "{skipped} rays skipped as near tangent");
    assert!(worst < 1e-9, "worst relative error {worst:e}");
}

#[test]
fn the_unit_sphere_is_a_known_answer() {
    let sphere = shape(1.0, 1.0);
    let mut rng = Rng::new(3);
    for _ in 0..1000 {
        let origin = 3.0 * rng.unit_vector();
        let ray = Ray::new(origin, rng.point_in(Vec3::splat(-1.0), Vec3::ONE) - origin);
        let exact = Sphere::new(Vec3::ZERO, 1.0).unwrap().intersect(&ray);
        match (sphere.intersect(&ray), exact) {
            (Some(ours), Some(exact)) => {
                assert!((ours.t - exact.t).abs() < 1e-12 * exact.t, "{ray:?}");
                let s = sphere.surface(&ray, &ours);
                assert!((s.normal - s.point).length() < 1e-12);
            }
            (None, None) => {}
            other => panic!("{ray:?}: {other:?}"),
        }
    }
}

#[test]
fn e_and_n_of_two_make_the_octahedron() {
    let octahedron = shape(2.0, 2.0);
    let mut rng = Rng::new(5);
    for _ in 0..1000 {
        let origin = 3.0 * rng.unit_vector();
        let ray = Ray::new(origin, rng.point_in(Vec3::splat(-1.0), Vec3::ONE) - origin);
        let Some(hit) = octahedron.intersect(&ray) else {
            continue;
        };
        let s = octahedron.surface(&ray, &hit);
        let p = ray.at(hit.t);
        assert!((p.abs().element_sum() - 1.0).abs() < 1e-12, "{p}");
        let face = Vec3::new(p.x.signum(), p.y.signum(), p.z.signum()) / 3f64.sqrt();
        assert!((s.normal - face).length() < 1e-9, "{:?} at {p}", s.normal);
    }
    // Straight down the z axis onto the vertex; at 45° onto a face.
    let down = Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z);
    assert!((octahedron.intersect(&down).unwrap().t - 4.0).abs() < 1e-12);
    let onto_face = Ray::new(Vec3::splat(2.0), -Vec3::ONE);
    assert!((octahedron.intersect(&onto_face).unwrap().t - (2.0 - 1.0 / 3.0)).abs() < 1e-12);
}

#[test]
fn edge_case_families() {
    let s = shape(0.5, 0.5);
    // In front, from each axis.
    for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
        let ray = Ray::new(-5.0 * axis, axis);
        let hit = s.intersect(&ray).unwrap();
        assert!((hit.t - 4.0).abs() < 1e-12);
        assert!((s.surface(&ray, &hit).normal + axis).length() < 1e-9);
    }
    // Behind.
    assert_eq!(
        s.intersect(&Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::Z)),
        None
    );
    // Beside, just out of the bounding cube, and beside the rounded edge.
    assert_eq!(
        s.intersect(&Ray::new(Vec3::new(1.0 + 1e-9, 0.0, -5.0), Vec3::Z)),
        None
    );
    let corner = Vec3::new(0.99, 0.99, -5.0);
    assert_eq!(s.intersect(&Ray::new(corner, Vec3::Z)), None);
    // From inside, the far side.
    let ray = Ray::new(Vec3::new(0.0, 0.5, 0.0), Vec3::Y);
    assert!((s.intersect(&ray).unwrap().t - 0.5).abs() < 1e-12);
    // Tangent along the flat-ish top of a rounded cube.
    let ray = Ray::new(Vec3::new(-5.0, 0.0, 1.0), Vec3::X);
    let touch = s.intersect(&ray);
    if let Some(hit) = touch {
        assert!(s.surface(&ray, &hit).normal.is_finite());
    }
    // Hits beyond t_max are ignored.
    assert_eq!(
        s.intersect(&Ray::segment(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 4.0)),
        None
    );
}

#[test]
fn grazing_rays_near_the_rim_are_never_lost() {
    // Rays parallel to z at distance r from the axis, for a rounded cube:
    // the hit exists exactly when (x^(2/e) + y^(2/e))^(e/n) < 1.
    let s = shape(0.3, 0.3);
    let mut rng = Rng::new(9);
    for _ in 0..2000 {
        let x = rng.range(-1.0, 1.0);
        let y = rng.range(-1.0, 1.0);
        let planar = reference_f(0.3, 0.3, Vec3::new(x, y, 0.0)) + 1.0;
        if (planar - 1.0).abs() < 1e-9 {
            continue;
        }
        let ray = Ray::new(Vec3::new(x, y, -3.0), Vec3::Z);
        let expected = (1.0 - planar).max(0.0).powf(0.3 / 2.0);
        match s.intersect(&ray) {
            Some(hit) => {
                assert!(planar < 1.0, "{x} {y}");
                assert!(
                    (hit.t - (3.0 - expected)).abs() < 1e-9,
                    "{x} {y}: {}",
                    hit.t
                );
            }
            None => assert!(planar > 1.0, "{x} {y} missed"),
        }
    }
}

#[test]
fn thin_spikes_of_star_shapes_are_found() {
    // e = n = 4: the spike along +x at x = 0.9 is a few 1e-5 across; a ray
    // along z through its middle must hit it.
    let s = shape(4.0, 4.0);
    let ray = Ray::new(Vec3::new(0.9, 0.0, -3.0), Vec3::Z);
    let hit = s.intersect(&ray).expect("the spike was skipped");
    let p = ray.at(hit.t);
    assert!(reference_f(4.0, 4.0, p).abs() < 1e-9 && p.z < 0.0, "{p}");
    // Just beside the spike, nothing.
    let beside = Ray::new(Vec3::new(0.9, 0.01, -3.0), Vec3::Z);
    assert_eq!(s.intersect(&beside), None);
}

#[test]
fn extreme_exponents_never_give_nan_and_agree_with_their_limits() {
    for (e, n) in [
        (MIN_EXPONENT, MIN_EXPONENT),
        (MIN_EXPONENT, MAX_EXPONENT),
        (MAX_EXPONENT, MIN_EXPONENT),
        (MAX_EXPONENT, MAX_EXPONENT),
        (0.01, 0.01),
    ] {
        let shape = Shape::Superellipsoid(shape(e, n));
        assert_no_nan_for_awkward_rays(&shape);
        assert_surface_is_sane(&shape, 21);
    }
    // The near-cube's face is at 1 to within its rounding.
    let cube = shape(MIN_EXPONENT, MIN_EXPONENT);
    let ray = Ray::new(Vec3::new(0.3, -0.2, -5.0), Vec3::Z);
    assert!((cube.intersect(&ray).unwrap().t - 4.0).abs() < 1e-3);
}

#[test]
fn secondary_rays_never_hit_the_surface_they_leave() {
    for (e, n) in [(0.2, 0.2), (0.5, 1.0), (1.0, 1.0), (1.7, 0.4), (2.0, 2.0)] {
        for (center, radius) in [(Vec3::ZERO, 1.0), (Vec3::new(1e3, -20.0, 7.0), 2.5)] {
            let s = Superellipsoid::new(center, radius, e, n).unwrap();
            let shape = Shape::Superellipsoid(s);
            assert_no_self_intersection(&shape, 7);
            assert_surface_is_sane(&shape, 11);
            assert_convex_exits_cleanly(&shape, 13);
            assert_no_nan_for_awkward_rays(&shape);
        }
    }
    for (e, n) in [(3.0, 1.0), (1.0, 3.0), (2.5, 2.5)] {
        let shape = Shape::Superellipsoid(shape(e, n));
        assert_no_self_intersection(&shape, 7);
        assert_surface_is_sane(&shape, 11);
        assert_no_nan_for_awkward_rays(&shape);
    }
}

#[test]
fn tangents_are_the_derivatives_of_the_parametric_form() {
    // Exponents of at least 1: below 1 the form's derivatives grow without
    // bound near ω = kπ/2 (still finite and tangent, but too fast for the
    // finite differences of the check).
    for (e, n) in [(1.0, 1.0), (1.5, 1.2), (1.2, 1.8)] {
        let shape = Shape::Superellipsoid(Superellipsoid::new(Vec3::X, 2.0, e, n).unwrap());
        assert_tangents_follow_uv(&shape, 3);
    }
    // For e = n = 1, u and v are the sphere's.
    let sphere = shape(1.0, 1.0);
    let ray = Ray::new(Vec3::new(0.0, -5.0, 0.0), Vec3::Y);
    let s = sphere.surface(&ray, &sphere.intersect(&ray).unwrap());
    assert!((s.uv - DVec2::new(0.75, 0.5)).length() < 1e-12);
    assert!((s.dpdu - TAU * Vec3::X).length() < 1e-9, "{}", s.dpdu);
    assert!((s.dpdv - PI * Vec3::Z).length() < 1e-9, "{}", s.dpdv);
}

#[test]
fn creases_and_poles_have_the_limit_normals() {
    // A star (e > 2) hit exactly on its crease x = 0 from +y: the normal is
    // along the infinite component, +x or -x, never NaN.
    let star = shape(3.0, 1.0);
    let ray = Ray::new(Vec3::new(0.0, 0.5, 5.0), -Vec3::Z);
    if let Some(hit) = star.intersect(&ray) {
        let normal = star.surface(&ray, &hit).normal;
        assert!(normal.is_finite() && (normal.length() - 1.0).abs() < 1e-12);
    }
    // The pole of a spiky profile (n > 2): ±z.
    let spiky = shape(1.0, 3.0);
    let down = Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z);
    let hit = spiky.intersect(&down).unwrap();
    assert_eq!(spiky.surface(&down, &hit).normal, Vec3::Z);
    // The equator of a spiky profile: the crease z = 0, normal ±z.
    let side = Ray::new(Vec3::new(5.0, 0.3, 0.0), -Vec3::X);
    let hit = spiky.intersect(&side).unwrap();
    let normal = spiky.surface(&side, &hit).normal;
    assert!((normal.abs() - Vec3::Z).length() < 1e-12, "{normal}");
}

#[test]
fn degenerate_parameters_are_refused() {
    for (e, n) in [
        (0.0, 1.0),
        (1.0, -1.0),
        (f64::NAN, 1.0),
        (1.0, f64::INFINITY),
    ] {
        assert!(
            Superellipsoid::new(Vec3::ZERO, 1.0, e, n).is_err(),
            "{e} {n}"
        );
    }
    for (e, n) in [(1e-4, 1.0), (1.0, 11.0)] {
        assert!(matches!(
            Superellipsoid::new(Vec3::ZERO, 1.0, e, n),
            Err(ShapeError::Degenerate { .. })
        ));
    }
    assert!(Superellipsoid::new(Vec3::ZERO, 0.0, 1.0, 1.0).is_err());
    assert!(Superellipsoid::new(Vec3::new(1e40, 0.0, 0.0), 1.0, 1.0, 1.0).is_err());
    assert!(Superellipsoid::new(Vec3::ZERO, 1.0, MIN_EXPONENT, MAX_EXPONENT).is_ok());
}
