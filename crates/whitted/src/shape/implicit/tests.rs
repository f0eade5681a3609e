//! Tests of the implicit surface against an independent numeric reference
//! and the exact sphere, and the edge-case families every shape passes.

use super::*;
use crate::math::random::Rng;
use crate::shape::testing::{
    assert_convex_exits_cleanly, assert_no_nan_for_awkward_rays, assert_no_self_intersection,
    assert_surface_is_sane, assert_tangents_follow_uv,
};
use crate::shape::{Shape, Sphere, Superellipsoid, Torus};

fn implicit(text: &str, min: Vec3, max: Vec3, max_gradient: f64) -> Implicit {
    Implicit::new(Expression::parse(text).unwrap(), min, max, max_gradient).unwrap()
}

fn unit_sphere() -> Implicit {
    implicit(
        "x^2 + y^2 + z^2 - 1",
        Vec3::splat(-1.5),
        Vec3::splat(1.5),
        2.0 * 1.5 * 3f64.sqrt(),
    )
}

/// What the reference found along a ray: the first root, and whether the
/// ray passes within 1e-6 (of the box's diagonal, in units of the
/// function's bound) of touching the surface away from that root.
struct Reference {
    root: Option<f64>,
    near_tangent: bool,
}

/// The independent reference: `f` sampled at 2000 points along the part of
/// the ray inside the box, each interval where the Lipschitz bound allows a
/// hidden root resampled at 2000 points more, the first change of sign
/// closed by bisection in f64.
fn reference(
    f: &dyn Fn(Vec3) -> f64,
    min: Vec3,
    max: Vec3,
    lipschitz: f64,
    ray: &Ray,
) -> Reference {
    let miss = Reference {
        root: None,
        near_tangent: false,
    };
    let (mut t0, mut t1) = (ray.t_min, ray.t_max);
    for axis in 0..3 {
        let (o, d) = (ray.origin[axis], ray.dir[axis]);
        if d == 0.0 {
            if o < min[axis] || o > max[axis] {
                return miss;
            }
            continue;
        }
        let (a, b) = ((min[axis] - o) / d, (max[axis] - o) / d);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    if t0 > t1 {
        return miss;
    }
    let speed = ray.dir.length();
    let size = (max - min).length();
    let g = |t: f64| f(ray.origin + t * ray.dir);
    let n = 2000;
    let mut samples = Vec::new();
    for i in 0..=n {
        let t = t0 + (t1 - t0) * i as f64 / n as f64;
        let (v, last) = (g(t), samples.last().copied());
        if let Some((s, w)) = last {
            let w: f64 = w;
            if v.abs() + w.abs() <= lipschitz * speed * (t - s) {
                for j in 1..n {
                    let u = s + (t - s) * j as f64 / n as f64;
                    samples.push((u, g(u)));
                }
            }
        }
        samples.push((t, v));
    }
    let crossing = samples
        .windows(2)
        .position(|w| (w[0].1 < 0.0) != (w[1].1 < 0.0));
    let root = crossing.map(|i| {
        let ((mut a, fa), (mut b, _)) = (samples[i], samples[i + 1]);
        for _ in 0..200 {
            let mid = 0.5 * (a + b);
            if mid <= a || mid >= b {
                break;
            }
            if (g(mid) < 0.0) == (fa < 0.0) {
                a = mid;
            } else {
                b = mid;
            }
        }
        b
    });
    let far_from_root = |t: f64| root.is_none_or(|r| (t - r).abs() * speed > 1e-4 * size);
    let upto = crossing.map_or(samples.len(), |i| i + 2);
    let near_tangent = samples[..upto]
        .iter()
        .any(|&(t, v)| far_from_root(t) && v.abs() < 1e-6 * lipschitz * size);
    Reference { root, near_tangent }
}

/// Random rays from outside the box aimed into it, at random scales of
/// the direction.
fn rays(min: Vec3, max: Vec3, seed: u64, count: usize) -> Vec<Ray> {
    let mut rng = Rng::new(seed);
    let center = 0.5 * (min + max);
    let size = (max - min).length();
    (0..count)
        .map(|_| {
            let origin = if rng.below(4) == 0 {
                rng.point_in(min, max)
            } else {
                center + size * rng.unit_vector()
            };
            let target = rng.point_in(min, max);
            let scale = [1.0, 1e-3, 1e3][rng.below(3) as usize];
            Ray::new(origin, scale * (target - origin))
        })
        .collect()
}

/// Compares the shape with the reference on random rays: the same hit or
/// miss, `t` within `tolerance` relative; returns how many rays were
/// compared (not near tangency) and how many of them hit.
fn compare_with_reference(
    shape: &Implicit,
    f: &dyn Fn(Vec3) -> f64,
    lipschitz: f64,
    tolerance: f64,
    seed: u64,
) -> (usize, usize) {
    let b = shape.bounds();
    let (mut compared, mut hits, mut worst) = (0, 0, 0.0f64);
    for ray in rays(b.min, b.max, seed, 400) {
        let expected = reference(f, b.min, b.max, lipschitz, &ray);
        if expected.near_tangent {
            continue;
        }
        compared += 1;
        let got = shape.intersect(&ray).map(|h| h.t);
        assert_eq!(
            got.is_some(),
            expected.root.is_some(),
            "{ray:?}: {got:?} != {:?}",
            expected.root
        );
        assert_eq!(got.is_some(), shape.occluded(&ray));
        if let (Some(t), Some(r)) = (got, expected.root) {
            hits += 1;
            let error = (t - r).abs() / r.abs();
            worst = worst.max(error);
            assert!(error <= tolerance, "{ray:?}: t {t} != {r} ({error:e})");
        }
    }
    assert!(shape.largest_gradient_seen().is_none());
    assert!(hits > 50, "only {hits} hits");
    assert!(compared > 300, "only {compared} rays compared");
    (compared, hits)
}

#[test]
fn a_sphere_matches_the_reference() {
    let sphere = unit_sphere();
    let f = |p: Vec3| p.length() - 1.0;
    compare_with_reference(&sphere, &f, 1.0, 1e-7, 1);
}

#[test]
fn a_torus_matches_its_closed_form_quartic() {
    let (big, small) = (1.0, 0.35);
    let torus = implicit(
        "sqrt((sqrt(x^2 + y^2) - 1)^2 + z^2) - 0.35",
        Vec3::new(-1.5, -1.5, -0.5),
        Vec3::new(1.5, 1.5, 0.5),
        1.0,
    );
    let quartic = move |p: Vec3| {
        let s = p.length_squared() + big * big - small * small;
        s * s - 4.0 * big * big * (p.x * p.x + p.y * p.y)
    };
    // The quartic's own bound over the box: |4 s p - 8 R² (x, y, 0)| with
    // s ≤ 5.6 and |p| ≤ 2.2 stays below 60.
    compare_with_reference(&torus, &quartic, 60.0, 1e-7, 2);
}

#[test]
fn a_superellipsoid_matches_its_closed_form() {
    let (e1, e2) = (0.4, 0.7);
    let text = "(abs(x)^(2/0.7) + abs(y)^(2/0.7))^(0.7/0.4) + abs(z)^(2/0.4) - 1";
    let shape = implicit(text, Vec3::splat(-1.2), Vec3::splat(1.2), 40.0);
    let closed = move |p: Vec3| {
        let xy = p.x.abs().powf(2.0 / e2) + p.y.abs().powf(2.0 / e2);
        xy.powf(e2 / e1) + p.z.abs().powf(2.0 / e1) - 1.0
    };
    compare_with_reference(&shape, &closed, 40.0, 1e-7, 3);
}

#[test]
fn a_sphere_as_an_expression_gives_the_exact_spheres_depth() {
    let exact = Sphere::new(Vec3::new(0.5, -0.25, 1.0), 0.75).unwrap();
    let shape = implicit(
        "(x - 0.5)^2 + (y + 0.25)^2 + (z - 1)^2 - 0.75^2",
        Vec3::new(-0.5, -1.25, 0.0),
        Vec3::new(1.5, 0.75, 2.0),
        4.0,
    );
    let mut compared = 0;
    for ray in rays(shape.bounds().min, shape.bounds().max, 4, 2000) {
        // The line's distance from the centre, to skip near-tangent rays.
        let to_center = exact.center() - ray.origin;
        let along = to_center.dot(ray.dir) / ray.dir.length_squared();
        let miss_distance = (to_center - along * ray.dir).length();
        if (miss_distance - exact.radius()).abs() < 1e-6 {
            continue;
        }
        let (got, want) = (shape.intersect(&ray), exact.intersect(&ray));
        assert_eq!(got.is_some(), want.is_some(), "{ray:?}");
        if let (Some(got), Some(want)) = (got, want) {
            assert!(
                (got.t - want.t).abs() <= 1e-6 * want.t,
                "{ray:?}: {} != {}",
                got.t,
                want.t
            );
            let n_got = shape.surface(&ray, &got).normal;
            let n_want = Shape::Sphere(exact).surface(&ray, &want).normal;
            assert!((n_got - n_want).length() < 1e-6, "{n_got} != {n_want}");
            compared += 1;
        }
    }
    assert!(compared > 500, "only {compared} hits compared");
}

/// Whether `ray` passes within 1e-6 of the shape's size of touching
/// `exact` without a clean crossing: moving the ray's origin by 2e-6 of the
/// size along any of ±x, ±y, ±z (one of them moves it at least 1e-6 of the
/// size along any normal) turns the exact shape's hit into a miss or the
/// reverse, or moves the first hit by more than 1e-3 of the size (a jump
/// to another part of the surface, or the √δ jump of a tangent hit).
fn near_tangent(exact: &Shape, ray: &Ray, size: f64) -> bool {
    let first = |r: &Ray| exact.intersect(r).map(|h| r.at(h.t));
    let here = first(ray);
    let steps = [Vec3::X, Vec3::Y, Vec3::Z];
    steps.iter().flat_map(|&a| [a, -a]).any(|step| {
        let moved = Ray::new(ray.origin + 2e-6 * size * step, ray.dir);
        match (here, first(&moved)) {
            (Some(p), Some(q)) => (p - q).length() > 1e-3 * size,
            (None, None) => false,
            _ => true,
        }
    })
}

/// The implicit surface and the exact shape agree on random rays: the same
/// hit or miss and `t` within 1e-6 relative, rays near tangency (by
/// [`near_tangent`]) skipped, fewer than 100 of the 2,000. Measured: the
/// worst relative error in `t` is 4.6e-13 (ring torus), at most one ray
/// skipped (the sphere).
fn assert_same_depth(shape: &Implicit, exact: &Shape, seed: u64) {
    let b = shape.bounds();
    let size = (b.max - b.min).length();
    let (mut hits, mut skipped, mut worst) = (0, 0, 0.0f64);
    for ray in rays(b.min, b.max, seed, 2000) {
        if near_tangent(exact, &ray, size) {
            skipped += 1;
            continue;
        }
        let (got, want) = (shape.intersect(&ray), exact.intersect(&ray));
        assert_eq!(
            got.map(|h| h.t).is_some(),
            want.is_some(),
            "{}: {ray:?}: {got:?} against {want:?}",
            exact.kind()
        );
        if let (Some(got), Some(want)) = (got, want) {
            let error = (got.t - want.t).abs() / want.t;
            worst = worst.max(error);
            assert!(
                error <= 1e-6,
                "{}: {ray:?}: t {} != {} ({error:e})",
                exact.kind(),
                got.t,
                want.t
            );
            hits += 1;
        }
    }
    assert!(shape.largest_gradient_seen().is_none(), "{}", exact.kind());
    assert!(hits > 500, "{}: only {hits} hits compared", exact.kind());
    assert!(skipped < 100, "{}: {skipped} rays skipped", exact.kind());
    assert!(worst <= 1e-6, "{}: worst {worst:e}", exact.kind());
}

/// Issue 17: a sphere, a torus (ring and spindle) and a superellipsoid
/// written as expressions give the exact shapes' depth to 1e-6.
#[test]
fn a_sphere_torus_and_superellipsoid_as_expressions_give_the_exact_depth() {
    let sphere = implicit(
        "(x - 0.5)^2 + (y + 0.25)^2 + (z - 1)^2 - 0.75^2",
        Vec3::new(-0.5, -1.25, 0.0),
        Vec3::new(1.5, 0.75, 2.0),
        4.0,
    );
    let exact_sphere = Shape::Sphere(Sphere::new(Vec3::new(0.5, -0.25, 1.0), 0.75).unwrap());
    // The ring torus as its distance function (slope 1).
    let ring = implicit(
        "sqrt((sqrt(x^2 + z^2) - 1)^2 + y^2) - 0.35",
        Vec3::new(-1.5, -0.5, -1.5),
        Vec3::new(1.5, 0.5, 1.5),
        1.0,
    );
    // The spindle torus as the quartic, whose zero set (unlike the distance
    // function's) holds the inner lemon: |4 s p - 8 R² (x, 0, z)| with
    // |p| ≤ 2.17 and |s| ≤ 4.98 over the box stays below 50.
    let spindle = implicit(
        "(x^2 + y^2 + z^2 + 0.25 - 0.64)^2 - 4*0.25*(x^2 + z^2)",
        Vec3::new(-1.4, -0.9, -1.4),
        Vec3::new(1.4, 0.9, 1.4),
        50.0,
    );
    let superellipsoid = implicit(
        "(abs(x)^(2/0.7) + abs(y)^(2/0.7))^(0.7/0.4) + abs(z)^(2/0.4) - 1",
        Vec3::splat(-1.2),
        Vec3::splat(1.2),
        40.0,
    );
    let exact_superellipsoid = Superellipsoid::new(Vec3::ZERO, 1.0, 0.7, 0.4).unwrap();
    let pairs = [
        (sphere, exact_sphere),
        (ring, Shape::Torus(Torus::new(1.0, 0.35).unwrap())),
        (spindle, Shape::Torus(Torus::new(0.5, 0.8).unwrap())),
        (superellipsoid, Shape::Superellipsoid(exact_superellipsoid)),
    ];
    for (seed, (shape, exact)) in pairs.iter().enumerate() {
        assert_same_depth(shape, exact, 40 + seed as u64);
    }
}

#[test]
fn edge_cases_front_behind_miss_inside_tangent() {
    let s = unit_sphere();
    // In front: the near side, normal towards the ray.
    let front = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
    let hit = s.intersect(&front).unwrap();
    assert!((hit.t - 4.0).abs() < 1e-12, "{}", hit.t);
    assert!((s.surface(&front, &hit).normal + Vec3::Z).length() < 1e-9);
    // Behind and beside: nothing.
    assert!(
        s.intersect(&Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::Z))
            .is_none()
    );
    let beside = Ray::new(Vec3::new(1.0 + 1e-4, 0.0, -5.0), Vec3::Z);
    assert!(s.intersect(&beside).is_none() && !s.occluded(&beside));
    // From inside: the far side, normal along the ray (outward).
    let inside = Ray::new(Vec3::new(0.0, 0.5, 0.0), Vec3::Y);
    let hit = s.intersect(&inside).unwrap();
    assert!((hit.t - 0.5).abs() < 1e-12);
    assert!((s.surface(&inside, &hit).normal - Vec3::Y).length() < 1e-9);
    // Beyond t_max: nothing.
    assert!(
        s.intersect(&Ray::segment(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 3.9))
            .is_none()
    );
    // Tangent and grazing: whatever is found is finite, no NaN.
    for x in [1.0, 1.0 - 1e-9, 1.0 - 1e-6, 1.0 + 1e-12] {
        let ray = Ray::new(Vec3::new(x, 0.0, -5.0), Vec3::Z);
        if let Some(hit) = s.intersect(&ray) {
            assert!(hit.t.is_finite() && (hit.t - 5.0).abs() < 1e-2);
            let surface = s.surface(&ray, &hit);
            assert!((surface.normal.length() - 1.0).abs() < 1e-9);
            assert!(surface.uv.is_finite() && surface.dpdu.is_finite());
        }
    }
}

#[test]
fn the_shape_families_hold() {
    let sphere = Shape::Implicit(unit_sphere());
    assert_no_self_intersection(&sphere, 7);
    assert_surface_is_sane(&sphere, 11);
    assert_convex_exits_cleanly(&sphere, 13);
    assert_no_nan_for_awkward_rays(&sphere);
    assert_tangents_follow_uv(&sphere, 3);
    let gyroid = Shape::Implicit(implicit(
        "sin(3*x)*cos(3*y) + sin(3*y)*cos(3*z) + sin(3*z)*cos(3*x)",
        Vec3::splat(-1.0),
        Vec3::splat(1.0),
        9.0,
    ));
    assert_no_self_intersection(&gyroid, 17);
    assert_surface_is_sane(&gyroid, 19);
    assert_no_nan_for_awkward_rays(&gyroid);
}

#[test]
fn a_function_steeper_than_its_bound_is_reported() {
    let s = implicit(
        "10*(x^2 + y^2 + z^2 - 1)",
        Vec3::splat(-2.0),
        Vec3::splat(2.0),
        1.0,
    );
    assert_eq!(s.largest_gradient_seen(), None);
    // The march trusts the bound, leaps over the sphere and misses it, but
    // sees the function change faster than the bound allows.
    let ray = Ray::new(Vec3::new(-5.0, 0.2, 0.1), Vec3::new(1.0, 0.1, 0.0));
    assert_eq!(s.intersect(&ray), None);
    let seen = s.largest_gradient_seen().unwrap();
    assert!(
        seen > 1.0 && seen <= 10.0 * 2.0 * 2.0 * 3f64.sqrt(),
        "{seen}"
    );
    s.clone().forget_gradient();
    assert_eq!(s.largest_gradient_seen(), None);
}

#[test]
fn undefined_values_count_as_outside() {
    // sqrt of a negative number is NaN below z = 0: outside, crossed.
    let s = implicit(
        "sqrt(z) - 0.5 + 0*x",
        Vec3::splat(-1.0),
        Vec3::splat(1.0),
        10.0,
    );
    let ray = Ray::new(Vec3::new(0.1, 0.2, -3.0), Vec3::Z);
    let hit = s.intersect(&ray).unwrap();
    // NaN (outside) to sqrt(z) - 0.5 < 0 (inside) at z = 0.
    assert!((hit.t - 3.0).abs() < 1e-9, "{}", hit.t);
}

#[test]
fn degenerate_parameters_are_refused() {
    let f = || Expression::parse("x^2 + y^2 + z^2 - 1").unwrap();
    let (lo, hi) = (Vec3::splat(-1.0), Vec3::splat(1.0));
    assert!(matches!(
        Implicit::new(f(), hi, lo, 1.0),
        Err(ShapeError::Degenerate { .. })
    ));
    assert!(matches!(
        Implicit::new(f(), lo, Vec3::new(1.0, -1.0, 1.0), 1.0),
        Err(ShapeError::Degenerate { .. })
    ));
    for bad in [0.0, -1.0] {
        assert!(matches!(
            Implicit::new(f(), lo, hi, bad),
            Err(ShapeError::NotPositive {
                what: "max_gradient",
                ..
            })
        ));
    }
    assert!(matches!(
        Implicit::new(f(), lo, hi, f64::NAN),
        Err(ShapeError::NotFinite { .. })
    ));
    assert!(matches!(
        Implicit::new(f(), lo, Vec3::splat(1e40), 1.0),
        Err(ShapeError::OutOfRange { what: "bounds", .. })
    ));
    let constant = Expression::parse("1 + 2").unwrap();
    assert!(matches!(
        Implicit::new(constant, lo, hi, 1.0),
        Err(ShapeError::Degenerate { .. })
    ));
}

#[test]
fn the_shape_stays_small_and_comparable() {
    assert!(std::mem::size_of::<Implicit>() <= 16);
    assert_eq!(unit_sphere(), unit_sphere());
    assert_ne!(
        unit_sphere(),
        implicit(
            "x^2 + y^2 + z^2 - 2",
            Vec3::splat(-1.5),
            Vec3::splat(1.5),
            6.0
        )
    );
}
